// NFF reader (Eric Haines' Neutral File Format, as written by the SPD generators).
//
// The input is read as a token stream with a line number per token rather than line by line:
// real files put the two cone circles either on one line or on two, and the grammar never
// needs line ends except for the optional light colour.

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "rtcost/io.hpp"

namespace rtcost {
namespace {

struct Token {
    std::string_view text;  // empty at end of input
    int line = 0;
};

class Tokenizer {
public:
    explicit Tokenizer(std::string_view text) : s_(text) {}

    Token next() {
        Token t = peek();
        pos_ = peek_end_;
        line_ = peek_line_end_;
        have_peek_ = false;
        return t;
    }

    Token peek() {
        if (have_peek_) return peeked_;
        std::size_t p = pos_;
        int line = line_;
        for (;;) {
            while (p < s_.size() && is_space(s_[p])) {
                if (s_[p] == '\n') ++line;
                ++p;
            }
            if (p < s_.size() && s_[p] == '#') {  // comment to end of line
                while (p < s_.size() && s_[p] != '\n') ++p;
                continue;
            }
            break;
        }
        std::size_t start = p;
        while (p < s_.size() && !is_space(s_[p]) && s_[p] != '#') ++p;
        peeked_ = {s_.substr(start, p - start), line};
        peek_end_ = p;
        peek_line_end_ = line;
        have_peek_ = true;
        return peeked_;
    }

private:
    static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

    std::string_view s_;
    std::size_t pos_ = 0;
    int line_ = 1;
    bool have_peek_ = false;
    Token peeked_;
    std::size_t peek_end_ = 0;
    int peek_line_end_ = 1;
};

std::string shown(std::string_view t) { return shown_token(t); }

bool is_entity(std::string_view t) {
    return t == "v" || t == "b" || t == "l" || t == "f" || t == "c" || t == "s" || t == "p" || t == "pp";
}

bool looks_numeric(std::string_view t) {
    if (t.empty()) return false;
    char c = t[0];
    return (c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.';
}

class NffParser {
public:
    NffParser(std::string_view text, const std::string& name) : tok_(text), name_(name) {}

    Scene parse() {
        for (;;) {
            Token t = tok_.next();
            if (t.text.empty()) break;
            entity_line_ = t.line;
            const std::string_view k = t.text;
            if (k == "v") viewpoint();
            else if (k == "b") background();
            else if (k == "l") light(t.line);
            else if (k == "f") material();
            else if (k == "c") cone();
            else if (k == "s") sphere();
            else if (k == "p") polygon(false);
            else if (k == "pp") polygon(true);
            else if (looks_numeric(k)) fail(t.line, fmt::format("unexpected number '{}' where an entity belongs", shown(k)));
            else fail(t.line, fmt::format("unknown entity '{}'", shown(k)));
        }
        if (flattened_ > 0)
            scene_.warnings.push_back(fmt::format("{}: {} non-planar polygon{} flattened onto the plane of the first "
                                                  "three vertices (first at line {})",
                                                  name_, flattened_, flattened_ == 1 ? "" : "s", first_flattened_));
        if (scene_.empty()) throw InputError(name_, 0, no_primitives_message(scene_.warnings));
        scene_.finalize();
        return std::move(scene_);
    }

private:
    [[noreturn]] void fail(int line, const std::string& problem) const { throw InputError(name_, line, problem); }

    // Reads one number; `what` names the entity for the end-of-file message.
    float number(const char* what) {
        Token t = tok_.next();
        if (t.text.empty()) fail(entity_line_, fmt::format("file ends inside {}", what));
        num_line_ = t.line;
        return to_float(t);
    }

    float to_float(const Token& t) const {
        std::string_view s = t.text;
        // from_chars rejects a leading '+', which some writers emit.
        if (s.size() > 1 && s[0] == '+' && s[1] != '-' && s[1] != '+') s.remove_prefix(1);
        const char* last = s.data() + s.size();
        float v = 0;
        auto [end, ec] = std::from_chars(s.data(), last, v);
        if (ec == std::errc() && end == last) return v;
        if (ec == std::errc::result_out_of_range && end == last) {
            // Tiny values are fine (they round to a subnormal or zero); too large ones are not.
            double d = 0;
            auto [dend, dec] = std::from_chars(s.data(), last, d);
            if (dec == std::errc() && dend == last && std::isfinite(static_cast<float>(d))) return static_cast<float>(d);
            fail(t.line, fmt::format("number out of range: '{}'", shown(t.text)));
        }
        fail(t.line, fmt::format("expected a number, got '{}'", shown(t.text)));
    }

    long integer(const char* what) {
        Token t = tok_.next();
        if (t.text.empty()) fail(entity_line_, fmt::format("file ends inside {}", what));
        long v = 0;
        auto [end, ec] = std::from_chars(t.text.data(), t.text.data() + t.text.size(), v);
        if (ec != std::errc() || end != t.text.data() + t.text.size())
            fail(t.line, fmt::format("expected an integer, got '{}'", shown(t.text)));
        return v;
    }

    Vec3 vec3(const char* what) {
        Vec3 v;
        v.x = number(what);
        v.y = number(what);
        v.z = number(what);
        return v;
    }

    // Reports at the line of the last number read: the entity's line except for two-line cones.
    void require_finite(bool ok, const char* what) const {
        if (!ok) fail(num_line_, fmt::format("{} is not finite", what));
    }

    // Coordinates beyond kMaxCoordinate are refused where they are read (check_scene would
    // refuse them too, without the line).
    void require_in_range(Vec3 v, float pad, const char* what) const {
        const float m = std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}) + pad;
        if (m > kMaxCoordinate)
            fail(num_line_, fmt::format("{} reaches {:g}, beyond +-{:g}, the largest coordinate the float "
                                        "intersection and box tests handle (scale the scene down)",
                                        what, m, kMaxCoordinate));
    }

    std::uint32_t current_material() {
        if (material_ < 0) {  // primitives before any `f` get a default material
            scene_.materials.push_back(Material{});
            material_ = static_cast<int>(scene_.materials.size()) - 1;
        }
        return static_cast<std::uint32_t>(material_);
    }

    void degenerate(const char* kind, const char* reason) {
        scene_.warnings.push_back(fmt::format("{}:{}: degenerate {} skipped ({})", name_, entity_line_, kind, reason));
    }

    void viewpoint() {
        Camera& cam = scene_.camera;
        bool from = false, at = false, up = false, angle = false, res = false;  // hither defaults to 0
        for (;;) {
            Token t = tok_.peek();
            std::string_view k = t.text;
            if (k != "from" && k != "at" && k != "up" && k != "angle" && k != "hither" && k != "resolution") break;
            tok_.next();
            if (k == "from") {
                cam.from = vec3("viewpoint");
                require_finite(is_finite(cam.from), "viewpoint 'from'");
                require_in_range(cam.from, 0, "viewpoint 'from'");
                from = true;
            } else if (k == "at") {
                cam.at = vec3("viewpoint");
                require_finite(is_finite(cam.at), "viewpoint 'at'");
                require_in_range(cam.at, 0, "viewpoint 'at'");
                at = true;
            } else if (k == "up") {
                cam.up = vec3("viewpoint");
                require_finite(is_finite(cam.up), "viewpoint 'up'");
                up = true;
            } else if (k == "angle") {
                cam.angle = number("viewpoint");
                angle = true;
            } else if (k == "hither") {
                cam.hither = number("viewpoint");
                require_finite(std::isfinite(cam.hither), "hither");
            } else {
                long w = integer("viewpoint"), h = integer("viewpoint");
                if (w <= 0 || h <= 0 || w > 1 << 16 || h > 1 << 16)
                    fail(t.line, fmt::format("bad resolution {} x {} (must be 1..65536)", w, h));
                cam.width = static_cast<int>(w);
                cam.height = static_cast<int>(h);
                res = true;
            }
        }
        const char* missing = !from ? "from" : !at ? "at" : !up ? "up" : !angle ? "angle" : !res ? "resolution" : nullptr;
        if (missing) fail(entity_line_, fmt::format("viewpoint lacks '{}'", missing));
        if (!(cam.angle > 0 && cam.angle < 180)) fail(entity_line_, fmt::format("bad view angle {} (must be in (0, 180))", cam.angle));
        if (cam.hither < 0) fail(entity_line_, "hither is negative");
        Vec3 dir = cam.at - cam.from;
        if (dir == Vec3{0, 0, 0}) fail(entity_line_, "viewpoint 'from' equals 'at'");
        if (cross(dir, cam.up) == Vec3{0, 0, 0}) fail(entity_line_, "'up' is zero or parallel to the view direction");
        scene_.has_camera = true;
    }

    void background() {
        Vec3 c = vec3("background");
        require_finite(is_finite(c), "background colour");
        scene_.background = c;
    }

    void light(int line) {
        Light l;
        l.position = vec3("light");
        require_finite(is_finite(l.position), "light position");
        require_in_range(l.position, 0, "light position");
        // The colour is optional and, when present, on the light's own line.
        Token t = tok_.peek();
        if (t.line == line && looks_numeric(t.text)) {
            l.color = vec3("light");
            require_finite(is_finite(l.color), "light colour");
        }
        scene_.lights.push_back(l);
    }

    void material() {
        Material m;
        m.color = vec3("material");
        m.kd = number("material");
        m.ks = number("material");
        m.shine = number("material");
        m.t = number("material");
        m.ior = number("material");
        require_finite(is_finite(m.color) && std::isfinite(m.kd) && std::isfinite(m.ks) && std::isfinite(m.shine) &&
                           std::isfinite(m.t) && std::isfinite(m.ior),
                       "material");
        scene_.materials.push_back(m);
        material_ = static_cast<int>(scene_.materials.size()) - 1;
    }

    void sphere() {
        Sphere s;
        s.center = vec3("sphere");
        float r = number("sphere");
        require_finite(is_finite(s.center), "sphere centre");
        require_finite(std::isfinite(r), "sphere radius");
        s.radius = std::fabs(r);  // negative: inside visible; hits are geometric either way
        require_in_range(s.center, s.radius, "sphere");
        std::uint32_t m = current_material();
        if (s.radius == 0) return degenerate("sphere", "zero radius");
        scene_.add(s, m);
    }

    void cone() {
        Cone c;
        c.base = vec3("cone");
        float br = number("cone");
        require_finite(is_finite(c.base), "cone base centre");
        require_finite(std::isfinite(br), "cone base radius");
        c.apex = vec3("cone");
        float ar = number("cone");
        require_finite(is_finite(c.apex), "cone apex centre");
        require_finite(std::isfinite(ar), "cone apex radius");
        c.base_radius = std::fabs(br);  // both negative: inside visible; hits are geometric
        c.apex_radius = std::fabs(ar);
        require_in_range(c.base, c.base_radius, "cone");
        require_in_range(c.apex, c.apex_radius, "cone");
        std::uint32_t m = current_material();
        if (c.base == c.apex) return degenerate("cone", "coincident ends");
        if (c.base_radius == 0 && c.apex_radius == 0) return degenerate("cone", "zero radii");
        scene_.add(c, m);
    }

    void polygon(bool patch) {
        const char* kind = patch ? "polygonal patch" : "polygon";
        long n = integer(kind);
        if (n < 3) fail(entity_line_, fmt::format("{} needs at least 3 vertices, got {}", kind, n));
        verts_.clear();
        const int nums = patch ? 6 : 3;
        for (long i = 0; i < n; ++i) {
            float v[6];
            int line = 0;
            for (int k = 0; k < nums; ++k) {
                Token t = tok_.next();
                if (t.text.empty())
                    fail(entity_line_, fmt::format("file ends inside {}: expected {} vertices, got {}", kind, n, i));
                if (is_entity(t.text))
                    fail(t.line, fmt::format("{} ends early: expected {} vertices, got {} before '{}'", kind, n, i, shown(t.text)));
                if (k == 0) line = t.line;
                v[k] = to_float(t);
            }
            Vec3 p{v[0], v[1], v[2]};
            if (!is_finite(p)) fail(line, fmt::format("{} vertex {} is not finite", kind, i + 1));
            num_line_ = line;
            require_in_range(p, 0, kind);
            if (patch && !is_finite(Vec3{v[3], v[4], v[5]}))
                fail(line, fmt::format("{} normal {} is not finite", kind, i + 1));
            verts_.push_back(p);  // patch normals are checked but not kept: hits are geometric
        }
        std::uint32_t m = current_material();
        bool flat = false;
        if (!scene_.add_polygon(verts_, m, nullptr, &flat)) degenerate(kind, degenerate_reason());
        else if (flat && flattened_++ == 0) first_flattened_ = entity_line_;
    }

    // Why add_polygon refused the polygon in verts_; only computed on that rare path.
    const char* degenerate_reason() const {
        Vec3 a = verts_[0];
        Vec3 far = a;
        double best = 0;
        for (Vec3 v : verts_) {
            Vec3 d = v - a;
            double l = dot(d, d);
            if (l > best) best = l, far = v;
        }
        if (best == 0) return "all vertices coincide";
        Vec3 axis = far - a;
        for (Vec3 v : verts_) {
            Vec3 c = cross(axis, v - a);
            // Collinear up to float rounding of the cross product.
            if (dot(c, c) > 1e-10 * best * dot(v - a, v - a)) return "zero area";
        }
        return "collinear vertices";
    }

    Tokenizer tok_;
    const std::string& name_;
    Scene scene_;
    int material_ = -1;
    int entity_line_ = 0;
    int num_line_ = 0;
    int flattened_ = 0, first_flattened_ = 0;
    std::vector<Vec3> verts_;
};

}  // namespace

Scene read_nff(std::string_view text, const std::string& name) {
    // A UTF-8 byte-order mark, as some editors write, is not part of the first entity.
    if (text.starts_with("\xEF\xBB\xBF")) text.remove_prefix(3);
    Scene s = NffParser(text, name).parse();
    s.name = name;
    return s;
}

Scene read_nff_file(const std::string& path) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(path, 0, "no such file");
    if (std::filesystem::is_directory(path, ec)) throw InputError(path, 0, "is a directory");
    // One read of the whole file: the large SPD scenes are ~11 MB.
    std::FILE* f = std::fopen(path.c_str(), "rb");
    if (!f) throw InputError(path, 0, "cannot open file");
    std::string text;
    std::uintmax_t size = std::filesystem::file_size(path, ec);
    if (!ec) text.resize(static_cast<std::size_t>(size));
    std::size_t got = std::fread(text.data(), 1, text.size(), f);
    bool bad = std::ferror(f) || got != text.size();
    std::fclose(f);
    if (bad) throw InputError(path, 0, "read error");
    return read_nff(text, path);
}

}  // namespace rtcost
