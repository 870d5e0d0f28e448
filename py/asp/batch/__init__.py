"""asp.batch: generation, planning, data collection and benchmarks over many assemblies, as Ray
tasks on one machine or a cluster, resumable.

>>> from asp.batch import GenJob, PlanJob, run                        # doctest: +SKIP
>>> run(GenJob.soma(size=6, count=100, seed=0), "data/soma6")          # doctest: +SKIP
>>> run(PlanJob(["data/soma6"], {"order": "gnn"}), "plans/", ray="auto")  # doctest: +SKIP

or from a shell, ``python -m asp.batch plan data/ --out plans/`` (``--help`` lists the jobs).
Each item (one assembly) is a pure function of the job's settings and its own inputs, so the
results are those of the serial commands (``asp gen``, ``asp plan --json``,
``asp collect removability``, ``asp bench feasible``) for the same seeds, wherever the items
run. The output folder keeps a journal (``.asp-batch/``): the same command run again skips the
items that are done. Ray (``pip install 'ray>=2.9'``, or the ``batch`` extra) is imported only
when a batch uses it; ``ray="none"`` runs a serial loop. On a cluster every node needs the
``asp`` package installed (the same wheel), and the models and output folder on a shared path.
"""

from __future__ import annotations

from .jobs import BenchJob, CollectJob, GenJob, Item, Job, LoadSettings, PlanJob, run_chunk, run_item
from .runner import BatchError, Outcome, run

__all__ = [
    "BatchError",
    "BenchJob",
    "CollectJob",
    "GenJob",
    "Item",
    "Job",
    "LoadSettings",
    "Outcome",
    "PlanJob",
    "run",
    "run_chunk",
    "run_item",
]
