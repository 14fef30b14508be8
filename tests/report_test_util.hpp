#pragma once
// Helpers of the heat map and report tests: PNG decoding and a temporary directory (files and
// the CLI come from test_support.hpp).
#include <png.h>
#include <unistd.h>

#include <array>
#include <cstring>
#include <filesystem>
#include <string>

#include "rtcost/whitted.hpp"
#include "test_support.hpp"

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

inline fs::path temp_dir() { return test::temp_dir("report_test"); }

using test::CliRun;
using test::run_cli;
using test::slurp;

}  // namespace rtcost::report_test
