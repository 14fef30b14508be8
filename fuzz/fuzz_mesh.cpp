// libFuzzer: the mesh path (read_mesh: rtcost's PLY and OFF checks, then assimp) on arbitrary
// bytes. The first byte picks the format; the rest is the file.
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    if (size < 1) return 0;
    static const char* kExt[] = {".ply", ".off", ".obj", ".stl"};
    const std::string path =
        rtcost::fuzz::scratch_file(std::string_view(reinterpret_cast<const char*>(data) + 1, size - 1), kExt[data[0] % 4]);
    try {
        rtcost::Scene s = rtcost::read_mesh(path);
        rtcost::check_scene(s);
    } catch (const rtcost::InputError&) {
    }
    std::remove(path.c_str());
    return 0;
}
