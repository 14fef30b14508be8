// Scene loading by spec: builtin:NAME[:LEVEL], an .nff file, or any mesh assimp reads.

#include <algorithm>
#include <cctype>
#include <charconv>
#include <filesystem>
#include <string>

#include "rtcost/io.hpp"

namespace rtcost {
namespace {

constexpr std::string_view kBuiltinPrefix = "builtin:";

Scene load_builtin(std::string_view spec) {
    std::string_view rest = spec.substr(kBuiltinPrefix.size());
    std::string_view name = rest;
    int level = -1;
    if (auto colon = rest.find(':'); colon != std::string_view::npos) {
        name = rest.substr(0, colon);
        std::string_view text = rest.substr(colon + 1);
        auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), level);
        if (text.empty() || ec != std::errc() || end != text.data() + text.size() || level < 0)
            throw InputError(std::string(spec), 0, "bad level '" + std::string(text) + "' (expected a non-negative integer)");
    }
    return builtin_scene(name, level);
}

bool has_nff_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext == ".nff";
}

}  // namespace

Scene load_scene(std::string_view spec) {
    Scene s;
    if (spec.starts_with(kBuiltinPrefix)) {
        s = load_builtin(spec);
    } else {
        std::string path(spec);
        std::error_code ec;
        if (path.empty()) throw InputError("scene", 0, "empty scene path");
        if (!std::filesystem::exists(path, ec)) throw InputError(path, 0, "no such file");
        s = has_nff_extension(path) ? read_nff_file(path) : read_mesh(path);
    }
    s.name = std::string(spec);
    check_scene(s);
    return s;
}

}  // namespace rtcost
