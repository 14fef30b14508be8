// libFuzzer: the --set parameters of every hierarchy. The first byte picks the hierarchy, the
// rest is newline-separated key=value assignments. A bad assignment must end in InputError; a
// good one must build, and trace brute force's hits on a small scene.
//
// Values that ask for a large build on purpose (rc5d max_bytes above 64 MiB, grids over 2^20
// cells) are skipped: they are bounded, but by more memory and time than a fuzzing run affords.
#include <charconv>
#include <vector>

#include "fuzz_support.hpp"

namespace {

bool asks_for_a_big_build(const std::string& a) {
    auto value = [&](const char* key, long long& v) {
        const std::string k = std::string(key) + "=";
        if (a.rfind(k, 0) != 0) return false;
        auto [p, ec] = std::from_chars(a.data() + k.size(), a.data() + a.size(), v);
        return ec == std::errc();
    };
    long long v = 0;
    if (value("max_bytes", v) && v > (1ll << 26)) return true;
    if (value("density", v) && v > 64) return true;
    if (a.rfind("res=", 0) == 0) {
        long long r[3] = {1, 1, 1};
        const char* p = a.data() + 4;
        const char* end = a.data() + a.size();
        for (int i = 0; i < 3 && p < end; ++i) {
            auto [q, ec] = std::from_chars(p, end, r[i]);
            if (ec != std::errc()) return false;
            p = q + 1;
        }
        // In doubles: the product of three parsed values overflows long long.
        return static_cast<double>(r[0]) * static_cast<double>(r[1]) * static_cast<double>(r[2]) >
               static_cast<double>(1ll << 20);
    }
    return false;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    using namespace rtcost;
    if (size < 1 || size > 512) return 0;
    static const Scene scene = builtin_scene("balls", 1);
    static const std::vector<Ray> rays = random_rays(scene.bounds(), 48, 5);
    static const auto brute = build_hierarchy(scene, "brute");
    const auto& all = hierarchies();
    const HierarchyInfo* info = all[data[0] % all.size()];
    std::vector<std::string> set;
    std::string cur;
    for (std::size_t i = 1; i <= size; ++i) {
        if (i == size || data[i] == '\n') {
            if (asks_for_a_big_build(cur)) return 0;
            set.push_back(cur);
            cur.clear();
        } else {
            cur.push_back(static_cast<char>(data[i]));
        }
    }
    std::unique_ptr<Hierarchy> h;
    try {
        h = build_hierarchy(scene, info->name, set);
    } catch (const InputError&) {
        return 0;
    }
    if (info->name != "embree") fuzz::require_same_hits(*h, *brute, rays, "params");
    return 0;
}
