"""Smooth Motion's CPU time against other checkouts of this repository, case by case, in
interleaved processes (each checkout with its own built extension and wheel in its `dist/`).

The cases of scripts/bench/bench_bake.py (Jarek 4 levels, timing Keys): 1 object x 100,000
frames, 100 objects x 1,000, 300 objects x 250, the 100-bone rig x 1,000 (Bones Only), and
the same at a tenth of the frames (`--quick`'s cases). Each round runs one process per
checkout, in turn (A B C A B C ...); each process smooths every case `--runs` times after a
warm-up and reports the process CPU time of each `bake.smooth` (every thread). Prints the
medians over all runs and each checkout's ratio to the first one.
Run with the bpy wheel (each checkout's `scripts/build_extension.sh` done):
    PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench/bench_bake_against.py /work/wt/base . [--rounds 3] [--runs 3]
or through `BENCH_AGAINST=<checkout> scripts/bench.sh` (part `bake`).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

#: (label, kind, owners, frames).
CASES = (
    ("1 object x 100,000 frames", "objects", 1, 100_000),
    ("100 objects x 1,000", "objects", 100, 1_000),
    ("300 objects x 250", "objects", 300, 250),
    ("100 bones x 1,000", "bones", 100, 1_000),
    ("1 object x 10,000 (quick)", "objects", 1, 10_000),
    ("100 objects x 100 (quick)", "objects", 100, 100),
    ("300 objects x 25 (quick)", "objects", 300, 25),
    ("100 bones x 100 (quick)", "bones", 100, 100),
)


def child(runs: int, only: list[str]) -> None:
    """In the checkout that is the current directory: every case `runs` times; JSON on the last line."""
    for folder in ("scripts", "scripts/bench"):  # bench_bake.py's place before and after scripts/bench/
        sys.path.insert(0, str(Path.cwd() / folder))
    import bench_bake  # installs this checkout's extension

    # isort: split
    import bpy  # (after bench_bake: it must install the extension first)

    bake = bench_bake.bake
    out = {}
    bench_bake.smooth_bones(3, 20, "keys")  # warm-up
    for label, kind, count, frames in CASES:
        if only and label not in only:
            continue
        times = []
        for _ in range(runs):
            if kind == "bones":
                times.append(bench_bake.smooth_bones(count, frames, "keys")[1])
                continue
            objects = bench_bake.keyed_objects(count, frames)
            bench_bake.select(objects)
            start = time.process_time()
            result = bake.smooth(objects, bake.Options(scheme="jarek", levels=4))
            times.append(time.process_time() - start)
            assert len(result.actions) == count and not result.skipped, result.skipped
        out[label] = times
    print(json.dumps({"blender": bpy.app.version_string, "cpu": out}))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("checkouts", nargs="+", type=Path, help="checkouts to compare; ratios are to the first")
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--runs", type=int, default=3, help="runs of each case per process")
    parser.add_argument("--case", action="append", default=[], help="only this case (its label; repeatable)")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.runs, args.case)
        return
    checkouts = [c.resolve() for c in args.checkouts]
    times: dict[Path, dict[str, list[float]]] = {c: {} for c in checkouts}
    for r in range(args.rounds):
        for c in checkouts:
            command = [sys.executable, str(Path(__file__).resolve()), "--child", "--runs", str(args.runs), "."]
            for label in args.case:
                command += ["--case", label]
            done = subprocess.run(command, cwd=c, capture_output=True, text=True, env=dict(os.environ))
            if done.returncode != 0:
                sys.exit(f"{c}: failed\n{done.stdout[-2000:]}\n{done.stderr[-2000:]}")
            got = json.loads(done.stdout.strip().splitlines()[-1])["cpu"]
            for label, values in got.items():
                times[c].setdefault(label, []).extend(values)
            print(f"round {r + 1}, {c}: " + ", ".join(f"{k} {statistics.median(v) * 1e3:.0f} ms" for k, v in got.items()),
                  flush=True)
    print("\nCPU medians (ms) over", args.rounds * args.runs, "runs; ratio to", checkouts[0])
    print("| case | " + " | ".join(str(c) for c in checkouts) + " |")
    print("| --- |" + " --- |" * len(checkouts))
    first = times[checkouts[0]]
    for label in first:
        base = statistics.median(first[label])
        cells = [f"{base * 1e3:.0f}"]
        for c in checkouts[1:]:
            m = statistics.median(times[c][label])
            cells.append(f"{m * 1e3:.0f} ({m / base:.2f})")
        print(f"| {label} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
