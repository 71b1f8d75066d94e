"""Smooth Motion at its edges: re-smoothing shared results that split, owners whose curves
polyscrew refuses, curves the bake must leave alone (muted, keyless), cycles with holds whose
unkeyed channels move, an unkeyed scale axis at zero, and commit actions that fail."""

from __future__ import annotations

import bpy
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h
from conftest import addon_module


def keyed(name: str, offset: float = 0.0, mode: str = "XYZ", scale: bool = False):
    """An object keyed on location and rotation (and all scale axes with `scale`) at 4 frames."""
    obj = h.new_object(name, "MESH", mode)
    frames = [1, 9, 17, 30]
    rot = Rotation.from_euler("xyz", [[0, 0, 0], [0.4, 0.1, 1.0], [0.2, 0.7, 2.0], [0.1, 0.1, 2.8]])
    poses = h.rigid(np.array([[0, 0, 0], [1, 2, 0], [3, 1, 1], [4, 0, 0]], dtype=float) + offset, rot.as_matrix())
    scales = np.array([[1, 1, 1], [1.5, 1, 1], [1, 2, 1], [1, 1, 0.5]], dtype=float) if scale else None
    h.key_poses(obj, frames, poses, scales)
    return obj


def linked_duplicate(obj, name: str):
    dup = obj.copy()  # shares the mesh and the action, as Alt+D does
    dup.name = name
    bpy.context.scene.collection.objects.link(dup)
    return dup


def curve(obj, path: str, index: int):
    found = [fc for fc in h.fcurves(obj) if fc.data_path == path and fc.array_index == index]
    assert len(found) <= 1, f"{obj.name}: {len(found)} curves {path}[{index}]"
    return found[0] if found else None


def reports(capfd) -> list[str]:
    return [line for line in capfd.readouterr().out.splitlines() if line.split(":")[0] in ("Info", "Warning", "Error")]


# 1. Objects sharing one earlier result that now get separate new results -----------------


def test_resmoothing_a_shared_result_that_splits_replaces_it_once(sb, capfd):
    obj = keyed("Wheel")
    dup = linked_duplicate(obj, "Wheel.001")
    original = obj.animation_data.action
    h.select_only(obj, dup)
    assert bpy.ops.screwbender.smooth(scheme="bspline") == {"FINISHED"}
    earlier = obj.animation_data.action
    assert dup.animation_data.action == earlier and earlier != original
    earlier_name = earlier.name

    dup.scale = (2.0, 2.0, 2.0)  # an unkeyed channel differs now: they get one result each
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(scheme="four_point", levels=3) == {"FINISHED"}
    out = reports(capfd)
    assert any("differ in unkeyed channels" in line for line in out), out
    assert not any(line.startswith("Error") for line in out), out

    mine, theirs = obj.animation_data.action, dup.animation_data.action
    assert mine != theirs
    # the earlier result is gone, once; the original stays; no other action is left over
    assert sorted(a.name for a in bpy.data.actions) == sorted([original.name, mine.name, theirs.name])
    assert mine.name == earlier_name == f"{original.name}.smooth"  # the earlier result's name went to a new one
    for action in (mine, theirs):
        assert action["screwbender_source"] == original and action.users == 1
    assert original.use_fake_user
    # each result is the original keys smoothed with the new options, for its own object
    options = sb.bake.Options(scheme="four_point", levels=3)
    for o in (obj, dup):
        motion = sb.keys.read(o, action=original, slot=sb.channels.slot_identifier(o))
        frames, baked = h.baked_matrices(o)
        expected = sb.bake.sample_poses(motion, frames, options, o)[0]
        assert np.abs(baked - expected).max() < 1e-5, o.name
    assert tuple(dup.scale) == (2.0, 2.0, 2.0)
    # one Revert each gives the original back and removes the results
    h.select_only(obj, dup)
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == original and dup.animation_data.action == original
    assert [a.name for a in bpy.data.actions] == [original.name]


def test_a_commit_action_that_fails_does_not_stop_the_others_and_is_reported():
    transaction = addon_module("blender.transaction")
    ran = []

    def broken():
        ran.append("broken")
        raise ReferenceError("StructRNA of type Action has been removed")

    action = bpy.data.actions.new("Kept")
    with pytest.raises(transaction.CommitIncomplete, match=r"has been removed") as error:
        with transaction.atomic() as t:
            t.set(action, "use_fake_user", True)
            t.on_commit(broken)
            t.on_commit(lambda: ran.append("after"))
    assert ran == ["broken", "after"]  # every commit action ran
    assert action.use_fake_user  # the changes stay: they were done, nothing rolled back

    class Operator:
        def __init__(self):
            self.reported = []

        def report(self, level, message):
            self.reported.append((level, message))

    op = Operator()
    result = transaction.report_failure(op, error.value, "Smooth Motion")
    assert result == {"FINISHED"}  # the change is made: Blender records it for Undo
    (level, message), = op.reported
    assert level == {"ERROR"}
    assert "nothing was changed" not in message and "the changes were made" in message


def test_a_commit_action_registered_once_per_key_runs_once():
    transaction = addon_module("blender.transaction")
    ran = []
    with transaction.atomic() as t:
        with transaction.atomic(t) as inner:
            inner.on_commit(lambda: ran.append(1), key=("remove", 7))
        t.on_commit(lambda: ran.append(2), key=("remove", 7))
        t.on_commit(lambda: ran.append(3), key=("remove", 8))
    assert ran == [1, 3]


# 2. Curves polyscrew refuses: that owner is skipped and told, the others smoothed --------


@pytest.mark.parametrize("where", ["handle", "key", "order"])
def test_an_owner_whose_curves_polyscrew_refuses_is_skipped_and_the_others_smoothed(sb, capfd, where):
    good, bad = keyed("Good"), keyed("Bad", offset=1.0)
    bad_action = bad.animation_data.action
    fc = curve(bad, "location", 0)
    points = fc.keyframe_points
    if where == "handle":
        points[1].handle_right = (points[1].co[0] + 2.0, float("nan"))
    elif where == "key":
        points[2].co = (points[2].co[0], float("nan"))
    else:  # keys out of order (set through keyframe_points, no update)
        points[1].co = (25.0, points[1].co[1])
    h.select_only(good, bad)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    out = reports(capfd)
    warnings = [line for line in out if line.startswith("Warning")]
    assert len(warnings) == 1 and warnings[0].startswith("Warning: Bad: ") and "skipped" in warnings[0], out
    assert any(line.startswith("Info: Smoothed 1 object(s): Good") for line in out), out
    assert bad.animation_data.action == bad_action  # unchanged
    assert good.animation_data.action.get("screwbender_source") is not None


# 3. Curves the bake does not write survive it --------------------------------------------


def test_muted_and_keyless_curves_the_bake_does_not_write_survive(sb, capfd):
    obj = keyed("Box", scale=True)
    action = obj.animation_data.action
    bag = sb.channels.container(action, sb.channels.assigned_slot(obj))
    muted_scale = curve(obj, "scale", 2)
    muted_scale.keyframe_points[1].co = (9.0, 3.0)
    muted_scale.mute = True  # the animator switched it off but keeps it
    keys_before = h.curve_points(muted_scale)
    muted_location = curve(obj, "location", 1)
    muted_location.mute = True
    # a keyless curve of a scale axis (a curve made ready for keys, e.g. by a script)
    sb.channels.remove_fcurve_at(bag, "scale", 1)
    obj.scale[1] = 1.25
    sb.channels.new_fcurve(bag, "scale", 1, "Object Transforms")
    h.select_only(obj)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    out = reports(capfd)
    result = obj.animation_data.action
    assert result != action
    kept = curve(obj, "scale", 2)
    assert kept is not None and kept.mute
    np.testing.assert_array_equal(h.curve_points(kept), keys_before)
    keyless = curve(obj, "scale", 1)
    assert keyless is not None and len(keyless.keyframe_points) == 0
    baked_x = curve(obj, "scale", 0)
    assert baked_x is not None and len(baked_x.keyframe_points) == 30 and not baked_x.mute
    # location is baked on every axis: the muted location Y curve had to give way, and that is told
    location_y = curve(obj, "location", 1)
    assert not location_y.mute and len(location_y.keyframe_points) == 30
    assert any("Box: muted curve location[1] replaced by the baked one" in line for line in out), out
    # the source keeps all of it
    assert curve_in(action, obj, "location", 1).mute and curve_in(action, obj, "scale", 2).mute


def curve_in(action, obj, path, index):
    channels = addon_module("blender.channels")
    return next(
        fc for fc in channels.action_fcurves(action, channels.slot_identifier(obj))
        if fc.data_path == path and fc.array_index == index
    )


# 4. A cycle with holds: every baked channel cycles ---------------------------------------


def test_a_cycle_with_a_hold_cycles_every_baked_channel(sb):
    obj = h.new_object("Turner", "MESH", "XYZ")
    keys = [(1, 0.0, 0.0), (10, 2.0, 1.5), (20, 2.0, 1.5), (30, 0.0, 0.0)]  # hold 10..20, closes at 30
    for frame, x, z in keys:
        obj.location = (x, 0.0, 0.2 * x)
        obj.rotation_euler = (0.0, 0.0, z)
        obj.keyframe_insert("location", index=0, frame=frame)  # location Y is not keyed
        obj.keyframe_insert("location", index=2, frame=frame)
        obj.keyframe_insert("rotation_euler", frame=frame)
    for fc in h.fcurves(obj):
        fc.modifiers.new("CYCLES")
    h.select_only(obj)
    motion = sb.keys.read(obj)
    assert motion.held is not None and motion.held.any()  # the hold is found
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}

    baked = [fc for fc in h.fcurves(obj) if fc.data_path in ("location", "rotation_euler")]
    assert sorted((fc.data_path, fc.array_index) for fc in baked) == [
        ("location", 0), ("location", 1), ("location", 2),
        ("rotation_euler", 0), ("rotation_euler", 1), ("rotation_euler", 2),
    ]
    y = curve(obj, "location", 1)
    first = np.arange(1.0, 30.0, 0.5)
    assert np.ptp([y.evaluate(f) for f in first]) > 0.05  # the screw path moves the unkeyed Y
    for fc in baked:
        assert [m.type for m in fc.modifiers] == ["CYCLES"], (fc.data_path, fc.array_index)
        now = np.array([fc.evaluate(f) for f in first])
        later = np.array([fc.evaluate(f + 29.0) for f in first])
        np.testing.assert_allclose(later, now, atol=1e-5, err_msg=f"{fc.data_path}[{fc.array_index}]")
    # and Blender plays it so: one period later the object is where it was
    np.testing.assert_allclose(h.evaluated_basis(obj, first + 29.0), h.evaluated_basis(obj, first), atol=1e-5)


# 5. An unkeyed scale axis at zero ---------------------------------------------------------


def test_an_unkeyed_scale_axis_at_zero_does_not_stop_smoothing(sb):
    obj = keyed("Flat", scale=True)
    bag = sb.channels.container(obj.animation_data.action, sb.channels.assigned_slot(obj))
    sb.channels.remove_fcurve_at(bag, "scale", 2)
    obj.scale[2] = 0.0  # flattened, not keyed
    motion = sb.keys.read(obj)
    assert bpy.ops.screwbender.smooth(timing="smooth") == {"FINISHED"}
    assert curve(obj, "scale", 2) is None and obj.scale[2] == 0.0
    keyed_axes = np.stack([h.curve_points(curve(obj, "scale", i))[:, 1] for i in (0, 1)], axis=1)
    assert np.all(np.isfinite(keyed_axes)) and np.all(keyed_axes > 0.0)
    # the keyed axes are the same as with any other unkeyed scale (timing "smooth": the pace
    # of timing "keys" depends on the body's size, which a zero scale changes)
    obj_ref = keyed("Reference", scale=True)
    bag_ref = sb.channels.container(obj_ref.animation_data.action, sb.channels.assigned_slot(obj_ref))
    sb.channels.remove_fcurve_at(bag_ref, "scale", 2)
    reference = sb.bake.sample_channels(obj_ref, sb.keys.read(obj_ref), sb.bake.Options(timing="smooth"))
    np.testing.assert_allclose(keyed_axes, reference.values["scale"], atol=1e-6)
    assert motion.scale_axes.tolist() == [True, True, False]
