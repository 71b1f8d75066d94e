"""All or nothing: every operator that writes, failing halfway through its writing (a failure
injected into the add-on's own write calls), leaves `bpy.data` exactly as it was: no new
action, object, mesh or curve, no added key, the same assignments, fake users, custom
properties and selection."""

from __future__ import annotations

import contextlib

import bpy
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h
from conftest import addon_module


class Injected(RuntimeError):
    """The failure a test injects."""


@contextlib.contextmanager
def fail_on_call(module_name: str, function: str, call: int):
    """Makes `module.function` raise :class:`Injected` on its `call`-th call (the earlier
    calls run normally, so the operator has already written something); yields the counter."""
    module = addon_module(module_name)
    original = getattr(module, function)
    calls = {"n": 0}

    def wrapper(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == call:
            raise Injected(f"injected failure in {function}, call {call}")
        return original(*args, **kwargs)

    setattr(module, function, wrapper)
    try:
        yield calls
    finally:
        setattr(module, function, original)


@contextlib.contextmanager
def fail_after_call(module_name: str, function: str, call: int):
    """Makes `module.function` raise :class:`Injected` right after its `call`-th call has
    returned (everything that call wrote is there to be undone); yields the counter."""
    module = addon_module(module_name)
    original = getattr(module, function)
    calls = {"n": 0}

    def wrapper(*args, **kwargs):
        calls["n"] += 1
        result = original(*args, **kwargs)
        if calls["n"] == call:
            raise Injected(f"injected failure after {function}, call {call}")
        return result

    setattr(module, function, wrapper)
    try:
        yield calls
    finally:
        setattr(module, function, original)


def keyed(name: str, mode: str = "XYZ", offset: float = 0.0, scale: bool = True):
    obj = h.new_object(name, "MESH", mode)
    frames = [1, 9, 17, 30]
    rot = Rotation.from_euler("xyz", [[0, 0, 0], [0.4, 0.1, 1.0], [0.2, 0.7, 2.0], [0.1, 0.1, 2.8]])
    poses = h.rigid(np.array([[0, 0, 0], [1, 2, 0], [3, 1, 1], [4, 0, 0]]) + offset, rot.as_matrix())
    scales = np.array([[1, 1, 1], [1.5, 1, 1], [1, 2, 1], [1, 1, 0.5]]) if scale else None
    h.key_poses(obj, frames, poses, scales)
    obj["weight"] = 1.0
    obj.keyframe_insert('["weight"]', frame=5)
    return obj


def check_unchanged(run, match="nothing was changed"):
    before = h.snapshot_data(key_selection=True)
    with pytest.raises(RuntimeError, match=match):
        run()
    after = h.snapshot_data(key_selection=True)
    assert after == before


def test_smooth_motion(sb):
    a, b = keyed("A"), keyed("B", offset=1.0)
    h.select_only(a, b)
    # 10 curves per object (location, Euler, scale): the 14th is B's 4th
    with fail_on_call("blender.channels", "new_fcurve", 14) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.smooth())
    assert calls["n"] == 14  # it failed halfway: A was written, B half
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}  # and works afterwards


def test_smooth_motion_resmoothing_a_result(sb):
    a = keyed("A")
    h.select_only(a)
    assert bpy.ops.screwbender.smooth(scheme="bspline") == {"FINISHED"}
    with fail_on_call("blender.channels", "new_fcurve", 5) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.smooth(scheme="four_point"))
    assert calls["n"] == 5


def test_revert(sb):
    a, b = keyed("A"), keyed("B", offset=1.0)
    h.select_only(a, b)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    with fail_on_call("blender.channels", "assign", 2) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.revert())
    assert calls["n"] >= 2  # (the undoing assigns the old actions again)


def test_apply_preview(sb):
    a, b = keyed("A"), keyed("B", offset=1.0)
    for obj in (a, b):
        obj.screwbender_preview = True
    h.select_only(a, b)
    with fail_on_call("blender.channels", "new_fcurve", 14) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.preview_apply())
    assert calls["n"] == 14
    for obj in (a, b):
        obj.screwbender_preview = False
    addon_module("ops.preview_draw").sync()


def test_insert_key_on_motion(sb):
    a, b = keyed("A"), keyed("B", offset=1.0)
    h.select_only(a, b)
    bpy.context.scene.frame_set(13)
    # 9 keyed channels per object: the 12th insertion is B's 3rd
    with fail_on_call("blender.channels", "insert_key", 12) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.insert_key())
    assert calls["n"] == 12


def test_insert_key_on_motion_new_curve(sb):
    """The first insertion adds a curve (location keyed, rotation not): it goes again."""
    obj = h.new_object("Mover", "MESH", "XYZ")
    for frame, x in ((1, 0.0), (10, 2.0), (20, 3.0)):
        obj.location = (x, 0.0, 0.0)
        obj.keyframe_insert("location", frame=frame)
    h.select_only(obj)
    bpy.context.scene.frame_set(5)
    with fail_on_call("blender.channels", "insert_key", 5) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.insert_key())
    assert calls["n"] == 5


def test_fit_angular_velocity(sb):
    obj = keyed("Top", mode="QUATERNION", scale=False)
    h.select_only(obj)
    assert bpy.ops.screwbender.add_angular_velocity_sketch() == {"FINISHED"}
    h.select_only(obj)
    with fail_on_call("blender.angvel", "_set_curve_points", 1) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.fit_angular_velocity())
    assert calls["n"] == 1
    # a second fit replaces the first fit's curve data: also undone when it fails
    assert bpy.ops.screwbender.fit_angular_velocity() == {"FINISHED"}
    with fail_on_call("blender.angvel", "_set_curve_points", 1):
        check_unchanged(lambda: bpy.ops.screwbender.fit_angular_velocity())


def test_add_angular_velocity_sketch(sb):
    obj = keyed("Top", mode="QUATERNION", scale=False)
    h.select_only(obj)
    with fail_on_call("blender.angvel", "_set_curve_points", 1) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.add_angular_velocity_sketch())
    assert calls["n"] == 1


def test_add_angular_velocity_sketch_after_its_last_write(sb):
    """A failure once the sketch is made and recorded on the object (t.set_item): the
    record, the sphere, the sketch and its curves all go."""
    obj = keyed("Top", mode="QUATERNION", scale=False)
    h.select_only(obj)
    with fail_after_call("ops.angvel_ops", "add_sketch", 1) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.add_angular_velocity_sketch())
    assert calls["n"] == 1
    assert addon_module("blender.angvel").SPHERE_KEY not in obj


def test_build_swept_region_into_an_unlinked_collection(sb):
    """An existing "Swept Regions" collection that is not in the scene: the sweep links it,
    and a failure unlinks it again."""
    bpy.data.collections.new(addon_module("blender.swept").COLLECTION)
    a, b = keyed("A", scale=False), keyed("B", offset=3.0, scale=False)
    h.select_only(a, b)
    with fail_on_call("blender.swept", "mesh_from_arrays", 2) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.sweep(closed=False))
    assert calls["n"] == 2
    assert addon_module("blender.swept").COLLECTION not in bpy.context.scene.collection.children


def test_build_swept_region(sb):
    a, b = keyed("A", scale=False), keyed("B", offset=3.0, scale=False)
    h.select_only(a, b)
    with fail_on_call("blender.swept", "mesh_from_arrays", 2) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.sweep(closed=False))
    assert calls["n"] == 2


def test_check_clearance(sb):
    a, b = keyed("A", scale=False), keyed("B", offset=3.0, scale=False)
    h.select_only(a)
    assert bpy.ops.screwbender.sweep(closed=False) == {"FINISHED"}  # open meshes: the open sweep
    region = bpy.context.view_layer.objects.active
    h.select_only(region, b)
    with fail_on_call("blender.swept", "select_faces", 2) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.check_clearance())
    assert calls["n"] == 2
