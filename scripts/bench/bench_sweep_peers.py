"""Benchmark: the swept region (`polyscrew.sweep`) against its peers, on one case, in one run.

Case: a bumpy torus (48 x 24 quads, 2,304 triangles) along a polyscrew of 25 poses (24 screws:
a helix of radius 1.2 rising by 1, tumbling by 3 rad about a fixed axis).

Reference: the union of dense stamps, the body placed at `--stamps` poses per screw sampled
along the 24 screws (`polyscrew.interpolate`, the exact screw motion; 125 per screw, 3,001 in
all, by default). What is
compared is what can be seen of a solid from outside: orthographic depth images (a software
z-buffer, tests/python/raster.py, independent of the Rust code) from `--views` directions
spread evenly over the sphere, every covered pixel taken back to its 3D point. The reference
surface is the visible surface of the stamps (back faces culled, exact for the closed body);
each method's mesh is rendered the same way (no culling) and its visible points compared with
the reference's by the two-sided Hausdorff distance (scipy cKDTree, each way):
  - method -> reference: how far what is seen of the method lies from the reference surface at
    worst (a bulge, a dent, or a surface seen through a gap that the reference hides);
  - reference -> method: how far the reference surface lies from what is seen of the method at
    worst (a part of the region missed or flattened).
The larger of the two is the two-sided Hausdorff distance, the "depth error" at which the
methods are compared.
Interior triangles (our sweep's excess lies inside the region) are hidden, as in a render.
The floor of the measure is about one pixel (reported as `pixel`).

Compared, all fed the same screw motion:
  - ours: `polyscrew.sweep(body, 25 poses, steps=8)`, median time of several runs;
  - stroboscopic instancing: k instances per screw (k = 8, 16, 32, ...; 24 k + 1 copies of the
    body), until its two-sided error is no larger than ours ("at equal depth error"):
    triangles, and the time to build the instance arrays with numpy;
  - gpytoolbox `swept_volume` (Sellan, Aigerman, Jacobson 2021) given the dense stamp poses as
    its transformations (it interpolates between them: Catmull-Rom translations, slerped
    rotations), at a couple of grid sizes `eps`;
  - NVIDIA Warp `warp.geometry.swept_volume_mesh` on the CPU (marching cubes of the minimum,
    over the given poses, of the body's signed distance; winding-number sign; threshold 0).
    Its cost is a brute-force loop over poses at every grid node (time linear in poses x
    nodes), too slow for all the dense poses at a fine grid here: it is given every 25th and
    every 5th of the dense poses at one voxel size, and its time for all of them is
    extrapolated (and labelled so). The kernels are compiled by a warm-up call, not timed.

Run (bench.sh does, with the bench requirements installed):
    PYTHONPATH=<pylib> .venv/bin/python scripts/bench/bench_sweep_peers.py --out target/bench/sweep.json [--quick]
The pure helpers (hausdorff, visible_points, first_match, ...) are tested in
tests/python/test_bench_tools.py without gpytoolbox or warp.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import sys
import time
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_shapes  # noqa: E402
from sweep_measures import hausdorff  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]

#: Instances per screw tried for stroboscopic instancing, in this order (stops at the first match).
STROBE_LEVELS = (8, 16, 32, 64, 128, 256)
#: Steps per screw of our sweep.
OUR_STEPS = 8


# --- the case --------------------------------------------------------------------------------


def bumpy_torus(n: int = 48, m: int = 24) -> tuple[np.ndarray, np.ndarray]:
    """The bumpy torus of benches/sweep.rs with `n x m` quads (`2 n m` triangles, outward)."""
    return bench_shapes.bumpy_torus(n, m)


def rotation(axis, angle: float) -> np.ndarray:
    """Rodrigues: the rotation matrix by `angle` about the unit `axis`."""
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * kx + (1 - np.cos(angle)) * kx @ kx


def key_poses(screws: int = 24) -> np.ndarray:
    """`screws + 1` poses (4 x 4): a helix of radius 1.2 rising by 1, tumbling by 3 rad."""
    out = np.zeros((screws + 1, 4, 4))
    for k in range(screws + 1):
        s = k / screws
        out[k, :3, :3] = rotation((0.3, 1.0, 0.5), 3.0 * s)
        out[k, :3, 3] = (1.2 * np.cos(2 * np.pi * s), 1.2 * np.sin(2 * np.pi * s), s)
        out[k, 3, 3] = 1.0
    return out


def poses_along(poses: np.ndarray, per_screw: int) -> np.ndarray:
    """`per_screw` poses on each screw (t = 0, 1/k, ...) and the last pose: (screws k + 1, 4, 4)."""
    import polyscrew

    t = np.arange(per_screw) / per_screw
    parts = [polyscrew.interpolate(a, b, t) for a, b in zip(poses[:-1], poses[1:])]
    return np.concatenate(parts + [poses[-1:]])


def instance_arrays(vertices: np.ndarray, triangles: np.ndarray, poses: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The body copied at every pose, as one triangle soup (what instancing draws)."""
    v = np.einsum("mij,vj->mvi", poses[:, :3, :3], vertices) + poses[:, None, :3, 3]
    offsets = (np.arange(len(poses)) * len(vertices))[:, None, None]
    return v.reshape(-1, 3), (triangles[None] + offsets).reshape(-1, 3)


# --- measuring -------------------------------------------------------------------------------


def visible_points(view, depth: np.ndarray) -> np.ndarray:
    """The 3D points of the covered pixels of a depth image of `view` (a raster.View):
    the pixel centre on screen, at its depth along the view direction."""
    ys, xs = np.nonzero(np.isfinite(depth))
    scale = view.matrix[0, :3] @ view.right  # pixels per world unit
    # Inverse of raster.View: screen x = scale right.(p - c) + res / 2 (likewise y with up).
    r = (xs + 0.5 - view.matrix[0, 3]) / scale
    u = (ys + 0.5 - view.matrix[1, 3]) / scale
    d = depth[ys, xs]
    return r[:, None] * view.right + u[:, None] * view.up + d[:, None] * view.forward


def first_match(rows: list[dict], target: float) -> dict | None:
    """The first row whose two-sided Hausdorff distance (the larger of its two directed ones)
    is no larger than `target`: "at equal depth error"."""
    for row in rows:
        if max(row["h_to_ref"], row["h_from_ref"]) <= target:
            return row
    return None


def median_time(fn, repeat: int) -> tuple[float, object]:
    """Median wall-clock seconds of `repeat` calls of `fn` and the last result."""
    times, out = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), out


class Scene:
    """The views and the reference's visible points."""

    def __init__(self, vertices, triangles, stamps: np.ndarray, views: int, res: int) -> None:
        sys.path.insert(0, str(ROOT / "tests" / "python"))
        import raster

        self.raster = raster
        world, _ = instance_arrays(vertices, triangles, stamps)
        lo, hi = world.min(axis=0), world.max(axis=0)
        center = (lo + hi) / 2
        size = 1.04 * np.linalg.norm(hi - lo)  # the bounding sphere's diameter, with a margin
        self.pixel = size / res
        self.views = [raster.View(d, center, size, res) for d in raster.fibonacci_directions(views)]
        start = time.perf_counter()
        depth = raster.instances_depth_images(self.views, vertices, triangles, stamps, cull=True)
        self.render_seconds = time.perf_counter() - start
        self.points = np.concatenate([visible_points(v, d) for v, d in zip(self.views, depth)])
        self.tree = cKDTree(self.points)

    def error(self, vertices, triangles) -> tuple[float, float]:
        """Hausdorff (method -> reference, reference -> method) of a mesh's visible points."""
        pts = np.concatenate([
            visible_points(v, self.raster.depth_image(v, vertices, triangles, cull=False)) for v in self.views
        ])
        return hausdorff(pts, self.points, self.tree)

    def instances_error(self, vertices, triangles, poses) -> tuple[float, float]:
        depth = self.raster.instances_depth_images(self.views, vertices, triangles, poses, cull=True)
        pts = np.concatenate([visible_points(v, d) for v, d in zip(self.views, depth)])
        return hausdorff(pts, self.points, self.tree)


# --- the peers -------------------------------------------------------------------------------


def run_gpytoolbox(vertices, triangles, stamps, eps: float) -> tuple[float, np.ndarray, np.ndarray]:
    from gpytoolbox import swept_volume

    start = time.perf_counter()
    v, f = swept_volume(vertices, triangles, transformations=list(stamps), eps=eps)
    return time.perf_counter() - start, np.asarray(v, float), np.asarray(f, np.int64)


def warp_transforms(stamps: np.ndarray) -> np.ndarray:
    """Poses (S, 4, 4) as Warp transforms (1, S, 7): translation, then quaternion (x, y, z, w)."""
    from scipy.spatial.transform import Rotation

    out = np.zeros((1, len(stamps), 7), dtype=np.float32)
    out[0, :, :3] = stamps[:, :3, 3]
    out[0, :, 3:] = Rotation.from_matrix(stamps[:, :3, :3]).as_quat()
    return out


def run_warp(vertices, triangles, stamps, voxel: float) -> tuple[float, np.ndarray, np.ndarray]:
    import warp as wp
    import warp.geometry as geo

    mesh = wp.Mesh(
        wp.array(vertices.astype(np.float32), dtype=wp.vec3, device="cpu"),
        wp.array(triangles.astype(np.int32).ravel(), dtype=wp.int32, device="cpu"),
        support_winding_number=True,
    )
    xforms = warp_transforms(stamps)
    start = time.perf_counter()
    v, idx = geo.swept_volume_mesh([mesh], xforms, voxel_size=voxel, threshold=0.0,
                                   sign_mode=geo.SweptVolumeSignMode.WINDING_NUMBER, device="cpu")
    wp.synchronize_device("cpu")
    seconds = time.perf_counter() - start
    return seconds, v.numpy().astype(float), idx.numpy().reshape(-1, 3).astype(np.int64)


def warp_warm_up(vertices, triangles, stamps) -> float:
    """Compiles Warp's CPU kernels (a coarse call on a few poses); returns the seconds taken."""
    import warp as wp

    wp.config.quiet = True
    wp.init()
    start = time.perf_counter()
    run_warp(vertices, triangles, stamps[:3], 0.2)
    return time.perf_counter() - start


# --- main ------------------------------------------------------------------------------------


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, required=True, help="JSON results")
    parser.add_argument("--quick", action="store_true", help="a smoke run: fewer stamps, views, pixels, grids")
    parser.add_argument("--stamps", type=int, help="reference stamps per screw (default 125, quick 25)")
    parser.add_argument("--views", type=int, help="depth images (default 12, quick 6)")
    parser.add_argument("--res", type=int, help="pixels per side (default 1024, quick 384)")
    args = parser.parse_args()
    quick = args.quick
    per_screw = args.stamps or (25 if quick else 125)
    n_views = args.views or (6 if quick else 12)
    res = args.res or (384 if quick else 1024)
    gpy_eps = (0.1,) if quick else (0.1, 0.05)
    # Warp's field is a brute-force minimum over every pose at every grid node: its time is
    # linear in poses x nodes (about 2.6 us per pair on this machine's CPU, one thread), so the
    # full 3,000 poses at a fine grid do not finish in the bench's time. It is run on every
    # m-th of the dense poses, at two m, and its time for all of them extrapolated.
    warp_voxel = 0.2 if quick else 0.1
    warp_every = (25, 5)

    import polyscrew

    vertices, triangles = bumpy_torus()
    poses = key_poses()
    stamps = poses_along(poses, per_screw)
    screws = len(poses) - 1
    result: dict = {
        "quick": quick,
        "case": {"body": "bumpy torus, 48 x 24 quads", "triangles": len(triangles), "poses": len(poses),
                 "screws": screws, "motion": "helix of radius 1.2 rising by 1, tumbling 3 rad about (0.3, 1, 0.5)"},
        "reference": {"stamps": len(stamps), "per_screw": per_screw, "views": n_views, "res": res},
        "versions": {"python": platform.python_version(), "numpy": np.__version__},
        "rows": [], "strobe": [], "notes": [],
    }
    print(f"bench_sweep_peers: {len(triangles)} triangles, {len(poses)} poses ({screws} screws); "
          f"reference {len(stamps)} stamps, {n_views} views of {res} x {res} pixels")
    scene = Scene(vertices, triangles, stamps, n_views, res)
    result["reference"].update(pixel=scene.pixel, points=len(scene.points), seconds=scene.render_seconds)
    print(f"  reference: {len(scene.points):,} visible points, pixel {scene.pixel:.4f}, "
          f"rendered in {scene.render_seconds:.1f} s")

    def record(rows, method, note, seconds, tris, h, **extra):
        row = {"method": method, "note": note, "seconds": seconds, "triangles": int(tris),
               "h_to_ref": h[0], "h_from_ref": h[1], **extra}
        rows.append(row)
        print(f"  {method:30s} {note:34s} {seconds * 1e3:10.1f} ms {int(tris):>11,} triangles  "
              f"Hausdorff {h[0]:.4f} / {h[1]:.4f}", flush=True)
        return row

    seconds, (sv, st) = median_time(lambda: polyscrew.sweep(vertices, triangles, poses, steps=OUR_STEPS, tolerance=0), 7)
    ours = record(result["rows"], "ours (polyscrew.sweep)", f"{OUR_STEPS} steps per screw", seconds, len(st),
                  scene.error(sv, st), ours=True)
    target = max(ours["h_to_ref"], ours["h_from_ref"])

    for k in STROBE_LEVELS:
        if k >= per_screw:
            result["notes"].append(f"instancing stopped below the reference's {per_screw} stamps per screw")
            break
        inst = poses_along(poses, k)
        seconds, (iv, it) = median_time(lambda: instance_arrays(vertices, triangles, poses_along(poses, k)), 3)
        row = record(result["strobe"], "stroboscopic instancing", f"{k} per screw ({len(inst)} copies)",
                     seconds, len(it), scene.instances_error(vertices, triangles, inst), per_screw=k)
        if first_match([row], target):
            break
    match = first_match(result["strobe"], target)
    result["strobe_match"] = match["per_screw"] if match else None

    try:
        import gpytoolbox  # noqa: F401

        result["versions"]["gpytoolbox"] = package_version("gpytoolbox")
        for eps in gpy_eps:
            seconds, gv, gf = run_gpytoolbox(vertices, triangles, stamps, eps)
            record(result["rows"], "gpytoolbox swept_volume", f"eps {eps:g}, {len(stamps)} poses", seconds,
                   len(gf), scene.error(gv, gf), grid=eps)
    except ImportError as exc:
        result["notes"].append(f"gpytoolbox not available: {exc}")
        print(f"  gpytoolbox not available: {exc}")

    try:
        import warp

        result["versions"]["warp-lang"] = warp.__version__
        compile_s = warp_warm_up(vertices, triangles, stamps)
        result["notes"].append(f"Warp: kernel compilation (or cache load) and a first call took {compile_s:.1f} s, "
                               "not counted")
        measured = []
        for every in warp_every:
            sub = stamps[::every]
            seconds, wv, wf = run_warp(vertices, triangles, sub, warp_voxel)
            measured.append((len(sub), seconds))
            record(result["rows"], "Warp swept_volume_mesh (CPU)", f"voxel {warp_voxel:g}, {len(sub)} poses",
                   seconds, len(wf), scene.error(wv, wf), grid=warp_voxel, poses=len(sub))
        sys.path.insert(0, str(ROOT / "scripts"))
        from bench_report import extrapolate

        full, p = extrapolate([n for n, _ in measured], [t for _, t in measured], len(stamps))
        result["warp_extrapolated"] = {"poses": len(stamps), "voxel": warp_voxel, "seconds": full, "exponent": p,
                                       "from": [{"poses": n, "seconds": t} for n, t in measured]}
        print(f"  Warp with all {len(stamps)} poses at voxel {warp_voxel:g}: about {full:.0f} s "
              f"(extrapolated, time ~ poses^{p:.2f})")
    except ImportError as exc:
        result["notes"].append(f"warp-lang not available: {exc}")
        print(f"  warp-lang not available: {exc}")

    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=1))
    print(f"bench_sweep_peers: wrote {args.out}")


def package_version(name: str) -> str:
    """The installed version of a distribution, or "?"."""
    from importlib.metadata import PackageNotFoundError, version

    try:
        return version(name)
    except PackageNotFoundError:
        return "?"


if __name__ == "__main__":
    main()
