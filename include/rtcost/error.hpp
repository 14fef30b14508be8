#pragma once
/// \file error.hpp
/// The one exception type for bad input. Its message always names the file (or source), the
/// line where there is one, and the problem: "scene.nff:12: sphere radius is NaN".

#include <stdexcept>
#include <string>

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

}  // namespace rtcost
