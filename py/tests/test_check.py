"""``Assembly.check``: a given sequence tested with the planner's removal tests, as ``asp check``
reports it."""

from __future__ import annotations

from pathlib import Path

import pytest

import asp
from conftest import _box_stl

#: Two boxes stacked on a base (metres): the lower one slides out sideways, which leaves the top
#: one floating, so the top box cannot be placed first.
STACK = {
    "base": ((-1, -1, -0.5), (2, 2, 0)),
    "lower": ((0, 0, 0), (1, 1, 1)),
    "top": ((0, 0, 1), (1, 1, 2)),
}


@pytest.fixture
def stack(tmp_path: Path) -> asp.Assembly:
    folder = tmp_path / "stack"
    folder.mkdir()
    for name, (lo, hi) in STACK.items():
        (folder / f"{name}.stl").write_text(_box_stl(name, lo, hi))
    return asp.load(folder, up="z", fixed=["base"])


def test_check_feasible_sequence(stack):
    report = stack.check(["lower", "top -z"], path_planner=False)
    assert report["status"] == "feasible"
    assert report["first_failure"] is None
    assert [s["parts"][0]["name"] for s in report["steps"]] == ["lower", "top"]
    assert report["steps"][1]["motion"]["direction"] == [0.0, 0.0, -1.0]
    assert "repair" not in report


def test_check_infeasible_sequence_with_repair(stack):
    report = stack.check("top\nlower\n", path_planner=False)
    assert report["status"] == "infeasible"
    assert report["first_failure"] == 1
    failure = report["steps"][1]["failure"]
    assert failure["reason"] == "unstable"
    assert [p["name"] for p in failure["floating"]] == ["top"]
    repair = report["repair"]
    assert repair["status"] == "found"
    assert [s["parts"][0]["name"] for s in repair["sequence"]] == ["lower", "top"]
    assert (repair["moved"], repair["kendall_tau"]) == (1, 1)
    # the repair checks feasible
    again = stack.check([s["parts"][0]["name"] for s in repair["sequence"]], path_planner=False)
    assert again["status"] == "feasible"


def test_check_groups_and_files(stack, tmp_path):
    assert stack.check([["lower", "top"]], path_planner=False)["status"] == "feasible"
    seq = tmp_path / "seq.txt"
    seq.write_text("# the stack\nbase\nlower\ntop\n")
    report = stack.check(seq, path_planner=False)
    assert report["status"] == "feasible"
    assert report["notes"], "the base part listed is noted"


def test_check_unknown_names_suggest_the_nearest(stack):
    with pytest.raises(asp.ConfigError, match=r"'lowr' \(nearest: lower"):
        stack.check(["lowr", "top"])
    with pytest.raises(TypeError):
        stack.check(["lower", "top"], no_such_setting=1)


def test_plan_precedence_keyword(stack):
    import json

    plan = stack.plan(precedence=True, path_planner=False)
    graph = json.loads(plan.json)["precedence"]
    assert graph["stability"]["conservative"] is True
    assert len(graph["steps"]) == 2
    # the top box rests on the lower one: it goes in after it
    assert [(e["before"], e["after"]) for e in graph["edges"]] == [(0, 1)]
    assert "supports" in graph["edges"][0]["reasons"]
    assert graph["critical_path"] == [0, 1]
    assert "precedence" not in json.loads(stack.plan(path_planner=False).json)


def test_check_with_the_robot_names_its_reason(stack):
    # metre boxes: nothing blocks them, but no grasp of the arm's gripper fits them
    report = stack.check(["lower", "top -z"], path_planner=False, robot="panda")
    assert report["status"] == "infeasible"
    assert report["robot"]["name"]
    failure = report["steps"][report["first_failure"]]["failure"]
    assert failure["reason"] == "robot"
    assert failure["robot_reason"] == "no reachable grasp"
    assert report["repair"]["status"] == "none"
