#pragma once
// The project's random numbers, in one place. Rays must be identical for the same seed on every
// machine and standard library, so no std:: distribution is used (their output is not specified):
// uniform doubles are made from the top 53 bits of a generator's raw word.
#include <cmath>
#include <cstdint>
#include <numbers>
#include <random>
#include <utility>
#include <vector>

#include "rtcost/math.hpp"

namespace rtcost {

/// splitmix64's finaliser (Steele, Lea and Flood): a well-mixed word from any 64-bit value.
constexpr std::uint64_t mix64(std::uint64_t z) {
    z *= 0x9E3779B97F4A7C15ull;
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
}

/// A uniform double in [0, 1) from the top 53 bits of `z`.
constexpr double unit_double(std::uint64_t z) { return static_cast<double>(z >> 11) * 0x1p-53; }

/// A stream of random numbers: mt19937_64, whose raw output the standard specifies bit for bit.
struct Rng {
    std::mt19937_64 engine;
    explicit Rng(std::uint64_t seed) : engine(seed) {}
    double uniform() { return unit_double(engine()); }
    /// Uniform on the unit sphere.
    Vec3 direction() {
        double z = 1 - 2 * uniform();
        double phi = 2 * std::numbers::pi * uniform();
        double r = std::sqrt(std::max(0.0, 1 - z * z));
        return {static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)), static_cast<float>(z)};
    }
};

/// Fisher-Yates on the raw output: the same permutation on every standard library (std::shuffle's
/// is not specified).
template <class T>
void shuffle(std::vector<T>& items, Rng& rng) {
    for (std::size_t i = items.size(); i > 1; --i) std::swap(items[i - 1], items[rng.engine() % i]);
}

/// splitmix64 as a generator whose whole state is one word, so that every item (a pixel, a
/// sample) gets its own stream from (seed, item) whatever thread computes it.
struct ItemRng {
    std::uint64_t state;
    ItemRng(std::uint64_t seed, std::uint64_t item)
        : state(seed * 0x9e3779b97f4a7c15ull ^ (item + 1) * 0xd1b54a32d192ed03ull) {
        next();
    }
    std::uint64_t next() {
        std::uint64_t z = (state += 0x9e3779b97f4a7c15ull);
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }
    double uniform() { return unit_double(next()); }
};

}  // namespace rtcost
