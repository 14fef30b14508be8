#!/usr/bin/env python3
"""Fits the ns per operation that bvh-design trades against each other: a BVH's box test against
each kind of primitive test, as they move *within* one scene and distribution.

`rtcost calibrate` fits one table for every hierarchy across scenes; its step price is mostly the
cell structures', and its primitive prices mix what a test costs with what the scenes around it
cost. A BVH design needs the margin instead: how many ns a ray gains when a split saves box tests
and adds primitive tests. So each scene and distribution here gets bvh-sah built with several
traversal costs (larger and smaller leaves), all timed in one `rtcost eval --interleave` run on one
core, and the fit gives every (scene, distribution) its own fixed ns per ray: only the differences
between a scene's trees decide the prices. A BVH visits two boxes per step, so the box price holds
the step's.

Usage: python3 scripts/bvh-prices.py [--binary build/rtcost] [--out prices.json]
"""
import argparse
import json
import os
import subprocess
import sys

import numpy as np

SPD = ["balls", "gears", "lattice", "mount", "rings", "shells", "sombrero", "teapot", "tetra", "tree"]
# Meshes of triangles, as docs/design.md.
MESHES = ["/usr/share/assimp/models/glTF2/2CylinderEngine-glTF-Binary/2CylinderEngine.glb",
          "/usr/share/assimp/models/BLEND/yxa_1.blend"]
VARIANTS = ["bvh-sah:c_trav=0.5", "bvh-sah", "bvh-sah:c_trav=2", "bvh-sah:c_trav=3", "bvh-sah:c_trav=5"]
KINDS = ["triangle", "polygon", "sphere", "cone"]


def runs(binary, scene, dist, size):
    cmd = ["taskset", "-c", "0", binary, "eval", scene, "--rays", dist, "--size", size, "-H", ",".join(VARIANTS),
           "--estimator", "segments", "--interleave", "--json", "-q", "-j", "1"]
    doc = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    for r in doc["results"]:
        m = r["measured"]
        yield [m["box"]] + [m["prim_by_kind"][k] for k in KINDS] + [m["polygon_edges"]], r["time"]["measured_ns_per_ray"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--binary", default="build/rtcost")
    ap.add_argument("--shared", default=os.environ.get("RTCOST_SHARED", "../shared"))
    ap.add_argument("--dists", default="camera,diffuse,spd")
    ap.add_argument("--size", default="128x128")
    ap.add_argument("--out", default="bvh-prices.json")
    a = ap.parse_args()
    rows, groups = [], []
    scenes = [os.path.join(a.shared, "scenes", "spd", name + ".nff") for name in SPD] + MESHES
    for scene in scenes:
        if not os.path.exists(scene):
            sys.exit(f"bvh-prices: {scene} not found (--shared, or the assimp models)")
        name = os.path.basename(scene)
        for dist in a.dists.split(","):
            print(f"{name} {dist}", file=sys.stderr, flush=True)
            for x, ns in runs(a.binary, scene, dist, a.size):
                rows.append((len(groups), x, ns))
            groups.append(f"{name}/{dist}")
    # ns = intercept[group] + sum(price * count), each run weighed by 1/ns (relative error).
    terms = 1 + len(KINDS) + 1
    X = np.zeros((len(rows), len(groups) + terms))
    y = np.array([ns for _, _, ns in rows])
    for i, (g, x, _) in enumerate(rows):
        X[i, g] = 1
        X[i, len(groups):] = x
    w = 1 / y
    coef, *_ = np.linalg.lstsq(X * w[:, None], y * w, rcond=None)
    prices = coef[len(groups):]
    residual = (X @ coef - y) / y
    out = {"box": prices[0], "prim": dict(zip(KINDS, prices[1:1 + len(KINDS)])), "polygon_edge": prices[-1],
           "rms_relative_residual": float(np.sqrt(np.mean(residual ** 2))), "runs": len(rows),
           "variants": VARIANTS, "dists": a.dists, "size": a.size}
    out["box"] = float(out["box"])
    out["prim"] = {k: float(v) for k, v in out["prim"].items()}
    out["polygon_edge"] = float(out["polygon_edge"])
    with open(a.out, "w") as f:
        json.dump(out, f, indent=1)
    print(json.dumps({k: out[k] for k in ("box", "prim", "polygon_edge", "rms_relative_residual")}))


if __name__ == "__main__":
    main()
