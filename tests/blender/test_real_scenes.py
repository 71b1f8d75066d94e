"""Objects as animators have them: subframe keys at 23.976 fps, mirrored objects, linked
duplicates sharing one action, smoothing a result again, many objects at once, and bakes too
big to write."""

from __future__ import annotations

import bpy
import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h
from conftest import addon_module

FRAMES = [1.5, 4.25, 9.0, 13.7, 20.6]


def poses(n: int = len(FRAMES), seed: int = 3) -> np.ndarray:
    rng = np.random.default_rng(seed)
    rot = Rotation.from_rotvec(np.cumsum(rng.normal(0, 0.5, (n, 3)), axis=0))
    return h.rigid(rng.uniform(-2, 2, (n, 3)), rot.as_matrix())


def keyed(name="Body", mode="XYZ", frames=FRAMES, scale=None, seed=3):
    obj = h.new_object(name, "MESH", mode)
    h.key_poses(obj, frames, poses(len(frames), seed), scale)
    h.select_only(obj)
    return obj


def baked_frames(obj) -> np.ndarray:
    frames, _ = h.channel(obj, "location", 3)
    return frames


@pytest.mark.parametrize("step", [0.1, 0.2, 0.5, 1.0])
def test_subframe_keys_at_23_976_fps_bake_on_the_grid(sb, step):
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = 24, 1.001
    obj = keyed()
    assert bpy.ops.screwbender.smooth(step=step, scheme="four_point") == {"FINISHED"}
    frames = baked_frames(obj)
    # the first and last key exactly (as float32, the way Blender stores key frames)
    assert frames[0] == np.float32(FRAMES[0]) and frames[-1] == np.float32(FRAMES[-1])
    inner = frames[1:-1]
    # issue 24: every key frame is a baked frame too; the other frames are on the grid
    is_key = np.array([np.min(np.abs(np.float32(FRAMES) - f)) == 0 for f in inner])
    on_grid = np.abs(inner[~is_key] - np.round(inner[~is_key] / step) * step)
    print(f"step {step}: {len(frames)} keys, {frames[:3]} ... {frames[-3:]}, largest grid offset {on_grid.max():.1e}")
    assert on_grid.max() <= 4 * np.finfo(np.float32).eps * np.abs(inner).max()
    assert np.all(np.diff(frames) > 0)
    on_grid_keys = sum(1 for f in FRAMES[1:-1] if abs(f / step - round(f / step)) < 1e-4 / step)
    expected = int(np.floor((FRAMES[-1] - 1e-4) / step) - np.ceil((FRAMES[0] + 1e-4) / step) + 1) + 2
    assert len(frames) == expected + len(FRAMES) - 2 - on_grid_keys
    assert is_key.sum() == len(FRAMES) - 2
    # and the smoothed motion passes through the first and last key pose there
    _, baked = h.baked_matrices(obj)
    keys = poses()
    assert np.abs(baked[0] - keys[0]).max() < 1e-5 and np.abs(baked[-1] - keys[-1]).max() < 1e-5


def test_step_not_dividing_the_range_reaches_the_last_key(sb):
    obj = keyed(frames=[1, 10, 20, 30])
    assert bpy.ops.screwbender.smooth(step=0.1) == {"FINISHED"}
    frames = baked_frames(obj)
    assert frames[-1] == 30.0 and frames[-2] == np.float32(29.9) and len(frames) == 291


def test_too_many_keys_are_refused_before_anything_is_done(sb):
    obj = keyed(frames=[1, 50_000, 100_000])
    before = h.snapshot_data()
    with pytest.raises(RuntimeError, match=r"Body: baking frames 1 to 100000 every 0.01 frames would write "
                       r"59,999,41\d keys; one Smooth Motion writes at most 20,000,000 .*raise Step"):
        bpy.ops.screwbender.smooth(step=0.01)
    assert h.snapshot_data() == before
    assert obj.animation_data.action.name == "BodyAction"


def test_mirrored_object_is_smoothed(sb):
    obj = keyed(mode="QUATERNION")
    obj.scale = (-1.0, 1.0, 1.0)  # mirrored, scale not keyed
    motion = sb.keys.read(obj)
    assert bpy.ops.screwbender.smooth(scheme="four_point", timing="smooth") == {"FINISHED"}
    paths = {fc.data_path for fc in h.fcurves(obj)}
    assert "scale" not in paths  # unkeyed scale stays unkeyed
    assert tuple(obj.scale) == (-1.0, 1.0, 1.0)
    frames, baked = h.baked_matrices(obj)
    expected = polyscrew.sample(motion.poses, motion.frames, frames, scheme="four_point")
    assert np.abs(baked - expected).max() < 1e-5
    # Blender plays the mirrored object along the smoothed motion
    basis = h.evaluated_basis(obj, frames[::7])
    mirrored = expected[::7] @ np.diag([-1.0, 1.0, 1.0, 1.0])
    assert np.abs(basis - mirrored).max() < 1e-5


def test_mirrored_object_with_one_scale_axis_keyed(sb):
    obj = keyed(scale=np.array([[-1, 1, 1], [-1, 2, 1], [-1, 1.5, 1], [-1, 1, 1], [-1, 3, 1]], dtype=float))
    channels = addon_module("blender.channels")
    bag = channels.container(obj.animation_data.action, channels.assigned_slot(obj))
    for index in (0, 2):
        channels.remove_fcurve_at(bag, "scale", index)
    obj.scale = (-1.0, 1.0, 1.0)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    scale_curves = sorted(fc.array_index for fc in h.fcurves(obj) if fc.data_path == "scale")
    assert scale_curves == [1]
    assert obj.scale[0] == -1.0


def test_negative_keyed_scale_is_refused_with_the_reason(sb):
    keyed(scale=np.array([[1, 1, 1], [1, 1, 1], [1, -1, 1], [1, 1, 1], [1, 1, 1]], dtype=float))
    with pytest.raises(RuntimeError, match=r"scale Y is -1 at frame 9; zero or negative scale cannot be "
                       r"smoothed when it is keyed \(a static negative scale, a mirrored object, can\)"):
        bpy.ops.screwbender.smooth()


def linked_duplicate(obj, name, location=None):
    dup = obj.copy()  # shares the mesh and the action, as Alt+D does
    dup.name = name
    bpy.context.scene.collection.objects.link(dup)
    if location is not None:
        dup.location = location
    return dup


def test_linked_duplicates_keep_sharing_one_action(sb):
    obj = keyed("Wheel")
    dups = [linked_duplicate(obj, f"Wheel.{i}") for i in range(1, 3)]
    source = obj.animation_data.action
    assert all(d.animation_data.action == source for d in dups)
    h.select_only(obj, *dups)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    smoothed = obj.animation_data.action
    assert smoothed != source and all(d.animation_data.action == smoothed for d in dups)
    assert [a.name for a in bpy.data.actions if a.get("screwbender_source")] == [smoothed.name]
    # one Revert (on one of them) reverts them together
    name = smoothed.name
    h.select_only(dups[0])
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert all(o.animation_data.action == source for o in (obj, *dups))
    assert name not in bpy.data.actions


def test_linked_duplicates_that_differ_in_unkeyed_channels_are_split_and_told(sb, capfd):
    obj = h.new_object("Spinner", "MESH", "XYZ")
    for frame, z in ((1, 0.0), (10, 1.0), (20, 2.5)):
        obj.rotation_euler = (0.0, 0.3 * z, z)
        obj.keyframe_insert("rotation_euler", frame=frame)  # location not keyed
    dup = linked_duplicate(obj, "Spinner.001", location=(5.0, 0.0, 0.0))
    h.select_only(obj, dup)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert obj.animation_data.action != dup.animation_data.action
    assert "share action 'SpinnerAction' but differ in unkeyed channels" in capfd.readouterr().out
    assert tuple(dup.location) == (5.0, 0.0, 0.0)


def test_smoothing_a_result_again_smooths_the_original_keys(sb):
    obj = keyed(mode="QUATERNION")
    original = obj.animation_data.action
    motion = sb.keys.read(obj)
    assert bpy.ops.screwbender.smooth(scheme="bspline") == {"FINISHED"}
    first = obj.animation_data.action
    first["note"] = "edited after smoothing"  # the animator's own data on the result survives
    assert bpy.ops.screwbender.smooth(scheme="four_point", levels=3, timing="smooth") == {"FINISHED"}
    second = obj.animation_data.action
    assert second.name == f"{original.name}.smooth" and second.get("note") == "edited after smoothing"
    assert [a.name for a in bpy.data.actions] == sorted([original.name, second.name])
    frames, baked = h.baked_matrices(obj)
    expected = polyscrew.sample(motion.poses, motion.frames, frames, scheme="four_point", levels=3, timing="smooth")
    assert np.abs(baked - expected).max() < 1e-5  # the original keys, not the B-spline result
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == original


def test_many_objects_are_reported_in_one_line(sb, capfd):
    objects = [keyed(f"Prop.{i:03d}", seed=i) for i in range(12)]
    h.select_only(*objects)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    lines = [line for line in capfd.readouterr().out.splitlines() if line.startswith("Info: Smoothed")]
    assert lines == ["Info: Smoothed 12 object(s): Prop.000, Prop.001, Prop.002 and 9 more"]


def test_a_linked_duplicate_smoothed_alone_keeps_sharing(sb):
    obj = keyed("Rotor")
    dup = linked_duplicate(obj, "Rotor.001")
    h.select_only(obj)  # only one of them selected
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert dup.animation_data.action == obj.animation_data.action  # still shared
