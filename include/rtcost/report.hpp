#pragma once
/// \file report.hpp
/// Reports: JSON forms of the statistics, human-readable numbers, and terminal progress.

#include <chrono>
#include <cstdio>
#include <map>
#include <nlohmann/json.hpp>
#include <string>

#include "rtcost/scene.hpp"
#include "rtcost/stats.hpp"

namespace rtcost {

/// `{"N_IN", "N_V", "N_EV", "N_OIV", "depth", "bytes", "seconds"}`.
nlohmann::json to_json(const StructureStats& s);
/// A hierarchy parameter's value as JSON: a number when the whole text is one ("8", "0.2"),
/// otherwise the text ("woo", "auto").
nlohmann::json param_json(const std::string& value);
/// Every parameter of a build, typed as by param_json.
nlohmann::json params_json(const std::map<std::string, std::string>& values);
/// Per-ray means: `{"N_IT", "N_TS", "N_ETS", "N_EETS", "box", "plane", "hop", "classify",
/// "prim", "prim_by_kind": {...}, "visits_by_depth": [...]}` (divided by `c.rays`).
nlohmann::json per_ray_json(const RayCounters& c);
/// Scene summary: name, primitive counts by kind, bounds, lights, camera, bytes.
nlohmann::json to_json(const Scene& s);

/// "1.23 MiB" style.
std::string human_bytes(std::uint64_t bytes);

/// A one-line progress indicator on stderr. It draws only when stderr is a terminal and it is
/// not quiet, at most ten times a second, and erases itself when done.
class Progress {
public:
    Progress(std::string label, std::size_t total, bool quiet);
    ~Progress();
    Progress(const Progress&) = delete;
    Progress& operator=(const Progress&) = delete;
    /// Reports `done` of `total` units finished, with the time left.
    void update(std::size_t done);
    /// A new step of `total` units: the clock restarts.
    void restart(std::string label, std::size_t total);
    /// Shows `text` now (a step that reports no fraction done, such as a build).
    void note(const std::string& text);
    void finish();
    bool active() const { return active_; }

private:
    std::string label_;
    std::size_t total_;
    bool active_;
    bool drawn_ = false;
    std::chrono::steady_clock::time_point start_, last_;
};

}  // namespace rtcost
