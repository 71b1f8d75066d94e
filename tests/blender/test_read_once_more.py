"""Issue 27, the remaining operators: Insert Key on Motion reads each F-curve's keys once per
run (`read_count.counting_reads()` around a real run), its report still measures the motion
Blender plays after the insertion, and its cost per bone does not grow with the rig.

Every test checks that the curves were read at all (a run that reads nothing would pass
`read_more_than_once(reads) == {}`) and that the run did its work.
"""

from __future__ import annotations

import bpy
import numpy as np

import bake_helpers as h
from bone_helpers import armature, key_bone, random_poses, select_bones
from conftest import addon_module
from read_count import counting_reads, read_more_than_once
from test_read_once import source_curve_reads


def keyed_object(name: str, offset: float, cyclic: bool = False) -> bpy.types.Object:
    """Location, XYZ Euler and scale keyed on four uneven frames (Blender's auto-clamped
    handles); `cyclic`: a Cycles modifier on every curve (cycle-aware handles)."""
    obj = h.new_object(name, "MESH", "XYZ")
    frames = [1, 9, 17, 30]
    poses = h.rigid(np.array([[0, 0, 0], [1, 2, 0], [3, 1, 1], [4, 0, 0]]) + offset,
                    h.rotation_to_matrices(np.array([[0, 0, 0], [0.4, 0.1, 1.0], [0.2, 0.7, 2.0], [0.1, 0.1, 2.8]]), "XYZ"))
    h.key_poses(obj, frames, poses, np.array([[1, 1, 1], [1.5, 1, 1], [1, 2, 1], [1, 1, 0.5]]))
    if cyclic:
        for fc in h.fcurves(obj):
            fc.modifiers.new("CYCLES")
    return obj


def keys_of(obj) -> dict:
    """(data path, index) -> (co, left handle, right handle) of every key of obj's action."""
    out = {}
    for fc in h.fcurves(obj):
        n = len(fc.keyframe_points)
        arrays = []
        for name in ("co", "handle_left", "handle_right"):
            values = np.empty(2 * n, dtype=np.float32)
            fc.keyframe_points.foreach_get(name, values)
            arrays.append(values.reshape(-1, 2))
        out[fc.data_path, fc.array_index] = tuple(arrays)
    return out


def test_insert_key_on_motion_reads_each_curve_once():
    """Two objects (one with cyclic curves) and a rig of three bones in Pose Mode: Insert Key
    on Motion reads each source curve's keys once (on 6a217ff: three times: the keys, the
    undo snapshot, the keys again after the insertion), and keys every channel. Only the
    handles of curves with Auto Handle Smoothing are read a second time, after the insertion
    (Blender may have moved all of them); with smoothing off, nothing is read twice."""
    objects = [keyed_object("Cam", 0.0), keyed_object("Loop", 1.0, cyclic=True), keyed_object("Still", 2.0)]
    for fc in h.fcurves(objects[2]):
        fc.auto_smoothing = "NONE"
        fc.update()  # (its handles recomputed so, as the UI does)
    rig = armature(bones=(("Upper", None, False), ("Fore", "Upper", False), ("Hand", "Fore", False)), holder=False)
    for i, bone in enumerate(("Upper", "Fore", "Hand")):
        key_bone(rig, bone, [1, 11, 30], random_poses(3, 20 + i, reach=0.4))
    bpy.context.scene.frame_set(14)
    counted_runs = []
    for selection in ("objects", "bones"):
        if selection == "objects":
            h.select_only(*objects)
            owners_ = objects
        else:
            h.select_only(rig)
            bpy.ops.object.mode_set(mode="POSE")
            select_bones(rig, ("Fore", "Hand"))
            owners_ = [rig]
        before = {ob.name: keys_of(ob) for ob in owners_}
        with counting_reads() as reads:
            assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
        if selection == "bones":
            bpy.ops.object.mode_set(mode="OBJECT")
        print(f"Insert Key on Motion, {selection}: {sum(reads.values())} reads, more than once: {read_more_than_once(reads)}")
        counted_runs.append(sum(reads.values()))
        # Blender's default Auto Handle Smoothing (Continuous Acceleration) may move every
        # handle of a curve when a key is inserted: the handles are read again after it, once.
        again = read_more_than_once(reads)
        assert {k[3] for k in again} <= {"handle_left", "handle_right"} and set(again.values()) <= {2}, again
        assert all(fc.auto_smoothing != "NONE" for ob in owners_ for fc in h.fcurves(ob)
                   if (ob.animation_data.action.name, fc.data_path, fc.array_index, "handle_left") in again)
        if selection == "objects":  # smoothing off: nothing read twice
            assert not [k for k in again if k[0] == objects[2].animation_data.action.name], again
        for ob in owners_:
            counted = source_curve_reads(reads, ob.animation_data.action)
            keyed = {k: v for k, v in keys_of(ob).items() if len(v[0]) != len(before[ob.name][k][0])}
            if selection == "objects":
                assert len(counted) == 9 and set(counted.values()) == {1}, (ob.name, counted)
                assert len(keyed) == 9, ob.name  # one key more on every channel
            else:  # the two selected bones: 6 curves each (location, Euler)
                assert {path.split('"')[1] for path, _ in counted} == {"Fore", "Hand"}, counted
                assert len(counted) == 12 and set(counted.values()) == {1}, counted
                assert {path.split('"')[1] for path, _ in keyed} == {"Fore", "Hand"} and len(keyed) == 12
            for co, _, _ in (v for k, v in keys_of(ob).items() if k in keyed):
                assert np.any(np.abs(co[:, 0] - 14.0) < 1e-6)
    print(f"Insert Key on Motion reads (objects, bones): {counted_runs}")


def test_insert_key_reports_the_motion_blender_plays_after_the_insertion():
    """The motion after the insertion is the first read with the new keys spliced in (the new
    key and the neighbours' recomputed handles read back one by one): the keys it holds equal
    Blender's curves read afresh, and the figures reported equal those measured from a fresh
    read, for plain and cyclic curves, with Auto Handle Smoothing and without (only the new
    key's neighbours read back), a key inserted between keys, on a key and on a subframe."""
    ik, keys, bake = addon_module("blender.insert_key"), addon_module("blender.keys"), addon_module("blender.bake")
    transaction, preview_draw = addon_module("blender.transaction"), addon_module("ops.preview_draw")
    options = preview_draw.smooth_options(bpy.context.scene)
    for cyclic, smoothing in ((False, "CONT_ACCEL"), (True, "CONT_ACCEL"), (False, "NONE"), (True, "NONE")):
        obj = keyed_object(f"{'Cyclic' if cyclic else 'Plain'} {smoothing}", 0.0, cyclic=cyclic)
        for fc in h.fcurves(obj):
            fc.auto_smoothing = smoothing
            fc.update()
        for frame in (14.0, 9.0, 23.5):  # between keys, on a key (replaced), a subframe
            source = obj.animation_data.action.copy()
            spliced = {}
            original = ik._spliced

            def spy(fcurve, before, at, original=original, spliced=spliced):
                out = original(fcurve, before, at)
                spliced[fcurve.data_path, fcurve.array_index] = out
                return out

            ik._spliced = spy
            try:
                with transaction.atomic() as t:
                    result = ik.insert_key(obj, frame, options, t)
            finally:
                ik._spliced = original
            fresh = keys_of(obj)
            assert len(spliced) == 9
            for key, packed in spliced.items():  # what the run holds is what Blender has
                for name, got in zip(("co", "handle_left", "handle_right"), fresh[key]):
                    np.testing.assert_array_equal(getattr(packed, name), got, err_msg=f"{key} {name} at {frame}")
            owner = addon_module("blender.owners").Owner(obj)
            slot = addon_module("blender.channels").slot_identifier(obj)
            was = keys.read(owner, options.closed, action=source, slot=slot, turns=options.turns)
            now = keys.read(owner, options.closed, turns=options.turns)
            a, _ = bake.sample_poses(was, result.checked_frames, options, owner)
            b, _ = bake.sample_poses(now, result.checked_frames, options, owner)
            translation, angle = ik.pose_change(a, b)
            print(f"{obj.name} at {frame}: moved {result.max_translation:.3g}, turned {result.max_angle:.3g} "
                  f"(fresh read: {translation.max():.3g}, {angle.max():.3g})")
            assert result.max_translation == translation.max() and result.max_angle == angle.max()
            assert result.max_translation > 0.0 or frame == 9.0


def test_insert_key_on_a_rig_does_the_same_work_per_bone_at_any_size():
    """Insert Key on Motion on every bone of rigs of 10 and 40 bones: the add-on lists each
    action's curves once per run (no scan of all curves per bone: what made it grow as
    bones^1.46), so the curves it touches grow linearly with the bones."""
    channels = addon_module("blender.channels")
    listed = []
    original = channels.object_fcurves

    def counting(obj, original=original):
        out = original(obj)
        listed.append(len(out))
        return out

    per_bone = []
    for bones in (10, 40):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        rig = armature(bones=tuple((f"B{i:02d}", f"B{i - 1:02d}" if i % 5 else None, False) for i in range(bones)),
                       holder=False)
        for i in range(bones):
            key_bone(rig, f"B{i:02d}", [1, 11, 30], random_poses(3, i, reach=0.2))
        bpy.context.scene.frame_set(14)
        h.select_only(rig)
        listed.clear()
        channels.object_fcurves = counting
        try:
            assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
        finally:
            channels.object_fcurves = original
        per_bone.append(sum(listed) / bones)
        keyed = sum(len(fc.keyframe_points) == 4 for fc in h.fcurves(rig))
        assert keyed == 6 * bones, (bones, keyed)
    print(f"curves listed per bone (10, 40 bones): {per_bone}")
    assert per_bone[1] <= per_bone[0] * 1.01, per_bone


def test_the_preview_refresh_reads_every_objects_curves_in_one_pass():
    """Twelve previewed objects and a rig of three previewed bones: a refresh reads all their
    curves in one `curves.read` call (on 6a217ff: one per owner), and the key hashes and
    previews equal those of owners read one by one."""
    pd, curves = addon_module("ops.preview_draw"), addon_module("blender.curves")
    scene = bpy.context.scene
    objects = [keyed_object(f"Previewed{i:02d}", 0.3 * i) for i in range(12)]
    rig = armature("Previewed rig", bones=(("Upper", None, False), ("Fore", "Upper", False), ("Hand", "Fore", False)),
                   holder=False)  # (names of their own: preview_draw.CACHE counts recomputes by name)
    for i, bone in enumerate(("Upper", "Fore", "Hand")):
        key_bone(rig, bone, [1, 11, 30], random_poses(3, 30 + i, reach=0.4))
    calls = []
    original = curves.read

    def counting(fcurves, keys_only=False, original=original):
        calls.append(len(fcurves))
        return original(fcurves, keys_only)

    previewed = [*objects, rig]
    try:
        for ob in previewed:
            ob.screwbender_preview = True
        pd.CACHE.forget()
        curves.read = counting
        try:
            pd.refresh(scene)
        finally:
            curves.read = original
        together = {k: (e.digest, e.batches) for k, e in pd.CACHE.entries.items()}
        print(f"curves.read calls in one refresh of {len(previewed)} objects: {calls}")
        assert calls == [12 * 9 + 3 * 6], calls  # every owner's curves, once, in one call
        assert len(together) == 15 and all(b is not None for _, b in together.values())
        pd.CACHE.forget()
        preview = addon_module("blender.preview")
        alone = preview.read_together
        preview.read_together = lambda pairs, memo: None  # each owner reads its own curves
        try:
            pd.refresh(scene)
        finally:
            preview.read_together = alone
        for key, entry in pd.CACHE.entries.items():
            digest, batches = together[key]
            assert entry.digest == digest, key
            np.testing.assert_array_equal(entry.batches.instances, batches.instances)
            np.testing.assert_array_equal(entry.batches.trajectory, batches.trajectory)
    finally:
        for ob in previewed:
            ob.screwbender_preview = False
