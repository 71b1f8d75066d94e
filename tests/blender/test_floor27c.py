"""Issue 27, Revert and Insert Key on Motion nearer their floor: the work removed is counted
(calls wrapped in the test), and what they write is the same as before.

- Insert Key on Motion samples each owner's motion twice (before and after the new key, at
  the frames it compares), not three times: the pose it keys is the one sampled before at
  its frame (which is among those frames), bit for bit the pose sampled at that frame alone.
- Revert reads each result's facts once per run: one pass over the selection for the
  actions, their slots and originals (on 148afe3: `bake.source_of` twice per object).
- Reduce Keys lists the scene's objects once for all the actions it replaces (on 148afe3:
  once per action, `bake.users_of`: a run that grew as actions x objects).

Counted or compared, not timed (speed: scripts/bench/bench_floor.py).
"""

from __future__ import annotations

import bpy
import numpy as np
import polyscrew
import pytest

import bake_helpers as h
from conftest import addon_module
from test_read_once_more import keyed_object
from test_speed_smooth import many


def _counting(module, name: str, calls: list, what=lambda first: first):
    """Wraps `module.name` to append `what(first argument)` of each call to `calls`; returns
    the original."""
    original = getattr(module, name)

    def counted(*args, **kwargs):
        calls.append(what(args[0]) if args else None)
        return original(*args, **kwargs)

    setattr(module, name, counted)
    return original


def test_insert_key_samples_each_owner_twice():
    """Five objects: every motion sampled twice (before and after each insertion), all owners
    together: two batched samplings (`bake.sample_poses_many`, each owner in it once), none
    alone; on 148afe3 fifteen samplings alone (a third one for the keyed pose alone), on
    ba6187d ten. Every channel still gets its key."""
    bake = addon_module("blender.bake")
    objects = [keyed_object(f"Twice{i}", 0.5 * i) for i in range(5)]
    bpy.context.scene.frame_set(14)
    h.select_only(*objects)
    calls: list = []
    batched: list = []
    originals = (_counting(bake, "sample_poses", calls), _counting(bake, "sample_poses_many", batched, len))
    try:
        assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
    finally:
        bake.sample_poses, bake.sample_poses_many = originals
    print(f"Insert Key on Motion, 5 objects: {len(calls)} samplings alone, {batched} batched (148afe3: 15 alone)")
    assert calls == [] and batched == [len(objects)] * 2
    for obj in objects:
        keyed = [fc for fc in h.fcurves(obj) if np.any(np.abs(h.curve_points(fc)[:, 0] - 14.0) < 1e-6)]
        assert len(keyed) == 9, obj.name


@pytest.mark.parametrize(("timing", "method", "frame"), [
    ("keys", "SCREW", 14.0), ("smooth", "SCREW", 13.25), ("linear", "SCREW", 17.0),
    ("keys", "FEATURE", 5.5), ("smooth", "FEATURE", 22.0),
])
def test_insert_key_keys_the_pose_sampled_at_its_frame_alone(timing, method, frame):
    """The keyed location, rotation and scale are, bit for bit, those of the motion sampled
    at the key's frame alone (what 148afe3 keyed: `bake.sample_poses` at [frame])."""
    ik, keys, bake, transaction = (addon_module(f"blender.{m}") for m in ("insert_key", "keys", "bake", "transaction"))
    obj = keyed_object("Alone", 0.3)
    options = bake.Options(timing=timing, method=method)
    motion = keys.read(obj, options.closed, turns=options.turns)
    pose, scale = bake.sample_poses(motion, np.array([frame]), options, obj)
    by_prop = {(fc.data_path, fc.array_index): fc for fc in h.fcurves(obj)}
    previous = ik._current_values(obj, by_prop, "rotation_euler", 3, frame)
    with transaction.atomic() as t:
        result = ik.insert_key(obj, frame, options, t)
    assert np.array_equal(result.values["location"], pose[0, :3, 3])
    assert np.array_equal(result.values["rotation_euler"], polyscrew.rotation_channels(pose, "XYZ", previous=previous)[0])
    assert np.array_equal(result.values["scale"], scale[0])


def test_revert_reads_each_objects_facts_once():
    """Revert of twenty objects (two pairs sharing an action, one edited result): the smoothed
    actions are found in one pass over the selection (`bake.source_of` only in the poll, which
    `bpy.ops` runs twice here; on 148afe3 also twice per object: 40 calls), each result's edit check made once per
    action, and what Revert promises still holds: every object has its original back, the
    edited result is kept with a fake user and named in the report, the others are removed."""
    bake, channels = addon_module("blender.bake"), addon_module("blender.channels")
    objects = many(18)
    for name in ("TwinA", "TwinB"):  # linked duplicates of the first two: they share their action
        twin = bpy.data.objects.new(name, objects[0 if name == "TwinA" else 1].data)
        bpy.context.scene.collection.objects.link(twin)
        original = objects[0 if name == "TwinA" else 1]
        twin.animation_data_create()
        channels.assign(twin, original.animation_data.action, channels.slot_identifier(original))
        objects.append(twin)
    sources = {o.name: o.animation_data.action for o in objects}
    actions = len(bpy.data.actions)
    h.select_only(*objects)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert objects[-2].animation_data.action is objects[0].animation_data.action
    edited = objects[5].animation_data.action
    h.fcurves(objects[5])[0].keyframe_points[3].co.y += 0.5
    edited_name = edited.name
    found: list = []
    digests: list = []
    originals = (_counting(bake, "source_of", found), _counting(bake, "keys_digest", digests, lambda a: a.as_pointer()))
    try:
        assert bpy.ops.screwbender.revert() == {"FINISHED"}
    finally:
        bake.source_of, bake.keys_digest = originals
    print(f"Revert of {len(objects)} objects (18 actions): source_of {len(found)} calls, "
          f"keys_digest {len(digests)} (148afe3: 40 and 18)")
    assert len(found) <= 2  # (the poll's)
    assert len(digests) == 18 and len(set(digests)) == 18
    assert all(o.animation_data.action is sources[o.name] for o in objects)
    assert edited_name in bpy.data.actions and bpy.data.actions[edited_name].use_fake_user
    assert len(bpy.data.actions) == actions + 1  # the other results removed


def test_reduce_keys_lists_the_scenes_objects_once():
    """Twelve objects with their own actions and a linked duplicate sharing the first one's:
    `bake.users_by_slot` once for the run (on 148afe3: 12 times, through `bake.users_of` per action); every
    object gets the reduced action, the duplicate the same as the object it shares with."""
    bake, channels = addon_module("blender.bake"), addon_module("blender.channels")
    objects = [keyed_object(f"Reduced{i:02d}", 0.4 * i) for i in range(12)]
    twin = bpy.data.objects.new("ReducedTwin", objects[0].data)
    bpy.context.scene.collection.objects.link(twin)
    twin.animation_data_create()
    channels.assign(twin, objects[0].animation_data.action, channels.slot_identifier(objects[0]))
    before = {o.name: o.animation_data.action for o in [*objects, twin]}
    h.select_only(*objects)
    calls = {"users_by_slot": []}
    originals = {name: _counting(bake, name, calls[name]) for name in calls}
    try:
        assert bpy.ops.screwbender.reduce_keys() == {"FINISHED"}
    finally:
        for name, original in originals.items():
            setattr(bake, name, original)
    counts = {name: len(made) for name, made in calls.items()}
    print(f"Reduce Keys, 12 objects and a linked duplicate: {counts} (148afe3: 12)")
    assert counts == {"users_by_slot": 1}
    assert all(o.animation_data.action is not before[o.name] for o in [*objects, twin])
    assert twin.animation_data.action is objects[0].animation_data.action
