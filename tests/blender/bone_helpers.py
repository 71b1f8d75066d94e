"""Rigs for the bone tests: armatures with chains of bones, keyed as an animator keys them.

References stay independent of the add-on: key poses are composed from the bone F-curves'
key values with scipy (bake_helpers), world poses come from Blender's own evaluation
(`Object.matrix_world @ PoseBone.matrix`).
"""

from __future__ import annotations

import bpy
import numpy as np
from scipy.spatial.transform import Rotation

import bake_helpers as h


def armature(
    name: str = "Rig", bones=(("Upper", None, False), ("Fore", "Upper", True), ("Hand", "Fore", False)),
    holder: bool = True,
) -> bpy.types.Object:
    """An armature object whose bones are `bones`: (name, parent name or None, connected),
    each one unit long along a slightly tilted Z with a little roll; parented to a rotated
    empty when `holder`. Selected and active, in Object Mode."""
    data = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    if holder:
        parent = h.new_object(f"{name}.parent", "EMPTY")
        parent.location, parent.rotation_euler = (1.0, -2.0, 0.5), (0.3, -0.2, 0.9)
        obj.parent = parent
    h.select_only(obj)
    bpy.ops.object.mode_set(mode="EDIT")
    made = {}
    for i, (bone_name, parent_name, connected) in enumerate(bones):
        bone = data.edit_bones.new(bone_name)
        parent = made.get(parent_name)
        head = np.array(parent.tail) if parent is not None and connected else np.array([0.2 * i, 0.0, float(i)])
        bone.head = tuple(head)
        bone.tail = tuple(head + [0.0, 0.1 * (i + 1), 1.0])
        bone.roll = 0.2 * i
        if parent is not None:
            bone.parent = parent
            bone.use_connect = connected
        made[bone_name] = bone
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


def key_bone(obj, bone: str, frames, poses, mode: str = "XYZ", scales=None) -> None:
    """Keys location (unless the bone is connected), rotation in `mode` and optionally scale."""
    pb = obj.pose.bones[bone]
    pb.rotation_mode = mode
    path = h.rotation_path(mode)
    previous = None
    connected = obj.data.bones[bone].use_connect
    for i, frame in enumerate(frames):
        value = h.continuous(h.rotation_from_matrix(poses[i, :3, :3], mode), previous, mode)
        setattr(pb, path, value)
        previous = value
        pb.keyframe_insert(path, frame=frame)
        if not connected:
            pb.location = poses[i, :3, 3]
            pb.keyframe_insert("location", frame=frame)
        if scales is not None:
            pb.scale = scales[i]
            pb.keyframe_insert("scale", frame=frame)


def random_poses(n: int, seed: int, reach: float = 0.5, gentle: bool = False) -> np.ndarray:
    """`n` random poses (a random walk of rotations); `gentle`: rotations of about 50 degrees
    about axes near one direction, so that no rotation channel (axis-angle included) turns by
    half a turn between keys, which Smooth Motion would keep as a spin."""
    rng = np.random.default_rng(seed)
    if gentle:
        rot = Rotation.from_rotvec([0.7, 0.4, 0.3] + rng.normal(0, 0.15, (n, 3)))
    else:
        rot = Rotation.from_rotvec(np.cumsum(rng.normal(0, 0.5, (n, 3)), axis=0))
    return h.rigid(rng.uniform(-reach, reach, (n, 3)), rot.as_matrix())


def select_bones(rig, names) -> None:
    """Selects exactly the bones `names` (PoseBone.select from 5.0, Bone.select before)."""
    for pb in rig.pose.bones:
        target = pb if hasattr(pb, "select") else pb.bone
        target.select = pb.name in names


def bone_path(bone: str, prop: str) -> str:
    return f'pose.bones["{bone}"].{prop}'


def bone_key_matrices(rig, bone: str, with_scale: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(frames, (N, 4, 4)) composed with scipy from the bone's F-curve key values (no
    translation for a connected bone: Blender ignores its location)."""
    pb = rig.pose.bones[bone]
    mode = pb.rotation_mode
    size = 4 if mode in h.ROTATION_PATH else 3
    frames, rotation = h.channel(rig, bone_path(bone, h.rotation_path(mode)), size)
    if rig.data.bones[bone].use_connect:
        location = np.zeros((len(frames), 3))
    else:
        loc_frames, location = h.channel(rig, bone_path(bone, "location"), 3)
        np.testing.assert_array_equal(loc_frames, frames)
    scale = h.channel(rig, bone_path(bone, "scale"), 3)[1] if with_scale else None
    return frames, h.compose(location, h.rotation_to_matrices(rotation, mode), scale)


def world_pose(rig, bone: str) -> np.ndarray:
    """Blender's own world matrix of a bone at the current frame (head, axes, scale)."""
    return np.array(rig.matrix_world, dtype=np.float64) @ np.array(rig.pose.bones[bone].matrix, dtype=np.float64)
