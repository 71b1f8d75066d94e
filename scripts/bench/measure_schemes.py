"""How far each subdivision scheme strays from the animator's key poses, at default settings
otherwise (4 levels, timing Keys): the figures quoted in the Scheme tooltips.

Scenes: the demo's keyed motions (scripts/demo/10_scene.py, rebuilt here in memory) and 20
random keyed motions (7 keys at uneven frames, random walks of orientation, every rotation
mode). For each scheme: the largest distance of the object's origin from the key pose at the
key frames (scene units) and the largest angle (degrees) between the smoothed and keyed
orientations there, over every key of every scene.

Run: PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench/measure_schemes.py
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "demo"))
import demo_common  # noqa: E402

bake = demo_common.blender_with_addon()
import bpy  # noqa: E402

keys = importlib.import_module(bake.__name__.rsplit(".", 1)[0] + ".keys")
MODES = ("XYZ", "QUATERNION", "AXIS_ANGLE", "ZXY", "YZX")


def rotation(rotvec: np.ndarray) -> np.ndarray:
    angle = np.linalg.norm(rotvec)
    if angle == 0:
        return np.eye(3)
    k = rotvec / angle
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * K + (1 - np.cos(angle)) * K @ K


def random_scene(seed: int) -> bpy.types.Object:
    rng = np.random.default_rng(seed)
    obj = bpy.data.objects.new(f"Random{seed}", None)
    bpy.context.scene.collection.objects.link(obj)
    obj.rotation_mode = MODES[seed % len(MODES)]
    frames = np.cumsum(rng.integers(4, 14, 7))
    walk = np.cumsum(rng.normal(0, 0.5, (7, 3)), axis=0)
    for frame, rv, loc in zip(frames, walk, rng.uniform(-3, 3, (7, 3))):
        m = np.eye(4)
        m[:3, :3], m[:3, 3] = rotation(rv), loc
        from mathutils import Matrix

        obj.matrix_basis = Matrix(m.tolist())
        for path in ("location", keys.rotation_path(obj.rotation_mode)):
            obj.keyframe_insert(path, frame=float(frame))
    return obj


def demo_scene() -> list[bpy.types.Object]:
    """The demo's keyed scene, built in memory by scripts/demo/10_scene.py (no out/ file needed)."""
    spec = importlib.util.spec_from_file_location("demo_scene", Path(__file__).resolve().parents[1] / "demo" / "10_scene.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.build()
    return [o for o in bpy.context.scene.objects if o.animation_data and o.animation_data.action]


def stray(objects, scheme: str) -> tuple[float, float]:
    worst_distance = worst_angle = 0.0
    options = bake.Options(scheme=scheme)
    for obj in objects:
        motion = keys.read(obj)
        at = motion.frames[motion.is_key] if motion.is_key is not None else motion.frames
        poses, _ = bake.sample_poses(motion, at, options, obj)
        expected = motion.poses[motion.is_key] if motion.is_key is not None else motion.poses
        distance = np.linalg.norm(poses[:, :3, 3] - expected[:, :3, 3], axis=1).max()
        relative = np.einsum("nji,njk->nik", expected[:, :3, :3], poses[:, :3, :3])
        angle = np.degrees(np.arccos(np.clip((np.trace(relative, axis1=1, axis2=2) - 1) / 2, -1, 1))).max()
        worst_distance, worst_angle = max(worst_distance, distance), max(worst_angle, angle)
    return worst_distance, worst_angle


def main() -> None:
    scenes = {"demo scene": demo_scene()}
    results = {}
    for name, objects in scenes.items():
        if objects:
            results[name] = {s: stray(objects, s) for s in ("four_point", "bspline", "jarek")}
    bpy.ops.wm.read_homefile(use_empty=True)
    randoms = [random_scene(seed) for seed in range(20)]
    results["20 random motions"] = {s: stray(randoms, s) for s in ("four_point", "bspline", "jarek")}
    print(f"Blender {bpy.app.version_string}; 4 levels, timing Keys; largest stray from the key poses")
    print("| scheme | " + " | ".join(results) + " |")
    print("| --- |" + " --- |" * len(results))
    for scheme in ("four_point", "bspline", "jarek"):
        cells = [f"{d:.3g} m, {a:.3g} deg" for d, a in (results[n][scheme] for n in results)]
        print(f"| {scheme} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()
