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
    /// Scene::fingerprint() of the scene it was drawn on (set by find_ends); 0: unknown (a
    /// version-1 sample file).
    std::uint64_t scene = 0;
    /// The version of the sample file it was read from; 0: drawn, not read.
    std::uint32_t file_version = 0;
    /// The file it was read from (what errors about it name); empty: drawn, not read.
    std::string path;
    /// What an error about this sample names: its file, or "sample" for one drawn.
    std::string source() const { return path.empty() ? "sample" : path; }

    std::size_t size() const { return rays.rays.size(); }
    std::span<const Crossing> crossings_of(std::size_t i) const {
        return {crossings.data() + first[i], crossings.data() + first[i + 1]};
    }
};

/// Crossings kept per ray: enough for the closest hit, the occluders an any-hit search may find
/// first, and the hits a BVH finds in subtrees it visits before the nearest one.
inline constexpr std::size_t kMaxCrossings = 16;

/// Draws `count` rays of the distribution `spec` names, without replacement, and finds how each
/// one ends with `reference` (any exact hierarchy over the same scene). Shadow and
/// ambient-occlusion rays get `occlusion`, the others `query`. Deterministic for a seed.
///  - A camera-based distribution (RaySet::image_pixels) is drawn by pixel: the sample's pixels
///    are a prefix of a seeded low-discrepancy order of the image's pixels (spread evenly over
///    the image), long enough to hold twice `count` rays and at most half the pixels, and the
///    sample is `count` of their rays stratified along the distribution's order (every kind of
///    a ray tree in its proportion). Only those pixels are traced, with `reference`: about
///    twice the sample's rays, whatever the distribution's size. `population` is then 0 (the
///    whole distribution is never made).
///  - Any other is made whole and `count` rays (at most half of them) are drawn stratified
///    along its order: one from each of `count` equal runs.
RaySample draw_sample(const Scene& scene, const RaySpec& spec, std::size_t count, std::uint64_t seed,
                      const Hierarchy& reference, Query query = Query::Closest, Query occlusion = Query::Any);

/// The same from the whole distribution's rays, already made: for a camera-based one the same
/// sample as draw_sample's, for another `count` rays (not capped) stratified along its order.
/// `population` is `all`'s size.
RaySample draw_sample_from(const Scene& scene, const RaySet& all, std::size_t count, std::uint64_t seed,
                           const Hierarchy& reference, Query query = Query::Closest, Query occlusion = Query::Any);

/// How many rays draw_sample_from(all, count, seed) draws: `count`, or fewer where `all` has
/// too few (a camera-based distribution's half of the pixels may hold fewer).
std::size_t sample_size(const RaySet& all, std::size_t count, std::uint64_t seed);

/// The `count` draw_sample asks draw_sample_from for, from the distribution `all` (made whole):
/// `count` for a camera-based one (its draw takes at most half the pixels), at most half the
/// rays of another. draw_sample's sample is then draw_sample_from(all, that, seed)'s.
std::size_t draw_sample_count(const RaySet& all, std::size_t count);

/// Finds how each of `s`'s rays ends (t_end and crossings, replacing any) with `reference`, an
/// exact hierarchy over the scene, tracing with the rays' own tmin and tmax: its first
/// kMaxCrossings crossings (Hierarchy::crossings).
void find_ends(RaySample& s, const Hierarchy& reference);

/// A sample of the scene alone, for predictions without the user's rays (the geometric
/// estimator under termination): `per_kind` rays standing for each of `kinds`, made from the
/// scene's geometry, camera, lights and materials, never from a distribution's rays. Eye rays
/// start at the scene's eye through uniform points of its view (view_rays); line and file rays
/// are aimed rays from outside, their targets chosen half by primitive and half by area
/// (aimed_rays). Reflection rays start where eye rays land on a material that reflects or
/// transmits, refraction rays where it transmits (bent by its index); shadow rays (towards one
/// of the lights), diffuse and ambient-occlusion rays (cosine-weighted, the latter ao_length()
/// long) start where eye rays land and, when reflection or refraction rays are among `kinds` (a
/// ray tree), where each eye landing's first reflection and refraction land. A kind listed twice
/// is drawn once. Ends are found with `reference`.
/// Deterministic for a seed; `population` is 0 (no distribution behind it). `view`, when given,
/// is the camera eye rays come from instead of the scene's (the same eye with the image shape a
/// distribution traces, say).
RaySample draw_visibility_sample(const Scene& scene, std::span<const RayKind> kinds, std::size_t per_kind,
                                 std::uint64_t seed, const Hierarchy& reference, Query query = Query::Closest,
                                 Query occlusion = Query::Any, const Camera* view = nullptr);

/// The rays of `all` that are not in the sample drawn from it with the same count and seed (the
/// test rays disjoint from a sample), in their order. For a camera-based distribution, the rays
/// of every pixel the sample's draw took are left out (sampled or not): the test rays are those
/// of the pixels the draw never traced.
RaySet rays_outside_sample(const RaySet& all, std::size_t count, std::uint64_t seed);

/// Sample file: "RTCSAMPL" then version, counts and the records (little-endian; the README
/// documents the layout). Written atomically.
void write_sample(const std::string& path, const RaySample& s);
/// Throws InputError naming the file for a malformed or truncated sample.
RaySample read_sample(const std::string& path);

}  // namespace rtcost
