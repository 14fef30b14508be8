// Checks of PLY and OFF files before assimp reads them. Assimp is lenient where rtcost must not
// be: a PLY header without `end_header` makes it spin forever, a face index beyond the vertices
// is clamped (OFF) or read from beyond them, and a vertex count larger than the vertices given
// loads silently. These files are simple enough to walk once here; other formats go to assimp
// unchecked.
#include "mesh_precheck.hpp"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
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

/// Whitespace-separated tokens of `s` from `pos`, with the line of each (for ASCII data).
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
    /// Skips the rest of the current line.
    void skip_line() {
        while (pos_ < s_.size() && s_[pos_] != '\n') ++pos_;
    }
    int line() const { return line_; }
    bool at_end() const { return pos_ >= s_.size(); }

private:
    std::string_view s_;
    std::size_t pos_;
    int line_;
};

bool to_int(std::string_view t, long long& v) {
    auto [p, ec] = std::from_chars(t.data(), t.data() + t.size(), v);
    return ec == std::errc() && p == t.data() + t.size();
}

std::string shown(std::string_view t) {
    return t.size() <= 40 ? std::string(t) : std::string(t.substr(0, 40)) + "...";
}

// ---- PLY ----

struct PlyProperty {
    int size = 0;        // scalar size in bytes, or the list's item size
    int count_size = 0;  // list count size; 0 for a scalar
    bool is_float = false;
    bool index = false;  // the face list of vertex indices
};
struct PlyElement {
    std::string name;
    long long count = 0;
    std::vector<PlyProperty> props;
};

int ply_type_size(std::string_view t, bool& is_float) {
    is_float = t == "float" || t == "float32" || t == "double" || t == "float64";
    if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
    if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
    if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
    if (t == "double" || t == "float64") return 8;
    return 0;
}

void check_ply(const std::string& path, const std::string& bytes) {
    auto fail = [&](int line, const std::string& what) { throw InputError(path, line, "PLY: " + what); };
    // The header is text ending in a line `end_header`; without one assimp never returns.
    std::size_t end = std::string::npos;
    for (std::size_t p = 0; p < bytes.size();) {
        std::size_t nl = bytes.find('\n', p);
        std::string_view l(bytes.data() + p, (nl == std::string::npos ? bytes.size() : nl) - p);
        while (!l.empty() && (l.back() == '\r' || l.back() == ' ')) l.remove_suffix(1);
        if (l == "end_header") {
            // Assimp spins forever on some headers whose `end_header` ends the file without a
            // line end (found by fuzzing); a file that ends there has no data anyway.
            if (nl == std::string::npos) fail(0, "the file ends at 'end_header': no line end and no data after it");
            end = nl + 1;
            break;
        }
        if (nl == std::string::npos) break;
        p = nl + 1;
    }
    if (end == std::string::npos) fail(0, "the header has no 'end_header' line");

    // The header, line by line: the lines PLY defines must have their exact arity; other lines
    // (some exporters write bare text such as "Created by ...") are skipped, as assimp does.
    std::vector<PlyElement> elements;
    std::string format;
    int line = 0, data_line = 0;
    for (std::size_t p = 0; p < end;) {
        std::size_t nl = std::min(bytes.find('\n', p), end);
        std::string_view l(bytes.data() + p, nl - p);
        p = nl + 1;
        ++line;
        std::vector<std::string_view> t;
        for (Words w(l, 0, line); !w.at_end();) {
            std::string_view x = w.next();
            if (!x.empty()) t.push_back(x);
        }
        if (line == 1) {  // the magic, 'ply' in any case, alone on its line
            if (t.size() != 1) fail(line, "the first line must be 'ply' alone");
            continue;
        }
        if (t.empty()) continue;
        const std::string_view key = t[0];
        if (key == "comment" || key == "obj_info") continue;
        if (key == "end_header") {
            if (t.size() != 1) fail(line, "'end_header' must be alone on its line");
            data_line = line + 1;
            break;
        }
        if (key == "format") {
            if (t.size() != 3 || !format.empty()) fail(line, "expected one 'format FORMAT VERSION' line");
            format = std::string(t[1]);
            if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
                fail(line, fmt::format("unknown format '{}'", shown(format)));
        } else if (key == "element") {
            PlyElement e;
            if (t.size() != 3) fail(line, "expected 'element NAME COUNT'");
            e.name = std::string(t[1]);
            if (!to_int(t[2], e.count) || e.count < 0) fail(line, fmt::format("bad count for element '{}'", shown(e.name)));
            elements.push_back(std::move(e));
        } else if (key == "property") {
            if (elements.empty()) fail(line, "property before any element");
            PlyProperty pr;
            if (t.size() == 5 && t[1] == "list") {
                bool f = false;
                pr.count_size = ply_type_size(t[2], f);
                pr.size = ply_type_size(t[3], pr.is_float);
                pr.index = elements.back().name == "face" && (t[4] == "vertex_indices" || t[4] == "vertex_index");
                if (pr.count_size == 0 || pr.size == 0 || f) fail(line, "bad list property types");
            } else if (t.size() == 3) {
                pr.size = ply_type_size(t[1], pr.is_float);
                if (pr.size == 0) fail(line, fmt::format("unknown property type '{}'", shown(t[1])));
            } else {
                fail(line, "expected 'property TYPE NAME' or 'property list TYPE TYPE NAME'");
            }
            elements.back().props.push_back(pr);
        }
    }
    if (format.empty()) fail(0, "the header has no 'format' line");
    long long vertices = 0;
    for (const auto& e : elements)
        if (e.name == "vertex") vertices = e.count;

    if (format == "ascii") {
        Words d(bytes, end, data_line);
        for (const auto& e : elements) {
            for (long long i = 0; i < e.count; ++i) {
                for (const PlyProperty& p : e.props) {
                    long long n = 1;
                    if (p.count_size) {
                        std::string_view t = d.next();
                        if (t.empty()) fail(0, fmt::format("file ends at {} {} of {} declared", e.name, i, e.count));
                        if (!to_int(t, n) || n < 0) fail(d.line(), fmt::format("bad list length '{}'", shown(t)));
                    }
                    for (long long k = 0; k < n; ++k) {
                        std::string_view t = d.next();
                        if (t.empty()) fail(0, fmt::format("file ends at {} {} of {} declared", e.name, i, e.count));
                        long long idx = 0;
                        if (p.index && (!to_int(t, idx) || idx < 0 || idx >= vertices))
                            fail(d.line(), fmt::format("face {} refers to vertex '{}'; there are {}", i, shown(t), vertices));
                    }
                }
            }
        }
        return;
    }
    const bool little = format == "binary_little_endian";
    std::size_t pos = end;
    auto read_uint = [&](int size, long long& out) {
        if (pos + size > bytes.size()) return false;
        std::uint64_t v = 0;
        for (int b = 0; b < size; ++b) {
            const auto byte = static_cast<unsigned char>(bytes[pos + (little ? b : size - 1 - b)]);
            v |= std::uint64_t{byte} << (8 * b);
        }
        pos += size;
        out = static_cast<long long>(v);
        return true;
    };
    for (const auto& e : elements) {
        for (long long i = 0; i < e.count; ++i) {
            for (const PlyProperty& p : e.props) {
                long long n = 1;
                if (p.count_size && !read_uint(p.count_size, n))
                    fail(0, fmt::format("file ends at {} {} of {} declared", e.name, i, e.count));
                for (long long k = 0; k < n; ++k) {
                    long long idx = 0;
                    if (!read_uint(p.size, idx)) fail(0, fmt::format("file ends at {} {} of {} declared", e.name, i, e.count));
                    // Signed index types: a negative index reads as a huge unsigned one here.
                    if (p.index && idx >= vertices)
                        fail(0, fmt::format("face {} refers to vertex {}; there are {}", i, idx, vertices));
                }
            }
        }
    }
}

// ---- OFF ----

void check_off(const std::string& path, const std::string& bytes) {
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
    // The keyword: [ST][C][N][4][n]OFF. What follows it on the line, with or without a space,
    // is the counts: assimp reads "OFF12 3" as OFF with counts, so rtcost checks them too.
    // Assimp takes the keyword as optional: without it, the first line is the counts.
    const std::size_t off = head.find("OFF");
    std::string_view counts = head;
    if (off != std::string_view::npos && head.substr(0, off).find_first_not_of("STCN4n") == std::string_view::npos)
        counts = head.substr(off + 3);
    else if (head.find_first_not_of("0123456789") == 0)
        fail(lines[0].second, "the first line is neither an OFF keyword nor the vertex, face and edge counts");
    while (!counts.empty() && is_space(counts.front())) counts.remove_prefix(1);
    // Assimp reads text OFF only (a binary one fails with "no valid vertices", or worse).
    if (counts.substr(0, 6) == "BINARY") fail(lines[0].second, "binary OFF is not supported; write it as text");
    if (counts.empty()) {
        if (at >= lines.size()) fail(lines[0].second, "no vertex and face counts");
        counts = lines[at++].first;
    }
    Words cw(counts, 0, 0);
    long long nv = 0, nf = 0;
    if (!to_int(cw.next(), nv) || !to_int(cw.next(), nf) || nv < 0 || nf < 0)
        fail(lines[at - 1].second, "bad vertex and face counts");
    // The edge count is unused but required: without it assimp reads the next line as counts.
    if (long long ne = 0; !to_int(cw.next(), ne) || ne < 0)
        fail(lines[at - 1].second, "the counts line needs three numbers: vertices, faces and edges");
    if (static_cast<long long>(lines.size() - at) < nv)
        fail(0, fmt::format("declares {} vertices, the file has {} lines after the counts", nv, lines.size() - at));
    at += static_cast<std::size_t>(nv);
    if (static_cast<long long>(lines.size() - at) < nf)
        fail(0, fmt::format("declares {} faces, the file has {} lines after the vertices", nf, lines.size() - at));
    for (long long f = 0; f < nf; ++f) {
        const auto [l, line] = lines[at + static_cast<std::size_t>(f)];
        Words fw(l, 0, line);
        long long k = 0;
        if (!to_int(fw.next(), k) || k < 0) fail(line, fmt::format("face {}: bad vertex count", f));
        for (long long i = 0; i < k; ++i) {
            std::string_view t = fw.next();
            long long idx = 0;
            if (t.empty()) fail(line, fmt::format("face {}: {} vertices declared, {} given", f, k, i));
            if (!to_int(t, idx) || idx < 0 || idx >= nv)
                fail(line, fmt::format("face {} refers to vertex '{}'; there are {}", f, shown(t), nv));
        }
    }
}

}  // namespace

void precheck_mesh(const std::string& path) {
    const std::string ext = lower_extension(path);
    if (ext != ".ply" && ext != ".off") return;
    const std::string bytes = read_whole(path);
    if (ext == ".ply") {
        // Assimp reads any .ply as PLY and takes the magic in any case ("Ply"): so must the check.
        auto lower = [](char c) { return static_cast<char>(c >= 'A' && c <= 'Z' ? c - 'A' + 'a' : c); };
        if (bytes.size() < 3 || lower(bytes[0]) != 'p' || lower(bytes[1]) != 'l' || lower(bytes[2]) != 'y')
            throw InputError(path, 1, "PLY: the file does not begin with 'ply'");
        check_ply(path, bytes);
    } else {
        check_off(path, bytes);
    }
}

}  // namespace rtcost
