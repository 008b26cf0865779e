"""Rows per second of `fiveaxis.run` into numpy on the benchmark program.

    python crates/fiveaxis-py/bench/run_rows.py [--blocks N] [--repeat R]

Makes the seeded 200,000-block program of bench/gen.py (random
`G1 X Y Z A C` moves on trunnion-ac, as bench/run.sh does), then times
`fiveaxis.run` on it R times (best and median): every row's 15 columns
in numpy arrays, no text formatting on the way. Also with `step=5`
(rows inside the blocks, about 127 per block) and through `run_chunks`.
The command line's time on the same program (CSV to /dev/null) is shown
when a release `fiveaxis` binary is found (FIVEAXIS_BIN or target/).
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import fiveaxis as fx

REPO = Path(__file__).resolve().parents[3]


def timed(fn, repeat: int):
    times, n = [], 0
    for _ in range(repeat):
        t = time.perf_counter()
        n = fn()
        times.append(time.perf_counter() - t)
    return n, min(times), statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--blocks", type=int, default=200_000)
    parser.add_argument("--repeat", type=int, default=7)
    parser.add_argument("--seed", type=int, default=5)
    args = parser.parse_args()

    work = Path(tempfile.mkdtemp(prefix="fiveaxis-bench-"))
    program = work / "bench.nc"
    subprocess.run(
        [sys.executable, str(REPO / "bench" / "gen.py"), str(args.blocks), str(program), "--seed", str(args.seed)],
        check=True,
    )
    fx.run(program)  # warm the page cache
    print(f"program: bench/gen.py {args.blocks} --seed {args.seed} ({program.stat().st_size / 1e6:.1f} MB), machine trunnion-ac")
    cases = [
        ("run", lambda: len(fx.run(program))),
        ("run_chunks", lambda: sum(len(c) for c in fx.run_chunks(program))),
        ("run step=5", lambda: len(fx.run(program, step=5.0))),
    ]
    for name, fn in cases:
        repeat = args.repeat if "step" not in name else max(1, args.repeat // 3)
        n, best, median = timed(fn, repeat)
        print(f"{name:<12} {n:>11,} rows  best {best:7.3f} s  median {median:7.3f} s"
              f"  {n / best / 1e6:6.2f} M rows/s (best)  {n / median / 1e6:6.2f} M rows/s (median)")
    cli = os.environ.get("FIVEAXIS_BIN") or next(
        (str(p) for p in [REPO / "target" / "release" / "fiveaxis"] if p.is_file()), None
    )
    if cli:
        def cli_run() -> int:
            subprocess.run([cli, "run", str(program), "-o", "/dev/null"], check=True)
            return args.blocks
        n, best, median = timed(cli_run, args.repeat)
        print(f"{'CLI csv':<12} {n:>11,} rows  best {best:7.3f} s  median {median:7.3f} s"
              f"  {n / best / 1e6:6.2f} M rows/s (best)")


if __name__ == "__main__":
    main()
