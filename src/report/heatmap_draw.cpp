// Drawing a heat map: the values in viridis, a colour bar with ticks, units and a title.
//
// Text needs a font and a rasteriser. cairo (libcairo2-dev) draws it through fontconfig and
// FreeType with a Debian font (fonts-dejavu-core's DejaVu Sans): legible, antialiased labels in
// any size, which hand-drawn glyphs would not give and would be code to keep for no gain.
#include <cairo.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "report/colormap.hpp"
#include "rtcost/error.hpp"
#include "rtcost/heatmap.hpp"

namespace rtcost {
namespace {

constexpr double kMargin = 10, kBarWidth = 18, kGap = 14, kFont = 12, kLine = 16;
constexpr int kMinMap = 192;  // smaller maps are enlarged (nearest pixel) so that labels fit

struct SurfaceDeleter {
    void operator()(cairo_surface_t* s) const { cairo_surface_destroy(s); }
};
struct ContextDeleter {
    void operator()(cairo_t* c) const { cairo_destroy(c); }
};
using Surface = std::unique_ptr<cairo_surface_t, SurfaceDeleter>;
using Context = std::unique_ptr<cairo_t, ContextDeleter>;

// A round step for about `n` intervals over [0, top]: 1, 2 or 5 times a power of ten.
double nice_step(double top, int n) {
    double raw = top / n;
    double p = std::pow(10.0, std::floor(std::log10(raw)));
    for (double m : {1.0, 2.0, 5.0})
        if (m * p >= raw) return m * p;
    return 10 * p;
}

std::string label(double v) { return fmt::format("{:.6g}", v); }

void set_font(cairo_t* cr, double size) {
    cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr, size);
}

double text_width(cairo_t* cr, const std::string& s) {
    cairo_text_extents_t e;
    cairo_text_extents(cr, s.c_str(), &e);
    return e.x_advance;
}

// Where `v` falls on the colour scale, 0 to 1.
struct Scale {
    double top;
    bool log;
    double operator()(double v) const {
        if (!(top > 0)) return 0;
        return log ? std::log1p(std::max(v, 0.0)) / std::log1p(top) : v / top;
    }
};

// Tick values: round steps on a linear scale; 0 and 1, 2 and 5 times powers of ten on a log one.
std::vector<double> ticks_of(const Scale& s) {
    std::vector<double> t;
    if (!(s.top > 0)) return {0};
    if (!s.log) {
        const double step = nice_step(s.top, 4);
        for (double v = 0; v <= s.top * (1 + 1e-9); v += step) t.push_back(v);
        return t;
    }
    t.push_back(0);
    std::vector<double> mult = {1.0};
    if (s.top < 100) mult = {1.0, 2.0, 5.0};
    for (double p = 1; p <= s.top * (1 + 1e-9); p *= 10)
        for (double m : mult)
            if (m * p <= s.top * (1 + 1e-9)) t.push_back(m * p);
    return t;
}

// cairo's largest image side: a larger one fails, and its null pixel data must not be written.
constexpr int kMaxSide = 32767;

// A cairo image of w x h pixels, or InputError where cairo cannot make it.
Surface image_surface(int w, int h) {
    Surface s(cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h));
    if (cairo_surface_status(s.get()) != CAIRO_STATUS_SUCCESS)
        throw InputError("heatmap", 0,
                         fmt::format("cannot draw an image of {}x{} pixels ({})", w, h,
                                     cairo_status_to_string(cairo_surface_status(s.get()))));
    return s;
}

// The values as a cairo image, one pixel each.
Surface map_surface(const std::vector<double>& values, int width, int height, const Scale& scale) {
    Surface s = image_surface(width, height);
    cairo_surface_flush(s.get());
    unsigned char* data = cairo_image_surface_get_data(s.get());
    const int stride = cairo_image_surface_get_stride(s.get());
    for (int j = 0; j < height; ++j) {
        auto* row = reinterpret_cast<std::uint32_t*>(data + static_cast<std::size_t>(j) * stride);
        for (int i = 0; i < width; ++i) {
            auto c = viridis(scale(values[static_cast<std::size_t>(j) * width + i]));
            row[i] = (std::uint32_t{c[0]} << 16) | (std::uint32_t{c[1]} << 8) | c[2];
        }
    }
    cairo_surface_mark_dirty(s.get());
    return s;
}

}  // namespace

Image draw_heatmap(const std::vector<double>& values, int width, int height, const HeatStyle& style) {
    if (width <= 0 || height <= 0 || values.size() != static_cast<std::size_t>(width) * height)
        throw InputError("heatmap", 0, "the values do not fill a width x height image");
    const HeatSummary sum = summarize(values, style.scale_max);
    const double top = sum.scale_max;
    const int zoom = std::max(1, (kMinMap + std::max(width, height) - 1) / std::max(width, height));
    const double mw = width * zoom, mh = height * zoom;

    // Tick labels and text lines, measured first to size the image.
    const Scale scale{top, style.log};
    const std::vector<double> ticks = ticks_of(scale);
    std::vector<std::string> lines = {style.title, style.log ? style.units + ", log scale" : style.units,
                                      fmt::format("min {:.4g}  mean {:.4g}  max {:.4g}", sum.min, sum.mean, sum.max)};
    if (sum.clipped)
        lines.push_back(fmt::format("scale top {}: {} pixels above it drawn in its colour", label(top), sum.clipped));
    Surface probe = image_surface(1, 1);
    Context pc(cairo_create(probe.get()));
    set_font(pc.get(), kFont);
    double label_w = 0, lines_w = 0;
    for (double t : ticks) label_w = std::max(label_w, text_width(pc.get(), label(t)));
    for (const auto& l : lines) lines_w = std::max(lines_w, text_width(pc.get(), l));
    const double bar_x = kMargin + mw + kGap;
    const double w = std::ceil(std::max(bar_x + kBarWidth + 6 + label_w, kMargin + lines_w) + kMargin);
    const double h = std::ceil(kMargin + mh + kMargin + kLine * lines.size() + kMargin / 2);

    if (w > kMaxSide || h > kMaxSide)
        throw InputError("heatmap", 0,
                         fmt::format("a heat map of {}x{} pixels is {:.0f}x{:.0f} with its legend, beyond the {} pixels "
                                     "a side an image can have: choose a smaller size",
                                     width, height, w, h, kMaxSide));
    Surface surf = image_surface(static_cast<int>(w), static_cast<int>(h));
    Context cr(cairo_create(surf.get()));
    cairo_set_source_rgb(cr.get(), 1, 1, 1);
    cairo_paint(cr.get());

    // The map, enlarged by whole pixels without smoothing.
    Surface map = map_surface(values, width, height, scale);
    cairo_save(cr.get());
    cairo_translate(cr.get(), kMargin, kMargin);
    cairo_scale(cr.get(), zoom, zoom);
    cairo_set_source_surface(cr.get(), map.get(), 0, 0);
    cairo_pattern_set_filter(cairo_get_source(cr.get()), CAIRO_FILTER_NEAREST);
    cairo_paint(cr.get());
    cairo_restore(cr.get());

    // The colour bar: bottom 0, top `top`, one band per device pixel.
    for (int y = 0; y < static_cast<int>(mh); ++y) {
        auto c = viridis(1.0 - (y + 0.5) / mh);
        cairo_set_source_rgb(cr.get(), c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
        cairo_rectangle(cr.get(), bar_x, kMargin + y, kBarWidth, 1);
        cairo_fill(cr.get());
    }
    cairo_set_source_rgb(cr.get(), 0.2, 0.2, 0.2);
    cairo_set_line_width(cr.get(), 1);
    cairo_rectangle(cr.get(), bar_x + 0.5, kMargin + 0.5, kBarWidth - 1, mh - 1);
    cairo_stroke(cr.get());
    set_font(cr.get(), kFont);
    for (double t : ticks) {
        double y = kMargin + mh * (1 - scale(t));
        cairo_move_to(cr.get(), bar_x + kBarWidth, std::round(y) + 0.5);
        cairo_line_to(cr.get(), bar_x + kBarWidth + 4, std::round(y) + 0.5);
        cairo_stroke(cr.get());
        cairo_move_to(cr.get(), bar_x + kBarWidth + 6, std::clamp(y + kFont / 3, kMargin + kFont * 0.8, kMargin + mh + kFont / 3));
        cairo_show_text(cr.get(), label(t).c_str());
    }
    for (std::size_t l = 0; l < lines.size(); ++l) {
        cairo_move_to(cr.get(), kMargin, kMargin + mh + kMargin + kLine * l + kFont);
        cairo_show_text(cr.get(), lines[l].c_str());
    }
    cairo_surface_flush(surf.get());

    Image img;
    img.width = static_cast<int>(w);
    img.height = static_cast<int>(h);
    img.rgb.resize(static_cast<std::size_t>(img.width) * img.height * 3);
    const unsigned char* data = cairo_image_surface_get_data(surf.get());
    const int stride = cairo_image_surface_get_stride(surf.get());
    for (int j = 0; j < img.height; ++j) {
        const auto* row = reinterpret_cast<const std::uint32_t*>(data + static_cast<std::size_t>(j) * stride);
        for (int i = 0; i < img.width; ++i) {
            std::uint8_t* o = &img.rgb[(static_cast<std::size_t>(j) * img.width + i) * 3];
            o[0] = static_cast<std::uint8_t>(row[i] >> 16);
            o[1] = static_cast<std::uint8_t>(row[i] >> 8);
            o[2] = static_cast<std::uint8_t>(row[i]);
        }
    }
    return img;
}

}  // namespace rtcost
