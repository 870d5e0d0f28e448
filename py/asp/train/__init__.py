"""Training of asp's learned guidance (needs PyTorch; the rest of ``asp`` does not).

* :mod:`asp.train.encoder`: the graph encoder of thesis 3.5.2 (:class:`GraphEncoder`), which the
  removability GNN and the Q network are both built on;
* :mod:`asp.train.gnn`: the removability GNN (:class:`RemovabilityGNN`: the encoder and a head);
* :mod:`asp.train.trainer`: supervised training on ``asp-removability`` data sets (thesis 3.6.2);
* :mod:`asp.train.export`: ONNX export as docs/learning.md specifies, with a parity check;
* :mod:`asp.train.fixture`: the ONNX fixtures of the Rust crate ``asp-learn``.
* :mod:`asp.train.q`: Q-functions by deep Q-learning on ``asp-transitions`` data sets (thesis 5.4.4,
  6.4.4), exported as Q models (a package: network, graphs, replay, learner, evaluate, export;
  imported on demand; ``python -m asp.train q``).

Command line: ``python -m asp.train removability DATA_DIR... --out model.onnx`` (see ``--help``).
"""
from __future__ import annotations

from .encoder import GraphEncoder
from .export import ExportError, export_onnx, parity_check
from .gnn import RemovabilityGNN
from .trainer import TrainConfig, evaluate, load_assemblies, train

__all__ = [
    "ExportError",
    "GraphEncoder",
    "RemovabilityGNN",
    "TrainConfig",
    "evaluate",
    "export_onnx",
    "load_assemblies",
    "parity_check",
    "train",
]
