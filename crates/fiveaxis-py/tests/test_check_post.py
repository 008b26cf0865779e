"""`check` and `post` give what `fiveaxis check --format json` and
`fiveaxis post` give: every finding, axis range and time exactly, and
the same program text."""

from __future__ import annotations

import json
import math
import subprocess
from pathlib import Path
from typing import Any, List, Optional

import numpy as np
import pytest

import fiveaxis as fx

from conftest import EXAMPLES, FIXTURES, REPO

CHECKED = [
    (EXAMPLES / "tcpc-vector.nc", "head-table-bc", EXAMPLES / "offsets.toml"),
    (EXAMPLES / "bracket.nc", "trunnion-ac", EXAMPLES / "offsets.toml"),
    (EXAMPLES / "tilted-holes.nc", "trunnion-ac", EXAMPLES / "offsets.toml"),
    (FIXTURES / "alarm_ot0500_overtravel_plus.nc", "trunnion-ac", None),
    (FIXTURES / "machine_head_head_ca_tool_axis_jsonl.nc", "head-head-ca", FIXTURES / "offsets.toml"),
]


def cli_args(machine: str, offsets: Optional[Path]) -> List[str]:
    return ["--machine", machine] + (["--offsets", str(offsets)] if offsets else [])


def same(a: Optional[float], b: Optional[float]) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return a == b and math.copysign(1, a) == math.copysign(1, b)


@pytest.mark.parametrize("program, machine, offsets", CHECKED, ids=lambda v: getattr(v, "name", str(v)))
def test_check_is_the_cli_report(cli: Path, program: Path, machine: str, offsets: Optional[Path]) -> None:
    done = subprocess.run(
        [str(cli), "check", str(program), *cli_args(machine, offsets), "--format", "json", "--fail-on", "never"],
        capture_output=True, timeout=300,
    )
    assert done.returncode == 0, done.stderr
    want: dict[str, Any] = json.loads(done.stdout)
    got = fx.check(program, machine, offsets)
    assert got.program == want["program"] and got.machine == want["machine"]
    assert got.ended == want["ended"] and got.blocks == want["blocks"]
    assert same(got.time.programmed, want["time"]["programmed"])
    assert same(got.time.estimated, want["time"]["estimated"])
    if want["alarm"] is None:
        assert got.alarm is None
    else:
        assert got.alarm is not None
        assert (got.alarm.code, got.alarm.line, got.alarm.message) == (
            want["alarm"]["code"], want["alarm"]["line"], want["alarm"]["message"])
    assert sorted(a.name for a in got.axes) == sorted(want["axes"])
    for a in got.axes:
        w = want["axes"][a.name]
        assert same(a.min, w["min"]) and same(a.max, w["max"]), a
        lo, hi = a.limits if a.limits is not None else (None, None)
        assert same(lo, w["limit_min"]) and same(hi, w["limit_max"]), a
    assert len(got.findings) == len(want["findings"])
    for f, w in zip(got.findings, want["findings"]):
        assert (f.kind, f.severity, f.line, f.message) == (w["kind"], w["severity"], w["line"], w["message"])
        assert f.axis == w.get("axis")
        assert same(f.value, w.get("value"))
    assert got.counts()[want["findings"][0]["kind"]] >= 1 if want["findings"] else got.verdict == "PASS"


POSTED = [
    (EXAMPLES / "tcpc-vector.nc", "head-table-bc", EXAMPLES / "offsets.toml", {}),
    (EXAMPLES / "tilted-holes.nc", "trunnion-ac", EXAMPLES / "offsets.toml", {}),
    (EXAMPLES / "tcpc-vector.nc", "head-table-bc", EXAMPLES / "offsets.toml", {"tolerance": 0.002, "angle_tolerance": 0.05}),
    (REPO / "crates" / "fiveaxis-post" / "tests" / "tcpc-arcs.nc", "head-table-bc", EXAMPLES / "offsets.toml", {}),
]


POSTED += [
    (EXAMPLES / "tcpc-vector.nc", "head-table-bc", EXAMPLES / "offsets.toml", {"feed": "dpm"}),
    (EXAMPLES / "tcpc-vector.nc", "head-table-bc", EXAMPLES / "offsets.toml", {"feed": "programmed"}),
    (EXAMPLES / "tcpc-winding.nc", str(EXAMPLES / "head-table-bc-limited.toml"), EXAMPLES / "offsets.toml",
     {"from_machine": "head-table-bc", "retract": 8.0}),
]


@pytest.mark.parametrize("program, machine, offsets, kw", POSTED, ids=lambda v: getattr(v, "name", str(v)))
def test_post_is_the_cli_program(cli: Path, program: Path, machine: str, offsets: Path, kw: dict) -> None:
    extra = []
    if "tolerance" in kw:
        extra = ["--tolerance", str(kw["tolerance"]), "--angle-tolerance", str(kw["angle_tolerance"])]
    if "feed" in kw:
        extra += ["--feed", kw["feed"]]
    if "retract" in kw:
        extra += ["--retract", str(kw["retract"])]
    if "from_machine" in kw:
        extra += ["--from-machine", kw["from_machine"]]
    done = subprocess.run(
        [str(cli), "post", str(program), *cli_args(machine, offsets), *extra], capture_output=True, timeout=300,
    )
    assert done.returncode == 0, done.stderr
    got = fx.post(program, machine, offsets, **kw)
    assert got.text == done.stdout.decode()
    assert 0 <= got.deviation_tip <= kw.get("tolerance", 0.01)
    assert 0 <= got.deviation_angle <= kw.get("angle_tolerance", 0.1)
    assert got.blocks > 0 and got.source_blocks > 0 and got.unresolved == 0


APT = """PARTNO/TEST
UNIT/MM
LOADTL/1
FEDRAT/500.0,MMPM
RAPID
GOTO/0.0,0.0,50.0,0.0,0.0,1.0
RAPID
GOTO/0.0,0.0,5.0,0.0,0.0,1.0
GOTO/40.0,0.0,5.0,0.3420201,0.0,0.9396926
GOTO/40.0,30.0,5.0,0.0,0.3420201,0.9396926
GOTO/0.0,30.0,5.0,0.0,0.0,1.0
FINI
"""


def test_apt_converts_and_posts(tmp_path: Path, cli: Path) -> None:
    tcpc = fx.apt_to_tcpc(APT)
    assert "G43.5" in tcpc
    path = tmp_path / "part.apt"
    path.write_text(APT)
    offsets = {"tools": {1: {"length": 100.0}}}
    got = fx.post(path, "head-table-bc", offsets)
    assert got.deviation_tip <= 0.01
    # The posted program, run without TCPC, passes through every GOTO point.
    machine = fx.Machine("head-table-bc")
    rows = fx.run(code=got.text, machine=machine, offsets=offsets)
    # Run without length compensation (G49): the tip is forward
    # kinematics of the axes with the posted tool length.
    tips, _ = machine.forward(rows.joints, 100.0)
    points = np.array([[40.0, 0.0, 5.0], [40.0, 30.0, 5.0], [0.0, 30.0, 5.0]])
    for p in points:
        assert np.linalg.norm(tips - p, axis=1).min() < 1e-3, p
    with pytest.raises(fx.InputError) as info:
        fx.apt_to_tcpc("GOTO/1,2\nFOO/BAR\n")
    assert info.value.line is not None


TCPC = "G21 G90 G94\nG0 X0 Y0 Z100. A0 C0\nG43.4 H1 X0 Y0 Z20.\nG1 X20. A10. F500.\nG49\nM30\n"


def test_post_needs_a_tool_length_as_the_cli_does(cli: Path, tmp_path: Path) -> None:
    with pytest.raises(fx.InputError) as info:
        fx.post(code=TCPC, machine="trunnion-ac")
    assert "no tool length" in info.value.message and "tool_length=" in info.value.message
    path = tmp_path / "p.nc"
    path.write_text(TCPC)
    done = subprocess.run([str(cli), "post", str(path), "--machine", "trunnion-ac"], capture_output=True, timeout=300)
    assert done.returncode == 2 and b"--tool-length" in done.stderr
    done = subprocess.run(
        [str(cli), "post", str(path), "--machine", "trunnion-ac", "--tool-length", "95.5"],
        capture_output=True, timeout=300,
    )
    assert done.returncode == 0, done.stderr
    got = fx.post(path, "trunnion-ac", tool_length=95.5)
    assert got.converted and got.text == done.stdout.decode()
    assert got.tool_lengths[0] == 95.5
    # The offsets' own tool is taken when they have it.
    got = fx.post(path, "trunnion-ac", {"tools": {1: {"length": 120.0}}})
    assert got.tool_lengths[0] == 120.0


def test_post_returns_a_program_with_nothing_to_convert_unchanged(cli: Path, tmp_path: Path) -> None:
    plain = "G21 G90\nG0 X0 Y0 Z50. A0 C0\nG43 H1 Z10.\nG2 X20. Y0 R10. F300.\nG49\nM30\n"
    path = tmp_path / "plain.nc"
    path.write_text(plain)
    got = fx.post(path, "trunnion-ac")
    assert not got.converted and got.text == plain
    done = subprocess.run([str(cli), "post", str(path), "--machine", "trunnion-ac"], capture_output=True, timeout=300)
    assert done.returncode == 0 and done.stdout.decode() == plain
    assert b"nothing to convert" in done.stderr


def test_cl_words_not_carried_out_come_back_as_warnings(tmp_path: Path) -> None:
    cl = tmp_path / "part.ncl.1"
    cl.write_text("PARTNO/BRACKET\nLOADTL/1\nPPWORD/XYZ\nFOOBAR/1,2\nFEDRAT/500,MMPM\nGOTO/0,0,10,0,0,1\nGOTO/10,0,10,0,0,1\nFINI\n")
    got = fx.post(cl, "head-table-bc", tool_length=100.0)
    assert got.converted
    words = {w[1]: w for w in got.cl_warnings}
    assert words["FOOBAR"][0] == 4 and not words["FOOBAR"][4]
    assert words["PPWORD"][0] == 3 and words["PPWORD"][4]


def test_check_keep_going_as_the_command_line(cli: Path, tmp_path: Path) -> None:
    program = "G21 G90 G94\nG0 X0 Y0 Z100.\nM123\nG1 X10.\nG1 X20. F500.\nG0 A50.\nM30\n"
    path = tmp_path / "p.nc"
    path.write_text(program)
    stopped = fx.check(path)
    assert stopped.alarm is not None and stopped.alarm.line == 3 and not stopped.ended
    report = fx.check(path, keep_going=True)
    assert report.ended and report.alarm is not None and report.alarm.line == 3
    got = [(f.kind, f.line) for f in report.findings]
    assert got == [("alarm", 3), ("alarm", 4), ("overtravel", 6)]
    done = subprocess.run(
        [str(cli), "check", str(path), "--keep-going", "--format", "json", "--fail-on", "never"],
        capture_output=True, timeout=300,
    )
    want = json.loads(done.stdout)
    assert got == [(f["kind"], f["line"]) for f in want["findings"]]
