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


KINDS = ["camera", "spd", "diffuse", "shadow", "aimed", "random"]
LABEL = {"random": "random (most miss)"}


def main():
    data = json.load(open(sys.argv[1]))
    if len(sys.argv) > 2:  # a second file (e.g. the all-core run) adds its benchmarks
        data["benchmarks"] += json.load(open(sys.argv[2]))["benchmarks"]
    one = defaultdict(dict)    # (scene, dist) -> hierarchy -> (Mrays/s of CPU time, bytes, hit %)
    many = defaultdict(dict)   # (scene, dist) -> hierarchy -> Mrays/s of wall time
    build = defaultdict(dict)  # scene -> hierarchy -> (real ms, cpu ms)
    model = defaultdict(dict)  # scene -> hierarchy -> (ms, spd trace ms, share %)
    # With --benchmark_repetitions, the medians stand for their repetitions.
    medians = {b["run_name"] for b in data["benchmarks"] if b.get("aggregate_name") == "median"}
    for b in data["benchmarks"]:
        if b.get("run_type") == "aggregate" and b.get("aggregate_name") != "median":
            continue
        if b.get("run_type") != "aggregate" and b.get("run_name") in medians:
            continue
        parts = b["name"].split("/")
        if parts[0] == "trace":
            _, scene, dist, h, threads = parts[:5]
            if threads == "1t":
                one[(scene, dist)][h] = (b["Mrays/s"], b.get("bytes", 0), b.get("hit_pct", 0))
            else:
                per_iter = b["rays"] / 1e6
                # Mrays per second of wall time, and per second of the process's CPU time
                many[(scene, dist)][h] = (per_iter / (b["real_time"] / 1e3), per_iter / (b["cpu_time"] / 1e3))
        elif parts[0] == "build":
            build[parts[1]][parts[2]] = (b["real_time"], b["cpu_time"])
        elif parts[0] == "model":
            model[parts[1]][parts[2]] = (b["real_time"], b.get("spd_trace_ms", 0), b.get("share_pct", 0))
    keys = sorted(one, key=lambda k: (k[0], KINDS.index(k[1]) if k[1] in KINDS else 99))
    hier = [h for h in ["embree", "bvh-wide", "bvh-sah", "kd-sah"] if any(h in one[k] for k in keys)]
    hier += sorted({h for k in keys for h in one[k]} - set(hier))
    print("### Traversal, one thread (Mrays/s of CPU time; x Embree in brackets)\n")
    print("| scene | rays | hits | " + " | ".join(hier) + " |")
    print("|---|---|---|" + "---|" * len(hier))
    for k in keys:
        hs = one[k]
        ref = hs.get("embree", (0, 0, 0))[0]
        hit = next(iter(hs.values()))[2]
        cells = []
        for h in hier:
            if h not in hs:
                cells.append("-")
                continue
            mr = hs[h][0]
            cells.append(f"{mr:.2f} ({mr / ref:.2f}x)" if ref else f"{mr:.2f}")
        print(f"| {k[0]} | {LABEL.get(k[1], k[1])} | {hit:.0f}% | " + " | ".join(cells) + " |")
    if many:
        print("\n### Traversal, all cores (Mrays/s of wall time, x its own one-thread rate; then Mrays per CPU-second of "
              "all threads, x the one-thread rate)\n")
        print("| scene | rays | " + " | ".join(hier) + " |")
        print("|---|---|" + "---|" * len(hier))
        for k in sorted(many, key=lambda k: (k[0], KINDS.index(k[1]) if k[1] in KINDS else 99)):
            cells = []
            for h in hier:
                mt = many[k].get(h)
                st = one.get(k, {}).get(h, (0,))[0]
                if mt is None or not st:
                    cells.append("-")
                else:
                    cells.append(f"{mt[0]:.2f} ({mt[0] / st:.2f}x); {mt[1]:.2f} ({mt[1] / st:.2f}x)")
            print(f"| {k[0]} | {LABEL.get(k[1], k[1])} | " + " | ".join(cells) + " |")
    print("\n### Memory of the structure (MiB)\n")
    print("| scene | " + " | ".join(hier) + " |")
    print("|---|" + "---|" * len(hier))
    for scene in sorted({k[0] for k in keys}):
        k = next(k for k in keys if k[0] == scene)
        print(f"| {scene} | " + " | ".join(f"{one[k][h][1] / 2**20:.1f}" if h in one[k] else "-" for h in hier) + " |")
    print("\n### Build, one thread (ms of wall time and of CPU time, each as a ratio to Embree's)\n")
    print("| scene | hierarchy | wall ms | x Embree | CPU ms | x Embree |")
    print("|---|---|---|---|---|---|")
    for scene, hs in build.items():
        ref = hs.get("embree", (0, 0))
        for h, (ms, cpu) in hs.items():
            if ref[0]:
                print(f"| {scene} | {h} | {ms:.1f} | {ms / ref[0]:.2f} | {cpu:.1f} | {cpu / ref[1]:.2f} |")
            else:
                print(f"| {scene} | {h} | {ms:.1f} | - | {cpu:.1f} | - |")
    if model:
        print("\n### Geometric estimator against tracing the `spd` rays (one thread, same run)\n")
        print("| scene | hierarchy | estimate, ms | spd trace, ms | share | under 5% |")
        print("|---|---|---|---|---|---|")
        for scene, hs in model.items():
            for h, (ms, trace, share) in hs.items():
                print(f"| {scene} | {h} | {ms:.2f} | {trace:.1f} | {share:.1f}% | {'yes' if share < 5 else 'no'} |")


if __name__ == "__main__":
    main()
