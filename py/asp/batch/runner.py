"""Running a job: the journal that makes a batch resumable, and the two executors (a serial loop
in this process, and Ray tasks on a local Ray or a cluster).

The journal lives in ``OUT/.asp-batch/``: ``job.json`` (the job's kind and spec) and
``done.jsonl`` (one line per finished item: its key and result, appended and flushed by this
process only, as results arrive). A batch run again with the same job skips every item whose line
is there and whose output files still exist; one killed half way finishes the rest. A line torn
by a kill is ignored (that item runs again). A different job in the same folder is refused
unless ``fresh`` is set, which starts over.
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable, TextIO

from ..errors import AspError
from .jobs import CHUNKED, Item, Job, run_chunk

JOURNAL_DIR = ".asp-batch"


class BatchError(AspError):
    """A batch cannot start or finish: its folder holds another job, Ray is missing, ..."""


@dataclass
class Outcome:
    """What a batch did: items run now, skipped as done before, and failed (with the error);
    ``seconds`` of the whole run, of which ``startup_seconds`` starting or joining Ray and
    ``shutdown_seconds`` stopping the Ray it started."""

    total: int
    ran: int = 0
    skipped: int = 0
    failed: dict[str, str] = field(default_factory=dict)
    seconds: float = 0.0
    startup_seconds: float = 0.0
    shutdown_seconds: float = 0.0
    summary: str = ""

    @property
    def ok(self) -> bool:
        return not self.failed


class Journal:
    """``OUT/.asp-batch/``: the job record and the finished items."""

    def __init__(self, out: Path, job: Job, fresh: bool = False) -> None:
        self.out = out
        self.dir = out / JOURNAL_DIR
        record = job.record()
        job_file = self.dir / "job.json"
        if fresh and self.dir.exists():
            shutil.rmtree(self.dir)
        if job_file.is_file():
            try:
                before = json.loads(job_file.read_text(encoding="utf-8"))
            except (OSError, ValueError) as e:
                raise BatchError(f"{job_file}: unreadable journal ({e}); start over with --fresh") from e
            if before != record:
                if not isinstance(before, dict) or before.get("kind") != record["kind"]:
                    what = f"a {before.get('kind') if isinstance(before, dict) else 'different'} batch"
                    difference = f"{what}, not {record['kind']}"
                else:
                    difference = _difference(before.get("spec"), record["spec"])
                raise BatchError(
                    f"{out}: holds a batch of other settings ({difference}); "
                    "use another --out, or --fresh to start over here"
                )
        else:
            self.dir.mkdir(parents=True, exist_ok=True)
            tmp = self.dir / ".job.json.tmp"
            tmp.write_text(json.dumps(record, indent=2) + "\n", encoding="utf-8")
            os.replace(tmp, job_file)
        self.path = self.dir / "done.jsonl"
        self.done: dict[str, dict[str, Any]] = {}
        if self.path.is_file():
            with open(self.path, encoding="utf-8") as f:
                for line in f:
                    try:
                        entry = json.loads(line)
                        self.done[entry["key"]] = entry["result"]
                    except (ValueError, KeyError, TypeError):
                        continue  # a line torn by a kill: that item runs again
        self._file: TextIO | None = None

    def add(self, key: str, result: dict[str, Any]) -> None:
        if self._file is None:
            self._file = open(self.path, "a", encoding="utf-8")
        self._file.write(json.dumps({"key": key, "result": result}) + "\n")
        self._file.flush()
        self.done[key] = result

    def close(self) -> None:
        if self._file is not None:
            self._file.close()
            self._file = None


_UNSET = object()


def _difference(before: Any, now: Any, where: str = "") -> str:
    """The first setting in which two specs differ, as `where: X before, Y now`."""
    if isinstance(before, dict) and isinstance(now, dict):
        for k in sorted(set(before) | set(now), key=str):
            b, n = before.get(k, _UNSET), now.get(k, _UNSET)
            if b != n:
                return _difference(b, n, f"{where}.{k}" if where else str(k))
    show = lambda v: "unset" if v is _UNSET or v is None else json.dumps(v)[:60]  # noqa: E731
    return f"{where or 'settings'}: {show(before)} before, {show(now)} now"


class Progress:
    """A line per finished item (on a terminal: one line updated in place), with rate and ETA."""

    def __init__(self, total: int, stream: TextIO = sys.stderr, quiet: bool = False) -> None:
        self.total, self.stream, self.quiet = total, stream, quiet
        self.tty = stream.isatty()
        self.count = 0
        self.started = time.perf_counter()
        self.last = 0.0

    def __call__(self, line: str) -> None:
        self.count += 1
        if self.quiet:
            return
        now = time.perf_counter()
        elapsed = now - self.started
        rate = self.count / elapsed if elapsed > 0 else 0.0
        left = (self.total - self.count) / rate if rate > 0 else 0.0
        text = f"[{self.count}/{self.total}] {line}  ({rate:.2f}/s, {left:.0f} s left)"
        if self.tty:
            self.stream.write("\r\x1b[K" + text[:200])
            if self.count == self.total:
                self.stream.write("\n")
        elif self.total <= 1000 or now - self.last >= 1.0 or self.count == self.total:
            self.stream.write(text + "\n")
            self.last = now
        self.stream.flush()

    def restart(self) -> None:
        """Rates count from now (after Ray has started)."""
        self.started = time.perf_counter()

    def message(self, text: str) -> None:
        if not self.quiet:
            if self.tty and 0 < self.count < self.total:
                self.stream.write("\n")
            self.stream.write(text + "\n")
            self.stream.flush()


def run(job: Job, out: os.PathLike | str, ray: str | None = "local", workers: int | None = None,
        fresh: bool = False, quiet: bool = False, stream: TextIO = sys.stderr) -> Outcome:
    """Runs ``job`` into folder ``out``: every item not done before, then the job's closing files.

    :param ray: ``"local"`` starts a Ray instance on this machine with ``workers`` CPUs;
        ``"auto"`` joins the cluster Ray finds (``RAY_ADDRESS``, or one started with
        ``ray start``); ``"ray://host:10001"`` or ``"host:6379"`` joins that cluster; ``None``
        or ``"none"`` runs the items in a serial loop in this process (no Ray needed).
    :param workers: CPUs of a local Ray (default: all); with a cluster, how many items run at
        once at most (default: the cluster's CPUs).
    :param fresh: forget what a previous batch in ``out`` did and start over.
    """
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    items = job.items()
    keys = [i.key for i in items]
    if len(set(keys)) != len(keys):
        raise BatchError("two items of the batch have the same name")
    journal = Journal(out, job, fresh=fresh)
    todo = [i for i in items if not (i.key in journal.done and job.done(out, i, journal.done[i.key]))]
    outcome = Outcome(total=len(items), skipped=len(items) - len(todo))
    progress = Progress(len(todo), stream=stream, quiet=quiet)
    if outcome.skipped:
        progress.message(f"{out}: {outcome.skipped} of {len(items)} items done before, {len(todo)} to go")
    started = time.perf_counter()

    def finished(item: Item, result: dict[str, Any]) -> None:
        if "error" in result:
            outcome.failed[item.key] = result["error"]
            progress(f"{item.key}: failed")
        else:
            journal.add(item.key, result)
            outcome.ran += 1
            progress(job.describe(item, result))

    try:
        if ray in (None, "none") or not todo:  # nothing to run: no Ray to start
            # plans in chunks as on Ray (one native call each, its models in parallel); other
            # kinds one item at a time (each journaled as soon as it ends)
            size = chunk_size(len(todo), 1) if job.kind in CHUNKED else 1
            for start in range(0, len(todo), size):
                chunk = todo[start:start + size]
                for item, result in zip(chunk, run_chunk(job.kind, job.spec, [i.payload for i in chunk], str(out))):
                    finished(item, result)
        else:
            outcome.startup_seconds, outcome.shutdown_seconds = _run_ray(
                job, todo, str(out), ray, workers, finished, progress.restart)
    except KeyboardInterrupt:
        journal.close()
        progress.message(
            f"interrupted: {len(journal.done)} of {len(items)} items done; "
            "the same command again finishes the rest"
        )
        raise
    journal.close()
    outcome.seconds = time.perf_counter() - started
    if outcome.failed:
        for key, error in outcome.failed.items():
            progress.message(f"error: {key}: {error}")
    if not outcome.failed or job.finishes_with_failures:
        results = {k: journal.done[k] if k in journal.done else {"error": outcome.failed[k]} for k in keys}
        outcome.summary = job.finish(out, results)
    if outcome.failed:
        note = (f"{len(outcome.failed)} of {len(items)} items failed; fix them and run the same "
                "command again (finished items are kept)")
        outcome.summary = f"{outcome.summary}\n{note}" if outcome.summary else note
    if outcome.ran:
        work = outcome.seconds - outcome.startup_seconds - outcome.shutdown_seconds
        rate = outcome.ran / work if work > 0 else float("inf")
        startup = f", after {outcome.startup_seconds:.1f} s starting Ray" if outcome.startup_seconds else ""
        if outcome.shutdown_seconds:
            startup += f", {outcome.shutdown_seconds:.1f} s stopping it"
        outcome.summary += f"\n{outcome.ran} items in {work:.1f} s ({rate:.2f} items/s{startup})"
    return outcome


def _ray_module():
    try:
        import ray
    except ImportError as e:
        raise BatchError("Ray is not installed: pip install 'ray>=2.9' (or ./py[batch]), or use --ray none") from e
    return ray


def chunk_size(items: int, slots: int) -> int:
    """Items of the first Ray tasks, before any cost is measured (:class:`ChunkSizer`): one while
    there are few (the slowest item bounds the batch, so spread them), up to 64 when there are
    many, so that a task's overhead (a few milliseconds) does not swamp items that take one
    (generating a Soma cube). A kill loses at most the chunks in flight."""
    return max(1, min(64, items // (16 * slots)))


# environment of every worker: one thread per task (Ray gives each task one CPU; asp's own
# thread pools would otherwise oversubscribe the cores)
WORKER_ENV = {"RAYON_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}


def _init_local(ray: Any, cpus: int) -> None:
    """Starts a local Ray whose workers have :data:`WORKER_ENV`. They inherit it from this
    process (set around ``ray.init``, which starts the processes that start the workers) rather
    than from a ``runtime_env``: a runtime environment makes Ray start a second set of worker
    processes through its agent, 0.5-0.8 s of every batch on a 2-core machine, and leaves the
    workers it started at ``init`` idle."""
    saved = {k: os.environ.get(k) for k in WORKER_ENV}
    os.environ.update(WORKER_ENV)
    try:
        ray.init(num_cpus=cpus, include_dashboard=False, log_to_driver=False, configure_logging=False)
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def timed_chunk(kind: str, spec: dict[str, Any], payloads: list[dict[str, Any]], out: str) -> tuple[float, list[dict[str, Any]]]:
    """:func:`run_chunk` and the seconds it took where it ran (what :class:`ChunkSizer` learns from)."""
    started = time.perf_counter()
    results = run_chunk(kind, spec, payloads, out)
    return time.perf_counter() - started, results


class ChunkSizer:
    """Items per Ray task by measured cost: the first tasks take :func:`chunk_size` items; once
    tasks have come back, as many items as take about :attr:`TARGET` seconds at the mean cost
    per item measured so far (up to :attr:`MOST`), and never more than an even share of what is
    left among twice the slots, so the last tasks still spread over the workers. Ray's overhead
    per task (a few milliseconds, and the driver's round trip through ``ray.wait``) then stays a
    small part of each task, whatever an item costs."""

    TARGET = 0.1
    MOST = 256

    def __init__(self, items: int, slots: int) -> None:
        self.slots = slots
        self.first = chunk_size(items, slots)
        self.seconds = 0.0
        self.items = 0

    def learn(self, seconds: float, items: int) -> None:
        """A task of ``items`` items took ``seconds`` where it ran."""
        self.seconds += seconds
        self.items += items

    def size(self, left: int) -> int:
        """Items for the next task, with ``left`` items not yet sent."""
        if self.items == 0:
            return self.first
        per_item = self.seconds / self.items
        wanted = self.MOST if per_item <= 0 else int(self.TARGET / per_item)
        share = -(-left // (2 * self.slots))  # ceiling: the tail spreads over the workers
        return max(1, min(self.MOST, wanted, share))


def _run_ray(job: Job, todo: list[Item], out: str, address: str, workers: int | None,
             finished: Callable[[Item, dict[str, Any]], None], ready: Callable[[], None]) -> tuple[float, float]:
    """Runs the items as Ray tasks; returns the seconds spent starting or joining Ray and the
    seconds spent stopping the Ray it started."""
    started = time.perf_counter()
    ray = _ray_module()
    started_here = not ray.is_initialized()
    if started_here:
        try:
            if address == "local":
                cpus = workers or os.cpu_count() or 1
                _init_local(ray, cpus)
            else:
                runtime_env = {"env_vars": dict(WORKER_ENV)}
                ray.init(address=address, runtime_env=runtime_env, log_to_driver=False, configure_logging=False)
        except Exception as e:  # Ray raises ConnectionError, RuntimeError, ValueError... by case
            first = str(e).splitlines()[0] if str(e) else type(e).__name__
            raise BatchError(f"cannot {'start' if address == 'local' else 'join'} Ray ({address}): {first}") from e
    startup = time.perf_counter() - started
    ready()
    try:
        if todo:
            _run_tasks(ray, job, todo, out, workers, finished)
    finally:
        stopping = time.perf_counter()
        if started_here:
            ray.shutdown()
    return startup, time.perf_counter() - stopping


def _run_tasks(ray: Any, job: Job, todo: list[Item], out: str, workers: int | None,
               finished: Callable[[Item, dict[str, Any]], None]) -> None:
    """The items as Ray tasks of :class:`ChunkSizer`'s sizes, a bounded number in flight."""
    cpus = int(ray.cluster_resources().get("CPU", 1))
    slots = max(1, min(workers, cpus) if workers else cpus)
    task = ray.remote(num_cpus=1, max_retries=1)(timed_chunk)
    spec = ray.put(job.spec)
    sizer = ChunkSizer(len(todo), slots)
    sent = 0
    pending: dict[Any, list[Item]] = {}
    # a bounded number of tasks in flight (twice the CPUs that run them): a batch of 100,000
    # assemblies does not become 100,000 tasks at once, and results are journaled as they come
    while sent < len(todo) or pending:
        while sent < len(todo) and len(pending) < 2 * slots:
            chunk = todo[sent:sent + sizer.size(len(todo) - sent)]
            sent += len(chunk)
            pending[task.remote(job.kind, spec, [i.payload for i in chunk], out)] = chunk
        finished_refs, _ = ray.wait(list(pending), num_returns=1)
        for ref in finished_refs:
            chunk = pending.pop(ref)
            try:
                seconds, results = ray.get(ref)
                sizer.learn(seconds, len(chunk))
            except Exception as e:  # a worker that died (out of memory, a crash)
                first = str(e).splitlines()[0] if str(e) else ""
                results = [{"error": f"the task failed: {type(e).__name__}: {first}"}] * len(chunk)
            for item, result in zip(chunk, results):
                finished(item, result)
