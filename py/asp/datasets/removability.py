"""Reader of the ``asp-removability`` data set (format version 1, docs/learning.md).

Also importable as :mod:`asp.data`.

Needs only NumPy. A data set is one folder::

    index.json          format, version, features, node_dim, edge_dim, assemblies
    <dir>/graph.json    parts (name, fixed) and directed contact edges [[s, t], ...]
    <dir>/nodes.npy     float32 [N, node_dim]
    <dir>/edge_attr.npy float32 [E, edge_dim]
    <dir>/states.jsonl  one visited state per line: run, step, present, removable
                        (and, when recorded, why the others failed: collision, gravity;
                        under the robot also arm_blocked, arm_no_grasp, arm_no_path)

``index.json``'s ``checker`` names the checker whose tests gave the labels (``default``,
``physics``, ``robot``); a data set without it was labelled by the default checker.

The arrays are memory-mapped and ``states.jsonl`` is read line by line, so a data set never has to
fit in memory. Every problem is reported as a :class:`~asp.datasets.DataError` whose message is
one line naming the file (and the line of ``states.jsonl``) and the cause.

Example::

    ds = RemovabilityDataset.open("data/removability")
    for state in ds.states():
        g = state.graph()          # x, edge_index, edge_attr, labels, mask
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from .jsonl import (
    DataError,
    _fail,
    _int_field,
    _optional_int,
    _read_json,
    assembly_entries,
    check_ascending,
    part_list,
    read_index,
    stream_jsonl,
)

__all__ = [
    "FORMAT",
    "VERSION",
    "DataError",
    "Assembly",
    "State",
    "StateGraph",
    "RemovabilityDataset",
    "induced_subgraph",
]

#: The ``format`` field of ``index.json``.
FORMAT = "asp-removability"
#: The only format version this reader knows.
VERSION = 1


def _load_array(path: Path, rows: int, cols: int, what: str) -> np.ndarray:
    try:
        array = np.load(path, mmap_mode="r", allow_pickle=False)
    except FileNotFoundError:
        raise _fail(path, "file not found") from None
    except (ValueError, OSError) as err:
        raise _fail(path, f"not a NumPy .npy array: {err}") from None
    if array.dtype != np.dtype("<f4"):
        raise _fail(path, f"{what} must be float32 (little endian), found {array.dtype}")
    if array.shape != (rows, cols):
        raise _fail(path, f"{what} must have shape [{rows}, {cols}], found {list(array.shape)}")
    if rows > 0 and not array.flags.c_contiguous:
        raise _fail(path, f"{what} must be in C order")
    return array


def induced_subgraph(
    edges: np.ndarray, num_parts: int, present: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The induced subgraph of the present parts, as the contract defines it.

    ``edges`` is the model's ``[E, 2]`` array of ``(s, t)`` part indices, ``present`` the ascending
    part indices of the state. Returns ``(edge_ids, edge_index)``: the rows of ``edges`` whose both
    ends are present, in file order (int64 ``[e]``), and those edges renumbered to positions in
    ``present`` (int64 ``[2, e]``, row 0 sources, row 1 targets).
    """
    position = np.full(num_parts, -1, dtype=np.int64)
    position[present] = np.arange(len(present), dtype=np.int64)
    if len(edges) == 0:
        return np.zeros(0, dtype=np.int64), np.zeros((2, 0), dtype=np.int64)
    ends = position[edges]  # [E, 2]
    keep = (ends[:, 0] >= 0) & (ends[:, 1] >= 0)
    edge_ids = np.flatnonzero(keep).astype(np.int64)
    edge_index = np.ascontiguousarray(ends[keep].T, dtype=np.int64)
    return edge_ids, edge_index


@dataclass(frozen=True)
class StateGraph:
    """The graph of one state, ready for a model (arrays as in the ONNX contract)."""

    x: np.ndarray
    """float32 ``[n, node_dim]``: node attributes of the present parts, in ``present`` order."""
    edge_index: np.ndarray
    """int64 ``[2, e]``: row 0 sources, row 1 targets, positions in ``x``."""
    edge_attr: np.ndarray
    """float32 ``[e, edge_dim]``: attributes of the edges, in ``graph.json`` order."""
    labels: np.ndarray
    """float32 ``[n]``: 1 for removable parts, 0 otherwise (fixed parts carry 0 and are masked)."""
    mask: np.ndarray
    """bool ``[n]``: True for labelled nodes (present, non-fixed parts)."""


@dataclass(frozen=True)
class Assembly:
    """One assembly of a data set: its model graph, memory-mapped arrays and states file."""

    name: str
    """The assembly's name (from ``index.json``)."""
    dir: Path
    """The assembly's folder."""
    part_names: list[str]
    """Part names, by part index."""
    fixed: np.ndarray
    """bool ``[N]``: base parts."""
    edges: np.ndarray
    """int64 ``[E, 2]``: the model's directed contact edges ``(s, t)``."""
    nodes: np.ndarray
    """float32 ``[N, node_dim]`` (memory-mapped)."""
    edge_attr: np.ndarray
    """float32 ``[E, edge_dim]`` (memory-mapped)."""
    states_path: Path
    """The ``states.jsonl`` file."""
    num_states: int
    """The number of states ``index.json`` announces."""

    @property
    def num_parts(self) -> int:
        """The number of parts N of the assembled model."""
        return len(self.part_names)

    def states(self) -> Iterator[State]:
        """Stream the states of ``states.jsonl``, validating each line."""
        return stream_jsonl(self.states_path, self.num_states, "state", self._parse_state)

    def _parse_state(self, obj: dict[str, Any], where: str) -> State:
        for key in ("run", "step"):
            value = obj.get(key)
            if isinstance(value, bool) or not isinstance(value, int) or value < 0:
                raise DataError(f"{where}: '{key}' must be a non-negative integer")
        present = part_list(obj, "present", where, self.num_parts)
        removable = part_list(obj, "removable", where, self.num_parts)
        check_ascending(present, "present", where)
        in_state = np.zeros(self.num_parts, dtype=bool)
        in_state[present] = True
        if not np.all(in_state[removable]):
            bad = int(removable[~in_state[removable]][0])
            raise DataError(f"{where}: removable part {bad} is not present")
        if np.any(self.fixed[removable]):
            bad = int(removable[self.fixed[removable]][0])
            raise DataError(f"{where}: removable part {bad} is fixed")
        reasons = []
        for key in REASONS:
            failed = part_list(obj, key, where, self.num_parts) if key in obj else np.zeros(0, dtype=np.int64)
            if np.any(np.isin(failed, removable)) or not np.all(in_state[failed]):
                raise DataError(f"{where}: '{key}' must name present parts that are not removable")
            reasons.append(failed)
        return State(self, int(obj["run"]), int(obj["step"]), present, removable, *reasons)


@dataclass(frozen=True)
class State:
    """One visited state: which parts are present and which of them are removable."""

    assembly: Assembly
    """The assembly the state belongs to."""
    run: int
    """The collection run."""
    step: int
    """The step within the run."""
    present: np.ndarray
    """int64, ascending part indices of the state."""
    removable: np.ndarray
    """int64 part indices labelled removable (present, non-fixed)."""
    collision: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    """int64 labelled parts that are not removable because every motion tried collides (empty
    when the data set does not record reasons)."""
    gravity: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    """int64 labelled parts that could leave but leave the rest unstable (the data set's
    checker's stability check; empty when the data set does not record reasons)."""
    arm_blocked: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    """int64 labelled parts the geometry lets out but the robot arm's lift collides (robot data
    sets only)."""
    arm_no_grasp: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    """int64 labelled parts the geometry lets out but the arm reaches no grasp of (robot data
    sets only)."""
    arm_no_path: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    """int64 labelled parts the geometry lets out but the arm finds no path to a grasp or to
    the drop-off for (robot data sets only)."""

    def subgraph(self) -> tuple[np.ndarray, np.ndarray]:
        """``(edge_ids, edge_index)`` of the induced subgraph (see :func:`induced_subgraph`)."""
        return induced_subgraph(self.assembly.edges, self.assembly.num_parts, self.present)

    def labels(self) -> tuple[np.ndarray, np.ndarray]:
        """``(labels, mask)`` per node: float32 1/0 removability and bool "is labelled"."""
        labels = np.isin(self.present, self.removable).astype(np.float32)
        mask = ~self.assembly.fixed[self.present]
        return labels, mask

    def graph(self) -> StateGraph:
        """The state's graph: node and edge attributes copied out of the memory maps."""
        edge_ids, edge_index = self.subgraph()
        labels, mask = self.labels()
        return StateGraph(
            x=np.ascontiguousarray(self.assembly.nodes[self.present], dtype=np.float32),
            edge_index=edge_index,
            edge_attr=np.ascontiguousarray(self.assembly.edge_attr[edge_ids], dtype=np.float32),
            labels=labels,
            mask=mask,
        )


REASONS = ("collision", "gravity", "arm_blocked", "arm_no_grasp", "arm_no_path")
"""The keys of ``states.jsonl`` that say why a labelled part is not removable (the ``arm_*`` keys
in data sets of the ``robot`` checker only)."""

CHECKERS = ("default", "physics", "robot")
"""The checkers a data set's labels (and a model's ``asp.checker``) can come from."""


@dataclass(frozen=True)
class RemovabilityDataset:
    """An opened ``asp-removability`` data set (validated ``index.json`` and model graphs)."""

    root: Path
    """The data set folder."""
    features: str
    """The features string the attributes were computed with."""
    node_dim: int
    """Floats per node attribute."""
    edge_dim: int
    """Floats per edge attribute."""
    seed: int | None
    """The collection seed, when recorded."""
    runs: int | None
    """Collection runs per assembly, when recorded."""
    assemblies: list[Assembly]
    """The assemblies, in index order."""
    checker: str = "default"
    """The checker whose tests labelled the states (``default``, ``physics``, ``robot``; a data
    set written before ``index.json`` recorded it reads as ``default``)."""

    @classmethod
    def open(cls, root: os.PathLike | str) -> RemovabilityDataset:
        """Open and validate a data set folder (index, graphs, array shapes; states stream later)."""
        root = Path(root)
        index_path = root / "index.json"
        index, features, node_dim, edge_dim = read_index(index_path, FORMAT, VERSION)
        assemblies = []
        for where, entry, name, sub in assembly_entries(index_path, index):
            parts = _int_field(index_path, entry, "parts", where, minimum=1)
            num_edges = _int_field(index_path, entry, "edges", where)
            num_states = _int_field(index_path, entry, "states", where)
            assemblies.append(_open_assembly(root / sub, name, parts, num_edges, num_states, node_dim, edge_dim))
        seed, runs = _optional_int(index, "seed"), _optional_int(index, "runs")
        checker = index.get("checker", "default")
        if checker not in CHECKERS:
            raise _fail(index_path, f"checker {checker!r} is not one of {', '.join(CHECKERS)}")
        return cls(root, features, node_dim, edge_dim, seed, runs, assemblies, checker)

    def assembly(self, name: str) -> Assembly:
        """The assembly called ``name``."""
        for a in self.assemblies:
            if a.name == name:
                return a
        known = ", ".join(a.name for a in self.assemblies)
        raise DataError(f"{self.root / 'index.json'}: no assembly named '{name}' (known: {known})")

    def states(self) -> Iterator[State]:
        """Stream every state of every assembly, assembly by assembly."""
        for a in self.assemblies:
            yield from a.states()


def _open_assembly(
    folder: Path, name: str, parts: int, num_edges: int, num_states: int, node_dim: int, edge_dim: int
) -> Assembly:
    graph_path = folder / "graph.json"
    graph = _read_json(graph_path)
    if not isinstance(graph, dict):
        raise _fail(graph_path, "must be a JSON object")
    part_list = graph.get("parts")
    if not isinstance(part_list, list):
        raise _fail(graph_path, "'parts' must be a list")
    if len(part_list) != parts:
        raise _fail(graph_path, f"has {len(part_list)} parts, index.json announces {parts}")
    part_names = []
    fixed = np.zeros(parts, dtype=bool)
    for i, part in enumerate(part_list):
        if not isinstance(part, dict) or not isinstance(part.get("name"), str):
            raise _fail(graph_path, f"parts[{i}] must be an object with a string 'name'")
        if not isinstance(part.get("fixed"), bool):
            raise _fail(graph_path, f"parts[{i}].fixed must be true or false")
        part_names.append(part["name"])
        fixed[i] = part["fixed"]
    edge_list = graph.get("edges")
    if not isinstance(edge_list, list):
        raise _fail(graph_path, "'edges' must be a list")
    if len(edge_list) != num_edges:
        raise _fail(graph_path, f"has {len(edge_list)} edges, index.json announces {num_edges}")
    edges = np.zeros((num_edges, 2), dtype=np.int64)
    seen = set()
    for k, edge in enumerate(edge_list):
        if (
            not isinstance(edge, list)
            or len(edge) != 2
            or not all(isinstance(v, int) and not isinstance(v, bool) for v in edge)
        ):
            raise _fail(graph_path, f"edges[{k}] must be a pair of part indices [s, t]")
        s, t = edge
        if not (0 <= s < parts and 0 <= t < parts):
            raise _fail(graph_path, f"edges[{k}] = [{s}, {t}] names a part outside 0..{parts - 1}")
        if s == t:
            raise _fail(graph_path, f"edges[{k}] = [{s}, {t}] is a self loop")
        if (s, t) in seen:
            raise _fail(graph_path, f"edges[{k}] = [{s}, {t}] appears twice")
        seen.add((s, t))
        edges[k] = (s, t)
    nodes = _load_array(folder / "nodes.npy", parts, node_dim, "node attributes")
    edge_attr = _load_array(folder / "edge_attr.npy", num_edges, edge_dim, "edge attributes")
    return Assembly(
        name=name,
        dir=folder,
        part_names=part_names,
        fixed=fixed,
        edges=edges,
        nodes=nodes,
        edge_attr=edge_attr,
        states_path=folder / "states.jsonl",
        num_states=num_states,
    )
