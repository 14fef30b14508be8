// Vega, Vega-Lite and vega-embed, embedded into the binary at build time (CMakeLists.txt finds
// them in third_party/js/node_modules, where scripts/install-deps.sh puts them), so that a report
// inlines them and the page fetches nothing.
#include "report/report_assets.hpp"

#if defined(RTCOST_VEGA_JS) && defined(RTCOST_VEGA_LITE_JS) && defined(RTCOST_VEGA_EMBED_JS)
// .incbin puts each file's bytes in read-only data; the versions and hashes in the strings below
// are there so that a compiler cache sees a new object when a file changes.
#define RTCOST_INCBIN(sym, path)                           \
    asm(".section .rodata\n"                               \
        ".global " #sym "\n"                               \
        ".type " #sym ", @object\n"                        \
        ".balign 16\n" #sym ":\n"                          \
        ".incbin \"" path "\"\n"                           \
        ".global " #sym "_end\n" #sym "_end:\n"            \
        ".byte 0\n"                                        \
        ".previous\n")
RTCOST_INCBIN(rtcost_vega_js, RTCOST_VEGA_JS);
RTCOST_INCBIN(rtcost_vega_lite_js, RTCOST_VEGA_LITE_JS);
RTCOST_INCBIN(rtcost_vega_embed_js, RTCOST_VEGA_EMBED_JS);
extern "C" const char rtcost_vega_js[], rtcost_vega_js_end[], rtcost_vega_lite_js[], rtcost_vega_lite_js_end[],
    rtcost_vega_embed_js[], rtcost_vega_embed_js_end[];

namespace rtcost::detail {
const ReportScripts* report_scripts() {
    static const ReportScripts s{
        {rtcost_vega_js, static_cast<std::size_t>(rtcost_vega_js_end - rtcost_vega_js)},
        {rtcost_vega_lite_js, static_cast<std::size_t>(rtcost_vega_lite_js_end - rtcost_vega_lite_js)},
        {rtcost_vega_embed_js, static_cast<std::size_t>(rtcost_vega_embed_js_end - rtcost_vega_embed_js)},
        RTCOST_JS_VERSIONS " (" RTCOST_JS_SHA ")"};
    return &s;
}
}  // namespace rtcost::detail
#else
namespace rtcost::detail {
const ReportScripts* report_scripts() { return nullptr; }
}  // namespace rtcost::detail
#endif
