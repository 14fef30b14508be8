// What an evaluation is asked for and what it reports, named: estimator, preset and query names,
// hierarchy requests parsed from a `-H` list, and the rank correlation the reports print.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "rtcost/error.hpp"
#include "rtcost/evaluate.hpp"
#include "rtcost/hierarchy.hpp"

namespace rtcost {

std::string_view estimator_name(Estimator e) {
    switch (e) {
        case Estimator::Geometric: return "geometric";
        case Estimator::Sampled: return "sampled";
        case Estimator::Segments: return "segments";
    }
    return "?";
}

double rank_correlation(std::span<const double> x, std::span<const double> y) {
    if (x.size() != y.size()) throw std::invalid_argument("rank_correlation: lengths differ");
    auto ranks = [](std::span<const double> v) {
        std::vector<std::size_t> idx(v.size());
        for (std::size_t i = 0; i < idx.size(); ++i) idx[i] = i;
        std::stable_sort(idx.begin(), idx.end(), [&](auto a, auto b) { return v[a] < v[b]; });
        std::vector<double> r(v.size());
        for (std::size_t k = 0; k < idx.size(); ++k) r[idx[k]] = static_cast<double>(k);
        return r;
    };
    const std::size_t n = x.size();
    if (n < 2) return 0;
    const auto rx = ranks(x), ry = ranks(y);
    double d2 = 0;
    for (std::size_t i = 0; i < n; ++i) d2 += (rx[i] - ry[i]) * (rx[i] - ry[i]);
    const double dn = static_cast<double>(n);
    return 1 - 6 * d2 / (dn * (dn * dn - 1));
}

std::string_view preset_name(Preset p) { return p == Preset::Paper ? "paper" : "exact"; }

std::string_view query_name(Query q) {
    switch (q) {
        case Query::Closest: return "closest";
        case Query::Any: return "any";
        case Query::All: return "all";
    }
    return "?";
}

std::string HierarchyRequest::label() const {
    std::string out = name;
    for (const std::string& p : params) out += ":" + p;
    return out;
}

std::vector<std::string> left_out_of_all(std::string_view list, std::size_t primitives) {
    std::vector<std::string> out;
    if (list != "all") return out;
    for (const HierarchyInfo* h : hierarchies())
        if (h->name != "embree" && primitives > h->all_up_to) out.push_back(h->name);
    return out;
}

std::vector<HierarchyRequest> parse_hierarchy_list(std::string_view list, std::size_t primitives,
                                                   const std::string& what) {
    std::vector<HierarchyRequest> out;
    if (list == "all") {
        for (const HierarchyInfo* h : hierarchies()) {
            if (h->name == "embree" || primitives > h->all_up_to) continue;
            out.push_back({h->name, {}});
        }
        return out;
    }
    std::size_t start = 0;
    while (start <= list.size()) {
        std::size_t comma = list.find(',', start);
        if (comma == std::string_view::npos) comma = list.size();
        std::string_view entry = list.substr(start, comma - start);
        start = comma + 1;
        if (entry.empty()) continue;
        HierarchyRequest r;
        std::size_t colon = entry.find(':');
        r.name = std::string(entry.substr(0, colon));
        while (colon != std::string_view::npos) {
            std::size_t next = entry.find(':', colon + 1);
            std::string_view p = entry.substr(colon + 1, next == std::string_view::npos ? next : next - colon - 1);
            if (p.find('=') == std::string_view::npos || p.front() == '=')
                throw InputError(what, 0, "'" + std::string(entry) + "': parameters are name:key=value");
            r.params.emplace_back(p);
            colon = next;
        }
        if (!find_hierarchy(r.name)) {
            std::string names;
            for (const HierarchyInfo* h : hierarchies()) names += (names.empty() ? "" : ", ") + h->name;
            throw InputError(what, 0, "unknown hierarchy '" + r.name + "' (known: " + names + ")");
        }
        out.push_back(std::move(r));
    }
    if (out.empty()) throw InputError(what, 0, "no hierarchy named");
    return out;
}

}  // namespace rtcost
