"""Finds where a program's tool passes near the singular direction.

    python 02_singular_passages.py [PROGRAM] [--machine NAME] [--cone DEG]

At the singular direction the tool lies on the line of the rotary axis
that turns about it (the C table of a B/C or A/C machine at B or A = 0):
that axis is free there, and a path passing close to it makes it swing
fast. From the rows of the program (every 0.5 mm / 0.5 degree) this
measures the angle between the tool and that axis line in the part
frame, lists the passages closer than --cone degrees, and puts them
beside the `singular_passage` findings of `fiveaxis.check`, which finds
them in closed form.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import List, Tuple

import numpy as np

import fiveaxis as fx

REPO = Path(__file__).resolve().parents[3]


def singular_line(machine: fx.Machine) -> np.ndarray:
    """The direction, fixed in the part frame, of the axis whose line the
    tool must not approach: the table axis nearest the part if there is
    one (it carries the part), else the head axis on the carriage."""
    rotary = machine.rotary_axes
    tables = [a for a in rotary if a["on"] == "table"]
    axis = tables[-1] if tables else rotary[0]
    v = np.array(axis["axis"])
    return v / np.linalg.norm(v)


def passages(rows: fx.Rows, line: np.ndarray, cone: float) -> List[Tuple[int, float]]:
    """(program line, smallest angle in degrees) of each run of feed rows
    within `cone` degrees of the line."""
    cos = np.abs(rows.tool @ line)
    angle = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    near = (angle < cone) & ~np.isnan(rows.feed)
    out: List[Tuple[int, float]] = []
    i = 0
    while i < len(near):
        if not near[i]:
            i += 1
            continue
        j = i
        while j + 1 < len(near) and near[j + 1]:
            j += 1
        k = i + int(np.argmin(angle[i : j + 1]))
        out.append((int(rows.line[k]), float(angle[k])))
        i = j + 1
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("program", nargs="?", default=str(REPO / "examples" / "tcpc-vector.nc"))
    parser.add_argument("--machine", default="head-table-bc")
    parser.add_argument("--offsets", default=str(REPO / "examples" / "offsets.toml"))
    parser.add_argument("--cone", type=float, default=2.0)
    args = parser.parse_args()

    machine = fx.Machine(args.machine)
    rows = fx.run(args.program, machine, args.offsets, step=0.5, step_angle=0.5)
    found = passages(rows, singular_line(machine), args.cone)
    print(f"{Path(args.program).name} on {machine.name}: {len(rows)} rows")
    print(f"from the rows ({args.cone} deg cone):")
    for line, angle in found:
        print(f"  line {line:<5} {angle:8.4f} deg from the singular direction")
    report = fx.check(args.program, machine, args.offsets)
    singular = [f for f in report.findings if f.kind == "singular_passage"]
    print(f"from fiveaxis.check ({machine.parameters['singular_cone']} deg cone):")
    for f in singular:
        print(f"  line {f.line:<5} {f.value:8.4f} deg")
    lines_rows = sorted({line for line, _ in found})
    lines_check = sorted({f.line for f in singular})
    print("same lines" if lines_rows == lines_check else f"rows: {lines_rows}, check: {lines_check}")


if __name__ == "__main__":
    main()
