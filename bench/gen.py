#!/usr/bin/env python3
"""Generates a seeded 5-axis benchmark program of straight feed moves.

    gen.py BLOCKS OUTPUT [--seed N] [--tcpc | --smooth | --finish | --contour KIND | --splines]

The program is valid for both `fiveaxis run` (FANUC syntax, default machine
`trunnion-ac`) and LinuxCNC's `rs274` (RS274/NGC):

    G21 G90 G94 G17
    G0 X0 Y0 Z0
    F1000.
    G1 X… Y… Z… A… C…     (BLOCKS lines)
    M30

Every value has a decimal point (FANUC reads numbers without one as least
input increments) and stays inside the default machine's soft limits:
X, Y in [-200, 200], Z in [-100, 100], A in [-100, 0], C in [0, 360).
With --tcpc the same number of blocks is written as tool centre point
control type 2 (FANUC G43.5): `G1 X… Y… Z… I… J… K…` with tool vectors
within 60 degrees of +Z, after `G43.5 H0` (for `fiveaxis` only).

Only the Python standard library is used.
"""

import math

import argparse
import random
import sys


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("blocks", type=int, help="number of G1 blocks")
    parser.add_argument("output", help="program file to write")
    parser.add_argument("--seed", type=int, default=5, help="random seed (default 5)")
    parser.add_argument("--tcpc", action="store_true", help="write a G43.5 program")
    parser.add_argument(
        "--contour",
        choices=["plain", "cutter", "comp3d"],
        help="write a 2-D contour (a polygon of BLOCKS sides, radius 200 mm) for the 3-axis mill:"
        " plain, with cutter compensation C (G41 D1), or with 3-D tool compensation (G41 I J K D1)",
    )
    parser.add_argument(
        "--finish",
        action="store_true",
        help="write a G43.5 finishing raster (zig-zag over a sphere cap of radius 250 mm, 200 x 200 mm,"
        " the tool along the surface normal, up to 34 degrees): a smooth path of BLOCKS short blocks",
    )
    parser.add_argument(
        "--smooth",
        action="store_true",
        help="write a smooth 5-axis path for both tools: G1 X Y Z A C blocks 0.5 mm apart along a"
        " wavy spiral, A and C turning a few hundredths of a degree per block (no chord error,"
        " no flip, inside the soft limits)",
    )
    parser.add_argument(
        "--splines",
        action="store_true",
        help="write BLOCKS random LinuxCNC G5 cubic splines in G17 (run on a machine file with"
        " control = \"linuxcnc\"): each a few hundred chords, the program that amplifies most",
    )
    args = parser.parse_args()
    if args.blocks < 1:
        parser.error("blocks must be at least 1")

    rng = random.Random(args.seed)
    uniform = rng.uniform
    if args.contour:
        write_contour(args.blocks, args.output, args.contour)
        return 0
    if args.finish:
        write_finish(args.blocks, args.output)
        return 0
    if args.smooth:
        write_smooth(args.blocks, args.output)
        return 0
    if args.splines:
        with open(args.output, "w", encoding="ascii", newline="\n") as out:
            out.write("G21 G90 G17 G0 X0 Y0 Z100\nG1 F1000\n")
            for _ in range(args.blocks):
                out.write("G5 I%.3f J%.3f P%.3f Q%.3f X%.3f Y%.3f\n" % tuple(uniform(-50.0, 50.0) for _ in range(6)))
            out.write("M2\n")
        return 0
    with open(args.output, "w", encoding="ascii", newline="\n") as out:
        out.write("G21 G90 G94 G17\nG0 X0 Y0 Z0\nF1000.\n")
        if args.tcpc:
            out.write("G43.5 H0 X0 Y0 Z50.\n")
        lines = []
        for i in range(args.blocks):
            if args.tcpc:
                tilt = math.radians(uniform(0.0, 60.0))
                turn = math.radians(uniform(0.0, 360.0))
                lines.append(
                    "G1 X%.3f Y%.3f Z%.3f I%.6f J%.6f K%.6f\n"
                    % (
                        uniform(-150.0, 150.0),
                        uniform(-150.0, 150.0),
                        uniform(0.0, 100.0),
                        math.sin(tilt) * math.cos(turn),
                        math.sin(tilt) * math.sin(turn),
                        math.cos(tilt),
                    )
                )
            else:
                lines.append(
                    "G1 X%.3f Y%.3f Z%.3f A%.3f C%.3f\n"
                    % (
                        uniform(-200.0, 200.0),
                        uniform(-200.0, 200.0),
                        uniform(-100.0, 100.0),
                        uniform(-100.0, 0.0),
                        uniform(0.0, 359.999),
                    )
                )
            if len(lines) == 10000:
                out.writelines(lines)
                lines.clear()
        out.writelines(lines)
        out.write("M30\n")
    return 0


def write_finish(blocks: int, output: str) -> None:
    """A zig-zag raster in X over a sphere cap, passes stepped in Y."""
    radius, top = 250.0, 50.0
    passes = max(1, round(math.sqrt(blocks) / 2.0))
    per_pass = max(1, blocks // passes)
    with open(output, "w", encoding="ascii", newline="\n") as out:
        out.write("G21 G90 G94 G17\nG0 X0 Y0 Z0\nF2000.\nG43.5 H0 X-100. Y-100. Z100.\n")
        lines = []
        written = 0
        for p in range(passes):
            y = -100.0 + 200.0 * p / max(1, passes - 1)
            for k in range(per_pass):
                if written == blocks:
                    break
                f = k / max(1, per_pass - 1)
                x = -100.0 + 200.0 * (f if p % 2 == 0 else 1.0 - f)
                z = math.sqrt(radius * radius - x * x - y * y) - radius + top
                i, j, kk = x / radius, y / radius, (z - top + radius) / radius
                lines.append("G1 X%.4f Y%.4f Z%.4f I%.6f J%.6f K%.6f\n" % (x, y, z, i, j, kk))
                written += 1
                if len(lines) == 10000:
                    out.writelines(lines)
                    lines.clear()
        out.writelines(lines)
        out.write("G49\nM30\n")


def write_smooth(blocks: int, output: str) -> None:
    """A spiral of radius 60 to 180 mm with a wavy Z, the table tilting
    between A-10 and A-50 and turning C slowly with the path: every value
    moves a little per block, as on a finishing path of a 5-axis part."""
    with open(output, "w", encoding="ascii", newline="\n") as out:
        out.write("G21 G90 G94 G17\nG0 X120. Y0 Z20. A-30. C0\nF2000.\n")
        lines = []
        angle = 0.0
        for i in range(blocks):
            f = i / max(1, blocks - 1)
            r = 120.0 + 60.0 * math.sin(2.0 * math.pi * 3.0 * f)
            angle += 0.5 / r  # 0.5 mm along the spiral per block
            x, y = r * math.cos(angle), r * math.sin(angle)
            z = 20.0 + 10.0 * math.sin(7.0 * angle)
            a = -30.0 + 20.0 * math.sin(0.37 * angle)
            c = math.degrees(angle) * 0.25
            lines.append("G1 X%.4f Y%.4f Z%.4f A%.4f C%.4f\n" % (x, y, z, a, c))
            if len(lines) == 10000:
                out.writelines(lines)
                lines.clear()
        out.writelines(lines)
        out.write("M30\n")


def write_contour(blocks: int, output: str, kind: str) -> None:
    """A closed polygon traversed clockwise (outside with G41: no gouging)."""
    with open(output, "w", encoding="ascii", newline="\n") as out:
        out.write("G21 G90 G94 G17\nG0 X0 Y250. Z0\nF1000.\n")
        start = {"plain": "G1", "cutter": "G41 G1", "comp3d": "G41 G1"}[kind]
        lines = []
        for i in range(blocks):
            a = -2.0 * math.pi * i / blocks
            x, y = 200.0 * math.sin(-a), 200.0 * math.cos(a)
            word = start if i == 0 else "G1"
            if kind == "comp3d":
                lines.append("%s X%.7f Y%.7f I%.6f J%.6f K0.5 D1\n" % (word, x, y, x / 200.0, y / 200.0))
            elif i == 0 and kind == "cutter":
                lines.append("%s X%.7f Y%.7f D1\n" % (word, x, y))
            else:
                lines.append("%s X%.7f Y%.7f\n" % (word, x, y))
            if len(lines) == 10000:
                out.writelines(lines)
                lines.clear()
        out.writelines(lines)
        end = {"plain": "", "cutter": "G40 ", "comp3d": "G40 "}[kind]
        out.write("%sG0 X0 Y250.\nM30\n" % end)


if __name__ == "__main__":
    sys.exit(main())
