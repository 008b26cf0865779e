"""Runs one program on several machines and compares them.

    python 03_compare_machines.py [PROGRAM] [--machines A,B,...]

Default: the repository's 3+2 example examples/tilted-holes.nc (a tilted
working plane, the tool turned normal to it, a bolt circle of drilled
holes) on the two built-in trunnions. The tool tip path in the part frame
must be the same on every machine (the program describes the part); the
axes that make it differ. Prints, per machine: the rows, each axis'
range, the machining time `check` estimates and its verdict, and the
largest tip difference from the first machine.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import fiveaxis as fx

REPO = Path(__file__).resolve().parents[3]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("program", nargs="?", default=str(REPO / "examples" / "tilted-holes.nc"))
    parser.add_argument("--machines", default="trunnion-ac,trunnion-bc")
    parser.add_argument("--offsets", default=str(REPO / "examples" / "offsets.toml"))
    args = parser.parse_args()

    first = None
    for name in args.machines.split(","):
        machine = fx.Machine(name)
        try:
            rows = fx.run(args.program, machine, args.offsets)
        except fx.Alarm as alarm:
            print(f"{name}: stops with {alarm.code} at line {alarm.line}: {alarm.message}")
            continue
        report = fx.check(args.program, machine, args.offsets)
        print(f"{name} ({machine.name}): {len(rows)} rows, {report.verdict},"
              f" {report.time.estimated:.1f} s estimated")
        for axis in machine.axes:
            v = rows[axis]
            print(f"    {axis} {v.min():10.3f} .. {v.max():10.3f}")
        if first is None:
            first = rows
        elif len(rows) == len(first):
            gap = np.linalg.norm(rows.tip - first.tip, axis=1).max()
            turn = np.degrees(np.arccos(np.clip((rows.tool * first.tool).sum(axis=1), -1, 1))).max()
            print(f"    tip differs from the first machine by at most {gap:.2e} mm,"
                  f" the tool direction by {turn:.2e} deg")
        else:
            print(f"    {len(rows)} rows against {len(first)}: the programs move differently")


if __name__ == "__main__":
    main()
