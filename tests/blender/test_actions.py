"""The source action is kept untouched, other F-curves are copied, revert and undo restore."""

from __future__ import annotations

import bpy
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h

TRANSFORM = {"location", "rotation_euler", "rotation_quaternion", "rotation_axis_angle", "scale"}


def keyed_with_extras(name: str = "Body", mode: str = "XYZ"):
    """Transform keys plus curves the add-on must copy: a custom property with a Noise
    modifier and edited handles, a delta location, and a muted curve."""
    obj = h.new_object(name, "MESH", mode)
    frames = [1, 8, 20, 31]
    poses = h.rigid(
        [[0, 0, 0], [1, 2, 0], [3, 1, 1], [4, 0, 0]],
        Rotation.from_euler("xyz", [[0, 0, 0], [0.3, 0.2, 1.0], [0.1, 0.8, 2.0], [0.0, 0.0, 3.0]]).as_matrix(),
    )
    h.key_poses(obj, frames, poses, scales=np.array([[1, 1, 1], [1.5, 1, 1], [1, 2, 1], [1, 1, 0.5]]))
    obj["weight"] = 0.0
    for frame, value in zip([1, 10, 25], [0.0, 1.0, 0.2]):
        obj["weight"] = value
        obj.keyframe_insert('["weight"]', frame=frame)
    obj.delta_location = (0, 0, 1)
    obj.keyframe_insert("delta_location", index=2, frame=5)
    obj.keyframe_insert("hide_render", frame=12)
    for fc in h.fcurves(obj):
        if fc.data_path == '["weight"]':
            fc.modifiers.new("NOISE")
            fc.keyframe_points[1].handle_left_type = "FREE"
            fc.keyframe_points[1].handle_left = (7.0, 3.0)
            fc.extrapolation = "LINEAR"
        if fc.data_path == "hide_render":
            fc.mute = True
    h.select_only(obj)
    return obj


def curves_by_path(action, obj=None) -> dict:
    snap = h.snapshot_action(action)
    out = {}
    for bag in snap["bags"]:
        for curve in bag["curves"]:
            out[curve["path"]] = curve
    return out


def test_source_kept_byte_for_byte_and_other_curves_copied(sb):
    obj = keyed_with_extras()
    source = obj.animation_data.action
    before = h.snapshot_action(source)
    assert not source.use_fake_user

    assert bpy.ops.screwbender.smooth(scheme="four_point", step=0.5) == {"FINISHED"}
    smoothed = obj.animation_data.action
    assert smoothed != source and smoothed.name == f"{source.name}.smooth"
    assert h.snapshot_action(source) == before, "the source action changed"
    assert source.use_fake_user, "the source action must be kept with a fake user"
    assert smoothed[sb.bake.SOURCE_KEY] == source

    old, new = curves_by_path(source), curves_by_path(smoothed)
    others = {path for path in old if path[0] not in TRANSFORM}
    assert others == {('["weight"]', 0), ("delta_location", 2), ("hide_render", 0)}
    for path in others:
        assert new[path] == old[path], f"{path} was not copied unchanged"
    for path in new:
        if path[0] in TRANSFORM:
            assert len(np.frombuffer(new[path]["keys"]["co"], dtype=np.float32)) == 2 * 61  # frames 1..31 by 0.5


def test_revert_restores_the_source_exactly(sb):
    obj = keyed_with_extras(mode="QUATERNION")
    source = obj.animation_data.action
    slot = sb.channels.slot_identifier(obj)
    before = h.snapshot_scene()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == source
    assert sb.channels.slot_identifier(obj) == slot
    assert h.snapshot_scene() == before  # same actions (the smoothed one removed), fake users, curves


def test_smooth_twice_then_revert_twice(sb):
    obj = keyed_with_extras()
    first = obj.animation_data.action
    first.use_fake_user = True  # an animator's own fake user is kept after revert
    assert bpy.ops.screwbender.smooth(scheme="bspline") == {"FINISHED"}
    second = obj.animation_data.action
    # Smooth Result: the result itself is smoothed again (without it the original keys are, below)
    assert bpy.ops.screwbender.smooth(scheme="jarek", levels=2, smooth_result=True) == {"FINISHED"}
    third = obj.animation_data.action
    assert len({first.name, second.name, third.name}) == 3
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == second and not second.use_fake_user
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == first and first.use_fake_user
    assert set(bpy.data.actions.keys()) == {first.name}
    with pytest.raises(RuntimeError, match="No selected object has an action made by Smooth Motion"):  # poll: nothing left to revert
        bpy.ops.screwbender.revert()


def test_undo_restores_the_scene(sb):
    keyed_with_extras()
    assert bpy.context.preferences.edit.undo_steps > 0
    bpy.ops.ed.undo_push(message="before smoothing")
    before = h.snapshot_scene()
    slot = sb.channels.slot_identifier(bpy.data.objects["Body"])
    # The second argument asks bpy.ops to push an undo step, as the UI does.
    assert bpy.ops.screwbender.smooth("EXEC_DEFAULT", True, scheme="jarek") == {"FINISHED"}
    assert h.snapshot_scene() != before
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert h.snapshot_scene() == before
    assert bpy.data.objects["Body"].animation_data.action.name == "BodyAction"
    assert sb.channels.slot_identifier(bpy.data.objects["Body"]) == slot  # "OBBody" from 4.4 on
    assert bpy.ops.ed.redo() == {"FINISHED"}
    assert bpy.data.objects["Body"].animation_data.action.name == "BodyAction.smooth"
