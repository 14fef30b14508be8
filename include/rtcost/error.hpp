#pragma once
/// \file error.hpp
/// The one exception type for bad input. Its message always names the file (or source), the
/// line where there is one, and the problem: "scene.nff:12: sphere radius is NaN".

#include <cstddef>
#include <stdexcept>
#include <string>
#include <string_view>

namespace rtcost {

class InputError : public std::runtime_error {
public:
    /// `line` 0 means the problem has no line (binary files, whole-file problems).
    InputError(std::string file, int line, const std::string& problem)
        : std::runtime_error(format(file, line, problem)), file_(std::move(file)), line_(line) {}

    const std::string& file() const { return file_; }
    int line() const { return line_; }

private:
    static std::string format(const std::string& file, int line, const std::string& problem) {
        return line > 0 ? file + ":" + std::to_string(line) + ": " + problem : file + ": " + problem;
    }
    std::string file_;
    int line_;
};

/// A piece of an input file as a message quotes it: at most 40 bytes (a runaway token can be
/// megabytes, said with its length), and a byte that is not printable ASCII (a NUL, a control
/// character, binary junk) as \xNN, so the message reaches the terminal whole and harmless.
inline std::string shown_token(std::string_view t) {
    constexpr std::size_t kMax = 40;
    static constexpr char kHex[] = "0123456789abcdef";
    std::string out;
    for (const char c : t.substr(0, kMax)) {
        const auto b = static_cast<unsigned char>(c);
        if (b >= 0x20 && b < 0x7f) {
            out.push_back(c);
        } else {
            out += "\\x";
            out.push_back(kHex[b >> 4]);
            out.push_back(kHex[b & 15]);
        }
    }
    if (t.size() > kMax) out += "... (" + std::to_string(t.size()) + " characters)";
    return out;
}

}  // namespace rtcost
