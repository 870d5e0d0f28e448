"""Tests of training (``asp.train.trainer``) and the command line ``python -m asp.train``."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from conftest import need

sys.path.insert(0, str(Path(__file__).resolve().parent))  # the shared synthetic data set writer

torch = need("torch", "asp.train needs PyTorch (pip install torch)")
need("onnx", "the ONNX export needs the onnx package")

from asp.train.__main__ import main  # noqa: E402
from asp.train.export import run_onnx  # noqa: E402
from asp.train.gnn import RemovabilityGNN  # noqa: E402
from asp.train.trainer import TrainConfig, evaluate, load_assemblies, make_batch, train  # noqa: E402
from test_train_data import write_stacks_dataset  # noqa: E402


@pytest.fixture(scope="module")
def stacks(tmp_path_factory) -> Path:
    return write_stacks_dataset(tmp_path_factory.mktemp("stacks") / "ds", ["a", "b", "c", "d"], seed=0, runs=4)


def test_batches_are_disjoint_unions(stacks):
    assemblies, *_ = load_assemblies([str(stacks)])
    a = assemblies[0]
    s0, s1 = a.states[0], a.states[3]
    batch = make_batch([(a, s0), (a, s1)])
    n0 = len(s0.present)
    assert batch.x.shape[0] == n0 + len(s1.present)
    np.testing.assert_array_equal(batch.edge_index[:, : s0.edge_index.shape[1]].numpy(), s0.edge_index)
    np.testing.assert_array_equal(batch.edge_index[:, s0.edge_index.shape[1] :].numpy(), s1.edge_index + n0)
    np.testing.assert_array_equal(batch.x[n0:].numpy(), np.asarray(a.assembly.nodes)[s1.present])


def test_training_learns_the_synthetic_rule(stacks):
    assemblies, features, node_dim, edge_dim = load_assemblies([str(stacks)])
    train_set, test = assemblies[:3], assemblies[3]
    torch.manual_seed(123)
    untrained = evaluate(RemovabilityGNN(node_dim, edge_dim), test)
    model, summary = train(train_set, node_dim, edge_dim, TrainConfig(epochs=25, seed=0, seconds=20))
    result = evaluate(model, test)
    chance = max(result["positive_fraction"], 1 - result["positive_fraction"])
    assert result["labels"] > 200
    # the held-out assembly was never seen; the majority class gets `chance`
    assert result["accuracy"] >= 0.95, (result, summary)
    assert result["accuracy"] > chance + 0.2, (result, chance)
    assert result["accuracy"] > untrained["accuracy"] + 0.2
    print(f"held-out accuracy {result['accuracy']:.4f}, majority class {chance:.4f}, untrained {untrained['accuracy']:.4f}")


def test_training_is_deterministic(stacks):
    assemblies, _, node_dim, edge_dim = load_assemblies([str(stacks)])
    config = TrainConfig(epochs=2, seed=5)
    m1, _ = train(assemblies[:2], node_dim, edge_dim, config)
    m2, _ = train(assemblies[:2], node_dim, edge_dim, config)
    m3, _ = train(assemblies[:2], node_dim, edge_dim, TrainConfig(epochs=2, seed=6))
    for (k, p1), p2 in zip(m1.state_dict().items(), m2.state_dict().values()):
        assert torch.equal(p1, p2), k
    assert not torch.equal(m1.head.weight, m3.head.weight)


def test_seconds_caps_training(stacks):
    assemblies, _, node_dim, edge_dim = load_assemblies([str(stacks)])
    _, summary = train(assemblies, node_dim, edge_dim, TrainConfig(epochs=1000, seconds=0.5))
    assert summary["time_capped"] and summary["epochs"] < 1000
    assert summary["seconds"] < 5


def test_early_stopping_keeps_the_best_epochs_model(stacks):
    assemblies, _, node_dim, edge_dim = load_assemblies([str(stacks)])
    config = TrainConfig(epochs=40, seed=3, patience=2, lr=3e-2)
    model, summary = train(assemblies[:2], node_dim, edge_dim, config, validation=assemblies[2:])
    history, best = summary["validation_accuracy"], summary["best_epoch"]
    assert len(history) == summary["epochs"] and best == history.index(max(history)) + 1
    # it stops `patience` epochs after the best one (or at the last epoch)
    assert summary["epochs"] == min(config.epochs, best + config.patience), summary
    # the model returned is the best epoch's, not the last one's: the same weights as a run of
    # exactly that many epochs (validation never touches the weights or the batch order)
    again, _ = train(assemblies[:2], node_dim, edge_dim, TrainConfig(epochs=best, seed=3, lr=3e-2))
    for (k, p1), p2 in zip(model.state_dict().items(), again.state_dict().values()):
        assert torch.equal(p1, p2), k
    pooled = sum(evaluate(model, a)["accuracy"] * evaluate(model, a)["labels"] for a in assemblies[2:])
    assert pooled / sum(evaluate(model, a)["labels"] for a in assemblies[2:]) == pytest.approx(max(history))


def test_cli_validation_data_sets(stacks, tmp_path, capsys):
    val = write_stacks_dataset(tmp_path / "val", ["v1", "v2"], seed=9, runs=2)
    out = tmp_path / "m.onnx"
    argv = ["removability", str(stacks), "--out", str(out), "--epochs", "6", "--validation", str(val), "--patience", "2"]
    assert main(argv) == 0
    doc = json.loads(Path(str(out) + ".json").read_text())
    assert doc["validation_assemblies"] == ["v1", "v2"] and doc["patience"] == 2
    assert 1 <= doc["best_epoch"] <= doc["epochs"] and len(doc["validation_accuracy"]) == doc["epochs"]
    assert "validation accuracy" in capsys.readouterr().err
    assert main(argv[:-1] + ["0"]) == 2
    assert "--patience must be at least 1, got 0" in capsys.readouterr().err
    other = _with_checker(val, tmp_path / "phys", "physics")
    assert main(["removability", str(stacks), "--out", str(out), "--validation", str(other)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--validation" in err and "physics checker" in err, err


def test_cli_holdout_writes_model_and_summary(stacks, tmp_path, capsys):
    out = tmp_path / "m.onnx"
    code = main(["removability", str(stacks), "--out", str(out), "--epochs", "3", "--holdout", "c", "d", "--seed", "1"])
    assert code == 0
    doc = json.loads(Path(str(out) + ".json").read_text())
    assert doc["features"] == "stacks/1" and doc["node_dim"] == 10 and doc["edge_dim"] == 6
    assert doc["epochs"] == 3 and doc["seed"] == 1
    assert doc["train_assemblies"] == ["a", "b"]
    assert set(doc["holdout_accuracy"]) == {"c", "d"}
    assert doc["onnx_parity_max_abs_diff"] <= 1e-5
    printed = capsys.readouterr().out
    assert "c: accuracy" in printed and "median held-out accuracy" in printed
    import onnx

    meta = {p.key: p.value for p in onnx.load(str(out)).metadata_props}
    assert meta["asp.features"] == "stacks/1"


def test_cli_leave_one_out(stacks, tmp_path, capsys):
    out_dir = tmp_path / "loo"
    code = main(["removability", str(stacks), "--leave-one-out", str(out_dir), "--epochs", "1"])
    assert code == 0
    for name in "abcd":
        assert (out_dir / f"{name}.onnx").is_file()
        doc = json.loads((out_dir / f"{name}.onnx.json").read_text())
        assert name not in doc["train_assemblies"] and list(doc["holdout_accuracy"]) == [name]
    summary = json.loads((out_dir / "leave-one-out.json").read_text())
    assert set(summary["accuracy"]) == set("abcd")
    assert "median leave-one-out accuracy" in capsys.readouterr().out


def test_cli_errors_are_one_line(stacks, tmp_path, capsys):
    assert main(["removability", str(tmp_path / "missing"), "--out", str(tmp_path / "m.onnx")]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("error: ") and "index.json: file not found" in err and "\n" not in err
    assert main(["removability", str(stacks), "--out", str(tmp_path / "m.onnx"), "--holdout", "zz"]) == 2
    assert "--holdout names no assembly 'zz'" in capsys.readouterr().err
    assert main(["removability", str(stacks)]) == 2
    assert "give --out" in capsys.readouterr().err


def test_module_runs_as_a_program(stacks, tmp_path):
    import asp.data

    out = tmp_path / "m.onnx"
    root = Path(asp.data.__file__).parent.parent  # the `asp` this test imported, not another one
    proc = subprocess.run(
        [sys.executable, "-m", "asp.train", "removability", str(stacks), "--out", str(out), "--epochs", "1"],
        cwd=tmp_path, env={"PYTHONPATH": str(root), "PATH": "/usr/bin:/bin"}, capture_output=True, text=True, timeout=300,
    )
    assert proc.returncode == 0, proc.stderr
    assert "epoch 1/1" in proc.stderr
    rng = np.random.default_rng(0)
    y = run_onnx(out, rng.random((4, 10), dtype=np.float32), np.array([[0, 1], [1, 0]]), rng.random((2, 6), dtype=np.float32))
    assert y.shape == (4,)


def _with_checker(src: Path, dst: Path, checker: str | None) -> Path:
    """A copy of the data set ``src`` whose ``index.json`` names ``checker`` (none: the key removed)."""
    import shutil

    shutil.copytree(src, dst)
    index = json.loads((dst / "index.json").read_text())
    index.pop("checker", None)
    if checker is not None:
        index["checker"] = checker
    (dst / "index.json").write_text(json.dumps(index))
    return dst


@pytest.mark.parametrize("checker", ["physics", None])
def test_the_model_records_the_checker_of_its_labels(stacks, tmp_path, checker):
    import onnx

    data = _with_checker(stacks, tmp_path / "ds", checker)
    out = tmp_path / "m.onnx"
    assert main(["removability", str(data), "--out", str(out), "--epochs", "1", "--holdout", "d"]) == 0
    meta = {p.key: p.value for p in onnx.load(str(out)).metadata_props}
    # a data set from before the index named its checker was labelled by the default checker
    expected = checker or "default"
    assert meta["asp.checker"] == expected
    assert json.loads(Path(str(out) + ".json").read_text())["checker"] == expected


def test_data_sets_of_two_checkers_do_not_train_one_model(stacks, tmp_path, capsys):
    a = _with_checker(stacks, tmp_path / "a", "physics")
    b = _with_checker(stacks, tmp_path / "b", None)
    # rename b's assemblies so only the checker differs
    index = json.loads((b / "index.json").read_text())
    for entry in index["assemblies"]:
        entry["name"] = "b_" + entry["name"]
    (b / "index.json").write_text(json.dumps(index))
    assert main(["removability", str(a), str(b), "--out", str(tmp_path / "m.onnx"), "--epochs", "1"]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "labelled by the default checker" in err and "physics checker" in err, err
