// libFuzzer: the NFF reader and the load-time checks on arbitrary bytes. Bad input must end in
// InputError; anything else (a crash, a sanitizer report, another exception) is a finding.
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    try {
        rtcost::Scene s = rtcost::read_nff(std::string_view(reinterpret_cast<const char*>(data), size), "fuzz.nff");
        rtcost::check_scene(s);
    } catch (const rtcost::InputError&) {
    }
    return 0;
}
