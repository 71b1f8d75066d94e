"""Time `polyscrew.sweep_closed` (the closed boundary) against `polyscrew.sweep` (the open
superset) on issue 29's cases: a unit cube on a 120-degree screw with a slide, an L-prism on a
half turn, a ~2,000-triangle torus on a smoothed 4-key motion, and (``--big``) a
100,000-triangle bumpy torus over 64 screws, at the default tolerance (``--cell-rel X``: a
fixed cell of X times the body's extent) on one thread and on all the machine's
(``--threads 1,0``). CPU time (the process's, every thread) and wall time, medians of
alternating runs.

    PYTHONPATH=.pylib .venv/bin/python scripts/bench/bench_sweep_closed.py [--repeat 3] [--big]

``--dump DIR`` instead writes the cases (all four) as text for the Rust driver
``rust/polyscrew/examples/count_sweep_closed.rs`` (instruction counts under callgrind).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import polyscrew

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_shapes import bumpy_torus  # noqa: E402
from bench_sweep_cases import cases, helix  # noqa: E402  (issue 29's cases, one definition)


def cpu(f):
    """(CPU seconds of the process, every thread; wall seconds; f())."""
    start, wall = time.process_time(), time.perf_counter()
    out = f()
    return time.process_time() - start, time.perf_counter() - wall, out


def dump(folder: Path, cases: dict) -> None:
    """Each case as `folder/NAME.txt`: counts, then vertices, triangles and 4 x 4 poses, one a line."""
    folder.mkdir(parents=True, exist_ok=True)
    for name, (v, t, poses) in cases.items():
        v, t, poses = np.asarray(v, float), np.asarray(t, int), np.asarray(poses, float)
        rows = [f"{len(v)} {len(t)} {len(poses)}"]
        rows += [" ".join(repr(float(x)) for x in r) for r in v]
        rows += [" ".join(str(int(x)) for x in r) for r in t]
        rows += [" ".join(repr(float(x)) for x in m.reshape(-1)) for m in poses]
        (folder / f"{name}.txt").write_text("\n".join(rows) + "\n")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--big", action="store_true", help="also the 100,000-triangle torus over 64 screws")
    parser.add_argument("--dump", type=Path, help="write the cases to DIR for count_sweep_closed and stop")
    parser.add_argument("--threads", default="1,0", help="thread counts to compare (0: the machine's)")
    parser.add_argument("--cell-rel", type=float, help="a fixed cell, times the body's extent (default: the tolerance's)")
    args = parser.parse_args()
    runs = {name: (v, t, keys) for name, (v, t, _, _, keys, *_) in cases().items()}
    if args.big or args.dump:
        runs["bumpy torus 100,000 triangles, 64 screws"] = (*bumpy_torus(250, 200), helix(64))
    if args.dump:
        dump(args.dump, dict(zip(["cube", "lprism", "torus", "big"], runs.values())))
        return
    threads = [int(x) for x in args.threads.split(",")]
    print("| case | body triangles | sweep (open) CPU | threads | sweep_closed CPU | wall | closed triangles | cell "
          "| tolerance | vertex bound |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, (v, t, poses) in runs.items():
        extent = float(np.linalg.norm(np.ptp(np.asarray(v, float), axis=0)))
        grid = {"cell": args.cell_rel * extent} if args.cell_rel else {}
        open_times, closed = [], {n: [] for n in threads}
        for _ in range(args.repeat):  # alternating A B C A B C
            open_times.append(cpu(lambda: polyscrew.sweep(v, t, poses))[0])
            for n in threads:
                closed[n].append(cpu(lambda n=n: polyscrew.sweep_closed(v, t, poses, info=True, threads=n, **grid)))
        for n in threads:
            _, ct, info = closed[n][-1][2]
            digests = {hash((m[0].tobytes(), m[1].tobytes())) for _, _, m in closed[n]}
            assert len(digests) == 1
            print(f"| {name} | {len(t)} | {1e3 * statistics.median(open_times):.1f} ms | {n or 'all'} | "
                  f"{statistics.median(c for c, _, _ in closed[n]):.2f} s | {statistics.median(w for _, w, _ in closed[n]):.2f} s | "
                  f"{len(ct)} | {info['cell']:.4f} | {info['tolerance']:.4f} | {info['error_bound']:.2e} |", flush=True)
        meshes = {n: closed[n][-1][2] for n in threads}
        first = meshes[threads[0]]
        assert all(np.array_equal(m[0], first[0]) and np.array_equal(m[1], first[1]) for m in meshes.values()), name


if __name__ == "__main__":
    main()
