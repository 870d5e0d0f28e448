"""Planning from Python gives the CLI's plan JSON, byte for byte apart from wall times."""

from __future__ import annotations

import json
import re

import pytest

import asp
from conftest import BEARING, LACK, PUMP, ROLLER_BEARING, without_seconds


@pytest.mark.parametrize(
    "kwargs, flags",
    [
        ({}, []),
        ({"order": "random", "seed": 3, "bookkeeping": True}, ["--order", "random", "--seed", "3", "--bookkeeping"]),
        ({"order": "shuffled", "seed": 7, "normals": 4, "sphere_directions": 6},
         ["--order", "shuffled", "--seed", "7", "--normals", "4", "--sphere-directions", "6"]),
        ({"order": "gnn", "seed": 2, "bookkeeping": True}, ["--order", "gnn", "--seed", "2", "--bookkeeping"]),
        ({"order": "bookkeeping", "tolerance": 0.0005, "path_planner": False},
         ["--order", "bookkeeping", "--tolerance", "0.0005", "--no-path-planner"]),
    ],
)
def test_plan_json_is_the_clis(root, asp_cli, kwargs, flags):
    code, out, err = asp_cli("plan", LACK, "--up", "z", "--json", *flags)
    assert code == 0, err
    plan = asp.plan(LACK, up="z", **kwargs)
    assert plan.found and plan.status == "found"
    assert without_seconds(plan.json) == without_seconds(out)
    # and the wall time really is the only difference that was masked
    assert plan.json.count('"seconds"') == out.count('"seconds"') == 1


def test_optimised_plan_json_is_the_clis(root, asp_cli):
    flags = ["--objective", "access", "--episodes", "40", "--threads", "1", "--seed", "2"]
    code, out, err = asp_cli("plan", LACK, "--up", "z", "--json", *flags)
    assert code == 0, err
    plan = asp.load(LACK, up="z").plan(objective="access", episodes=40, threads=1, seed=2)
    assert without_seconds(plan.json) == without_seconds(out)
    assert plan.optimisation["method"] == "mcts"
    assert plan.trace_csv is not None and plan.trace_csv.count("\n") >= 2


def test_local_search_share_is_the_clis_polish_flag(root, asp_cli):
    flags = ["--objective", "access", "--episodes", "40", "--threads", "1", "--seed", "2", "--polish", "0"]
    code, out, err = asp_cli("plan", LACK, "--up", "z", "--json", *flags)
    assert code == 0, err
    a = asp.load(LACK, up="z")
    off = a.plan(objective="access", episodes=40, threads=1, seed=2, polish=0)
    assert without_seconds(off.json) == without_seconds(out)
    assert off.optimisation["polish"] == 0 and off.optimisation["polished"] == 0
    on = a.plan(objective="access", episodes=40, threads=1, seed=2)
    assert on.optimisation["polish"] == 0.25
    # the same tree search; the local search keeps the best sequence or finds a better one
    assert on.optimisation["iterations"] == off.optimisation["iterations"]
    assert on.optimisation["values"][0] >= off.optimisation["values"][0]
    with pytest.raises(asp.ConfigError, match="polish: must be a share of the search"):
        a.plan(objective="access", episodes=5, polish=-1.0)


def test_no_plan_explains_what_holds_what(crossed_bars, asp_cli):
    a = asp.load(crossed_bars, unit="mm", up="z")
    # single parts only: the cap comes off; bar and cross, pushed into each other, hold each
    # other, and the plate cannot leave from under them (with subassemblies, the default, the two
    # leave as one subassembly that cannot be taken apart: a partial plan,
    # test_a_plan_with_a_locked_core_is_partial)
    assert a.plan().status == "partial"
    plan = a.plan(subassemblies=False)
    assert plan.status == "no_plan" and not plan.found
    assert plan.assembly_sequence == []
    explanation = plan.explanation
    assert explanation, "a no_plan result explains the dead end"
    names = {p.name for p in a.parts}
    for entry in explanation:
        assert entry["name"] in names
        assert entry["reason"] in ("blocked", "unsupported", "dead_end")
    why = {e["name"]: (e["reason"], sorted(q["name"] for q in e["parts"])) for e in explanation}
    assert why == {
        "bar": ("blocked", ["cross", "ground", "plate"]),
        "cross": ("blocked", ["bar", "ground", "plate"]),
        "plate": ("unsupported", ["bar", "cross"]),
    }
    # the partial plan: the parts that came off, onto the stuck core that remains
    partial = [s["part"] for s in plan.partial_assembly_sequence]
    assert partial == plan.disassembly_sequence[::-1] and len(partial) == len(a) - 3
    assert sorted(plan.remaining + partial) == list(range(len(a)))
    assert sorted(a.parts[i].name for i in plan.remaining) == ["bar", "cross", "plate"]
    assert {e["part"] for e in explanation} <= set(plan.remaining)
    code, out, err = asp_cli("plan", crossed_bars, "--unit", "mm", "--up", "z", "--json", "--no-subassemblies")
    assert code == 1, err
    assert without_seconds(plan.json) == without_seconds(out)


def test_assembly_owns_its_data_and_plans_again(root, tmp_path):
    copy = tmp_path / "lack.glb"
    copy.write_bytes((root / LACK).read_bytes())
    a = asp.load(copy, up="z")
    copy.unlink()  # the handle no longer needs the file
    first, second = a.plan(), a.plan()
    assert without_seconds(first.json) == without_seconds(second.json)
    assert a.source == str(copy) and first.model == str(copy)


def test_plan_result_views(root, tmp_path):
    a = asp.load(LACK, up="z")
    assert len(a) == len(a.parts) == 5
    assert [p.index for p in a.parts] == list(range(5))
    assert a.units == "m" and a.up == "+z"
    plan = a.plan()
    d = plan.to_dict()
    assert d == json.loads(plan.json)
    d["status"] = "changed"
    assert plan.status == "found", "to_dict returns a copy"
    assert [p["name"] for p in plan.parts] == [p.name for p in a.parts]
    movable = [p for p in a.parts if not p.fixed]
    assert len(plan.assembly_sequence) == len(movable)
    assert sorted(plan.disassembly_sequence) == sorted(p.index for p in movable)
    assert plan.stats["removal_tests"] >= len(movable)
    assert plan.optimisation is None and plan.pareto_front is None and plan.trace_csv is None
    out = tmp_path / "plan.json"
    plan.write(out)
    assert out.read_text() == plan.json
    assert a.part(a.parts[2].name) == a.parts[2]


def test_budget_exhausted_is_a_status(root):
    plan = asp.plan(PUMP, unit="mm", up="z", max_tests=5)
    assert plan.status == "budget_exhausted" and not plan.found
    assert plan.stats["removal_tests"] == 5


def test_defaults_are_the_librarys():
    import inspect
    import typing

    from asp import _asp, settings

    defaults = _asp.default_settings()
    plan = inspect.signature(asp.Assembly.plan).parameters
    graph = {k: p.default for k, p in inspect.signature(asp.Assembly.graph).parameters.items()
             if k not in ("self", "present")}
    # every plan keyword is a setting of the request, left to its default by None
    assert set(plan) - {"self"} == set(defaults) - {"radius_bins", "degree", "points_per_part"}
    assert all(p.default is None for k, p in plan.items() if k != "self")
    assert set(typing.get_type_hints(settings.PlanSettings)) == set(plan) - {"self"}
    assert {k: v for k, v in graph.items() if v is not None} == {k: defaults[k] for k in graph if graph[k] is not None}
    # the closed sets are the library's, in its order
    choices = _asp.choices()
    for name, literal in [("order", settings.Order), ("overlaps", settings.Overlaps), ("stability", settings.Stability),
                          ("support", settings.Support), ("q_use", settings.QUse)]:
        assert list(typing.get_args(literal)) == choices[name], name
    assert asp.ORDERS == tuple(choices["order"])


@pytest.mark.parametrize(
    "flags",
    [
        [],
        ["--objective", "access", "--episodes", "40", "--threads", "1", "--seed", "2"],
    ],
)
def test_plan_table_is_the_clis_stdout(root, asp_cli, tmp_path, flags):
    out_json = tmp_path / "plan.json"
    code, out, err = asp_cli("plan", LACK, "--up", "z", "--out", str(out_json), *flags)
    assert code == 0, err
    # the CLI's own plan, as text from Python: its stdout byte for byte
    cli_plan = asp.Plan(out_json.read_text(), True)
    assert cli_plan.table() == out
    assert out.startswith(f"{LACK}: found in ")
    # and the same run from Python: the same text but for the wall times
    kwargs = {} if not flags else {"objective": "access", "episodes": 40, "threads": 1, "seed": 2}
    plan = asp.load(LACK, up="z").plan(**kwargs)
    times = re.compile(r"\d+\.\d+ s\b")
    assert times.sub("T s", plan.table()) == times.sub("T s", out)


def test_plan_table_of_a_bad_json_is_an_asp_error():
    with pytest.raises(asp.AspError, match="plan JSON: not a plan"):
        asp.Plan('{"status": "found"}', True).table()


def test_a_plan_with_a_locked_core_is_partial(crossed_bars, asp_cli):
    # With subassemblies (the default) the sequence is complete, but bar and cross go in
    # as one unit its own plan cannot open: the plan is partial, not found, with that core listed,
    # as the CLI says it (exit code 1)
    plan = asp.load(crossed_bars, unit="mm", up="z").plan()
    assert plan.status == "partial" and not plan.found
    assert plan.assembly_sequence and plan.remaining is None
    cores = plan.locked_cores
    assert len(cores) == 1
    core = cores[0]
    assert core["names"] == ["bar", "cross"]
    assert core["status"] == "no_plan" and core["explanation"]
    assert core["base"] in core["parts"]
    # why it is locked (format 1.9): one overlap, no fit, deeper than any
    # tessellation artefact; the bar blocked by the cross along every direction; no grid;
    # lenient overlaps would free the bar
    why = core["why"]
    assert len(why["overlaps"]) == 1
    overlap = why["overlaps"][0]
    assert overlap["names"] == ["bar", "cross"] and overlap["gross"] and overlap["artefact"]
    assert overlap["depth"] > why["artefact_depth"]
    assert sorted(b["part"] for b in why["blocks"]) == sorted(p for p in core["parts"] if p != core["base"])
    assert all(b["free"] == 0 and b["by"] for b in why["blocks"])
    assert why["grid"] == {"tried": False, "reason": "not_on_grid", "core_on_grid": False}
    assert why["lenient"] == {"status": "found", "frees": 1}
    cores[0]["names"] = []
    assert plan.locked_cores[0]["names"], "locked_cores returns a copy"
    code, out, err = asp_cli("plan", crossed_bars, "--unit", "mm", "--up", "z", "--json")
    assert code == 1, err
    assert without_seconds(plan.json) == without_seconds(out)
    table = plan.table()
    assert ": partial in " in table.splitlines()[0]
    assert table.splitlines()[1] == "planned 2 of 4 parts; 2 stay in 1 locked core: bar, cross"
    assert table.splitlines()[2] == "  why the core on cross (2 parts) is locked:"
    assert "    --overlaps lenient: would free its other part\n" in table
    # declared one unit on purpose, the same core makes the plan found
    core = plan.locked_cores[0]  # a fresh copy (the one above had its names cleared)
    unit = asp.load(crossed_bars, unit="mm", up="z").plan(unit_group=[core["names"]])
    assert unit.status == "found" and unit.found and unit.locked_cores == []
    step = next(s for s in unit.to_dict()["assembly_sequence"] if "subassembly" in s)
    assert step["subassembly"]["status"] == "unit" and sorted(step["subassembly"]["parts"]) == sorted(core["parts"])
    with pytest.raises(asp.ConfigError, match="unit_group: no part is named 'nope'"):
        asp.load(crossed_bars, unit="mm", up="z").plan(unit_group="nope,bar")
    # a plan that takes every part apart has none: the pump, its screws, shaft and ring taken
    # out along their fits, and an IKEA table
    pump = asp.load(PUMP, unit="mm", up="z").plan()
    assert pump.status == "found" and pump.found and pump.locked_cores == []
    lack = asp.plan(LACK, up="z")
    assert lack.status == "found" and lack.found and lack.locked_cores == []


def test_steps_are_typed_frozen_views_of_the_sequence(root, crossed_bars):
    import dataclasses

    # a plan with linear motions and a subassembly whose own plan is a locked core
    plan = asp.load(crossed_bars, unit="mm", up="z").plan()
    steps = plan.steps
    assert len(steps) == len(plan.assembly_sequence)
    for step, entry in zip(steps, plan.assembly_sequence):
        assert (step.part, step.name, step.motion.kind) == (entry["part"], entry["name"], entry["motion"]["kind"])
        if step.motion.kind == "linear":
            assert step.motion.direction == tuple(entry["motion"]["direction"])
            assert step.motion.distance == entry["motion"]["distance"]
    subs = [s for s in steps if s.subassembly is not None]
    assert [sorted(s.subassembly.parts) for s in subs] == [sorted(plan.locked_cores[0]["parts"])]
    assert subs[0].subassembly.status == "no_plan"
    with pytest.raises(dataclasses.FrozenInstanceError):
        steps[0].part = 99  # type: ignore[misc]
    assert plan.partial_steps == ()

    # every motion kind and step key the format documents, read from a hand-written plan
    d = json.loads(plan.json)
    d["assembly_sequence"] = [
        {"part": 1, "name": "bolt", "motion": {"kind": "screw", "direction": [0, 0, -1], "distance": 2.5,
                                               "axis_point": [1, 2, 3]}, "held": [4]},
        {"part": 2, "name": "hook", "motion": {"kind": "path", "pivot": [0, 0, 1],
                                               "poses": [[0, 0, 1, 0, 0, 0, 1], [0, 0, 0, 0, 0, 0, 1]]},
         "moves": [{"parts": [2, 3], "translation": [0, 0, -0.01]}],
         "robot": {"grasp": [0, 0, 0, 0, 0, 0, 1], "grasp_width": 0.02, "joint_trajectory": [[0.1, 0.2], [0.3, 0.4]],
                   "gripper_path": [[0, 0, 0], [0, 0, 0.05]], "path_length": 0.05},
         "a_key_of_a_newer_format": True},
    ]
    screw, hook = asp.Plan(json.dumps(d), found=True).steps
    assert screw.motion == asp.Motion("screw", direction=(0.0, 0.0, -1.0), distance=2.5, axis_point=(1.0, 2.0, 3.0))
    assert screw.held == (4,) and screw.moves == () and screw.robot is None
    assert hook.motion.kind == "path" and hook.motion.pivot == (0.0, 0.0, 1.0) and len(hook.motion.poses) == 2
    assert hook.moves == (asp.Move((2, 3), (0.0, 0.0, -0.01)),)
    assert hook.robot is not None and hook.robot.joint_trajectory == ((0.1, 0.2), (0.3, 0.4))
    assert hook.robot.path_length == 0.05


def test_split_bodies_makes_each_body_of_a_mesh_a_part(tmp_path):
    # A shelf whose mesh also holds two pins stored beside it: named in a
    # warning and moved as one part, or, with split_bodies, one part per body
    from conftest import _box_stl

    folder = tmp_path / "shelf"
    folder.mkdir()
    bodies = [_box_stl("shelf", lo, hi) for lo, hi in [((0, 0, 0), (400, 200, 20)), ((500, 0, 0), (520, 20, 100)),
                                                        ((600, 0, 0), (620, 20, 100))]]
    # one solid of all three bodies' facets
    facets = [line for b in bodies for line in b.splitlines()[1:-1]]
    (folder / "shelf.stl").write_text("\n".join(["solid shelf", *facets, "endsolid shelf", ""]))
    (folder / "side.stl").write_text(_box_stl("side", (0, 0, 20), (20, 200, 300)))
    whole = asp.load(folder, unit="mm", up="z")
    assert [p.name for p in whole.parts] == ["shelf", "side"]
    assert any(w.startswith("part 'shelf' holds 3 separate bodies") and "--split-bodies" in w for w in whole.warnings)
    split = asp.load(folder, unit="mm", up="z", split_bodies=True)
    assert [p.name for p in split.parts] == ["shelf#1", "shelf#2", "shelf#3", "side"]
    assert split.warnings == ("split into one part per body (--split-bodies): shelf",)
    plan = split.plan()
    assert plan.found and len(plan.assembly_sequence) == 4
    assert without_seconds(asp.plan(folder, unit="mm", up="z", split_bodies=True).json) == without_seconds(plan.json)
    with pytest.raises(TypeError, match="split_bodies"):
        whole.plan(split_bodies=True)  # type: ignore[call-arg]


def test_a_ball_bearing_is_one_unit(root, asp_cli):
    # balls captive between two rings: recognised, planned as one unit, listed in the plan
    plan = asp.load(BEARING, up="z").plan()
    assert plan.status == "found" and plan.locked_cores == []
    (bearing,) = plan.bearings
    assert bearing["names"] == ["inner ring", "outer ring"] and len(bearing["balls"]) == 9 and bearing["rows"] == 1
    unit = next(s for s in plan.to_dict()["assembly_sequence"] if "subassembly" in s)["subassembly"]
    assert unit["status"] == "unit" and sorted(unit["parts"]) == bearing["parts"]
    assert "rolling bearing: inner ring in outer ring, 9 balls in 1 row" in plan.table()
    code, out, err = asp_cli("plan", BEARING, "--up", "z", "--json")
    assert code == 0, err
    assert without_seconds(plan.json) == without_seconds(out)


def test_a_roller_bearing_is_one_unit():
    # rollers between two ribbed rings: a bearing too, and the plan says what rolls
    plan = asp.load(ROLLER_BEARING, up="z").plan()
    assert plan.status == "found" and plan.locked_cores == []
    (bearing,) = plan.bearings
    assert bearing["rolling_elements"] == "rollers" and len(bearing["balls"]) == 10
    assert "rolling bearing: inner ring in outer ring, 10 rollers in 1 row" in plan.table()
    assert asp.load(LACK, up="z").plan().bearings == []
