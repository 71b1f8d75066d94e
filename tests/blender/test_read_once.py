"""Issue 27: Remove Noise, Build Swept Region and the live preview read each F-curve's keys
once per run (one `bulk.get` per keyframe property and curve), counted by
`read_count.counting_reads()` around a real run of each.

Every test also checks that the curves were read at all (a run that reads nothing would pass
`read_more_than_once(reads) == {}`) and that the run did its work.
"""

from __future__ import annotations

import math

import bpy
import numpy as np

import bake_helpers as h
from bone_helpers import armature, key_bone, random_poses, select_bones
from conftest import addon_module
from read_count import counting_reads, read_more_than_once

FRAMES = 60


def dense_noisy_keys(obj, seed: int, prefix: str = "") -> None:
    """Location and XYZ Euler keyed on every frame 1..FRAMES: a slow sway plus noise."""
    rng = np.random.default_rng(seed)
    t = np.arange(1, FRAMES + 1, dtype=np.float64)
    target = obj.pose.bones[prefix] if prefix else obj
    target.rotation_mode = "XYZ"
    for frame in (1, FRAMES):
        target.keyframe_insert("location", frame=frame)
        target.keyframe_insert("rotation_euler", frame=frame)
    path = f'pose.bones["{prefix}"].' if prefix else ""
    co = np.empty(2 * FRAMES, dtype=np.float32)
    co[0::2] = t
    for fc in addon_module("blender.channels").object_fcurves(obj):
        if not fc.data_path.startswith(path) or fc.data_path[len(path):] not in ("location", "rotation_euler"):
            continue
        rotation = "rotation" in fc.data_path
        truth = (0.4 if rotation else 0.5) * np.sin(t / 15.0 + fc.array_index + seed)
        co[1::2] = truth + rng.normal(0.0, math.radians(0.5) if rotation else 0.01, FRAMES)
        points = fc.keyframe_points
        points.add(FRAMES - len(points))
        points.foreach_set("co", co)
        points.foreach_set("select_control_point", np.zeros(FRAMES, dtype=bool))
        fc.update()


def curve_keys(obj) -> dict:
    """(data path, index) -> key values of the object's action."""
    out = {}
    for fc in addon_module("blender.channels").object_fcurves(obj):
        co = np.empty(2 * len(fc.keyframe_points), dtype=np.float32)
        fc.keyframe_points.foreach_get("co", co)
        out[fc.data_path, fc.array_index] = co[1::2].copy()
    return out


def source_curve_reads(reads, action, prop: str = "co") -> dict:
    """Per curve of `action` (or the action named so): how many times its keyframe property
    `prop` (the key coordinates) was read."""
    named = action if isinstance(action, str) else action.name
    return {(path, index): n for (name, path, index, attr), n in
            ((k, n) for k, n in reads.items() if len(k) == 4) if name == named and attr == prop}


def test_remove_noise_on_objects_reads_each_curve_once():
    """Three objects, two of them linked duplicates sharing one action: every source curve's
    keys read once, and every key moved."""
    objects = []
    for i, name in enumerate(("Cam", "Prop")):
        ob = bpy.data.objects.new(name, None)
        bpy.context.scene.collection.objects.link(ob)
        dense_noisy_keys(ob, seed=i + 1)
        objects.append(ob)
    twin = objects[1].copy()  # a linked duplicate: the same action
    twin.name = "Prop twin"
    bpy.context.scene.collection.objects.link(twin)
    objects.append(twin)
    sources = {ob.animation_data.action for ob in objects}
    before = {ob.name: curve_keys(ob) for ob in objects}
    h.select_only(*objects)
    with counting_reads() as reads:
        assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    print(f"Remove Noise, objects: {sum(reads.values())} reads, more than once: {read_more_than_once(reads)}")
    assert read_more_than_once(reads) == {}
    for action in sources:  # each source curve read (once)
        counted = source_curve_reads(reads, action)
        assert len(counted) == 6 and set(counted.values()) == {1}, (action.name, counted)
    for ob in objects:  # and smoothed
        after = curve_keys(ob)
        assert ob.animation_data.action not in sources
        assert all(np.abs(after[k] - before[ob.name][k]).max() > 1e-4 for k in after), ob.name


def test_remove_noise_run_again_on_its_result_reads_each_curve_once():
    """A rerun starts from the original keys under the result shown: the original curves, the
    result's and its new copy's are each read once (and the keys come out as the first run's)."""
    ob = bpy.data.objects.new("Cam", None)
    bpy.context.scene.collection.objects.link(ob)
    dense_noisy_keys(ob, seed=3)
    original = ob.animation_data.action
    h.select_only(ob)
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    first, shown = curve_keys(ob), ob.animation_data.action.name  # (removed once replaced)
    with counting_reads() as reads:
        assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    print(f"Remove Noise again: {sum(reads.values())} reads, more than once: {read_more_than_once(reads)}")
    assert read_more_than_once(reads) == {}
    # the original keys (smoothed again), the selection on the result shown
    for action, prop in ((original.name, "co"), (shown, "select_control_point")):
        counted = source_curve_reads(reads, action, prop)
        assert len(counted) == 6 and set(counted.values()) == {1}, (action, prop, counted)
    assert ob.animation_data.action is not original
    again = curve_keys(ob)
    for k, values in first.items():
        np.testing.assert_array_equal(again[k], values)


def test_remove_noise_on_a_rig_in_pose_mode_with_a_key_selection_reads_each_curve_once():
    """Three bones keyed on every frame, Pose Mode, two bones selected, keys selected on
    frames 11..50 only: each curve read once; the unselected keys held exactly."""
    rig = armature(bones=(("Upper", None, False), ("Fore", "Upper", False), ("Hand", "Fore", False)), holder=False)
    for i, bone in enumerate(("Upper", "Fore", "Hand")):
        dense_noisy_keys(rig, seed=10 + i, prefix=bone)
    for fc in addon_module("blender.channels").object_fcurves(rig):
        flags = np.zeros(FRAMES, dtype=bool)
        flags[10:50] = True
        fc.keyframe_points.foreach_set("select_control_point", flags)
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    select_bones(rig, ("Fore", "Hand"))
    source = rig.animation_data.action
    before = curve_keys(rig)
    with counting_reads() as reads:
        assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    print(f"Remove Noise, rig in Pose Mode: {sum(reads.values())} reads, more than once: {read_more_than_once(reads)}")
    assert read_more_than_once(reads) == {}
    counted = source_curve_reads(reads, source)
    assert {path.split('"')[1] for path, _ in counted} == {"Fore", "Hand"}, counted
    assert len(counted) == 12 and set(counted.values()) == {1}, counted
    after = curve_keys(rig)
    for (path, index), values in after.items():
        was = before[path, index]
        if "Upper" in path:
            np.testing.assert_array_equal(values, was)  # not selected: not touched
            continue
        np.testing.assert_array_equal(values[:10], was[:10])  # held: unselected keys
        np.testing.assert_array_equal(values[50:], was[50:])
        assert np.abs(values[10:50] - was[10:50]).max() > 1e-4, path


def box(name: str) -> bpy.types.Object:
    mesh = bpy.data.meshes.new(name)
    corners = [(x, y, z) for z in (-0.2, 0.2) for y in (-0.3, 0.3) for x in (-0.1, 0.1)]
    faces = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
    mesh.from_pydata(corners, [], faces)
    ob = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(ob)
    return ob


def test_build_swept_region_reads_each_curve_and_mesh_once():
    """Two linked duplicates sharing a smoothed action and two boxes parented to two bones of
    one smoothed rig: each key curve read once; each source mesh read once (the new meshes
    are measured from what was written, not read back: the same area as Blender's mesh)."""
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 24
    body = box("Body")
    for frame, x in ((1, 0.0), (12, 1.0), (24, 2.5)):
        body.location = (x, 0.2 * x, 0.0)
        body.rotation_euler = (0.1 * x, 0.0, 0.5 * x)
        body.keyframe_insert("location", frame=frame)
        body.keyframe_insert("rotation_euler", frame=frame)
    h.select_only(body)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    twin = body.copy()  # shares the mesh and the smoothed action
    twin.name = "Body twin"
    scene.collection.objects.link(twin)
    rig = armature(bones=(("Arm", None, False), ("Hand", "Arm", False)), holder=False)
    key_bone(rig, "Arm", [1, 12, 24], random_poses(3, 4, reach=0.0))
    key_bone(rig, "Hand", [1, 10, 24], random_poses(3, 9, reach=0.3))
    h.select_only(rig)
    assert bpy.ops.screwbender.smooth(armature="BOTH") == {"FINISHED"}
    props = []
    for bone in ("Arm", "Hand"):
        prop = box(f"Prop {bone}")
        prop.parent, prop.parent_type, prop.parent_bone = rig, "BONE", bone
        props.append(prop)
    sources = [body, twin, *props]
    h.select_only(*sources)
    with counting_reads() as reads:
        assert bpy.ops.screwbender.sweep(closed=False) == {"FINISHED"}  # the reads are the same closed
    print(f"Build Swept Region: {dict(reads)}")
    assert read_more_than_once(reads) == {}
    for action in (body.animation_data.action, rig.animation_data.action):
        counted = source_curve_reads(reads, action)
        assert counted and set(counted.values()) == {1}, (action.name, counted)
    assert reads["MeshVertices", "co"] == len(sources)  # each source's evaluated mesh, none read back
    created = bpy.data.collections["Swept Regions"].objects
    assert len(created) == len(sources)
    swept = addon_module("blender.swept")
    for ob in created:  # the area stored is the mesh's own
        area = addon_module("pure.sweep_report").measures(*swept.mesh_triangles(ob.data)).area
        assert math.isclose(ob["screwbender_area"], area, rel_tol=1e-12), (ob.name, ob["screwbender_area"], area)


def test_the_preview_refresh_on_many_objects_reads_each_curve_once():
    """Twenty previewed objects, ten of them linked duplicates of the other ten: a first
    refresh computes every preview, a refresh after a key edit recomputes one, a refresh
    with no change recomputes none; each reads each curve's keys once."""
    pd = addon_module("ops.preview_draw")
    scene = bpy.context.scene
    objects = []
    for i in range(10):
        ob = bpy.data.objects.new(f"Body{i:02d}", None)
        scene.collection.objects.link(ob)
        for frame, x in ((1, 0.0), (9, 1.0 + i), (20, 2.0)):
            ob.location = (x, 0.1 * i, 0.0)
            ob.rotation_euler = (0.0, 0.2 * x, 0.3 * i)
            ob.keyframe_insert("location", frame=frame)
            ob.keyframe_insert("rotation_euler", frame=frame)
        twin = ob.copy()
        twin.name = f"Twin{i:02d}"
        scene.collection.objects.link(twin)
        objects += [ob, twin]
    try:
        for ob in objects:
            ob.screwbender_preview = True
        actions = {ob.animation_data.action for ob in objects}
        counts = []
        for step in ("first", "edited", "unchanged"):
            if step == "edited":
                fc = addon_module("blender.channels").object_fcurves(objects[0])[0]
                fc.keyframe_points[1].co.y += 0.5
                fc.update()
            before = dict(pd.CACHE.recomputed)
            with counting_reads() as reads:
                pd.refresh(scene)
            recomputed = {n: c - before.get(n, 0) for n, c in pd.CACHE.recomputed.items() if c != before.get(n, 0)}
            counts.append((step, len(recomputed), sum(reads.values())))
            assert read_more_than_once(reads) == {}, step
            for action in actions:  # every curve read (once)
                counted = source_curve_reads(reads, action)
                assert len(counted) == 6 and set(counted.values()) == {1}, (step, action.name, counted)
            expected = {"first": 20, "edited": 2, "unchanged": 0}[step]  # the edit changes both sharers
            assert len(recomputed) == expected, (step, recomputed)
            assert all(pd.CACHE.entries[ob.session_uid].batches is not None for ob in objects)
        print(f"preview refreshes (step, recomputed, reads): {counts}")
    finally:
        for ob in objects:
            ob.screwbender_preview = False
