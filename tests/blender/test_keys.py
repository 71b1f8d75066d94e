"""Reading keys: the key poses equal Blender's own `matrix_basis` at the key frames."""

from __future__ import annotations

import bpy
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h

#: matrix_basis is computed by Blender in single precision.
BASIS_TOLERANCE = 2e-6

FRAMES = [1.0, 4.0, 11.0, 12.5, 30.0]  # uneven, one subframe


def random_keys(seed: int, n: int = len(FRAMES)):
    rng = np.random.default_rng(seed)
    rotations = Rotation.random(n, random_state=seed).as_matrix()
    poses = h.rigid(rng.uniform(-3, 3, (n, 3)), rotations)
    scales = rng.uniform(0.5, 2.0, (n, 3))
    return poses, scales


def parented(mode: str, kind: str = "MESH"):
    parent = h.new_object("Parent", "EMPTY")
    parent.location = (1.0, -2.0, 0.5)
    parent.rotation_euler = (0.3, -0.2, 1.1)
    parent.scale = (2.0, 1.0, 0.5)
    obj = h.new_object("Body", kind, mode)
    obj.parent = parent
    h.select_only(obj)
    return obj


@pytest.mark.parametrize("mode", h.ROTATION_MODES)
def test_key_poses_equal_matrix_basis(sb, mode):
    obj = parented(mode)
    poses, scales = random_keys(seed=len(mode))
    h.key_poses(obj, FRAMES, poses, scales)
    motion = sb.keys.read(obj)

    # the animator's keys, and poses of Blender's playback added inside spans turning over
    # 150 degrees (random keys do): every one equals matrix_basis at its frame
    np.testing.assert_allclose(motion.frames[motion.is_key], FRAMES)
    assert motion.rotation_mode == mode and motion.scale_keyed and not motion.closed
    basis = h.evaluated_basis(obj, motion.frames)
    read = h.compose(motion.poses[:, :3, 3], motion.poses[:, :3, :3], motion.scales)
    error = np.abs(read - basis).max()
    print(f"{bpy.app.version_string} {mode}: max |read - matrix_basis| = {error:.2e}")
    assert error < BASIS_TOLERANCE
    # the poses handed to polyscrew are rigid
    rot = motion.poses[:, :3, :3]
    np.testing.assert_allclose(rot @ rot.transpose(0, 2, 1), np.broadcast_to(np.eye(3), rot.shape), atol=1e-12)
    # and the world matrix is the parent's times that basis (the object's own space)
    world = np.array(bpy.context.scene.objects["Parent"].matrix_world) @ np.array(obj.matrix_parent_inverse)
    np.testing.assert_allclose(np.array(obj.matrix_world), world @ basis[-1], atol=1e-5)


@pytest.mark.parametrize("kind", ["EMPTY", "CAMERA", "LIGHT"])
def test_channels_keyed_on_different_frames(sb, kind):
    """Location keyed on some frames, rotation on others: the union, each channel evaluated."""
    obj = parented("YZX", kind)
    poses, _ = random_keys(seed=7, n=4)
    for frame, pose in zip([1, 9, 20, 33], poses):
        obj.location = pose[:3, 3]
        obj.keyframe_insert("location", frame=frame)
    for frame, pose in zip([1, 14, 33], poses[1:]):
        obj.rotation_euler = h.rotation_from_matrix(pose[:3, :3], "YZX")
        obj.keyframe_insert("rotation_euler", frame=frame)
    obj.scale = (1.5, 1.5, 0.5)  # not keyed: the static value
    motion = sb.keys.read(obj)
    np.testing.assert_allclose(motion.frames, [1, 9, 14, 20, 33])
    assert not motion.scale_keyed
    basis = h.evaluated_basis(obj, motion.frames)
    read = h.compose(motion.poses[:, :3, 3], motion.poses[:, :3, :3], motion.scales)
    assert np.abs(read - basis).max() < BASIS_TOLERANCE


def add_cycles(obj):
    for fc in h.fcurves(obj):
        fc.modifiers.new("CYCLES")


def test_cycles_modifier_with_repeated_first_pose_closes_the_period(sb):
    obj = h.new_object(mode="QUATERNION")
    poses, _ = random_keys(seed=3, n=4)
    poses = np.concatenate([poses, poses[:1]])
    h.key_poses(obj, [1, 6, 15, 19, 31], poses)
    add_cycles(obj)
    motion = sb.keys.read(obj)
    assert motion.closed and motion.cyclic
    assert motion.period == pytest.approx(30.0)
    np.testing.assert_allclose(motion.frames, [1, 6, 15, 19])
    assert motion.poses.shape == (4, 4, 4)
    assert motion.frame_range == (1.0, 31.0)

    open_motion = sb.keys.read(obj, closed="OFF")
    assert not open_motion.closed and open_motion.period is None and len(open_motion.frames) == 5


def test_cycle_without_repeated_pose_keeps_every_key(sb):
    obj = h.new_object(mode="XYZ")
    poses, _ = random_keys(seed=4, n=4)
    h.key_poses(obj, [1, 6, 15, 19], poses)
    motion = sb.keys.read(obj, closed="ON")
    assert motion.closed and not motion.cyclic
    assert motion.period == pytest.approx(24.0)  # closed after the mean key spacing (6)
    assert motion.is_key.sum() == 4 and motion.frame_range == (1.0, 25.0)
    np.testing.assert_array_equal(motion.frames[motion.is_key], [1, 6, 15, 19])
