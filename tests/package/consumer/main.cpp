// Loads a scene, builds bvh-sah, traces isotropic lines counting every operation and predicts
// the cost with the geometric estimator: rtcost used as a library from an installed package.
// Prints one line of numbers the package test checks.
#include <cstdio>
#include <exception>

#include "rtcost/io.hpp"
#include "rtcost/model.hpp"
#include "rtcost/trace.hpp"

int main(int argc, char** argv) {
    try {
        rtcost::Scene scene = rtcost::load_scene(argc > 1 ? argv[1] : "builtin:tetra:4");
        auto h = rtcost::build_hierarchy(scene, "bvh-sah");
        std::vector<rtcost::Ray> rays = rtcost::line_rays(scene.bounds(), 20000, 7);
        rtcost::TraceOptions opt;
        opt.query = rtcost::Query::All;
        opt.count = true;
        rtcost::TraceResult r = rtcost::trace_rays(*h, rays, opt);
        rtcost::ModelOptions mopt;
        mopt.query = rtcost::Query::All;
        rtcost::Prediction p = rtcost::predict_geometric(*h, mopt);
        double measured = rtcost::UnitCosts{}.scalar(rtcost::measured_cost(r.counters));
        std::printf("primitives %zu hierarchies %zu rays %zu hits %zu predicted %.6f measured %.6f\n", scene.size(),
                    rtcost::hierarchies().size(), rays.size(), r.hit_count, p.scalar, measured);
        return 0;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "consumer: error: %s\n", e.what());
        return 2;
    }
}
