"""Every numbered example runs as a script, and says what it should."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

import fiveaxis as fx

from conftest import PY_EXAMPLES, REPO

EXAMPLES = sorted(PY_EXAMPLES.glob("[0-9][0-9]_*.py"))


def run(script: Path, *args: str) -> str:
    done = subprocess.run(
        [sys.executable, str(script), *args], capture_output=True, timeout=600, cwd=script.parent
    )
    assert done.returncode == 0, done.stderr.decode(errors="replace")
    return done.stdout.decode()


def test_there_are_four_numbered_examples() -> None:
    assert [p.name[:3] for p in EXAMPLES] == ["01_", "02_", "03_", "04_"]


def test_axes_against_time_writes_a_png(tmp_path: Path) -> None:
    out = run(PY_EXAMPLES / "01_axes_against_time.py", "--out", str(tmp_path))
    png = tmp_path / "axes.png"
    assert png.is_file() and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # The programmed time the example adds up from the rows is the one
    # `check` computes from the blocks.
    seconds = float(out.split("rows over ")[1].split(" s")[0])
    report = fx.check(REPO / "examples" / "tcpc-vector.nc", "head-table-bc", REPO / "examples" / "offsets.toml")
    assert abs(seconds - report.time.programmed) <= 0.01 * report.time.programmed


def test_singular_passages_agree_with_check() -> None:
    out = run(PY_EXAMPLES / "02_singular_passages.py")
    assert "same lines" in out
    assert "line 9 " in out


def test_compare_machines_same_tip() -> None:
    out = run(PY_EXAMPLES / "03_compare_machines.py")
    assert out.count("rows,") == 2
    gap = float(out.split("at most ")[1].split(" mm")[0])
    assert gap < 1e-9


def test_convert_cl_data_sample() -> None:
    out = run(PY_EXAMPLES / "04_convert_cl_data.py")
    assert "passes every GOTO point" in out


CORPUS_APT = REPO.parent / "shared" / "corpus" / "cl_solidworks_boss.apt"


@pytest.mark.skipif(not CORPUS_APT.is_file(), reason="../shared/corpus is not beside the repository")
def test_convert_cl_data_corpus() -> None:
    out = run(PY_EXAMPLES / "04_convert_cl_data.py", str(CORPUS_APT), "--tool-length", "76")
    assert "9814 GOTO points" in out and "passes every GOTO point" in out
