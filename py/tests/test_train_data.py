"""Tests of the asp-removability reader (``asp.data``, NumPy only) and the synthetic data sets
the training tests share (:func:`write_dataset`, :func:`write_stacks_dataset`)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from asp.data import DataError, RemovabilityDataset, induced_subgraph  # noqa: E402


def write_dataset(root: Path, assemblies: list[dict], node_dim: int, edge_dim: int, features: str = "test/1") -> Path:
    """Write an asp-removability folder. Each assembly dict: name, parts (list of (name, fixed)),
    edges [[s, t]...], nodes [N, node_dim], edge_attr [E, edge_dim], states (list of dicts)."""
    root.mkdir(parents=True, exist_ok=True)
    entries = []
    for a in assemblies:
        folder = root / a["name"]
        folder.mkdir()
        graph = {
            "name": a["name"],
            "source": "synthetic",
            "parts": [{"name": n, "fixed": f} for n, f in a["parts"]],
            "edges": a["edges"],
        }
        (folder / "graph.json").write_text(json.dumps(graph))
        np.save(folder / "nodes.npy", np.asarray(a["nodes"], dtype="<f4").reshape(len(a["parts"]), node_dim))
        np.save(folder / "edge_attr.npy", np.asarray(a["edge_attr"], dtype="<f4").reshape(len(a["edges"]), edge_dim))
        with open(folder / "states.jsonl", "w") as f:
            for s in a["states"]:
                f.write(json.dumps(s) + "\n")
        entries.append(
            {"name": a["name"], "dir": a["name"], "parts": len(a["parts"]), "edges": len(a["edges"]), "states": len(a["states"])}
        )
    index = {
        "format": "asp-removability",
        "version": 1,
        "features": features,
        "node_dim": node_dim,
        "edge_dim": edge_dim,
        "seed": 0,
        "runs": 1,
        "assemblies": entries,
    }
    (root / "index.json").write_text(json.dumps(index))
    return root


def stacks_assembly(
    name: str, rng: np.random.Generator, columns: int, max_height: int, runs: int, node_dim: int = 10, edge_dim: int = 6
) -> dict:
    """A learnable synthetic assembly: columns of stacked blocks on a fixed base (part 0).

    A block is removable exactly when no present block sits on it, which a GNN sees in the
    ``above`` edge attribute (second to last) of its incoming edges. Descriptors are noise.
    """
    parts = [("base", True)]
    cell = {}
    for c in range(columns):
        for k in range(int(rng.integers(1, max_height + 1))):
            cell[(c, k)] = len(parts)
            parts.append((f"c{c}k{k}", False))
    edges, attrs = [], []

    def link(s: int, t: int, above: float) -> None:
        for a, b, up in ((s, t, above), (t, s, -above)):
            edges.append([a, b])
            attrs.append(np.concatenate([rng.gamma(2.0, 0.5, edge_dim - 2), [up + rng.normal(0, 0.05), rng.uniform(-1, 1)]]))

    for (c, k), p in cell.items():
        link(p, cell[(c, k - 1)] if k > 0 else 0, 1.0)  # p sits on the block below (or the base)
        if (c + 1, k) in cell:
            link(p, cell[(c + 1, k)], 0.0)  # side contact
    nodes = np.concatenate([rng.gamma(2.0, 0.5, (len(parts), node_dim - 2)), np.zeros((len(parts), 2))], axis=1)
    nodes[0, -2] = 1.0  # fixed
    for (_, k), p in cell.items():
        nodes[p, -1] = 1.0 if k == 0 else 0.0  # on_base
    on_top = {p: cell.get((c, k + 1)) for (c, k), p in cell.items()}
    states = []
    for run in range(runs):
        present = set(range(len(parts)))
        step = 0
        while len(present) > 1:
            removable = sorted(p for p in present if p != 0 and on_top[p] not in present)
            states.append({"run": run, "step": step, "present": sorted(present), "removable": removable})
            present.remove(int(rng.choice(removable)))
            step += 1
    edge_attr = np.asarray(attrs).reshape(-1, edge_dim)
    return {"name": name, "parts": parts, "edges": edges, "nodes": nodes, "edge_attr": edge_attr, "states": states}


def write_stacks_dataset(root: Path, names: list[str], seed: int = 0, runs: int = 4) -> Path:
    """A data set of :func:`stacks_assembly` assemblies (node_dim 10, edge_dim 6)."""
    rng = np.random.default_rng(seed)
    assemblies = [stacks_assembly(n, rng, columns=int(rng.integers(3, 6)), max_height=5, runs=runs) for n in names]
    return write_dataset(root, assemblies, 10, 6, features="stacks/1")


def _small(root: Path) -> Path:
    # 4 parts, part 0 fixed; node k's attributes are [k, 10k], edge k's are [k, -k, 0.5]
    edges = [[0, 1], [1, 0], [1, 2], [2, 1], [2, 3], [3, 2], [0, 3]]
    a = {
        "name": "small",
        "parts": [("base", True), ("a", False), ("b", False), ("c", False)],
        "edges": edges,
        "nodes": [[k, 10 * k] for k in range(4)],
        "edge_attr": [[k, -k, 0.5] for k in range(len(edges))],
        "states": [
            {"run": 0, "step": 0, "present": [0, 1, 2, 3], "removable": [1]},
            {"run": 0, "step": 1, "present": [0, 2, 3], "removable": [3]},
            {"run": 0, "step": 2, "present": [1, 2, 3], "removable": [3, 1]},
        ],
    }
    return write_dataset(root, [a], 2, 3)


def test_induced_subgraph_by_hand(tmp_path):
    ds = RemovabilityDataset.open(_small(tmp_path / "ds"))
    assert (ds.features, ds.node_dim, ds.edge_dim) == ("test/1", 2, 3)
    states = list(ds.states())
    assert len(states) == 3
    # present [0, 2, 3]: edges 4 [2,3], 5 [3,2], 6 [0,3]; positions 0->0, 2->1, 3->2
    g = states[1].graph()
    np.testing.assert_array_equal(g.edge_index, [[1, 2, 0], [2, 1, 2]])
    assert g.edge_index.dtype == np.int64
    np.testing.assert_array_equal(g.x, [[0, 0], [2, 20], [3, 30]])
    np.testing.assert_array_equal(g.edge_attr, [[4, -4, 0.5], [5, -5, 0.5], [6, -6, 0.5]])
    assert g.x.dtype == np.float32 and g.edge_attr.dtype == np.float32
    np.testing.assert_array_equal(g.labels, [0, 0, 1])
    assert g.labels.dtype == np.float32
    np.testing.assert_array_equal(g.mask, [False, True, True])
    # present [1, 2, 3]: edges 2 [1,2], 3 [2,1], 4 [2,3], 5 [3,2]; every node labelled
    g = states[2].graph()
    np.testing.assert_array_equal(g.edge_index, [[0, 1, 1, 2], [1, 0, 2, 1]])
    np.testing.assert_array_equal(g.edge_attr[:, 0], [2, 3, 4, 5])
    np.testing.assert_array_equal(g.labels, [1, 0, 1])
    np.testing.assert_array_equal(g.mask, [True, True, True])
    assert (states[2].run, states[2].step) == (0, 2)


def test_induced_subgraph_without_edges():
    edge_ids, edge_index = induced_subgraph(np.array([[0, 1], [1, 0]]), 3, np.array([2]))
    assert edge_ids.shape == (0,) and edge_index.shape == (2, 0) and edge_index.dtype == np.int64
    edge_ids, edge_index = induced_subgraph(np.zeros((0, 2), dtype=np.int64), 3, np.array([0, 1]))
    assert edge_index.shape == (2, 0)


def test_arrays_are_memory_mapped(tmp_path):
    ds = RemovabilityDataset.open(_small(tmp_path / "ds"))
    assert isinstance(ds.assemblies[0].nodes, np.memmap)
    assert isinstance(ds.assemblies[0].edge_attr, np.memmap)


def _edit_json(path: Path, **changes) -> None:
    doc = json.loads(path.read_text())
    doc.update(changes)
    path.write_text(json.dumps(doc))


@pytest.mark.parametrize(
    "change, message",
    [
        ({"format": "other"}, 'index.json: format is "other", expected "asp-removability"'),
        ({"version": 2}, "index.json: asp-removability version 2 is not supported"),
        ({"node_dim": "74"}, "index.json: 'node_dim' must be an integer"),
        ({"edge_dim": 4}, "edge_attr.npy: edge attributes must have shape [7, 4], found [7, 3]"),
        ({"node_dim": 3}, "nodes.npy: node attributes must have shape [4, 3], found [4, 2]"),
    ],
)
def test_index_errors_name_the_file(tmp_path, change, message):
    root = _small(tmp_path / "ds")
    _edit_json(root / "index.json", **change)
    with pytest.raises(DataError) as err:
        RemovabilityDataset.open(root)
    assert message in str(err.value)
    assert "\n" not in str(err.value)


def test_graph_errors_name_the_file(tmp_path):
    root = _small(tmp_path / "ds")
    _edit_json(root / "small" / "graph.json", edges=[[0, 1], [1, 0], [1, 2], [2, 1], [2, 3], [3, 2], [0, 9]])
    with pytest.raises(DataError, match=r"small/graph.json: edges\[6\] = \[0, 9\] names a part outside 0..3"):
        RemovabilityDataset.open(root)


def test_wrong_dtype_is_refused(tmp_path):
    root = _small(tmp_path / "ds")
    np.save(root / "small" / "nodes.npy", np.zeros((4, 2), dtype=np.float64))
    with pytest.raises(DataError, match=r"nodes.npy: node attributes must be float32"):
        RemovabilityDataset.open(root)


def test_missing_files(tmp_path):
    with pytest.raises(DataError, match=r"index.json: file not found"):
        RemovabilityDataset.open(tmp_path / "nothing")
    root = _small(tmp_path / "ds")
    (root / "small" / "edge_attr.npy").unlink()
    with pytest.raises(DataError, match=r"edge_attr.npy: file not found"):
        RemovabilityDataset.open(root)


@pytest.mark.parametrize(
    "line, message",
    [
        ('{"run": 0, "step": 1, "present": [0, 2, 3], "removable": [1]}', "states.jsonl:2: removable part 1 is not present"),
        ('{"run": 0, "step": 1, "present": [0, 2, 3], "removable": [0]}', "states.jsonl:2: removable part 0 is fixed"),
        ('{"run": 0, "step": 1, "present": [0, 3, 2], "removable": []}', "states.jsonl:2: 'present' must be strictly ascending"),
        ('{"run": 0, "step": 1, "present": [0, 7], "removable": []}', "states.jsonl:2: 'present' names part 7, the model has 4 parts"),
        ('{"run": 0, "step": 1, "present": [0, 2]', "states.jsonl:2: invalid JSON"),
        ('{"run": -1, "step": 1, "present": [0, 2], "removable": []}', "states.jsonl:2: 'run' must be a non-negative integer"),
    ],
)
def test_state_errors_name_the_line(tmp_path, line, message):
    root = _small(tmp_path / "ds")
    path = root / "small" / "states.jsonl"
    lines = path.read_text().splitlines()
    lines[1] = line
    path.write_text("\n".join(lines) + "\n")
    ds = RemovabilityDataset.open(root)
    it = ds.states()
    next(it)  # line 1 is fine: states stream lazily
    with pytest.raises(DataError) as err:
        next(it)
    assert message in str(err.value)


def test_state_count_must_match_index(tmp_path):
    root = _small(tmp_path / "ds")
    path = root / "small" / "states.jsonl"
    path.write_text("\n".join(path.read_text().splitlines()[:2]) + "\n")
    with pytest.raises(DataError, match=r"states.jsonl: has 2 states, index.json announces 3"):
        list(RemovabilityDataset.open(root).states())


def test_stacks_dataset_labels_follow_the_rule(tmp_path):
    root = write_stacks_dataset(tmp_path / "stacks", ["a", "b"], runs=2)
    ds = RemovabilityDataset.open(root)
    assert [a.name for a in ds.assemblies] == ["a", "b"]
    for state in ds.states():
        g = state.graph()
        above = g.edge_attr[:, -2] > 0.5
        covered = np.zeros(len(g.x), dtype=bool)
        covered[g.edge_index[1][above]] = True
        expected = (~covered) & g.mask
        np.testing.assert_array_equal(g.labels.astype(bool), expected)


def test_checker_and_failure_reasons_are_read(tmp_path):
    root = _small(tmp_path / "ds")
    assert RemovabilityDataset.open(root).checker == "default"  # written without the key
    index = json.loads((root / "index.json").read_text())
    index["checker"] = "physics"
    (root / "index.json").write_text(json.dumps(index))
    lines = (root / "small" / "states.jsonl").read_text().splitlines()
    first = json.loads(lines[0])
    first.update(collision=[2], gravity=[3])
    (root / "small" / "states.jsonl").write_text("\n".join([json.dumps(first), *lines[1:]]) + "\n")
    ds = RemovabilityDataset.open(root)
    assert ds.checker == "physics"
    states = list(ds.states())
    assert list(states[0].collision) == [2] and list(states[0].gravity) == [3]
    assert len(states[1].collision) == 0 and len(states[1].gravity) == 0
    # a robot data set: the arm's reasons are read, and checked like the others
    index["checker"] = "robot"
    (root / "index.json").write_text(json.dumps(index))
    first.update(collision=[], gravity=[3], arm_no_grasp=[2], arm_blocked=[], arm_no_path=[])
    (root / "small" / "states.jsonl").write_text("\n".join([json.dumps(first), *lines[1:]]) + "\n")
    ds = RemovabilityDataset.open(root)
    assert ds.checker == "robot"
    state = next(iter(ds.states()))
    assert list(state.arm_no_grasp) == [2] and len(state.arm_blocked) == 0 and list(state.gravity) == [3]
    first.update(arm_no_path=[first["removable"][0]])
    (root / "small" / "states.jsonl").write_text("\n".join([json.dumps(first), *lines[1:]]) + "\n")
    with pytest.raises(DataError, match="'arm_no_path' must name present parts that are not removable"):
        list(RemovabilityDataset.open(root).states())
    index["checker"] = "magic"
    (root / "index.json").write_text(json.dumps(index))
    with pytest.raises(DataError, match="checker 'magic'"):
        RemovabilityDataset.open(root)
