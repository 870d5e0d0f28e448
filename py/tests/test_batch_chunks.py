"""asp.batch's plan chunks (no Ray needed): a chunk of models is one native call
(``_asp.plan_items``) whose plan files are ``asp plan --each``'s, with errors per model; Ray
tasks are sized by measured cost (:class:`ChunkSizer`)."""

from __future__ import annotations

import json
import time
from pathlib import Path

from asp import _asp
from asp.batch import GenJob, PlanJob, run, runner
from asp.batch.runner import ChunkSizer, chunk_size
from conftest import without_seconds


def soma_models(tmp_path: Path, count: int) -> Path:
    out = tmp_path / "soma3"
    run(GenJob.soma(size=3, count=count, seed=5), out, ray="none", quiet=True)
    return out


def plan_files(folder: Path) -> dict[str, str]:
    return {p.name: p.read_text() for p in sorted(folder.glob("*.json")) if p.name != "summary.json"}


def test_a_serial_batch_writes_the_plans_of_asp_plan_each(tmp_path, asp_cli):
    models = soma_models(tmp_path, 20)
    cli, batch = tmp_path / "each", tmp_path / "batch"
    code, _, err = asp_cli("plan", "--each", str(models), "--order", "shuffled", "--seed", "2", "--quiet", "--out", str(cli))
    assert code == 0, err
    outcome = run(PlanJob([models], {"order": "shuffled", "seed": 2}), batch, ray="none", quiet=True)
    assert outcome.ok and outcome.ran == 20
    mine, theirs = plan_files(batch), plan_files(cli)
    assert list(mine) == list(theirs) and len(mine) == 20
    for name, text in mine.items():
        assert without_seconds(text) == without_seconds(theirs[name]), name
        # the load's time is in the plan's timings, as `asp plan` records it (it was 0 before)
        assert json.loads(text)["stats"]["timings"]["load"] > 0, name
    summary = json.loads((batch / "summary.json").read_text())
    for row in summary["plans"]:
        plan = json.loads(mine[row["file"]])
        assert row["steps"] == len(plan["assembly_sequence"]) > 0
        assert row["removal_tests"] == plan["stats"]["removal_tests"]
        assert (row["status"], row["found"], row["parts"]) == (plan["status"], True, len(plan["parts"]))


def test_a_chunk_keeps_its_order_and_reports_errors_per_model(tmp_path):
    models = soma_models(tmp_path, 3)
    broken = tmp_path / "broken.glb"
    broken.write_bytes(b"not a glb")
    pairs = [(str(models / "soma3_000.glb"), "a.json"), (str(broken), "b.json"), (str(models / "soma3_002.glb"), "c.json")]
    out = tmp_path / "out"
    out.mkdir()
    rows = _asp.plan_items(pairs, str(out), {}, load={"unit": None, "up": None, "fixed": []})
    assert [r[0] is None for r in rows] == [True, False, True]
    error = rows[1][0]
    assert error is not None and str(broken) in error and "\n" not in error
    assert sorted(p.name for p in out.iterdir()) == ["a.json", "c.json"]
    for (_, status, found, parts, steps, tests, seconds), file in zip([rows[0], rows[2]], ["a.json", "c.json"]):
        plan = json.loads((out / file).read_text())
        assert (status, found, parts, steps, tests) == (
            "found", True, len(plan["parts"]), len(plan["assembly_sequence"]), plan["stats"]["removal_tests"])
        assert seconds > 0
    # wrong settings: the error for every model of the chunk, nothing written
    bad = _asp.plan_items(pairs[:2], str(tmp_path / "none"), {"tolerance": -1.0})
    assert [r[0] is not None and "tolerance" in r[0] for r in bad] == [True, True]
    assert not (tmp_path / "none").exists()


def test_chunks_grow_to_the_measured_cost_and_spread_the_tail():
    sizer = ChunkSizer(1000, 2)
    assert sizer.size(1000) == chunk_size(1000, 2) == 31  # nothing measured yet
    sizer.learn(0.031, 31)  # 1 ms per item: 100 items take the target 0.1 s
    assert sizer.size(900) == 100
    assert sizer.size(40) == 10  # the last 40 over twice 2 slots
    assert sizer.size(1) == 1
    slow = ChunkSizer(1000, 2)
    slow.learn(4.0, 2)  # 2 s per item: one at a time
    assert slow.size(900) == 1
    fast = ChunkSizer(100_000, 2)
    fast.learn(0.0001, 64)
    assert fast.size(90_000) == ChunkSizer.MOST


class Ref:
    """A finished task's reference (hashable by identity, as Ray's)."""

    def __init__(self, value) -> None:
        self.value = value


class FakeRay:
    """Ray's calls that a local batch makes, run in this process; ``shutdown`` takes 0.3 s."""

    def __init__(self) -> None:
        self.up = False
        self.sizes: list[int] = []

    def is_initialized(self) -> bool:
        return self.up

    def init(self, **kw) -> None:
        self.up = True

    def cluster_resources(self) -> dict:
        return {"CPU": 2}

    def put(self, value):
        return value

    def remote(self, **kw):
        fake = self

        class Task:
            def __init__(self, fn) -> None:
                self.fn = fn

            def remote(self, *args):
                fake.sizes.append(len(args[2]))
                return Ref(self.fn(*args))

        return Task

    def wait(self, refs, num_returns=1):
        return refs[:num_returns], refs[num_returns:]

    def get(self, ref):
        return ref.value

    def shutdown(self) -> None:
        time.sleep(0.3)
        self.up = False


def test_stopping_ray_is_reported_apart_from_the_items(tmp_path, monkeypatch):
    models = soma_models(tmp_path, 40)
    fake = FakeRay()
    monkeypatch.setattr(runner, "_ray_module", lambda: fake)
    outcome = run(PlanJob([models]), tmp_path / "plans", ray="local", workers=2, quiet=True)
    assert outcome.ok and outcome.ran == 40 and not fake.up
    assert outcome.shutdown_seconds >= 0.3
    assert outcome.seconds >= outcome.startup_seconds + outcome.shutdown_seconds
    assert "s stopping it)" in outcome.summary.splitlines()[-1]
    # the first tasks take chunk_size's items, the next ones the measured cost's, the tail spreads
    assert fake.sizes[0] == chunk_size(40, 2) == 1 and sum(fake.sizes) == 40 and max(fake.sizes) > 1
