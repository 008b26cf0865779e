"""Shared fixtures of the fiveaxis Python tests: the repository, the
`fiveaxis` command line binary (to compare with), seeded random machines."""

from __future__ import annotations

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
FIXTURES = REPO / "crates" / "fiveaxis-cli" / "tests" / "fixtures"
EXAMPLES = REPO / "examples"
PY_EXAMPLES = REPO / "crates" / "fiveaxis-py" / "examples"


def find_cli() -> Path | None:
    """The `fiveaxis` binary: $FIVEAXIS_BIN, else a cargo build of it."""
    given = os.environ.get("FIVEAXIS_BIN")
    if given:
        return Path(given).resolve()
    targets = [Path(os.environ["CARGO_TARGET_DIR"])] if os.environ.get("CARGO_TARGET_DIR") else []
    targets.append(REPO / "target")
    for target in targets:
        for profile in ("release", "debug"):
            candidate = target / profile / "fiveaxis"
            if candidate.is_file():
                return candidate
    return None


@pytest.fixture(scope="session")
def cli() -> Path:
    found = find_cli()
    if found is None:
        cargo = shutil.which("cargo")
        if cargo is None:
            pytest.fail("no fiveaxis binary: set FIVEAXIS_BIN or build it (cargo build -p fiveaxis-cli)")
        subprocess.run([cargo, "build", "-q", "-p", "fiveaxis-cli"], cwd=REPO, check=True)
        found = find_cli()
    assert found is not None and found.is_file(), f"no fiveaxis binary at {found}"
    return found
