// Typed build parameters: a declaration says what values a parameter takes, and every value is
// checked against it before a build starts.
#include <charconv>
#include <cmath>
#include <fmt/format.h>

#include "rtcost/error.hpp"
#include "rtcost/hierarchy.hpp"

namespace rtcost {
namespace {

[[noreturn]] void bad_param(const std::string& key, const std::string& value, const std::string& want) {
    throw InputError("--set", 0, fmt::format("{}={}: {}", key, value, want));
}

/// The whole of `v` as a number of type T, or nothing.
template <class T>
bool parse_number(const std::string& v, T& x) {
    auto [p, ec] = std::from_chars(v.data(), v.data() + v.size(), x);
    return ec == std::errc() && p == v.data() + v.size();
}

std::string join(const std::vector<std::string>& words) {
    std::string out;
    for (const std::string& w : words) out += (out.empty() ? "" : ", ") + w;
    return out;
}

bool has(const std::vector<std::string>& words, const std::string& v) {
    for (const std::string& w : words)
        if (w == v) return true;
    return false;
}

int flag_value(const std::string& v) {
    if (v == "1" || v == "true" || v == "on" || v == "yes") return 1;
    if (v == "0" || v == "false" || v == "off" || v == "no") return 0;
    return -1;
}

}  // namespace

std::string_view param_kind_name(ParamKind k) {
    switch (k) {
        case ParamKind::Integer: return "integer";
        case ParamKind::Real: return "real";
        case ParamKind::Flag: return "flag";
        case ParamKind::Choice: return "choice";
        case ParamKind::Text: return "text";
    }
    return "text";
}

ParamSpec ParamSpec::integer(std::string name, std::string def, long long lo, long long hi, std::string help,
                             std::vector<std::string> words) {
    return {std::move(name), std::move(def), std::move(help), ParamKind::Integer, double(lo), double(hi),
            std::move(words)};
}

ParamSpec ParamSpec::real(std::string name, std::string def, double lo, double hi, std::string help,
                          std::vector<std::string> words) {
    return {std::move(name), std::move(def), std::move(help), ParamKind::Real, lo, hi, std::move(words)};
}

ParamSpec ParamSpec::flag(std::string name, std::string def, std::string help) {
    return {std::move(name), std::move(def), std::move(help), ParamKind::Flag, 0, 1, {}};
}

ParamSpec ParamSpec::choice(std::string name, std::string def, std::vector<std::string> words, std::string help) {
    return {std::move(name), std::move(def), std::move(help), ParamKind::Choice, 0, 0, std::move(words)};
}

ParamSpec ParamSpec::text(std::string name, std::string def, std::string help) {
    return {std::move(name), std::move(def), std::move(help), ParamKind::Text, 0, 0, {}};
}

std::string ParamSpec::domain() const {
    const std::string also = words.empty() ? "" : ", or " + join(words);
    switch (kind) {
        case ParamKind::Integer: return fmt::format("integer in [{:.0f}, {:.0f}]{}", lo, hi, also);
        case ParamKind::Real: return fmt::format("number in [{:g}, {:g}]{}", lo, hi, also);
        case ParamKind::Flag: return "0 or 1";
        case ParamKind::Choice: return "one of " + join(words);
        case ParamKind::Text: return "text";
    }
    return "text";
}

std::string ParamSpec::problem(const std::string& v) const {
    switch (kind) {
        case ParamKind::Integer: {
            if (has(words, v)) return {};
            long long x = 0;
            if (!parse_number(v, x)) return "expected an integer" + (words.empty() ? "" : " or " + join(words));
            // Compared as integers: a double cannot tell 2^62 + 1 from 2^62.
            if (x < static_cast<long long>(lo) || x > static_cast<long long>(hi))
                return fmt::format("must be in [{:.0f}, {:.0f}]", lo, hi);
            return {};
        }
        case ParamKind::Real: {
            if (has(words, v)) return {};
            double x = 0;
            if (!parse_number(v, x) || !std::isfinite(x))
                return "expected a number" + (words.empty() ? "" : " or " + join(words));
            if (x < lo || x > hi) return fmt::format("must be in [{:g}, {:g}]", lo, hi);
            return {};
        }
        case ParamKind::Flag: return flag_value(v) < 0 ? "expected 0 or 1" : "";
        case ParamKind::Choice: return has(words, v) ? "" : "expected one of " + join(words);
        case ParamKind::Text: return {};
    }
    return {};
}

Params::Params(const std::vector<ParamSpec>& specs, const std::vector<std::string>& assignments) {
    for (const auto& s : specs) {
        values_[s.name] = s.default_value;
        specs_.emplace(s.name, s);
    }
    for (const auto& a : assignments) {
        auto eq = a.find('=');
        if (eq == std::string::npos || eq == 0) {
            throw InputError("--set", 0, fmt::format("'{}': expected key=value", a));
        }
        std::string key = a.substr(0, eq);
        if (!values_.contains(key)) {
            std::string known;
            for (const auto& s : specs) known += (known.empty() ? "" : ", ") + s.name;
            throw InputError("--set", 0,
                             fmt::format("unknown parameter '{}' (known: {})", key, known.empty() ? "none" : known));
        }
        values_[key] = a.substr(eq + 1);
    }
    // Defaults too: a declaration whose default it does not take is caught by the first build.
    for (const auto& [key, value] : values_)
        if (std::string why = specs_.at(key).problem(value); !why.empty()) bad_param(key, value, why);
}

const ParamSpec& Params::spec(const std::string& key) const {
    auto it = specs_.find(key);
    if (it == specs_.end()) throw InputError("--set", 0, fmt::format("parameter '{}' is not declared", key));
    return it->second;
}

const std::string& Params::str(const std::string& key) const {
    auto it = values_.find(key);
    if (it == values_.end()) throw InputError("--set", 0, fmt::format("parameter '{}' is not declared", key));
    return it->second;
}

long long Params::integer(const std::string& key) const {
    const std::string& v = str(key);
    long long x = 0;
    if (spec(key).kind != ParamKind::Integer || !parse_number(v, x)) bad_param(key, v, "expected an integer");
    return x;
}

double Params::real(const std::string& key) const {
    const std::string& v = str(key);
    double x = 0;
    const ParamKind k = spec(key).kind;
    if ((k != ParamKind::Real && k != ParamKind::Integer) || !parse_number(v, x)) bad_param(key, v, "expected a number");
    return x;
}

bool Params::flag(const std::string& key) const {
    const std::string& v = str(key);
    const int f = flag_value(v);
    if (f < 0) bad_param(key, v, "expected 0 or 1");
    return f == 1;
}

}  // namespace rtcost
