"""``python -m asp.train removability DATA_DIR... --out model.onnx [options]``.

Trains the removability GNN on ``asp-removability`` data sets and writes an ONNX model plus a
JSON summary beside it (``model.onnx.json``: features, dimensions, epochs, seed, per-assembly
accuracy). ``--holdout NAME...`` keeps assemblies out of training and reports their accuracy;
``--validation DATA_DIR...`` stops early: the epoch with the best accuracy on those data sets is kept;
``--leave-one-out OUT_DIR`` trains one model per assembly on all the others
(``OUT_DIR/<name>.onnx``) and reports each on its own assembly (the thesis' five-fold protocol).

``python -m asp.train q DATA_DIR... --objective NAME --out q.onnx [options]`` learns the Q-function of
one objective by deep Q-learning on ``asp-transitions`` data sets (:mod:`asp.train.q`) and writes the
ONNX Q model plus ``q.onnx.json`` (settings, loss curve, ranking quality per held-out assembly) and
``q.onnx.pt`` (the weights, for retraining).

``python -m asp.train distill DATA_DIR... --teacher q.onnx --out small.onnx [options]`` fits a
smaller Q network (default 16 wide, one layer) to a trained one's values of every action of the data
sets' states (:mod:`asp.train.q.distill`) and writes it with ``small.onnx.json`` (the ranking of the
teacher it keeps on held-out states) and ``small.onnx.pt``.

``python -m asp.train q-online MODEL --objective LIST --seconds S --out DIR [--q PRETRAINED...]`` runs
the optimiser on MODEL with its Q-functions trained after every episode (thesis 6.5's online
setting; ``--q``: the retrained setting, :mod:`asp.train.online`).

``python -m asp.train bench-mcts MODEL... --objective LIST --settings vanilla,online,pretrained,retrained
--q MODELS --seconds 10,60`` compares the four settings at equal wall time (``asp bench mcts``'s table).

Exit status 0 on success, 2 on bad input; `q-online` exits 1 when it found no complete sequence and
130 when Ctrl-C ended it (after writing the plan of the episodes finished).
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import sys
from pathlib import Path
from typing import TYPE_CHECKING, Any, get_args

from ..datasets import DataError
from ..errors import AspError
from ..settings import QUse
from .export import ExportError, export_onnx, write_parity_cases
from .trainer import AssemblyData, TrainConfig, evaluate, load_assemblies, train

if TYPE_CHECKING:
    from .online import OnlineConfig


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
    r.add_argument(
        "--validation", nargs="+", metavar="DATA_DIR", default=[],
        help="data sets of other assemblies, never trained on: after every epoch their accuracy is measured "
        "and the model of the best epoch is kept (early stopping)",
    )
    r.add_argument(
        "--patience", type=int, default=5,
        help="with --validation: stop after this many epochs without a better validation accuracy (default 5)",
    )
    g = r.add_mutually_exclusive_group()
    g.add_argument("--holdout", nargs="+", metavar="NAME", default=[], help="assemblies to evaluate on, not train on")
    g.add_argument("--leave-one-out", type=Path, metavar="OUT_DIR", help="one model per assembly, trained on the others")
    _q_parser(sub)
    _distill_parser(sub)
    _online_parsers(sub)
    return p


def _online_flags(o: argparse.ArgumentParser) -> None:
    o.add_argument("--objective", required=True, metavar="LIST", help="objectives, comma-separated (several: Pareto-MCTS)")
    o.add_argument("--steps-per-episode", type=int, default=20, help="deep Q-learning steps after each episode (default 20)")
    o.add_argument("--batch", type=int, default=5, help="transitions per step (default 5, the thesis')")
    o.add_argument("--buffer", type=int, default=10_000, help="replay buffer capacity (default 10000)")
    o.add_argument("--target-sync", type=int, default=100, help="steps between target network syncs (default 100)")
    o.add_argument("--lr", type=float, default=1e-3, help="Adam learning rate (default 1e-3)")
    o.add_argument("--layers", type=int, default=3, help="GNN layers of a new network (default 3)")
    o.add_argument("--width", type=int, default=64, help="hidden width of a new network (default 64)")
    o.add_argument("--threads", type=int, default=1, help="PyTorch CPU threads (default 1)")
    o.add_argument("--epsilon", type=float, help="probability of a random removal in a guided rollout (default: asp's, 0.2)")
    o.add_argument(
        "--q-use", choices=list(get_args(QUse)), help="where the Q models guide (default: asp's, rollouts)"
    )
    o.add_argument("--budget", type=int, default=5, help="MCTS iterations per step (default 5)")
    o.add_argument("--resolution", type=int, default=9, help="distance map resolution (default 9)")
    o.add_argument("--unit", help="the model's unit (mm, ...), as asp plan --unit")
    o.add_argument("--up", help="the up axis (+z, ...), as asp plan --up")
    o.add_argument(
        "--aggregation", choices=["scatter", "dense"], default="dense",
        help="aggregation ops in the ONNX files (default dense)",
    )


def _online_parsers(sub: argparse._SubParsersAction) -> None:
    o = sub.add_parser("q-online", help="optimise with Q-functions trained after each episode (thesis 6.5)")
    o.add_argument("model", metavar="MODEL", help="the model to plan (.glb, .gltf or a folder of OBJ/STL parts)")
    o.add_argument("--out", type=Path, required=True, help="folder for plan.json, trace.csv, the models and the transitions")
    o.add_argument("--seconds", type=float, help="wall time of the search, training included")
    o.add_argument("--episodes", type=int, help="the most episodes (reproducible without --seconds)")
    o.add_argument("--q", metavar="MODELS", help="pretrained Q models, comma-separated, one per objective: the retrained setting")
    o.add_argument("--seed", type=int, default=0, help="seed of the search and the networks (default 0)")
    _online_flags(o)
    b = sub.add_parser("bench-mcts", help="vanilla, online, pretrained and retrained MCTS at equal wall time (thesis Fig. 6.6/6.7)")
    b.add_argument("models", nargs="+", metavar="MODEL", help="models, or folders of them")
    b.add_argument("--settings", default="vanilla,online,pretrained,retrained", help="settings, comma-separated (default all four)")
    b.add_argument("--q", metavar="MODELS", help="pretrained Q models, one per objective (pretrained, retrained)")
    b.add_argument("--seconds", default="10,60", help="checkpoints, seconds, increasing; each run lasts the last (default 10,60)")
    b.add_argument("--runs", type=int, default=1, help="runs per model and setting, seeds 0, 1, ... (default 1)")
    b.add_argument("--csv", type=Path, help="also write the rows as CSV")
    b.add_argument("--json", type=Path, help="also write the rows as JSON")
    _online_flags(b)


def _q_parser(sub: argparse._SubParsersAction) -> None:
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
        "--train-eval-states", type=int, default=None,
        help="states per training assembly scored likewise (default: --eval-states; 0 skips them)",
    )
    q.add_argument(
        "--aggregation", choices=["scatter", "dense"], default="dense",
        help="aggregation ops in the ONNX file (default dense)",
    )
    q.add_argument(
        "--parity-tolerance", type=float, default=1e-5,
        help="largest ONNX/PyTorch difference the export check accepts (default 1e-5)",
    )


def _distill_parser(sub: argparse._SubParsersAction) -> None:
    d = sub.add_parser("distill", help="a smaller Q network fitted to a trained one's values (its ranking kept is measured)")
    d.add_argument("data", nargs="+", metavar="DATA_DIR", help="asp-transitions data set folders (the states to fit on)")
    d.add_argument("--teacher", type=Path, required=True, help="the trained Q model (its weights TEACHER.pt beside it)")
    d.add_argument("--out", type=Path, required=True, help="the ONNX student to write (its summary goes to OUT.json)")
    d.add_argument("--width", type=int, default=16, help="the student's hidden width (default 16)")
    d.add_argument("--layers", type=int, default=1, help="the student's GNN layers (default 1)")
    d.add_argument("--steps", type=int, default=2000, help="gradient steps (default 2000)")
    d.add_argument("--batch", type=int, default=32, help="states per step (default 32)")
    d.add_argument("--lr", type=float, default=3e-3, help="Adam learning rate (default 3e-3)")
    d.add_argument("--states", type=int, default=1500, help="distinct states per assembly (default 1500)")
    d.add_argument("--seed", type=int, default=0, help="seed of weights and sampling (default 0)")
    d.add_argument("--threads", type=int, default=1, help="PyTorch CPU threads (default 1)")


def _distill(args: argparse.Namespace) -> int:
    from .q import BindingGraphs, DistillConfig, distill_q, export_q, load_q_weights, open_q_assemblies, save_q_weights

    teacher, features, objective = load_q_weights(str(args.teacher) + ".pt")
    assemblies, data_features, node_dim, edge_dim = open_q_assemblies(args.data, objective)
    if (data_features, node_dim, edge_dim) != (features, teacher.node_dim, teacher.edge_dim):
        raise DataError(f"{args.teacher}: trained on features '{features}', the data sets have '{data_features}'")
    config = DistillConfig(
        width=args.width, layers=args.layers, steps=args.steps, batch=args.batch, lr=args.lr,
        states=args.states, seed=args.seed, threads=args.threads,
    )
    graphs = BindingGraphs(features, node_dim, edge_dim)
    _log(f"distilling '{objective}' from {args.teacher} into width {config.width}, {config.layers} layer(s)")
    student, summary = distill_q(teacher, assemblies, config, graphs, log=_log)
    parity = export_q(student, args.out, features, objective)
    save_q_weights(student, str(args.out) + ".pt", features, objective)
    kept = summary["ranking_kept"]
    print(f"{args.out}: keeps the teacher's best action in {kept['top1']:.4f} of {kept['states']} held-out states "
          f"(chance {kept['chance']:.4f}), rank correlation {kept['spearman']:.4f}")
    doc = {"kind": "q-distilled", "objective": objective, "features": features, "teacher": str(args.teacher),
           "data": [str(d) for d in args.data], "onnx_parity_max_abs_diff": parity, **summary}
    Path(str(args.out) + ".json").write_text(json.dumps(doc, indent=2) + "\n")
    return 0


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
    validation: list[AssemblyData] | None = None,
) -> dict:
    validation = validation or []
    config = TrainConfig(
        epochs=args.epochs, lr=args.lr, batch=args.batch, seed=args.seed,
        width=args.width, layers=args.layers, seconds=args.seconds, threads=args.threads,
        pos_weight=args.pos_weight, patience=args.patience,
    )
    names = ", ".join(a.name for a in train_set)
    _log(f"training on {sum(len(a.states) for a in train_set)} states of {len(train_set)} assemblies ({names})")
    model, summary = train(train_set, node_dim, edge_dim, config, log=_log, validation=validation)
    checker = train_set[0].checker
    parity = export_onnx(
        model, out, features, aggregation=args.aggregation, tolerance=args.parity_tolerance, extra_metadata={"asp.checker": checker}
    )
    _log(f"wrote {out} for the {checker} checker (ONNX matches PyTorch to {parity:.2g})")
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
        "checker": checker,
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
        "best_epoch": summary.get("best_epoch"),
        "patience": args.patience if validation else None,
        "validation_assemblies": [a.name for a in validation],
        "validation_accuracy": summary.get("validation_accuracy"),
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
    if args.patience < 1:
        raise DataError(f"--patience must be at least 1, got {args.patience}")
    validation: list[AssemblyData] = []
    if args.validation:
        like = (f"the training data {args.data[0]}", features, node_dim, edge_dim, assemblies[0].checker)
        try:
            validation, *_ = load_assemblies(args.validation, like=like)
        except DataError as e:
            raise DataError(f"--validation: {e}") from None
    if args.leave_one_out is not None:
        if len(assemblies) < 2:
            raise DataError("--leave-one-out needs at least two assemblies")
        out_dir: Path = args.leave_one_out
        out_dir.mkdir(parents=True, exist_ok=True)
        results = {}
        for a in assemblies:
            _log(f"== leaving out {a.name}")
            others = [o for o in assemblies if o is not a]
            doc = _fit_and_export(args, others, [a], features, node_dim, edge_dim, out_dir / f"{_safe(a.name)}.onnx", validation)
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
        _fit_and_export(args, train_set, test_set, features, node_dim, edge_dim, args.out, validation)
    return 0


def _q(args: argparse.Namespace) -> int:
    from .q import BindingGraphs, QConfig, config_dict, export_q, open_q_assemblies, ranking_quality, save_q_weights, train_q

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
    save_q_weights(model, str(args.out) + ".pt", features, args.objective)
    train_states = args.eval_states if args.train_eval_states is None else args.train_eval_states
    train_rank = {a.name: ranking_quality(model, a, graphs, max_states=train_states) for a in train_set} if train_states > 0 else {}
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


def _online_config(args: argparse.Namespace, **more: Any) -> OnlineConfig:
    from .online import OnlineConfig

    return OnlineConfig(
        objective=args.objective, steps_per_episode=args.steps_per_episode, batch=args.batch, buffer=args.buffer,
        target_sync=args.target_sync, lr=args.lr, layers=args.layers, width=args.width, threads=args.threads,
        epsilon=args.epsilon, q_use=args.q_use, budget=args.budget, resolution=args.resolution,
        aggregation=args.aggregation, **more,
    )


def _load_args(args: argparse.Namespace) -> dict:
    return {k: v for k, v in (("unit", args.unit), ("up", args.up)) if v is not None}


def _q_online(args: argparse.Namespace) -> int:
    from .online import run_online

    if args.seconds is None and args.episodes is None:
        raise DataError("give --seconds, --episodes or both")
    q = [p.strip() for p in args.q.split(",") if p.strip()] if args.q else None
    more = {"seconds": args.seconds, "seed": args.seed, "q": q}
    if args.episodes is not None:
        more["episodes"] = args.episodes
    r = run_online(args.model, args.out, _online_config(args, **more), load=_load_args(args))
    opt = r.plan.optimisation or {}
    print(f"{r.plan.status}: {r.episodes} episodes, {r.swaps} model swaps, "
          + (f"hypervolume {opt.get('hypervolume')}" if opt.get("hypervolume") is not None else f"values {opt.get('values')}"))
    if r.interrupted:
        return 130
    return 0 if r.plan.found else 1


def _bench_mcts(args: argparse.Namespace) -> int:
    from .online import bench_mcts

    try:
        checkpoints = [float(t) for t in args.seconds.split(",") if t.strip()]
    except ValueError:
        raise DataError(f"--seconds: '{args.seconds}' is not a list of seconds") from None
    settings = [s.strip() for s in args.settings.split(",") if s.strip()]
    q = [p.strip() for p in args.q.split(",") if p.strip()] if args.q else None
    table, csv, rows = bench_mcts(
        args.models, args.objective, settings, checkpoints, runs=args.runs, q=q,
        config=_online_config(args), load=_load_args(args),
    )
    print(table, end="")
    if args.csv is not None:
        args.csv.write_text(csv)
    if args.json is not None:
        args.json.write_text(json.dumps(rows, indent=2) + "\n")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Run the command line; returns the exit status."""
    args = _parser().parse_args(argv)
    counts = ("epochs", "batch", "layers", "width", "threads", "steps", "buffer", "target_sync", "eval_states", "episodes")
    for flag in counts + ("runs", "budget"):
        value = getattr(args, flag, None)
        if value is not None and value < 1:
            print(f"error: --{flag.replace('_', '-')} must be at least 1", file=sys.stderr)
            return 2
    if isinstance(getattr(args, "seconds", None), float) and args.seconds <= 0:
        print("error: --seconds must be positive", file=sys.stderr)
        return 2
    if getattr(args, "steps_per_episode", 1) < 0:
        print("error: --steps-per-episode must be at least 0", file=sys.stderr)
        return 2
    try:
        if args.command == "q":
            return _q(args)
        if args.command == "distill":
            return _distill(args)
        if args.command == "q-online":
            return _q_online(args)
        if args.command == "bench-mcts":
            return _bench_mcts(args)
        return _removability(args)
    except (DataError, ExportError, ValueError, AspError) as err:
        print(f"error: {err}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    raise SystemExit(main())
