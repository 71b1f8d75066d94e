"""Issue 27, Revert and Insert Key on Motion nearer their floor: the work removed is counted
(calls wrapped in the test), and what they write is the same as before.

- Insert Key on Motion samples each owner's motion twice (before and after the new key, at
  the frames it compares), not three times: the pose it keys is the one sampled before at
  its frame (which is among those frames), bit for bit the pose sampled at that frame alone.

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
    """Five objects: ten samplings of a motion (before and after each insertion); on 148afe3
    fifteen (a third one for the keyed pose alone). Every channel still gets its key."""
    bake = addon_module("blender.bake")
    objects = [keyed_object(f"Twice{i}", 0.5 * i) for i in range(5)]
    bpy.context.scene.frame_set(14)
    h.select_only(*objects)
    calls: list = []
    original = _counting(bake, "sample_poses", calls)
    try:
        assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
    finally:
        bake.sample_poses = original
    print(f"Insert Key on Motion, 5 objects: {len(calls)} samplings (148afe3: 15)")
    assert len(calls) == 2 * len(objects)
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

