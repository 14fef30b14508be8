#pragma once
// The plotting scripts a report page inlines (embedded at build time).
#include <string_view>

namespace rtcost::detail {

struct ReportScripts {
    std::string_view vega, vega_lite, vega_embed;
    std::string_view versions;  ///< e.g. "vega 6.4.0, vega-lite 6.4.1, vega-embed 7.3.0 (sha256 ...)"
};

/// The scripts, or nullptr when the build did not find them.
const ReportScripts* report_scripts();

}  // namespace rtcost::detail
