#!/usr/bin/env python3
"""Writes an SPD (NFF) scene as a triangle mesh (Wavefront OBJ), for benchmarks on meshes of
100k+ triangles where no real scanned mesh of that size is at hand: polygons become triangle
fans (exact for the convex polygons of balls, rings and tetra), spheres UV spheres of STACKS x
SLICES, cones and cylinders bands of SLICES quads. Loaded through assimp, the triangles are
rtcost triangles (and Embree's own triangles), not NFF polygons.

Usage: python3 scripts/tessellate.py IN.nff OUT.obj [STACKS SLICES]
"""
import math
import sys


def tokens(path):
    with open(path) as f:
        for line in f:
            if line.startswith("#"):
                continue
            yield from line.split()


def main():
    src, dst = sys.argv[1], sys.argv[2]
    stacks = int(sys.argv[3]) if len(sys.argv) > 3 else 10
    slices = int(sys.argv[4]) if len(sys.argv) > 4 else 16
    verts, tris = [], []

    def vert(p):
        verts.append(p)
        return len(verts)  # OBJ indices are 1-based

    def sphere(c, r):
        top = vert((c[0], c[1], c[2] + r))
        bottom = vert((c[0], c[1], c[2] - r))
        rings = []
        for i in range(1, stacks):
            th = math.pi * i / stacks
            rings.append([vert((c[0] + r * math.sin(th) * math.cos(2 * math.pi * j / slices),
                                c[1] + r * math.sin(th) * math.sin(2 * math.pi * j / slices),
                                c[2] + r * math.cos(th))) for j in range(slices)])
        for j in range(slices):
            k = (j + 1) % slices
            tris.append((top, rings[0][j], rings[0][k]))
            tris.append((bottom, rings[-1][k], rings[-1][j]))
            for i in range(len(rings) - 1):
                a, b, c2, d = rings[i][j], rings[i][k], rings[i + 1][k], rings[i + 1][j]
                tris.append((a, d, c2))
                tris.append((a, c2, b))

    def cone(base, rb, apex, ra):
        w = [apex[i] - base[i] for i in range(3)]
        h = math.sqrt(sum(x * x for x in w))
        w = [x / h for x in w]
        a = (1.0, 0.0, 0.0) if abs(w[0]) < 0.9 else (0.0, 1.0, 0.0)
        e1 = [w[1] * a[2] - w[2] * a[1], w[2] * a[0] - w[0] * a[2], w[0] * a[1] - w[1] * a[0]]
        n = math.sqrt(sum(x * x for x in e1))
        e1 = [x / n for x in e1]
        e2 = [w[1] * e1[2] - w[2] * e1[1], w[2] * e1[0] - w[0] * e1[2], w[0] * e1[1] - w[1] * e1[0]]
        rim = []
        for centre, r in ((base, abs(rb)), (apex, abs(ra))):
            rim.append([vert(tuple(centre[i] + r * (math.cos(2 * math.pi * j / slices) * e1[i] +
                                                   math.sin(2 * math.pi * j / slices) * e2[i]) for i in range(3)))
                        for j in range(slices)])
        for j in range(slices):
            k = (j + 1) % slices
            tris.append((rim[0][j], rim[0][k], rim[1][k]))
            tris.append((rim[0][j], rim[1][k], rim[1][j]))

    it = tokens(src)
    num = lambda: float(next(it))
    for t in it:
        if t == "v":
            continue
        if t in ("from", "at", "up"):
            num(); num(); num()
        elif t in ("angle", "hither"):
            num()
        elif t == "resolution":
            num(); num()
        elif t == "b":
            num(); num(); num()
        elif t == "l":
            # position, optionally a colour: peek by reading three and keeping the rest for later
            num(); num(); num()
        elif t == "f":
            for _ in range(8):
                num()
        elif t == "s":
            c = (num(), num(), num())
            sphere(c, abs(num()))
        elif t == "c":
            base = (num(), num(), num()); rb = num()
            apex = (num(), num(), num()); ra = num()
            cone(base, rb, apex, ra)
        elif t in ("p", "pp"):
            n = int(next(it))
            ids = []
            for _ in range(n):
                ids.append(vert((num(), num(), num())))
                if t == "pp":
                    num(); num(); num()
            for i in range(1, n - 1):
                tris.append((ids[0], ids[i], ids[i + 1]))
        else:
            # a light's colour after its position, or anything this script does not know
            try:
                float(t)
            except ValueError:
                sys.exit(f"{src}: unknown NFF entity '{t}'")
    with open(dst, "w") as out:
        out.write(f"# {src} tessellated by scripts/tessellate.py: {len(tris)} triangles\n")
        out.writelines(f"v {p[0]:.7g} {p[1]:.7g} {p[2]:.7g}\n" for p in verts)
        out.writelines(f"f {a} {b} {c}\n" for a, b, c in tris)
    print(f"{dst}: {len(tris)} triangles")


if __name__ == "__main__":
    main()
