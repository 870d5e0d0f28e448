"""STEP files through OpenCASCADE (cascadio): ``asp.load`` in-process, ``asp plan`` through the
converter in a Python with cascadio (``ASP_PYTHON``), the two plans equal; the product tree,
units and exact surfaces in the plan JSON; ``subassemblies="from-file"``."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

import asp
from asp import _asp
from conftest import ROOT, need, without_seconds

cascadio = need("cascadio", "pip install cascadio")

STEP = "tests/data/step"
AS1 = f"{STEP}/as1-oc-214.stp"
MODELS = sorted(p.name for p in (ROOT / STEP).iterdir() if p.suffix in (".step", ".stp"))


@pytest.fixture
def step_cli(asp_cli, monkeypatch):
    """``asp`` with this Python (which has cascadio) as the converter's."""
    monkeypatch.setenv("ASP_PYTHON", os.environ.get("ASP_PYTHON", sys.executable))
    return asp_cli


def test_as1_loads_with_the_files_names_unit_and_tree(root):
    a = asp.load(AS1)
    assert (len(a.parts), a.units, a.up) == (18, "mm", "+z")
    names = [p.name for p in a.parts]
    assert "plate_1" in names and "rod_1" in names
    # six instances of one bolt, each named so a person can tell them apart
    bolts = [n for n in names if n.endswith("bolt_1")]
    assert len(bolts) == len(set(bolts)) == 6
    assert "l-bracket-assembly_1/nut-bolt-assembly_2/bolt_1" in bolts
    assert any("+z is assumed" in w for w in a.warnings)


@pytest.mark.parametrize("model", MODELS)
def test_every_step_file_reads_and_plans_and_python_plans_as_the_cli(root, step_cli, model):
    path = f"{STEP}/{model}"
    code, out, err = step_cli("plan", path, "--json")
    assert code in (0, 1), err
    plan = json.loads(out)
    assert plan["status"] in ("found", "partial"), plan["status"]
    assert all(p.get("path") for p in plan["parts"]), "every part has its place in the product tree"
    assert all(p["tessellation"]["relative"] == _asp.STEP_RELATIVE for p in plan["parts"])
    assert plan["units"] == ("in" if model.startswith("inch") else "mm")
    mine = asp.load(path).plan()
    assert without_seconds(mine.json) == without_seconds(out)


def test_exact_surfaces_are_in_the_part_list(root):
    plan = json.loads(asp.load(f"{STEP}/shaft_bearings.step").plan().json)
    shaft = next(p for p in plan["parts"] if p["name"] == "shaft")
    cylinders = [s for s in shaft["surfaces"] if s["kind"] == "cylinder"]
    assert cylinders and all(s["source"] == "exact" for s in cylinders)
    assert {round(s["radius"], 6) for s in cylinders} == {8.0}
    assert all(abs(abs(s["axis"][2]) - 1) < 1e-6 for s in cylinders)
    # the tessellation stays within its tolerance of the exact shape: 0.001 of an edge's size
    # (the circle's 16 mm), doubled at most by OpenCASCADE's adjustment
    assert 0 < shaft["tessellation"]["chord_error"] < 2 * 0.001 * 16 * 1.01


def test_the_inch_file_reports_in_inches(root):
    plan = json.loads(asp.load(f"{STEP}/inch_bracket.step").plan().json)
    bolt = next(p for p in plan["parts"] if p["name"].endswith("bolt_quarter_20"))
    shank = [s["radius"] for s in bolt["surfaces"] if s["kind"] == "cylinder"]
    assert any(abs(r - 0.125) < 1e-6 for r in shank), shank


def test_from_file_plans_each_subassembly_and_the_top(root, step_cli):
    code, out, err = step_cli("plan", f"{STEP}/shaft_bearings.step", "--subassemblies", "from-file", "--json")
    assert code == 0, err
    plan = json.loads(out)
    names = [g["name"] for g in plan["file_subassemblies"]]
    assert names == ["shaft_bearings/spindle", "shaft_bearings/spindle/bearing_1", "shaft_bearings/spindle/bearing_2"]
    mine = asp.load(f"{STEP}/shaft_bearings.step").plan(subassemblies="from-file")
    assert without_seconds(mine.json) == without_seconds(out)


def test_bad_step_input_is_one_line(root, step_cli, tmp_path):
    bad = tmp_path / "broken.step"
    bad.write_text("ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1=FOO(;\nENDSEC;\nEND-ISO-10303-21;\n")
    code, out, err = step_cli("plan", str(bad))
    assert code == 2 and err.count("\n") == 1, err
    assert str(bad) in err and "OpenCASCADE cannot read it as STEP" in err
    with pytest.raises(asp.LoadError, match="OpenCASCADE cannot read it as STEP"):
        asp.load(bad)
    with pytest.raises(asp.ConfigError, match="tessellation"):
        asp.load("tests/data/ikea/table_lack_0825.glb", tessellation=0.01)
    code, out, err = step_cli("plan", AS1, "--unit", "in")
    assert code == 2 and "names its own unit" in err


def test_the_clis_converter_is_the_packages(root, tmp_path):
    """The script the command line runs gives a GLB that loads like the in-process one."""
    glb = subprocess.run(
        [sys.executable, "-c", _asp.STEP_CONVERTER, str(_asp.STEP_RELATIVE), str(_asp.STEP_ANGULAR)],
        input=(ROOT / AS1).read_bytes(), capture_output=True, check=True,
    ).stdout
    assert glb[:4] == b"glTF"
    here = asp.step.convert(ROOT / AS1)
    path = tmp_path / "as1.glb"
    path.write_bytes(glb)
    a, b = asp.load(path), asp.load(tmp_path / "as1.glb")
    path.write_bytes(here)
    c = asp.load(path)
    assert [p.name for p in a.parts] == [p.name for p in c.parts] == [p.name for p in b.parts]


def test_the_generated_step_files_are_what_the_script_writes():
    """Runs only where build123d is installed (about 1 GB; not in CI): the committed files are
    the script's output byte for byte."""
    pytest.importorskip("build123d", reason="pip install build123d==0.13.0")
    done = subprocess.run([sys.executable, str(ROOT / "scripts" / "gen-step-data.py"), "--check"], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr


def test_no_step_file_is_left_untested():
    assert len(MODELS) == 7 and Path(ROOT / AS1).is_file()
