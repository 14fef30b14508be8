// Drawing a ray sample: rays of a distribution picked without replacement (stratified along
// their order), and how each ends.
#include "rtcost/sample.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <functional>
#include <oneapi/tbb/parallel_for.h>

#include "rtcost/error.hpp"
#include "util/rng.hpp"

namespace rtcost {
namespace {

/// The indices of a sample of `count` out of `n`, ascending, stratified: one index drawn
/// uniformly from each of `count` runs of consecutive indices of equal length (to one). A
/// distribution's rays come in their order (camera-based kinds pixel by pixel, a ray tree's
/// kinds together), so the sample covers the image evenly and each kind in its proportion,
/// where an unstratified draw leaves clusters and gaps: the mean cost of nearby pixels is
/// alike, so the sample's mean varies less (`tests/test_segments.cpp` measures by how much).
std::vector<std::size_t> pick(std::size_t n, std::size_t count, std::uint64_t seed) {
    count = std::min(count, n);
    std::vector<std::size_t> idx(count);
    Rng rng(seed);
    for (std::size_t j = 0; j < count; ++j) {
        // Run j is [j n / count, (j + 1) n / count), never empty since count <= n.
        const std::size_t lo = static_cast<std::size_t>(static_cast<unsigned __int128>(j) * n / count);
        const std::size_t hi = static_cast<std::size_t>(static_cast<unsigned __int128>(j + 1) * n / count);
        idx[j] = lo + static_cast<std::size_t>(rng.engine() % (hi - lo));
    }
    return idx;
}

/// The pixels of a width x height image in the order a sample takes them: a 2D low-discrepancy
/// order. Pixel (x, y) has a code whose bits, most significant first, alternate between x's
/// and y's (the longer side alone first, until both have as many left), and the order takes
/// codes in bit-reversed counting order (the van der Corput sequence), Owen-scrambled with the
/// seed (each bit flipped or not by a hash of the bits above it), skipping codes outside the
/// image. Any prefix of 2^k codes then has one pixel in each of 2^k blocks that halve the image
/// alternately across and down, at a random place in its block, so a few hundred pixels cover
/// the image evenly in both directions without a regular pattern. (An order along the pixel
/// index alone aligned with a width of a power of two and took whole columns.) A longer prefix
/// keeps the shorter one's pixels: a sample can be traced pixel batch by pixel batch and be the
/// same as one drawn from the whole distribution.
class PixelOrder {
public:
    PixelOrder(std::size_t width, std::size_t height, std::uint64_t seed)
        : width_(width), height_(height), seed_(mix64(seed ^ 0x5eed5a3b1e0f1ce5ull)) {
        while ((std::uint64_t{1} << xbits_) < width) ++xbits_;
        while ((std::uint64_t{1} << ybits_) < height) ++ybits_;
        bits_ = xbits_ + ybits_;
        // The flips of the codes' first bits, which every code needs: hashed once here.
        flips_.resize(std::size_t{2} << std::min(bits_, kTabledBits));
        for (std::size_t above = 1; above < flips_.size(); ++above) flips_[above] = flip(above);
    }
    /// The next pixel (row x width + column); false once every pixel was given.
    bool next(std::uint32_t& pixel) {
        while (i_ <= last()) {
            const std::uint64_t code = bits_ ? reverse(i_) >> (64 - bits_) : 0;
            ++i_;
            // The scrambled code's bits, most significant first (each flipped or not by a hash
            // of the original bits above it), dealt to x and y as they come. A code is given up
            // as soon as its bits so far put the pixel outside the image: with an image side
            // just above a power of two, three codes in four are, most known from a few bits.
            std::uint64_t x = 0, y = 0, above = 1;  // the original bits above, after a leading 1
            int xb = xbits_, yb = ybits_;
            bool inside = true;
            for (int b = bits_ - 1; b >= 0 && inside; --b) {
                const std::uint64_t bit = (code >> b) & 1;
                const std::uint64_t out = bit ^ (above < flips_.size() ? flips_[above] : flip(above));
                above = (above << 1) | bit;
                // x takes a bit when it has more left than y, or as many (x first).
                if (xb > 0 && (xb >= yb || yb == 0)) {
                    x |= out << --xb;
                    inside = x < width_;
                } else {
                    y |= out << --yb;
                    inside = y < height_;
                }
            }
            if (inside) {
                pixel = static_cast<std::uint32_t>(y * width_ + x);
                return true;
            }
        }
        return false;
    }

private:
    /// Whether the bit after the original bits `above` (after a leading 1) is flipped.
    std::uint64_t flip(std::uint64_t above) const { return mix64(seed_ ^ (above * 0x9E3779B97F4A7C15ull)) & 1; }
    static constexpr int kTabledBits = 12;
    std::uint64_t last() const { return bits_ >= 64 ? ~0ull : (std::uint64_t{1} << bits_) - 1; }
    static std::uint64_t reverse(std::uint64_t x) {
        x = ((x >> 1) & 0x5555555555555555ull) | ((x & 0x5555555555555555ull) << 1);
        x = ((x >> 2) & 0x3333333333333333ull) | ((x & 0x3333333333333333ull) << 2);
        x = ((x >> 4) & 0x0F0F0F0F0F0F0F0Full) | ((x & 0x0F0F0F0F0F0F0F0Full) << 4);
        return __builtin_bswap64(x);  // std::byteswap is C++23
    }
    std::size_t width_, height_;
    std::uint64_t seed_;
    int xbits_ = 0, ybits_ = 0, bits_ = 0;
    std::uint64_t i_ = 0;
    std::vector<std::uint8_t> flips_;  ///< flip(above) for every `above` of the first kTabledBits bits
};

/// A set of an image's pixels, a bit each: its pixels in ascending order and each one's rank
/// among them without a sort (a sample's pixel batches come in the scrambled PixelOrder).
class PixelSet {
public:
    explicit PixelSet(std::size_t image_pixels) : words_((image_pixels + 63) / 64, 0) {}
    void insert(std::uint32_t p) { words_[p >> 6] |= std::uint64_t{1} << (p & 63); }
    /// The pixels, ascending; ranks are counted from here on.
    std::vector<std::uint32_t> ascending() {
        std::vector<std::uint32_t> out;
        below_.resize(words_.size());
        for (std::size_t w = 0; w < words_.size(); ++w) {
            below_[w] = static_cast<std::uint32_t>(out.size());
            for (std::uint64_t bits = words_[w]; bits; bits &= bits - 1)
                out.push_back(static_cast<std::uint32_t>(w * 64 + std::countr_zero(bits)));
        }
        return out;
    }
    /// The index of member `p` in ascending().
    std::size_t rank(std::uint32_t p) const {
        const std::uint64_t lower = (std::uint64_t{1} << (p & 63)) - 1;
        return below_[p >> 6] + static_cast<std::size_t>(std::popcount(words_[p >> 6] & lower));
    }

private:
    std::vector<std::uint64_t> words_;
    std::vector<std::uint32_t> below_;  ///< members in the words before each
};

/// A pixel-drawn sample takes the rays of about twice its size in pixels, so that it holds about
/// every other ray of a pixel's ray tree rather than whole trees (a tree's rays are alike).
constexpr std::size_t kPixelRaysPerSampleRay = 2;

/// The pixels (ascending) whose rays a sample of `count` rays of a camera-based distribution is
/// drawn from: a prefix of PixelOrder, as long as it takes to hold kPixelRaysPerSampleRay x
/// `count` rays, and at most half the image (the other half stays for test rays).
/// `rays_in(batch)` gives the number of rays of each pixel of a batch of the order's pixels:
/// looked up in a whole distribution, or traced there and then.
std::vector<std::uint32_t> sample_pixels(std::size_t image_pixels, std::size_t image_width, std::size_t count,
                                         std::uint64_t seed,
                                         const std::function<std::vector<std::size_t>(const std::vector<std::uint32_t>&)>& rays_in) {
    if (image_width == 0 || image_pixels % image_width) throw std::logic_error("a ray set's image is not width x height");
    PixelOrder order(image_width, image_pixels / image_width, seed);
    const std::size_t cap = image_pixels / 2, want = kPixelRaysPerSampleRay * count;
    std::vector<std::uint32_t> taken;
    std::size_t rays = 0;
    while (rays < want && taken.size() < cap) {
        // A first batch of a sixteenth of the sample's pixels at one ray each, to learn how many
        // rays a pixel holds (from none to dozens); then as many pixels as that says are
        // missing, a quarter more, at least 64.
        std::size_t size = std::max<std::size_t>(64, want / 16);
        if (!taken.empty()) {
            const double per_pixel = std::max(double(rays) / double(taken.size()), 1e-3);
            const double missing = 1.25 * double(want - rays) / per_pixel;
            size = std::max<std::size_t>(64, static_cast<std::size_t>(std::min(missing, 1e12)));
        }
        size = std::min(size, cap - taken.size());
        std::vector<std::uint32_t> batch;
        for (std::uint32_t p; batch.size() < size && order.next(p);) batch.push_back(p);
        if (batch.empty()) break;
        const std::vector<std::size_t> n = rays_in(batch);
        for (std::size_t k = 0; k < batch.size() && rays < want; ++k) {
            taken.push_back(batch[k]);
            rays += n[k];
        }
    }
    PixelSet set(image_pixels);
    for (std::uint32_t p : taken) set.insert(p);
    return set.ascending();
}

/// The rays of `all` (a camera-based distribution: RaySet::pixels) of the sample's pixels.
std::vector<std::size_t> rays_of_pixels(const RaySet& all, const std::vector<std::uint32_t>& taken) {
    std::vector<std::size_t> out;
    // Both ascending: one merge.
    auto at = taken.begin();
    for (std::size_t i = 0; i < all.pixels.size() && at != taken.end(); ++i) {
        while (at != taken.end() && *at < all.pixels[i]) ++at;
        if (at != taken.end() && *at == all.pixels[i]) out.push_back(i);
    }
    return out;
}

/// sample_pixels for a whole distribution.
std::vector<std::uint32_t> sample_pixels(const RaySet& all, std::size_t count, std::uint64_t seed) {
    if (all.pixels.size() != all.rays.size()) throw std::logic_error("a ray set without a pixel per ray");
    return sample_pixels(all.image_pixels, all.image_width, count, seed, [&](const std::vector<std::uint32_t>& batch) {
        std::vector<std::size_t> n(batch.size());
        for (std::size_t k = 0; k < batch.size(); ++k) {
            const auto [lo, hi] = std::equal_range(all.pixels.begin(), all.pixels.end(), batch[k]);
            n[k] = static_cast<std::size_t>(hi - lo);
        }
        return n;
    });
}

/// Indices into `all` of the sample of `count` (fewer where `all` has too few): stratified
/// along the distribution's order, over all of it or, for a camera-based distribution, over the
/// rays of the sample's pixels (sample_pixels).
std::vector<std::size_t> sample_indices(const RaySet& all, std::size_t count, std::uint64_t seed) {
    if (!all.image_pixels) return pick(all.rays.size(), count, seed);
    const std::vector<std::size_t> from = rays_of_pixels(all, sample_pixels(all, count, seed));
    std::vector<std::size_t> idx = pick(from.size(), count, seed);
    for (std::size_t& i : idx) i = from[i];
    return idx;
}

}  // namespace

std::size_t sample_size(const RaySet& all, std::size_t count, std::uint64_t seed) {
    return sample_indices(all, count, seed).size();
}

std::size_t draw_sample_count(const RaySet& all, std::size_t count) {
    return all.image_pixels ? count : std::min(count, std::max<std::size_t>(all.rays.size() / 2, 1));
}

RaySet rays_outside_sample(const RaySet& all, std::size_t count, std::uint64_t seed) {
    // A camera-based distribution's sample leaves out every ray of its pixels, sampled or not:
    // the test rays are those of the pixels it never traced.
    std::vector<std::size_t> in;
    if (all.image_pixels) {
        if (all.pixels.size() != all.rays.size()) throw std::logic_error("a ray set without a pixel per ray");
        in = rays_of_pixels(all, sample_pixels(all, count, seed));
    } else {
        in = pick(all.rays.size(), count, seed);
    }
    RaySet out;
    out.described = all.described;
    out.image_pixels = all.image_pixels;
    out.image_width = all.image_width;
    out.rays.reserve(all.rays.size() - in.size());
    out.kinds.reserve(all.rays.size() - in.size());
    std::size_t next = 0;
    for (std::size_t i = 0; i < all.rays.size(); ++i) {
        if (next < in.size() && in[next] == i) {
            ++next;
            continue;
        }
        out.rays.push_back(all.rays[i]);
        out.kinds.push_back(all.kinds[i]);
        if (all.image_pixels) out.pixels.push_back(all.pixels[i]);
    }
    return out;
}

void find_ends(RaySample& s, const Hierarchy& reference) {
    s.scene = reference.scene().fingerprint();
    const std::size_t n = s.rays.rays.size();
    std::vector<std::vector<Crossing>> per(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
        Crossing found[kMaxCrossings];
        const std::size_t k = reference.crossings(s.rays.rays[i], found);
        if (k) per[i].assign(found, found + k);
    });
    s.first.clear();
    s.t_end.clear();
    s.crossings.clear();
    s.first.reserve(n + 1);
    s.t_end.reserve(n);
    for (std::size_t i = 0; i < n; ++i) {
        s.first.push_back(static_cast<std::uint32_t>(s.crossings.size()));
        s.t_end.push_back(per[i].empty() ? s.rays.rays[i].tmax : per[i].front().t);
        s.crossings.insert(s.crossings.end(), per[i].begin(), per[i].end());
    }
    s.first.push_back(static_cast<std::uint32_t>(s.crossings.size()));
}

namespace {

/// The sample of `idx` (ascending indices into `all`), its ends found with `reference`.
RaySample sample_of(const RaySet& all, const std::vector<std::size_t>& idx, std::uint64_t seed, const Hierarchy& reference,
                    Query query, Query occlusion) {
    RaySample s;
    s.distribution = all.described;
    s.seed = seed;
    s.population = all.rays.size();
    s.rays.described = all.described + " (sample)";
    for (std::size_t i : idx) {
        s.rays.rays.push_back(all.rays[i]);
        s.rays.kinds.push_back(all.kinds[i]);
        s.queries.push_back(is_occlusion(all.kinds[i]) ? occlusion : query);
    }
    find_ends(s, reference);
    return s;
}

void check_draw(const RaySet& all, std::size_t count) {
    if (count == 0) throw InputError("--count", 0, "a sample needs at least one ray");
    if (all.rays.empty()) throw InputError(all.described, 0, "the distribution has no rays");
}

}  // namespace

RaySample draw_sample(const Scene& scene, const RaySpec& spec, std::size_t count, std::uint64_t seed,
                      const Hierarchy& reference, Query query, Query occlusion) {
    // Only the rays are wanted, made with the reference; no pixel at first, to learn whether
    // the distribution is camera-based (a distribution of another kind ignores the pixels and
    // is made whole here).
    const std::vector<std::uint32_t> none;
    RayMaking making;
    making.tracer = &reference;
    making.rays_only = true;
    making.only_pixels = &none;
    RaySet all = make_rays(scene, spec, making);
    if (!all.image_pixels)
        return draw_sample_from(scene, all, draw_sample_count(all, count), seed, reference, query, occlusion);
    if (count == 0) throw InputError("--count", 0, "a sample needs at least one ray");
    // Trace the sample's pixels batch by batch, as many as it takes: the same pixels, rays and
    // sample as a draw from the whole distribution, for the price of about twice the sample.
    std::vector<RaySet> parts;
    const std::vector<std::uint32_t> taken =
        sample_pixels(all.image_pixels, all.image_width, count, seed, [&](const std::vector<std::uint32_t>& batch) {
            PixelSet set(all.image_pixels);
            for (std::uint32_t p : batch) set.insert(p);
            const std::vector<std::uint32_t> sorted = set.ascending();
            making.only_pixels = &sorted;
            parts.push_back(make_rays(scene, spec, making));
            // Rays per pixel of `sorted` (both ascending: one merge), then in the batch's order.
            std::vector<std::size_t> in_sorted(sorted.size());
            std::size_t at = 0;
            for (std::uint32_t p : parts.back().pixels) {
                while (at < sorted.size() && sorted[at] < p) ++at;
                if (at == sorted.size() || sorted[at] != p) throw std::logic_error("a ray of a pixel not asked for");
                ++in_sorted[at];
            }
            std::vector<std::size_t> n(batch.size());
            for (std::size_t k = 0; k < batch.size(); ++k) n[k] = in_sorted[set.rank(batch[k])];
            return n;
        });
    // The taken pixels' rays in the distribution's order: by pixel, each pixel's in its order
    // (every part is in that order; a pixel is in one part).
    std::vector<std::pair<std::uint32_t, std::pair<std::size_t, std::size_t>>> order;  // pixel, (part, ray)
    for (std::size_t k = 0; k < parts.size(); ++k)
        for (std::size_t i : rays_of_pixels(parts[k], taken)) order.push_back({parts[k].pixels[i], {k, i}});
    std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    RaySet from;
    from.described = all.described;
    for (const auto& [pixel, at] : order) {
        from.rays.push_back(parts[at.first].rays[at.second]);
        from.kinds.push_back(parts[at.first].kinds[at.second]);
    }
    if (from.rays.empty())
        throw InputError(all.described, 0, "no rays in half the image's pixels to draw a sample from");
    RaySample s = sample_of(from, pick(from.rays.size(), count, seed), seed, reference, query, occlusion);
    s.population = 0;  // not counted: the distribution was traced at the sample's pixels only
    return s;
}

RaySample draw_sample_from(const Scene& scene, const RaySet& all, std::size_t count, std::uint64_t seed,
                           const Hierarchy& reference, Query query, Query occlusion) {
    (void)scene;
    check_draw(all, count);
    return sample_of(all, sample_indices(all, count, seed), seed, reference, query, occlusion);
}

}  // namespace rtcost
