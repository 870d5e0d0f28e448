"""asp.batch: the same results as the serial commands, on a local Ray with 2 CPUs and in a serial
loop; resumable after a kill; clear errors."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from conftest import LACK, ROOT, need, without_seconds

ray = need("ray", "asp.batch on Ray needs ray (pip install 'ray>=2.9')")

from asp.batch import BatchError, BenchJob, CollectJob, GenJob, PlanJob, run  # noqa: E402
from asp.batch.runner import JOURNAL_DIR, _init_local, chunk_size  # noqa: E402


@pytest.fixture(scope="module")
def local_ray():
    """One local Ray with 2 CPUs for the module (asp.batch.run uses a Ray that is already up)."""
    _init_local(ray, 2)
    yield
    ray.shutdown()


def files(folder: Path) -> dict:
    """Every file of a folder (not the journal) by relative path: its bytes."""
    return {
        str(p.relative_to(folder)): p.read_bytes()
        for p in sorted(folder.rglob("*"))
        if p.is_file() and JOURNAL_DIR not in p.parts
    }


def soma_models(tmp_path: Path, count: int = 4, size: int = 3) -> Path:
    out = tmp_path / f"soma{size}"
    run(GenJob.soma(size=size, count=count, seed=7), out, ray="none", quiet=True)
    return out


def test_gen_on_ray_writes_the_files_of_asp_gen(tmp_path, asp_cli, local_ray):
    for args, job in [
        (["soma", "--size", "3", "--count", "5", "--seed", "11"], GenJob.soma(size=3, count=5, seed=11)),
        # 70 items on 2 CPUs: tasks of 2 items each (chunk_size)
        (["soma", "--size", "2", "--count", "70", "--seed", "4"], GenJob.soma(size=2, count=70, seed=4)),
        (["profiles", "--preset", "double-layer", "--count", "2", "--seed", "3"],
         GenJob.profiles("double-layer", count=2, seed=3)),
        (["stress", "--kind", "bolted", "--count", "3", "--seed", "5"], GenJob.stress("bolted", count=3, seed=5)),
    ]:
        cli, batch = tmp_path / f"cli-{args[0]}-{args[2]}", tmp_path / f"batch-{args[0]}-{args[2]}"
        code, _, err = asp_cli("gen", *args, "--out", str(cli), "--quiet")
        assert code == 0, err
        outcome = run(job, batch, quiet=True)
        assert outcome.ok and outcome.ran == job.spec["count"]
        assert files(batch) == files(cli), f"{args[0]}: the batch's files differ from asp gen's"


def test_small_items_go_in_chunks():
    assert [chunk_size(n, 2) for n in (1, 31, 64, 70, 1000, 100_000)] == [1, 1, 2, 2, 31, 64]


def test_plans_on_ray_equal_the_serial_loop_and_the_cli(tmp_path, asp_cli, local_ray):
    models = [str(soma_models(tmp_path)), str(ROOT / LACK)]
    job = PlanJob(models, {"order": "shuffled", "seed": 3}, )
    serial, parallel = tmp_path / "serial", tmp_path / "ray"
    a = run(job, serial, ray="none", quiet=True)
    b = run(job, parallel, quiet=True)
    assert a.ok and b.ok and a.ran == b.ran == 5
    plans = sorted(p.name for p in serial.glob("*.json") if p.name != "summary.json")
    assert plans == sorted(p.name for p in parallel.glob("*.json") if p.name != "summary.json")
    for name in plans:
        assert without_seconds((serial / name).read_text()) == without_seconds((parallel / name).read_text()), name
    # and each is the plan JSON of `asp plan --json` for the same settings
    code, out, err = asp_cli("plan", str(ROOT / LACK), "--order", "shuffled", "--seed", "3", "--json", "--quiet")
    assert code == 0, err
    assert without_seconds((parallel / "table_lack_0825.json").read_text()) == without_seconds(out)
    summary = json.loads((parallel / "summary.json").read_text())
    assert [p["name"] for p in summary["plans"]] == [i.key for i in job.items()]
    assert all(p["status"] == "found" and p["steps"] > 0 for p in summary["plans"])


def test_collect_on_ray_writes_the_data_set_of_asp_collect(tmp_path, asp_cli, local_ray):
    models = soma_models(tmp_path, count=3)
    cli, batch = tmp_path / "cli", tmp_path / "batch"
    code, _, err = asp_cli("collect", "removability", str(models), "--runs", "3", "--seed", "5",
                           "--max-tests", "2000", "--out", str(cli))
    assert code == 0, err
    outcome = run(CollectJob([models], runs=3, seed=5, max_tests=2000), batch, quiet=True)
    assert outcome.ok and outcome.ran == 3
    assert files(batch) == files(cli)
    index = json.loads((batch / "index.json").read_text())
    assert len(index["assemblies"]) == 3 and all(a["states"] > 0 for a in index["assemblies"])


def test_a_collect_batch_names_the_checker_of_its_settings(tmp_path, asp_cli):
    # the index of a physics batch says physics (it said default whatever the settings were)
    models = soma_models(tmp_path, count=1)
    cli, batch = tmp_path / "cli", tmp_path / "batch"
    code, _, err = asp_cli("collect", "removability", str(models), "--runs", "1", "--max-tests", "300",
                           "--stability", "physics", "--out", str(cli))
    assert code == 0, err
    outcome = run(CollectJob([models], runs=1, max_tests=300, settings={"stability": "physics"}), batch,
                  ray="none", quiet=True)
    assert outcome.ok
    assert json.loads((batch / "index.json").read_text())["checker"] == "physics"
    assert files(batch) == files(cli)


def test_bench_on_ray_counts_the_tests_of_asp_bench(tmp_path, asp_cli, local_ray):
    models = soma_models(tmp_path, count=2)
    rows_cli = tmp_path / "rows.json"
    code, _, err = asp_cli("bench", "feasible", str(models), "--orderings", "3", "--methods", "vanilla,bk",
                           "--json", str(rows_cli))
    assert code == 0, err
    out = tmp_path / "bench"
    outcome = run(BenchJob([models], orderings=3, methods="vanilla,bk"), out, quiet=True)
    assert outcome.ok
    counts = lambda rows: [(r["model"], r["method"], r["found"], r["removal_tests"]) for r in rows]  # noqa: E731
    assert counts(json.loads((out / "bench.json").read_text())) == counts(json.loads(rows_cli.read_text()))
    assert "vanilla" in (out / "bench.txt").read_text()


def test_a_second_run_skips_what_is_done_and_other_settings_are_refused(tmp_path):
    models = soma_models(tmp_path, count=3)
    out = tmp_path / "plans"
    job = PlanJob([models], {"order": "shuffled"})
    assert run(job, out, ray="none", quiet=True).ran == 3
    (out / "soma3_001.json").unlink()  # a lost output is made again
    again = run(job, out, ray="none", quiet=True)
    assert (again.ran, again.skipped) == (1, 2)
    with pytest.raises(BatchError, match=r"other settings \(settings\.seed"):
        run(PlanJob([models], {"order": "shuffled", "seed": 1}), out, ray="none", quiet=True)
    assert run(PlanJob([models], {"order": "shuffled", "seed": 1}), out, ray="none", quiet=True, fresh=True).ran == 3


def test_a_bad_model_fails_alone(tmp_path):
    models = soma_models(tmp_path, count=2)
    broken = tmp_path / "broken.glb"
    broken.write_bytes(b"not a glb")
    out = tmp_path / "plans"
    outcome = run(PlanJob([models, broken]), out, ray="none", quiet=True)
    assert outcome.ran == 2 and list(outcome.failed) == ["broken"]
    assert str(broken) in outcome.failed["broken"]
    summary = json.loads((out / "summary.json").read_text())
    assert [("error" in p, p.get("status")) for p in summary["plans"]] == [(False, "found")] * 2 + [(True, None)]
    assert "1 of 3 items failed" in outcome.summary
    data = tmp_path / "data"
    collected = run(CollectJob([models, broken], runs=1, max_tests=200), data, ray="none", quiet=True)
    assert list(collected.failed) == ["broken"] and collected.ran == 2
    assert not (data / "index.json").exists(), "no data set index while a model is missing"
    broken.unlink()
    env = dict(os.environ)
    cli = subprocess.run([sys.executable, "-m", "asp.batch", "plan", str(tmp_path / "nothing"), "--out", str(out),
                          "--ray", "none"], capture_output=True, text=True, env=env)
    assert cli.returncode == 2 and cli.stderr.startswith("error: ") and len(cli.stderr.splitlines()) == 1, cli.stderr
    cli = subprocess.run([sys.executable, "-m", "asp.batch", "plan", str(models), "--out", str(out), "--ray", "none",
                          "--set", "no_such_setting=1"], capture_output=True, text=True, env=env)
    assert cli.returncode == 2 and "no_such_setting" in cli.stderr, cli.stderr


def test_killed_half_way_the_same_command_finishes_the_rest(tmp_path, asp_cli):
    """A local Ray with 2 CPUs started by the command itself, killed (SIGKILL, the whole process
    group) once some items are journaled; the same command again redoes none of them."""
    out = tmp_path / "gen"
    count = 60
    command = [sys.executable, "-m", "asp.batch", "gen", "profiles", "--count", str(count), "--seed", "2",
               "--out", str(out), "--workers", "2"]
    journal = out / JOURNAL_DIR / "done.jsonl"
    first = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    deadline = time.time() + 120
    done_before = 0
    while time.time() < deadline and first.poll() is None:
        if journal.is_file():
            done_before = len(journal.read_text().splitlines())
            if done_before >= 5:
                break
        time.sleep(0.05)
    assert first.poll() is None, f"the batch ended before it could be killed: {first.communicate()}"
    os.killpg(first.pid, signal.SIGKILL)
    first.wait()
    lines = journal.read_text().splitlines()
    finished = [json.loads(line)["result"]["entry"]["file"] for line in lines if line.endswith("}")]
    assert 5 <= len(finished) < count, "killed half way"
    stamps = {f: (out / f).stat().st_mtime_ns for f in finished}
    second = subprocess.run(command, capture_output=True, text=True, timeout=300)
    assert second.returncode == 0, second.stderr
    assert f"{len(finished)} of {count} items done before" in second.stderr
    assert {f: (out / f).stat().st_mtime_ns for f in finished} == stamps, "finished items were redone"
    cli = tmp_path / "cli"
    code, _, err = asp_cli("gen", "profiles", "--count", str(count), "--seed", "2", "--out", str(cli), "--quiet")
    assert code == 0, err
    assert files(out) == files(cli), "the resumed batch's files differ from asp gen's"


def test_a_batch_joins_a_cluster_by_address(tmp_path, asp_cli):
    """`ray start --head` makes a one-node cluster (2 CPUs) in a process of its own; the batch joins
    it by the address ray start prints, as it would join a cluster on other machines."""
    import re
    import shutil
    import socket
    import tempfile

    ray_cli = shutil.which("ray", path=str(Path(sys.executable).parent)) or shutil.which("ray")
    assert ray_cli, "the ray command comes with the ray package"
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    # Ray's socket paths must stay under 108 bytes: a short folder, not pytest's tmp_path
    temp = tempfile.mkdtemp(prefix="asp-ray-", dir="/tmp")
    # a cluster's nodes and drivers share one token (Ray >= 2.59 authenticates by default)
    env = dict(os.environ, RAY_AUTH_MODE="token", RAY_AUTH_TOKEN=os.urandom(16).hex())
    head = subprocess.Popen(
        [ray_cli, "start", "--head", "--block", "--num-cpus", "2", "--port", str(port), "--include-dashboard",
         "false", "--disable-usage-stats", "--temp-dir", temp],
        stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True, start_new_session=True, env=env,
    )
    try:
        address, seen = None, []
        deadline = time.time() + 90
        while address is None and time.time() < deadline:
            line = head.stdout.readline()
            if not line:
                break
            seen.append(line)
            m = re.search(r"ray start --address='([^']+)'", line)
            address = m.group(1) if m else None
        assert address, "ray start printed no address:\n" + "".join(seen[-20:])
        out = tmp_path / "gen"
        batch = subprocess.run(
            [sys.executable, "-m", "asp.batch", "gen", "soma", "--size", "3", "--count", "6", "--seed", "5",
             "--out", str(out), "--ray", address], capture_output=True, text=True, timeout=300, env=env,
        )
        assert batch.returncode == 0, batch.stderr
        cli = tmp_path / "cli"
        code, _, err = asp_cli("gen", "soma", "--size", "3", "--count", "6", "--seed", "5", "--out", str(cli), "--quiet")
        assert code == 0, err
        assert files(out) == files(cli)
    finally:
        os.killpg(head.pid, signal.SIGTERM)  # --block: ray start stops the processes it started
        try:
            head.wait(timeout=60)
        except subprocess.TimeoutExpired:
            os.killpg(head.pid, signal.SIGKILL)
        shutil.rmtree(temp, ignore_errors=True)


def test_partial_plans_are_counted_apart(tmp_path, crossed_bars):
    # The crossed bars' plan holds a locked core (a partial plan); the summary says so
    # instead of counting it as planned
    from asp.batch.jobs import LoadSettings

    out = tmp_path / "plans"
    outcome = run(PlanJob([Path(crossed_bars)], load=LoadSettings(unit="mm", up="z")), out, ray="none", quiet=True)
    assert outcome.ran == 1 and not outcome.failed
    summary = json.loads((out / "summary.json").read_text())
    assert [(p["status"], p["found"]) for p in summary["plans"]] == [("partial", False)]
    assert outcome.summary.startswith("0 of 1 models planned, 1 partial (locked cores); "), outcome.summary
