#!/usr/bin/env python3
"""Turns a Google Benchmark JSON file from build/bench/rtcost_bench into the tables of
docs/benchmarks.md: single-thread rays per second and build time of every hierarchy, each as a
ratio to Embree measured in the same run, and the memory each structure holds.

Usage: build/bench/rtcost_bench --benchmark_out=bench.json --benchmark_out_format=json
       python3 scripts/benchmarks.py bench.json > table.md
"""
import json
import sys
from collections import defaultdict


def main():
    data = json.load(open(sys.argv[1]))
    trace = defaultdict(dict)   # (scene, dist) -> hierarchy -> (Mrays/s, bytes)
    build = defaultdict(dict)   # scene -> hierarchy -> ms
    model = defaultdict(dict)   # scene -> hierarchy -> (ms, spd trace ms, share %)
    for b in data["benchmarks"]:
        parts = b["name"].split("/")
        if parts[0] == "trace":
            _, scene, dist, h = parts[:4]
            trace[(scene, dist)][h] = (b["Mrays/s"] / 1e6 if b["Mrays/s"] > 1e3 else b["Mrays/s"], b.get("bytes", 0))
        elif parts[0] == "build":
            build[parts[1]][parts[2]] = b["real_time"]
        elif parts[0] == "model":
            model[parts[1]][parts[2]] = (b["real_time"], b.get("spd_trace_ms", 0), b.get("share_pct", 0))
    print("### Traversal, one thread (closest hit)\n")
    print("| scene | rays | hierarchy | Mrays/s | x Embree | memory |")
    print("|---|---|---|---|---|---|")
    for (scene, dist), hs in trace.items():
        ref = hs.get("embree", (0, 0))[0]
        for h, (mr, by) in hs.items():
            ratio = f"{mr / ref:.2f}" if ref else "-"
            mem = f"{by / 2**20:.1f} MiB" if by else "-"
            print(f"| {scene} | {dist} | {h} | {mr:.2f} | {ratio} | {mem} |")
    print("\n### Build, one thread\n")
    print("| scene | hierarchy | ms | x Embree |")
    print("|---|---|---|---|")
    for scene, hs in build.items():
        ref = hs.get("embree", 0)
        for h, ms in hs.items():
            print(f"| {scene} | {h} | {ms:.1f} | {ms / ref:.2f} |" if ref else f"| {scene} | {h} | {ms:.1f} | - |")
    if model:
        print("\n### Geometric estimator against tracing the `spd` rays (one thread, same run)\n")
        print("| scene | hierarchy | estimate, ms | spd trace, ms | share | under 5% |")
        print("|---|---|---|---|---|---|")
        for scene, hs in model.items():
            for h, (ms, trace, share) in hs.items():
                print(f"| {scene} | {h} | {ms:.2f} | {trace:.1f} | {share:.1f}% | {'yes' if share < 5 else 'no'} |")


if __name__ == "__main__":
    main()
