#!/usr/bin/env python3
"""Generates docs/design.md: each designed hierarchy against its family's yardstick, on the SPD
scenes and real meshes, for several ray distributions, from `rtcost design --json` runs pinned
to one core (`taskset -c 0`), with Embree's ns per ray on the same rays in the same run.

Usage: python3 scripts/design.py [--scenes a,b] [--dists camera,shadow,...] [--families grid,bvh]
                                 [--size 128x128] [--sample 4096] [--out docs/design.md]
"""
import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.environ.get("RTCOST_SHARED", os.path.join(ROOT, "..", "shared"))
SPD = ["balls", "gears", "lattice", "mount", "rings", "shells", "sombrero", "teapot", "tetra", "tree"]
MESHES = ["/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb"]


def scene_path(name):
    if name.startswith("builtin:") or "/" in name:
        return name
    return os.path.join(SHARED, "scenes", "spd", name + ".nff")


def run(binary, scene, dist, families, size, sample):
    cmd = ["taskset", "-c", "0", binary, "design", scene, "--rays", dist, "--size", size,
           "--family", families, "--sample", str(sample), "--json", "--quiet"]
    start = time.time()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out), time.time() - start


def sweep(binary, scene, dist, size, sample, designed, variants):
    """One `rtcost eval` run (one core, segments estimator: the same test rays as `rtcost design`)
    of the designed hierarchy and every variant of its yardstick; ns per ray by label."""
    hs = ",".join([designed] + variants)
    cmd = ["taskset", "-c", "0", binary, "eval", scene, "-H", hs, "--rays", dist, "--size", size,
           "--estimator", "segments", "--sample", str(sample), "-j", "1", "--json", "--quiet"]
    doc = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    return [(r["hierarchy"], r["time"]["measured_ns_per_ray"], r["measured"]["cost"]) for r in doc["results"]]


def sweep_tables(a, scenes):
    grid = [f"grid:res=hetero:density={2 ** (k / 3):.4g}" for k in range(-9, 13)]  # 22 resolutions
    kd = [f"kd-sah:c_trav={t}:empty_bonus={b}" for t in (5, 10, 15, 20, 30) for b in (0, 0.2, 0.5)]
    out = []
    for fam, variants in (("grid", grid), ("kd", kd)):
        out += ["", f"## {fam}-design against a sweep of its yardstick's parameters (`{a.sweep_dist}` rays)", "",
                f"Every variant in one `rtcost eval -j 1` run with the designed one, pinned to one core: "
                f"{len(variants)} variants ({'hetero grids at densities 2^(k/3), k = -9..12' if fam == 'grid' else 'kd-sah c_trav 5..30 x empty_bonus 0, 0.2, 0.5'}).", "",
                "| scene | designed ns | best of sweep | best ns | designed / best | designed ops | best's ops |",
                "|---|---|---|---|---|---|---|"]
        for scene in scenes:
            print(f"sweep {fam} {os.path.basename(scene)}", file=sys.stderr, flush=True)
            designed = f"{fam}-design:rays={a.sweep_dist}:size={a.size}:sample={a.sample}"
            rows = sweep(a.binary, scene, a.sweep_dist, a.size, a.sample, designed, variants)
            d = rows[0]
            best = min(rows[1:], key=lambda r: r[1])
            out.append(f"| {os.path.basename(scene)} | {d[1]:.0f} | `{best[0]}` | {best[1]:.0f} | "
                       f"{d[1] / best[1]:.3f} | {d[2]:.1f} | {best[2]:.1f} |")
    return out


def cpu_name():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "rtcost"))
    ap.add_argument("--scenes", default=",".join(SPD + MESHES))
    ap.add_argument("--dists", default="camera,shadow,ao,diffuse,spd")
    ap.add_argument("--families", default="all")
    ap.add_argument("--size", default="128x128")
    ap.add_argument("--sample", type=int, default=4096)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "design.md"))
    ap.add_argument("--sweep-scenes", default=",".join(SPD), help="scenes of the grid and kd sweeps ('' for none)")
    ap.add_argument("--sweep-dist", default="spd")
    a = ap.parse_args()
    rows = []
    for scene in a.scenes.split(","):
        path = scene_path(scene)
        if not path.startswith("builtin:") and not os.path.exists(path):
            print(f"skipping {path}: not present", file=sys.stderr)
            continue
        for dist in a.dists.split(","):
            print(f"{os.path.basename(path)} {dist}", file=sys.stderr, flush=True)
            doc, secs = run(a.binary, path, dist, a.families, a.size, a.sample)
            for r in doc["results"]:
                rows.append((os.path.basename(path), dist, doc, r))
    lines = ["# Designed hierarchies against their yardsticks", "",
             "Generated by `scripts/design.py` (do not edit by hand): "
             f"`rtcost design SCENE --rays DIST --size {a.size} --sample {a.sample} --family {a.families} --json`, "
             "pinned to one core (`taskset -c 0`).", "",
             f"Machine: {cpu_name()}, {os.cpu_count()} hardware threads, shared with other jobs while this ran "
             f"(absolute ns are noisy; designed, yardstick and Embree ran back to back on the same rays). "
             f"Date: {datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC.", "",
             "Each designed hierarchy draws its own sample of the distribution (the sample size below) and "
             "is measured on every other ray of the distribution (test rays). `predicted`: the model's "
             "operations per ray on the design sample (segments estimator); `measured`: counted operations "
             "per ray on the test rays (unit costs); `ns`: measured single-thread ns per ray on the test "
             "rays; `gain`: 1 - designed ns / yardstick ns; `build`: seconds, the designed one's including "
             "drawing its sample (the design time).", "",
             "| scene | rays | family | sample | test rays | build s (design / yardstick) | predicted ops | measured ops | ns per ray | Embree ns | gain |",
             "|---|---|---|---|---|---|---|---|---|---|---|"]
    for scene, dist, doc, r in rows:
        b, p, m, n = r["build_seconds"], r["predicted"], r["measured"], r["ns_per_ray"]
        lines.append(f"| {scene} | {dist} | {r['designed']} vs {r['yardstick']} | {doc['sample']} | {doc['test_rays']} | "
                     f"{b['designed']:.3f} / {b['yardstick']:.3f} | {p['designed']:.1f} / {p['yardstick']:.1f} | "
                     f"{m['designed']:.1f} / {m['yardstick']:.1f} | {n['designed']:.0f} / {n['yardstick']:.0f} | "
                     f"{n['embree']:.0f} | {100 * r['gain']:+.1f}% |")
    # Per family and distribution: mean gain and worst case.
    lines += ["", "## Gain by family and distribution", "", "| family | rays | scenes | mean gain | worst | best |",
              "|---|---|---|---|---|---|"]
    groups = {}
    for scene, dist, doc, r in rows:
        groups.setdefault((r["family"], dist), []).append(r["gain"])
    for (fam, dist), g in sorted(groups.items()):
        lines.append(f"| {fam} | {dist} | {len(g)} | {100 * sum(g) / len(g):+.1f}% | {100 * min(g):+.1f}% | {100 * max(g):+.1f}% |")
    if a.sweep_scenes:
        scenes = [scene_path(x) for x in a.sweep_scenes.split(",")]
        lines += sweep_tables(a, [x for x in scenes if x.startswith("builtin:") or os.path.exists(x)])
    text = "\n".join(lines) + "\n"
    with open(a.out + ".tmp", "w") as f:
        f.write(text)
    os.replace(a.out + ".tmp", a.out)
    print(text)


if __name__ == "__main__":
    main()
