#!/usr/bin/env python3
"""Writes real assemblies that no test of asp uses, drawn by other people's code, as STEP files:
the assembly examples of build123d and bd_warehouse (both Apache-2.0), run as their authors wrote
them, plus bd_warehouse's bearings pressed into its pillow block in place of the example's. For
docs/benchmarks.md, "Fits and fasteners" (real models); not used by CI or any test.

    python3 -m venv /tmp/b123 && /tmp/b123/bin/pip install build123d==0.13.0 bd_warehouse==0.4.0
    pip download --no-deps --no-binary :all: build123d==0.13.0 bd_warehouse==0.4.0 -d SDISTS
    (cd SDISTS && tar xzf build123d-0.13.0.tar.gz && tar xzf bd_warehouse-0.4.0.tar.gz)
    /tmp/b123/bin/python scripts/real-models-build123d.py SDISTS OUT
    for f in OUT/*.step; do asp plan "$f"; done

The examples call ocp_vscode's `show` (or CQ-editor's `show_object`) to display what they built;
this script stands in for both and writes what the example names as its assembly. A model that an
example fails to build is reported and skipped.
"""

from __future__ import annotations

import os
import runpy
import sys
import tempfile
import types
from pathlib import Path

from build123d import Compound, Unit, export_step

# (name, example file under the sdists, replacements in its source, the globals that hold the
# assembly's parts or subassemblies)
BEARING_SWAP = 'skate_bearing = SingleRowDeepGrooveBallBearing(size="M8-22-7")'
MODELS = [
    ("tutorial_joints", "build123d-0.13.0/docs/tutorial_joints.py", [], ["box_assembly"]),
    ("stud_wall", "build123d-0.13.0/examples/stud_wall.py", [], ["x_wall", "y_wall"]),
    ("slide_latch", "build123d-0.13.0/docs/slide_latch.py", [], ["latch", "slide"]),
    ("toy_truck", "build123d-0.13.0/examples/toy_truck.py", [], ["body", "cab"]),
    ("rigid_joints_pipe", "build123d-0.13.0/docs/rigid_joints_pipe.py", [], ["pipe_builder", "flange_inlet", "flange_outlet"]),
    ("rod_end", "build123d-0.13.0/docs/rod_end.py", [], ["rod_end", "ball"]),
    ("pillow_block_threaded", "bd_warehouse-0.4.0/examples/pillow_block.py", [], ["pillow_block_assembly"]),
    (
        "pillow_block",
        "bd_warehouse-0.4.0/examples/pillow_block.py",
        [("simple=False", "simple=True")],
        ["pillow_block_assembly"],
    ),
] + [
    (
        f"pillow_block_{tag}",
        "bd_warehouse-0.4.0/examples/pillow_block.py",
        [
            ("simple=False", "simple=True"),
            ("import PressFitHole, SingleRowDeepGrooveBallBearing", f"import PressFitHole, {cls}"),
            (BEARING_SWAP, f'skate_bearing = {cls}(size="{size}")'),
        ],
        ["pillow_block_assembly"],
    )
    for tag, cls, size in [
        ("capped", "SingleRowCappedDeepGrooveBallBearing", "M8-22-7"),
        ("angular_contact", "SingleRowAngularContactBallBearing", "M10-30-9"),
        ("cylindrical_roller", "SingleRowCylindricalRollerBearing", "M15-35-11"),
        ("tapered_roller", "SingleRowTaperedRollerBearing", "M15-42-14.25"),
    ]
]


class Shown:
    """Stands in for ocp_vscode and CQ-editor: records nothing, draws nothing."""

    @staticmethod
    def show(*_objects, **_options) -> None:
        return None


def fake_viewer() -> None:
    module = types.ModuleType("ocp_vscode")
    for name in ["show", "show_all", "show_object", "set_port", "set_defaults", "reset_show"]:
        setattr(module, name, Shown.show)
    module.__all__ = ["show", "show_all", "show_object", "set_port", "set_defaults", "reset_show"]  # type: ignore[attr-defined]
    sys.modules["ocp_vscode"] = module


def shape(value, name: str):
    """The shape of an example's global: a BuildPart's part, or the value itself."""
    value = getattr(value, "part", value)
    if getattr(value, "label", None) in (None, ""):
        value.label = name
    return value


def main() -> int:
    if len(sys.argv) != 3:
        print(__doc__, file=sys.stderr)
        return 2
    sdists, out = Path(sys.argv[1]).resolve(), Path(sys.argv[2]).resolve()
    out.mkdir(parents=True, exist_ok=True)
    fake_viewer()
    failed = 0
    for name, file, swaps, names in MODELS:
        source = (sdists / file).read_text()
        for old, new in swaps:
            if old not in source:
                print(f"{name}: {file} has no {old!r}", file=sys.stderr)
                return 1
            source = source.replace(old, new)
        with tempfile.TemporaryDirectory() as work:
            script = Path(work) / Path(file).name
            script.write_text(source)
            # the files an example reads beside it (a screw's STEP file) and where it writes
            (Path(work) / "assets").mkdir()
            for data in (sdists / file).parent.glob("*.step"):
                (Path(work) / data.name).write_bytes(data.read_bytes())
            here = os.getcwd()
            os.chdir(work)
            try:
                found = runpy.run_path(str(script), init_globals={"show_object": Shown.show}, run_name="__main__")
                parts = [shape(found[n], n) for n in names]
                assembly = parts[0] if len(parts) == 1 else Compound(children=parts, label=name)
                export_step(assembly, str(out / f"{name}.step"), unit=Unit.MM)
                print(f"{name}: {out / (name + '.step')}")
            except Exception as e:  # an example that does not build here is skipped, said so
                failed += 1
                print(f"{name}: not built: {type(e).__name__}: {e}", file=sys.stderr)
            finally:
                os.chdir(here)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
