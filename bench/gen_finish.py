#!/usr/bin/env python3
"""Writes a seeded 5-axis finishing program and its work for `check`.

    gen_finish.py BLOCKS OUTPUT.nc [--fixture OUT.stl --triangles N]

The program (FANUC syntax, built-in machine `trunnion-ac`, tool 1 of
`bench/finish-offsets.toml`) finishes the surface
z = 4·sin(x/15)·cos(y/20) − 6 over a 100 × 100 mm stock
(`box:-50,-50,-40,50,50,0`) with a ball mill under tool centre point
control type 1 (G43.4): raster lines along X, 0.1 mm apart along a line
and spaced so that BLOCKS blocks cover the square, the table tilted 10° to
20° (A) and turning slowly (C) as the line advances.

With --fixture it also writes a binary STL: a round fixture plate of N
triangles under the stock (z −60 to −40, radius 80), finely tessellated
as a scanned or CAD fixture is.

Only the Python standard library is used.
"""

import argparse
import math
import struct
import sys


def surface(x: float, y: float) -> float:
    return 4.0 * math.sin(x / 15.0) * math.cos(y / 20.0) - 6.0


def program(blocks: int, out) -> None:
    per_line = 1001
    lines = max(1, -(-blocks // per_line))
    out.write("%\nO2700 (FINISHING, BALL MILL, G43.4)\nG21 G17 G90 G94 G54\n")
    out.write("T1 M6\nG0 A0. C0.\nG43.4 H1 X-55. Y-50. Z20. A-10. C0.\nF2000.\n")
    written = 0
    for j in range(lines):
        y = -50.0 + 100.0 * j / max(1, lines - 1)
        a = -10.0 - 10.0 * j / max(1, lines - 1)
        c = 5.0 * math.sin(j / 20.0)
        forward = j % 2 == 0
        for k in range(per_line):
            if written >= blocks:
                break
            t = k / (per_line - 1)
            x = -50.0 + 100.0 * (t if forward else 1.0 - t)
            out.write(f"G1 X{x:.4f} Y{y:.4f} Z{surface(x, y):.4f} A{a:.4f} C{c:.4f}\n")
            written += 1
    out.write("G0 Z50.\nG49 Z200.\nM30\n%\n")


def fixture(path: str, triangles: int) -> None:
    """A closed cylinder z −60..−40, radius 80, of about `triangles`."""
    # n around, m rings on the side, fans on the caps: 2·n·m + 2·n.
    n = max(16, int(math.sqrt(triangles / 4.0)) * 2)
    m = max(1, (triangles - 2 * n) // (2 * n))
    r, z0, z1 = 80.0, -60.0, -40.0
    tris = []

    def p(i: int, z: float):
        a = 2.0 * math.pi * (i % n) / n
        return (r * math.cos(a), r * math.sin(a), z)

    for i in range(n):
        for k in range(m):
            za = z0 + (z1 - z0) * k / m
            zb = z0 + (z1 - z0) * (k + 1) / m
            tris.append((p(i, za), p(i + 1, za), p(i + 1, zb)))
            tris.append((p(i, za), p(i + 1, zb), p(i, zb)))
        tris.append(((0.0, 0.0, z1), p(i, z1), p(i + 1, z1)))
        tris.append(((0.0, 0.0, z0), p(i + 1, z0), p(i, z0)))
    with open(path, "wb") as f:
        f.write(b"fiveaxis bench fixture".ljust(80, b" "))
        f.write(struct.pack("<I", len(tris)))
        for t in tris:
            f.write(struct.pack("<3f", 0.0, 0.0, 0.0))
            for v in t:
                f.write(struct.pack("<3f", *v))
            f.write(b"\0\0")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blocks", type=int)
    parser.add_argument("output")
    parser.add_argument("--fixture")
    parser.add_argument("--triangles", type=int, default=100_000)
    args = parser.parse_args()
    with open(args.output, "w") as out:
        program(args.blocks, out)
    if args.fixture:
        fixture(args.fixture, args.triangles)
    return 0


if __name__ == "__main__":
    sys.exit(main())
