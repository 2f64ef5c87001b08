"""The package as shipped: type stubs that match the module, docstrings on every public name,
py.typed, and the README's Python example, run as written."""

import ast
import re
import subprocess
import sys
from pathlib import Path

import weft
import weft._weft

from conftest import REPO

PACKAGE = Path(weft.__file__).parent


def stub():
    return ast.parse((PACKAGE / "_weft.pyi").read_text())


def test_the_stub_names_exactly_what_the_module_has():
    tree = stub()
    top = {
        n.name for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))
    } | {
        n.target.id for n in tree.body if isinstance(n, ast.AnnAssign)
    }
    module = {n for n in dir(weft._weft) if not n.startswith("_")} | {"__version__"}
    assert top == module
    assert set(weft.__all__) == module
    (cls,) = [n for n in tree.body if isinstance(n, ast.ClassDef) and n.name == "Simulation"]
    members = {n.name for n in cls.body if isinstance(n, ast.FunctionDef)} - {"__init__"}
    public = {n for n in dir(weft.Simulation) if not n.startswith("_")}
    assert members == public


def test_every_public_name_has_a_docstring_and_the_package_is_typed():
    assert (PACKAGE / "py.typed").exists()
    for name in ("Simulation", "SceneError", "SimulationError", "methods", "materials"):
        assert len(getattr(weft, name).__doc__ or "") > 20, name
    for name in dir(weft.Simulation):
        if not name.startswith("_"):
            assert len(getattr(weft.Simulation, name).__doc__ or "") > 20, name
    assert "scene" in weft.Simulation.__doc__ and "overrides" in weft.Simulation.__doc__


def test_the_readme_example_runs_and_prints_the_sag():
    readme = (REPO / "README.md").read_text()
    block = re.search(r"<!-- python-example -->\n```python\n(.*?)```", readme, re.S)
    assert block, "README.md has a ```python block after <!-- python-example -->"
    code = block.group(1)
    assert len(code.strip().splitlines()) <= 10
    out = subprocess.run(
        [sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True, check=True
    ).stdout
    sag = re.fullmatch(r"sag of the top edge after 2\.0 s: ([0-9.]+) mm\n", out)
    assert sag, out
    assert 1.0 < float(sag.group(1)) < 100.0, out
