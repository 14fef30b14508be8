#include "rtcost/report.hpp"

#include <charconv>
#include <cmath>

#include <fmt/format.h>
#include <unistd.h>

namespace rtcost {

nlohmann::json to_json(const StructureStats& s) {
    nlohmann::json j = {{"N_IN", s.interior}, {"N_V", s.leaves},  {"N_EV", s.empty_leaves}, {"N_OIV", s.references},
                        {"depth", s.depth},   {"bytes", s.bytes}, {"seconds", s.seconds},
                        {"box_lanes", s.box_lanes}};
    if (!s.limits.empty()) j["limits"] = s.limits;
    return j;
}

nlohmann::json param_json(const std::string& value) {
    const char* first = value.data();
    const char* last = first + value.size();
    long long i = 0;
    if (auto [end, ec] = std::from_chars(first, last, i); ec == std::errc() && end == last && !value.empty()) return i;
    double d = 0;
    if (auto [end, ec] = std::from_chars(first, last, d); ec == std::errc() && end == last && !value.empty() &&
                                                          std::isfinite(d))
        return d;
    return value;
}

nlohmann::json params_json(const std::map<std::string, std::string>& values) {
    nlohmann::json j = nlohmann::json::object();
    for (const auto& [k, v] : values) j[k] = param_json(v);
    return j;
}

nlohmann::json per_ray_json(const RayCounters& c) {
    double n = c.rays ? static_cast<double>(c.rays) : 1.0;
    nlohmann::json by_kind = nlohmann::json::object();
    for (int k = 0; k < kPrimKinds; ++k) by_kind[std::string(prim_kind_name(static_cast<PrimKind>(k)))] = c.prim[k] / n;
    int deepest = 0;
    for (int d = 0; d < kMaxStatDepth; ++d)
        if (c.visits[d]) deepest = d + 1;
    nlohmann::json visits = nlohmann::json::array();
    for (int d = 0; d < deepest; ++d) visits.push_back(c.visits[d] / n);
    return {{"N_IT", c.prim_tests() / n},
            {"N_TS", c.steps / n},
            {"N_ETS", c.leaves / n},
            {"N_EETS", c.empty_leaves / n},
            {"box", c.box / n},
            {"plane", c.plane / n},
            {"hop", c.hop / n},
            {"classify", c.classify / n},
            {"prim", c.prim_tests() / n},
            {"prim_by_kind", by_kind},
            {"polygon_edges", c.polygon_edges / n},
            {"visits_by_depth", visits}};
}

nlohmann::json to_json(const Scene& s) {
    auto counts = s.kind_counts();
    nlohmann::json kinds = nlohmann::json::object();
    for (int k = 0; k < kPrimKinds; ++k) kinds[std::string(prim_kind_name(static_cast<PrimKind>(k)))] = counts[k];
    auto v = [](Vec3 p) { return nlohmann::json::array({p.x, p.y, p.z}); };
    nlohmann::json lights = nlohmann::json::array();
    for (const auto& l : s.lights) lights.push_back({{"position", v(l.position)}, {"color", v(l.color)}});
    const Camera& c = s.camera;
    return {{"scene", s.name},
            {"primitives", s.size()},
            {"by_kind", kinds},
            {"bounds", {{"lo", v(s.bounds().lo)}, {"hi", v(s.bounds().hi)}}},
            {"lights", lights},
            {"background", v(s.background)},
            {"materials", s.materials.size()},
            {"camera",
             {{"from", v(c.from)}, {"at", v(c.at)}, {"up", v(c.up)}, {"angle", c.angle}, {"hither", c.hither},
              {"resolution", {c.width, c.height}}, {"from_file", s.has_camera}}},
            {"bytes", s.bytes()},
            {"warnings", s.warnings.size()}};
}

std::string human_bytes(std::uint64_t bytes) {
    const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB"};
    double v = static_cast<double>(bytes);
    int u = 0;
    while (v >= 1024 && u < 4) { v /= 1024; ++u; }
    return u == 0 ? fmt::format("{} B", bytes) : fmt::format("{:.2f} {}", v, units[u]);
}

Progress::Progress(std::string label, std::size_t total, bool quiet)
    : label_(std::move(label)), total_(total), active_(!quiet && ::isatty(STDERR_FILENO)),
      start_(std::chrono::steady_clock::now()), last_(start_) {}

Progress::~Progress() { finish(); }

void Progress::update(std::size_t done) {
    if (!active_) return;
    auto now = std::chrono::steady_clock::now();
    // Stay silent during the first second: short work shows no progress at all.
    if (now - start_ < std::chrono::seconds(1) || now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    double frac = total_ ? static_cast<double>(done) / total_ : 0;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    std::string left = frac > 0 ? fmt::format(", {:.0f} s left", elapsed * (1 - frac) / frac) : std::string();
    std::fprintf(stderr, "\r\033[K%s %5.1f%% (%zu/%zu)%s", label_.c_str(), 100 * frac, done, total_, left.c_str());
    std::fflush(stderr);
    drawn_ = true;
}

void Progress::restart(std::string label, std::size_t total) {
    finish();
    label_ = std::move(label);
    total_ = total;
    start_ = last_ = std::chrono::steady_clock::now();
}

void Progress::note(const std::string& text) {
    if (!active_) return;
    std::fprintf(stderr, "\r\033[K%s ...", text.c_str());
    std::fflush(stderr);
    drawn_ = true;
}

void Progress::finish() {
    if (drawn_) {
        std::fprintf(stderr, "\r\033[K");
        std::fflush(stderr);
        drawn_ = false;
    }
}

}  // namespace rtcost
