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
import subprocess
import sys
import time

from machine import cpu_name  # scripts/machine.py

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.environ.get("RTCOST_SHARED", os.path.join(ROOT, "..", "shared"))
SPD = ["balls", "gears", "lattice", "mount", "rings", "shells", "sombrero", "teapot", "tetra", "tree"]
# Real meshes of over 50,000 triangles among assimp's test models (Debian's assimp-testmodels).
MESHES = ["/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
          "/usr/share/assimp/models/BLEND/yxa_1.blend"]


def scene_path(name):
    if name.startswith("builtin:") or "/" in name:
        return name
    return os.path.join(SHARED, "scenes", "spd", name + ".nff")


def run(binary, scene, dist, families, size, sample, costs=None):
    cmd = ["taskset", "-c", "0", binary, "design", scene, "--rays", dist, "--size", size,
           "--family", families, "--sample", str(sample), "--control", "--json", "--quiet"] + (["--costs", costs] if costs else [])
    start = time.time()
    out = subprocess.run(cmd, check=True, capture_output=True, text=True).stdout
    return json.loads(out), time.time() - start


# Timed passes per variant in a sweep, interleaved, the median kept: with the default (as many as
# take 0.2 s, two on the larger scenes) one disturbed pass moved a grid 40% off its own copy.
SWEEP_PASSES = 7


def sweep(binary, scene, dist, size, sample, designed, variants):
    """One `rtcost eval --interleave` run (one core, segments estimator: the same test rays as
    `rtcost design`) of the designed hierarchy and every variant of its yardstick, timed in rounds
    so that a change of the machine's load weighs on all alike; ns per ray by label."""
    hs = ",".join([designed] + variants)
    cmd = ["taskset", "-c", "0", binary, "eval", scene, "-H", hs, "--rays", dist, "--size", size,
           "--estimator", "segments", "--sample", str(sample), "-j", "1", "--interleave", "--repeat", str(SWEEP_PASSES),
           "--json", "--quiet"]
    doc = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    return [(r["hierarchy"], r["time"]["measured_ns_per_ray"], r["measured"]["cost"]) for r in doc["results"]]


def sweep_runs(a, scenes):
    """Raw sweep results: {family: [(scene, designed (label, ns, ops), [(label, ns, ops), ...])]}."""
    grid = [f"grid:res=hetero:density={2 ** (k / 3):.4g}" for k in range(-9, 13)]  # 22 resolutions
    kd = [f"kd-sah:c_trav={t}:empty_bonus={b}" for t in (5, 10, 15, 20, 30) for b in (0, 0.2, 0.5)]
    out = {}
    for fam, variants in (("grid", grid), ("kd", kd)):
        for scene in scenes:
            print(f"sweep {fam} {os.path.basename(scene)}", file=sys.stderr, flush=True)
            designed = f"{fam}-design:rays={a.sweep_dist}:size={a.size}:sample={a.sample}"
            rows = sweep(a.binary, scene, a.sweep_dist, a.size, a.sample, designed, variants)
            # The fastest of many noisy times is biased low (the variant that drew the luckiest
            # passes wins): the designed one and the sweep's best timed again, head to head, in
            # a run of their own, which did not choose the best.
            best = min(rows[1:], key=lambda r: r[1])
            again = sweep(a.binary, scene, a.sweep_dist, a.size, a.sample, designed, [best[0]])
            out.setdefault(fam, []).append([os.path.basename(scene), rows[0], rows[1:],
                                            {"designed": again[0], "best": again[1]}])
    return out


def sweep_tables(raw, dist, counts=None, when=None):
    out = []
    for fam, runs in raw.items():
        n = (counts or {}).get(fam, len(runs[0][2]) if runs else 0)
        what = "hetero grids at densities 2^(k/3), k = -9..12" if fam == "grid" else "kd-sah c_trav 5..30 x empty_bonus 0, 0.2, 0.5"
        out += ["", f"## {fam}-design against a sweep of its yardstick's parameters (`{dist}` rays)", "",
                f"Every variant in one `rtcost eval -j 1 --interleave` run with the designed one, pinned to one core (all built, then timed in {SWEEP_PASSES} rounds of one pass each, the median kept): {n} variants ({what}). "
                "`re-timed`: the designed one and the sweep's best again, head to head, in a second run of the same kind "
                "(the fastest of many noisy times is biased low: the sweep's best is chosen on the first run and "
                "timed on the second)" + (f". Sweeps run on {when}, with the code of that day" if when else "") + ".", "",
                "| scene | designed ns | best of sweep | best ns | designed / best | re-timed: designed / best ns | re-timed ratio | designed ops | best's ops | best ops of sweep |",
                "|---|---|---|---|---|---|---|---|---|---|"]
        for scene, d, variants, *again in runs:
            best = min(variants, key=lambda r: r[1])
            best_ops = min(r[2] for r in variants)
            retimed = again[0] if again else None
            re_ns = f"{retimed['designed'][1]:.0f} / {retimed['best'][1]:.0f}" if retimed else "-"
            re_ratio = f"{retimed['designed'][1] / retimed['best'][1]:.3f}" if retimed else "-"
            out.append(f"| {scene} | {d[1]:.0f} | `{best[0]}` | {best[1]:.0f} | {d[1] / best[1]:.3f} | {re_ns} | {re_ratio} | {d[2]:.1f} | {best[2]:.1f} | {best_ops:.1f} |")
    return out


def targets(rows, raw_sweeps):
    """The issue's targets, each met or not, in measured ns and in measured operations."""
    def gain(r, what):
        d, y = r[what]["designed"], r[what]["yardstick"]
        return 1 - d / y if y else 0
    out = ["", "## The issue's targets on these runs", "",
           "Each in measured single-thread ns per ray (noisy here: see the machine note) and in measured "
           "operations per ray (unit costs, exact counts on the test rays).", ""]
    bvh = [(sc, d, r) for sc, d, doc, r in rows if r["family"] == "bvh"]
    for dist in ("shadow", "ao"):
        g = [(sc, gain(r, "ns_per_ray"), gain(r, "measured")) for sc, d, r in bvh if d == dist]
        if not g:
            continue
        ok_ns = sum(1 for _, x, _ in g if x >= 0.2)
        ok_ops = sum(1 for _, _, x in g if x >= 0.2)
        out.append(f"- bvh-design at least 20% fewer than bvh-sah on `{dist}` rays on at least three scenes: "
                   f"ns: {ok_ns} scenes ({'met' if ok_ns >= 3 else 'not met'}); operations: {ok_ops} scenes "
                   f"({'met' if ok_ops >= 3 else 'not met'}); best ops gain {100 * max(x for *_, x in g):+.1f}%.")
    # The words, "occlusion (shadow, ao) rays on at least three occluded scenes", read the
    # other way too: scenes where either kind of occlusion ray gains 20%.
    either = {}
    for sc, d, r in bvh:
        if d in ("shadow", "ao"):
            either.setdefault(sc, []).append((d, gain(r, "ns_per_ray"), gain(r, "measured")))
    ns_scenes = sorted(sc for sc, g in either.items() if any(x >= 0.2 for _, x, _ in g))
    ops_scenes = sorted(sc for sc, g in either.items() if any(x >= 0.2 for *_, x in g))
    if either:
        out.append(f"- the same read as shadow or ao rays on a scene: ns: {len(ns_scenes)} scenes ({', '.join(ns_scenes) or 'none'}); "
                   f"operations: {len(ops_scenes)} scenes ({', '.join(ops_scenes) or 'none'}).")
    spd = [(sc, gain(r, "ns_per_ray"), gain(r, "measured")) for sc, d, r in bvh if d == "spd" and sc.endswith(".nff")]
    if spd:
        mean_ns = sum(x for _, x, _ in spd) / len(spd)
        mean_ops = sum(x for _, _, x in spd) / len(spd)
        worst_ns = min(gain(r, "ns_per_ray") for _, _, r in bvh)
        controls = [r["control_gain"] for _, _, r in bvh if "control_gain" in r]
        worst_ops = min(gain(r, "measured") for _, _, r in bvh)
        out.append(f"- bvh-design at least 10% faster than bvh-sah on `spd` rays on average over the SPD scenes: "
                   f"ns {100 * mean_ns:+.1f}%, operations {100 * mean_ops:+.1f}% ({'met' if mean_ns >= 0.1 else 'not met'} in ns, "
                   f"{'met' if mean_ops >= 0.1 else 'not met'} in operations); no scene and distribution more than 3% slower: "
                   f"worst ns {100 * worst_ns:+.1f}%, worst operations {100 * worst_ops:+.1f}% "
                   f"({'met' if worst_ns >= -0.03 else 'not met'} in ns, {'met' if worst_ops >= -0.03 else 'not met'} in operations).")
        if controls:
            slower = sum(1 for x in controls if x < -0.03)
            out.append(f"- the A/A control on the same {len(controls)} bvh rows (bvh-sah in a second evaluation against the first): "
                       f"from {100 * min(controls):+.1f}% to {100 * max(controls):+.1f}%, more than 3% slower on {slower}; "
                       f"a gain of a few percent either way is within this run's noise.")
    grid = [(sc, gain(r, "ns_per_ray"), gain(r, "measured")) for sc, d, doc, r in rows
            if r["family"] == "grid" and d == "spd" and sc.endswith(".nff")]
    if grid:
        out.append(f"- grid-design faster than `res=hetero` on every SPD scene (`spd` rays): ns on "
                   f"{sum(1 for _, x, _ in grid if x > 0)} of {len(grid)}, operations on {sum(1 for *_, x in grid if x > 0)} of {len(grid)}.")
    for fam, limit in (("grid", 0.05), ("kd", 0.03)):
        runs = raw_sweeps.get(fam, [])
        if not runs:
            continue
        ns_ok = sum(1 for _, d, v, *_ in runs if d[1] <= (1 + limit) * min(x[1] for x in v))
        ops_ok = sum(1 for _, d, v, *_ in runs if d[2] <= (1 + limit) * min(x[2] for x in v))
        again = [x[3] for x in runs if len(x) > 3]
        re_ok = sum(1 for r in again if r["designed"][1] <= (1 + limit) * r["best"][1])
        out.append(f"- {fam}-design within {100 * limit:.0f}% of the best of the sweep: ns on {ns_ok} of {len(runs)} scenes "
                   f"in the sweep's run" + (f", on {re_ok} of {len(again)} re-timed head to head with that best" if again else "")
                   + f"; operations on {ops_ok} of {len(runs)}.")
    sah_build = {sc: r["build_seconds"]["yardstick"] for sc, d, r in bvh}
    worst = max(((r["build_seconds"]["designed"] / sah_build[sc], sc, r["designed"]) for sc, d, doc, r in rows
                 if sah_build.get(sc)), default=None)
    if worst:
        within = sum(1 for sc, d, doc, r in rows if sah_build.get(sc) and r["build_seconds"]["designed"] <= 10 * sah_build[sc])
        out.append(f"- design time at most 10x bvh-sah's build (sample 4096 at most): {within} of {len(rows)} designs; "
                   f"worst {worst[0]:.0f}x ({worst[2]} on {worst[1]}).")
    return out


# Design changes measured with this script and not kept (operations: exact counts on the test rays).
TRIED = ["", "## Tried and not kept", "",
         "- 2026-12-05, bvh-design's splits priced for occlusion rays by where their search can end (the "
         "termination term of Feltman, Lee and Fussell's shadow ray distribution heuristic): a ray that "
         "crosses a primitive of the child it enters first (the cheaper order per candidate and direction "
         "sign) never reaches the other child; segments run to tmax. Operations against bvh-sah, averaged over "
         "the ten SPD scenes: shadow +10.35% on average (was +10.16%; rings +16.8% -> +18.8%, mount "
         "+17.9% -> +18.7%), ao +8.85% (was +9.84%; gears +5.3% -> -0.3%, balls +14.7% -> +10.4%), spd "
         "+6.95% (was +7.23%; balls +1.5% -> -2.5%). Building both trees and keeping the one the sample "
         "prices cheaper: +10.35%, +9.87% and +7.14%, for 1.3x to 1.9x the design time on every distribution "
         "with occlusion rays. Counting occlusion rays to tmax in the order bytes' statistics too: balls shadow "
         "+2.7% -> -1.7%, the averages within 0.5 point. None kept.",
         "- 2026-12-05, for design time, bvh-design's held-out choice of its candidate count among two counts "
         "rather than 8, 16 and 32 (each is a build on half the sample). Operations against bvh-sah over the "
         "60 bvh rows (SPD scenes and meshes): 8 or 32: +9.74% on average (three counts: +9.81%), spd +7.9% "
         "(+8.2%), shadow rays at least 20% fewer on 4 scenes as before; within 10x bvh-sah's build on 21 of "
         "60 rows (13). 8 or 16: +9.01%, spd +8.0%, shadow at least 20% on 1 scene; 23 of 60 rows. Not kept: "
         "the design-time target is missed either way, and the third count designs the cheaper trees.",
         "- 2026-12-05, bvh-design's occlusion order bytes priced weighing at each node only the sample rays "
         "that get to it (which depends on the orders above), every bit turned where that pays, all at once, "
         "sweep after sweep. On rings and gears the bits still changed after 12 sweeps (rings: 38 ms against "
         "13 ms for the kept pricing, which decides each subtree for every ray that enters it, bottom up, and "
         "settles in 3 or 4 sweeps). Shadow operations against bvh-sah (shadow, ao and spd rows of the bvh "
         "family): lattice +24.1% (kept: +23.4%), rings +18.2% (+17.9%), mount +23.8% (+23.8%); spd and ao "
         "averages within 0.1 point. Not kept: at most 0.7 point better, three times as slow, and not settled.",
         "- 2026-12-06, for design time, bvh-design's candidate count chosen without the three held-out builds "
         "(half of its design time). Operations against bvh-sah, averaged over 30 rows (the ten SPD scenes, "
         "shadow, spd and ao rays): the kept held-out choice +10.10%; the best of the three counts row by row "
         "(an oracle) +10.35%. Chosen at each node by two-fold cross-validation of the node's own split (each "
         "half's cheapest cut among the 8, 16 or 32 priced on the other half): +9.69% (mount spd +20.8% "
         "against +23.4%, tree spd -0.2% against +2.9%, balls ao +12.4% against +14.4%; gears spd +1.3% "
         "against -1.0%), for 47% fewer instructions on lattice's shadow rays (callgrind). Those per-node "
         "scores summed over the tree to choose one count for a second build: +9.62%. One count for every "
         "scene: 8 +8.99%, 16 +9.33%, 32 +9.64%, 64 +9.63%. The held-out builds without the sweep: 16% fewer "
         "instructions, another count on 5 of the 30 rows, -0.08 point (rings shadow +17.9% -> +16.7%, "
         "teapot spd +16.5% -> +14.5%). The sweep only at nodes of at least 32 (128) primitives: +9.97% "
         "(+9.84%), 3-5% fewer instructions. Design samples of 1,024 and 2,048 rays instead of 4,096: shadow "
         "+9.9% and +9.95% against +10.7%, spd +7.2% and +7.8% against +8.4% (ten SPD scenes). How much "
         "of the 8- and 16-count held-out builds repeats the 32-count one (the same node, reached by the "
         "same cuts): 98% of the node work on balls' shadow rays, 93-96% on sombrero, 57-76% on rings, "
         "12-34% on mount, 10% on lattice and teapot, so memoising across them saves least where the counts "
         "design different trees. None kept: the held-out choice stays within a quarter point of the oracle.",
         "- Taken up on 2026-12-08: 32 candidates by default, the held-out choice (`--set candidates=auto`) "
         "an option. Measured with `rtcost eval -H bvh-sah,bvh-design:rays=D,bvh-design:rays=D:candidates=32` "
         "(segments estimator, one core) on the 60 bvh rows' scenes and distributions: the design within 10x "
         "bvh-sah's build on 40 of 60 rows (auto: 1; the 20 left are the small scenes, shells, sombrero, "
         "tetra and some of lattice and rings, where drawing the 4,096-ray sample alone is several bvh-sah "
         "builds), for +8.34% operations against bvh-sah on average (auto: +8.77%); shadow rays at least "
         "20% fewer on the same three scenes, ao on the same two; rows that lost most: teapot diffuse "
         "+19.3% -> +15.3%, tree camera +13.1% -> +9.7%, balls diffuse +3.1% -> +0.1%; gained most: balls "
         "spd -4.4% -> +1.5%.",
         "- 2026-12-08, for design time, bvh-design's occlusion order bytes priced from each ray's walk "
         "recorded once (the nodes a ray meets do not depend on the orders, so each later sweep only adds "
         "the recorded costs up again: the same bytes on 15 scene and distribution pairs, and with the "
         "walk at each sweep). Callgrind: the pricing's instructions on lattice's shadow rays halved (156 M "
         "to 80 M), the design's fell 16%; but its wall time rose, 9.7-10.2 ms to 23-31 ms for one tree's "
         "pricing (one core): the 150,000 recorded steps (2.4 MB, written into fresh memory as the vector "
         "grew) cost more in page faults on this VM than the three walks they saved. Not kept.",
         ]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "rtcost"))
    ap.add_argument("--scenes", default=",".join(SPD + MESHES))
    ap.add_argument("--dists", default="camera,shadow,ao,diffuse,spd")
    ap.add_argument("--families", default="all")
    ap.add_argument("--size", default="128x128")
    ap.add_argument("--sample", type=int, default=4096)
    ap.add_argument("--costs", help="costs file passed to rtcost design --costs (default: the design's own)")
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "design.md"))
    ap.add_argument("--sweep-scenes", default=",".join(SPD), help="scenes of the grid and kd sweeps ('' for none)")
    ap.add_argument("--sweep-dist", default="spd")
    ap.add_argument("--from", dest="from_raw", help="render from a raw JSON file this script wrote, running nothing")
    ap.add_argument("--sweeps-only", help="run only the grid and kd sweeps and render them with the rows of this "
                    "raw JSON file (kept with their date)")
    ap.add_argument("--merge", help="run only --scenes x --dists x --families and put those rows in place of the "
                    "same rows of this raw JSON file (the rest, and its sweeps, kept with their date)")
    a = ap.parse_args()
    if sum(bool(x) for x in (a.merge, a.from_raw, a.sweeps_only)) > 1:
        sys.exit("design.py: --merge, --from and --sweeps-only: one of them at most")
    rows = []
    raw_sweeps = {}
    sweeps_date = None
    if a.sweeps_only:
        raw = json.load(open(a.sweeps_only))
        rows, stamp, reruns_kept = raw["rows"], raw["date"], raw.get("reruns", [])
        counts, note = None, raw.get("note")
        a.size, a.sample, a.families, a.sweep_dist = raw["size"], raw["sample"], raw["families"], raw["sweep_dist"]
        sweeps_date = f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC"
    elif a.from_raw:
        raw = json.load(open(a.from_raw))
        rows, raw_sweeps, stamp = raw["rows"], raw["sweeps"], raw["date"]
        sweeps_date = raw.get("sweeps_date")
        counts, note = raw.get("variants"), raw.get("note")
        a.size, a.sample, a.families, a.sweep_dist = raw["size"], raw["sample"], raw["families"], raw["sweep_dist"]
    else:
        counts, note = None, None
        stamp = f"{datetime.datetime.now(datetime.timezone.utc):%Y-%m-%d %H:%M} UTC"
    for scene in ([] if a.from_raw or a.sweeps_only else a.scenes.split(",")):
        path = scene_path(scene)
        if not path.startswith("builtin:") and not os.path.exists(path):
            print(f"skipping {path}: not present", file=sys.stderr)
            continue
        for dist in a.dists.split(","):
            print(f"{os.path.basename(path)} {dist}", file=sys.stderr, flush=True)
            doc, secs = run(a.binary, path, dist, a.families, a.size, a.sample, a.costs)
            for r in doc["results"]:
                rows.append((os.path.basename(path), dist, {"sample": doc["sample"], "test_rays": doc["test_rays"]}, r))
    reruns = []
    if a.merge:
        if not rows:
            sys.exit("design.py: --merge ran no rows (no scene of --scenes present): nothing to merge")
        raw = json.load(open(a.merge))
        fresh = {(r[0], r[1], r[3]["family"]) for r in rows}
        kept = [r for r in raw["rows"] if (r[0], r[1], r[3]["family"]) not in fresh]
        reruns = raw.get("reruns", []) + [{"date": stamp, "scenes": sorted({x[0] for x in fresh}),
                                            "dists": sorted({x[1] for x in fresh}),
                                            "families": sorted({x[2] for x in fresh})}]
        fam_order = {}
        for r in raw["rows"]:
            fam_order.setdefault(r[3]["family"], len(fam_order))
        for r in rows:
            r[3]["run"] = stamp
        rows = kept + rows
        order = {s: i for i, s in enumerate(os.path.basename(scene_path(x)) for x in SPD + MESHES)}
        dists = ["camera", "shadow", "ao", "diffuse", "spd"]
        rows.sort(key=lambda r: (order.get(r[0], len(order)), dists.index(r[1]) if r[1] in dists else 9,
                                 fam_order.get(r[3]["family"], len(fam_order))))
        stamp, raw_sweeps = raw["date"], raw["sweeps"]
        sweeps_date = raw.get("sweeps_date")
        a.size, a.sample, a.families, a.sweep_dist = raw["size"], raw["sample"], raw["families"], raw["sweep_dist"]
        a.sweep_scenes = ""
    elif a.from_raw:
        reruns = raw.get("reruns", [])
    elif a.sweeps_only:
        reruns = reruns_kept
    if not a.from_raw and not a.merge and a.sweep_scenes:
        scenes = [scene_path(x) for x in a.sweep_scenes.split(",")]
        raw_sweeps = sweep_runs(a, [x for x in scenes if x.startswith("builtin:") or os.path.exists(x)])
    if not a.from_raw:
        head = {"date": stamp, "size": a.size, "sample": a.sample, "families": a.families, "sweep_dist": a.sweep_dist,
                "sweeps": raw_sweeps}
        if reruns:
            head["reruns"] = reruns
        if sweeps_date:
            head["sweeps_date"] = sweeps_date
        with open(os.path.splitext(a.out)[0] + ".json", "w") as f:  # one row per line
            f.write("{\n" + "".join(f" {json.dumps(k)}: {json.dumps(v)},\n" for k, v in head.items()) + ' "rows": [\n')
            f.write(",\n".join("  " + json.dumps(r) for r in rows) + "\n ]\n}\n")
    lines = ["# Designed hierarchies against their yardsticks", "",
             "Generated by `scripts/design.py` (do not edit by hand): "
             f"`rtcost design SCENE --rays DIST --size {a.size} --sample {a.sample} --family {a.families} --json`, "
             "pinned to one core (`taskset -c 0`).", "",
             f"Machine: {cpu_name()}, {os.cpu_count()} hardware threads, shared with other jobs while this ran "
             f"(absolute ns are noisy; designed, yardstick and Embree ran back to back on the same rays). "
             f"Date: {stamp}." + "".join(
                 f" Rows run again on {x['date']} (the code of that day, the rest of the table unchanged; each row's "
                 f"designed structure, yardstick, Embree and A/A control still ran in one evaluation): "
                 f"the {', '.join(x['families'])} rows of {', '.join(x['scenes'])} for {', '.join(x['dists'])} rays." for x in reruns), "",
             "The designed structure, its yardstick and Embree are timed in rounds of one pass each, every round "
             "in a new order. Timed passes repeat the same rays, and the branch predictor learns them: a "
             "structure timed alone, or beside an identical twin, runs faster than beside a different structure "
             "traversed by the same code (bvh-sah on tree's diffuse rays: 59 ns per ray alone or beside its twin, "
             "88 to 107 ns beside another BVH; 78 against 80 ns on its 78,000 spd rays). Runs of this table "
             "before 2026-12-05 timed their A/A control beside the yardstick, which sped the yardstick up, and "
             "had every round in one order turned by one; both biased their small rows' gains by up to 6%.", "",
             "Each designed hierarchy draws its own sample of the distribution (the sample size below) and "
             "is measured on every other ray of the distribution (test rays). `predicted`: the model's "
             "operations per ray on the design sample (segments estimator); `measured`: counted operations "
             "per ray on the test rays (unit costs); `ns`: measured single-thread ns per ray on the test "
             "rays; `gain`: 1 - designed ns / yardstick ns; `build`: seconds, the designed one's including "
             "drawing its sample (the design time); `A/A`: 1 - control ns / yardstick ns, the control being the "
             "yardstick's time in a second evaluation of the three structures, built again with the yardstick "
             "first (`rtcost design --control`): this run's noise on that row. The designs minimise "
             + (f"the ns per operation of `{a.costs}`" if a.costs else
                "each family's default costs: for bvh a BVH's own ns per box test against each kind of primitive "
                "test (`typical-bvh`, rtcost's built-in `UnitCosts::typical_bvh`, the margins between BVHs of one "
                "scene that scripts/bvh-prices.py fits), for kd typical ns per operation (`UnitCosts::typical`, "
                "the time model fitted on the twelve scenes of docs/time-model.md, with its step, cache and "
                "polygon-edge terms), operation counts for grid, octree and bsp (`ops`: a polygon "
                "edge walked counts as the share of a test the time model gives it, about a quarter)") + ".", "",
             "| scene | rays | family | sample | test rays | build s (design / yardstick) | predicted ops | measured ops | ns per ray | Embree ns | gain | A/A |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    def aa(r):
        return f"{100 * r['control_gain']:+.1f}%" if "control_gain" in r else "-"
    for scene, dist, doc, r in rows:
        b, p, m, n = r["build_seconds"], r["predicted"], r["measured"], r["ns_per_ray"]
        lines.append(f"| {scene} | {dist} | {r['designed']} vs {r['yardstick']} | {doc['sample']} | {doc['test_rays']} | "
                     f"{b['designed']:.3f} / {b['yardstick']:.3f} | {p['designed']:.1f} / {p['yardstick']:.1f} | "
                     f"{m['designed']:.1f} / {m['yardstick']:.1f} | {n['designed']:.0f} / {n['yardstick']:.0f} | "
                     f"{n['embree']:.0f} | {100 * r['gain']:+.1f}% | {aa(r)} |")
    # Per family and distribution: mean gain and worst case.
    lines += ["", "## Gain by family and distribution", "", "| family | rays | scenes | mean gain | worst | best |",
              "|---|---|---|---|---|---|"]
    groups = {}
    for scene, dist, doc, r in rows:
        groups.setdefault((r["family"], dist), []).append(r["gain"])
    for (fam, dist), g in sorted(groups.items()):
        lines.append(f"| {fam} | {dist} | {len(g)} | {100 * sum(g) / len(g):+.1f}% | {100 * min(g):+.1f}% | {100 * max(g):+.1f}% |")
    if note:
        lines += ["", f"Raw data: {note}."]
    lines += sweep_tables(raw_sweeps, a.sweep_dist, counts, sweeps_date)
    lines += targets(rows, raw_sweeps)
    lines += TRIED
    text = "\n".join(lines) + "\n"
    with open(a.out + ".tmp", "w") as f:
        f.write(text)
    os.replace(a.out + ".tmp", a.out)
    print(text)


if __name__ == "__main__":
    main()
