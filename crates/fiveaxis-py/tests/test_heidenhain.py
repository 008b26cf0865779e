"""HEIDENHAIN programs from Python, as the command line reads them: a path
ending `.h` or a text whose first block is `BEGIN PGM` runs on the machine
read as a TNC (on any machine); `programs=` holds what `CALL PGM` runs;
`check` and `post` give what `fiveaxis check` and `fiveaxis post` give."""

from __future__ import annotations

from pathlib import Path

import pytest

import fiveaxis as fx

from conftest import EXAMPLES
from test_cli_agreement import assert_same, cli_rows

EXAMPLE = EXAMPLES / "plane-drill.h"
OFFSETS = EXAMPLES / "heidenhain-offsets.toml"
HEIDENHAIN = "heidenhain-dmu-ac"

#: Klartext that a FANUC control refuses.
PROGRAM = "0 BEGIN PGM P MM\n1 Q1 = 12\n2 L X+Q1 Y-5 R0 FMAX\n3 END PGM P MM\n"


def test_the_example_gives_the_cli_rows(cli: Path) -> None:
    status, expected, stderr = cli_rows(cli, EXAMPLE, ["--machine", HEIDENHAIN, "--offsets", OFFSETS.name])
    assert status == 0, stderr
    assert len(expected) > 10
    assert_same(fx.run(EXAMPLE, HEIDENHAIN, OFFSETS), expected, EXAMPLE.name)
    assert_same(fx.run(code=EXAMPLE.read_text(), machine=HEIDENHAIN, offsets=OFFSETS), expected, "code=")
    chunks = list(fx.run_chunks(EXAMPLE, HEIDENHAIN, OFFSETS, chunk_rows=4))
    assert len(chunks) > 1
    assert_same(fx.Rows.concatenate(chunks), expected, "run_chunks")


def test_begin_pgm_reads_as_klartext_on_a_fanuc_machine() -> None:
    assert fx.Machine("trunnion-ac").control != "heidenhain"
    for program in (PROGRAM, PROGRAM.encode()):
        rows = fx.run(code=program, machine="trunnion-ac")
        assert rows["X"][-1] == 12.0 and rows["Y"][-1] == -5.0
    report = fx.check(code=PROGRAM, machine="trunnion-ac")
    assert report.ended and report.alarm is None


def test_a_dot_h_path_reads_as_klartext(tmp_path: Path) -> None:
    path = tmp_path / "part.H"
    path.write_text(PROGRAM)
    assert fx.run(path, "trunnion-ac")["X"][-1] == 12.0


def test_call_pgm_runs_a_program_of_the_memory() -> None:
    main = "0 BEGIN PGM M MM\n1 Q1 = 7\n2 CALL PGM TNC:\\PARTS\\SUB1.H\n3 END PGM M MM\n"
    sub = "0 BEGIN PGM SUB1 MM\n1 L X+Q1 R0 FMAX\n2 END PGM SUB1 MM\n"
    for key in ("SUB1.h", "SUB1", "sub1.H"):
        rows = fx.run(code=main, machine=HEIDENHAIN, programs={key: sub})
        assert rows["X"][-1] == 7.0
    with pytest.raises(fx.Alarm):
        fx.run(code=main, machine=HEIDENHAIN)
    with pytest.raises(fx.InputError):
        fx.run(code=main, machine=HEIDENHAIN, programs={"SUB1.nc.h": sub})


def test_plane_stay_writes_the_axis_positions_for_the_next_block() -> None:
    code = (
        "0 BEGIN PGM P MM\n"
        "1 PLANE SPATIAL SPA+0 SPB+0 SPC+0 STAY\n"
        "2 PLANE SPATIAL SPA+90 SPB+0 SPC+180 STAY SEQ-\n"
        "3 L A+Q120 C+Q122 R0 FMAX\n"
        "4 END PGM P MM\n"
    )
    rows = fx.run(code=code, machine=HEIDENHAIN)
    assert rows["A"][-1] == pytest.approx(-90.0, abs=1e-9)
    assert rows["C"][-1] == pytest.approx(0.0, abs=1e-9)
    # The tool along the plane's Z, the part's +Y.
    assert rows.tool[-1] == pytest.approx([0.0, 1.0, 0.0], abs=1e-12)


def test_errors_name_the_line() -> None:
    with pytest.raises(fx.Alarm) as e:
        fx.run(code="0 BEGIN PGM P MM\n1 C X+10 Y+0 DR+\n2 END PGM P MM\n", machine=HEIDENHAIN)
    assert e.value.line == 2
    assert "CC" in str(e.value)
