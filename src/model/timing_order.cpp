// The order of each round of interleaved timing passes (eval --interleave, calibrate).
#include <numeric>

#include "rtcost/evaluate.hpp"
#include "util/rng.hpp"

namespace rtcost {

std::vector<std::size_t> timing_order(std::size_t n, int round) {
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), std::size_t{0});
    // One stream per round, so that round r's order does not depend on how many came before.
    Rng rng(mix64(static_cast<std::uint64_t>(round) + 1));
    shuffle(order, rng);
    return order;
}

}  // namespace rtcost
