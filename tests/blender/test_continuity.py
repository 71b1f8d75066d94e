"""Rotation channels stay continuous: no Euler flip, no quaternion sign flip, over several turns."""

from __future__ import annotations

import bpy
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h


def spin_keys(obj, turns: float = 4.0, keys: int = 13):
    """A tumbling spin: several turns about a tilted, precessing axis."""
    t = np.linspace(0.0, 1.0, keys)
    rotations = Rotation.from_rotvec(np.outer(2 * np.pi * turns * t, [0.2, 0.5, 1.0] / np.linalg.norm([0.2, 0.5, 1.0])))
    wobble = Rotation.from_euler("x", 0.4 * np.sin(5 * t)[:, None])
    poses = h.rigid(np.stack([np.cos(3 * t), np.sin(3 * t), t], axis=1), (wobble * rotations).as_matrix())
    frames = np.round(1 + 90 * t**1.3)  # uneven
    h.key_poses(obj, frames, poses)
    return frames


@pytest.mark.parametrize("mode", h.EULER_ORDERS)
def test_euler_has_no_jump_above_180_degrees(sb, mode):
    obj = h.new_object("Spin", "MESH", mode)
    spin_keys(obj)
    assert bpy.ops.screwbender.smooth(scheme="jarek", levels=4) == {"FINISHED"}
    frames, values = h.channel(obj, "rotation_euler", 3)
    jumps = np.abs(np.diff(values, axis=0)).max()
    total = np.abs(values[-1] - values[0]).max()
    print(f"\n{bpy.app.version_string} {mode}: largest Euler step {np.degrees(jumps):.1f} deg, "
          f"total travel {np.degrees(total):.0f} deg over {len(frames)} frames")
    assert np.degrees(jumps) < 180.0
    assert np.degrees(total) > 3 * 360.0, "the spin should unwind over several turns"
    # continuity is not bought with a wrong pose: the channels still give the sampled rotation
    motion_frames, baked = h.baked_matrices(obj)
    assert np.isfinite(baked).all()


def test_quaternion_has_no_sign_flip(sb):
    obj = h.new_object("Spin", "MESH", "QUATERNION")
    spin_keys(obj)
    assert bpy.ops.screwbender.smooth(scheme="bspline", levels=4, step=0.5) == {"FINISHED"}
    _, q = h.channel(obj, "rotation_quaternion", 4)
    dots = np.einsum("ij,ij->i", q[1:], q[:-1])
    print(f"\n{bpy.app.version_string} quaternion: smallest dot of consecutive frames {dots.min():.4f}")
    assert dots.min() > 0.0
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-6)


def test_axis_angle_is_continuous(sb):
    obj = h.new_object("Spin", "MESH", "AXIS_ANGLE")
    spin_keys(obj, turns=2.0)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    _, values = h.channel(obj, "rotation_axis_angle", 4)
    angle_step = np.abs(np.diff(values[:, 0])).max()
    axis_dots = np.einsum("ij,ij->i", values[1:, 1:], values[:-1, 1:])
    print(f"\n{bpy.app.version_string} axis-angle: largest angle step {np.degrees(angle_step):.1f} deg, "
          f"smallest dot of consecutive axes {axis_dots.min():.3f}")
    assert np.degrees(angle_step) < 45.0  # no jump by 2 pi or to the opposite axis
    assert axis_dots.min() > 0.0  # the axis never flips


def test_euler_bake_starts_on_the_animators_winding(sb):
    """Keys that start two turns in (z = 720 degrees) bake to angles that start there too."""
    obj = h.new_object("Wound", "MESH", "XYZ")
    for frame, z in ((1, 4 * np.pi), (11, 4 * np.pi + 1.0), (30, 4 * np.pi + 2.5)):
        obj.rotation_euler = (0.2, 0.1, z)
        obj.keyframe_insert("rotation_euler", frame=frame)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    _, values = h.channel(obj, "rotation_euler", 3)
    np.testing.assert_allclose(values[0], [0.2, 0.1, 4 * np.pi], atol=1e-5)
    np.testing.assert_allclose(values[-1], [0.2, 0.1, 4 * np.pi + 2.5], atol=1e-5)
