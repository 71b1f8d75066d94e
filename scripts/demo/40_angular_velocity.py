"""Demo part 40: angular-velocity editing (Xie et al. 2011) on the paper's spinning top.

Builds a top keyed every 5 frames for 96 frames (24 fps) as a steady precession (spin
1 turn/s about its axis, tilted 20 degrees, precessing 1 turn per 4 s), then works exactly
as an animator would in the add-on: Add Angular Velocity Sketch, a wobble pattern (loops of
12 degrees, two per second) applied to the blue direction curve on the sphere, every third
key selected to hold, Fit Angular Velocity. Prints the fit figures and writes

- out/angvel_sphere.png: the sketch (blue) and the fitted angular velocity (red) on the
  unit sphere, and their magnitudes over time (the paper's figures 2b and 3b);
- out/angvel_tip.png: the path of the top's tip before (grey) and after (red) the fit;
- out/angvel_filmstrip.png: Workbench filmstrip of the top every 6 frames, before (top row)
  and after (bottom row);

(`scripts/demo.sh --update-docs` copies them to docs/images/). Run: PYTHONPATH=<pylib>:.venv/bpy/5.0 python scripts/demo/40_angular_velocity.py
"""

from __future__ import annotations

import importlib
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import demo_common  # noqa: E402

demo_common.blender_with_addon()
import bmesh  # noqa: E402
import bpy  # noqa: E402
import matplotlib  # noqa: E402

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mathutils import Matrix, Quaternion, Vector  # noqa: E402

angvel = importlib.import_module("bl_ext.user_default.screwbender.blender.angvel")
transaction = importlib.import_module("bl_ext.user_default.screwbender.blender.transaction")

FPS = 24
N_KEYS = 20
KEY_STEP = 5
SPIN, PRECESSION, TILT = 2 * math.pi, 2 * math.pi / 4, math.radians(20)
WOBBLE, LOOPS = math.radians(12), -2.0
HOLD_EVERY = 3


def top_quaternion(t: float) -> Quaternion:
    """Rz(precession t) Rx(tilt) Rz(spin t) as a mathutils quaternion."""
    return (
        Quaternion((0, 0, 1), PRECESSION * t)
        @ Quaternion((1, 0, 0), TILT)
        @ Quaternion((0, 0, 1), SPIN * t)
    )


def wobble(directions: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The user's pattern: each direction moved onto a loop of radius WOBBLE around it."""
    d = directions / np.linalg.norm(directions, axis=1, keepdims=True)
    u = np.cross([0.0, 0.0, 1.0], d)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(d, u)
    phi = (2 * np.pi * LOOPS * t)[:, None]
    return np.cos(WOBBLE) * d + np.sin(WOBBLE) * (np.cos(phi) * u + np.sin(phi) * v)


def top_mesh() -> bpy.types.Mesh:
    """A cone standing on its tip at the origin, with a marker block on its rim."""
    bm = bmesh.new()
    bmesh.ops.create_cone(
        bm, cap_ends=True, segments=24, radius1=0.0, radius2=0.5, depth=1.0,
        matrix=Matrix.Translation((0, 0, 0.5)),
    )
    bmesh.ops.create_cube(bm, size=0.18, matrix=Matrix.Translation((0.5, 0, 0.95)))
    mesh = bpy.data.meshes.new("Top")
    bm.to_mesh(mesh)
    bm.free()
    return mesh


def build_scene() -> tuple[bpy.types.Object, np.ndarray]:
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = FPS, 1.0
    frames = 1.0 + KEY_STEP * np.arange(N_KEYS)
    scene.frame_start, scene.frame_end = int(frames[0]), int(frames[-1])
    obj = bpy.data.objects.new("Top", top_mesh())
    scene.collection.objects.link(obj)
    obj.rotation_mode = "QUATERNION"
    previous = None
    for f in frames:
        q = top_quaternion((f - 1.0) / FPS)
        if previous is not None and q.dot(previous) < 0:
            q.negate()
        previous = q
        obj.rotation_quaternion = q
        obj.location = (0.0, 0.0, 0.0)
        obj.keyframe_insert("rotation_quaternion", frame=f)
        obj.keyframe_insert("location", frame=f)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    return obj, frames


def evaluated(obj: bpy.types.Object, frames: np.ndarray) -> list[Matrix]:
    scene = bpy.context.scene
    out = []
    for f in frames:
        scene.frame_set(int(f))
        out.append(obj.matrix_world.copy())
    return out


def select_held_keys(obj: bpy.types.Object, held: np.ndarray) -> None:
    for fc in angvel.channels.object_fcurves(obj):
        for kp in fc.keyframe_points:
            on = fc.data_path == "rotation_quaternion" and bool(np.min(np.abs(held - kp.co[0])) < 1e-3)
            kp.select_control_point = kp.select_left_handle = kp.select_right_handle = on


def curve_points(curve_obj: bpy.types.Object) -> np.ndarray:
    pts = curve_obj.data.splines[-1].points
    co = np.empty(4 * len(pts))
    pts.foreach_get("co", co)
    return co.reshape(-1, 4)[:, :3]


def plot_sphere(sketch: np.ndarray, fit: np.ndarray, t_sketch, speed_sketch, t_fit, speed_fit, path: Path, title: str):
    fig = plt.figure(figsize=(11, 5))
    ax = fig.add_subplot(1, 2, 1, projection="3d")
    u, v = np.mgrid[0 : 2 * np.pi : 36j, 0 : np.pi : 18j]
    ax.plot_wireframe(np.cos(u) * np.sin(v), np.sin(u) * np.sin(v), np.cos(v), color="0.85", linewidth=0.4)
    s = sketch / np.linalg.norm(sketch, axis=1, keepdims=True)
    f = fit / np.linalg.norm(fit, axis=1, keepdims=True)
    ax.plot(*s.T, color="tab:blue", linewidth=2.0, label="sketch (target direction)")
    ax.plot(*f.T, color="tab:red", linewidth=1.4, label="fitted angular velocity")
    ax.view_init(elev=70, azim=-60)
    # Zoom on the cap the sketch lives on.
    ax.set_xlim(-0.55, 0.55)
    ax.set_ylim(-0.55, 0.55)
    ax.set_zlim(0.5, 1.05)
    ax.set_box_aspect((1.1, 1.1, 0.55))
    ax.set_axis_off()
    ax.legend(loc="lower left", fontsize=8)
    ax.set_title("direction on the unit sphere", fontsize=10)
    ax2 = fig.add_subplot(1, 2, 2)
    ax2.plot(t_sketch, speed_sketch, color="tab:blue", linewidth=2.0, label="sketch |omega|")
    ax2.plot(t_fit, speed_fit, color="tab:red", linewidth=1.2, label="fit |omega|")
    ax2.set_xlabel("time (s)")
    ax2.set_ylabel("rad/s")
    ax2.set_ylim(0, 1.3 * max(speed_sketch.max(), speed_fit.max()))
    ax2.legend(fontsize=8)
    ax2.set_title("magnitude over time", fontsize=10)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def plot_tip(before: list[Matrix], after: list[Matrix], path: Path):
    tip = Vector((0.0, 0.0, 1.0))
    b = np.array([tuple(m.to_3x3() @ tip) for m in before])
    a = np.array([tuple(m.to_3x3() @ tip) for m in after])
    fig = plt.figure(figsize=(5.5, 5))
    ax = fig.add_subplot(projection="3d")
    ax.plot(*b.T, color="0.55", linewidth=1.5, label="keyed (Blender's interpolation of the keys)")
    ax.plot(*a.T, color="tab:red", linewidth=1.5, label="after Fit Angular Velocity")
    ax.set_title("path of the top's axis (unit length)", fontsize=10)
    ax.view_init(elev=55, azim=-60)
    ax.legend(fontsize=8, loc="lower left")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def render_filmstrip(mesh, before: list[Matrix], after: list[Matrix], path: Path) -> None:
    scene = bpy.data.scenes.new("Filmstrip")
    spacing = 1.4
    for row, (mats, color) in enumerate(((before, (0.55, 0.6, 0.65, 1.0)), (after, (0.9, 0.25, 0.15, 1.0)))):
        for j, m in enumerate(mats):
            inst = bpy.data.objects.new(f"top {row} {j}", mesh)
            inst.matrix_world = Matrix.Translation((j * spacing, 0.0, -row * 1.8)) @ m.to_3x3().to_4x4()
            inst.color = color
            scene.collection.objects.link(inst)
    cam_data = bpy.data.cameras.new("Filmstrip")
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = spacing * len(before) + 0.6
    cam = bpy.data.objects.new("Filmstrip", cam_data)
    cam.rotation_euler = (math.radians(80), 0.0, 0.0)
    cam.location = (spacing * (len(before) - 1) / 2, -30.0, -0.4 + 30 * math.tan(math.radians(10)))
    scene.collection.objects.link(cam)
    scene.camera = cam
    world = bpy.data.worlds.new("Filmstrip")
    world.color = (1.0, 1.0, 1.0)
    scene.world = world
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x = 1600
    scene.render.resolution_y = int(1600 * 4.2 / cam_data.ortho_scale)
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.compression = 100
    scene.view_settings.view_transform = "Standard"
    shading = scene.display.shading
    shading.light = "STUDIO"
    shading.color_type = "OBJECT"
    shading.show_object_outline = True
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True, scene=scene.name)


def main() -> None:
    out = demo_common.out_dir()
    obj, key_frames = build_scene()
    frames = np.arange(key_frames[0], key_frames[-1] + 1.0)
    before = evaluated(obj, frames)
    assert bpy.ops.screwbender.add_angular_velocity_sketch() == {"FINISHED"}
    sphere = angvel.sphere_of(obj)
    sketch_obj = sphere[angvel.SKETCH_KEY]
    pts = sketch_obj.data.splines[-1].points
    n = len(pts)
    co = np.ones((n, 4))
    co[:, :3] = wobble(curve_points(sketch_obj), np.linspace(0.0, (frames[-1] - frames[0]) / FPS, n))
    pts.foreach_set("co", co.ravel())
    held = key_frames[[i for i in range(N_KEYS) if i % HOLD_EVERY == 0 or i == N_KEYS - 1]]
    select_held_keys(obj, held)
    t0 = time.perf_counter()
    with transaction.atomic() as t:
        result = angvel.fit(bpy.context, obj, t)
    elapsed = time.perf_counter() - t0
    after = evaluated(obj, frames)

    target_frames, directions, speeds = angvel.read_sketch(sphere)
    t_fit = (frames - frames[0]) / FPS
    fit_dirs = curve_points(sphere[angvel.FIT_KEY])
    target_at = np.array([np.interp(frames, target_frames, directions[:, k]) for k in range(3)]).T
    cos = np.sum(fit_dirs * target_at, axis=1) / np.linalg.norm(fit_dirs, axis=1) / np.linalg.norm(target_at, axis=1)
    off = np.degrees(np.arccos(np.clip(cos, -1, 1)))
    tip = Vector((0.0, 0.0, 1.0))
    nutation = [math.degrees((a.to_3x3() @ tip).angle(b.to_3x3() @ tip)) for a, b in zip(before, after)]
    print(f"40_angular_velocity: {N_KEYS} keys, {len(held)} held, Fit Angular Velocity in {1000 * elapsed:.1f} ms (whole operator pipeline)")
    print(
        f"  fit error {result.fit_error:.4f} (delta {result.delta:g}), {len(result.frame_times)} variable frames, "
        f"{result.iterations} iterations, status {result.status}"
    )
    print(f"  fitted omega direction vs sketch: mean {off.mean():.2f} deg, max {off.max():.2f} deg (sketch loops: {math.degrees(WOBBLE):.0f} deg)")
    print(f"  the top's axis now wobbles up to {max(nutation):.2f} deg away from the keyed precession")

    paths = [out / "angvel_sphere.png", out / "angvel_tip.png", out / "angvel_filmstrip.png"]
    plot_sphere(
        directions, fit_dirs, (target_frames - frames[0]) / FPS, speeds, t_fit, np.linalg.norm(result.omega, axis=1),
        paths[0],
        f"Spinning top: fit error {result.fit_error:.3f} (delta {result.delta:g}), "
        f"{len(result.frame_times)} variable frames, direction off by {off.mean():.1f} deg on average",
    )
    plot_tip(before, after, paths[1])
    strip = np.arange(0, len(frames), 6)
    render_filmstrip(obj.data, [before[i] for i in strip], [after[i] for i in strip], paths[2])
    for p in paths:
        print(f"40_angular_velocity: {p}")


if __name__ == "__main__":
    main()
