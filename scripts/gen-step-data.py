#!/usr/bin/env python3
"""Writes the STEP test models of tests/data/step/ with build123d (OpenCASCADE), as CAD draws
them: fasteners without their helix, fits at their nominal sizes, a product tree of named
subassemblies and part instances.

    pip install build123d==0.13.0          # about 1 GB with OpenCASCADE; not needed by CI
    python scripts/gen-step-data.py        # (re)writes tests/data/step/*.step
    python scripts/gen-step-data.py --check   # writes to a temporary folder, compares

The files are committed (each well under 1 MB); `--check` (and py/tests/test_step.py where
build123d is installed) holds them equal to what this script writes. Every file has a fixed
timestamp, so the output is byte for byte the same from run to run.
"""

from __future__ import annotations

import argparse
import copy
import filecmp
import sys
import tempfile
from pathlib import Path

from build123d import Align, Box, Compound, Cylinder, Location, Part, Pos, Rot, Unit, export_step

OUT = Path(__file__).resolve().parents[1] / "tests" / "data" / "step"
STAMP = "2026-12-06T00:00:00"
BOTTOM = (Align.CENTER, Align.CENTER, Align.MIN)


def named(shape: Part, label: str) -> Part:
    shape.label = label
    return shape


def group(label: str, children: list) -> Compound:
    return Compound(label=label, children=children)


def plate(x: float, y: float, t: float, holes: list[tuple[float, float]], r: float) -> Part:
    p = Box(x, y, t, align=BOTTOM)
    for hx, hy in holes:
        p -= Pos(hx, hy, 0) * Cylinder(r, t, align=BOTTOM)
    return p


def bolt(length: float, r: float, head_r: float, head_t: float) -> Part:
    """A hexagon-less bolt: a round head on a plain shank of the nominal radius, shank along -z
    from the head's underside at z = 0."""
    return Cylinder(head_r, head_t, align=BOTTOM) + Pos(0, 0, -length) * Cylinder(r, length, align=BOTTOM)


def nut(r: float, width: float, t: float) -> Part:
    return Box(width, width, t, align=BOTTOM) - Cylinder(r, t, align=BOTTOM)


def bolted_plates() -> Compound:
    """Two 10 mm plates held by four M6 bolts and nuts (holes, shanks and nuts at 3 mm radius);
    each bolt and its nut a subassembly `fastener_N`."""
    holes = [(-30, -20), (30, -20), (-30, 20), (30, 20)]
    lower = named(plate(90, 60, 10, holes, 3), "lower_plate")
    upper = named(Pos(0, 0, 10) * plate(90, 60, 10, holes, 3), "upper_plate")
    fasteners = []
    for k, (x, y) in enumerate(holes, 1):
        b = named(Pos(x, y, 20) * bolt(26, 3, 5, 4), "bolt")
        n = named(Pos(x, y, -5) * nut(3, 10, 5), "nut")
        fasteners.append(group(f"fastener_{k}", [b, n]))
    return group("bolted_plates", [lower, upper, *fasteners])


def bolt_grid() -> Compound:
    """Fifty parts: two plates joined by a 4 x 6 grid of M6 bolts and nuts, each pair a
    subassembly (the benchmark's model of 50 parts)."""
    holes = [(x, y) for x in (-75, -45, -15, 15, 45, 75) for y in (-45, -15, 15, 45)]
    lower = named(plate(180, 120, 10, holes, 3), "lower_plate")
    upper = named(Pos(0, 0, 10) * plate(180, 120, 10, holes, 3), "upper_plate")
    # one bolt and one nut, placed 24 times (instances of one product each, as CAD writes them)
    the_bolt, the_nut = bolt(26, 3, 5, 4), nut(3, 10, 5)
    fasteners = []
    for k, (x, y) in enumerate(holes, 1):
        b, n = copy.copy(the_bolt), copy.copy(the_nut)
        b.location, n.location = Location((x, y, 20)), Location((x, y, -5))
        fasteners.append(group(f"fastener_{k}", [named(b, "bolt"), named(n, "nut")]))
    return group("bolt_grid", [lower, upper, *fasteners])


def tapped_screws() -> Compound:
    """A cover screwed onto a block by four M5 screws whose tapped holes are drawn at the
    thread's minor diameter (4.1 mm) while the screws keep their major diameter (5 mm): each
    screw overlaps its hole by the thread's depth, as CAD draws it."""
    holes = [(-25, -15), (25, -15), (-25, 15), (25, 15)]
    block = Box(70, 50, 30, align=BOTTOM)
    for x, y in holes:
        block -= Pos(x, y, 15) * Cylinder(2.05, 15, align=BOTTOM)
    block = named(block, "block")
    cover = named(Pos(0, 0, 30) * plate(70, 50, 6, holes, 2.75), "cover")
    screws = [named(Pos(x, y, 36) * bolt(18, 2.5, 4.5, 3.5), "screw") for x, y in holes]
    return group("tapped_screws", [block, cover, *screws])


def pins_and_dowels() -> Compound:
    """A bracket located on a base by two dowels pressed into both (dowels and bores at 4 mm
    radius, 0.01 mm interference on the dowels) and a roll pin through a clevis."""
    base = Box(80, 40, 15, align=BOTTOM)
    bracket = Pos(0, 0, 15) * Box(80, 40, 10, align=BOTTOM)
    for x in (-25, 25):
        base -= Pos(x, 0, 5) * Cylinder(4, 10, align=BOTTOM)
        bracket -= Pos(x, 0, 15) * Cylinder(4, 10, align=BOTTOM)
    # a clevis on the bracket with a cross bore, a tongue in it, a pin through both
    clevis = Pos(0, 0, 25) * (Box(30, 20, 20, align=BOTTOM) - Pos(0, 0, 5) * Box(10, 20, 15, align=BOTTOM))
    clevis -= Pos(0, 0, 40) * Rot(0, 90, 0) * Cylinder(2.5, 30)
    tongue = Pos(0, 0, 30) * Box(9.8, 20, 30, align=BOTTOM) - Pos(0, 0, 40) * Rot(0, 90, 0) * Cylinder(2.5, 10)
    dowels = [named(Pos(x, 0, 5) * Cylinder(4.01, 20, align=BOTTOM), "dowel") for x in (-25, 25)]
    pin = named(Pos(0, 0, 40) * Rot(0, 90, 0) * Cylinder(2.5, 30), "pin")
    return group(
        "pins_and_dowels",
        [named(base, "base"), group("bracket_assembly", [named(bracket + clevis, "bracket"), *dowels]), named(tongue, "tongue"), pin],
    )


def shaft_bearings() -> Compound:
    """A shaft in two ball bearings (drawn as rings: inner and outer race) in a housing, closed
    by a cover: the shaft with its bearings is a subassembly, each bearing a subassembly of two
    races, nested three levels deep."""
    housing = Cylinder(30, 60, align=BOTTOM) - Pos(0, 0, 5) * Cylinder(16, 55, align=BOTTOM) - Cylinder(8, 5, align=BOTTOM)
    cover = Pos(0, 0, 60) * (Cylinder(30, 5, align=BOTTOM) - Cylinder(8, 5, align=BOTTOM))
    shaft = Pos(0, 0, -10) * Cylinder(8, 90, align=BOTTOM)
    bearings = []
    for k, z in enumerate((5, 48), 1):
        inner = named(Pos(0, 0, z) * (Cylinder(11, 12, align=BOTTOM) - Cylinder(8, 12, align=BOTTOM)), "inner_race")
        outer = named(Pos(0, 0, z) * (Cylinder(16, 12, align=BOTTOM) - Cylinder(11, 12, align=BOTTOM)), "outer_race")
        bearings.append(group(f"bearing_{k}", [inner, outer]))
    spindle = group("spindle", [named(shaft, "shaft"), *bearings])
    return group("shaft_bearings", [named(housing, "housing"), spindle, named(cover, "cover")])


def inch_bracket() -> Compound:
    """An angle bracket bolted to a base with two 1/4-20 bolts and nuts, drawn in inches
    (written with the file's unit `in`). The shape's numbers are inches: OpenCASCADE writes them
    as they are and names the unit, it does not convert them."""
    mm = 1.0  # one inch, in the model's numbers
    holes = [(-1.0 * mm, 0), (1.0 * mm, 0)]
    base = named(plate(3 * mm, 1.5 * mm, 0.25 * mm, holes, 0.125 * mm), "base")
    angle = Pos(0, 0, 0.25 * mm) * plate(3 * mm, 1.5 * mm, 0.25 * mm, holes, 0.125 * mm)
    angle += Pos(0, 0.625 * mm, 0.5 * mm) * Box(3 * mm, 0.25 * mm, 1.5 * mm, align=BOTTOM)
    bolts = []
    for k, (x, y) in enumerate(holes, 1):
        b = named(Pos(x, y, 0.5 * mm) * bolt(0.875 * mm, 0.125 * mm, 0.22 * mm, 0.16 * mm), "bolt_quarter_20")
        n = named(Pos(x, y, -0.22 * mm) * nut(0.125 * mm, 0.44 * mm, 0.22 * mm), "nut_quarter_20")
        bolts.append(group(f"fastener_{k}", [b, n]))
    return group("inch_bracket", [base, named(angle, "angle"), *bolts])


MODELS = {
    "bolted_plates.step": (bolted_plates, Unit.MM),
    "bolt_grid.step": (bolt_grid, Unit.MM),
    "tapped_screws.step": (tapped_screws, Unit.MM),
    "pins_and_dowels.step": (pins_and_dowels, Unit.MM),
    "shaft_bearings.step": (shaft_bearings, Unit.MM),
    "inch_bracket.step": (inch_bracket, Unit.IN),
}


def write(folder: Path) -> None:
    from OCP.Interface import Interface_Static
    from OCP.STEPControl import STEPControl_Controller

    folder.mkdir(parents=True, exist_ok=True)
    STEPControl_Controller.Init_s()
    for name, (make, unit) in MODELS.items():
        # OpenCASCADE names `write.step.unit` as the file's unit; the numbers stay the shape's
        Interface_Static.SetCVal_s("write.step.unit", "INCH" if unit == Unit.IN else "MM")
        export_step(make(), folder / name, unit=unit, timestamp=STAMP)
    Interface_Static.SetCVal_s("write.step.unit", "MM")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--check", action="store_true", help="compare with tests/data/step/ instead of writing it")
    args = parser.parse_args()
    if not args.check:
        write(OUT)
        print(f"wrote {len(MODELS)} files to {OUT}")
        return 0
    with tempfile.TemporaryDirectory() as tmp:
        write(Path(tmp))
        differ = [n for n in MODELS if not filecmp.cmp(Path(tmp) / n, OUT / n, shallow=False)]
    for n in differ:
        print(f"tests/data/step/{n} differs from what scripts/gen-step-data.py writes", file=sys.stderr)
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
