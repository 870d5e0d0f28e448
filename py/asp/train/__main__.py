"""``python -m asp.train removability DATA_DIR... --out model.onnx [options]``.

Trains the removability GNN on ``asp-removability`` data sets and writes an ONNX model plus a
JSON summary beside it (``model.onnx.json``: features, dimensions, epochs, seed, per-assembly
accuracy). ``--holdout NAME...`` keeps assemblies out of training and reports their accuracy;
``--leave-one-out OUT_DIR`` trains one model per assembly on all the others
(``OUT_DIR/<name>.onnx``) and reports each on its own assembly (the thesis' five-fold protocol).

``python -m asp.train q DATA_DIR... --objective NAME --out q.onnx [options]`` learns the Q-function of
one objective by deep Q-learning on ``asp-transitions`` data sets (:mod:`asp.train.q`) and writes the
ONNX Q model plus ``q.onnx.json`` (settings, loss curve, ranking quality per held-out assembly).

Exit status 0 on success, 2 on bad input.
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import sys
from pathlib import Path

from ..data import DataError
from .export import ExportError, export_onnx, write_parity_cases
from .trainer import AssemblyData, TrainConfig, evaluate, load_assemblies, train


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m asp.train", description="Train asp's learned guidance models.")
    sub = p.add_subparsers(dest="command", required=True)
    r = sub.add_parser("removability", help="train the part removability GNN (thesis 3.5)")
    r.add_argument("data", nargs="+", metavar="DATA_DIR", help="asp-removability data set folders")
    r.add_argument("--out", type=Path, help="the ONNX model to write (its summary goes to OUT.json)")
    r.add_argument("--epochs", type=int, default=50, help="passes over the training states (default 50)")
    r.add_argument("--lr", type=float, default=1e-3, help="Adam learning rate (default 1e-3)")
    r.add_argument("--batch", type=int, default=32, help="states per batch (default 32)")
    r.add_argument("--seed", type=int, default=0, help="seed of weights and batch order (default 0)")
    r.add_argument("--layers", type=int, default=3, help="GNN layers (default 3)")
    r.add_argument("--width", type=int, default=64, help="hidden width (default 64)")
    r.add_argument("--threads", type=int, default=1, help="PyTorch CPU threads (default 1)")
    r.add_argument("--seconds", type=float, help="cap the training time of each model")
    r.add_argument(
        "--aggregation", choices=["scatter", "dense"], default="dense",
        help="aggregation ops in the ONNX file: one-hot MatMul (default, the faster in tract) or ScatterND",
    )
    r.add_argument(
        "--parity-tolerance", type=float, default=1e-5,
        help="largest ONNX/PyTorch difference the export check accepts (default 1e-5)",
    )
    r.add_argument(
        "--parity-cases", type=Path, metavar="FILE",
        help="also write a few input graphs with the PyTorch outputs as JSON (for parity tests in other runtimes)",
    )
    r.add_argument("--pos-weight", type=float, default=1.0, help="weight of the removable class in the loss (default 1)")
    g = r.add_mutually_exclusive_group()
    g.add_argument("--holdout", nargs="+", metavar="NAME", default=[], help="assemblies to evaluate on, not train on")
    g.add_argument("--leave-one-out", type=Path, metavar="OUT_DIR", help="one model per assembly, trained on the others")
    _q_parser(sub)
    return p


def _q_parser(sub) -> None:
    q = sub.add_parser("q", help="learn the Q-function of one objective by deep Q-learning (thesis 5.4.4, 6.4.4)")
    q.add_argument("data", nargs="+", metavar="DATA_DIR", help="asp-transitions data set folders")
    q.add_argument("--objective", required=True, metavar="NAME", help="the objective of the data sets to learn")
    q.add_argument("--out", type=Path, required=True, help="the ONNX Q model to write (its summary goes to OUT.json)")
    q.add_argument("--steps", type=int, default=2000, help="gradient steps (default 2000)")
    q.add_argument("--seconds", type=float, help="stop training after this many seconds")
    q.add_argument("--batch", type=int, default=128, help="transitions per step (default 128)")
    q.add_argument("--buffer", type=int, default=10_000, help="replay buffer capacity (default 10000)")
    q.add_argument("--target-sync", type=int, default=100, help="steps between target network syncs (default 100)")
    q.add_argument("--loss", choices=["huber", "mse"], default="huber", help="regression loss (default huber)")
    q.add_argument("--lr", type=float, default=1e-3, help="Adam learning rate (default 1e-3)")
    q.add_argument("--seed", type=int, default=0, help="seed of weights and sampling (default 0)")
    q.add_argument("--layers", type=int, default=3, help="GNN layers (default 3)")
    q.add_argument("--width", type=int, default=64, help="hidden width (default 64)")
    q.add_argument("--threads", type=int, default=1, help="PyTorch CPU threads (default 1)")
    q.add_argument("--holdout", nargs="+", metavar="NAME", default=[], help="assemblies to evaluate on, not train on")
    q.add_argument(
        "--eval-states", type=int, default=2000,
        help="states per assembly scored for the ranking quality (default 2000)",
    )
    q.add_argument(
        "--aggregation", choices=["scatter", "dense"], default="dense",
        help="aggregation ops in the ONNX file (default dense)",
    )
    q.add_argument(
        "--parity-tolerance", type=float, default=1e-5,
        help="largest ONNX/PyTorch difference the export check accepts (default 1e-5)",
    )


def _log(message: str) -> None:
    print(message, file=sys.stderr, flush=True)


def _safe(name: str) -> str:
    return re.sub(r"[^A-Za-z0-9._-]", "_", name) or "assembly"


def _fit_and_export(
    args: argparse.Namespace,
    train_set: list[AssemblyData],
    test_set: list[AssemblyData],
    features: str,
    node_dim: int,
    edge_dim: int,
    out: Path,
) -> dict:
    config = TrainConfig(
        epochs=args.epochs, lr=args.lr, batch=args.batch, seed=args.seed,
        width=args.width, layers=args.layers, seconds=args.seconds, threads=args.threads,
        pos_weight=args.pos_weight,
    )
    names = ", ".join(a.name for a in train_set)
    _log(f"training on {sum(len(a.states) for a in train_set)} states of {len(train_set)} assemblies ({names})")
    model, summary = train(train_set, node_dim, edge_dim, config, log=_log)
    parity = export_onnx(model, out, features, aggregation=args.aggregation, tolerance=args.parity_tolerance)
    _log(f"wrote {out} (ONNX matches PyTorch to {parity:.2g})")
    if getattr(args, "parity_cases", None) is not None:
        write_parity_cases(model, args.parity_cases, features)
        _log(f"wrote {args.parity_cases}")
    train_acc = {a.name: evaluate(model, a) for a in train_set}
    held = {a.name: evaluate(model, a) for a in test_set}
    for name, r in held.items():
        print(f"{name}: accuracy {r['accuracy']:.4f} on {r['labels']} labels of {r['states']} states")
    median = statistics.median(r["accuracy"] for r in held.values()) if held else None
    if median is not None:
        print(f"median held-out accuracy: {median:.4f}")
    doc = {
        "kind": "removability",
        "features": features,
        "node_dim": node_dim,
        "edge_dim": edge_dim,
        "epochs": summary["epochs"],
        "epochs_requested": args.epochs,
        "time_capped": summary["time_capped"],
        "seed": args.seed,
        "lr": args.lr,
        "batch": args.batch,
        "layers": args.layers,
        "width": args.width,
        "aggregation": args.aggregation,
        "pos_weight": args.pos_weight,
        "final_loss": summary["loss"],
        "train_seconds": summary["seconds"],
        "onnx_parity_max_abs_diff": parity,
        "train_assemblies": [a.name for a in train_set],
        "train_accuracy": {k: v["accuracy"] for k, v in train_acc.items()},
        "holdout_accuracy": {k: v["accuracy"] for k, v in held.items()},
        "holdout": held,
        "median_holdout_accuracy": median,
    }
    Path(str(out) + ".json").write_text(json.dumps(doc, indent=2) + "\n")
    return doc


def _removability(args: argparse.Namespace) -> int:
    if args.out is None and args.leave_one_out is None:
        raise DataError("give --out MODEL.onnx, --leave-one-out OUT_DIR, or both")
    assemblies, features, node_dim, edge_dim = load_assemblies(args.data)
    by_name = {a.name: a for a in assemblies}
    if args.leave_one_out is not None:
        if len(assemblies) < 2:
            raise DataError("--leave-one-out needs at least two assemblies")
        out_dir: Path = args.leave_one_out
        out_dir.mkdir(parents=True, exist_ok=True)
        results = {}
        for a in assemblies:
            _log(f"== leaving out {a.name}")
            others = [o for o in assemblies if o is not a]
            doc = _fit_and_export(args, others, [a], features, node_dim, edge_dim, out_dir / f"{_safe(a.name)}.onnx")
            results[a.name] = doc["holdout_accuracy"][a.name]
        median = statistics.median(results.values())
        print("leave-one-out accuracy: " + ", ".join(f"{k} {v:.4f}" for k, v in results.items()))
        print(f"median leave-one-out accuracy: {median:.4f}")
        summary = {"features": features, "seed": args.seed, "epochs": args.epochs, "accuracy": results, "median_accuracy": median}
        (out_dir / "leave-one-out.json").write_text(json.dumps(summary, indent=2) + "\n")
    if args.out is not None:
        unknown = [n for n in args.holdout if n not in by_name]
        if unknown:
            raise DataError(f"--holdout names no assembly '{unknown[0]}' (known: {', '.join(by_name)})")
        test_set = [by_name[n] for n in args.holdout]
        train_set = [a for a in assemblies if a.name not in args.holdout]
        if not train_set:
            raise DataError("--holdout leaves no assembly to train on")
        _fit_and_export(args, train_set, test_set, features, node_dim, edge_dim, args.out)
    return 0


def _q(args: argparse.Namespace) -> int:
    from .q import QConfig, config_dict, export_q, open_q_assemblies, ranking_quality, train_q, BindingGraphs

    assemblies, features, node_dim, edge_dim = open_q_assemblies(args.data, args.objective)
    by_name = {a.name: a for a in assemblies}
    unknown = [n for n in args.holdout if n not in by_name]
    if unknown:
        raise DataError(f"--holdout names no assembly '{unknown[0]}' (known: {', '.join(by_name)})")
    test_set = [by_name[n] for n in args.holdout]
    train_set = [a for a in assemblies if a.name not in args.holdout]
    if not train_set:
        raise DataError("--holdout leaves no assembly to train on")
    config = QConfig(
        steps=args.steps, seconds=args.seconds, batch=args.batch, buffer=args.buffer, lr=args.lr,
        seed=args.seed, layers=args.layers, width=args.width, threads=args.threads,
        target_sync=args.target_sync, loss=args.loss,
    )
    graphs = BindingGraphs(features, node_dim, edge_dim)
    transitions = sum(a.assembly.num_transitions for a in train_set)
    _log(f"learning Q of '{args.objective}' from {transitions} transitions of {len(train_set)} assemblies "
         f"({', '.join(a.name for a in train_set)})")
    model, summary = train_q(train_set, node_dim, edge_dim, config, graphs, log=_log)
    parity = export_q(model, args.out, features, args.objective, aggregation=args.aggregation, tolerance=args.parity_tolerance)
    _log(f"wrote {args.out} (ONNX matches PyTorch to {parity:.2g}, padded graphs included)")
    train_rank = {a.name: ranking_quality(model, a, graphs, max_states=args.eval_states) for a in train_set}
    held = {a.name: ranking_quality(model, a, graphs, max_states=args.eval_states) for a in test_set}
    for name, r in held.items():
        if r["accuracy"] is None:
            print(f"{name}: no state with two observed actions to rank")
        else:
            print(f"{name}: argmax-Q is the best observed action in {r['accuracy']:.4f} of {r['scored']} states "
                  f"(chance {r['chance']:.4f}, mean regret {r['regret']:.4g})")
    doc = {
        "kind": "q",
        "objective": args.objective,
        "features": features,
        "node_dim": node_dim,
        "edge_dim": edge_dim,
        "data": [str(d) for d in args.data],
        "settings": config_dict(config),
        "aggregation": args.aggregation,
        "training": summary,
        "onnx_parity_max_abs_diff": parity,
        "train_assemblies": [a.name for a in train_set],
        "train_ranking": train_rank,
        "holdout_ranking": held,
    }
    Path(str(args.out) + ".json").write_text(json.dumps(doc, indent=2) + "\n")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    args = _parser().parse_args(argv)
    for flag in ("epochs", "batch", "layers", "width", "threads", "steps", "buffer", "target_sync", "eval_states"):
        value = getattr(args, flag, None)
        if value is not None and value < 1:
            print(f"error: --{flag.replace('_', '-')} must be at least 1", file=sys.stderr)
            return 2
    if args.seconds is not None and args.seconds <= 0:
        print("error: --seconds must be positive", file=sys.stderr)
        return 2
    try:
        if args.command == "q":
            return _q(args)
        return _removability(args)
    except (DataError, ExportError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
