"""``python -m asp.batch {gen,plan,collect,bench} ... --out DIR [--ray local|auto|ADDRESS|none]``.

Every assembly of a batch as a Ray task (a local Ray by default, a cluster by address, or a
serial loop with ``--ray none``), resumable: run the same command again and finished items are
skipped. The results are those of the serial commands (``asp gen``, ``asp plan --json``,
``asp collect removability``, ``asp bench feasible``) for the same settings and seeds.
Exit status 0 when every item succeeded, 1 when some failed (the rest are kept), 2 on bad
input, 130 on Ctrl-C.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path
from typing import Any

from asp.errors import AspError

from .jobs import BenchJob, CollectJob, GenJob, Job, LoadSettings, PlanJob
from .runner import BatchError, run


def _value(text: str) -> Any:
    try:
        return json.loads(text)
    except ValueError:
        return text


def _pairs(pairs: list[str] | None, what: str) -> dict[str, Any]:
    out: dict[str, Any] = {}
    for pair in pairs or []:
        key, sep, value = pair.partition("=")
        if not sep or not key:
            raise BatchError(f"--{what} {pair!r}: expected KEY=VALUE")
        out[key.strip().replace("-", "_")] = _value(value)
    return out


def _common(p: argparse.ArgumentParser) -> None:
    p.add_argument("--out", type=Path, required=True, metavar="DIR", help="output folder (created; holds the journal)")
    p.add_argument(
        "--ray", default="local", metavar="WHERE",
        help="local (default: a Ray on this machine), auto (the cluster Ray finds), ray://HOST:PORT or "
             "HOST:PORT (that cluster), none (a serial loop, no Ray)",
    )
    p.add_argument("--workers", type=int, metavar="N",
                   help="CPUs of the local Ray (default: all); on a cluster, items at once at most")
    p.add_argument("--fresh", action="store_true", help="forget an earlier batch in --out and start over")
    p.add_argument("--quiet", "-q", action="store_true", help="no progress lines")


def _models(p: argparse.ArgumentParser) -> None:
    p.add_argument("models", nargs="+", metavar="MODEL",
                   help=".glb/.gltf files, folders of them (each file a model), or folders of OBJ/STL parts")
    p.add_argument("--unit", help="model unit (m, mm, ... or metres per unit; default from the file)")
    p.add_argument("--up", help="up axis (z, -y, ...; default from the file)")
    p.add_argument("--fixed", nargs="+", default=[], metavar="PART", help="base part names")
    p.add_argument("--max-triangles", type=int, metavar="N", help="most triangles a model may have (default 20 M; docs/security.md)")
    p.add_argument("--max-parts", type=int, metavar="N", help="most parts a model may have (default 10,000)")
    p.add_argument("--tessellation", type=float, metavar="RELATIVE",
                   help="STEP files: the chord tolerance of each edge and face relative to its own size (default 0.001)")
    p.add_argument("--split-bodies", action="store_true",
                   help="make each separate body of a part's mesh a part of its own (NAME#1, NAME#2, ...)")
    p.add_argument("--set", action="append", metavar="KEY=VALUE",
                   help="any keyword of asp.Assembly.plan (repeatable), e.g. --set normals=20 --set stability=physics")


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="python -m asp.batch", description=__doc__.split("\n\n")[1])
    sub = p.add_subparsers(dest="command", required=True)

    g = sub.add_parser("gen", help="generate assemblies (asp gen)")
    gsub = g.add_subparsers(dest="generator", required=True)
    soma = gsub.add_parser("soma", help="Soma cubes of any size")
    soma.add_argument("--size", type=int, default=5, help="cells along each edge, 2 or more (default 5)")
    soma.add_argument("--cell", type=float, default=0.05, help="cell edge in metres (default 0.05)")
    prof = gsub.add_parser("profiles", help="aluminium profile assemblies")
    prof.add_argument("--preset", choices=["single-layer", "double-layer"], help="a thesis data set (default single-layer)")
    prof.add_argument("--param", action="append", metavar="KEY=VALUE",
                      help="override a parameter (width, length, height, layers, supports, front, back, min_length, ...)")
    stress = gsub.add_parser("stress", help="the planner's stress cases: chairs, dowelled carcasses, bolted plates")
    stress.add_argument("--kind", required=True, choices=["chair", "carcass", "bolted"], help="which stress case")
    for q in (soma, prof, stress):
        q.add_argument("--count", type=int, default=1, help="how many assemblies (default 1)")
        q.add_argument("--seed", type=int, default=0, help="batch seed: the same seed gives the same files (default 0)")
        _common(q)

    pl = sub.add_parser("plan", help="plan every model (asp plan --json)")
    _models(pl)
    pl.add_argument("--order", help="part ordering: auto, given, shuffled, random, bookkeeping, gnn (default auto)")
    pl.add_argument("--model", help="removability model of --order gnn (default: the shipped one)")
    pl.add_argument("--bookkeeping", action="store_true", help="bookkeeping of blocked parts")
    pl.add_argument("--seed", type=int, help="seed of every random choice (default 0)")
    pl.add_argument("--max-tests", type=int, help="removal tests per model before it stops")
    pl.add_argument("--timeout", type=float, help="seconds per model before it stops")
    _common(pl)

    c = sub.add_parser("collect", help="collect training data (asp collect)")
    csub = c.add_subparsers(dest="what", required=True)
    rem = csub.add_parser("removability", help="labelled states of vanilla DFS runs (docs/learning.md)")
    _models(rem)
    rem.add_argument("--runs", type=int, default=20, help="DFS runs per model (default 20)")
    rem.add_argument("--seed", type=int, default=0, help="base seed (default 0)")
    rem.add_argument("--max-tests", type=int, default=20_000, help="removal tests per run (default 20000)")
    rem.add_argument("--timeout", type=float, default=60.0, help="seconds per run (default 60)")
    _common(rem)

    b = sub.add_parser("bench", help="benchmarks (asp bench)")
    bsub = b.add_subparsers(dest="what", required=True)
    fe = bsub.add_parser("feasible", help="removal tests and time per ordering (thesis Table 3.1)")
    _models(fe)
    fe.add_argument("--orderings", type=int, default=10, help="initial orderings per method (default 10)")
    fe.add_argument("--methods", help="comma-separated: vanilla, bk, random, given, gnn, each optionally +bk")
    m = fe.add_mutually_exclusive_group()
    m.add_argument("--model", help="removability model of the gnn methods")
    m.add_argument("--models-dir", help="leave-one-out models: DIR/<model name>.onnx for each model")
    fe.add_argument("--max-tests", type=int, help="removal tests per run before it stops")
    fe.add_argument("--timeout", type=float, help="seconds per run before it stops")
    _common(fe)
    return p


def job_of(args: argparse.Namespace) -> Job:
    """The job the parsed command line describes."""
    if args.command == "gen":
        if args.generator == "soma":
            return GenJob.soma(size=args.size, cell=args.cell, count=args.count, seed=args.seed)
        if args.generator == "stress":
            return GenJob.stress(args.kind, count=args.count, seed=args.seed)
        return GenJob.profiles(args.preset, _pairs(args.param, "param"), count=args.count, seed=args.seed)
    load = LoadSettings(unit=args.unit, up=args.up, fixed=list(args.fixed), max_triangles=args.max_triangles,
                        max_parts=args.max_parts, tessellation=args.tessellation, split_bodies=args.split_bodies)
    settings = _pairs(args.set, "set")
    if args.command == "plan":
        for key in ("order", "model", "seed", "max_tests", "timeout"):
            value = getattr(args, key)
            if value is not None:
                settings[key] = value
        if args.bookkeeping:
            settings["bookkeeping"] = True
        return PlanJob(args.models, settings, load)
    if args.command == "collect":
        return CollectJob(args.models, runs=args.runs, seed=args.seed, max_tests=args.max_tests,
                          timeout=args.timeout, settings=settings, load=load)
    for key in ("max_tests", "timeout"):
        value = getattr(args, key)
        if value is not None:
            settings[key] = value
    return BenchJob(args.models, orderings=args.orderings, methods=args.methods, model=args.model,
                    models_dir=args.models_dir, settings=settings, load=load)


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    try:
        job = job_of(args)
        outcome = run(job, args.out, ray=args.ray, workers=args.workers, fresh=args.fresh, quiet=args.quiet)
    except (BatchError, AspError, ValueError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        return 130
    print(outcome.summary)
    return 0 if outcome.ok else 1


if __name__ == "__main__":
    sys.exit(main())
