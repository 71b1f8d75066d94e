"""Time `polyscrew.sweep_closed` (the closed boundary) against `polyscrew.sweep` (the open
superset) on issue 29's cases: a unit cube on a 120-degree screw with a slide, an L-prism on a
half turn, a ~2,000-triangle torus on a smoothed 4-key motion, and (``--big``) a
100,000-triangle bumpy torus over 64 screws. CPU-time medians of alternating runs.

    PYTHONPATH=.pylib .venv/bin/python scripts/bench/bench_sweep_closed.py [--repeat 3] [--big]

``--dump DIR`` instead writes the cases (all four) as text for the Rust driver
``rust/polyscrew/examples/count_sweep_closed.rs`` (instruction counts under callgrind).
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

import numpy as np
import polyscrew

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tests" / "python"))
sys.path.insert(0, str(ROOT / "tests" / "fixtures"))
from screws import screw_matrix  # noqa: E402
from test_sweep_closed import CUBE_T, CUBE_V, HALF, LONG, SMOOTH, l_prism  # noqa: E402


def torus(n, m, big=0.6, small=0.22, bumps=0.0):
    u = 2 * np.pi * np.arange(n) / n
    w = 2 * np.pi * np.arange(m) / m
    uu, ww = np.meshgrid(u, w, indexing="ij")
    s = small * (1 + bumps * np.sin(5 * uu) * np.cos(3 * ww))
    r = big + s * np.cos(ww)
    v = np.stack([r * np.cos(uu), r * np.sin(uu), s * np.sin(ww)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    a, b = i * m + j, ((i + 1) % n) * m + j
    c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
    t = np.concatenate([np.stack([a, b, c], -1).reshape(-1, 3), np.stack([a, c, d], -1).reshape(-1, 3)])
    return v, t


def helix(count):
    """`count + 1` poses on a helical path with tumbling (the Rust sweep bench's motion)."""
    return np.array([screw_matrix((0.3, 1.0, 0.5), (0.5, 0.0, 0.0), 2.0 * math.pi * k / count, 2.0 * k / count)
                     for k in range(count + 1)])


def cpu(f):
    start = time.process_time()
    out = f()
    return time.process_time() - start, out


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
    args = parser.parse_args()
    cases = {
        "cube, 120-degree screw + slide": (CUBE_V, CUBE_T, LONG),
        "L-prism, half turn": (*l_prism(), HALF),
        "torus 2,304 triangles, smoothed 4 keys": (*torus(48, 24), SMOOTH),
    }
    if args.big or args.dump:
        cases["bumpy torus 100,000 triangles, 64 screws"] = (*torus(250, 200, bumps=0.25), helix(64))
    if args.dump:
        dump(args.dump, dict(zip(["cube", "lprism", "torus", "big"], cases.values())))
        return
    print("| case | body triangles | sweep (open) CPU | sweep_closed CPU | closed triangles | cell | vertex bound |")
    print("|---|---|---|---|---|---|---|")
    for name, (v, t, poses) in cases.items():
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
