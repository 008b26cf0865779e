"""The package as installed: typing stubs cover the API, py.typed ships,
versions agree, and machines read back what their files say."""

from __future__ import annotations

import re
import sys
from pathlib import Path

import pytest

import fiveaxis as fx

from conftest import REPO

if sys.version_info >= (3, 11):
    import tomllib
else:  # pragma: no cover
    tomllib = None


def test_stubs_and_py_typed_ship() -> None:
    package = Path(fx.__file__).parent
    assert (package / "py.typed").is_file()
    stub = (package / "__init__.pyi").read_text()
    for name in fx.__all__:
        assert re.search(rf"^(class|def) {name}\b|^{name}\b|import {name} as {name}", stub, re.M), name


def test_versions_agree() -> None:
    cargo = (REPO / "Cargo.toml").read_text()
    pyproject = (REPO / "pyproject.toml").read_text()
    version = re.search(r'^version = "([^"]+)"', cargo, re.M).group(1)
    assert fx.__version__ == version
    assert f'version = "{version}"' in pyproject


@pytest.mark.skipif(tomllib is None, reason="tomllib needs Python 3.11")
@pytest.mark.parametrize("name", fx.machines())
def test_machines_read_back_their_file(name: str) -> None:
    m = fx.Machine(name)
    data = tomllib.loads(m.to_toml())
    assert m.name == data["name"] and m.control == data["control"]
    assert m.axes == tuple(a["name"] for a in data.get("linear", []) + data.get("rotary", []))
    for a in data.get("linear", []):
        assert m.limits[a["name"]] == (a["min"], a["max"])
    for a, r in zip(data.get("rotary", []), m.rotary_axes):
        assert r["on"] == a["on"] and r["rollover"] == a["rollover"]
        assert m.limits[a["name"]] == (None if a["rollover"] else (a["min"], a["max"]) if "min" in a else None)
        assert list(r["axis"]) == a["axis"] and list(r["center"]) == a["center"]
    params = data.get("parameters", {})
    for key in ("tcpc_option", "rotary_choice", "singular_cone", "flip_angle", "chord_tolerance",
                "least_input_increment", "input_unit", "programming_frame"):
        if key in params:
            assert m.parameters[key] == params[key], key
    again = fx.Machine.from_toml(m.to_toml())
    assert again.to_toml() == m.to_toml()
    assert repr(m).startswith("Machine(")


def test_stubs_type_check_the_examples(tmp_path: Path) -> None:
    """The stubs are valid (mypy --strict) and the examples use the API as
    they declare it."""
    pytest.importorskip("mypy")
    import subprocess

    from conftest import PY_EXAMPLES

    for args in (["--strict", "-p", "fiveaxis"], ["--ignore-missing-imports", *map(str, sorted(PY_EXAMPLES.glob("*.py")))]):
        done = subprocess.run(
            [sys.executable, "-m", "mypy", "--cache-dir", str(tmp_path / "cache"), *args],
            capture_output=True, cwd=tmp_path, timeout=600,
        )
        assert done.returncode == 0, done.stdout.decode() + done.stderr.decode()
