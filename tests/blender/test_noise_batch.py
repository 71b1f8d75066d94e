"""Remove Noise batched over its owners (issue 27): one read of every owner's curves, one pass
over the scene's objects, one `rotation_channels_near` call per rotation mode and one
`polyscrew.denoise` call per set of key frames for all owners, and the keys written exactly
those of a run on each owner alone.

The scene mixes what the batching must keep apart: objects in every kind of rotation mode
(XYZ and ZXY Euler, quaternion with a keyed sign flip, axis-angle) keyed on two different sets
of frames, a linked duplicate sharing an action, and a rig whose bones have their own modes
(two connected bones, whose location is not read), with keys held by the selection on one
object and one bone.
"""

from __future__ import annotations

import math

import bpy
import numpy as np
import pytest
from mathutils import Euler

import bake_helpers as h
from conftest import addon_module

OBJECT_MODES = ("XYZ", "QUATERNION", "AXIS_ANGLE", "ZXY", "XYZ", "QUATERNION")
BONE_MODES = ("XYZ", "QUATERNION", "AXIS_ANGLE", "YZX", "XYZ", "QUATERNION")
FRAMES_A = [float(f) for f in range(1, 61)]
FRAMES_B = [1.0 + 1.5 * i for i in range(45)]


def noisy_keys(target, frames: list[float], mode: str, rng: np.random.Generator) -> None:
    """Location and rotation (in `mode`) keyed at `frames`: a slow turn and path plus noise."""
    target.rotation_mode = mode
    for i, f in enumerate(frames):
        target.location = (0.5 * math.sin(f / 20) + rng.normal(0, 0.01), 0.3 * math.cos(f / 30) + rng.normal(0, 0.01), f / 100)
        euler = Euler((0.4 * math.sin(f / 25) + rng.normal(0, 0.01), 0.3 * f / 40 + rng.normal(0, 0.01),
                       2.5 * f / 30 + rng.normal(0, 0.01)), "XYZ")
        if mode == "QUATERNION":
            q = euler.to_quaternion()
            target.rotation_quaternion = -q if i % 37 == 5 else q  # a sign flip the animator keyed
            path = "rotation_quaternion"
        elif mode == "AXIS_ANGLE":
            axis, angle = euler.to_quaternion().to_axis_angle()
            target.rotation_axis_angle = (angle, *axis)
            path = "rotation_axis_angle"
        else:
            target.rotation_euler = euler.to_matrix().to_euler(mode)
            path = "rotation_euler"
        target.keyframe_insert("location", frame=f)
        target.keyframe_insert(path, frame=f)


def build() -> list[bpy.types.Object]:
    """The scene (see the module's documentation) in a fresh file; its objects."""
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    rng = np.random.default_rng(3)
    scene = bpy.context.scene
    objects = []
    for i, mode in enumerate(OBJECT_MODES):
        ob = bpy.data.objects.new(f"O{i}", None)
        scene.collection.objects.link(ob)
        noisy_keys(ob, FRAMES_A if i % 3 else FRAMES_B, mode, rng)
        objects.append(ob)
    twin = objects[0].copy()  # a linked duplicate: the same action
    twin.name = "O0 twin"
    scene.collection.objects.link(twin)
    objects.append(twin)
    data = bpy.data.armatures.new("Rig")
    rig = bpy.data.objects.new("Rig", data)
    scene.collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    parent = None
    for j in range(len(BONE_MODES)):
        bone = data.edit_bones.new(f"B{j}")
        bone.head, bone.tail = (0.0, float(j), 0.0), (0.0, j + 1.0, 0.0)
        if parent is not None and j % 2:
            bone.parent, bone.use_connect = parent, True
        parent = bone
    bpy.ops.object.mode_set(mode="OBJECT")
    for pb, mode in zip(rig.pose.bones, BONE_MODES):
        noisy_keys(pb, FRAMES_A, mode, rng)
    objects.append(rig)
    # Keys held by the selection: every other rotation key of O1 and every other key of B2 selected.
    for ob in objects:
        for fc in addon_module("blender.channels").object_fcurves(ob):
            flags = np.zeros(len(fc.keyframe_points), dtype=bool)
            if (ob.name == "O1" and fc.data_path.startswith("rotation")) or '"B2"' in fc.data_path:
                flags[::2] = True
            fc.keyframe_points.foreach_set("select_control_point", flags)
    return objects


def owners_of(objects) -> list:
    owners = addon_module("blender.owners")
    out = []
    for ob in objects:
        if ob.type == "ARMATURE":
            out.extend(owners.Owner(ob, pb.name) for pb in ob.pose.bones)
        else:
            out.append(owners.Owner(ob))
    return out


def written(owner) -> dict:
    """The owner's keys in its action now: co, both handles and their types, bytes per curve."""
    prefix = f'pose.bones["{owner.bone}"].' if owner.bone else ""
    out = {}
    for fc in addon_module("blender.channels").object_fcurves(owner.obj):
        if prefix and not fc.data_path.startswith(prefix) or not prefix and fc.data_path.startswith("pose."):
            continue
        points = fc.keyframe_points
        arrays = []
        for attr, width, kind in (("co", 2, np.float32), ("handle_left", 2, np.float32), ("handle_right", 2, np.float32),
                                  ("handle_left_type", 1, np.uint8), ("handle_right_type", 1, np.uint8)):
            values = np.empty(width * len(points), dtype=kind)
            points.foreach_get(attr, values)
            arrays.append(values.tobytes())
        out[fc.data_path, fc.array_index] = arrays
    return out


@pytest.mark.parametrize("key_mode", ["EVERY_STEP", "REDUCED"])
def test_owners_denoised_together_get_the_keys_each_gets_alone(key_mode):
    """All 13 owners in one run write, bit for bit, the keys a run on each owner alone writes
    (with Keys: Reduced, the objects' keys)."""
    denoise = addon_module("blender.denoise")
    options = denoise.Options(key_mode=key_mode)
    objects = build()
    h.select_only(*objects)
    bpy.context.view_layer.objects.active = objects[-1]
    assert bpy.ops.screwbender.denoise(armature="BOTH", key_mode=key_mode) == {"FINISHED"}
    together = {(o.obj.name, o.bone): written(o) for o in owners_of(objects)}
    # (Reduced keys of a bone depend on the rig's other bones reduced with it: objects only)
    chosen = [k for k, o in enumerate(owners_of(build())) if key_mode == "EVERY_STEP" or not o.bone]
    count = len(chosen)
    changed = 0
    for k in chosen:
        objects = build()
        owner = owners_of(objects)[k]
        before = written(owner)
        result = denoise.remove_noise([owner], options)
        assert result.owners[0] == owner.name and not result.skipped, (owner.name, result.skipped)
        alone = written(owner)
        assert alone == together[owner.obj.name, owner.bone], owner.name
        changed += alone != before
        if owner.obj.name == "O0":  # the linked duplicate shares the result
            twin = bpy.data.objects["O0 twin"]
            assert twin.animation_data.action is owner.obj.animation_data.action
    assert changed == count  # every owner's keys were smoothed
    print(f"Remove Noise ({key_mode}): {count} owners together = each alone, bit for bit")


def test_one_read_one_pass_over_the_objects_one_call_per_mode(monkeypatch):
    """Forty objects (each its own action) in two rotation modes: the curves are read in one
    `curves.read` call, the scene's objects are listed once for all forty actions (one pass
    per action grew as objects x actions), `rotation_channels_near` is called once per mode
    and `polyscrew.denoise` once for the forty."""
    rng = np.random.default_rng(9)
    objects = []
    for i in range(40):
        ob = bpy.data.objects.new(f"Take{i:02d}", None)
        bpy.context.scene.collection.objects.link(ob)
        noisy_keys(ob, FRAMES_A, "XYZ" if i % 2 else "QUATERNION", rng)
        objects.append(ob)
    h.select_only(*objects)
    curves, bake, denoise = (addon_module(f"blender.{m}") for m in ("curves", "bake", "denoise"))
    calls = {"curves.read": 0, "users_by_slot": 0, "rotation_channels_near": 0, "denoise": 0}

    def counted(module, name, label):
        original = getattr(module, name)

        def wrapper(*args, **kwargs):
            calls[label] += 1
            return original(*args, **kwargs)

        monkeypatch.setattr(module, name, wrapper)

    counted(curves, "read", "curves.read")
    counted(bake, "users_by_slot", "users_by_slot")
    counted(denoise.polyscrew, "rotation_channels_near", "rotation_channels_near")
    counted(denoise.polyscrew, "denoise", "denoise")
    before = [ob.animation_data.action for ob in objects]
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    print(f"Remove Noise, 40 objects: {calls}")
    assert calls == {"curves.read": 1, "users_by_slot": 1, "rotation_channels_near": 2, "denoise": 1}
    assert all(ob.animation_data.action is not a for ob, a in zip(objects, before))
