#!/usr/bin/env python3
"""Generates a seeded 5-axis APT / CL file of GOTO points for `fiveaxis post`.

    gen_cl.py POINTS OUTPUT [--seed N]

A surface sweep: zig-zag passes over a 160 x 160 mm wavy surface, the tool
vector the surface normal tilted a little more (within 40 degrees of +Z),
every point a `GOTO/x,y,z,i,j,k` at `FEDRAT/1200,MMPM`, with a tool load,
spindle and coolant around it. Only the Python standard library is used.
"""

import argparse
import math
import random


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("points", type=int)
    parser.add_argument("output")
    parser.add_argument("--seed", type=int, default=13)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    a, b = rng.uniform(4.0, 8.0), rng.uniform(4.0, 8.0)
    passes = max(2, int(math.sqrt(args.points / 4)))
    per_pass = max(2, -(-args.points // passes))
    lines = ["PARTNO/SWEEP", "UNIT/MM", "LOAD/TOOL,1", "SPINDL/12000,RPM,CLW", "COOLNT/ON"]

    def surface(x, y):
        z = a * math.sin(x / 25.0) + b * math.cos(y / 30.0)
        dzdx = a / 25.0 * math.cos(x / 25.0)
        dzdy = -b / 30.0 * math.sin(y / 30.0)
        n = (-dzdx * 1.3, -dzdy * 1.3, 1.0)
        norm = math.sqrt(sum(c * c for c in n))
        return z, tuple(c / norm for c in n)

    count = 0
    for k in range(passes):
        y = -80.0 + 160.0 * k / (passes - 1)
        for i in range(per_pass):
            if count == args.points:
                break
            t = i / (per_pass - 1)
            x = -80.0 + 160.0 * (t if k % 2 == 0 else 1.0 - t)
            z, (ni, nj, nk) = surface(x, y)
            if count == 0:
                lines.append("RAPID")
                lines.append(f"GOTO/{x:.4f},{y:.4f},{z + 20:.4f},{ni:.7f},{nj:.7f},{nk:.7f}")
                lines.append("FEDRAT/1200.0000,MMPM")
            lines.append(f"GOTO/{x:.4f},{y:.4f},{z:.4f},{ni:.7f},{nj:.7f},{nk:.7f}")
            count += 1
    lines += ["COOLNT/OFF", "SPINDL/OFF", "FINI"]
    with open(args.output, "w") as f:
        f.write("\n".join(lines) + "\n")


if __name__ == "__main__":
    main()
