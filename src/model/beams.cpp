// 5D ray classification under the line measure: each beam's weight by quadrature.
#include <algorithm>
#include <cmath>

#include "model_internal.hpp"

namespace rtcost::model {

// ---- 5D ray classification under the line measure ----------------------------------------
// A line entering the root box B through face f at a point x with direction w has density
// |w . n_f| dA dw (the invariant measure of lines). A beam is a set of (entry point, direction):
// its weight is the sum over the faces of B it touches of area(face within its origin box) times
// the integral over its directions entering that face of |w . n_f|. With w = (s e_k + u e_i1 +
// v e_i2) / r, r = sqrt(1 + u^2 + v^2), dw = du dv / r^3, the integrand is |component| / r^4.
// Integrated by Gauss-Legendre quadrature (the integrands are smooth once split at 0).

namespace {
double gauss_2d(double u0, double u1, double v0, double v1, int which, double sign) {
    static constexpr double x[8] = {-0.9602898564975363, -0.7966664774136267, -0.5255324099163290,
                                    -0.1834346424956498, 0.1834346424956498,  0.5255324099163290,
                                    0.7966664774136267,  0.9602898564975363};
    static constexpr double w[8] = {0.1012285362903763, 0.2223810344533745, 0.3137066458778873,
                                    0.3626837833783620, 0.3626837833783620, 0.3137066458778873,
                                    0.2223810344533745, 0.1012285362903763};
    // which: 0 = constant component (the dominant axis), 1 = u, 2 = v; only where sign*comp > 0.
    auto part = [&](double a0, double a1, double b0, double b1) {
        if (!(a1 > a0) || !(b1 > b0)) return 0.0;
        double hu = 0.5 * (a1 - a0), cu = 0.5 * (a1 + a0), hv = 0.5 * (b1 - b0), cv = 0.5 * (b1 + b0);
        double sum = 0;
        for (int i = 0; i < 8; ++i) {
            double u = cu + hu * x[i];
            for (int j = 0; j < 8; ++j) {
                double v = cv + hv * x[j];
                double r2 = 1 + u * u + v * v;
                double comp = which == 0 ? 1.0 : which == 1 ? sign * u : sign * v;
                sum += w[i] * w[j] * std::max(0.0, comp) / (r2 * r2);
            }
        }
        return sum * hu * hv;
    };
    // Split at 0 on the axis whose component changes sign, so each piece is smooth.
    if (which == 1 && u0 < 0 && u1 > 0) return part(u0, 0, v0, v1) + part(0, u1, v0, v1);
    if (which == 2 && v0 < 0 && v1 > 0) return part(u0, u1, v0, 0) + part(u0, u1, 0, v1);
    return part(u0, u1, v0, v1);
}

}  // namespace

/// Line-measure weight of a beam with directions `m` whose origins lie in `o` (inside root box `b`).
double beam_weight(const ModelBeam& m, const Box3& o, const Box3& b) {
    const int k = m.axis;
    const int i1 = k == 0 ? 1 : 0;  // the other axis carries v
    const double s = m.negative ? -1.0 : 1.0;
    double total = 0;
    for (int a = 0; a < 3; ++a) {
        const int p = (a + 1) % 3, q = (a + 2) % 3;
        const double area = (double(o.hi[p]) - o.lo[p]) * (double(o.hi[q]) - o.lo[q]);
        for (int side = 0; side < 2; ++side) {
            // side 0: the low face (outward normal -e_a): entering needs w_a > 0.
            const bool touches = side == 0 ? o.lo[a] <= b.lo[a] : o.hi[a] >= b.hi[a];
            if (!touches || area <= 0) continue;
            const double dir = side == 0 ? 1.0 : -1.0;
            double integral;
            if (a == k) integral = s * dir > 0 ? gauss_2d(m.u[0], m.u[1], m.v[0], m.v[1], 0, 1) : 0;
            else if (a == i1) integral = gauss_2d(m.u[0], m.u[1], m.v[0], m.v[1], 1, dir);
            else integral = gauss_2d(m.u[0], m.u[1], m.v[0], m.v[1], 2, dir);
            total += area * integral;
        }
    }
    return total;
}

}  // namespace rtcost::model
