#pragma once
/// \file sample.hpp
/// A ray sample: a few thousand rays of a distribution with how each one ends, found once with
/// an exact hierarchy. It belongs to the scene and the distribution, not to any hierarchy, so one
/// sample predicts (model.hpp, predict_segments) any hierarchy built over the scene, including
/// one built after the sample was drawn, and drives the design of new ones.

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "rtcost/hierarchy.hpp"
#include "rtcost/rays.hpp"

namespace rtcost {

/// One primitive a sampled ray meets in (tmin, tmax): its id and the nearest parameter there.
struct Crossing {
    std::uint32_t prim = 0;
    float t = 0;
};

/// The sample: rays with their kinds, the query each is traced with, where the search ends
/// (`t_end`: the closest hit, the nearest occluder, or tmax when nothing is met), and the first
/// primitives met along each ray (up to `kMaxCrossings`, nearest first, each once), which a
/// traversal replayed over any hierarchy needs to know where it would have stopped.
struct RaySample {
    RaySet rays;
    std::vector<Query> queries;          ///< one per ray
    std::vector<float> t_end;            ///< one per ray
    std::vector<std::uint32_t> first;    ///< ray i's crossings: [first[i], first[i + 1])
    std::vector<Crossing> crossings;
    std::string distribution;            ///< what was sampled, e.g. "spd 512x512 seed 1"
    std::uint64_t seed = 0;
    std::size_t population = 0;          ///< rays of the whole distribution the sample was drawn from

    std::size_t size() const { return rays.rays.size(); }
    std::span<const Crossing> crossings_of(std::size_t i) const {
        return {crossings.data() + first[i], crossings.data() + first[i + 1]};
    }
};

/// Crossings kept per ray: enough for the closest hit, the occluders an any-hit search may find
/// first, and the hits a BVH finds in subtrees it visits before the nearest one.
inline constexpr std::size_t kMaxCrossings = 16;

/// Draws `count` rays of the distribution `spec` names, without replacement and stratified
/// along the distribution's order (one ray from each of `count` equal runs: every kind of a ray
/// tree in its proportion, camera-based kinds spread evenly over the image), and finds how
/// each one ends with `reference` (any exact hierarchy over the same scene). Shadow and
/// ambient-occlusion rays get `occlusion`, the others `query`. Deterministic for a seed.
RaySample draw_sample(const Scene& scene, const RaySpec& spec, std::size_t count, std::uint64_t seed,
                      const Hierarchy& reference, Query query = Query::Closest, Query occlusion = Query::Any);

/// The same from the whole distribution's rays, already made.
RaySample draw_sample_from(const Scene& scene, const RaySet& all, std::size_t count, std::uint64_t seed,
                           const Hierarchy& reference, Query query = Query::Closest, Query occlusion = Query::Any);

/// Finds how each of `s`'s rays ends (t_end and crossings, replacing any) with `reference`, an
/// exact hierarchy over the scene, tracing with the rays' own tmin and tmax.
void find_ends(RaySample& s, const Hierarchy& reference);

/// A sample of the scene alone, for predictions without the user's rays (the geometric
/// estimator under termination): `per_kind` rays standing for each of `kinds`, made from the
/// geometry and the lights only, never from the camera. Eye, line and file rays are aimed rays
/// from outside, their targets chosen half by primitive and half by area (aimed_rays). The
/// others start where such rays first meet a surface, on the side they came from: shadow rays towards one of the scene's lights (cosine-
/// weighted without lights), diffuse and ambient-occlusion rays cosine-weighted (the latter
/// ao_length() long), reflection rays mirrored, refraction rays straight on. Ends are found
/// with `reference`. Deterministic for a seed; `population` is 0 (no distribution behind it).
RaySample draw_visibility_sample(const Scene& scene, std::span<const RayKind> kinds, std::size_t per_kind,
                                 std::uint64_t seed, const Hierarchy& reference, Query query = Query::Closest,
                                 Query occlusion = Query::Any);

/// The rays of `all` that are not in the sample drawn from it with the same count and seed (the
/// test rays disjoint from a sample), in their order.
RaySet rays_outside_sample(const RaySet& all, std::size_t count, std::uint64_t seed);

/// Sample file: "RTCSAMPL" then version, counts and the records (little-endian; the README
/// documents the layout). Written atomically.
void write_sample(const std::string& path, const RaySample& s);
/// Throws InputError naming the file for a malformed or truncated sample.
RaySample read_sample(const std::string& path);

}  // namespace rtcost
