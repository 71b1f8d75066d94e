"""Smooth Motion and Revert at scene scale (issue 24's last criterion, issue 27).

Each source curve's keys are read once per run (`read_count.counting_reads`: every
`foreach_get` of the add-on goes through `bulk.get`), over objects that share an action and
objects that do not, a rig in Pose Mode, and Revert; and Revert of many objects costs less
than smoothing them (one pass over the scene's objects, not one per action).
"""

from __future__ import annotations

import math
import time

import bpy
import numpy as np
import pytest

import bake_helpers as h
import bone_helpers as bh
from conftest import addon_module
from read_count import counting_reads, read_more_than_once


def keyed(name: str, seed: int, mode: str = "XYZ", scale: bool = False) -> bpy.types.Object:
    """An object keyed at five uneven frames (location, rotation, optionally scale)."""
    obj = h.new_object(name, mode=mode)
    rng = np.random.default_rng(seed)
    poses = h.rigid(rng.uniform(-2, 2, (5, 3)), np.stack([np.eye(3)] * 5))
    angles = np.cumsum(rng.uniform(0.2, 0.8, 5))
    for i, a in enumerate(angles):
        c, s = math.cos(a), math.sin(a)
        poses[i, :3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    h.key_poses(obj, [1, 4, 11, 15, 24], poses, rng.uniform(0.8, 1.2, (5, 3)) if scale else None)
    return obj


def transform_curves(action, owner_prefix: str = "") -> list[tuple[str, str, int]]:
    """(action name, data path, index) of the keyed transform curves of `action` (legacy or
    slotted: every channelbag), named before an operator may remove the action."""
    out = []
    for _identifier, bag in addon_channels().containers(action):
        out += [(action.name, fc.data_path, fc.array_index) for fc in bag.fcurves if fc.data_path.startswith(owner_prefix)
                and fc.data_path.rsplit(".", 1)[-1] in ("location", "rotation_euler", "rotation_quaternion", "scale")]
    return out


def addon_channels():
    return addon_module("blender.channels")


def assert_read_once(reads, curves) -> None:
    """Every curve of `curves` had its key positions read exactly once, and no keyframe
    property of any curve was read twice."""
    twice = read_more_than_once(reads)
    print(f"keyframe-property reads: {sum(n for k, n in reads.items() if len(k) == 4)} over "
          f"{len({k[:3] for k in reads if len(k) == 4})} curves; read more than once: {twice}")
    assert twice == {}
    missing = [curve for curve in curves if reads[(*curve, "co")] != 1]
    assert missing == [], "source curves whose keys were not read (the test would prove nothing)"


def test_smooth_reads_each_source_curve_once_shared_and_own_actions():
    # two linked duplicates sharing one action, two objects with their own actions (one
    # quaternion with scale), a third sharing nothing
    a = keyed("Shared", 1)
    twin = bpy.data.objects.new("SharedTwin", a.data)
    bpy.context.scene.collection.objects.link(twin)
    twin.animation_data_create()
    addon_channels().assign(twin, a.animation_data.action, addon_channels().slot_identifier(a))
    b = keyed("Own", 2, mode="QUATERNION", scale=True)
    c = keyed("Other", 3)
    sources = {o.name: o.animation_data.action for o in (a, b, c)}
    curves = [fc for action in sources.values() for fc in transform_curves(action)]
    assert len(curves) == 6 + 10 + 6
    h.select_only(a, twin, b, c)
    with counting_reads() as reads:
        assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert_read_once(reads, curves)
    # the smoothing happened: every object has a new action, the twins still share one
    assert all(o.animation_data.action is not sources[o.name] for o in (a, b, c))
    assert twin.animation_data.action is a.animation_data.action


def test_smooth_reads_each_source_curve_once_rig_in_pose_mode():
    rig = bh.armature()
    frames = [1, 6, 13, 20]
    for n, bone in enumerate(("Upper", "Fore", "Hand")):
        bh.key_bone(rig, bone, frames, bh.random_poses(len(frames), seed=10 + n, gentle=True))
    action = rig.animation_data.action
    curves = transform_curves(action, "pose.bones")
    assert len(curves) == 6 + 3 + 6  # a connected bone has no location keys
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    bh.select_bones(rig, ["Upper", "Fore", "Hand"])
    with counting_reads() as reads:
        assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    assert_read_once(reads, curves)
    assert rig.animation_data.action is not action


def test_revert_reads_each_result_curve_once():
    objects = [keyed(f"Body{n}", 20 + n) for n in range(3)]
    h.select_only(*objects)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    results = [o.animation_data.action for o in objects]
    curves = [fc for action in results for fc in transform_curves(action)]
    with counting_reads() as reads:
        assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert_read_once(reads, curves)  # (the edit check reads each result curve once)
    assert all(o.animation_data.action is not r for o, r in zip(objects, results))


def many(count: int) -> list[bpy.types.Object]:
    """`count` objects with two keys each (a mesh shared by all), fast to make."""
    mesh = bpy.data.meshes.new("Block")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], [], [(0, 1, 2)])
    out = []
    for n in range(count):
        obj = bpy.data.objects.new(f"Many{n:04d}", mesh)
        bpy.context.scene.collection.objects.link(obj)
        for frame, x in ((1, 0.0), (50, 3.0)):
            obj.location = (x, 0.01 * n, 0.0)
            obj.rotation_euler = (0.0, 0.0, x / 2)
            obj.keyframe_insert("location", frame=frame)
            obj.keyframe_insert("rotation_euler", frame=frame)
        out.append(obj)
    return out


@pytest.mark.parametrize("count", [500])
def test_revert_of_many_objects_scans_the_scene_once(count):
    """Revert of many objects does one pass over the scene for all the smoothed actions and
    removes the smoothed copies in one batch (before: a scan of every object and of the file
    per reverted action, quadratic: 0.27 of the smoothing's CPU at 300 objects, 0.4 at 500).
    Counted, not timed (the times are printed; speed is measured in scripts/bench/bench_floor.py)."""
    bake = addon_module("blender.bake")
    objects = many(count)
    sources = [o.animation_data.action for o in objects]
    h.select_only(*objects)
    actions = len(bpy.data.actions)
    start = time.process_time()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    smoothed = time.process_time() - start
    assert len(bpy.data.actions) == actions + count
    calls = {"users_by_slot": 0, "remove_unused": 0, "_remove_if_unused": 0}
    originals = {name: getattr(bake, name) for name in calls}

    def counted(name):
        def call(*args, **kwargs):
            calls[name] += 1
            return originals[name](*args, **kwargs)
        return call

    for name in calls:
        setattr(bake, name, counted(name))
    try:
        start = time.process_time()
        assert bpy.ops.screwbender.revert() == {"FINISHED"}
        reverted = time.process_time() - start
    finally:
        for name, original in originals.items():
            setattr(bake, name, original)
    print(f"{count} objects x 50 frames: Smooth Motion {smoothed * 1e3:.0f} ms, Revert {reverted * 1e3:.0f} ms CPU "
          f"({reverted / smoothed:.2f} of it); calls {calls}")
    assert [o.animation_data.action for o in objects] == sources
    assert calls == {"users_by_slot": 1, "remove_unused": 1, "_remove_if_unused": 0}
    assert len(bpy.data.actions) == actions  # the smoothed copies removed (in one batch)


def long_object(name: str) -> bpy.types.Object:
    """An object keyed at frames 1, 3001 and 6001 (location and rotation): spans of 3,000
    frames, far off the screw between their keys."""
    obj = h.new_object(name)
    for frame, x in ((1, 0.0), (3001, 4.0), (6001, 4.5)):
        obj.location = (x, 0.3 * x, 0.0)
        obj.rotation_euler = (0.2 * x, 0.0, 0.4 * x)
        obj.keyframe_insert("location", frame=frame)
        obj.keyframe_insert("rotation_euler", frame=frame)
    return obj


def test_departure_of_a_long_bake_measured_per_span_agrees_with_every_frame():
    """A span baked at more than intent.DEPARTURE_SPAN_FRAMES frames is measured at that many
    frames: the largest departure and the frames over the thresholds agree with measuring
    every frame (a screw between two keys against Blender's independent channel curves)."""
    intent = addon_module("pure.intent")
    bake = addon_module("blender.bake")
    obj = long_object("Long")
    actions, skipped, _ = bake.prepare([obj], bake.Options())
    part = actions[0].parts[0]
    motion = part.motion
    args = (motion.source, motion.size, part.frames, part.values["location"], part.values["rotation_euler"])
    start = time.process_time()
    every = intent.departure(*args)
    whole = time.process_time() - start
    start = time.process_time()
    sampled = intent.departure(*args, motion.frames)
    spans = time.process_time() - start
    print(f"{len(part.frames)} frames: every frame {every.degrees:.4f} deg {every.distance:.6f} units, "
          f"{len(every.frames)} frames over, {whole * 1e3:.1f} ms; per span {sampled.degrees:.4f} deg "
          f"{sampled.distance:.6f} units, {len(sampled.frames)} frames over, {spans * 1e3:.1f} ms")
    assert len(every.frames) > 100, "the case departs (else it proves nothing)"
    assert abs(sampled.degrees - every.degrees) <= 1e-3 * every.degrees
    assert abs(sampled.distance - every.distance) <= 1e-3 * every.distance
    # the frames over the thresholds: the same but within a sample spacing at the ends of runs
    spacing = 3000 / (intent.DEPARTURE_SPAN_FRAMES - 1)
    differ = np.setxor1d(every.frames, sampled.frames)
    assert len(differ) <= 4 * spacing, (len(differ), spacing)
    assert intent.frame_runs(sampled.frames).count("-") == intent.frame_runs(every.frames).count("-")


def departure_plays(intent) -> tuple[list, object]:
    """Wraps `intent.departures` (what Smooth Motion measures its owners' results with, all in
    one call): per owner measured, (rows the owner's playback had played before it, rows the
    departure played, frames measured). Returns the list and the original, to put back."""
    seen = []
    original = intent.departures

    def counted(items, *args, **kwargs):
        before = [item[0].playback.rows_evaluated for item in items]
        found = original(items, *args, **kwargs)
        seen.extend((b, item[0].playback.rows_evaluated - b, len(item[2])) for b, item in zip(before, items))
        return found

    intent.departures = counted
    return seen, original


def test_the_departure_measure_plays_no_frame_timing_keys_has_played():
    """Smooth Motion plays each owner's source curves once per baked frame: timing Keys plays
    them at the baked frames (to follow Blender's pace) and the departure measure compares the
    result with those rows instead of playing them again (issue 24 item 5 at the cost of a
    comparison). Counted with the playback's own counter of rows played, for objects, a rig in
    Pose Mode, and a long bake whose spans are measured on a grid (there the departure plays
    at most DEPARTURE_SPAN_FRAMES frames a span). Before: it played every measured frame again."""
    intent = addon_module("pure.intent")
    objects = [keyed(f"Once{n}", 40 + n, mode=mode) for n, mode in enumerate(("XYZ", "QUATERNION", "ZXY"))]
    seen, original = departure_plays(intent)
    try:
        h.select_only(*objects)
        assert bpy.ops.screwbender.smooth() == {"FINISHED"}
        rig = bh.armature()
        for n, bone in enumerate(("Upper", "Fore", "Hand")):
            bh.key_bone(rig, bone, [1, 6, 13, 20], bh.random_poses(4, seed=50 + n, gentle=True))
        h.select_only(rig)
        bpy.ops.object.mode_set(mode="POSE")
        bh.select_bones(rig, ["Upper", "Fore", "Hand"])
        assert bpy.ops.screwbender.smooth() == {"FINISHED"}
        bpy.ops.object.mode_set(mode="OBJECT")
        short = list(seen)
        h.select_only(long_object("LongOnce"))
        assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    finally:
        intent.departures = original
    for before, played, frames in short:
        print(f"{frames} baked frames: the owner's playback played {before} rows before the departure "
              f"(span analysis and timing Keys), the departure {played} (before this change: {frames})")
    assert len(short) == 6, "three objects and three bones measured"
    assert all(played == 0 for _, played, _ in short)
    assert all(before >= frames for before, _, frames in short), "timing Keys played every baked frame"
    (before, played, frames), = seen[len(short):]
    print(f"long bake, {frames} frames: timing Keys played {before} rows, the departure {played} "
          f"(at most {2 * intent.DEPARTURE_SPAN_FRAMES}: the frames of its grid timing Keys did not play)")
    assert 0 < played <= 2 * intent.DEPARTURE_SPAN_FRAMES


def test_the_written_digest_notices_every_kind_of_edit():
    # the result's digest (a CRC per curve, issue 24 item 6 made cheaper) as written equals the
    # one read back, and changes for a moved key (frame or value), a changed interpolation,
    # an added and a deleted key; put back, it is the written one again
    bake = addon_module("blender.bake")
    obj = keyed("Edited", 7)
    h.select_only(obj)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    result = obj.animation_data.action
    identifier = addon_channels().slot_identifier(obj)
    written = result[bake.WRITTEN_KEY]
    assert written == bake.keys_digest(result, identifier) and not bake.was_edited(result, identifier)
    fcurve = next(fc for fc in addon_channels().action_fcurves(result, identifier) if fc.data_path == "location")
    point = fcurve.keyframe_points[3]
    frame, value, kind = point.co[0], point.co[1], point.interpolation

    def edited(change, undo) -> bool:
        change()
        seen = bake.was_edited(result, identifier)
        undo()
        assert bake.keys_digest(result, identifier) == written, "the edit put back gives the written digest"
        return seen

    kinds = {
        "value moved": edited(lambda: setattr(point, "co", (frame, value + 1e-3)), lambda: setattr(point, "co", (frame, value))),
        "frame moved": edited(lambda: setattr(point, "co", (frame + 0.25, value)), lambda: setattr(point, "co", (frame, value))),
        "interpolation": edited(lambda: setattr(point, "interpolation", "BEZIER"), lambda: setattr(point, "interpolation", kind)),
    }
    count = len(fcurve.keyframe_points)
    fcurve.keyframe_points.insert(frame + 0.5, value)
    kinds["key added"] = bake.was_edited(result, identifier)
    fcurve.keyframe_points.remove(fcurve.keyframe_points[4])
    assert len(fcurve.keyframe_points) == count
    fcurve.keyframe_points.remove(fcurve.keyframe_points[3])
    kinds["key deleted"] = bake.was_edited(result, identifier)
    print(f"digest {written}; edits seen: {kinds}")
    assert kinds == dict.fromkeys(kinds, True)
