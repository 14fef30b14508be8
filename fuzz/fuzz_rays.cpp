// libFuzzer: ray files. Arbitrary bytes through read_rays; the rays it accepts are traced
// through every hierarchy over a small scene and must give brute force's hits.
#include <memory>
#include <vector>

#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size > 32 * 64) return 0;  // a few dozen rays are enough
    using namespace rtcost;
    static const Scene scene = builtin_scene("balls", 1);
    static const std::vector<std::unique_ptr<Hierarchy>> built = [] {
        std::vector<std::unique_ptr<Hierarchy>> v;
        for (const HierarchyInfo* h : hierarchies())
            if (h->name != "embree") v.push_back(build_hierarchy(scene, h->name));  // Embree: not exact
        return v;
    }();
    static const auto brute = build_hierarchy(scene, "brute");
    const std::string path = fuzz::scratch_file(std::string_view(reinterpret_cast<const char*>(data), size), ".rays");
    std::vector<Ray> rays;
    try {
        rays = read_rays(path);
    } catch (const InputError&) {
    }
    std::remove(path.c_str());
    for (const auto& h : built) fuzz::require_same_hits(*h, *brute, rays, "ray file");
    return 0;
}
