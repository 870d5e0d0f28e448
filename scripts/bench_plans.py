#!/usr/bin/env python3
"""Whole-plan figures for docs/benchmarks.md: wall time of `asp plan` (median of 3 runs, the
process from start to exit, loading included) and removal tests, for the vanilla (given order)
and bookkeeping orderings on every shipped assembly.

Usage: cargo build --release -p asp-cli && python3 scripts/bench_plans.py
"""
import json
import statistics
import subprocess
import time

ASP = "target/release/asp"
MODELS = [
    ("beam", ["tests/data/beam/beam.glb", "--up", "z"]),
    ("bed_dalselv", ["tests/data/ikea/bed_dalselv_0270.glb", "--up", "z", "--ignore-overlapping"]),
    ("bookcase_billy", ["tests/data/ikea/bookcase_billy_0191.glb", "--up", "z"]),
    ("bookcase_grevback", ["tests/data/ikea/bookcase_grevback_0484.glb", "--up", "z"]),
    ("cabinet_akurum", ["tests/data/ikea/cabinet_akurum_0011.glb", "--up", "z"]),
    ("chair_bertil", ["tests/data/ikea/chair_bertil_0148.glb", "--up", "z"]),
    ("desk_hannes", ["tests/data/ikea/desk_hannes_0529.glb", "--up", "z"]),
    ("table_hemnes", ["tests/data/ikea/table_hemnes_0541.glb", "--up", "z"]),
    ("table_lack", ["tests/data/ikea/table_lack_0825.glb", "--up", "z"]),
    ("pump", ["tests/data/pump", "--unit", "mm"]),
]


def run(args):
    start = time.perf_counter()
    out = subprocess.run([ASP, "plan", *args, "--json", "-q"], capture_output=True, text=True)
    wall = time.perf_counter() - start
    if out.returncode not in (0, 1):
        raise SystemExit(f"asp failed on {args}: {out.stderr}")
    return wall, json.loads(out.stdout)


print("| model | parts | ordering | status | wall time (median of 3) | search time | removal tests | failed (collision / gravity) | path planner calls |")
print("|---|---|---|---|---|---|---|---|---|")
for name, args in MODELS:
    for label, extra in [("vanilla", ["--order", "given"]), ("bookkeeping", ["--order", "bookkeeping"])]:
        runs = [run(args + extra) for _ in range(3)]
        wall = statistics.median(r[0] for r in runs)
        plan = runs[0][1]
        s = plan["stats"]
        print(
            f"| {name} | {len(plan['parts'])} | {label} | {plan['status']} | {wall:.3f} s | {s['seconds']:.3f} s"
            f" | {s['removal_tests']} | {s['failed_collision']} / {s['failed_gravity']} | {s['path_planner_calls']} |"
        )
