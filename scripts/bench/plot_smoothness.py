"""The ScrewBender paper's smoothness figures, for our schemes and for Blender's own keys.

Figure 10 (docs/smoothness_fig10.png): a tumbling throw keyed by six poses; the
x-coordinate of the body points (0,0,0) and (2,0,0), its first and its second derivative
over time, for the B-spline, Jarek and 4-point polyscrew subdivisions and for Blender's
default Bezier keyframes of the same keys (location and XYZ Euler channels, evaluated by
Blender itself at sub-frames).

Figure 11 (docs/circle_fig11.png): a circular motion keyed by four poses (the body facing
along the circle), seen from above: the polyscrew subdivision keeps the circle, Blender's
per-channel interpolation does not.

Run with the project venv (numpy, matplotlib) and polyscrew importable; the Blender part
runs in a child process with the bpy module on its path (default .venv/bpy/5.0):
    PYTHONPATH=<polyscrew> .venv/bin/python scripts/bench/plot_smoothness.py [--out-dir docs]
Derivatives are central differences of the dense samples (`derivatives`, tested in
tests/python/test_bench_tools.py against an analytic curve).
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
FPS = 24  # frames per second; one key per second in both figures
SPAN_FRAMES = 24
LEVELS = 6  # 2**6 = 64 samples per key span for every curve

#: Figure 10's keys: location and XYZ Euler angles (degrees), one per second.
THROW = [
    ((0.0, 0.0, 0.0), (0, 0, 0)),
    ((2.0, 1.0, 2.0), (40, 10, 60)),
    ((4.0, 0.0, 3.0), (90, -20, 150)),
    ((6.5, -1.0, 2.5), (120, 30, 220)),
    ((8.0, 0.0, 1.0), (200, 10, 260)),
    ((10.0, 1.0, 0.0), (260, -10, 330)),
]
BODY_POINTS = ((0.0, 0.0, 0.0), (2.0, 0.0, 0.0))

#: Figure 11: four keys on a circle of this radius, the body's x axis along the circle.
RADIUS = 3.0
CIRCLE = [((RADIUS * math.cos(a), RADIUS * math.sin(a), 0.0), (0, 0, math.degrees(a + math.pi / 2)))
          for a in (k * math.pi / 2 for k in range(4))]
ARROW = np.array([(0.6, 0.0, 0.0), (-0.4, 0.3, 0.0), (-0.4, -0.3, 0.0)])  # body outline (top view)


def euler_xyz_matrix(loc, euler_deg) -> np.ndarray:
    """Blender's object matrix for location ``loc`` and XYZ Euler angles (degrees):
    ``T(loc) Rz(z) Ry(y) Rx(x)`` (Blender layout: translation in the last column)."""
    x, y, z = (math.radians(v) for v in euler_deg)
    cx, sx, cy, sy, cz, sz = math.cos(x), math.sin(x), math.cos(y), math.sin(y), math.cos(z), math.sin(z)
    rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    m = np.eye(4)
    m[:3, :3] = rz @ ry @ rx
    m[:3, 3] = loc
    return m


def derivatives(x: np.ndarray, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """First and second derivative of samples ``x`` spaced ``dt`` apart, by central
    differences ``(x[i+1] - x[i-1]) / 2dt`` and ``(x[i+1] - 2x[i] + x[i-1]) / dt^2``, at the
    interior samples ``x[1:-1]`` (both of length ``len(x) - 2``; errors O(dt^2))."""
    x = np.asarray(x, float)
    if x.ndim != 1 or len(x) < 3 or not dt > 0:
        raise ValueError("derivatives: a 1-D array of at least 3 samples and dt > 0 are needed")
    return (x[2:] - x[:-2]) / (2 * dt), (x[2:] - 2 * x[1:-1] + x[:-2]) / dt**2


def points_x(poses: np.ndarray, point) -> np.ndarray:
    """World x-coordinate of body ``point`` at each pose (N, 4, 4)."""
    return poses[:, 0, :3] @ np.asarray(point, float) + poses[:, 0, 3]


# ---------------------------------------------------------------- Blender (child process)

def blender_dump(path: Path) -> None:
    """Inside bpy: key an empty with Blender's defaults, evaluate its matrix at sub-frames."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    result = {"version": np.array(bpy.app.version_string)}
    for name, keys, closed in (("throw", THROW, False), ("circle", CIRCLE, True)):
        obj = bpy.data.objects.new(name, None)
        scene.collection.objects.link(obj)
        seq = list(keys) + ([(keys[0][0], tuple(np.add(keys[0][1], (0, 0, 360))))] if closed else [])
        for k, (loc, rot) in enumerate(seq):
            obj.location = loc
            obj.rotation_euler = [math.radians(v) for v in rot]
            frame = 1 + k * SPAN_FRAMES
            obj.keyframe_insert("location", frame=frame)
            obj.keyframe_insert("rotation_euler", frame=frame)
        spans = len(seq) - 1
        steps = spans * 2**LEVELS
        mats = []
        for j in range(steps + 1):
            f = 1 + j * SPAN_FRAMES / 2**LEVELS
            scene.frame_set(int(math.floor(f)), subframe=f - math.floor(f))
            mats.append(np.array(obj.matrix_world))
        result[name] = np.array(mats)
        result[name + "_keys"] = np.array([euler_xyz_matrix(*k) for k in seq])
    np.savez(path, **result)


def blender_curves(bpy_dir: Path) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "blender.npz"
        env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(bpy_dir)]))
        subprocess.run([sys.executable, __file__, "--blender-dump", str(out)], check=True, env=env,
                       stdout=subprocess.DEVNULL)
        data = dict(np.load(out))
    for name in ("throw", "circle"):
        # Blender's own evaluation at the key frames is the key pose we give polyscrew.
        keys = data[name + "_keys"]
        at_keys = data[name][:: 2**LEVELS]
        err = np.abs(at_keys - keys).max()
        assert err < 1e-5, f"Blender's keyed matrices differ from euler_xyz_matrix by {err}"
    return data


# ---------------------------------------------------------------- figures

SCHEMES = (("bspline", "B-spline polyscrew", "tab:blue"), ("jarek", "Jarek polyscrew", "tab:green"),
           ("four_point", "4-point polyscrew", "tab:orange"))
BLENDER_STYLE = ("Blender Bezier keys (per channel)", "black")


def figure10(blender: dict, out: Path) -> list[str]:
    import matplotlib.pyplot as plt
    import polyscrew

    keys = np.array([euler_xyz_matrix(*k) for k in THROW])
    dt = 1.0 / 2**LEVELS
    curves = [(label, color, "-", polyscrew.subdivide(keys, scheme, LEVELS, closed=False))
              for scheme, label, color in SCHEMES]
    curves.append((BLENDER_STYLE[0], BLENDER_STYLE[1], "--", blender["throw"]))
    fig, axes = plt.subplots(3, 2, figsize=(12, 10), sharex=True)
    rows = ("x (m)", "dx/dt (m/s)", "d²x/dt² (m/s²)")
    summary = []
    for col, point in enumerate(BODY_POINTS):
        for label, color, style, poses in curves:
            x = points_x(poses, point)
            t = np.arange(len(x)) * dt
            v, a = derivatives(x, dt)
            for row, (tt, yy) in enumerate(((t, x), (t[1:-1], v), (t[1:-1], a))):
                axes[row, col].plot(tt, yy, style, color=color, lw=1.2, label=label)
            # Largest jump of the second derivative between neighbouring samples: a kink
            # (C1 only) shows as a jump that does not shrink with the sample spacing.
            summary.append(f"point {point}: {label}: max |jump of d²x/dt²| = {np.abs(np.diff(a)).max():.2f} m/s²")
        axes[0, col].plot(np.arange(len(keys)), keys[:, 0, :3] @ np.array(point) + keys[:, 0, 3], "o",
                          color="red", ms=6, label="keys", zorder=5)
        axes[0, col].set_title(f"body point {point}")
        for row in range(3):
            ax = axes[row, col]
            ax.set_ylabel(rows[row])
            ax.grid(alpha=0.3)
            for k in range(len(keys)):
                ax.axvline(k, color="grey", lw=0.5, ls=":")
        axes[2, col].set_xlabel("time (s); one key per second (dotted lines)")
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=5, frameon=False)
    fig.suptitle("ScrewBender fig. 10 for a tumbling throw: x of two body points and its derivatives\n"
                 f"polyscrew subdivision (open, {LEVELS} levels) vs Blender {blender['version']} default Bezier keyframes",
                 fontsize=12)
    fig.tight_layout(rect=(0, 0.04, 1, 1))
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return summary


def figure11(blender: dict, out: Path) -> list[str]:
    import matplotlib.pyplot as plt
    import polyscrew

    keys = np.array([euler_xyz_matrix(*k) for k in CIRCLE])
    ours = polyscrew.subdivide(keys, "jarek", LEVELS, closed=True)
    ours = np.concatenate([ours, ours[:1]])
    theirs = blender["circle"]
    fig, axes = plt.subplots(1, 2, figsize=(12, 7), sharex=True, sharey=True)
    circle = np.linspace(0, 2 * np.pi, 400)
    summary = []
    for ax, poses, title, color in ((axes[0], ours, "polyscrew (Jarek, closed)", "tab:green"),
                                    (axes[1], theirs, f"Blender {blender['version']} Bezier keys (per channel)", "black")):
        ax.plot(RADIUS * np.cos(circle), RADIUS * np.sin(circle), ls=(0, (4, 4)), color="grey", lw=1, label="circle r = 3 m")
        origin = poses[:, :2, 3]
        ax.plot(origin[:, 0], origin[:, 1], color=color, lw=1.5, label="path of the body origin")
        for p in poses[:: 2**LEVELS // 8]:
            outline = (p[:3, :3] @ ARROW.T).T + p[:3, 3]
            ax.fill(outline[:, 0], outline[:, 1], facecolor="none", edgecolor=color, lw=0.7, alpha=0.8)
        for k in keys:
            outline = (k[:3, :3] @ ARROW.T).T + k[:3, 3]
            ax.fill(outline[:, 0], outline[:, 1], color="red", alpha=0.8)
        ax.plot([], [], "^", color="red", label="key poses (4)")
        dev = np.abs(np.linalg.norm(origin, axis=1) - RADIUS).max()
        ax.set_title(f"{title}\nlargest distance of the origin from the circle: {dev:.3g} m", fontsize=10)
        summary.append(f"{title}: largest radial deviation {dev:.3g} m")
        ax.set_aspect("equal")
        ax.set_xlabel("x (m), seen from above")
        ax.grid(alpha=0.3)
        ax.legend(loc="center", fontsize=9, frameon=False)
    axes[0].set_ylabel("y (m)")
    fig.suptitle("ScrewBender fig. 11: a circular motion keyed by four poses (outlines every 1/8 s), one key per second",
                 fontsize=12)
    fig.tight_layout(rect=(0, 0, 1, 0.95))
    fig.savefig(out, dpi=110)
    plt.close(fig)
    return summary


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out-dir", type=Path, default=ROOT / "docs")
    parser.add_argument("--bpy", type=Path, default=ROOT / ".venv" / "bpy" / "5.0", help="the bpy module tree")
    parser.add_argument("--blender-dump", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.blender_dump:
        blender_dump(args.blender_dump)
        return
    import matplotlib

    matplotlib.use("Agg")
    args.out_dir.mkdir(parents=True, exist_ok=True)
    blender = blender_curves(args.bpy)
    for line in figure10(blender, args.out_dir / "smoothness_fig10.png"):
        print(line)
    for line in figure11(blender, args.out_dir / "circle_fig11.png"):
        print(line)
    print(f"plot_smoothness: wrote {args.out_dir / 'smoothness_fig10.png'} and {args.out_dir / 'circle_fig11.png'}")


if __name__ == "__main__":
    main()
