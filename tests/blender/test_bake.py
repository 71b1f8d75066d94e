"""Baking: the dense F-curves reproduce `polyscrew.sample` at every baked frame."""

from __future__ import annotations

import bpy
import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h

#: Baked values are stored by Blender as float32: this is what "to 1e-6" can mean.
SAMPLE_TOLERANCE = 1e-6

FRAMES = [1.0, 5.0, 17.0, 21.0, 40.0]


def keyed(mode: str, seed: int, name: str = "Body", parent: bool = True):
    obj = h.new_object(name, "MESH", mode)
    if parent:
        holder = h.new_object(f"{name}.parent", "EMPTY")
        holder.rotation_euler = (0.5, 0.1, -0.7)
        holder.location = (2.0, 0.0, -1.0)
        obj.parent = holder
    rng = np.random.default_rng(seed)
    # a gentle random walk of orientations (Euler angles stay small enough for float32)
    steps = Rotation.from_rotvec(rng.normal(0, 0.6, (len(FRAMES), 3)))
    rotations = [Rotation.identity()]
    for step in steps[1:]:
        rotations.append(step * rotations[-1])
    poses = h.rigid(rng.uniform(-3, 3, (len(FRAMES), 3)), np.array([r.as_matrix() for r in rotations]))
    scales = rng.uniform(0.5, 2.0, (len(FRAMES), 3))
    h.key_poses(obj, FRAMES, poses, scales)
    h.select_only(obj)
    return obj


def grid(start: float, end: float, step: float, key_frames=()) -> np.ndarray:
    """The frames a bake must have: the ends, and the multiples of `step` strictly between,
    and every key frame in between (issue 24: every key is a baked frame)."""
    multiples = [k * step for k in range(int(np.floor(start / step)) - 1, int(np.ceil(end / step)) + 2)]
    keys_inside = [f for f in key_frames if start + 1e-4 < f < end - 1e-4]
    inner = [f for f in multiples if start + 1e-4 < f < end - 1e-4 and all(abs(f - k) > 1e-4 for k in keys_inside)]
    return np.array([start, *sorted(inner + keys_inside), end])


def check_against_sample(sb, obj, motion, scheme, levels, timing, step):
    frames, baked = h.baked_matrices(obj, with_scale=False)
    start, end = motion.frame_range
    key_frames = motion.frames if motion.is_key is None else motion.frames[motion.is_key]
    np.testing.assert_allclose(frames, grid(start, end, step, key_frames), atol=1e-4)
    spec = dict(scheme=scheme, levels=levels, closed=motion.closed, period=motion.period, timing=timing)
    expected = polyscrew.sample(motion.poses, motion.frames, frames, **spec)
    error = np.abs(baked - expected).max()
    _, scale = h.channel(obj, "scale", 3)
    expected_scale = np.exp(polyscrew.sample_vectors(np.log(motion.scales), motion.frames, frames, **spec))
    scale_error = np.abs(scale - expected_scale).max()
    print(f"{bpy.app.version_string} {obj.rotation_mode} {scheme} L{levels} {timing} step {step}: "
          f"pose {error:.1e}, scale {scale_error:.1e} over {len(frames)} frames")
    assert error < SAMPLE_TOLERANCE
    assert scale_error < SAMPLE_TOLERANCE
    return frames


@pytest.mark.parametrize("mode", h.ROTATION_MODES)
@pytest.mark.parametrize("scheme", ["four_point", "bspline", "jarek"])
def test_baked_channels_reproduce_sample(sb, mode, scheme):
    obj = keyed(mode, seed=len(mode) + len(scheme))
    motion = sb.keys.read(obj)
    source = obj.animation_data.action
    assert bpy.ops.screwbender.smooth(scheme=scheme, levels=5, timing="smooth") == {"FINISHED"}
    assert obj.animation_data.action != source
    check_against_sample(sb, obj, motion, scheme, 5, "smooth", 1.0)


@pytest.mark.parametrize("step, timing", [(0.25, "linear"), (0.5, "smooth"), (3.0, "smooth")])
def test_subframe_steps_and_timings(sb, step, timing):
    obj = keyed("QUATERNION", seed=11)
    motion = sb.keys.read(obj)
    assert bpy.ops.screwbender.smooth(scheme="jarek", levels=4, timing=timing, step=step) == {"FINISHED"}
    check_against_sample(sb, obj, motion, "jarek", 4, timing, step)


def test_evaluated_motion_follows_the_bake(sb):
    """Blender evaluating the new action gives the sampled poses (scale included)."""
    obj = keyed("ZXY", seed=5)
    motion = sb.keys.read(obj)
    assert bpy.ops.screwbender.smooth(scheme="jarek", timing="smooth") == {"FINISHED"}
    frames = np.arange(1.0, 41.0)
    basis = h.evaluated_basis(obj, frames)
    poses = polyscrew.sample(motion.poses, motion.frames, frames)
    scales = np.exp(polyscrew.sample_vectors(np.log(motion.scales), motion.frames, frames))
    expected = h.compose(poses[:, :3, 3], poses[:, :3, :3], scales)
    assert np.abs(basis - expected).max() < 1e-5  # matrix_basis itself is single precision


def test_custom_and_scene_frame_ranges(sb, factory_scene):
    obj = keyed("XYZ", seed=2)
    motion = sb.keys.read(obj)
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=-5, frame_end=50, scheme="jarek", timing="smooth") == {"FINISHED"}
    frames, baked = h.baked_matrices(obj)
    np.testing.assert_allclose(frames, np.arange(-5, 51))
    expected = polyscrew.sample(motion.poses, motion.frames, frames)
    assert np.abs(baked - expected).max() < SAMPLE_TOLERANCE
    # open motions hold the end poses outside the keys
    np.testing.assert_allclose(baked[0], baked[6], atol=1e-6)
    np.testing.assert_allclose(baked[-1], baked[-11], atol=1e-6)

    bpy.ops.screwbender.revert()
    factory_scene.frame_start, factory_scene.frame_end = 3, 12
    assert bpy.ops.screwbender.smooth(range_mode="SCENE", scheme="jarek", timing="smooth") == {"FINISHED"}
    frames, _ = h.baked_matrices(obj)
    # issue 24: frames 3 to 12 baked, the source keys outside the range kept (1; 17, 21, 40)
    inside = (frames >= 3) & (frames <= 12)
    np.testing.assert_allclose(frames[inside], np.arange(3, 13))
    np.testing.assert_allclose(frames[~inside], [f for f in FRAMES if f < 3 or f > 12])


def test_cyclic_motion_bakes_one_period_with_cycles_modifier(sb):
    obj = h.new_object(mode="QUATERNION")
    poses = h.rigid(
        [[0, 0, 0], [2, 0, 0], [2, 2, 1], [0, 2, 0], [0, 0, 0]],
        Rotation.from_euler("z", [[0], [90], [180], [270], [360]], degrees=True).as_matrix(),
    )
    h.key_poses(obj, [1, 7, 13, 25, 31], poses)
    for fc in h.fcurves(obj):
        fc.modifiers.new("CYCLES")
    motion = sb.keys.read(obj)
    assert motion.closed and motion.period == 30
    assert bpy.ops.screwbender.smooth(scheme="bspline", timing="smooth") == {"FINISHED"}
    frames, baked = h.baked_matrices(obj)
    np.testing.assert_allclose(frames, np.arange(1, 32))
    expected = polyscrew.sample(motion.poses, motion.frames, frames, scheme="bspline", closed=True, period=30.0)
    assert np.abs(baked - expected).max() < SAMPLE_TOLERANCE
    assert np.abs(baked[-1] - baked[0]).max() < 1e-6  # the cycle closes
    transform = [fc for fc in h.fcurves(obj) if fc.data_path in ("location", "rotation_quaternion")]
    assert len(transform) == 7 and all([m.type for m in fc.modifiers] == ["CYCLES"] for fc in transform)
    # and Blender keeps cycling it: one period later the pose repeats
    np.testing.assert_allclose(h.evaluated_basis(obj, [5.0])[0], h.evaluated_basis(obj, [35.0])[0], atol=1e-5)


def test_several_objects_in_one_run(sb):
    objects = [keyed(mode, seed=i, name=f"Body{i}", parent=False) for i, mode in enumerate(["XYZ", "QUATERNION", "AXIS_ANGLE"])]
    motions = [sb.keys.read(obj) for obj in objects]
    sources = [obj.animation_data.action for obj in objects]
    h.select_only(*objects)
    assert bpy.ops.screwbender.smooth(levels=3, scheme="jarek", timing="smooth") == {"FINISHED"}
    for obj, motion, source in zip(objects, motions, sources):
        assert obj.animation_data.action != source
        check_against_sample(sb, obj, motion, "jarek", 3, "smooth", 1.0)


def test_forced_cycle_without_closing_key(sb):
    """Closed ON and no key repeating the first pose: the cycle closes after the mean spacing."""
    obj = keyed("YXZ", seed=9, parent=False)
    motion = sb.keys.read(obj, closed="ON")
    assert motion.period == pytest.approx(39.0 * 5 / 4)
    assert bpy.ops.screwbender.smooth(closed="ON", levels=4, scheme="jarek", timing="smooth") == {"FINISHED"}
    frames = check_against_sample(sb, obj, motion, "jarek", 4, "smooth", 1.0)
    assert frames[-2] == 49.0 and frames[-1] == 49.75  # every whole frame of the period 1 .. 49.75, and its end
    assert all(len(fc.modifiers) == 0 for fc in h.fcurves(obj))  # no Cycles modifier was there
