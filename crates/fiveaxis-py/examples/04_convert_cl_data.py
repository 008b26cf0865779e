"""Converts CL data (APT) into a machine-axis program and checks it.

    python 04_convert_cl_data.py [FILE.apt] [--machine NAME] [--tool-length MM]

CAM systems write tool paths as CL data: `GOTO/x,y,z,i,j,k` points with
tool vectors in the part. `fiveaxis.apt_to_tcpc` makes a TCPC program of
them (G43.5); `fiveaxis.post` turns that into straight moves of the
machine's own axes within 0.01 mm and 0.1 degree, for a control without
TCPC. The posted program is then run on the machine with TCPC off, and
every GOTO point is looked for among its rows (forward kinematics of the
machine axes): the conversion is judged by where the tool really goes.

Default: examples/data/sample.apt beside this script. The corpus's
SolidWorks CL file works too (../shared/corpus/cl_solidworks_boss.apt,
--tool-length 76). The G54 of the default offsets is the machine zero, so
part and table frames are the same here.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

import fiveaxis as fx

HERE = Path(__file__).resolve().parent


def goto_points(text: str) -> np.ndarray:
    """The GOTO points of APT text, read separately from the converter."""
    points = []
    for line in text.splitlines():
        if line.strip().upper().startswith("GOTO/"):
            values = [float(v) for v in line.strip()[5:].split(",")]
            points.append(values[:3])
    return np.array(points)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("file", nargs="?", default=str(HERE / "data" / "sample.apt"))
    parser.add_argument("--machine", default="head-table-bc")
    parser.add_argument("--tool-length", type=float, default=100.0)
    args = parser.parse_args()

    text = Path(args.file).read_text()
    offsets = {"tools": {n: {"length": args.tool_length} for n in range(1, 10)}}
    tcpc = fx.apt_to_tcpc(text, Path(args.file).name)
    print(f"{Path(args.file).name}: {len(goto_points(text))} GOTO points,"
          f" TCPC program of {tcpc.count(chr(10))} lines")
    try:
        result = fx.post(args.file, args.machine, offsets, apt=True)
    except fx.Alarm as alarm:
        print(f"post: the TCPC program stops with {alarm.code} at line {alarm.line}: {alarm.message}")
        report = fx.check(code=tcpc, machine=args.machine, offsets=offsets)
        print(f"check: {report.summary()}; {report.counts()}")
        return
    print(f"post: {result.source_blocks} cutting blocks in, {result.blocks} blocks out;"
          f" largest deviation {result.deviation_tip:.5f} mm, {result.deviation_angle:.5f} deg")
    machine = fx.Machine(args.machine)
    rows = fx.run(code=result.text, machine=machine, offsets=offsets)
    # The posted program runs without length compensation (G49): its rows'
    # tips are the gauge point. The tool tip is forward kinematics of the
    # machine axes with the tool length the program was posted for.
    tips, _ = machine.forward(rows.joints, args.tool_length)
    points = goto_points(text)
    misses = [np.linalg.norm(tips - p, axis=1).min() for p in points]
    print(f"the machine-axis program, run without TCPC ({len(rows)} rows), passes every GOTO point"
          f" within {max(misses):.2e} mm")
    assert max(misses) < 1e-3


if __name__ == "__main__":
    main()
