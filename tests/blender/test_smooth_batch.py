"""Smooth Motion samples every selected owner in one polyscrew call per rotation mode (issue
27: `sampling.sample_many`, `polyscrew.sample_owners`), and writes the keys the owner-by-owner
sampling wrote, to the bit.
"""

from __future__ import annotations

import bpy
import numpy as np
import polyscrew
import pytest

import bake_helpers as h
import bone_helpers as bh
from conftest import addon_module
from test_speed_smooth import keyed

#: polyscrew's sampling functions, counted by :func:`counting_calls`.
SAMPLERS = ("sample_owners", "sample_channels", "sample_vectors", "sample", "timed_frames", "rotation_channels")


def counting_calls(monkeypatch, names: tuple[str, ...] = SAMPLERS, module=polyscrew) -> dict[str, int]:
    """Wraps the functions `names` of `module` (by default polyscrew's sampling functions, the
    module object the add-on imports) to count their calls; `raising=False`: a module without
    one of them (`sample_owners`) is counted too."""
    calls = dict.fromkeys(names, 0)
    for name in names:
        original = getattr(module, name, None)
        if original is None:
            continue

        def counted(*args, _name=name, _original=original, **kwargs):
            calls[_name] += 1
            return _original(*args, **kwargs)

        monkeypatch.setattr(module, name, counted, raising=False)
    return calls


@pytest.mark.parametrize("timing", ["keys", "smooth"])
def test_forty_objects_are_sampled_in_one_call(monkeypatch, timing):
    objects = [keyed(f"Batch{i}", seed=i, scale=i % 2 == 0) for i in range(40)]
    h.select_only(*objects)
    calls = counting_calls(monkeypatch)
    assert bpy.ops.screwbender.smooth(timing=timing) == {"FINISHED"}
    assert all(o.animation_data.action.name.endswith(".smooth") for o in objects)
    print(f"timing {timing}, 40 objects: {calls}")
    # one call for all of them; owner by owner it was a timed_frames and a sample_channels
    # call per object (and a sample_vectors per scaled one)
    assert calls["sample_owners"] == 1
    assert calls["sample_channels"] == calls["sample_vectors"] == calls["timed_frames"] == calls["sample"] == 0


def varied_scene(suffix: str) -> list:
    """Objects in every kind of rotation mode, scale keyed or not, a held span, a cycle
    (Cycles modifiers), two linked duplicates sharing an action, and a rig of three bones."""
    made = []
    for i, mode in enumerate(("XYZ", "QUATERNION", "AXIS_ANGLE", "ZXY", "YZX")):
        made.append(keyed(f"Var{mode}{suffix}", seed=100 + i, mode=mode, scale=i % 2 == 1))
    held = h.new_object(f"Held{suffix}")
    poses = h.rigid(np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0], [3, 1, 0], [4, 2, 1.0]]), np.stack([np.eye(3)] * 5))
    h.key_poses(held, [1, 5, 12, 16, 22], poses)
    made.append(held)
    cycle = keyed(f"Cycle{suffix}", seed=7)
    for fc in h.fcurves(cycle):
        fc.modifiers.new("CYCLES")
    made.append(cycle)
    twin = keyed(f"Twin{suffix}", seed=8)
    other = twin.copy()  # a linked duplicate: the same action
    other.name = f"TwinCopy{suffix}"
    bpy.context.scene.collection.objects.link(other)
    made += [twin, other]
    return made


def smooth_varied_scene(suffix: str, gentle: bool = True, **options) -> list:
    """The :func:`varied_scene` and a rig of three keyed bones (`gentle` poses or not), each
    smoothed with `options` (the objects, then the bones in Pose Mode): the owners smoothed."""
    objects = varied_scene(suffix)
    rig = bh.armature()
    rig.name = f"Rig{suffix}"
    for n, bone in enumerate(("Upper", "Fore", "Hand")):
        bh.key_bone(rig, bone, [1, 6, 13, 20], bh.random_poses(4, seed=30 + n, gentle=gentle))
    h.select_only(*objects)
    assert bpy.ops.screwbender.smooth(**options) == {"FINISHED"}
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    bh.select_bones(rig, ["Upper", "Fore", "Hand"])
    assert bpy.ops.screwbender.smooth(**options) == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    return objects + [rig]


def result_digests(objects) -> list[str]:
    bake = addon_module("blender.bake")
    channels = addon_module("blender.channels")
    out = []
    for obj in objects:
        action = obj.animation_data.action
        assert action.get(bake.SOURCE_KEY) is not None, f"{obj.name} not smoothed"
        out.append(bake.keys_digest(action, channels.slot_identifier(obj)))
    return out


@pytest.mark.parametrize("timing", ["keys", "linear"])
def test_batched_keys_are_the_owner_by_owner_keys(monkeypatch, timing):
    """The same varied scene twice: smoothed with the batch, and with `sample_many` refusing
    every owner (so each is sampled alone, as before the batch): every result's keys (frames,
    values, interpolations of every curve) have the same digest."""
    sampling = addon_module("pure.sampling")
    digests = {}
    for way in ("batched", "alone"):
        if way == "alone":
            monkeypatch.setattr(sampling, "sample_many", lambda items, options, poses=False: [None] * len(items))
        digests[way] = result_digests(smooth_varied_scene(way, timing=timing))
    assert digests["batched"] == digests["alone"]
    print(f"timing {timing}: {len(digests['alone'])} results, digests identical")
