"""Plots every machine axis of a program against time with matplotlib.

    python 01_axes_against_time.py [PROGRAM] [--machine NAME] [--out DIR]

Default: the repository's examples/tcpc-vector.nc on the swivel-head
machine, rows every 1 mm / 1 degree. The time of each row is the
programmed time: a feed move takes its tip path at F, a rapid its longest
axis travel at that axis' rapid rate. Writes axes.png into --out (a
temporary folder when not given) and prints its path.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

import fiveaxis as fx  # noqa: E402

REPO = Path(__file__).resolve().parents[3]


def row_times(rows: fx.Rows, machine: fx.Machine) -> np.ndarray:
    """Programmed time of each row, seconds from the first."""
    joints = rows.joints
    tip_step = np.linalg.norm(np.diff(rows.tip, axis=0), axis=1)
    axis_step = np.abs(np.diff(joints, axis=0))
    rapid_rates = np.array(
        [a["dynamics"]["rapid"] for a in machine.linear_axes + machine.rotary_axes]
    )
    rapid_minutes = (axis_step / rapid_rates).max(axis=1)
    feed = rows.feed[1:]
    with np.errstate(invalid="ignore", divide="ignore"):
        feed_minutes = np.where(np.isnan(feed), rapid_minutes, tip_step / feed)
    return np.concatenate([[0.0], np.cumsum(feed_minutes) * 60.0])


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("program", nargs="?", default=str(REPO / "examples" / "tcpc-vector.nc"))
    parser.add_argument("--machine", default="head-table-bc")
    parser.add_argument("--offsets", default=str(REPO / "examples" / "offsets.toml"))
    parser.add_argument("--out", default=None)
    args = parser.parse_args()

    machine = fx.Machine(args.machine)
    rows = fx.run(args.program, machine, args.offsets, step=1.0)
    t = row_times(rows, machine)

    fig, plots = plt.subplots(len(machine.axes), 1, sharex=True, figsize=(8, 1.8 * len(machine.axes)))
    for ax, name in zip(plots, machine.axes):
        ax.plot(t, rows[name], lw=1)
        ax.set_ylabel(f"{name} ({'mm' if name in 'XYZUVW' else 'deg'})")
        limits = machine.limits[name]
        if limits is not None:
            lo, hi = limits
            inside = rows[name]
            # Show a limit only when the axis comes near it.
            for lim in (lo, hi):
                if abs(lim - inside).min() < 0.25 * (hi - lo):
                    ax.axhline(lim, color="red", ls="--", lw=0.8)
        ax.grid(alpha=0.3)
    plots[-1].set_xlabel("programmed time (s)")
    fig.suptitle(f"{Path(args.program).name} on {machine.name}: {len(rows)} rows")
    fig.tight_layout()

    out = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="fiveaxis-"))
    out.mkdir(parents=True, exist_ok=True)
    png = out / "axes.png"
    fig.savefig(png, dpi=100)
    print(f"{len(rows)} rows over {t[-1]:.1f} s programmed; plot: {png}")


if __name__ == "__main__":
    main()
