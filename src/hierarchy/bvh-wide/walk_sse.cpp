// bvh-wide traversals for the baseline instruction set: SSE2 on x86-64 (four lanes in one
// register, eight in two), plain per-lane loops elsewhere.
#include <algorithm>
#include <cmath>
#include <utility>

#include "../common/lanes_base.hpp"
#include "wide.hpp"

namespace rtcost::wide {
namespace base {

using P4 = lanes::F4;

/// Eight lanes as two halves.
struct P8 {
    P4 a, b;
    static P8 load(const float* p) { return {P4::load(p), P4::load(p + 4)}; }
    static P8 splat(float x) { return {P4::splat(x), P4::splat(x)}; }
    static P8 sub(P8 x, P8 y) { return {P4::sub(x.a, y.a), P4::sub(x.b, y.b)}; }
    static P8 mul(P8 x, P8 y) { return {P4::mul(x.a, y.a), P4::mul(x.b, y.b)}; }
    static P8 max(P8 x, P8 y) { return {P4::max(x.a, y.a), P4::max(x.b, y.b)}; }
    static P8 min(P8 x, P8 y) { return {P4::min(x.a, y.a), P4::min(x.b, y.b)}; }
    static unsigned le(P8 x, P8 y) { return P4::le(x.a, y.a) | (P4::le(x.b, y.b) << 4); }
    void store(float* p) const {
        a.store(p);
        b.store(p + 4);
    }
};

#include "walk.inc"

}  // namespace base

Walks walks_baseline(int width) {
    return width == 8 ? base::make_walks<base::P8, 8, base::P4, 4, base::P4>()
                      : base::make_walks<base::P4, 4, base::P4, 4, base::P4>();
}

}  // namespace rtcost::wide
