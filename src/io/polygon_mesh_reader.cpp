// rtcost reads PLY and OFF itself rather than through assimp. Assimp is lenient where rtcost
// must not be, and fuzzing found it spinning forever (a PLY header without `end_header`, or one
// whose `end_header` ends the file after a garbled line), allocating tens of GB (OFF counts glued
// to the keyword, or without the keyword), clamping or reading beyond a face's vertex indices,
// and loading files with fewer vertices than declared. Both formats are simple enough to read in
// one strict pass; the other formats still go to assimp (mesh_reader.cpp).
#include "polygon_mesh_reader.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <string_view>
#include <vector>

#include <fmt/format.h>

#include "rtcost/error.hpp"

namespace rtcost {
namespace {

std::string lower_extension(const std::string& path) {
    std::string ext = std::filesystem::path(path).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
    return ext;
}

std::string read_whole(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path, 0, "cannot open file");
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r' || c == '\v' || c == '\f'; }

/// Whitespace-separated tokens of `s` from `pos`, with the line of each (for text data).
class Words {
public:
    Words(std::string_view s, std::size_t pos, int line) : s_(s), pos_(pos), line_(line) {}
    /// The next token, or empty at the end.
    std::string_view next() {
        while (pos_ < s_.size() && is_space(s_[pos_])) line_ += s_[pos_++] == '\n';
        std::size_t start = pos_;
        while (pos_ < s_.size() && !is_space(s_[pos_])) ++pos_;
        return s_.substr(start, pos_ - start);
    }
    int line() const { return line_; }

private:
    std::string_view s_;
    std::size_t pos_;
    int line_;
};

bool to_int(std::string_view t, long long& v) {
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    return ec == std::errc() && p == t.data() + t.size();
}

/// A decimal number; out of double's range reads as an infinity (as assimp and strtod do), so
/// that it is reported as a vertex that is not finite rather than as a syntax error.
bool to_double(std::string_view t, double& v) {
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    if (ec == std::errc::result_out_of_range) {
        const bool negative = !t.empty() && t[0] == '-';
        const std::size_t e = t.find_first_of("eE");
        const bool tiny = e != std::string_view::npos && e + 1 < t.size() && t[e + 1] == '-';
        v = tiny ? 0.0 : (negative ? -HUGE_VAL : HUGE_VAL);
        return p == t.data() + t.size();
    }
    return ec == std::errc() && p == t.data() + t.size();
}

std::string shown(std::string_view t) { return shown_token(t); }

/// The vertex index `idx` of face `f`, checked against the vertex count.
std::uint32_t checked_index(long long idx, long long vertices, auto&& fail, int line, long long f, std::string_view text) {
    if (idx < 0 || idx >= vertices)
        fail(line, fmt::format("face {} refers to vertex '{}'; there are {}", f, shown(text), vertices));
    return static_cast<std::uint32_t>(idx);
}

// ---- PLY ----

enum class PlyKind { None, Int, UInt, Float };

struct PlyType {
    PlyKind kind = PlyKind::None;
    int size = 0;
};

PlyType ply_type(std::string_view t) {
    if (t == "char" || t == "int8") return {PlyKind::Int, 1};
    if (t == "uchar" || t == "uint8") return {PlyKind::UInt, 1};
    if (t == "short" || t == "int16") return {PlyKind::Int, 2};
    if (t == "ushort" || t == "uint16") return {PlyKind::UInt, 2};
    if (t == "int" || t == "int32") return {PlyKind::Int, 4};
    if (t == "uint" || t == "uint32") return {PlyKind::UInt, 4};
    if (t == "float" || t == "float32") return {PlyKind::Float, 4};
    if (t == "double" || t == "float64") return {PlyKind::Float, 8};
    return {};
}

struct PlyProperty {
    PlyType type;          // the scalar's type, or the list items' type
    PlyType count;         // the list count's type; None for a scalar
    int coordinate = -1;   // 0, 1, 2 for a vertex's x, y, z
    bool indices = false;  // the face list of vertex indices
};

struct PlyElement {
    std::string name;
    long long count = 0;
    std::vector<PlyProperty> props;
};

struct PlyHeader {
    std::string format;
    std::vector<PlyElement> elements;
    std::size_t data_begin = 0;  // the byte after the end_header line
    int data_line = 0;           // its line
};

PlyHeader read_ply_header(const std::string& bytes, auto&& fail) {
    PlyHeader h;
    int line = 0;
    for (std::size_t p = 0;;) {
        if (p >= bytes.size()) fail(0, "the header has no 'end_header' line");
        const std::size_t nl = bytes.find('\n', p);
        std::string_view l(bytes.data() + p, (nl == std::string::npos ? bytes.size() : nl) - p);
        p = nl == std::string::npos ? bytes.size() : nl + 1;
        ++line;
        std::vector<std::string_view> t;
        for (Words w(l, 0, line);;) {
            std::string_view x = w.next();
            if (x.empty()) break;
            t.push_back(x);
        }
        if (line == 1) {  // the magic, 'ply' in any case (as assimp takes it), alone on its line
            const bool ply = t.size() == 1 && t[0].size() == 3 && std::tolower(t[0][0]) == 'p' &&
                             std::tolower(t[0][1]) == 'l' && std::tolower(t[0][2]) == 'y';
            if (!ply) fail(1, "the file does not begin with a line 'ply'");
            continue;
        }
        // Lines PLY does not define (some exporters write bare text such as "Created by ...")
        // are skipped, as other readers do; the ones it defines must have their arity.
        if (t.empty() || t[0] == "comment" || t[0] == "obj_info") continue;
        if (t[0] == "end_header") {
            if (t.size() != 1) fail(line, "'end_header' must be alone on its line");
            if (nl == std::string::npos) fail(line, "the file ends at 'end_header': no line end and no data after it");
            h.data_begin = p;
            h.data_line = line + 1;
            break;
        }
        if (t[0] == "format") {
            if (t.size() != 3 || !h.format.empty()) fail(line, "expected one line 'format FORMAT VERSION'");
            h.format = std::string(t[1]);
            if (h.format != "ascii" && h.format != "binary_little_endian" && h.format != "binary_big_endian")
                fail(line, fmt::format("unknown format '{}'", shown(h.format)));
        } else if (t[0] == "element") {
            PlyElement e;
            if (t.size() != 3) fail(line, "expected 'element NAME COUNT'");
            e.name = std::string(t[1]);
            if (!to_int(t[2], e.count) || e.count < 0)
                fail(line, fmt::format("bad count for element '{}'", shown(e.name)));
            h.elements.push_back(std::move(e));
        } else if (t[0] == "property") {
            if (h.elements.empty()) fail(line, "property before any element");
            PlyElement& e = h.elements.back();
            PlyProperty pr;
            std::string_view name;
            if (t.size() == 5 && t[1] == "list") {
                pr.count = ply_type(t[2]);
                pr.type = ply_type(t[3]);
                if (pr.count.kind == PlyKind::None || pr.count.kind == PlyKind::Float || pr.type.kind == PlyKind::None)
                    fail(line, "bad list property types");
                name = t[4];
                pr.indices = e.name == "face" && (name == "vertex_indices" || name == "vertex_index");
                if (pr.indices && pr.type.kind == PlyKind::Float) fail(line, "vertex indices must be integers");
            } else if (t.size() == 3) {
                pr.type = ply_type(t[1]);
                if (pr.type.kind == PlyKind::None) fail(line, fmt::format("unknown property type '{}'", shown(t[1])));
                name = t[2];
                if (e.name == "vertex" && name.size() == 1 && name[0] >= 'x' && name[0] <= 'z') pr.coordinate = name[0] - 'x';
            } else {
                fail(line, "expected 'property TYPE NAME' or 'property list TYPE TYPE NAME'");
            }
            e.props.push_back(pr);
        }
    }
    if (h.format.empty()) fail(0, "the header has no 'format' line");
    return h;
}

/// Reads a binary value of `type` at `pos` (advancing it); false at the end of the data.
bool read_binary(const std::string& bytes, std::size_t& pos, PlyType type, bool little, double& out) {
    if (bytes.size() - pos < static_cast<std::size_t>(type.size)) return false;
    std::uint64_t v = 0;
    for (int b = 0; b < type.size; ++b) {
        const auto byte = static_cast<unsigned char>(bytes[pos + (little ? b : type.size - 1 - b)]);
        v |= std::uint64_t{byte} << (8 * b);
    }
    pos += type.size;
    if (type.kind == PlyKind::Float) {
        out = type.size == 4 ? double(std::bit_cast<float>(static_cast<std::uint32_t>(v))) : std::bit_cast<double>(v);
    } else if (type.kind == PlyKind::Int) {
        const int shift = 64 - 8 * type.size;  // sign-extend
        out = double(static_cast<std::int64_t>(v << shift) >> shift);
    } else {
        out = double(v);
    }
    return true;
}

PolygonMesh read_ply(const std::string& path, const std::string& bytes) {
    auto fail = [&](int line, const std::string& what) { throw InputError(path, line, "PLY: " + what); };
    const PlyHeader h = read_ply_header(bytes, fail);
    const PlyElement* vertex_element = nullptr;
    for (const auto& e : h.elements)
        if (e.name == "vertex" && !vertex_element) vertex_element = &e;
    long long vertices = vertex_element ? vertex_element->count : 0;
    if (vertex_element) {
        bool has[3] = {false, false, false};
        for (const auto& p : vertex_element->props)
            if (p.coordinate >= 0) has[p.coordinate] = true;
        if (!has[0] || !has[1] || !has[2]) fail(0, "the vertex element has no properties x, y and z");
    }
    if (vertices > std::numeric_limits<std::int32_t>::max()) fail(0, fmt::format("{} vertices: more than 2^31", vertices));

    PolygonMesh mesh;
    const bool ascii = h.format == "ascii";
    const bool little = h.format == "binary_little_endian";
    Words words(bytes, h.data_begin, h.data_line);
    std::size_t pos = h.data_begin;
    for (const auto& e : h.elements) {
        if (e.props.empty()) continue;  // no data, whatever its count
        const bool is_vertex = &e == vertex_element;
        for (long long i = 0; i < e.count; ++i) {
            Vec3 v{0, 0, 0};
            for (const PlyProperty& p : e.props) {
                auto ends = [&] { fail(0, fmt::format("file ends at {} {} of {} declared", e.name, i, e.count)); };
                // One value: its text (ASCII) for messages, its value, the line it is on.
                std::string_view text;
                double value = 0;
                auto next = [&](PlyType type) {
                    if (ascii) {
                        text = words.next();
                        if (text.empty()) ends();
                        if (!to_double(text, value)) fail(words.line(), fmt::format("'{}' is not a number", shown(text)));
                        if (type.kind != PlyKind::Float && value != std::floor(value))
                            fail(words.line(), fmt::format("'{}' is not an integer", shown(text)));
                    } else if (!read_binary(bytes, pos, type, little, value)) {
                        ends();
                    }
                };
                long long n = 1;
                if (p.count.kind != PlyKind::None) {
                    next(p.count);
                    if (value < 0 || value > 1e9) fail(words.line(), fmt::format("bad list length '{}'", ascii ? shown(text) : fmt::format("{}", value)));
                    n = static_cast<long long>(value);
                    // Binary: the whole list must be in the file before it is read.
                    if (!ascii && static_cast<double>(bytes.size() - pos) < double(n) * p.type.size) ends();
                    if (p.indices) mesh.face_sizes.push_back(static_cast<std::uint32_t>(n));
                }
                for (long long k = 0; k < n; ++k) {
                    next(p.type);
                    if (p.indices) {
                        const long long idx = value >= -1e18 && value <= 1e18 ? static_cast<long long>(value) : -1;
                        const std::string t = ascii ? std::string(text) : fmt::format("{}", value);
                        mesh.indices.push_back(checked_index(idx, vertices, fail, ascii ? words.line() : 0, i, t));
                    } else if (is_vertex && p.coordinate >= 0) {
                        v[p.coordinate] = static_cast<float>(value);
                    }
                }
            }
            if (is_vertex) {
                if (!is_finite(v)) fail(ascii ? words.line() : 0, fmt::format("vertex {} is not finite", i));
                mesh.vertices.push_back(v);
            }
        }
    }
    return mesh;
}

// ---- OFF ----

PolygonMesh read_off(const std::string& path, const std::string& bytes) {
    auto fail = [&](int line, const std::string& what) { throw InputError(path, line, "OFF: " + what); };
    // Lines without comments and blank lines, with their line numbers.
    std::vector<std::pair<std::string_view, int>> lines;
    int number = 0;
    for (std::size_t p = 0; p <= bytes.size();) {
        std::size_t nl = bytes.find('\n', p);
        if (nl == std::string::npos) nl = bytes.size();
        ++number;
        std::string_view l(bytes.data() + p, nl - p);
        if (auto h = l.find('#'); h != std::string_view::npos) l = l.substr(0, h);
        while (!l.empty() && is_space(l.front())) l.remove_prefix(1);
        while (!l.empty() && is_space(l.back())) l.remove_suffix(1);
        if (!l.empty()) lines.emplace_back(l, number);
        p = nl + 1;
    }
    if (lines.empty()) fail(0, "empty file");
    std::string_view head = lines[0].first;
    std::size_t at = 1;
    // The keyword, [ST][C][N][4][n]OFF, is optional (without it the first line is the counts),
    // and the counts may follow it on its line, with or without a space.
    const std::size_t off = head.find("OFF");
    std::string_view counts = head;
    if (off != std::string_view::npos && head.substr(0, off).find_first_not_of("STCN4n") == std::string_view::npos) {
        if (head.substr(0, off).find_first_of("4n") != std::string_view::npos)
            fail(lines[0].second, "4OFF and nOFF (other than 3 coordinates) are not supported");
        counts = head.substr(off + 3);
    } else if (head.find_first_not_of("0123456789") == 0) {
        fail(lines[0].second, "the first line is neither an OFF keyword nor the vertex, face and edge counts");
    }
    while (!counts.empty() && is_space(counts.front())) counts.remove_prefix(1);
    if (counts.substr(0, 6) == "BINARY") fail(lines[0].second, "binary OFF is not supported; write it as text");
    if (counts.empty()) {
        if (at >= lines.size()) fail(lines[0].second, "no vertex and face counts");
        counts = lines[at++].first;
    }
    const int counts_line = lines[at - 1].second;
    Words cw(counts, 0, 0);
    long long nv = 0, nf = 0, ne = 0;
    if (!to_int(cw.next(), nv) || !to_int(cw.next(), nf) || nv < 0 || nf < 0) fail(counts_line, "bad vertex and face counts");
    // The edge count is unused, but required (a reader taking two would misread the next line).
    if (!to_int(cw.next(), ne) || ne < 0) fail(counts_line, "the counts line needs three numbers: vertices, faces and edges");
    if (!cw.next().empty()) fail(counts_line, "more than three numbers on the counts line");
    if (static_cast<long long>(lines.size() - at) < nv)
        fail(0, fmt::format("declares {} vertices, the file has {} lines after the counts", nv, lines.size() - at));
    PolygonMesh mesh;
    mesh.vertices.reserve(static_cast<std::size_t>(nv));
    for (long long v = 0; v < nv; ++v) {
        const auto [l, line] = lines[at++];
        Words vw(l, 0, line);
        Vec3 p{0, 0, 0};
        for (int a = 0; a < 3; ++a) {
            const std::string_view t = vw.next();
            double x = 0;
            if (t.empty()) fail(line, fmt::format("vertex {} has fewer than 3 coordinates", v));
            if (!to_double(t, x)) fail(line, fmt::format("vertex {}: '{}' is not a number", v, shown(t)));
            p[a] = static_cast<float>(x);
        }
        if (!is_finite(p)) fail(line, fmt::format("vertex {} is not finite", v));
        mesh.vertices.push_back(p);  // what follows (colour, normal, texture coordinates) is unused
    }
    if (static_cast<long long>(lines.size() - at) < nf)
        fail(0, fmt::format("declares {} faces, the file has {} lines after the vertices", nf, lines.size() - at));
    for (long long f = 0; f < nf; ++f) {
        const auto [l, line] = lines[at++];
        Words fw(l, 0, line);
        long long k = 0;
        if (!to_int(fw.next(), k) || k < 0) fail(line, fmt::format("face {}: bad vertex count", f));
        if (k > static_cast<long long>(l.size())) fail(line, fmt::format("face {}: {} vertices declared, fewer given", f, k));
        mesh.face_sizes.push_back(static_cast<std::uint32_t>(k));
        for (long long i = 0; i < k; ++i) {
            const std::string_view t = fw.next();
            long long idx = 0;
            if (t.empty()) fail(line, fmt::format("face {}: {} vertices declared, {} given", f, k, i));
            if (!to_int(t, idx)) idx = -1;
            mesh.indices.push_back(checked_index(idx, nv, fail, line, f, t));
        }  // a colour after the indices is unused
    }
    return mesh;
}

}  // namespace

bool is_polygon_mesh_file(const std::string& path) {
    const std::string ext = lower_extension(path);
    return ext == ".ply" || ext == ".off";
}

PolygonMesh read_polygon_mesh(const std::string& path) {
    const std::string bytes = read_whole(path);
    return lower_extension(path) == ".ply" ? read_ply(path, bytes) : read_off(path, bytes);
}

}  // namespace rtcost
