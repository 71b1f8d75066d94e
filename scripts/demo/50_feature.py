"""Demo part 50: noisy keys smoothed by feature-point motion design (Hofer-Pottmann-Ravani),
interpolating (every key hit) beside approximating (only the first and last key hit, the
others, all selected, pulled by the Stiffness spring). Writes out/demo_feature.blend, a stroboscopic
Workbench render out/demo_feature.png and the figures of the README
in out/demo_feature.txt.

Run: PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/demo/50_feature.py [--out-dir out]
(scripts/demo.sh runs it after building the extension).
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import demo_common  # noqa: E402

bake = demo_common.blender_with_addon()
import bpy  # noqa: E402
from mathutils import Euler, Matrix, Vector  # noqa: E402

#: Keys: one every KEY_STEP frames along a clean S-shaped flight, then jittered.
KEYS = 10
KEY_STEP = 10
JITTER_LOCATION = 0.35
JITTER_ROTATION = 0.15  # radians
STIFFNESS = 0.2
LEVELS = 5
#: The second panel sits this far from the first (world y).
PANEL_OFFSET = Vector((0.0, -9.0, 0.0))
SEED = 2026


def dart_mesh() -> bpy.types.Mesh:
    """A paper dart: nose along +x, wings in the xy plane, a fin up."""
    mesh = bpy.data.meshes.new("Dart")
    verts = [(0.9, 0, 0), (-0.5, 0.45, 0), (-0.5, -0.45, 0), (-0.5, 0, 0.3), (-0.3, 0, -0.05)]
    faces = [(0, 1, 3), (0, 3, 2), (0, 2, 4), (0, 4, 1), (1, 4, 2, 3)]
    mesh.from_pydata(verts, [], faces)
    return mesh


def clean_and_noisy_keys(rng: np.random.Generator) -> tuple[np.ndarray, list[Matrix]]:
    """Key frames and jittered key poses (heading along the path, banking into the turns)."""
    t = np.linspace(0.0, 1.0, KEYS)
    x, y = 14.0 * t, 2.5 * np.sin(2 * np.pi * t)
    heading = np.arctan2(2.5 * 2 * np.pi * np.cos(2 * np.pi * t), 14.0)
    bank = -0.5 * np.sin(2 * np.pi * t)
    poses = []
    for i in range(KEYS):
        rotation = Euler((bank[i], 0.0, heading[i]), "XYZ").to_matrix()
        jitter = Matrix.Rotation(float(np.linalg.norm(w := rng.normal(0, JITTER_ROTATION, 3))), 3, Vector(w))
        location = Vector((x[i], y[i], 0.0)) + Vector(rng.normal(0, JITTER_LOCATION, 3))
        poses.append(Matrix.Translation(location) @ (jitter @ rotation).to_4x4())
    return 1.0 + KEY_STEP * np.arange(KEYS), poses


def keyed_object(name: str, mesh, frames, poses, offset: Vector) -> bpy.types.Object:
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    obj.rotation_mode = "XYZ"
    previous = None
    for frame, pose in zip(frames, poses):
        obj.location = pose.translation + offset
        euler = pose.to_euler("XYZ", previous) if previous is not None else pose.to_euler("XYZ")
        obj.rotation_euler = euler
        previous = euler
        obj.keyframe_insert("location", frame=float(frame))
        obj.keyframe_insert("rotation_euler", frame=float(frame))
    return obj


def select_keys(obj, frames) -> None:
    """Selects exactly the keys at `frames` (the keys Approximate Keys works on)."""
    from bl_ext.user_default.screwbender.blender import channels

    for fcurve in channels.object_fcurves(obj):
        for point in fcurve.keyframe_points:
            point.select_control_point = any(abs(point.co[0] - f) < 1e-3 for f in frames)


def matrices(obj, frames) -> list[Matrix]:
    scene = bpy.context.scene
    out = []
    for frame in frames:
        scene.frame_set(int(frame), subframe=float(frame) - int(frame))
        out.append(obj.matrix_world.copy())
    return out


def add_instance(scene, mesh, matrix: Matrix, color, name: str) -> None:
    inst = bpy.data.objects.new(name, mesh)
    inst.matrix_world = matrix
    inst.color = color
    scene.collection.objects.link(inst)


def add_polyline(scene, points, color, name) -> None:
    curve = bpy.data.curves.new(name, "CURVE")
    curve.dimensions = "3D"
    curve.bevel_depth = 0.03
    spline = curve.splines.new("POLY")
    spline.points.add(len(points) - 1)
    for p, q in zip(spline.points, points):
        p.co = (q.x, q.y, q.z, 1.0)
    obj = bpy.data.objects.new(name, curve)
    obj.color = color
    scene.collection.objects.link(obj)


def add_text(scene, text: str, location: Vector, size: float) -> None:
    data = bpy.data.curves.new(f"Text {text[:12]}", "FONT")
    data.body = text
    data.size = size
    obj = bpy.data.objects.new(f"Text {text[:12]}", data)
    obj.location = location
    obj.color = (0.1, 0.1, 0.1, 1.0)
    scene.collection.objects.link(obj)


def roughness(ms: list[Matrix]) -> float:
    """Mean |second difference| of the origin per frame: how much the path jerks."""
    p = np.array([m.translation for m in ms])
    return float(np.linalg.norm(np.diff(p, 2, axis=0), axis=1).mean())


def main() -> None:
    out = demo_common.out_dir()
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    rng = np.random.default_rng(SEED)
    key_frames, poses = clean_and_noisy_keys(rng)
    mesh = dart_mesh()
    exact = keyed_object("Interpolating", mesh, key_frames, poses, Vector())
    approx = keyed_object("Approximating", mesh, key_frames, poses, PANEL_OFFSET)
    # Approximate Keys works on the selected keys (all of them after keying, as here); the
    # first and last key of an open motion are hit anyway.
    select_keys(approx, key_frames)
    common = dict(method="FEATURE", levels=LEVELS)
    bake.smooth([exact], bake.Options(**common), strict=True)
    bake.smooth([approx], bake.Options(**common, approximate=True, stiffness=STIFFNESS), strict=True)
    scene.frame_start, scene.frame_end = int(key_frames[0]), int(key_frames[-1])
    bpy.ops.wm.save_as_mainfile(filepath=str(out / "demo_feature.blend"))

    frames = np.arange(key_frames[0], key_frames[-1] + 1e-9, 1.0)
    figures = {}
    render = bpy.data.scenes.new("Render feature")
    for obj, offset in ((exact, Vector()), (approx, PANEL_OFFSET)):
        dense = matrices(obj, frames)
        at_keys = matrices(obj, key_frames)
        miss = [
            max(abs(a[i][j] - (Matrix.Translation(offset) @ k)[i][j]) for i in range(3) for j in range(4))
            for a, k in zip(at_keys, poses)
        ]
        figures[obj.name] = (roughness(dense), max(miss), float(np.mean(miss[1:-1])))
        for k, pose in enumerate(poses):
            add_instance(render, mesh, Matrix.Translation(offset) @ pose, (0.35, 0.35, 0.35, 1.0), f"key {obj.name} {k}")
        for i in range(0, len(frames), 4):
            u = i / (len(frames) - 1)
            add_instance(render, mesh, dense[i], (0.2 + 0.7 * u, 0.45, 0.9 - 0.6 * u, 1.0), f"{obj.name} {i}")
        add_polyline(render, [m.translation for m in dense], (0.9, 0.55, 0.1, 1.0), f"path {obj.name}")
    add_text(render, "Feature points, interpolating: every noisy key (grey) hit", Vector((-1.0, 4.0, 0.0)), 0.6)
    add_text(
        render,
        f"Approximating, stiffness {STIFFNESS}: first and last key hit",
        Vector((-1.0, 4.0, 0.0)) + PANEL_OFFSET,
        0.6,
    )

    camera_data = bpy.data.cameras.new("Camera feature")
    camera_data.type = "ORTHO"
    camera_data.ortho_scale = 18.5
    camera = bpy.data.objects.new("Camera feature", camera_data)
    camera.location = (7.0, -4.2, 50.0)
    camera.rotation_euler = (0.0, 0.0, 0.0)
    render.collection.objects.link(camera)
    render.camera = camera
    render.render.engine = "BLENDER_WORKBENCH"
    render.display.shading.color_type = "OBJECT"
    render.display.shading.light = "STUDIO"
    render.display.shading.show_object_outline = True
    render.render.resolution_x, render.render.resolution_y = 1400, 1400
    render.render.image_settings.file_format = "PNG"
    render.render.image_settings.color_mode = "RGB"
    render.render.image_settings.compression = 100
    render.world = bpy.data.worlds.new("White")
    render.world.color = (1.0, 1.0, 1.0)
    path = out / "demo_feature.png"
    render.render.filepath = str(path)
    bpy.ops.render.render(write_still=True, scene=render.name)

    lines = [
        f"noisy keys: {KEYS}, every {KEY_STEP} frames, jitter {JITTER_LOCATION} (location), "
        f"{math.degrees(JITTER_ROTATION):.1f} deg (rotation); levels {LEVELS}",
    ]
    for name, (rough, worst, mean_inner) in figures.items():
        lines.append(
            f"{name}: path roughness (mean |second difference| per frame) {rough:.4f}; "
            f"off the keys (largest matrix entry difference): max {worst:.3f}, mean over inner keys {mean_inner:.3f}"
        )
    text = "\n".join(lines)
    (out / "demo_feature.txt").write_text(text + "\n")
    print(text)
    print(f"wrote {path}, {out / 'demo_feature.blend'}")


if __name__ == "__main__":
    main()
