"""Every kind of bad input gives a clear exception, never a crash: bad
programs (alarms with code, line, column), bad machine and offsets files
(line, column, key), unknown machine names, missing files, arrays of the
wrong shape or holding NaN, bad options and wrong types."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import fiveaxis as fx

from conftest import EXAMPLES


def test_alarm_carries_code_line_column_message_and_rows() -> None:
    with pytest.raises(fx.Alarm) as info:
        fx.run(code="G0 X10.\nG1 X600. F100.\n")
    a = info.value
    assert (a.code, a.line, a.column) == ("OT0500", 2, 4)
    assert "soft limit 500" in a.message
    assert a.text == "G1 X600. F100."
    assert a.program == "<string>"
    assert len(a.rows) == 1 and a.rows["X"][0] == 10.0
    assert str(a).startswith("OT0500 line 2:")
    assert isinstance(a, fx.FiveaxisError)


@pytest.mark.parametrize(
    "code, alarm",
    [
        ("G0 X10.\nG500\n", "PS0010"),
        ("G1 X10.\n", "PS0011"),
        ("G0 X10. Q\n", None),
        ("#1=1/0\n", None),
        ("M98 P1234\n", "PS0078"),
        ("G1 X1. F100. Z\n", None),
    ],
)
def test_bad_programs_raise_alarms(code: str, alarm: str) -> None:
    with pytest.raises(fx.Alarm) as info:
        fx.run(code=code)
    if alarm is not None:
        assert info.value.code == alarm
    assert info.value.line >= 1 and info.value.message


def test_check_reports_an_alarm_as_a_finding() -> None:
    report = fx.check(code="G0 X10.\nG500\n")
    assert not report.ended and report.alarm is not None and report.alarm.code == "PS0010"
    assert report.verdict == "FAIL" and report.counts()["alarm"] == 1


def test_post_raises_the_source_alarm() -> None:
    with pytest.raises(fx.Alarm):
        fx.post(code="G43.5 H1\nG1 X10. I1. J0 K0 F100.\nG500\n", machine="head-table-bc")


@pytest.mark.parametrize("kw", [{"feed": "fast"}, {"retract": -1.0}, {"retract": float("nan")},
                                {"tool_length": float("inf")}, {"tolerance": 0.0}])
def test_post_refuses_bad_options(kw: dict) -> None:
    with pytest.raises(fx.InputError):
        fx.post(code="G43.5 H1\nG1 X10. I0 J0 K1. F100.\nM30\n", machine="head-table-bc", **kw)


def test_bad_machine_toml_names_line_column_key() -> None:
    with pytest.raises(fx.InputError) as info:
        fx.Machine.from_toml('name = "m"\ntype = "table"\n[[linear]]\nname = "X"\nmin = "low"\n', "m.toml")
    e = info.value
    assert e.file == "m.toml" and e.line == 5 and e.column is not None
    assert "m.toml:5:" in str(e)
    with pytest.raises(fx.InputError):
        fx.Machine.from_toml("this is [not toml")
    with pytest.raises(fx.InputError) as info:
        fx.Machine.from_toml(re.sub(r"min = -?[0-9.]+", "min = -1e300", fx.Machine().to_toml(), count=1))
    assert info.value.line is not None


def test_bad_machine_file_and_unknown_names(tmp_path: Path) -> None:
    with pytest.raises(fx.InputError, match="not a built-in machine"):
        fx.Machine("no-such-machine")
    with pytest.raises(fx.InputError, match="neither a built-in machine nor a machine file"):
        fx.run(code="G0 X1.\n", machine="no-such-machine")
    with pytest.raises(fx.InputError):
        fx.Machine.from_file(tmp_path / "missing.toml")
    binary = tmp_path / "binary.toml"
    binary.write_bytes(b'name = "\xff\xfe"\n')
    with pytest.raises(fx.InputError, match="UTF-8") as info:
        fx.Machine.from_file(binary)
    assert info.value.line == 1
    big = tmp_path / "big.toml"
    big.write_bytes(b"#" * (2 << 20))
    with pytest.raises(fx.InputError, match="larger than"):
        fx.Machine.from_file(big)
    with pytest.raises(TypeError):
        fx.Machine(42)  # type: ignore[arg-type]


def test_bad_offsets(tmp_path: Path) -> None:
    with pytest.raises(fx.InputError) as info:
        fx.Offsets({"tools": {1: {"length": float("nan")}}})
    assert "tools.1.length" in str(info.value)
    with pytest.raises(fx.InputError):
        fx.Offsets({"tools": {1000: {"length": 1.0}}})
    with pytest.raises(fx.InputError):
        fx.Offsets({"tools": {1: {"lenght": 1.0}}})
    with pytest.raises(fx.InputError):
        fx.Offsets({"work": {"G54": [0.0, 0.0]}})
    with pytest.raises(fx.InputError):
        fx.Offsets({"tools": {1: {"length": object()}}})
    with pytest.raises(fx.InputError):
        fx.Offsets.from_toml("[tools]\n1 = { length = 1e9 }\n")
    with pytest.raises(fx.InputError):
        fx.run(code="G0 X1.\n", offsets=tmp_path / "missing.toml")
    with pytest.raises(TypeError):
        fx.run(code="G0 X1.\n", offsets=12)  # type: ignore[arg-type]


def test_offsets_from_a_dict_are_those_of_the_file() -> None:
    as_dict = {
        "tools": {1: {"length": 120.0, "radius": 5.0}, "2": {"length": 95.5, "radius": 3.0}},
        "work": {"G54": (0.0, 0, 50.0), "G55": np.array([-40.0, 30.0, 50.0])},
    }
    a = fx.run(EXAMPLES / "bracket.nc", offsets=as_dict)
    b = fx.run(EXAMPLES / "bracket.nc", offsets=EXAMPLES / "offsets.toml")
    for name in a.names:
        assert np.array_equal(a[name], b[name], equal_nan=True), name
    assert fx.Offsets(as_dict).tools[1]["length"] == 120.0


def test_missing_and_unreadable_programs(tmp_path: Path) -> None:
    with pytest.raises(fx.InputError) as info:
        fx.run(tmp_path / "missing.nc")
    assert info.value.file is not None and "missing.nc" in info.value.file
    with pytest.raises(fx.InputError, match="directory"):
        fx.run(tmp_path)
    long_line = tmp_path / "long.nc"
    long_line.write_bytes(b"G0 X1." + b"0" * (70 * 1024) + b"\n")
    with pytest.raises(fx.InputError, match="longer than"):
        fx.run(long_line)
    with pytest.raises(fx.InputError):
        fx.run()
    with pytest.raises(fx.InputError):
        fx.run(EXAMPLES / "bracket.nc", code="G0 X1.\n")
    with pytest.raises(fx.InputError):
        fx.check(tmp_path / "missing.nc")
    with pytest.raises(fx.InputError):
        fx.post(tmp_path / "missing.nc")


@pytest.mark.parametrize(
    "kw",
    [dict(step=0.0), dict(step=-1.0), dict(step=float("nan")), dict(step_angle=0.0),
     dict(max_blocks=0), dict(variables={"x": 1.0}), dict(variables={100: 1.0}),
     dict(variables={500: "a"})],
)
def test_bad_run_options(kw: dict) -> None:
    with pytest.raises(fx.InputError):
        fx.run(code="G0 X1.\n", **kw)


def test_bad_arrays() -> None:
    m = fx.Machine("trunnion-ac")
    for joints in (np.zeros((3, 4)), np.zeros(7), np.zeros((2, 3, 5)), [["a"] * 5]):
        with pytest.raises(fx.InputError):
            m.forward(joints)
    bad = np.zeros((3, 5))
    bad[1, 2] = np.nan
    with pytest.raises(fx.InputError, match=r"joints\[1, 2\]"):
        m.forward(bad)
    bad[1, 2] = np.inf
    with pytest.raises(fx.InputError):
        m.forward(bad)
    with pytest.raises(fx.InputError):
        m.forward(np.zeros((3, 5)), [1.0, 2.0])
    with pytest.raises(fx.InputError):
        m.forward(np.zeros((3, 5)), [1.0, np.nan, 2.0])
    with pytest.raises(fx.InputError, match="directions"):
        m.inverse(np.zeros((2, 3)), [[0, 0, 1], [0, 0, 0]])
    with pytest.raises(fx.InputError):
        m.inverse(np.zeros((2, 3)), np.zeros((3, 3)) + [0, 0, 1])
    with pytest.raises(fx.InputError):
        m.inverse(np.zeros((2, 3)), [[0, 0, 1], [0, 0, np.nan]])
    with pytest.raises(fx.InputError):
        m.inverse(np.zeros((1, 3)), [[0, 0, 1]], held=(np.nan, 0))
    with pytest.raises(fx.InputError, match="two rotary axes"):
        fx.Machine("mill-3axis").choose(np.zeros((1, 3)), [[0, 0, 1]])
    # Empty arrays are fine.
    tips, dirs = m.forward(np.zeros((0, 5)))
    assert tips.shape == (0, 3)


def test_unreachable_directions_give_no_solution() -> None:
    # The 3-axis mill reaches its own tool direction only; a one-axis
    # machine the cone about its axis.
    mill = fx.Machine("mill-3axis")
    inv = mill.inverse([[1, 2, 3], [1, 2, 3]], [[0, 0, 1], [0, 1, 0]])
    assert list(inv.count) == [1, 0]
    assert np.isnan(inv.joints[1]).all()
    ac = fx.Machine("trunnion-ac")
    chosen, reached = ac.choose([[0, 0, 0], [0, 0, 0]], [[0, 0, 1], [0, 0, -1]])
    assert reached[0]
    if not reached[1]:
        assert np.isnan(chosen[1]).all()


FUZZ = r"""
import random, sys
import fiveaxis as fx
rng = random.Random(int(sys.argv[1]))
words = ["G0", "G1", "G2", "G3", "G43.4", "G43.5", "G68.2", "G69", "G49", "X", "Y", "Z", "A", "C",
         "I", "J", "K", "R", "F", "H1", "#1=", "[", "]", "(", ")", "M30", "M98", "P", "G81", "Q", ".",
         "-", "1.", "360.", "1e9", "GOTO", "WHILE", "IF", "/", "%", "\x00", "\xff", "\n"]
for _ in range(300):
    text = "".join(rng.choice(words) + (rng.choice(["", " ", "5.", "-90."])) for _ in range(rng.randrange(1, 40)))
    for call in (lambda: fx.run(code=text, step=rng.choice([None, 5.0]), max_blocks=2000),
                 lambda: fx.check(code=text, max_blocks=2000),
                 lambda: fx.post(code=text, machine="head-table-bc")):
        try:
            call()
        except (fx.Alarm, fx.InputError):
            pass
print("ok")
"""


@pytest.mark.parametrize("seed", [1, 2])
def test_random_programs_never_crash_the_interpreter(seed: int) -> None:
    done = subprocess.run([sys.executable, "-c", FUZZ, str(seed)], capture_output=True, timeout=600)
    assert done.returncode == 0, done.stderr.decode(errors="replace")[-2000:]
    assert done.stdout.strip() == b"ok"


def test_post_refuses_tolerances_finer_than_a_program_can_hold() -> None:
    program = "G43.5 H1 X0 Y0 Z50.\nG1 X10. I0 J0 K1. F100.\nM30\n"
    for kw in [{"tolerance": 1e-8}, {"angle_tolerance": 1e-6}]:
        with pytest.raises(fx.InputError, match="finer than a program can hold"):
            fx.post(code=program, machine="head-table-bc", tool_length=100.0, **kw)
    # At the floors it runs.
    fx.post(code=program, machine="head-table-bc", tool_length=100.0, tolerance=1e-6, angle_tolerance=1e-5)


def test_an_alarm_in_apt_input_names_the_records_line_and_text() -> None:
    record = "GOTO/999,0,0,0,0,1"
    cl = f"$$ over-travel on line 6\nLOAD/TOOL,1\nRAPID\nGOTO/0,0,10,0,0,1\nFEDRAT/500,MMPM\n{record}\nFINI\n"
    with pytest.raises(fx.Alarm) as info:
        fx.post(code=cl, machine="head-table-bc", apt=True, tool_length=100.0)
    a = info.value
    assert a.line == 6 and a.text == record and a.column is None
    assert "X999" not in str(a)
