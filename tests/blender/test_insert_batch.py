"""Insert Key on Motion samples every owner together (issue 27): one polyscrew call per
rotation mode for the motions before the insertions and one for the motions after
(`bake.sample_poses_many`, `sampling.sample_many(poses=True)`, `polyscrew.sample_owners`),
and keys what one owner after another keyed, to the bit.

Counted or compared, not timed (speed: scripts/bench/bench_floor.py).
"""

from __future__ import annotations

import bpy
import numpy as np
import pytest

import bake_helpers as h
import bone_helpers as bh
from conftest import addon_module
from test_read_once_more import keys_of
from test_smooth_batch import counting_calls, varied_scene
from test_speed_smooth import keyed

BONES = ("Upper", "Fore", "Hand")


def rig(name: str):
    """A three-bone rig, each bone keyed on four frames."""
    made = bh.armature()
    made.name = name
    for n, bone in enumerate(BONES):
        bh.key_bone(made, bone, [1, 6, 13, 20], bh.random_poses(4, seed=30 + n, gentle=True))
    return made


def test_twenty_four_objects_and_a_rig_are_sampled_in_two_calls(monkeypatch):
    """24 objects (half with scale keyed), then a rig's three bones: each run samples the
    motions before and after in one `sample_owners` call each, no per-piece call (ba6187d:
    a timed_frames and a sample call per owner and sampling: 48 of each for the objects, and 24
    sample_vectors)."""
    objects = [keyed(f"Insert{i}", seed=i, scale=i % 2 == 0) for i in range(24)]
    bpy.context.scene.frame_set(9)
    h.select_only(*objects)
    calls = counting_calls(monkeypatch)
    assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
    print(f"Insert Key on Motion, 24 objects: {calls}")
    assert calls["sample_owners"] == 2
    assert calls["sample"] == calls["timed_frames"] == calls["sample_vectors"] == calls["sample_channels"] == 0
    for obj in objects:
        assert all(np.any(h.curve_points(fc)[:, 0] == 9.0) for fc in h.fcurves(obj)), obj.name

    armature = rig("InsertRig")
    h.select_only(armature)
    bpy.ops.object.mode_set(mode="POSE")
    bh.select_bones(armature, list(BONES))
    calls.update(dict.fromkeys(calls, 0))
    try:
        assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
    finally:
        bpy.ops.object.mode_set(mode="OBJECT")
    print(f"Insert Key on Motion, a rig of 3 bones: {calls}")
    assert calls["sample_owners"] == 2
    assert calls["sample"] == calls["timed_frames"] == calls["sample_vectors"] == 0


@pytest.mark.parametrize(("timing", "frame"), [("keys", 13.5), ("smooth", 11.0), ("linear", 7.25)])
def test_batched_keys_are_the_owner_by_owner_keys(monkeypatch, timing, frame):
    """The same varied scene (rotation modes, scale, a hold, a cycle, linked duplicates, a
    rig) twice: keyed with :func:`insert_key.insert_keys` (owners together), and one owner
    after another with `insert_key` in its own nested transaction and `sample_many` refusing
    every owner (each sampled alone: ba6187d's operator). Every curve's keys and handles, and
    every owner's keyed values, largest move and turn, are the same to the bit."""
    ik, owners, transaction, sampling, bake, channels = (
        addon_module(m) for m in ("blender.insert_key", "blender.owners", "blender.transaction", "pure.sampling",
                                  "blender.bake", "blender.channels")
    )
    options = bake.Options(timing=timing)
    found = {}
    for way in ("batched", "alone"):
        objects = varied_scene(f"{way}{frame}")
        armature = rig(f"Rig{way}{frame}")
        selection = [owners.as_owner(o) for o in objects] + [owners.Owner(armature, b) for b in BONES]
        results = []
        with transaction.atomic() as t:
            if way == "batched":
                requests = [(o, owners.curves_by_owner(channels.object_fcurves(o.obj)).get(o.bone, [])) for o in selection]
                results = ik.insert_keys(requests, frame, options, t)
            else:
                monkeypatch.setattr(sampling, "sample_many", lambda items, options, poses=False: [None] * len(items))
                for owner in selection:
                    with transaction.atomic(t) as one:
                        results.append(ik.insert_key(owner, frame, options, one))
                monkeypatch.undo()
        assert not any(isinstance(r, Exception) for r in results), results
        found[way] = (
            [keys_of(o) for o in objects + [armature]],
            [(r.values, r.max_translation, r.max_angle, r.worst_frame) for r in results],
        )
    curves = {way: keys for way, (keys, _) in found.items()}
    for batched, alone in zip(curves["batched"], curves["alone"]):
        assert batched.keys() == alone.keys()
        for name in batched:
            assert all(np.array_equal(a, b) for a, b in zip(batched[name], alone[name])), name
    for (values, *facts), (values_alone, *facts_alone) in zip(found["batched"][1], found["alone"][1]):
        assert facts == facts_alone
        assert values.keys() == values_alone.keys()
        assert all(np.array_equal(values[p], values_alone[p]) for p in values)
    print(f"timing {timing}, frame {frame}: {len(found['alone'][1])} owners keyed the same")


def test_a_refused_owner_is_told_as_alone_and_the_others_keyed():
    """Among owners keyed together, one with a single key: refused with the message
    `insert_key` gives it alone, its curves untouched; the others keyed."""
    ik, owners, transaction, bake, channels = (
        addon_module(m)
        for m in ("blender.insert_key", "blender.owners", "blender.transaction", "blender.bake", "blender.channels")
    )
    options = bake.Options()
    good = [keyed(f"Good{i}", seed=50 + i) for i in range(2)]
    lone = h.new_object("Lone")
    h.key_poses(lone, [5], h.rigid(np.zeros((1, 3)), np.eye(3)[None]))
    before = keys_of(lone)
    with transaction.atomic() as t:
        with pytest.raises(addon_module("blender.keys").SmoothError) as alone:
            with transaction.atomic(t) as one:
                ik.insert_key(lone, 12.0, options, one)
        got = ik.insert_keys(
            [(owners.as_owner(o), channels.object_fcurves(o)) for o in [good[0], lone, good[1]]], 12.0, options, t
        )
    print(f"refused: {got[1]}")
    assert isinstance(got[1], Exception) and str(got[1]) == str(alone.value)
    assert all(isinstance(r, ik.InsertResult) for r in (got[0], got[2]))
    after = keys_of(lone)
    assert after.keys() == before.keys() and all(
        np.array_equal(a, b) for name in after for a, b in zip(after[name], before[name])
    )
