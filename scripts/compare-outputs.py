#!/usr/bin/env python3
"""Checks that a change left rtcost's numbers alone: runs the same commands with two rtcost
binaries (before and after) and compares their --json outputs with every timing removed.

Usage: python3 scripts/compare-outputs.py BEFORE_RTCOST AFTER_RTCOST [--hits]

The commands are the README's kinds of run on built-in scenes, small enough for a minute:
`trace` of every registered hierarchy (counts per ray, hits), `eval` with each estimator
(predicted and measured costs, ranks; the exact and the paper's presets), `rays` of each distribution, `design`, `list`, and the
hit files of `trace --hits` (with --hits). Exits 1 and prints the first differences when any
output differs; 0 when all agree.
"""
import json
import os
import subprocess
import sys
import tempfile

# Keys whose values are timings or depend on the machine: dropped before comparing.
TIMING = {"seconds", "mrays_per_s", "ns_per_ray", "time", "threads", "build_seconds", "rtcost", "date",
          "machine", "command", "out", "measured_ns_per_ray", "predicted_ns_per_ray", "rank_time",
          "ns", "spread", "median", "repeats", "prediction_share"}


def timing(key):
    return key in TIMING or "seconds" in key or "ns_per" in key or "mrays" in key or key == "gain"


def strip(doc):
    if isinstance(doc, dict):
        return {k: strip(v) for k, v in doc.items() if not timing(k)}
    if isinstance(doc, list):
        return [strip(v) for v in doc]
    return doc


def hierarchies(binary):
    doc = json.loads(subprocess.run([binary, "list", "--json"], check=True, capture_output=True, text=True).stdout)
    items = doc["hierarchies"] if isinstance(doc, dict) else doc
    return [h["name"] for h in items]


def commands(names):
    scene = "builtin:balls:2"
    cmds = [["list", "--json"]]
    for h in names:
        if h == "embree":  # not counted; its hits are Embree's
            continue
        cmds.append(["trace", scene, "-H", h, "--rays", "spd", "--size", "24x24", "-j", "1", "--json", "-q"])
    for est in ("geometric", "sampled", "segments"):
        cmds.append(["eval", scene, "-H", "bvh-sah,kd-sah,grid,octree,bsp,rc5d", "--rays", "camera", "--size", "32x32",
                     "--estimator", est, "--json", "-q"])
    # The seed paper's formulas (the hierarchies declare what they charge) beside the exact ones.
    for est in ("geometric", "sampled"):
        cmds.append(["eval", scene, "-H", "bvh-sah,kd-sah,grid,octree,bsp,rc5d,brute", "--rays", "spd", "--size", "24x24",
                     "--estimator", est, "--preset", "both", "--json", "-q"])
    for dist in ("camera", "spd", "shadow", "diffuse", "ao", "lines", "random", "aimed"):
        cmds.append(["rays", scene, "--rays", dist, "--size", "16x16", "--count", "500", "--json", "-q"])
    cmds.append(["design", scene, "--rays", "spd", "--size", "32x32", "--sample", "512", "--json", "-q"])
    return cmds


def diff(a, b, path="", out=None, limit=10):
    out = [] if out is None else out
    if len(out) >= limit:
        return out
    if type(a) is not type(b):
        out.append(f"{path}: {a!r} != {b!r}")
    elif isinstance(a, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                out.append(f"{path}/{k}: only in {'after' if k in b else 'before'}")
            else:
                diff(a[k], b[k], f"{path}/{k}", out, limit)
    elif isinstance(a, list):
        if len(a) != len(b):
            out.append(f"{path}: {len(a)} items before, {len(b)} after")
        for i, (x, y) in enumerate(zip(a, b)):
            diff(x, y, f"{path}[{i}]", out, limit)
    elif a != b:
        out.append(f"{path}: {a!r} before, {b!r} after")
    return out


def run(binary, args, tmp, tag):
    args = list(args)
    if "--hits-file" in args:
        i = args.index("--hits-file")
        args[i:i + 2] = ["--hits", os.path.join(tmp, tag + ".hits")]
    p = subprocess.run([binary] + args, capture_output=True, text=True)
    return p.returncode, p.stdout, p.stderr


def main():
    if len(sys.argv) < 3:
        print(__doc__.strip())
        return 2
    before, after = sys.argv[1], sys.argv[2]
    names = hierarchies(before)
    if names != hierarchies(after):
        print("compare-outputs: the registries differ:", names, hierarchies(after))
        return 1
    cmds = commands(names)
    if "--hits" in sys.argv:
        for h in names:
            if h != "embree":
                cmds.append(["trace", "builtin:balls:2", "-H", h, "--rays", "aimed", "--count", "2000", "-j", "1",
                             "--no-count", "--hits-file", "x", "-q"])
    failed = 0
    with tempfile.TemporaryDirectory() as tmp:
        for n, args in enumerate(cmds):
            rb, ob, eb = run(before, args, tmp, f"b{n}")
            ra, oa, ea = run(after, args, tmp, f"a{n}")
            what = " ".join(args)
            if rb != ra:
                print(f"DIFFERS  {what}: exit {rb} before, {ra} after\n  {eb.strip()}\n  {ea.strip()}")
                failed += 1
                continue
            if "--hits-file" in args:
                same = open(os.path.join(tmp, f"b{n}.hits"), "rb").read() == open(os.path.join(tmp, f"a{n}.hits"), "rb").read()
                problems = [] if same else ["hit files differ"]
            elif "--json" in args:
                problems = diff(strip(json.loads(ob)), strip(json.loads(oa)))
            else:
                problems = [] if ob == oa else ["outputs differ"]
            if problems:
                failed += 1
                print(f"DIFFERS  {what}")
                for p in problems:
                    print("  " + p)
    print(f"compare-outputs: {len(cmds) - failed} of {len(cmds)} commands give the same numbers")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
