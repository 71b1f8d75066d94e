"""Results written in one packed pass (issue 27): Smooth Motion's dense curves of every owner
packed into one array per operator (`bake.pack_dense`), their digests from the arrays written
(none read back), Revert's edit check reading each result curve's keys once
(`bake._read_digests`); the digest counts a BEZIER key's handles (a handle edit on a Reduce
Keys result was not seen, and Revert threw the edited result away).

`test_written_keys_of_every_operator` fingerprints every curve of every action (keys, handles,
handle types, interpolations, easings, groups, modifiers, the recorded digest) after Smooth
Motion (three ways), Remove Noise, Reduce Keys and Revert on a varied scene; with
SCREWBENDER_WRITE_FINGERPRINT=<file> it also writes them to <file>, to compare, byte for byte,
with a run of the same test against an earlier extension (SCREWBENDER_EXTENSION_ZIP).
"""

from __future__ import annotations

import json
import os
import zlib

import bpy
import numpy as np
import pytest

import bake_helpers as h
import bone_helpers as bh
from conftest import addon_module
from test_smooth_batch import varied_scene
from test_speed_smooth import keyed

ATTRS = (
    ("co", 2, np.float32), ("handle_left", 2, np.float32), ("handle_right", 2, np.float32),
    ("handle_left_type", 1, np.uint8), ("handle_right_type", 1, np.uint8), ("interpolation", 1, np.uint8),
    ("easing", 1, np.uint8),
)


def fingerprint() -> dict:
    """Every action's curves: per curve its group, every key attribute of `ATTRS` (CRC-32 of
    the bytes Blender gives), its modifiers; the action's recorded digest and maker."""
    bake, channels = addon_module("blender.bake"), addon_module("blender.channels")
    out = {}
    for action in sorted(bpy.data.actions, key=lambda a: a.name):
        for identifier, bag in channels.containers(action):
            curves = {}
            for fc in bag.fcurves:
                points = fc.keyframe_points
                keys = {}
                for attr, width, kind in ATTRS:
                    values = np.empty(width * len(points), dtype=kind)
                    points.foreach_get(attr, values)
                    keys[attr] = f"{zlib.crc32(values):08x}"
                mods = [(m.type, getattr(m, "mode_before", ""), getattr(m, "mode_after", "")) for m in fc.modifiers]
                curves[f"{fc.data_path}[{fc.array_index}]"] = {
                    "group": fc.group.name if fc.group else "", "keys": len(points), **keys, "modifiers": mods,
                }
            out[f"{action.name}/{identifier}"] = {
                "curves": curves, "written": action.get(bake.WRITTEN_KEY), "made_by": action.get(bake.MADE_BY_KEY),
            }
    return out


def scene() -> list:
    """test_smooth_batch's varied scene (every rotation mode, scale keyed or not, a hold, a
    cycle, linked duplicates), a non-transform curve on one object, a Noise modifier on
    another's curve, an object keyed off the whole frames (first: the others' frames differ
    from its), and a rig of three bones; all selected, the rig last."""
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    objects = varied_scene("")
    extra = objects[0]
    extra["weight"] = 0.0
    for frame, value in ((1, 0.0), (12, 1.0), (24, 0.5)):
        extra["weight"] = value
        extra.keyframe_insert('["weight"]', frame=frame)
    h.fcurves(objects[1])[0].modifiers.new("NOISE").strength = 0.5
    late = h.new_object("Late")  # keys off the whole frames, from frame 6.5: a grid of its own
    rng = np.random.default_rng(11)
    h.key_poses(late, [6.5, 9.25, 15, 21.5, 30], h.rigid(rng.uniform(-2, 2, (5, 3)), np.stack([np.eye(3)] * 5)))
    objects.insert(0, late)
    rig = bh.armature()
    rig.name = "Rig"
    for n, bone in enumerate(("Upper", "Fore", "Hand")):
        bh.key_bone(rig, bone, [1, 6, 13, 20], bh.random_poses(4, seed=30 + n, gentle=True))
    return objects + [rig]


def smooth_all(objects, **options) -> None:
    h.select_only(*objects[:-1])
    assert bpy.ops.screwbender.smooth(**options) == {"FINISHED"}
    rig = objects[-1]
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    bh.select_bones(rig, ["Upper", "Fore", "Hand"])
    assert bpy.ops.screwbender.smooth(**options) == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")


def dense_scene() -> list:
    """Objects keyed on every frame with noise, in three rotation modes, one with a cycle."""
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    made = []
    rng = np.random.default_rng(5)
    for i, mode in enumerate(("XYZ", "QUATERNION", "ZXY")):
        obj = h.new_object(f"Dense{mode}", mode=mode)
        frames = np.arange(1, 61, dtype=float)
        t = frames / 24
        loc = np.stack([np.cos(t + i), np.sin(0.7 * t), 0.2 * t], axis=1) + rng.normal(0, 0.005, (60, 3))
        rot = np.zeros((60, 3, 3))
        for k, a in enumerate(0.8 * t + rng.normal(0, 0.003, 60)):
            c, s = np.cos(a), np.sin(a)
            rot[k] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
        h.key_poses(obj, frames, h.rigid(loc, rot))
        made.append(obj)
    for fc in h.fcurves(made[2]):
        fc.modifiers.new("CYCLES")
    return made


def record(label: str, prints: dict) -> None:
    prints[label] = fingerprint()
    bake, channels = addon_module("blender.bake"), addon_module("blender.channels")
    for obj in bpy.data.objects:
        action = obj.animation_data.action if obj.animation_data else None
        written = action.get(bake.WRITTEN_KEY) if action is not None else None
        if written is not None:  # the digest made from what was written is the one read back
            assert written == bake.keys_digest(action, channels.slot_identifier(obj)), f"{label}: {obj.name}"
            assert not bake.was_edited(action, channels.slot_identifier(obj))


def run_everything(prints: dict) -> None:
    objects = scene()
    smooth_all(objects, timing="keys")
    record("smooth", prints)
    smooth_all(objects, range_mode="CUSTOM", frame_start=5, frame_end=18)  # (re-run: the range joined)
    record("smooth range", prints)
    smooth_all(objects, key_mode="REDUCED")
    record("smooth reduced", prints)
    h.select_only(*objects[:-1])
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    record("revert", prints)
    dense = dense_scene()
    h.select_only(*dense)
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    record("denoise", prints)
    assert bpy.ops.screwbender.reduce_keys(distance=0.01, angle=0.02) == {"FINISHED"}
    record("reduce on denoised", prints)
    dense = dense_scene()
    h.select_only(*dense)
    assert bpy.ops.screwbender.reduce_keys(distance=0.01, angle=0.02) == {"FINISHED"}
    record("reduce", prints)


def test_written_keys_of_every_operator(monkeypatch):
    """Every operator's results, written with every owner's curves packed together, are those
    written with each owner packed alone (`pack_dense` per owner), to the bit: keys, handles,
    their types, interpolations, easings, groups, modifiers, digests; each recorded digest is
    the one read back. With SCREWBENDER_WRITE_FINGERPRINT the fingerprints go to that file
    (the packed run's), to compare with another build's."""
    bake = addon_module("blender.bake")
    packed: dict = {}
    run_everything(packed)
    path = os.environ.get("SCREWBENDER_WRITE_FINGERPRINT")
    if path:
        with open(path, "w") as f:
            json.dump(packed, f, indent=1, sort_keys=True)
    real = bake.pack_dense
    monkeypatch.setattr(bake, "pack_dense", lambda parts: {k: v for p in parts for k, v in real([p]).items()})
    alone: dict = {}
    run_everything(alone)
    assert packed.keys() == alone.keys()
    for label in packed:
        assert packed[label] == alone[label], label
    curves = sum(len(a["curves"]) for a in packed["smooth"].values())
    print(f"{len(packed)} steps, {curves} curves after the first Smooth Motion: identical")


def counting_bulk(monkeypatch) -> dict:
    """bulk.get / bulk.put wrapped: calls per (get|put, attribute)."""
    bulk = addon_module("blender.bulk")
    counts: dict = {}
    for name in ("get", "put"):
        original = getattr(bulk, name)

        def counted(collection, attr, values, _name=name, _original=original):
            counts[_name, attr] = counts.get((_name, attr), 0) + 1
            return _original(collection, attr, values)

        monkeypatch.setattr(bulk, name, counted)
    return counts


def test_smooth_and_revert_touch_each_curve_once_per_attribute(monkeypatch):
    """Smooth Motion of 12 objects writes each baked curve's keys with one `foreach_set` per
    attribute written (co, interpolation) and reads none back for its digest; Revert reads
    each result curve's co and interpolation once (linear keys: no handles). (The floor per
    curve, which main already kept: this test passes on main too; it fails when a read or a
    write per curve is added.)"""
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    objects = [keyed(f"Count{i}", seed=i, scale=i % 2 == 0) for i in range(12)]
    h.select_only(*objects)
    curves = sum(6 + (3 if i % 2 == 0 else 0) for i in range(12))
    counts = counting_bulk(monkeypatch)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    smoothed = dict(counts)
    counts.clear()
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    print(f"{curves} curves; smooth {smoothed}; revert {counts}")
    puts = {attr: n for (kind, attr), n in smoothed.items() if kind == "put"}
    assert puts == {"co": curves, "interpolation": curves}
    # the source curves' keys read once (keys.read), the results' never: a digest read back
    # would read each result curve's co and interpolation again (2 x curves)
    assert smoothed.get(("get", "co"), 0) <= curves and smoothed.get(("get", "interpolation"), 0) <= curves
    assert counts == {("get", "co"): curves, ("get", "interpolation"): curves}


@pytest.mark.parametrize("edit", ["handle", "handle put back"])
def test_a_handle_edit_on_a_reduced_result_is_seen_and_kept_by_revert(edit):
    """Reduce Keys writes BEZIER keys whose handles shape the motion: moving one handle of one
    key is an edit (before, the digest held keys and interpolations only and Revert threw the
    edited result away); put back, it is not."""
    bake, channels = addon_module("blender.bake"), addon_module("blender.channels")
    obj = dense_scene()[0]
    h.select_only(obj)
    assert bpy.ops.screwbender.reduce_keys(distance=0.01, angle=0.02) == {"FINISHED"}
    result, identifier = obj.animation_data.action, channels.slot_identifier(obj)
    assert result[bake.WRITTEN_KEY].startswith(bake.DIGEST_HANDLES)
    fc = next(fc for fc in channels.action_fcurves(result, identifier) if len(fc.keyframe_points) > 2)
    point = fc.keyframe_points[1]
    assert point.interpolation == "BEZIER"
    x, y = point.handle_left
    point.handle_left = (x, y + 0.25)
    if edit == "handle put back":
        point.handle_left = (x, y)
    edited = edit == "handle"
    assert bake.was_edited(result, identifier) is edited
    name = result.name
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert (name in bpy.data.actions) is edited  # an edited result is kept, an unedited one removed


def test_a_digest_written_before_handles_counted_is_compared_as_it_was_made():
    """A result saved with the former digest ("crc32:", keys and interpolations) is not taken
    for an edited one: was_edited compares it without the handles."""
    bake, channels = addon_module("blender.bake"), addon_module("blender.channels")
    obj = dense_scene()[0]
    h.select_only(obj)
    assert bpy.ops.screwbender.reduce_keys(distance=0.01, angle=0.02) == {"FINISHED"}
    result, identifier = obj.animation_data.action, channels.slot_identifier(obj)
    old = bake.keys_digest(result, identifier, handles=False)
    assert old.startswith("crc32:") and old[len("crc32:"):] != result[bake.WRITTEN_KEY][len(bake.DIGEST_HANDLES):]
    result[bake.WRITTEN_KEY] = old
    assert not bake.was_edited(result, identifier)
    fc = channels.action_fcurves(result, identifier)[0]
    fc.keyframe_points[0].co.y += 0.5
    assert bake.was_edited(result, identifier)


def test_the_transform_group_is_looked_up_once_per_action(monkeypatch):
    """On 4.4 and 4.5 (whose `fcurves.new` of a channelbag takes no group) Smooth Motion finds
    or makes each result's F-curve group once per action, not once per curve (before: one
    `ensure_group` per curve, 9 per object here); the other versions name the group in
    `fcurves.new` (no lookup)."""
    channels = addon_module("blender.channels")
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    objects = [keyed(f"Group{i}", seed=i, scale=True) for i in range(4)]
    h.select_only(*objects)
    calls = []
    real = channels.ensure_group
    monkeypatch.setattr(channels, "ensure_group", lambda bag, name: calls.append(name) or real(bag, name))
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert all(fc.group is not None and fc.group.name == "Object Transforms" for o in objects
               for fc in channels.object_fcurves(o))
    slotted_without_group_name = channels.is_slotted(objects[0].animation_data.action) and not channels.NEW_TAKES_GROUP
    print(f"ensure_group calls: {len(calls)} for {len(objects)} actions ({bpy.app.version_string})")
    assert len(calls) == (len(objects) if slotted_without_group_name else 0)
