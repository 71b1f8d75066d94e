"""Reduce Keys' own time (issue 26, item 1): the dense motion is played once per owner (the
probes of the spans cut at their quarter frames come from that one playback), the reduced
curves are not played a second time by the add-on (the core measures them in world space, a
connected bone's head included), one `polyscrew.reduce_keys` call; and Blender's playback of
the result stays within the tolerance in world space at every frame and three subframes, on a
rig whose connected bone carries its parent's error and whose last bone keys its scale."""

from __future__ import annotations

import contextlib
import math

import bpy
import numpy as np
from scipy.spatial.transform import Rotation

import bake_helpers as h
import bone_helpers as bh
from conftest import addon_module
from playback_rows import playing_rows
from test_reduce_keys import check_within, play, sample_times, transform_keys

DISTANCE, ANGLE = 0.001, math.radians(0.5)


@contextlib.contextmanager
def counting_calls():
    """Counts `polyscrew.reduce_keys` and `polyscrew.evaluate_fcurves` calls of the Reduce
    Keys module and the playbacks of the dense motion (`Source.channels`, and each playback
    of a `polyscrew.channels_many` call, which plays many owners in one call)."""
    reduce = addon_module("blender.reduce")
    intent = addon_module("pure.intent")
    calls = {"reduce_keys": 0, "evaluate_fcurves": 0, "channels": 0}
    names = ("reduce_keys", "evaluate_fcurves", "channels_many")
    originals = {name: getattr(reduce.polyscrew, name) for name in names}
    channels = intent.Source.channels

    def counted(name):
        def call(*args, **kwargs):
            if name == "channels_many":
                calls["channels"] += len(args[0])
            else:
                calls[name] += 1
            return originals[name](*args, **kwargs)

        return call

    def counted_channels(self, frames):
        calls["channels"] += 1
        return channels(self, frames)

    for name in originals:
        setattr(reduce.polyscrew, name, counted(name))
    intent.Source.channels = counted_channels
    try:
        yield calls
    finally:
        for name, original in originals.items():
            setattr(reduce.polyscrew, name, original)
        intent.Source.channels = channels


def test_reduce_keys_plays_the_dense_motion_once_and_measures_in_the_core(sb):
    bones = ("Upper", "Fore", "Hand")
    rig = bh.armature("Rig", bones=(("Upper", None, False), ("Fore", "Upper", True), ("Hand", "Fore", False)))
    frames = np.arange(1, 97, dtype=float)
    t = (frames - 1) / 24.0
    for i, bone in enumerate(bones):
        rot = Rotation.from_rotvec(np.stack([0.5 * np.sin(1.3 * t + i), 0.3 * np.cos(0.8 * t), 0.2 * t], axis=1))
        loc = np.stack([0.1 * np.sin(t + i), 0.05 * t, 0.0 * t], axis=1)
        scales = np.stack([1.0 + 0.1 * np.sin(t), np.ones_like(t), np.ones_like(t)], axis=1) if bone == "Hand" else None
        bh.key_bone(rig, bone, frames, h.rigid(loc, rot.as_matrix()), scales=scales)
    owners_ = [(rig, b) for b in bones]
    times = sample_times(1, 96)
    ref = play(owners_, times)
    before = sum(transform_keys(rig, b) for b in bones)
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    bh.select_bones(rig, list(bones))
    with counting_calls() as calls:
        assert bpy.ops.screwbender.reduce_keys(distance=DISTANCE, angle=ANGLE) == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    after = sum(transform_keys(rig, b) for b in bones)
    print(f"rig: {before} key frames -> {after}; calls {calls}")
    # one playback per owner, of the dense frames with their probes: the keys, keyed on every
    # frame without modifiers, are read from their key values (before: a second playback at
    # the key frames, and before that a third where spans were cut at their quarter frames),
    # no second evaluation of the reduced curves (before: one per reduce_keys call)
    assert calls["channels"] == len(bones), calls
    assert calls["evaluate_fcurves"] == 0, calls
    assert 1 <= calls["reduce_keys"] <= 1 + addon_module("blender.reduce").RETRIES
    assert after < 0.5 * before
    # Blender's playback in world space: the connected bone's head carries the upper arm's
    # error, the hand's scale is keyed
    check_within(owners_, ref, times, DISTANCE, ANGLE, "connected rig")


def test_a_capture_read_from_its_key_values_reduces_to_the_same_keys(sb):
    """Reduce Keys reads a capture (every curve keyed on every key frame, no modifiers) from
    its key values, not from Blender's playback at the key frames: on two identical sets of
    noisy captures in four rotation modes, one reduced with the playback read forced (the
    former path) and one as it is, every written key, handle and interpolation is the same,
    to the bit, and the forced path plays the keys once more per owner."""
    from test_noise_batch import noisy_keys

    keys = addon_module("blender.keys")
    modes = ("XYZ", "ZXY", "QUATERNION", "AXIS_ANGLE")
    frames = [float(f) for f in range(1, 121)]
    sets = []
    for label in ("played", "values"):
        rng = np.random.default_rng(11)  # the same keys in both sets
        objects = []
        for mode in modes:
            ob = bpy.data.objects.new(f"{label}_{mode}", None)
            bpy.context.scene.collection.objects.link(ob)
            noisy_keys(ob, frames, mode, rng)
            objects.append(ob)
        sets.append(objects)
    read = keys.read_many

    def played_read(requests, *args, **kwargs):
        for request in requests:
            request.key_values = False
        return read(requests, *args, **kwargs)

    plays = []
    for objects, forced in zip(sets, (True, False)):
        h.select_only(*objects)
        if forced:
            keys.read_many = played_read
        try:
            with counting_calls() as calls, playing_rows() as played:  # (tolerances above the noise: keys are dropped)
                assert bpy.ops.screwbender.reduce_keys(distance=0.05, angle=math.radians(5.0)) == {"FINISHED"}
        finally:
            keys.read_many = read
        plays.append((calls["channels"], played["rows"]))
    # the forced path played the key frames too: each owner's once more
    assert plays[0][1] - plays[1][1] == len(modes) * len(frames), plays

    def written(ob):
        """Every curve's keys, handles and interpolations as Blender holds them."""
        arrays = {}
        for fc in h.fcurves(ob):
            points = fc.keyframe_points
            for name, width, dtype in (("co", 2, np.float32), ("handle_left", 2, np.float32),
                                       ("handle_right", 2, np.float32), ("interpolation", 1, np.int32)):
                values = np.empty(len(points) * width, dtype=dtype)
                points.foreach_get(name, values)
                arrays[fc.data_path, fc.array_index, name] = values
        return arrays

    for a, b in zip(*sets):
        first, second = written(a), written(b)
        assert first.keys() == second.keys() and first, a.name
        for key in first:
            assert np.array_equal(first[key], second[key]), (a.name, key)
        assert all(len(v) < len(frames) for k, v in first.items() if k[2] == "interpolation")  # keys were dropped
