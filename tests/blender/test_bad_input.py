"""Bad input gets a clear report and leaves the scene as it was."""

from __future__ import annotations

import bpy
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h


def keyed(name: str = "Body", kind: str = "MESH", mode: str = "XYZ", frames=(1, 9, 24)):
    obj = h.new_object(name, kind, mode)
    poses = h.rigid(
        np.array([[0, 0, 0], [1, 1, 0], [2, 0, 1], [3, 3, 3]])[: len(frames)],
        Rotation.from_euler("xyz", [[0, 0, 0], [0.5, 0, 1], [0, 1, 2], [1, 1, 1]][: len(frames)]).as_matrix(),
    )
    h.key_poses(obj, frames, poses)
    return obj


def refuse(match: str):
    """Runs Smooth Motion on the selection: it must fail with `match` and change nothing."""
    before = h.snapshot_scene()
    with pytest.raises(RuntimeError, match=match) as error:
        bpy.ops.screwbender.smooth()
    print(f"\n{bpy.app.version_string}: {error.value}")
    assert h.snapshot_scene() == before


def test_no_animation():
    h.new_object("Still", "EMPTY")
    refuse(r"Still: no animation")


def test_single_key():
    keyed(frames=(5,))
    refuse(r"Body: only one key frame \(5\)")


def test_no_transform_channels():
    obj = h.new_object("Prop", "MESH")
    obj["weight"] = 1.0
    obj.keyframe_insert('["weight"]', frame=1)
    obj["weight"] = 2.0
    obj.keyframe_insert('["weight"]', frame=10)
    refuse(r"Prop: no keyed transform channels \(location, rotation_euler, scale\)")


def test_linked_action(tmp_path):
    obj = keyed()
    action = obj.animation_data.action
    action.name = "Shared"
    library = tmp_path / "library.blend"
    bpy.data.libraries.write(str(library), {action})
    obj.animation_data.action = None
    bpy.data.actions.remove(action)
    with bpy.data.libraries.load(str(library), link=True) as (source, target):
        target.actions = ["Shared"]
    linked = next(a for a in bpy.data.actions if a.library is not None)
    channels = h.addon_module("blender.channels")
    slot = channels.ensure_slot(linked, obj)  # its own slot "OBBody" (None on 4.2)
    channels.assign(obj, linked, slot.identifier if slot is not None else "")
    refuse(r"Body: action 'Shared' is linked from a library and cannot be edited")


def test_drivers_on_transform_channels():
    obj = keyed()
    driver = obj.driver_add("location", 1).driver
    driver.expression = "frame * 0.1"
    refuse(r"Body: drivers on location\[1\]: skipped")


def test_nla_strips():
    obj = keyed()
    action = obj.animation_data.action
    track = obj.animation_data.nla_tracks.new()
    track.strips.new("Walk", 1, action)
    refuse(r"Body: has 1 NLA strip\(s\)")


@pytest.mark.parametrize("value, shown", [(0.0, "0"), (-1.0, "-1")])
def test_zero_or_negative_scale(value, shown):
    obj = keyed()
    obj.keyframe_insert("scale", frame=1)
    obj.scale = (1.0, value, 1.0)
    obj.keyframe_insert("scale", frame=9)
    refuse(rf"Body: scale Y is {shown} at frame 9; zero or negative scale cannot be smoothed")


def test_every_problem_reported_at_once():
    h.new_object("Still", "EMPTY")
    keyed("One", frames=(3,))
    h.select_only(bpy.data.objects["Still"], bpy.data.objects["One"])
    refuse(r"(?s)One: only one key frame.*Still: no animation")


@pytest.mark.parametrize("kind", ["EMPTY", "CAMERA", "LIGHT"])
def test_any_object_type_is_valid_and_bad_ones_are_skipped(sb, kind):
    good = keyed("Good", kind, "QUATERNION")
    bad = h.new_object("Still", "MESH")
    h.select_only(good, bad)
    before = h.snapshot_scene()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert good.animation_data.action.name == "GoodAction.smooth"
    after = h.snapshot_scene()
    assert after["objects"]["Still"] == before["objects"]["Still"]
    # what was skipped is said (the operator reports it as a warning; the pipeline returns it)
    result = sb.bake.smooth([bad], sb.bake.Options())
    assert result.actions == [] and result.skipped == ["Still: no animation (no active action): skipped"]


def test_poll_explains_itself():
    h.select_only()
    with pytest.raises(RuntimeError, match="Select one or more keyed objects"):
        bpy.ops.screwbender.smooth()


def test_empty_custom_frame_range():
    keyed()
    before = h.snapshot_scene()
    with pytest.raises(RuntimeError, match=r"Body: frame range 20 to 10 is empty"):
        bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=20, frame_end=10)
    assert h.snapshot_scene() == before
