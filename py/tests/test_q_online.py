"""The online settings of thesis 6.5: a search run episode by episode from Python
(``asp.Assembly.search``) whose Q-functions are trained after every episode
(``python -m asp.train q-online``, :mod:`asp.train.online`), on a generated 4×4×4 Soma cube with
fixed seeds and a few episodes."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from conftest import CTRL_C_HANDLER, _asp_command, need, without_seconds

torch = need("torch", "asp.train needs torch (pip install ./py[train])")

import asp  # noqa: E402
from asp.qdata import TransitionDataset  # noqa: E402
from asp.train.online import OnlineConfig, run_online  # noqa: E402

#: Small networks and few steps: the tests check the plumbing, not what is learned.
SMALL = dict(steps_per_episode=3, batch=4, width=16, layers=2, resolution=5)


@pytest.fixture(scope="module")
def cube(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("cube")
    subprocess.run(_asp_command() + ["gen", "soma", "--size", "4", "--count", "1", "--seed", "31", "--out", str(out)],
                   check=True, capture_output=True, timeout=600)
    return out / "soma4_000.glb"


def lines_by_episode(text: str) -> dict[int, list[str]]:
    out: dict[int, list[str]] = {}
    for line in text.splitlines():
        if line.strip():
            out.setdefault(json.loads(line)["episode"], []).append(line)
    return out


def feasible(model: Path, objective: str, sequence: list[int], resolution: int) -> bool:
    """Whether ``sequence`` removes every removable part, each feasible where it is removed."""
    qg = asp.load(model).q_graphs(objective=objective, resolution=resolution)
    present = list(range(qg.num_parts))
    for p in sequence:
        if p not in qg.feasible_actions(present):
            return False
        present.remove(p)
    return len(sequence) == qg.removable


def test_the_stepped_search_from_python_is_the_plan_and_swaps_models(cube: Path) -> None:
    a = asp.load(cube)
    s = a.search(objective="access", seed=3, resolution=5, episodes=4)
    assert s.objectives == ["access"] and s.index["assemblies"][0]["removable"] > 0
    ends = [s.episode() for _ in range(4)]
    assert [e.episodes for e in ends] == [1, 2, 3, 4] and ends[-1].finished and not ends[0].finished
    assert all(e.records and all(r["episode"] == k for r in e.records) for k, e in enumerate(ends))
    with pytest.raises(asp.ConfigError, match="ended"):
        s.episode()
    recorded = s.result()
    # no swap: exactly Assembly.plan's answer on one thread (recording runs removability tests of
    # its own, which count in the statistics: the same plan otherwise)
    s = a.search(objective="access", seed=3, resolution=5, episodes=4, record=False)
    assert all(e.records == [] for e in [s.episode() for _ in range(4)])
    plan = s.result()
    same = a.plan(objective="access", seed=3, resolution=5, episodes=4, threads=1)
    assert without_seconds(plan.json) == without_seconds(same.json)
    assert recorded.disassembly_sequence == same.disassembly_sequence
    with pytest.raises(asp.ConfigError):
        a.search(seed=3)  # no objective


def test_online_swaps_models_after_each_episode_and_learns_from_what_the_search_recorded(cube: Path, tmp_path: Path) -> None:
    config = OnlineConfig(objective="access", episodes=4, seed=5, keep_models=True, **SMALL)
    r = run_online(cube, tmp_path / "on", config, log=None)
    # a model after each episode but the last, the first episode random
    assert r.episodes == 4 and r.swaps == 3 and r.steps == 3 * SMALL["steps_per_episode"]
    kept = sorted((tmp_path / "on" / "models").glob("*_q_access.onnx"))
    assert [p.name for p in kept] == ["1_q_access.onnx", "2_q_access.onnx", "3_q_access.onnx"]
    # the transitions learned from are the search's: a search driven by hand with the same seed
    # and the same models, swapped in after the same episodes, records the same lines
    written = (tmp_path / "on" / "transitions" / "model" / "transitions.jsonl").read_text()
    s = asp.load(cube).search(objective="access", seed=5, resolution=5, episodes=4)
    by_hand = []
    for k in range(4):
        by_hand.append(s.episode().transitions_jsonl)
        if k < 3:
            s.set_q([kept[k]])
    assert s.swaps == 3
    assert "".join(by_hand) == written
    assert len(lines_by_episode(written)) == 4
    assert without_seconds(s.result().json) == without_seconds(r.plan.json)
    # the transitions are a data set `python -m asp.train q` reads
    ds = TransitionDataset.open(tmp_path / "on" / "transitions")
    assert sum(1 for _ in ds.transitions()) == r.transitions == written.count("\n")
    # the answer is a feasible complete sequence
    assert r.plan.found and feasible(cube, "access", r.plan.disassembly_sequence, 5)


def test_the_same_seed_and_episodes_give_the_same_front(cube: Path, tmp_path: Path) -> None:
    config = OnlineConfig(objective="access,dirchange", episodes=3, seed=2, **SMALL)
    a = run_online(cube, tmp_path / "a", config, log=None)
    b = run_online(cube, tmp_path / "b", config, log=None)
    assert a.swaps == b.swaps == 2
    front = lambda r: r.plan.to_dict()["pareto_front"]  # noqa: E731
    assert front(a) and front(a) == front(b)
    assert without_seconds(a.plan.json) == without_seconds(b.plan.json)
    for name in ("q_access.onnx", "q_dirchange.onnx"):
        assert (tmp_path / "a" / name).read_bytes() == (tmp_path / "b" / name).read_bytes()
    assert all(feasible(cube, "access,dirchange", p["disassembly_sequence"], 5) for p in front(a))


def test_retrained_starts_from_pretrained_weights_from_the_command_line(cube: Path, tmp_path: Path) -> None:
    run_online(cube, tmp_path / "pre", OnlineConfig(objective="access", episodes=2, seed=1, **SMALL), log=None)
    pretrained = tmp_path / "pre" / "q_access.onnx"
    assert Path(str(pretrained) + ".pt").is_file()
    p = subprocess.run(
        [sys.executable, "-m", "asp.train", "q-online", str(cube), "--objective", "access", "--episodes", "3",
         "--q", str(pretrained), "--out", str(tmp_path / "re"), "--steps-per-episode", "2", "--batch", "4",
         "--resolution", "5"],
        capture_output=True, text=True, timeout=600,
    )
    assert p.returncode == 0, p.stderr
    assert "episode 1:" in p.stderr and "2 model swaps" in p.stdout, (p.stdout, p.stderr)
    doc = json.loads((tmp_path / "re" / "online.json").read_text())
    assert doc["setting"] == "retrained" and doc["swaps"] == 2
    # a model without its weights cannot be retrained: one line naming the file
    (tmp_path / "bare.onnx").write_bytes(pretrained.read_bytes())
    p = subprocess.run(
        [sys.executable, "-m", "asp.train", "q-online", str(cube), "--objective", "access", "--episodes", "2",
         "--q", str(tmp_path / "bare.onnx"), "--out", str(tmp_path / "x"), "--resolution", "5"],
        capture_output=True, text=True, timeout=600,
    )
    assert p.returncode == 2 and "bare.onnx.pt" in p.stderr and len(p.stderr.strip().splitlines()) == 1, p.stderr


def test_bench_mcts_prints_the_four_settings_and_the_cli_points_to_it(cube: Path, tmp_path: Path) -> None:
    run_online(cube, tmp_path / "pre", OnlineConfig(objective="access", episodes=2, seed=1, **SMALL), log=None)
    q = str(tmp_path / "pre" / "q_access.onnx")
    p = subprocess.run(
        [sys.executable, "-m", "asp.train", "bench-mcts", str(cube.parent), "--objective", "access", "--q", q,
         "--seconds", "1,2", "--resolution", "5", "--steps-per-episode", "2", "--batch", "4", "--csv", str(tmp_path / "b.csv")],
        capture_output=True, text=True, timeout=600,
    )
    assert p.returncode == 0, p.stderr
    assert "soma4_000" in p.stdout, p.stdout  # a folder of models is expanded
    for setting in ("vanilla", "online", "pretrained", "retrained"):
        assert f"  {setting}" in p.stdout, p.stdout
    assert "access at 2 s" in p.stdout and "mean over 1 model(s)" in p.stdout
    assert (tmp_path / "b.csv").read_text().count("\n") == 1 + 4 * 2
    code = subprocess.run(_asp_command() + ["bench", "mcts", str(cube), "--objective", "access", "--settings", "vanilla,online"],
                          capture_output=True, text=True, timeout=600)
    assert code.returncode == 2 and "python -m asp.train bench-mcts" in code.stderr, code.stderr


def test_ctrl_c_stops_a_stepped_search(cube: Path, tmp_path: Path) -> None:
    script = CTRL_C_HANDLER + f"""
import _thread, threading, time, asp
s = asp.load({str(cube)!r}).search(objective="access", episodes=10**9, budget=10**9, resolution=5)
threading.Timer(1.0, _thread.interrupt_main).start()
start = time.monotonic()
try:
    s.episode()
    print("finished", time.monotonic() - start)
except KeyboardInterrupt:
    print("interrupted", time.monotonic() - start, s.ended)
"""
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=600)
    assert p.returncode == 0, p.stderr
    word, seconds, ended = p.stdout.split()
    assert word == "interrupted" and float(seconds) < 10 and ended == "True", p.stdout
