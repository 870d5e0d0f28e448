"""Readers of asp's learning data sets (docs/learning.md); they need only NumPy.

* :mod:`asp.datasets.removability`: ``asp-removability`` (states labelled with their removable
  parts; ``asp collect removability``), for :mod:`asp.train`'s removability GNN;
* :mod:`asp.datasets.transitions`: ``asp-transitions`` (optimiser transitions ``(s, a, r, s')``;
  ``asp collect q``), for :mod:`asp.train.q`'s Q-functions;
* :mod:`asp.datasets.jsonl`: what both share: :class:`DataError`, the checked ``index.json`` and
  the validated JSONL streamer.

``asp.data`` and ``asp.qdata`` are the same two readers under their earlier names.
"""

from __future__ import annotations

from .jsonl import DataError
from .removability import RemovabilityDataset
from .transitions import TransitionDataset

__all__ = ["DataError", "RemovabilityDataset", "TransitionDataset"]
