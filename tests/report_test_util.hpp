#pragma once
// Helpers of the heat map and report tests: PNG decoding, running the CLI, files.
#include <png.h>
#include <sys/wait.h>
#include <unistd.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "rtcost/whitted.hpp"

namespace rtcost::report_test {

namespace fs = std::filesystem;

inline Image decode_png(const std::string& bytes) {
    png_image image;
    std::memset(&image, 0, sizeof image);
    image.version = PNG_IMAGE_VERSION;
    Image img;
    if (!png_image_begin_read_from_memory(&image, bytes.data(), bytes.size())) return img;
    image.format = PNG_FORMAT_RGB;
    img.width = static_cast<int>(image.width);
    img.height = static_cast<int>(image.height);
    img.rgb.resize(PNG_IMAGE_SIZE(image));
    if (!png_image_finish_read(&image, nullptr, img.rgb.data(), 0, nullptr)) img = Image{};
    return img;
}

inline std::array<int, 3> pixel(const Image& img, int i, int j) {
    const std::uint8_t* p = &img.rgb[(static_cast<std::size_t>(j) * img.width + i) * 3];
    return {p[0], p[1], p[2]};
}

inline fs::path temp_dir() {
    fs::path d = fs::temp_directory_path() / ("rtcost_report_test_" + std::to_string(::getpid()));
    fs::create_directories(d);
    return d;
}

inline std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

struct CliRun {
    int code;
    std::string out, err;
};

inline CliRun run_cli(const std::string& args) {
    fs::path d = temp_dir();
    std::string cmd = std::string(RTCOST_CLI) + " " + args + " > " + (d / "out").string() + " 2> " +
                      (d / "err").string() + " < /dev/null";
    int status = std::system(cmd.c_str());
    return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, slurp(d / "out"), slurp(d / "err")};
}

}  // namespace rtcost::report_test
