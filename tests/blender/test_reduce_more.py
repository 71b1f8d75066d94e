"""Reduce Keys and Keys: Reduced, the misses left last stop (issue 26 in Blender):

- a source keyed LINEAR on every frame (a bake) is reduced against what Blender plays between
  its frames (the straight line in channel space), at every frame and 1/4, 1/2, 3/4 between;
- Smooth Motion with Keys: Reduced reduces a sparse motion to few keys, within the tolerance
  at every baked frame and no further from the smoothed motion between frames than Every Step;
- re-running Reduce Keys on an edited reduction keeps the edit (it becomes the new source);
- Keys: Reduced with a Frame Range narrower than the keys reduces inside the range and keeps
  the keys outside it, joined at the ends;
- Reduce Keys reads each source curve once.

Every figure is measured by Blender's own playback (`frame_set` with subframes,
`matrix_world`, `PoseBone.matrix`)."""

from __future__ import annotations

import math

import bpy
import numpy as np
from scipy.spatial.transform import Rotation

import bake_helpers as h
import bone_helpers as bh
from read_count import counting_reads, read_more_than_once
from test_range_and_grid import curves_of, difference, grid, keyed, played
from test_reduce_keys import SLACK, check_within, dense_object, play, sample_times, transform_keys, world_errors

DISTANCE, ANGLE = 0.001, math.radians(0.5)


def linear_bake(name: str, mode: str, n: int = 72):
    """An object keyed LINEAR on every frame (what Smooth Motion's Every Step and nla.bake
    write) along a tumble smooth in Euler angles (6 and 7 degrees a frame about two axes), 2 cm
    a frame, a body 1.7 m from its origin to its corners: between frames Blender's straight
    lines in Euler angles depart from the screw by about 2.5 mm on the body."""
    obj = h.new_object(name, "MESH", mode)
    t = np.arange(n, dtype=float)
    angles = np.stack([0.1 * t, 0.3 * np.sin(0.04 * t), 0.12 * t], axis=1)
    loc = np.stack([0.02 * t, np.sin(0.03 * t), 0.2 * np.cos(0.02 * t)], axis=1)
    obj.animation_data_create().action = bpy.data.actions.new(f"{name}Action")
    rotation = Rotation.from_euler("xyz", angles).as_matrix()  # (Blender's XYZ: X first)
    h.key_poses(obj, np.arange(1, n + 1, dtype=float), h.rigid(loc, rotation))
    for fc in h.fcurves(obj):
        for kp in fc.keyframe_points:
            kp.interpolation = "LINEAR"
        fc.update()
    h.select_only(obj)
    return obj


def test_a_linear_bake_is_reduced_against_its_straight_lines(sb):
    """Item 1: Blender plays straight lines in channel space between LINEAR keys; the reduced
    action plays within the tolerance of that at every frame and at 1/4, 1/2, 3/4 between."""
    for mode in ("XYZ",):  # (its motion is smooth in XYZ angles, not in another order's)
        obj = linear_bake(f"Linear{mode}", mode)
        times = sample_times(1, 72)
        ref = play([obj], times)
        before = transform_keys(obj)
        assert bpy.ops.screwbender.reduce_keys(distance=DISTANCE, angle=ANGLE) == {"FINISHED"}
        after = transform_keys(obj)
        got = play([obj], times)
        dist, ang = world_errors([obj], ref, got)
        whole = np.isclose(times, np.round(times))
        d_f, _ = world_errors([obj], ref[:, whole], got[:, whole])
        within = np.mean([
            np.all(world_errors([obj], ref[:, k : k + 1], got[:, k : k + 1])[0] <= DISTANCE + SLACK)
            for k in range(len(times))
        ])
        print(f"LINEAR bake ({mode}): {before} key frames -> {after}; largest error at frames {1000 * d_f.max():.3g} mm, "
              f"with subframes {1000 * dist.max():.3g} mm / {math.degrees(ang.max()):.3g} degrees; "
              f"{100 * within:.1f} % of {len(times)} samples within")
        assert after < 0.8 * before
        check_within([obj], ref, times, DISTANCE, ANGLE, f"LINEAR bake ({mode})")


def test_a_linear_bake_of_a_rig_holds_in_world_space(sb):
    """Item 1 on bones: every bone keyed LINEAR on every frame, the chain checked in world space."""
    rig = bh.armature("LinRig")
    frames = np.arange(1, 61, dtype=float)
    t = frames - 1
    for i, bone in enumerate(("Upper", "Fore", "Hand")):
        rot = Rotation.from_rotvec(np.stack([0.12 * t + i, 0.4 * np.sin(0.1 * t), 0.09 * t], axis=1))
        loc = np.stack([0.05 * np.sin(0.1 * t + i), 0.01 * t, 0.0 * t], axis=1)
        bh.key_bone(rig, bone, frames, h.rigid(loc, rot.as_matrix()), mode="QUATERNION" if i == 1 else "XYZ")
    for fc in h.fcurves(rig):
        for kp in fc.keyframe_points:
            kp.interpolation = "LINEAR"
        fc.update()
    owners_ = [(rig, b) for b in ("Upper", "Fore", "Hand")]
    times = sample_times(1, 60)
    ref = play(owners_, times)
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    bh.select_bones(rig, ["Upper", "Fore", "Hand"])
    assert bpy.ops.screwbender.reduce_keys(distance=DISTANCE, angle=ANGLE) == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    after = sum(transform_keys(rig, b) for b in ("Upper", "Fore", "Hand"))
    print(f"LINEAR rig: {3 * 60} key frames -> {after}")
    assert after < 0.9 * 3 * 60
    check_within(owners_, ref, times, DISTANCE, ANGLE, "LINEAR rig")


def sparse(name: str):
    """Four keys over 31 frames (a location path with three corners, no rotation)."""
    obj = h.new_object(name, "MESH", "XYZ")
    poses = h.rigid(np.array([[0, 0, 0], [2, 1, 0], [4, 0, 1], [6, 2, 0]], float), np.repeat(np.eye(3)[None], 4, 0))
    h.key_poses(obj, [1, 11, 21, 31], poses)
    return obj


def test_smooth_motion_reduced_keeps_few_keys_of_a_sparse_motion(sb):
    """Item 2: Smooth Motion with Keys: Reduced on a sparse 4-key motion: few keys, within the
    tolerance of the smoothed motion at every baked frame; between frames no further from the
    smoothed motion (Every Step at Step 1/4) than the tolerance plus Every Step's own departure."""
    every, reduced, quarter = sparse("SEvery"), sparse("SReduced"), sparse("SQuarter")
    h.select_only(every)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    h.select_only(quarter)
    assert bpy.ops.screwbender.smooth(step=0.25) == {"FINISHED"}
    h.select_only(reduced)
    assert bpy.ops.screwbender.smooth(key_mode="REDUCED", key_distance=DISTANCE, key_angle=ANGLE) == {"FINISHED"}
    keys_ = transform_keys(reduced)
    times = sample_times(1, 31)
    whole = np.isclose(times, np.round(times))
    ref, got, exact = play([every], times), play([reduced], times), play([quarter], times)
    d_f, a_f = world_errors([reduced], ref[:, whole], got[:, whole])
    d_q, _ = world_errors([reduced], exact, got)
    d_e, _ = world_errors([every], exact, ref)
    print(f"sparse Smooth Motion, Reduced: {keys_} key frames of 31; at frames {1000 * d_f.max():.3g} mm; against the "
          f"smoothed motion with subframes {1000 * d_q.max():.3g} mm (Every Step {1000 * d_e.max():.3g} mm)")
    assert keys_ <= 15  # (the screw between frames as the reference kept 29)
    assert d_f.max() <= DISTANCE + SLACK and a_f.max() <= ANGLE + SLACK
    assert d_q.max() <= DISTANCE + d_e.max() + SLACK
    # unedited, it is replaced by a re-run (the digest of the reduced keys it wrote is Blender's)
    name = reduced.animation_data.action.name
    assert bpy.ops.screwbender.smooth(key_mode="REDUCED", key_distance=DISTANCE, key_angle=ANGLE) == {"FINISHED"}
    assert reduced.animation_data.action.name == name
    assert len([a for a in bpy.data.actions if a.name.startswith(name)]) == 1


def test_a_rerun_keeps_an_edited_reduction(sb):
    """Item 3: an edited reduction is the new source of a re-run (never deleted); Revert
    returns to it; an unedited one is replaced (test_reduce_keys covers that)."""
    obj = dense_object("Ed")
    assert bpy.ops.screwbender.reduce_keys(distance=0.01, angle=math.radians(2)) == {"FINISHED"}
    first = obj.animation_data.action
    assert first.name == "EdAction.reduce"
    fc = next(fc for fc in h.fcurves(obj) if fc.data_path == "location" and fc.array_index == 2)
    point = fc.keyframe_points[len(fc.keyframe_points) // 2]
    point.co.y += 0.3
    point.handle_left.y += 0.3
    point.handle_right.y += 0.3
    fc.update()
    times = sample_times(1, 120)
    edited_play = play([obj], times)
    assert bpy.ops.screwbender.reduce_keys(distance=DISTANCE, angle=ANGLE) == {"FINISHED"}
    second = obj.animation_data.action
    assert second != first
    assert first.name in bpy.data.actions and first.use_fake_user  # the edit is kept
    assert second.get("screwbender_source") == first
    # the re-run reduced the edited keys: it plays the edit
    check_within([obj], edited_play, times, DISTANCE, ANGLE, "re-run on an edited reduction")
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == first
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == bpy.data.actions["EdAction"]
    assert first.name in bpy.data.actions  # an edited result is never thrown away


def test_reduced_with_a_narrower_range_reduces_inside_it(sb):
    """Item 4: Keys: Reduced with a Frame Range narrower than the keys: inside the range fewer
    keys than Every Step writes there, within the tolerance of Every Step's result; outside it
    the source plays as it did, its keys kept."""
    every, _ = keyed("REvery")
    reduced, _ = keyed("RReduced")
    frames = grid(-2, 44)
    before = played(reduced, frames)
    first_keys = {k: fc.keyframe_points[0].co[:] for k, fc in curves_of(reduced).items()}
    h.select_only(every)
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10.0, frame_end=30.0) == {"FINISHED"}
    h.select_only(reduced)
    distance, angle = 0.005, math.radians(1.0)
    assert bpy.ops.screwbender.smooth(
        range_mode="CUSTOM", frame_start=10.0, frame_end=30.0, key_mode="REDUCED", key_distance=distance,
        key_angle=angle,
    ) == {"FINISHED"}
    now = played(reduced, frames)
    outside = (frames < 10.0) | (frames > 30.0)
    loc, ang = difference(now[outside], before[outside])
    assert loc < 0.01 and ang < 1e-3, (loc, ang)
    for key, co in first_keys.items():
        assert tuple(curves_of(reduced)[key].keyframe_points[0].co) == tuple(co), key

    def inside_keys(obj) -> int:
        x = np.concatenate([h.curve_points(fc)[:, 0] for fc in h.fcurves(obj)])
        return len(np.unique(np.round(x[(x > 10.0 + 1e-3) & (x < 30.0 - 1e-3)], 3)))

    n_every, n_reduced = inside_keys(every), inside_keys(reduced)
    times = sample_times(10, 30)
    whole = np.isclose(times, np.round(times))
    ref, got = play([every], times), play([reduced], times)
    d, a = world_errors([reduced], ref[:, whole], got[:, whole])
    d_all, _ = world_errors([reduced], ref, got)
    print(f"\n[Reduced + Custom 10..30] key frames inside the range: Every Step {n_every}, Reduced {n_reduced}; "
          f"at frames {1000 * d.max():.3g} mm / {math.degrees(a.max()):.3g} deg off Every Step "
          f"({1000 * d_all.max():.3g} mm with subframes); outside {loc:.4f} mm, {ang:.5f} deg off the source")
    assert n_reduced < 0.7 * n_every
    assert d.max() <= distance + SLACK and a.max() <= angle + SLACK


def test_reduce_keys_reads_each_curve_once(sb):
    """Item 5: Reduce Keys reads every keyframe property of every source curve at most once
    (an object and a rig in one run)."""
    obj = dense_object("Once")
    rig = bh.armature("OnceRig")
    frames = np.arange(1, 49, dtype=float)
    for i, bone in enumerate(("Upper", "Fore", "Hand")):
        rot = Rotation.from_rotvec(np.stack([0.3 * np.sin(0.1 * frames + i), 0.02 * frames, 0 * frames], axis=1))
        bh.key_bone(rig, bone, frames, h.rigid(np.zeros((len(frames), 3)), rot.as_matrix()))
    h.select_only(obj, rig)
    with counting_reads() as reads:
        assert bpy.ops.screwbender.reduce_keys() == {"FINISHED"}
    curves = {(k[0], k[1], k[2]) for k in reads if len(k) == 4}
    print(f"read once: {len(curves)} curves read, {sum(n for k, n in reads.items() if len(k) == 4)} reads; "
          f"more than once: {read_more_than_once(reads)}")
    assert len(curves) >= 6 + 3 * 3
    assert read_more_than_once(reads) == {}
