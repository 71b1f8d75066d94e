"""Angular-velocity editing in Blender (Xie et al. 2011): the sketch helpers, Fit Angular
Velocity on the paper's spinning top, location untouched, selected keys held, clean refusal.

Orientations and angular velocities are checked with scipy (test-only), independently of
the add-on's numpy conversions."""

from __future__ import annotations

import bpy
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from bake_helpers import curve_points, fcurves, key_poses, new_object, rigid, select_only
from conftest import addon_module
from spinning_top import top_omega, top_rotation, top_target

FPS = 24
N_KEYS = 20
LAST = 96.0  # keys every 5 frames, 1..96 (3.96 s at 24 fps)


def angles_deg(a, b):
    cos = np.sum(a * b, axis=1) / np.linalg.norm(a, axis=1) / np.linalg.norm(b, axis=1)
    return np.degrees(np.arccos(np.clip(cos, -1, 1)))


@pytest.fixture
def top():
    """A keyed spinning top: 20 quaternion keys every 5 frames from frame 1, sliding along x."""
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = FPS, 1.0
    obj = new_object("Top", mode="QUATERNION")
    frames = 1.0 + 5.0 * np.arange(N_KEYS)
    t = (frames - 1.0) / FPS
    location = np.stack([0.5 * t, np.sin(t), 0.0 * t], axis=1)
    key_poses(obj, frames, rigid(location, top_rotation(t).as_matrix()))
    select_only(obj)
    bpy.context.view_layer.objects.active = obj
    return obj, frames


def snapshot(obj, path):
    out = {}
    for fc in fcurves(obj):
        if fc.data_path == path:
            kp = fc.keyframe_points
            data = {}
            for attr in ("co", "handle_left", "handle_right"):
                a = np.empty(2 * len(kp), dtype=np.float32)
                kp.foreach_get(attr, a)
                data[attr] = a.tobytes()
            out[fc.array_index] = data
    return out


def select_rotation_keys(obj, chosen_frames):
    select_rotation_keys_path(obj, chosen_frames, "rotation_quaternion")


def select_rotation_keys_path(obj, chosen_frames, path):
    for fc in fcurves(obj):
        for kp in fc.keyframe_points:
            selected = fc.data_path == path and np.min(np.abs(chosen_frames - kp.co[0])) < 1e-3
            kp.select_control_point = kp.select_left_handle = kp.select_right_handle = bool(selected)


def test_sketch_starts_as_the_current_angular_velocity(top):
    obj, frames = top
    assert bpy.ops.screwbender.add_angular_velocity_sketch() == {"FINISHED"}
    av = addon_module("blender.angvel")
    sphere = av.sphere_of(obj)
    assert sphere is not None and sphere.type == "MESH"
    target_frames, directions, speeds = av.read_sketch(sphere)
    assert len(target_frames) == int(LAST)  # one point per frame 1..96
    t = (target_frames - 1.0) / FPS
    off = angles_deg(directions, top_omega(t))
    rel = np.abs(speeds - np.linalg.norm(top_omega(t), axis=1)) / np.linalg.norm(top_omega(t), axis=1)
    print(f"sketch from the keyed motion: direction off by mean {off.mean():.2f} deg, speed by mean {100 * rel.mean():.2f} %")
    assert np.median(off) < 3.0
    assert np.median(rel) < 0.03


def test_fit_follows_the_sketch_keeps_selected_keys_and_location(top):
    obj, frames = top
    assert bpy.ops.screwbender.add_angular_velocity_sketch() == {"FINISHED"}
    av = addon_module("blender.angvel")
    sphere = av.sphere_of(obj)
    sketch = sphere[av.SKETCH_KEY]
    # The user's wobble pattern on the direction curve (points stay on the unit sphere).
    n = len(sketch.data.splines[-1].points)
    t = np.linspace(0.0, (LAST - 1.0) / FPS, n)
    d = top_target(t)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    co = np.ones((n, 4))
    co[:, :3] = d
    sketch.data.splines[-1].points.foreach_set("co", co.ravel())
    source = obj.animation_data.action
    location_before = snapshot(obj, "location")
    keys_before = {i: curve_points(fc) for fc in fcurves(obj) if fc.data_path == "rotation_quaternion" for i in [fc.array_index]}
    held = frames[[i for i in range(N_KEYS) if i % 3 == 0 or i == N_KEYS - 1]]
    select_rotation_keys(obj, held)

    assert bpy.ops.screwbender.fit_angular_velocity() == {"FINISHED"}
    assert obj.animation_data.action is not source
    # Location curves: byte for byte.
    assert snapshot(obj, "location") == location_before
    # Baked rotation: one key per frame.
    rot = {fc.array_index: curve_points(fc) for fc in fcurves(obj) if fc.data_path == "rotation_quaternion"}
    baked_frames = rot[0][:, 0]
    q = np.stack([rot[i][:, 1] for i in range(4)], axis=1)
    np.testing.assert_allclose(baked_frames, np.arange(1.0, LAST + 1.0))
    original = np.stack([keys_before[i][:, 1] for i in range(4)], axis=1)
    moved = (Rotation.from_quat(q[np.round(frames - 1).astype(int)][:, [1, 2, 3, 0]]) * Rotation.from_quat(original[:, [1, 2, 3, 0]]).inv()).magnitude()
    is_held = np.isin(frames, held)
    print(f"held keys moved at most {moved[is_held].max():.1e} rad (float32 curves); free keys {moved[~is_held].min():.3f}..{moved[~is_held].max():.3f} rad")
    assert moved[is_held].max() < 1e-6
    assert (moved[~is_held] > 1e-3).all()
    # Angular velocity of the baked keys (scipy, central differences) against the sketch.
    r = Rotation.from_quat(q[:, [1, 2, 3, 0]])
    omega = (r[2:] * r[:-2].inv()).as_rotvec() / (2.0 / FPS)
    mid_t = (baked_frames[1:-1] - 1.0) / FPS
    off = angles_deg(omega, top_target(mid_t))
    base = angles_deg(top_omega(mid_t), top_target(mid_t))
    print(f"baked rotation vs sketch: direction off by mean {off.mean():.2f} deg, max {off.max():.2f} deg (unedited motion: {base.mean():.2f} deg)")
    assert off.mean() < 3.0
    # The fit is drawn on the sphere in red, one point per baked frame.
    fit_curve = sphere[av.FIT_KEY]
    assert len(fit_curve.data.splines[-1].points) == len(baked_frames)
    # Revert restores the original action.
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == source


def test_infeasible_sketch_is_refused_and_nothing_changes(top):
    obj, frames = top
    assert bpy.ops.screwbender.add_angular_velocity_sketch() == {"FINISHED"}
    av = addon_module("blender.angvel")
    sphere = av.sphere_of(obj)
    # A sketch spinning the other way round, every key held, no variable frames.
    sketch = sphere[av.SKETCH_KEY]
    pts = sketch.data.splines[-1].points
    co = np.empty(4 * len(pts))
    pts.foreach_get("co", co)
    co = co.reshape(-1, 4)
    co[:, :3] *= -1.0
    pts.foreach_set("co", co.ravel())
    select_rotation_keys(obj, frames)
    source = obj.animation_data.action
    before = snapshot(obj, "rotation_quaternion")
    with pytest.raises(RuntimeError, match="infeasible"):
        bpy.ops.screwbender.fit_angular_velocity(max_frames=0)
    assert obj.animation_data.action == source
    assert snapshot(obj, "rotation_quaternion") == before
    assert av.FIT_KEY not in sphere


def test_fit_needs_a_sketch(top):
    obj, _ = top
    assert not bpy.ops.screwbender.fit_angular_velocity.poll()


def test_drawn_bezier_stroke_timed_by_length(top):
    obj, frames = top
    assert bpy.ops.screwbender.add_angular_velocity_sketch() == {"FINISHED"}
    av = addon_module("blender.angvel")
    sphere = av.sphere_of(obj)
    sketch = sphere[av.SKETCH_KEY]
    # A hand-drawn stroke: a Bezier spline along the equator, 90 degrees then 180 more.
    spline = sketch.data.splines.new("BEZIER")
    spline.bezier_points.add(2)
    for bp, a in zip(spline.bezier_points, (0.0, np.pi / 2, 3 * np.pi / 2)):
        bp.co = (np.cos(a), np.sin(a), 0.0)
        bp.handle_left_type = bp.handle_right_type = "AUTO"
    target_frames, directions, _ = av.read_sketch(sphere, "LENGTH")
    assert target_frames[0] == 1.0 and target_frames[-1] == LAST
    assert np.all(np.diff(target_frames) > 0)
    angle = np.unwrap(np.arctan2(directions[:, 1], directions[:, 0]))
    # By length: the 90-degree part takes about a third of the range.
    at_90 = np.interp(np.pi / 2, angle, target_frames)
    assert abs((at_90 - 1.0) / (LAST - 1.0) - 1 / 3) < 0.05, at_90
    # Per point: the stroke's two segments share the range equally.
    per_point, _, _ = av.read_sketch(sphere, "POINTS")
    assert abs((np.interp(np.pi / 2, angle, per_point) - 1.0) / (LAST - 1.0) - 0.5) < 0.01


def test_euler_object_fits_and_keeps_held_keys_and_location():
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = FPS, 1.0
    obj = new_object("EulerTop", mode="XYZ")
    frames = 1.0 + 5.0 * np.arange(N_KEYS)
    t = (frames - 1.0) / FPS
    location = np.stack([t, 0 * t, 0 * t], axis=1)
    key_poses(obj, frames, rigid(location, top_rotation(t).as_matrix()))
    select_only(obj)
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.screwbender.add_angular_velocity_sketch() == {"FINISHED"}
    held = frames[::4]
    select_rotation_keys_path(obj, held, "rotation_euler")
    location_before = snapshot(obj, "location")
    assert bpy.ops.screwbender.fit_angular_velocity() == {"FINISHED"}
    assert snapshot(obj, "location") == location_before
    rot = {fc.array_index: curve_points(fc) for fc in fcurves(obj) if fc.data_path == "rotation_euler"}
    baked_frames = rot[0][:, 0]
    euler = np.stack([rot[i][:, 1] for i in range(3)], axis=1)
    idx = [int(np.argmin(np.abs(baked_frames - f))) for f in held]
    got = Rotation.from_euler("xyz", euler[idx])
    want = top_rotation((held - 1.0) / FPS)
    assert (got * want.inv()).magnitude().max() < 1e-5
    # Compatible Euler angles: no jump between baked frames.
    assert np.abs(np.diff(euler, axis=0)).max() < np.pi / 2
