"""Bones are rigid bodies too: pose-bone keys read, smoothed, baked and reverted like objects'."""

from __future__ import annotations

import bpy
import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h

CHAIN = ("Upper", "Fore", "Hand")


def armature(name: str = "Rig", parent: bool = True) -> bpy.types.Object:
    """An armature object with a chain of three bones (the middle one connected to its
    parent), parented to a rotated empty."""
    data = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    if parent:
        holder = h.new_object(f"{name}.parent", "EMPTY")
        holder.location, holder.rotation_euler = (1.0, -2.0, 0.5), (0.3, -0.2, 0.9)
        obj.parent = holder
    h.select_only(obj)
    bpy.ops.object.mode_set(mode="EDIT")
    previous = None
    for i, bone_name in enumerate(CHAIN):
        bone = data.edit_bones.new(bone_name)
        bone.head = (0.0, 0.0, float(i))
        bone.tail = (0.0, 0.1 * i, float(i + 1))
        bone.roll = 0.2 * i
        if previous is not None:
            bone.parent = previous
            bone.use_connect = bone_name == "Fore"  # one connected bone (its location is ignored), one not
        previous = bone
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


def key_bone(obj, bone: str, frames, poses, mode: str, scales=None) -> None:
    pb = obj.pose.bones[bone]
    pb.rotation_mode = mode
    path = h.rotation_path(mode)
    previous = None
    for i, frame in enumerate(frames):
        pb.location = poses[i, :3, 3]
        value = h.continuous(h.rotation_from_matrix(poses[i, :3, :3], mode), previous, mode)
        setattr(pb, path, value)
        previous = value
        pb.keyframe_insert("location", frame=frame)
        pb.keyframe_insert(path, frame=frame)
        if scales is not None:
            pb.scale = scales[i]
            pb.keyframe_insert("scale", frame=frame)


def select_bones(rig, names) -> None:
    """Selects exactly the bones `names` (PoseBone.select from 5.0, Bone.select before)."""
    for pb in rig.pose.bones:
        target = pb if hasattr(pb, "select") else pb.bone
        target.select = pb.name in names


def random_poses(n: int, seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    rot = Rotation.from_rotvec(np.cumsum(rng.normal(0, 0.5, (n, 3)), axis=0))
    return h.rigid(rng.uniform(-0.5, 0.5, (n, 3)), rot.as_matrix())


FRAMES = [1, 6, 14, 20, 33]


@pytest.mark.parametrize("mode", h.ROTATION_MODES)
def test_key_poses_equal_matrix_basis(sb, mode):
    rig = armature()
    for k, bone in enumerate(CHAIN):
        scales = np.random.default_rng(k).uniform(0.6, 1.5, (len(FRAMES), 3))
        key_bone(rig, bone, FRAMES, random_poses(len(FRAMES), 7 * k + len(mode)), mode, scales)
    owners = addon_module_owners()
    for bone in CHAIN:
        motion = sb.keys.read(owners.Owner(rig, bone))
        np.testing.assert_array_equal(motion.frames[motion.is_key], FRAMES)
        scene = bpy.context.scene
        for i, frame in enumerate(motion.frames):  # keys, and poses added inside spins
            scene.frame_set(int(np.floor(frame)), subframe=float(frame - np.floor(frame)))
            basis = np.array(rig.pose.bones[bone].matrix_basis, dtype=np.float64)
            rigid = h.compose(motion.poses[i : i + 1, :3, 3], motion.poses[i : i + 1, :3, :3], motion.scales[i : i + 1])[0]
            assert np.abs(rigid - basis).max() < 1e-5, (bone, frame)


def addon_module_owners():
    from conftest import addon_module

    return addon_module("blender.owners")


def helix_poses(t: np.ndarray, radius=0.7, pitch=0.3) -> np.ndarray:
    """Poses on one screw: a turn of t about the bone's Y axis with a slide pitch * t."""
    rot = Rotation.from_rotvec(np.outer(t, [0.0, 1.0, 0.0])).as_matrix()
    loc = np.stack([radius * np.cos(t), pitch * t, -radius * np.sin(t)], axis=1)  # R_y(t) (r, 0, 0) + slide
    return h.rigid(loc, rot)


def test_bone_on_a_helix_stays_on_it(sb):
    rig = armature()
    frames = [1, 4, 11, 15, 26, 31]
    t = np.array([0.0, 0.5, 1.4, 1.9, 3.1, 3.6])
    key_bone(rig, "Hand", frames, helix_poses(t), "QUATERNION")
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    select_bones(rig, ["Hand"])
    blender = []
    scene = bpy.context.scene
    dense = np.arange(1.0, 32.0)
    for f in dense:
        scene.frame_set(int(f))
        blender.append(np.array(rig.pose.bones["Hand"].matrix_basis))
    assert bpy.ops.screwbender.smooth(scheme="four_point", levels=5, timing="smooth") == {"FINISHED"}
    baked = []
    for f in dense:
        scene.frame_set(int(f))
        baked.append(np.array(rig.pose.bones["Hand"].matrix_basis))
    bpy.ops.object.mode_set(mode="OBJECT")

    def off_helix(matrices):
        m = np.array(matrices)
        angle = np.arctan2(-m[:, 2, 3], m[:, 0, 3])
        angle = np.unwrap(angle)
        expected = helix_poses(angle)
        return np.abs(m - expected).max()

    ours, theirs = off_helix(baked), off_helix(blender)
    print(f"bone on a helix: ScrewBender {ours:.2e}, Blender's own interpolation {theirs:.2e}")
    assert ours < 1e-5
    assert theirs > 1e-2


def test_pose_mode_smooths_only_the_selected_bones(sb):
    rig = armature()
    for k, bone in enumerate(CHAIN):
        key_bone(rig, bone, FRAMES, random_poses(len(FRAMES), k), "XYZ")
    rig["twist"] = 0.0
    rig.keyframe_insert('["twist"]', frame=3)
    rig.location = (0.0, 1.0, 0.0)
    rig.keyframe_insert("location", frame=1)
    source = rig.animation_data.action
    before = h.snapshot_action(source)
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    select_bones(rig, ["Upper", "Hand"])
    motions = {b: sb.keys.read(addon_module_owners().Owner(rig, b)) for b in CHAIN}
    assert bpy.ops.screwbender.smooth(scheme="jarek", levels=3, timing="smooth") == {"FINISHED"}
    smoothed = rig.animation_data.action
    assert smoothed != source
    snap = h.snapshot_action(smoothed)
    old = {c["path"]: c for bag in before["bags"] for c in bag["curves"]}
    new = {c["path"]: c for bag in snap["bags"] for c in bag["curves"]}
    for path, curve in old.items():
        if path[0].startswith('pose.bones["Fore"]') or not path[0].startswith("pose.bones"):
            assert new[path] == curve, path  # other bones and non-bone curves byte for byte
    for bone in ("Upper", "Hand"):  # (both unconnected: their location is baked)
        fc = {c["path"]: c for c in new.values()}[(f'pose.bones["{bone}"].location', 0)]
        frames = np.frombuffer(fc["keys"]["co"], dtype=np.float32)[0::2]
        assert len(frames) == FRAMES[-1] - FRAMES[0] + 1  # dense
        m = motions[bone]
        expected = polyscrew.sample(m.poses, m.frames, frames.astype(np.float64), scheme="jarek", levels=3)
        values = np.frombuffer(fc["keys"]["co"], dtype=np.float32)[1::2]
        assert np.abs(values - expected[:, 0, 3]).max() < 1e-5
    assert h.snapshot_action(source) == before  # the source is untouched
    bpy.ops.object.mode_set(mode="OBJECT")
    h.select_only(rig)
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert rig.animation_data.action == source


def test_object_mode_takes_every_visible_keyed_bone(sb):
    rig = armature()
    for k, bone in enumerate(CHAIN):
        key_bone(rig, bone, FRAMES, random_poses(len(FRAMES), k), "QUATERNION")
    rig.data.bones["Hand"].hide = True
    select_bones(rig, [])
    h.select_only(rig)
    assert bpy.ops.screwbender.smooth(armature="BONES", scheme="jarek", timing="smooth") == {"FINISHED"}
    curves = h.fcurves(rig)
    dense = {fc.data_path for fc in curves if len(fc.keyframe_points) > len(FRAMES)}
    # (Fore is connected to its parent: Blender ignores its location, so it is not baked)
    assert dense == {'pose.bones["Upper"].location', 'pose.bones["Upper"].rotation_quaternion',
                     'pose.bones["Fore"].rotation_quaternion'}


def test_refusals_name_the_bone(sb):
    rig = armature()
    key_bone(rig, "Upper", [3], random_poses(1, 0), "XYZ")
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    select_bones(rig, ["Upper"])
    with pytest.raises(RuntimeError, match=r"Rig: Upper: only one key frame \(3\)"):
        bpy.ops.screwbender.smooth(scheme="jarek", timing="smooth")
    bpy.ops.object.mode_set(mode="OBJECT")
