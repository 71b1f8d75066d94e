"""channels.py, the add-on's one place that knows each Blender's action API, under this Blender.

Runs under every bpy of the test matrix (4.2, 4.5, 5.0, 5.2). A legacy-style action is one
made through `action.fcurves` (4.2: the only kind; 4.4 and 4.5: the compatibility proxy,
which makes a slot on demand; 5.0 removed it). A slotted action is made through slots,
layers and channelbags (4.4 and later). Each test checks what channels.py reports against
what Blender itself does with the data: which curves animate the object when the scene is
evaluated, which group Blender lists them in.
"""

from __future__ import annotations

import bpy
import numpy as np
import pytest

import bake_helpers as h
from conftest import addon_module

channels = addon_module("blender.channels")
VERSION = bpy.app.version[:2]
LOCATIONS = np.array([[0.0, 0.0, 0.0], [1.0, 2.0, 0.5], [3.0, 1.0, 1.0]])
FRAMES = (1.0, 11.0, 21.0)


def test_api_facts_are_those_of_this_blender():
    """The facts channels.py reads from the RNA match the release notes of each version, and
    the call it avoids on 4.4/4.5 really fails there (the error of issue 16)."""
    assert channels.HAS_SLOTS == (VERSION >= (4, 4))
    assert channels.HAS_ACTION_FCURVES == (VERSION < (5, 0))
    assert channels.NEW_TAKES_GROUP == (VERSION >= (5, 0))
    if channels.HAS_SLOTS and not channels.NEW_TAKES_GROUP:
        action = bpy.data.actions.new("Probe")
        slot = action.slots.new(id_type="OBJECT", name="Probe")
        bag = channels.ensure_container(action, slot)
        with pytest.raises(TypeError, match="takes at most 2 arguments"):
            bag.fcurves.new("location", index=0, group_name="G")


def new_action(kind: str, obj: bpy.types.Object):
    """(action, container of `obj`'s curves) of a `kind` action, or a skip where this Blender
    cannot make one."""
    action = bpy.data.actions.new(f"{obj.name}Action")
    if kind == "legacy":
        if not channels.HAS_ACTION_FCURVES:
            pytest.skip(f"Blender {bpy.app.version_string} has no action.fcurves (removed in 5.0)")
        if not channels.HAS_SLOTS:
            assert channels.ensure_slot(action, obj) is None and channels.find_slot(action, "OBBody") is None
        return action, action  # the action is its own container (the proxy's on 4.4 and 4.5)
    if not channels.HAS_SLOTS:
        pytest.skip(f"Blender {bpy.app.version_string} has no slotted actions (4.4 and later)")
    slot = channels.ensure_slot(action, obj)
    assert channels.ensure_slot(action, obj) == slot, "a second ensure_slot made another slot"
    assert slot.identifier == f"OB{obj.name}" and slot.target_id_type == "OBJECT"
    assert channels.container(action, slot) is None, "an empty slot has no channelbag yet"
    bag = channels.ensure_container(action, slot)
    assert channels.ensure_container(action, slot) == bag
    assert channels.container(action, slot) == bag
    return action, bag


def key_location(bag, locations=LOCATIONS, frames=FRAMES) -> list[bpy.types.FCurve]:
    """Location curves (in the transform group) and a custom-property curve (group "Extra")."""
    curves = []
    for index in range(3):
        fcurve = channels.new_fcurve(bag, "location", index)
        for frame, value in zip(frames, locations[:, index]):
            fcurve.keyframe_points.insert(frame, float(value))
        curves.append(fcurve)
    extra = channels.new_fcurve(bag, '["weight"]', 0, group="Extra")
    extra.keyframe_points.insert(1.0, 0.25)
    return curves + [extra]


@pytest.mark.parametrize("kind", ["legacy", "slotted"])
def test_curves_in_groups_found_back_and_animating(kind):
    obj = h.new_object("Body", "EMPTY")
    obj["weight"] = 0.0
    action, bag = new_action(kind, obj)
    made = key_location(bag)

    # Found back through the container, by path and index, with their groups.
    assert channels.fcurves(bag) == made
    for index in range(3):
        assert channels.find_fcurve(bag, "location", index) == made[index]
        assert made[index].group.name == channels.TRANSFORM_GROUP
    assert channels.find_fcurve(bag, "location", 3) is None
    assert channels.find_fcurve(bag, '["weight"]') == made[3] and made[3].group.name == "Extra"
    assert channels.groups(bag) == [channels.TRANSFORM_GROUP, "Extra"]
    group = bag.groups[channels.TRANSFORM_GROUP]
    assert [(c.data_path, c.array_index) for c in group.channels] == [("location", i) for i in range(3)]

    # Assigned: the object's curves are these, and Blender evaluates them onto the object.
    # The slot: none on 4.2, "OBBody" when made through channels.py, and the proxy's own
    # "XXLegacy Slot" (unknown ID type until assigned, then "OBLegacy Slot") on 4.4 and 4.5.
    (identifier, _), = channels.containers(action)
    expected = {("legacy", False): "", ("legacy", True): "XXLegacy Slot", ("slotted", True): "OBBody"}
    assert identifier == expected[kind, channels.HAS_SLOTS]
    channels.assign(obj, action, identifier)
    assert obj.animation_data.action == action
    assert channels.slot_identifier(obj) == identifier.replace("XX", "OB", 1)
    assert channels.object_fcurves(obj) == made
    assert [slot for slot, _ in channels.containers(action)] == [channels.slot_identifier(obj)]
    for frame, location in zip(FRAMES, LOCATIONS):
        bpy.context.scene.frame_set(int(frame))
        np.testing.assert_allclose(obj.location, location, atol=1e-6)
    assert obj["weight"] == pytest.approx(0.25)

    channels.remove_fcurve(bag, made[1])
    assert channels.find_fcurve(bag, "location", 1) is None
    assert len(channels.object_fcurves(obj)) == 3


def test_two_slots_animate_two_objects_apart():
    """One slotted action, a slot per object: each object sees and plays only its own curves."""
    if not channels.HAS_SLOTS:
        pytest.skip(f"Blender {bpy.app.version_string} has no slotted actions (4.4 and later)")
    first, second = h.new_object("First", "EMPTY"), h.new_object("Second", "EMPTY")
    action = bpy.data.actions.new("Shared")
    for obj in (first, second):
        obj["weight"] = 0.0
    slots = [channels.ensure_slot(action, obj) for obj in (first, second)]
    assert [s.identifier for s in slots] == ["OBFirst", "OBSecond"]
    curves = [key_location(channels.ensure_container(action, slot), LOCATIONS * (k + 1)) for k, slot in enumerate(slots)]
    for obj, slot in zip((first, second), slots):
        channels.assign(obj, action, slot.identifier)
    assert [s for s, _ in channels.containers(action)] == ["OBFirst", "OBSecond"]
    assert channels.object_fcurves(first) == curves[0] and channels.object_fcurves(second) == curves[1]
    bpy.context.scene.frame_set(21)
    np.testing.assert_allclose(first.location, LOCATIONS[2], atol=1e-6)
    np.testing.assert_allclose(second.location, 2 * LOCATIONS[2], atol=1e-6)
    # Switching the slot switches what the object plays.
    channels.assign(first, action, "OBSecond")
    assert channels.slot_identifier(first) == "OBSecond" and channels.object_fcurves(first) == curves[1]
    assert channels.find_slot(action, "OBNobody") is None


@pytest.mark.parametrize("kind", ["legacy", "slotted"])
def test_smooth_and_revert_on_an_action_made_through_channels(kind):
    """Smooth Motion bakes into the object's own container, transform curves in Blender's
    transform group, the custom-property curve copied; Revert gives the action back."""
    obj = h.new_object("Body", "EMPTY")
    obj["weight"] = 0.0
    action, bag = new_action(kind, obj)
    key_location(bag)
    rotation = [channels.new_fcurve(bag, "rotation_euler", i) for i in range(3)]
    for i, fcurve in enumerate(rotation):
        for frame, angle in zip(FRAMES, (0.0, 0.4, 1.1)):
            fcurve.keyframe_points.insert(frame, angle * (i + 1))
    channels.assign(obj, action, channels.containers(action)[0][0])
    identifier = channels.slot_identifier(obj)
    h.select_only(obj)
    before = h.snapshot_action(action)

    assert bpy.ops.screwbender.smooth(step=1.0) == {"FINISHED"}
    smoothed = obj.animation_data.action
    smoothed_name = smoothed.name
    assert smoothed != action and channels.slot_identifier(obj) == identifier
    assert h.snapshot_action(action) == before
    curves = channels.object_fcurves(obj)
    baked = [fc for fc in curves if fc.data_path in ("location", "rotation_euler")]
    assert len(baked) == 6 and all(len(fc.keyframe_points) == 21 for fc in baked)
    assert all(fc.group is not None and fc.group.name == channels.TRANSFORM_GROUP for fc in baked)
    weight = [fc for fc in curves if fc.data_path == '["weight"]']
    assert len(weight) == 1 and weight[0].group.name == "Extra"
    bpy.context.scene.frame_set(21)
    np.testing.assert_allclose(obj.location, LOCATIONS[2], atol=1e-5)  # keys are hit

    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == action and channels.slot_identifier(obj) == identifier
    assert smoothed_name not in bpy.data.actions
    assert h.snapshot_action(action) == before


def test_smoothing_one_slot_leaves_the_other_slot_alone():
    if not channels.HAS_SLOTS:
        pytest.skip(f"Blender {bpy.app.version_string} has no slotted actions (4.4 and later)")
    first, second = h.new_object("First", "EMPTY"), h.new_object("Second", "EMPTY")
    action = bpy.data.actions.new("Shared")
    for obj in (first, second):
        obj["weight"] = 0.0
        slot = channels.ensure_slot(action, obj)
        key_location(channels.ensure_container(action, slot))
        channels.assign(obj, action, slot.identifier)
    before = h.snapshot_action(action)
    h.select_only(first)
    assert bpy.ops.screwbender.smooth(step=0.5) == {"FINISHED"}
    smoothed = first.animation_data.action
    assert second.animation_data.action == action and h.snapshot_action(action) == before
    assert channels.slot_identifier(first) == "OBFirst"
    by_slot = {slot: channels.fcurves(bag) for slot, bag in channels.containers(smoothed)}
    assert set(by_slot) == {"OBFirst", "OBSecond"}  # the copy keeps both slots
    dense = [len(fc.keyframe_points) for fc in by_slot["OBFirst"] if fc.data_path == "location"]
    kept = [len(fc.keyframe_points) for fc in by_slot["OBSecond"] if fc.data_path == "location"]
    assert dense == [41, 41, 41] and kept == [3, 3, 3]


def test_ensure_container_needs_a_slot_on_a_slotted_action():
    if not channels.HAS_SLOTS:
        pytest.skip(f"Blender {bpy.app.version_string} has no slotted actions (4.4 and later)")
    action = bpy.data.actions.new("NoSlot")
    with pytest.raises(ValueError, match="needs a slot"):
        channels.ensure_container(action, None)
    assert channels.container(action, None) is None and channels.containers(action) == []
