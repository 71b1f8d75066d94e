"""Benchmarks of the Python API, each comparison side by side in one process run.

Plain Python (the project venv, numpy 2):
    python scripts/bench/bench_python.py --out target/bench/python.json
  * polyscrew.interpolate(a, b, ts) for 10,000 t in one call (batch), against a Python loop
    of pytransform3d's transform_sclerp and against a Python loop of polyscrew.interpolate
    with one float t per call;
  * when they exist in the installed module: feature-point design (polyscrew.feature_motion,
    6 keys x 7 levels, the case of Hofer et al. Table 1) and angular-velocity fitting
    (polyscrew.fit_angular_velocity, 20 keys, the case of Xie et al.).
Inside Blender (PYTHONPATH=.venv/bpy/5.0, numpy 1.26):
    python scripts/bench/bench_python.py --blender --out target/bench/blender.json
  * mathutils.Matrix.lerp (Blender's decoupled matrix interpolation) one call per t in a
    Python loop, against polyscrew.interpolate batch and per call in the same process.

Every figure is the median over --repeat runs of both wall-clock time and the thread's CPU
time (time.thread_time); ratios are taken between figures of the same run. The JSON holds
one record per measurement: name, per-call seconds (wall and CPU), calls per run, repeats.
"""

from __future__ import annotations

import argparse
import json
import math
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np


def measure(run, repeat: int) -> tuple[float, float]:
    """Median wall-clock and thread-CPU seconds of ``run()`` over ``repeat`` runs (one warm-up)."""
    run()
    walls, cpus = [], []
    for _ in range(repeat):
        w0, c0 = time.perf_counter(), time.thread_time()
        run()
        cpus.append(time.thread_time() - c0)
        walls.append(time.perf_counter() - w0)
    return statistics.median(walls), statistics.median(cpus)


def pose(angle: float, axis, translation) -> np.ndarray:
    """A 4x4 pose (Blender layout: translation in the last column) by Rodrigues' formula."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + math.sin(angle) * kx + (1 - math.cos(angle)) * kx @ kx
    m[:3, 3] = translation
    return m


A = pose(0.4, (0.2, -0.5, 1.0), (0.5, -1.0, 2.0))
B = pose(2.3, (1.0, 0.3, 0.2), (-1.5, 2.0, 0.5))


class Records:
    def __init__(self) -> None:
        self.items: list[dict] = []
        self.notes: list[str] = []

    def add(self, name: str, run, calls: int, repeat: int, **extra) -> dict:
        wall, cpu = measure(run, repeat)
        rec = {"name": name, "calls": calls, "repeat": repeat, "wall_per_call": wall / calls,
               "cpu_per_call": cpu / calls, **extra}
        self.items.append(rec)
        print(f"  {name}: {wall / calls * 1e6:10.3f} us per call wall, {cpu / calls * 1e6:10.3f} us CPU")
        return rec


def bench_interpolate(rec: Records, n: int, repeat: int) -> None:
    import polyscrew

    ts = np.linspace(0.0, 1.0, n)
    floats = [float(t) for t in ts]
    rec.add("polyscrew.interpolate batch", lambda: polyscrew.interpolate(A, B, ts), n, repeat)

    def ours_loop():
        for t in floats:
            polyscrew.interpolate(A, B, t)

    rec.add("polyscrew.interpolate per call (Python loop)", ours_loop, n, repeat)


def bench_pytransform3d(rec: Records, n: int, repeat: int) -> None:
    import polyscrew
    from pytransform3d.transformations import transform_sclerp

    ts = np.linspace(0.0, 1.0, n)
    floats = [float(t) for t in ts]

    def loop():
        for t in floats:
            transform_sclerp(A, B, t)

    import pytransform3d

    # The two agree (both are the screw between A and B): record the largest difference.
    ours = polyscrew.interpolate(A, B, ts[:: max(1, n // 100)])
    theirs = np.array([transform_sclerp(A, B, float(t)) for t in ts[:: max(1, n // 100)]])
    rec.add("pytransform3d transform_sclerp (Python loop)", loop, n, repeat,
            version=pytransform3d.__version__, max_abs_difference=float(np.abs(ours - theirs).max()))


def bench_feature(rec: Records, repeat: int) -> None:
    import polyscrew

    if not hasattr(polyscrew, "feature_motion"):
        rec.notes.append("feature-point design: not available: polyscrew.feature_motion is not in this build")
        return
    keys = np.array([pose(0.9 * k, (math.sin(k), 1.0, 0.3 * k), (k, math.cos(k), 0.2 * k)) for k in range(6)])
    for scheme in ("variational", "four_point", "jarek"):
        out = polyscrew.feature_motion(keys, scheme=scheme, levels=7)
        rec.add(f"polyscrew.feature_motion {scheme}, 6 keys x 7 levels", lambda s=scheme: polyscrew.feature_motion(keys, scheme=s, levels=7),
                1, repeat, output_poses=int(len(out)))


def bench_angvel(rec: Records, repeat: int) -> None:
    import polyscrew

    if not hasattr(polyscrew, "fit_angular_velocity"):
        rec.notes.append("angular-velocity fitting: not available: polyscrew.fit_angular_velocity is not in this build")
        return
    # The paper's spinning top (tests/fixtures/spinning_top.py, the twin of the Rust fixture),
    # the case of benches/angular_velocity.rs's fit_angular_velocity/top_20_keys: 20 keys over
    # 4 s, every third and the last constrained, the wobbly sketch sampled at 60 Hz.
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests" / "fixtures"))
    from spinning_top import top_rotation, top_target

    key_times = np.linspace(0.0, 4.0, 20)
    keys = np.roll(top_rotation(key_times).as_quat(), 1, axis=-1)  # w, x, y, z
    target_times = np.linspace(0.0, 4.0, 241)
    omega = top_target(target_times)
    constrained = np.array([i % 3 == 0 or i == len(keys) - 1 for i in range(len(keys))])
    fit = polyscrew.fit_angular_velocity(keys, key_times, target_times, omega, constrained=constrained)
    rec.add("polyscrew.fit_angular_velocity, 20 keys (spinning top)",
            lambda: polyscrew.fit_angular_velocity(keys, key_times, target_times, omega, constrained=constrained),
            1, repeat, status=str(fit.status), fit_error=float(fit.fit_error), iterations=int(fit.iterations))


def bench_mathutils(rec: Records, n: int, repeat: int) -> None:
    import bpy
    from mathutils import Matrix

    ma, mb = Matrix(A.tolist()), Matrix(B.tolist())
    floats = [float(t) for t in np.linspace(0.0, 1.0, n)]

    def loop():
        for t in floats:
            ma.lerp(mb, t)

    rec.add("mathutils.Matrix.lerp (Python loop)", loop, n, repeat, blender=bpy.app.version_string)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--blender", action="store_true", help="the comparison with mathutils, run under bpy")
    parser.add_argument("--n", type=int, default=10_000, help="interpolation parameters per run")
    parser.add_argument("--repeat", type=int, default=7)
    args = parser.parse_args()

    import polyscrew

    rec = Records()
    env = {"python": platform.python_version(), "numpy": np.__version__,
           "polyscrew": str(Path(polyscrew.__file__).parent)}
    print(f"bench_python: Python {env['python']}, numpy {env['numpy']}, n = {args.n}, median of {args.repeat}")
    bench_interpolate(rec, args.n, args.repeat)
    if args.blender:
        import bpy

        env["bpy"] = bpy.app.version_string
        bench_mathutils(rec, args.n, args.repeat)
    else:
        bench_pytransform3d(rec, args.n, args.repeat)
        for part in (bench_feature, bench_angvel):
            try:
                part(rec, max(3, args.repeat // 2))
            except Exception as exc:  # a part that fails is reported, the others still run
                rec.notes.append(f"{part.__name__}: not available: {type(exc).__name__}: {exc}")
    for note in rec.notes:
        print("  " + note)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps({"env": env, "records": rec.items, "notes": rec.notes}, indent=1))


if __name__ == "__main__":
    sys.exit(main())
