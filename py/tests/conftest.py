"""Shared fixtures: the repository root, the shipped models, and the `asp` binary the plan JSON is
compared with (``ASP_BIN``, else a built ``target/*/asp``, else ``cargo run -p asp-cli``)."""

from __future__ import annotations

import importlib
import os
import re
import shutil
import subprocess
from pathlib import Path
from typing import Callable

import pytest

ROOT = Path(__file__).resolve().parents[2]
LACK = "tests/data/ikea/table_lack_0825.glb"
PUMP = "tests/data/pump"
BEARING = "tests/data/bearing/ball_bearing_6204.glb"
ROLLER_BEARING = "tests/data/bearing/roller_bearing_nup204.glb"

# every wall-time figure of a plan JSON: the one thing two runs of the same plan may differ in
# (`stats.timings` since format 1.4: load, world, search, path_planner)
_SECONDS = re.compile(r'("(?:seconds|map_seconds|search_seconds|load|world|search|path_planner)": )[-+0-9.eE]+')


#: First lines of a child Python script that tests Ctrl-C with ``_thread.interrupt_main``: Python's
#: own SIGINT handler, also when the test run was started with SIGINT ignored (a background job of
#: a non-interactive shell), where the child would inherit the ignoring and the interrupt do nothing.
CTRL_C_HANDLER = "import signal\nsignal.signal(signal.SIGINT, signal.default_int_handler)\n"


def need(module: str, install: str):
    """Imports an optional test dependency, or skips the test module without it, unless the
    environment variable ``ASP_TEST_REQUIRE`` (comma-separated top-level names) lists it: there a
    missing package fails the run instead. ``scripts/test`` installs and requires them all, so
    in CI these tests cannot pass by skipping."""
    required = {m.strip() for m in os.environ.get("ASP_TEST_REQUIRE", "").split(",") if m.strip()}
    if module.split(".")[0] in required:
        return importlib.import_module(module)
    return pytest.importorskip(module, reason=install)


def without_seconds(plan_json: str) -> str:
    """The plan JSON with its wall times replaced by 0 (bytes otherwise untouched)."""
    return _SECONDS.sub(r"\g<1>0", plan_json)


def _box_stl(name: str, lo: tuple[float, float, float], hi: tuple[float, float, float]) -> str:
    """An axis-aligned box as ASCII STL, its triangles wound outwards."""
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    v = [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0), (x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)]
    faces = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4),
             (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7)]
    lines = [f"solid {name}"]
    for tri in faces:
        lines += ["facet normal 0 0 0", " outer loop", *(f"  vertex {v[i][0]} {v[i][1]} {v[i][2]}" for i in tri)]
        lines += [" endloop", "endfacet"]
    return "\n".join([*lines, f"endsolid {name}", ""])


#: The crossed-bars model (millimetres, +z up): a plate, a cap standing on it, and a bar pushed
#: through a cross standing on the plate, as a modelling slip draws them (5 mm into each other,
#: no fit): every shipped real model now comes apart, so this is the model with a locked core.
CROSSED_BARS = {
    "plate": ((0, 0, 0), (100, 60, 5)),
    "bar": ((10, 20, 10), (70, 30, 20)),
    "cross": ((35, 10, 5), (45, 40, 25)),
    "cap": ((80, 40, 5), (95, 55, 15)),
}


@pytest.fixture
def crossed_bars(tmp_path: Path) -> str:
    """A folder of STL files, one per part of `CROSSED_BARS` (load it with unit mm, up z): plate
    and cap come off, bar and cross stay in a locked core that `overlaps="lenient"` frees."""
    folder = tmp_path / "crossed_bars"
    folder.mkdir()
    for name, (lo, hi) in CROSSED_BARS.items():
        (folder / f"{name}.stl").write_text(_box_stl(name, lo, hi))
    return str(folder)


@pytest.fixture
def root(monkeypatch: pytest.MonkeyPatch) -> Path:
    """The repository root, also made the working directory (model paths as the CLI gets them)."""
    monkeypatch.chdir(ROOT)
    return ROOT


def _asp_command() -> list[str]:
    env = os.environ.get("ASP_BIN")
    if env:
        return [env]
    for profile in ("debug", "release"):
        exe = ROOT / "target" / profile / "asp"
        if exe.is_file():
            return [str(exe)]
    if shutil.which("cargo"):
        return ["cargo", "run", "-q", "--locked", "-p", "asp-cli", "--"]
    pytest.skip("no asp binary: set ASP_BIN or build it (cargo build -p asp-cli)")


@pytest.fixture
def asp_cli(root: Path) -> Callable[..., tuple[int, str, str]]:
    """Runs ``asp ARGS...`` in the repository root: ``(exit code, stdout, stderr)``."""
    command = _asp_command()

    def run(*args: str) -> tuple[int, str, str]:
        p = subprocess.run(command + list(args), cwd=root, capture_output=True, text=True, timeout=600)
        return p.returncode, p.stdout, p.stderr

    return run
