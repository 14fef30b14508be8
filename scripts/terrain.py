#!/usr/bin/env python3
"""Writes a heightfield terrain as an OBJ mesh, stored row by row as scanned terrains are: the
large-mesh case of `rtcost eval` (docs/benchmarks.md). N x N quads, two triangles each.

    python3 scripts/terrain.py OUT.obj [N]     # N = 708: 1,002,528 triangles
"""
import math
import sys


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    out = sys.argv[1]
    n = int(sys.argv[2]) if len(sys.argv) == 3 else 708
    if not 1 <= n <= 4096:
        sys.exit("terrain.py: N must be in 1..4096")
    with open(out, "w") as f:
        w = f.write
        for j in range(n + 1):
            for i in range(n + 1):
                x, y = i / n, j / n
                z = 0.05 * math.sin(12 * x) * math.cos(9 * y) + 0.02 * math.sin(37 * x + 23 * y)
                w(f"v {x:.6f} {y:.6f} {z:.6f}\n")
        for j in range(n):
            for i in range(n):
                a = j * (n + 1) + i + 1
                b, c = a + 1, a + n + 1
                w(f"f {a} {b} {c + 1}\nf {a} {c + 1} {c}\n")
    print(f"{out}: {2 * n * n} triangles")


if __name__ == "__main__":
    main()
