// Whitted shading to an image, and PNG output through libpng.
#include <png.h>

#include <algorithm>
#include <cmath>

#include "rays/whitted_tracer.hpp"
#include "rtcost/error.hpp"
#include "rtcost/io.hpp"

namespace rtcost {

Image render(const Hierarchy& h, const RenderOptions& opt) {
    const Scene& scene = h.scene();
    const CameraRay eye(scene.camera, opt.width, opt.height);  // as whitted_tree's
    detail::WhittedTracer tracer(h, opt.max_depth);
    Image img;
    img.width = opt.width;
    img.height = opt.height;
    img.rgb.assign(static_cast<std::size_t>(opt.width) * opt.height * 3, 0);
    auto to_byte = [](float v) {
        return static_cast<std::uint8_t>(std::lround(255.0f * std::clamp(std::isfinite(v) ? v : 0.0f, 0.0f, 1.0f)));
    };
    detail::run_rows(
        opt.height, opt.threads,
        [&](int j) {
            for (int i = 0; i < opt.width; ++i) {
                std::size_t pixel = static_cast<std::size_t>(j) * opt.width + i;
                Vec3 c = tracer.trace(eye(pixel), RayKind::Eye, 1, nullptr);
                img.rgb[pixel * 3 + 0] = to_byte(c.x);
                img.rgb[pixel * 3 + 1] = to_byte(c.y);
                img.rgb[pixel * 3 + 2] = to_byte(c.z);
            }
        },
        opt.progress);
    return img;
}

namespace {
void append_bytes(png_structp png, png_bytep data, png_size_t n) {
    static_cast<std::string*>(png_get_io_ptr(png))->append(reinterpret_cast<const char*>(data), n);
}
void no_flush(png_structp) {}
}  // namespace

std::string encode_png(const Image& img) {
    if (img.width <= 0 || img.height <= 0 || img.rgb.size() != static_cast<std::size_t>(img.width) * img.height * 3)
        throw InputError("png", 0, "image has no pixels or the wrong number of bytes");
    std::string out;
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
    if (!png) throw InputError("png", 0, "cannot create the PNG writer");
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, nullptr);
        throw InputError("png", 0, "cannot create the PNG writer");
    }
    std::vector<png_bytep> rows(static_cast<std::size_t>(img.height));
    for (int j = 0; j < img.height; ++j)
        rows[j] = const_cast<png_bytep>(img.rgb.data() + static_cast<std::size_t>(j) * img.width * 3);
    // libpng reports errors by longjmp; nothing with a destructor is created past this point.
    if (setjmp(png_jmpbuf(png))) {
        png_destroy_write_struct(&png, &info);
        throw InputError("png", 0, "PNG encoding failed");
    }
    png_set_write_fn(png, &out, append_bytes, no_flush);
    png_set_IHDR(png, info, static_cast<png_uint_32>(img.width), static_cast<png_uint_32>(img.height), 8,
                 PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 9);
    png_set_rows(png, info, rows.data());
    png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
    png_destroy_write_struct(&png, &info);
    return out;
}

void write_png(const std::string& path, const Image& img) { write_file_atomic(path, encode_png(img)); }

}  // namespace rtcost
