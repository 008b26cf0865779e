"""SINUMERIK programs from Python, as the command line reads them: a path
ending `.mpf` / `.spf` or a text starting with a `%_N_` transfer header
runs on the machine read as a SINUMERIK (on any machine); `programs=`
holds subprograms by name and definition files (`.DEF`); SINUMERIK alarms
keep their numbers; `check` and `post` give what `fiveaxis check` and
`fiveaxis post` give."""

from __future__ import annotations

import csv
import io
import json
import subprocess
from pathlib import Path
from typing import Dict, List, Union

import numpy as np
import pytest

import fiveaxis as fx

from conftest import EXAMPLES
from test_cli_agreement import assert_same, cli_rows

EXAMPLE = EXAMPLES / "swivel-drill.mpf"
OFFSETS = EXAMPLES / "offsets.toml"
SINUMERIK = "sinumerik-dmu-bc"

#: A SINUMERIK line that a FANUC control refuses.
DEF_PROGRAM = "DEF REAL H=5\nG0 X=H\nM30\n"

LIFT = "PROC LIFT(REAL H)\nG0 Z=H\nRET\n"
GUD = "DEF NCK REAL SAFE_Z\n"


@pytest.mark.parametrize("machine", [SINUMERIK, "head-table-bc"])
def test_the_example_gives_the_cli_rows(cli: Path, machine: str) -> None:
    status, expected, stderr = cli_rows(cli, EXAMPLE, ["--machine", machine, "--offsets", OFFSETS.name])
    assert status == 0, stderr
    assert len(expected) > 10
    assert_same(fx.run(EXAMPLE, machine, OFFSETS), expected, EXAMPLE.name)
    # Its text (with its %_N_ header) as code=, and in chunks.
    assert_same(fx.run(code=EXAMPLE.read_text(), machine=machine, offsets=OFFSETS), expected, "code=")
    chunks = list(fx.run_chunks(EXAMPLE, machine, OFFSETS, chunk_rows=4))
    assert len(chunks) > 1
    assert_same(fx.Rows.concatenate(chunks), expected, "run_chunks")


@pytest.mark.parametrize("header", ["%_N_H_MPF\n", "%_N_H_MPF\r\n;$PATH=/_N_MPF_DIR\r\n"])
def test_a_transfer_header_reads_as_sinumerik_on_a_fanuc_machine(cli: Path, header: str) -> None:
    assert fx.Machine("trunnion-ac").control != "sinumerik"
    with pytest.raises(fx.Alarm):
        fx.run(code=DEF_PROGRAM, machine="trunnion-ac")
    code = header + DEF_PROGRAM
    for program in (code, code.encode()):
        rows = fx.run(code=program, machine="trunnion-ac")
        assert rows["X"][-1] == 5.0 and rows["A"][-1] == 0.0
        assert len(list(fx.run_chunks(code=program, machine="trunnion-ac"))) == 1
    report = fx.check(code=code, machine="trunnion-ac")
    assert report.ended and report.alarm is None
    # The command line reading the text from standard input agrees.
    done = subprocess.run(
        [str(cli), "run", "-", "--machine", "trunnion-ac", "--format", "csv"],
        input=code.encode(), capture_output=True, timeout=300,
    )
    assert done.returncode == 0, done.stderr
    expected = list(csv.DictReader(io.StringIO(done.stdout.decode())))
    assert_same(fx.run(code=code, machine="trunnion-ac"), expected, "code=")


def test_a_header_after_a_byte_order_mark_reads_as_sinumerik(cli: Path, tmp_path: Path) -> None:
    """Recognised as the command line does, and the mark is skipped by the
    SINUMERIK reader: the rows are those of the text without it."""
    code = "\ufeff%_N_H_MPF\n" + DEF_PROGRAM
    program = tmp_path / "bom.nc"
    program.write_bytes(code.encode())
    status, expected, stderr = cli_rows(cli, program, ["--machine", "trunnion-ac"])
    assert status == 0, stderr
    plain = tmp_path / "plain.nc"
    plain.write_bytes(code[1:].encode())
    assert cli_rows(cli, plain, ["--machine", "trunnion-ac"])[1] == expected
    for kw in ({"code": code}, {"code": code.encode()}, {"program": program}):
        assert_same(fx.run(machine="trunnion-ac", **kw), expected, "bom")  # type: ignore[arg-type]


@pytest.mark.parametrize("name", ["h.mpf", "H.SPF", "h.Mpf"])
def test_an_mpf_or_spf_file_reads_as_sinumerik(cli: Path, tmp_path: Path, name: str) -> None:
    program = tmp_path / name
    program.write_text(DEF_PROGRAM)
    status, expected, stderr = cli_rows(cli, program, ["--machine", "trunnion-ac"])
    assert status == 0, stderr
    assert_same(fx.run(program, "trunnion-ac"), expected, name)
    assert fx.check(program, "trunnion-ac").alarm is None
    # The same text under another name is FANUC.
    other = tmp_path / "h.nc"
    other.write_text(DEF_PROGRAM)
    with pytest.raises(fx.Alarm):
        fx.run(other, "trunnion-ac")


def memory_folder(tmp_path: Path, files: Dict[str, str]) -> str:
    folder = tmp_path / "memory"
    folder.mkdir()
    for name, text in files.items():
        (folder / name).write_text(text)
    return str(folder)


ProgramMemory = Dict[Union[int, str], Union[str, bytes, Path]]


def test_a_subprogram_called_by_name(cli: Path, tmp_path: Path) -> None:
    main = tmp_path / "main.mpf"
    main.write_text("G0 X10\nLIFT(50)\nG0 X20\nM30\n")
    folder = memory_folder(tmp_path, {"LIFT.SPF": LIFT})
    status, expected, stderr = cli_rows(cli, main, ["--machine", SINUMERIK, "--programs", folder])
    assert status == 0, stderr
    memories: List[ProgramMemory] = [
        {"LIFT": LIFT},
        {"lift": LIFT.encode()},
        {"LIFT.SPF": Path(folder) / "LIFT.SPF"},
        {"_N_LIFT_SPF": LIFT, 9010: "G0 X0\nM99\n"},
    ]
    for programs in memories:
        rows = fx.run(main, SINUMERIK, programs=programs)
        assert_same(rows, expected, f"main.mpf with {list(programs)}")
        assert rows["Z"][1] == 50.0
        assert fx.check(main, SINUMERIK, programs=programs).ended
    with pytest.raises(fx.Alarm):
        fx.run(main, SINUMERIK)


def test_a_definition_file_is_read_first(cli: Path, tmp_path: Path) -> None:
    main = tmp_path / "main.mpf"
    main.write_text("SAFE_Z=80\nG0 Z=SAFE_Z\nM30\n")
    folder = memory_folder(tmp_path, {"GUD.DEF": GUD})
    status, expected, stderr = cli_rows(cli, main, ["--machine", SINUMERIK, "--programs", folder])
    assert status == 0, stderr
    for key in ("GUD.DEF", "gud.def", "_N_GUD_DEF"):
        rows = fx.run(main, SINUMERIK, programs={key: GUD})
        assert_same(rows, expected, key)
        assert rows["Z"][-1] == 80.0
    # Without it the name is not defined: SINUMERIK alarm 12550.
    with pytest.raises(fx.Alarm) as info:
        fx.run(main, SINUMERIK)
    assert info.value.code == "12550" and info.value.line == 1
    # A definition file is not a program to call.
    with pytest.raises(fx.Alarm):
        fx.run(code="GUD\nM30\n", machine=SINUMERIK, programs={"GUD.DEF": GUD})


def test_a_numbered_program_is_also_a_sinumerik_name() -> None:
    rows = fx.run(code='%_N_M_MPF\nEXTCALL("4444411")\nM30\n', machine="trunnion-ac",
                  programs={4444411: "G0 X7\nM17\n"})
    assert rows["X"][-1] == 7.0


def test_an_alarm_keeps_its_sinumerik_number(cli: Path, tmp_path: Path) -> None:
    program = tmp_path / "jump.mpf"
    program.write_text("G0 X10\nGOTOF NOWHERE\nM30\n")
    status, expected, stderr = cli_rows(cli, program, ["--machine", SINUMERIK])
    assert status == 1 and "ALARM 14080 line 2" in stderr, stderr
    with pytest.raises(fx.Alarm) as info:
        fx.run(program, SINUMERIK)
    assert info.value.code == "14080" and info.value.line == 2
    assert isinstance(info.value.rows, fx.Rows)
    assert_same(info.value.rows, expected, "rows before the alarm")
    with pytest.raises(fx.Alarm) as streamed:
        list(fx.run_chunks(program, SINUMERIK))
    assert streamed.value.code == "14080"
    report = fx.check(program, SINUMERIK)
    assert report.alarm is not None and report.alarm.code == "14080" and report.alarm.line == 2


def test_check_of_the_example_is_the_cli_report(cli: Path) -> None:
    args = [str(EXAMPLE), "--machine", SINUMERIK, "--offsets", str(OFFSETS)]
    text = subprocess.run([str(cli), "check", *args], capture_output=True, timeout=300)
    assert text.returncode == 0, text.stderr
    done = subprocess.run([str(cli), "check", *args, "--format", "json"], capture_output=True, timeout=300)
    want = json.loads(done.stdout)
    got = fx.check(EXAMPLE, SINUMERIK, OFFSETS)
    assert got.verdict == "PASS" and got.ended and got.alarm is None
    assert got.summary() == text.stdout.decode().splitlines()[0]
    assert (got.program, got.machine, got.blocks) == (want["program"], want["machine"], want["blocks"])
    assert (got.time.programmed, got.time.estimated) == (want["time"]["programmed"], want["time"]["estimated"])
    assert len(got.findings) == len(want["findings"])


def test_post_of_the_example_is_the_cli_program(cli: Path) -> None:
    done = subprocess.run(
        [str(cli), "post", str(EXAMPLE), "--machine", SINUMERIK, "--offsets", str(OFFSETS)],
        capture_output=True, timeout=300,
    )
    assert done.returncode == 0, done.stderr
    got = fx.post(EXAMPLE, SINUMERIK, OFFSETS)
    assert got.converted and got.text.startswith("%_N_")
    assert got.text == done.stdout.decode()
    assert got.unresolved == 0 and got.blocks > 0
    # The same text as code= is read as SINUMERIK too (the source line
    # of the header differs).
    again = fx.post(code=EXAMPLE.read_text(), machine=SINUMERIK, offsets=OFFSETS)
    assert again.blocks == got.blocks and again.deviation_tip == got.deviation_tip


def test_post_reads_a_header_on_a_fanuc_machine() -> None:
    code = "%_N_P_MPF\nDEF REAL Z0=20\nG0 X10 Y0 Z=Z0\nM30\n"
    with pytest.raises(fx.Alarm):
        fx.post(code=code.split("\n", 1)[1], machine="head-table-bc")
    got = fx.post(code=code, machine="head-table-bc")
    assert not got.converted and got.text == code


def test_program_names_are_checked() -> None:
    for bad in ("drill x", "", "../LIFT", "LIFT.NC", "O123456789"):
        with pytest.raises(fx.InputError, match="a program number"):
            fx.run(code="M30\n", programs={bad: LIFT})
    with pytest.raises(fx.InputError, match=r"program `O123456789`: a program number, as 9010 or 'O9010'$"):
        fx.run(code="M30\n", programs={"O123456789": LIFT})
    rows = fx.run(code="%_N_A_MPF\nL100\nM30\n", machine=SINUMERIK, programs={"L100": "G0 X3\nM17\n"})
    assert np.array_equal(rows["X"], [3.0])


def test_the_docs_example_runs(monkeypatch: pytest.MonkeyPatch) -> None:
    """The code block of docs/python.md "SINUMERIK programs" runs as written."""
    from conftest import REPO

    page = (REPO / "docs" / "python.md").read_text()
    section = page.split("## SINUMERIK programs", 1)[1].split("\n## ", 1)[0]
    code = section.split("```python\n", 1)[1].split("```", 1)[0]
    monkeypatch.chdir(REPO)
    scope: Dict[str, object] = {"fx": fx}
    exec(compile(code, "docs/python.md", "exec"), scope)
    rows = scope["rows"]
    assert isinstance(rows, fx.Rows)
    assert rows["Z"][-1] == 80.0
