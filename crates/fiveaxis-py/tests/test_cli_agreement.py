"""`fiveaxis.run` gives the same numbers as `fiveaxis run` to the last bit.

Every program of the command line's fixtures (run as its golden test runs
it: the `(args: ...)` and `(offsets: ...)` comments on its first lines)
and of examples/ is run both ways; the CSV (numbers in their shortest
round-trip form, so parsing gives the exact float) is read back and every
column compared bit for bit. A program the command line stops with an
alarm must raise the same alarm (code, line) with the same rows before it;
one whose input it refuses must raise InputError.
"""

from __future__ import annotations

import csv
import io
import math
import subprocess
import sys
from pathlib import Path
from typing import Any, Dict, List, Optional, Tuple

import numpy as np
import pytest

import fiveaxis as fx

from conftest import EXAMPLES, FIXTURES

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    tomllib = None


def options_of(path: Path) -> Optional[List[str]]:
    """The command-line options a fixture asks for (as golden.rs reads
    them), or None when it asks for something the package does not take."""
    options: List[str] = []
    for line in path.read_text(errors="replace").splitlines():
        line = line.strip()
        if line in ("%", ""):
            continue
        if not (line.startswith("(") and line.endswith(")")):
            break
        key, sep, value = line[1:-1].partition(":")
        if not sep:
            continue
        if key.strip() == "args":
            options += value.split()
        elif key.strip() == "offsets":
            options += ["--offsets", value.strip()]
    return options


def keywords(options: List[str], base: Path) -> Optional[Tuple[List[str], Dict[str, Any]]]:
    """CLI options (without --format) and the matching keywords of
    `fiveaxis.run`; None for an option the package does not have."""
    cli: List[str] = []
    kw: Dict[str, Any] = {}
    i = 0
    while i < len(options):
        o = options[i]
        value = options[i + 1] if i + 1 < len(options) else None
        if o == "--format":
            i += 2
            continue
        if o in ("--block-delete", "--optional-stop"):
            kw[o[2:].replace("-", "_")] = True
            cli.append(o)
            i += 1
            continue
        if o == "--machine":
            spec = value if value in fx.machines() else str(base / value)
            kw["machine"] = spec
        elif o == "--offsets":
            kw["offsets"] = str(base / value)
        elif o == "--step":
            kw["step"] = float(value)
        elif o == "--step-angle":
            kw["step_angle"] = float(value)
        elif o == "--max-blocks":
            kw["max_blocks"] = int(value)
        elif o == "--variables" and tomllib is not None:
            with open(base / value, "rb") as f:
                kw["variables"] = {int(str(k).lstrip("#")): v for k, v in tomllib.load(f).items()}
        else:
            return None
        cli += [o, value]
        i += 2
    return cli, kw


def cli_rows(cli: Path, program: Path, options: List[str]) -> Tuple[int, List[Dict[str, str]], str]:
    done = subprocess.run(
        [str(cli), "run", program.name, *options, "--format", "csv"],
        cwd=program.parent,
        capture_output=True,
        timeout=300,
    )
    text = done.stdout.decode("utf-8")
    rows = list(csv.DictReader(io.StringIO(text))) if text else []
    return done.returncode, rows, done.stderr.decode("utf-8", "replace")


def bits(a: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(a, dtype=np.float64).view(np.uint64)


def assert_same(rows: fx.Rows, expected: List[Dict[str, str]], name: str) -> None:
    assert len(rows) == len(expected), f"{name}: {len(rows)} rows, the CLI {len(expected)}"
    if not expected:
        return
    assert list(rows.names) == list(expected[0].keys()), name
    for column in rows.names:
        got = rows[column]
        want_text = [r[column] for r in expected]
        if column == "line":
            assert np.array_equal(got, np.array([int(t) for t in want_text])), name
        elif column == "motion":
            assert list(rows.motion_names()) == want_text, name
        elif column == "feed":
            want = np.array([math.nan if t == "" else float(t) for t in want_text])
            assert np.array_equal(np.isnan(got), np.isnan(want)), f"{name}: feed blanks"
            ok = ~np.isnan(want)
            assert np.array_equal(bits(got[ok]), bits(want[ok])), f"{name}: feed"
        else:
            want = np.array([float(t) for t in want_text])
            same = bits(got) == bits(want)
            if not same.all():
                i = int(np.argmin(same))
                pytest.fail(f"{name}: column {column} row {i}: {got[i]!r} here, {want_text[i]} from the CLI")


def programs() -> List[Path]:
    found = sorted(FIXTURES.glob("*.nc")) + sorted(EXAMPLES.glob("*.nc"))
    assert len(found) > 20
    return found


EXAMPLE_OPTIONS = {
    "bracket.nc": ["--offsets", "offsets.toml"],
    "pocket.nc": ["--offsets", "offsets.toml", "--step", "10"],
    "subprogram.nc": ["--offsets", "offsets.toml"],
    "tcpc-vector.nc": ["--machine", "head-table-bc", "--offsets", "offsets.toml", "--step", "10"],
    "tcpc-winding.nc": ["--machine", "head-table-bc", "--offsets", "offsets.toml", "--step", "10"],
    "tilted-holes.nc": ["--offsets", "offsets.toml"],
}


@pytest.mark.parametrize("program", programs(), ids=lambda p: p.name)
def test_same_numbers_as_the_cli(cli: Path, program: Path) -> None:
    options = EXAMPLE_OPTIONS.get(program.name) if program.parent == EXAMPLES else options_of(program)
    assert options is not None
    converted = keywords(options, program.parent)
    if converted is None:
        pytest.skip(f"options the package does not take: {options}")
    cli_options, kw = converted
    status, expected, stderr = cli_rows(cli, program, cli_options)
    if status == 0:
        rows = fx.run(program, **kw)
        assert_same(rows, expected, program.name)
    elif status == 1:
        with pytest.raises(fx.Alarm) as info:
            fx.run(program, **kw)
        alarm = info.value
        assert f"ALARM {alarm.code} line {alarm.line}:" in stderr, (stderr, alarm)
        assert alarm.rows is not None
        assert_same(alarm.rows, expected, program.name)
    else:
        with pytest.raises(fx.InputError):
            fx.run(program, **kw)


@pytest.mark.parametrize("program", ["bracket.nc", "tcpc-vector.nc"])
def test_chunks_are_the_whole_run(program: str) -> None:
    kw = dict(machine="head-table-bc", step=2.0) if program == "tcpc-vector.nc" else {}
    whole = fx.run(EXAMPLES / program, offsets=EXAMPLES / "offsets.toml", **kw)
    parts = list(fx.run_chunks(EXAMPLES / program, offsets=EXAMPLES / "offsets.toml", chunk_rows=7, **kw))
    assert len(parts) > 1
    assert all(len(p) >= 7 for p in parts[:-1])
    joined = fx.Rows.concatenate(parts)
    for name in whole.names:
        assert np.array_equal(bits(whole[name].astype(np.float64)), bits(joined[name].astype(np.float64))), name


def test_chunks_end_with_the_alarm() -> None:
    code = "".join(f"G0 X{i}.\n" for i in range(1, 51)) + "G1 X600. F100.\n"
    seen = 0
    with pytest.raises(fx.Alarm) as info:
        for part in fx.run_chunks(code=code, chunk_rows=8):
            seen += len(part)
    assert seen == 50
    assert info.value.code == "OT0500" and info.value.line == 51


def test_text_and_file_give_the_same_rows(tmp_path: Path) -> None:
    text = (EXAMPLES / "bracket.nc").read_bytes()
    a = fx.run(EXAMPLES / "bracket.nc", offsets=EXAMPLES / "offsets.toml")
    b = fx.run(code=text, offsets=EXAMPLES / "offsets.toml")
    c = fx.run(code=text.decode(), offsets=fx.Offsets.from_file(EXAMPLES / "offsets.toml"))
    for name in a.names:
        assert np.array_equal(bits(a[name] * 1.0), bits(b[name] * 1.0)), name
        assert np.array_equal(bits(a[name] * 1.0), bits(c[name] * 1.0)), name


def test_structured_array_holds_the_columns() -> None:
    rows = fx.run(EXAMPLES / "bracket.nc", offsets=EXAMPLES / "offsets.toml")
    table = rows.structured()
    assert table.dtype.names == rows.names and len(table) == len(rows)
    for name in rows.names:
        assert np.array_equal(table[name], rows[name], equal_nan=name == "feed"), name


INTERRUPT = r"""
import os, signal, sys, threading, time
import fiveaxis as fx
# An endless loop: only the block budget or Ctrl-C ends it.
code = "#1=0\nWHILE[#1 LT 1]DO1\nG0 X1.\nG0 X2.\nEND1\nM30\n"
threading.Timer(1.0, lambda: os.kill(os.getpid(), signal.SIGINT)).start()
start = time.monotonic()
try:
    fx.run(code=code, max_blocks=10**12)
except KeyboardInterrupt:
    print("interrupted after", round(time.monotonic() - start, 1))
    sys.exit(0)
print("not interrupted")
sys.exit(1)
"""


def test_ctrl_c_stops_a_long_run() -> None:
    import subprocess
    import sys

    done = subprocess.run([sys.executable, "-c", INTERRUPT], capture_output=True, timeout=120)
    assert done.returncode == 0, done.stdout + done.stderr
    seconds = float(done.stdout.split()[-1])
    assert seconds < 10


def test_program_memory_is_the_cli_programs_folder(cli: Path, tmp_path: Path) -> None:
    memory = tmp_path / "memory"
    memory.mkdir()
    drill = "%\nO9010 (DRILL)\nG0 X#24 Y#25\nG1 Z-#26 F100.\nG0 Z0\nM99\n%\n"
    (memory / "O9010.nc").write_text(drill)
    (memory / "O0042.nc").write_text("O0042\nG0 X99.\nM99\n")
    main = tmp_path / "main.nc"
    main.write_text("G65 P9010 X10. Y20. Z5.\nM98 P42\nG0 X0\nM30\n")
    status, expected, stderr = cli_rows(cli, main, ["--programs", "memory"])
    assert status == 0, stderr
    for programs in ({9010: drill, 42: memory / "O0042.nc"}, {"O9010": drill.encode(), "42": memory / "O0042.nc"}):
        rows = fx.run(main, programs=programs)
        assert_same(rows, expected, "main.nc")
        assert len(list(fx.run_chunks(main, programs=programs, chunk_rows=2))) >= 2
        assert fx.check(main, programs=programs).ended
    with pytest.raises(fx.Alarm) as info:
        fx.run(main, programs={9010: drill})
    assert info.value.code == "PS0078" and info.value.line == 2
    # Neither a number nor a SINUMERIK program name.
    with pytest.raises(fx.InputError):
        fx.run(main, programs={"drill.nc": drill})
    # A name is a SINUMERIK program, which M98 does not call.
    with pytest.raises(fx.Alarm):
        fx.run(main, programs={"O9010X": drill, 42: memory / "O0042.nc"})
    with pytest.raises(fx.InputError):
        fx.run(main, programs={42: tmp_path / "missing.nc"})
    with pytest.raises(TypeError):
        fx.run(main, programs={42: 3.5})  # type: ignore[dict-item]
