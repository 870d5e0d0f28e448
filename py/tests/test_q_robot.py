"""Q-functions for the robot's objective: ``Assembly.q_graphs`` takes the robot's
keywords (what a data set of ``asp collect transitions --robot`` records), builds the robot-path
problem with its reward range, and gives the same ``asp-q/1`` graphs as without the robot; a Q
model of another objective is refused by ``Assembly.plan`` under the robot."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import asp

ROOT = Path(__file__).resolve().parents[2]
BEAM = ROOT / "tests" / "data" / "beam" / "beam.glb"
FIXTURES = ROOT / "crates" / "asp-learn" / "tests" / "data"


def test_q_graphs_take_the_robot_and_give_the_same_graphs():
    model = asp.load(BEAM)
    robot = model.q_graphs(objective="robot-path", resolution=5, robot="panda", drop_off=(0.1, 0.5, 0.3), replans=2)
    assert tuple(robot.objectives) == ("robot-path",)
    assert [tuple(r) for r in robot.reward_ranges] == [(-20.0, 0.0)]
    assert robot.features == "asp-q/1 directions=25 neighbours=8"
    plain = model.q_graphs(objective="pathlen", resolution=5)
    present = list(range(plain.num_parts))
    actions = plain.feasible_actions(present)
    a, b = robot.graph(present, actions=actions), plain.graph(present, actions=actions)
    for name in ("nodes", "x", "edge_index", "edge_attr"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    with pytest.raises(asp.ConfigError, match="robot-path needs a robot"):
        model.q_graphs(objective="robot-path", resolution=5)
    with pytest.raises(asp.ConfigError, match="drop_off: needs a robot"):
        model.q_graphs(objective="pathlen", resolution=5, drop_off=(0, 0, 1))


def test_a_q_model_of_another_objective_is_refused_under_the_robot():
    model = asp.load(BEAM)
    with pytest.raises(asp.ConfigError, match="estimates objective 'access', but its place in the list is that of 'robot-path'"):
        model.plan(objective="robot-path", robot="panda", q=str(FIXTURES / "random_q_access.onnx"), resolution=5, episodes=1)
