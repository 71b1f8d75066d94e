"""Time `polyscrew.sweep_closed` (the closed boundary) against `polyscrew.sweep` (the open
superset) on issue 29's cases: a unit cube on a 120-degree screw with a slide, an L-prism on a
half turn, a ~2,000-triangle torus on a smoothed 4-key motion, and (``--big``) a
100,000-triangle bumpy torus over 64 screws. CPU-time medians of alternating runs.

    PYTHONPATH=.pylib .venv/bin/python scripts/bench/bench_sweep_closed.py [--repeat 3] [--big]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import polyscrew

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_shapes import bumpy_torus  # noqa: E402
from bench_sweep_cases import cases, helix  # noqa: E402  (issue 29's cases, one definition)


def cpu(f):
    start = time.process_time()
    out = f()
    return time.process_time() - start, out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--big", action="store_true", help="also the 100,000-triangle torus over 64 screws")
    args = parser.parse_args()
    runs = {name: (v, t, keys) for name, (v, t, _, _, keys, _) in cases().items()}
    if args.big:
        runs["bumpy torus 100,000 triangles, 64 screws"] = (*bumpy_torus(250, 200), helix(64))
    print("| case | body triangles | sweep (open) CPU | sweep_closed CPU | closed triangles | cell | vertex bound |")
    print("|---|---|---|---|---|---|---|")
    for name, (v, t, poses) in runs.items():
        open_times, closed_times = [], []
        for _ in range(args.repeat):  # alternating A B A B
            open_times.append(cpu(lambda: polyscrew.sweep(v, t, poses))[0])
            seconds, out = cpu(lambda: polyscrew.sweep_closed(v, t, poses, info=True))
            closed_times.append(seconds)
        _, ct, info = out
        print(f"| {name} | {len(t)} | {1e3 * statistics.median(open_times):.1f} ms | "
              f"{statistics.median(closed_times):.2f} s | {len(ct)} | {info['cell']:.4f} | {info['error_bound']:.2e} |")


if __name__ == "__main__":
    main()
