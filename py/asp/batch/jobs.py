"""The jobs of ``asp.batch``: what a batch is made of, how each item runs, how the results are
put together.

A job is a list of items and a ``spec``: the settings that decide every result (generator and
seed, plan keywords, runs...). Each item is a pure function of the spec and its own payload: it
writes its output files (through temporary files and renames) and returns a small JSON-able
result, the same wherever it runs. That is what lets a batch run serially or as Ray tasks on any
machine, and resume by skipping the items whose results are recorded.
"""

from __future__ import annotations

import abc
import json
import os
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from asp import _asp

# format of the journal's job record: bump when a job's spec or results change meaning
JOURNAL_FORMAT = "asp-batch"
JOURNAL_VERSION = 1


@dataclass(frozen=True)
class Item:
    """One unit of work: its key (unique in the job, names its journal line) and payload."""

    key: str
    payload: dict[str, Any]


def _write_atomic(path: Path, text: str) -> None:
    tmp = path.with_name(f".{path.name}.tmp")
    with open(tmp, "w", encoding="utf-8") as f:
        f.write(text)
    os.replace(tmp, path)


def _models(paths: Sequence[os.PathLike | str]) -> list[dict[str, Any]]:
    """The models of files and folders, named as a data set names them."""
    return [
        {"path": path, "index": index, "name": name, "dir": d}
        for path, index, name, d in _asp.model_items([str(p) for p in paths])
    ]


class Job(abc.ABC):
    """A batch job (abstract): each kind defines its items, its :func:`run_item` runner and
    :meth:`finish`."""

    kind: str = ""
    # whether :meth:`finish` runs when some items failed (their results are ``{"error": ...}``)
    finishes_with_failures: bool = False

    def __init__(self, spec: dict[str, Any]) -> None:
        self.spec = spec

    @abc.abstractmethod
    def items(self) -> list[Item]:
        """The job's items, in a fixed order."""

    def done(self, out: Path, item: Item, result: dict[str, Any]) -> bool:
        """Whether a journaled item is still done (its output files exist)."""
        return all((out / f).is_file() for f in result.get("files", []))

    def describe(self, item: Item, result: dict[str, Any]) -> str:
        """One line of progress for an item that succeeded."""
        return item.key

    @abc.abstractmethod
    def finish(self, out: Path, results: dict[str, dict[str, Any]]) -> str:
        """Writes what needs every item (manifest, index, summary); returns the closing line."""

    def record(self) -> dict[str, Any]:
        """The job record of the journal: a resumed batch must have the same one."""
        return {"format": JOURNAL_FORMAT, "version": JOURNAL_VERSION, "kind": self.kind, "spec": self.spec}


# ---------------------------------------------------------------------------------------------
# gen: Soma cubes and profile assemblies (asp gen)


class GenJob(Job):
    """``count`` assemblies of one generator: the files ``asp gen`` writes for the same
    generator, count and seed, byte for byte, and the same ``manifest.json``."""

    kind = "gen"

    def __init__(self, generator: dict[str, Any], count: int, seed: int = 0, preset: str | None = None) -> None:
        if count < 1:
            raise ValueError(f"count must be at least 1, got {count}")
        canonical = json.loads(_asp.generator_canonical(json.dumps(generator)))
        super().__init__({"generator": canonical, "preset": preset, "count": int(count), "seed": int(seed)})

    @staticmethod
    def soma(size: int = 5, cell: float = 0.05, **kw: Any) -> GenJob:
        return GenJob({"kind": "soma", "size": size, "cell": cell}, **kw)

    @staticmethod
    def stress(kind: str, **kw: Any) -> GenJob:
        """The planner's stress cases (``asp gen stress --kind KIND``): ``chair``, ``carcass`` or
        ``bolted``."""
        if kind not in ("chair", "carcass", "bolted"):
            raise ValueError(f"unknown stress kind '{kind}' (one of bolted, carcass, chair)")
        return GenJob({"kind": "stress", "stress": kind}, **kw)

    @staticmethod
    def profiles(preset: str | None = None, overrides: dict[str, Any] | None = None, **kw: Any) -> GenJob:
        params = json.loads(_asp.profile_preset(preset or "single-layer"))
        for key, value in (overrides or {}).items():
            if key not in params:
                raise ValueError(f"unknown profile parameter '{key}' (one of {', '.join(sorted(params))})")
            params[key] = value
        return GenJob({"kind": "profiles", **params}, preset=preset, **kw)

    def items(self) -> list[Item]:
        return [Item(str(i), {"index": i}) for i in range(self.spec["count"])]

    def describe(self, item: Item, result: dict[str, Any]) -> str:
        entry = result["entry"]
        checks = entry["checks"]
        # stress cases need groups, screw motions or fits on purpose: only their linkage counts
        required = ("straight_line_disassemblable", "stable_order_found") if checks.get("straight_line_required", True) else ()
        passed = checks["contact_linked"] and all(checks[k] for k in required)
        return f"{entry['file']}: {entry['parts']} parts{'' if passed else ', failed its checks'}"

    def finish(self, out: Path, results: dict[str, dict[str, Any]]) -> str:
        s = self.spec
        entries = [json.dumps(results[str(i)]["entry"]) for i in range(s["count"])]
        manifest = json.loads(
            _asp.gen_manifest(json.dumps(s["generator"]), s["preset"], s["count"], s["seed"], entries, str(out))
        )
        failed = manifest["failed_checks"]
        note = f" ({failed} failed the generator's checks: see manifest.json)" if failed else ""
        return f"wrote {manifest['count']} assemblies and manifest.json to {out}{note}"


def _gen(spec: dict[str, Any], payload: dict[str, Any], out: str) -> dict[str, Any]:
    entry = json.loads(
        _asp.gen_item(json.dumps(spec["generator"]), payload["index"], spec["count"], spec["seed"], out)
    )
    return {"entry": entry, "files": [entry["file"]]}


# ---------------------------------------------------------------------------------------------
# plan: one plan JSON per model (asp plan --json)


@dataclass
class LoadSettings:
    """``asp.load``'s settings, the same for every model of a batch."""

    unit: str | None = None
    up: str | None = None
    fixed: list[str] = field(default_factory=list)
    max_triangles: int | None = None
    """The cap on a model's triangles (``None``: asp's, docs/security.md)."""
    max_parts: int | None = None
    """The cap on a model's parts (``None``: asp's)."""
    tessellation: float | None = None
    """STEP files: the chord tolerance relative to each edge's and face's size (``None``: 0.001)."""
    split_bodies: bool = False
    """Make each separate body of a part's mesh a part of its own (``NAME#1``, ``NAME#2``, ...)."""

    def as_dict(self) -> dict[str, Any]:
        d: dict[str, Any] = {"unit": self.unit, "up": self.up, "fixed": list(self.fixed)}
        for key in ("max_triangles", "max_parts", "tessellation"):
            if getattr(self, key) is not None:
                d[key] = getattr(self, key)
        if self.split_bodies:
            d["split_bodies"] = True
        return d


class PlanJob(Job):
    """Plans every model with the same keywords of :meth:`asp.Assembly.plan`: ``OUT/<name>.json``
    holds the plan JSON ``asp plan MODEL --json`` prints, and ``OUT/summary.json`` one row per
    model (with ``"error"`` for a model that could not be planned)."""

    kind = "plan"
    finishes_with_failures = True  # the summary lists the models that failed, with the error

    def __init__(self, models: Sequence[os.PathLike | str], settings: dict[str, Any] | None = None,
                 load: LoadSettings | None = None) -> None:
        settings = dict(settings or {})
        defaults = _asp.default_settings()
        unknown = sorted(set(settings) - set(defaults))
        if unknown:
            raise ValueError(f"unknown plan setting(s) {', '.join(unknown)} (known: {', '.join(sorted(defaults))})")
        super().__init__({
            "models": _models(models),
            "settings": settings,
            "load": (load or LoadSettings()).as_dict(),
        })

    def items(self) -> list[Item]:
        return [Item(m["name"], m) for m in self.spec["models"]]

    def describe(self, item: Item, result: dict[str, Any]) -> str:
        return (f"{item.key}: {result['status']}, {result['steps']} steps, "
                f"{result['removal_tests']} removal tests, {result['seconds']:.2f} s")

    def finish(self, out: Path, results: dict[str, dict[str, Any]]) -> str:
        rows = [{"name": i.key, "source": i.payload["path"], **results[i.key]} for i in self.items()]
        summary = {"format": "asp-batch-plans", "version": 1, "settings": self.spec["settings"],
                   "load": self.spec["load"], "plans": rows}
        _write_atomic(out / "summary.json", json.dumps(summary, indent=2) + "\n")
        found = sum(1 for r in rows if r.get("found"))
        partial = sum(1 for r in rows if r.get("status") == "partial")
        failed = sum(1 for r in rows if "error" in r)
        locked = f", {partial} partial (locked cores)" if partial else ""
        errors = f", {failed} could not be planned (errors in summary.json)" if failed else ""
        return f"{found} of {len(rows)} models planned{locked}{errors}; plans and summary.json in {out}"


def _plan_chunk(spec: dict[str, Any], payloads: list[dict[str, Any]], out: str) -> list[dict[str, Any]]:
    """Plans a chunk of models in one native call (``_asp.plan_items``): the settings resolved
    once, the models in parallel on asp's thread pool (one thread in a Ray task), each plan
    written to ``OUT/<dir>.json`` with the bytes ``asp plan --each`` writes (timings apart), and
    a small row per model, or ``{"error": message}`` for one that could not be planned."""
    settings = {k: v for k, v in spec["settings"].items() if v is not None}
    files = [f"{p['dir']}.json" for p in payloads]
    rows = _asp.plan_items([(p["path"], f) for p, f in zip(payloads, files)], out, settings, load=spec["load"])
    results: list[dict[str, Any]] = []
    for file, (error, status, found, parts, steps, tests, seconds) in zip(files, rows):
        if error is not None:
            results.append({"error": error})
        else:
            results.append({"file": file, "files": [file], "status": status, "found": found, "parts": parts,
                            "steps": steps, "removal_tests": tests, "seconds": seconds})
    return results


def _plan(spec: dict[str, Any], payload: dict[str, Any], out: str) -> dict[str, Any]:
    return _plan_chunk(spec, [payload], out)[0]


# ---------------------------------------------------------------------------------------------
# collect: removability training data (asp collect removability)


class CollectJob(Job):
    """Labelled states of ``runs`` vanilla DFS runs per model: the data set
    ``asp collect removability`` writes for the same models, runs and seed (``docs/learning.md``).
    As there, ``timeout`` (seconds per run) makes the data depend on timing; ``max_tests`` does
    not."""

    kind = "collect"

    def __init__(self, models: Sequence[os.PathLike | str], runs: int = 20, seed: int = 0,
                 max_tests: int | None = 20_000, timeout: float | None = 60.0,
                 settings: dict[str, Any] | None = None, load: LoadSettings | None = None) -> None:
        if runs < 1:
            raise ValueError(f"runs must be at least 1, got {runs}")
        super().__init__({
            "models": _models(models),
            "runs": int(runs),
            "seed": int(seed),
            "max_tests": max_tests,
            "timeout": timeout,
            "settings": dict(settings or {}),
            "load": (load or LoadSettings()).as_dict(),
        })

    def items(self) -> list[Item]:
        return [Item(m["name"], m) for m in self.spec["models"]]

    def done(self, out: Path, item: Item, result: dict[str, Any]) -> bool:
        d = out / item.payload["dir"]
        return all((d / f).is_file() for f in ("graph.json", "nodes.npy", "edge_attr.npy", "states.jsonl"))

    def describe(self, item: Item, result: dict[str, Any]) -> str:
        e = result["entry"]
        return f"{item.key}: {e['parts']} parts, {e['states']} states ({e['runs_found']} of {self.spec['runs']} runs complete)"

    def finish(self, out: Path, results: dict[str, dict[str, Any]]) -> str:
        entries = [json.dumps(results[i.key]["entry"]) for i in self.items()]
        index = json.loads(_asp.collect_index(
            str(out), self.spec["runs"], self.spec["seed"], entries, self.spec["settings"], load=self.spec["load"]
        ))
        states = sum(a["states"] for a in index["assemblies"])
        return (f"{out}: {len(index['assemblies'])} models, {states} labelled states, features "
                f"{index['features']} ({index['node_dim']} node, {index['edge_dim']} edge attributes)")


def _collect(spec: dict[str, Any], payload: dict[str, Any], out: str) -> dict[str, Any]:
    load = spec["load"]
    entry = _asp.collect_item(
        payload["path"], payload["index"], payload["name"], payload["dir"], out, spec["runs"], spec["seed"],
        spec["max_tests"], spec["timeout"], spec["settings"], load=load,
    )
    return {"entry": json.loads(entry)}


# ---------------------------------------------------------------------------------------------
# bench: the thesis' Table 3.1 (asp bench feasible)


class BenchJob(Job):
    """Time and removal tests of feasible planning under several orderings per model: the rows
    of ``asp bench feasible``, ``OUT/<name>.json`` per model and ``OUT/bench.json`` in all. Removal
    test counts do not depend on where a model runs; wall times do (models sharing a machine
    share its cores and caches)."""

    kind = "bench"

    def __init__(self, models: Sequence[os.PathLike | str], orderings: int = 10, methods: str | None = None,
                 model: str | None = None, models_dir: str | None = None,
                 settings: dict[str, Any] | None = None, load: LoadSettings | None = None) -> None:
        if orderings < 1:
            raise ValueError(f"orderings must be at least 1, got {orderings}")
        if model and models_dir:
            raise ValueError("give a model or a folder of leave-one-out models, not both")
        super().__init__({
            "models": _models(models),
            "orderings": int(orderings),
            "methods": methods,
            "model": None if model is None else str(model),
            "models_dir": None if models_dir is None else str(models_dir),
            "settings": dict(settings or {}),
            "load": (load or LoadSettings()).as_dict(),
        })

    def items(self) -> list[Item]:
        return [Item(m["name"], m) for m in self.spec["models"]]

    def describe(self, item: Item, result: dict[str, Any]) -> str:
        rows = result["rows"]
        best = min(rows, key=lambda r: r["removal_tests"]["mean"])
        return f"{item.key}: {len(rows)} methods, fewest tests {best['method']} ({best['removal_tests']['mean']:.1f})"

    def finish(self, out: Path, results: dict[str, dict[str, Any]]) -> str:
        rows = [row for i in self.items() for row in results[i.key]["rows"]]
        _write_atomic(out / "bench.json", json.dumps(rows, indent=2) + "\n")
        table = _asp.bench_table([json.dumps(rows)])
        _write_atomic(out / "bench.txt", table)
        return table.rstrip("\n") + f"\n(rows in {out / 'bench.json'})"


def _bench(spec: dict[str, Any], payload: dict[str, Any], out: str) -> dict[str, Any]:
    load = spec["load"]
    model = spec["model"]
    if spec["models_dir"]:
        model = str(Path(spec["models_dir"]) / f"{payload['name']}.onnx")
    rows = _asp.bench_item(
        payload["path"], payload["name"], spec["orderings"], spec["settings"], methods=spec["methods"],
        model=model, load=load,
    )
    file = f"{payload['dir']}.json"
    _write_atomic(Path(out) / file, rows + "\n")
    return {"rows": json.loads(rows), "files": [file]}


_RUNNERS = {"gen": _gen, "plan": _plan, "collect": _collect, "bench": _bench}


def run_item(kind: str, spec: dict[str, Any], payload: dict[str, Any], out: str) -> dict[str, Any]:
    """Runs one item of a job of ``kind`` (in this process: a serial loop or a Ray worker).
    asp's own errors (a model that does not load, bad settings) become ``{"error": message}``:
    one bad model does not stop a batch."""
    from asp.errors import AspError

    try:
        return _RUNNERS[kind](spec, payload, out)
    except AspError as e:
        return {"error": str(e)}


# kinds whose chunks run in one native call (the per-item call costs more than a small item)
_CHUNK_RUNNERS = {"plan": _plan_chunk}
#: The kinds of job whose chunks are one native call (see :func:`run_chunk`).
CHUNKED = frozenset(_CHUNK_RUNNERS)


def run_chunk(kind: str, spec: dict[str, Any], payloads: list[dict[str, Any]], out: str) -> list[dict[str, Any]]:
    """:func:`run_item` of several items (one Ray task, or one step of the serial loop): a plan
    chunk in one native call, in parallel; other kinds one item after the other."""
    chunk = _CHUNK_RUNNERS.get(kind)
    if chunk is not None:
        return chunk(spec, payloads, out)
    return [run_item(kind, spec, p, out) for p in payloads]
