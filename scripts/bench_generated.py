#!/usr/bin/env python3
"""Generator figures for docs/benchmarks.md: how fast `asp gen` writes each kind (assemblies per
second, whole command, best of 3) and how long `asp plan` takes on what it wrote (median over
the batch of the process wall time, and of the search time in the plan's stats).

Usage: cargo build --release -p asp-cli && python3 scripts/bench_generated.py [OUT_DIR]
"""
import json
import os
import statistics
import subprocess
import sys
import time

ASP = "target/release/asp"
OUT = sys.argv[1] if len(sys.argv) > 1 else "/tmp/asp-bench-gen"

RATES = [
    ("Soma 5×5×5", ["soma", "--size", "5", "--count", "2000", "--seed", "0"]),
    ("Soma 6×6×6", ["soma", "--size", "6", "--count", "500", "--seed", "0"]),
    ("single-layer profiles", ["profiles", "--preset", "single-layer", "--count", "300", "--seed", "1"]),
    ("double-layer profiles", ["profiles", "--preset", "double-layer", "--count", "300", "--seed", "1"]),
]
PLANS = [
    ("classic Soma cube", ["soma", "--classic"]),
    ("Soma 5×5×5", ["soma", "--size", "5", "--count", "50", "--seed", "0"]),
    ("Soma 6×6×6", ["soma", "--size", "6", "--count", "50", "--seed", "0"]),
    ("single-layer profiles", ["profiles", "--preset", "single-layer", "--count", "14", "--seed", "0"]),
    ("double-layer profiles", ["profiles", "--preset", "double-layer", "--count", "7", "--seed", "0"]),
]


def gen(args, out):
    subprocess.run(["rm", "-rf", out], check=True)
    start = time.perf_counter()
    subprocess.run([ASP, "gen", *args, "--out", out, "-q"], check=True)
    return time.perf_counter() - start


print("| kind | command | assemblies/s (best of 3) |")
print("|---|---|---|")
for name, args in RATES:
    out = os.path.join(OUT, "rate")
    best = min(gen(args, out) for _ in range(3))
    count = int(args[args.index("--count") + 1])
    print(f"| {name} | `asp gen {' '.join(args)} --out DIR -q` | {count / best:.0f} ({best:.2f} s) |")

print()
print("| kind | batch | found | median parts | median removal tests | median search | median wall | max wall |")
print("|---|---|---|---|---|---|---|---|")
for name, args in PLANS:
    out = os.path.join(OUT, "plan")
    gen(args, out)
    walls, searches, tests, parts, found = [], [], [], [], 0
    files = sorted(f for f in os.listdir(out) if f.endswith(".glb"))
    for f in files:
        start = time.perf_counter()
        r = subprocess.run([ASP, "plan", os.path.join(out, f), "--json", "-q"], capture_output=True, text=True)
        walls.append(time.perf_counter() - start)
        plan = json.loads(r.stdout)
        found += plan["status"] == "found"
        searches.append(plan["stats"]["seconds"])
        tests.append(plan["stats"]["removal_tests"])
        parts.append(len(plan["parts"]))
    batch = " ".join(args[1:]) or "1"
    print(
        f"| {name} | `{batch}` | {found} of {len(files)} | {statistics.median(parts):.0f} | {statistics.median(tests):.0f}"
        f" | {statistics.median(searches) * 1000:.1f} ms | {statistics.median(walls) * 1000:.0f} ms | {max(walls) * 1000:.0f} ms |"
    )
