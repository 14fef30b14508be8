// The extension module rtcost._rtcost; python/rtcost/__init__.py is the package around it.
#include "bindings.hpp"
#include "rtcost/error.hpp"

PYBIND11_MODULE(_rtcost, m) {
    namespace pb = pybind11;
    m.doc() = "rtcost: build, trace, count and model ray tracing acceleration structures";
    // InputError's text is the CLI's message after "rtcost: error: " ("FILE:LINE: problem").
    pb::register_exception<rtcost::InputError>(m, "InputError", PyExc_ValueError);
    rtcost::py::bind_scene(m);
    rtcost::py::bind_hierarchy(m);
    rtcost::py::bind_evaluate(m);
}
