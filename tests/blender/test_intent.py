"""Keep what the animator meant (issue 17): spins, holds and pops, easing (timing Keys), the
animator's key poses, and Cycles with offset; measured against Blender's own playback."""

from __future__ import annotations

import math

import bpy
import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h
from conftest import addon_module

SCHEMES = ["four_point", "bspline", "jarek"]


def playback(obj, frames) -> np.ndarray:
    """Blender's own matrix_basis of `obj` at `frames` (the active action)."""
    return h.evaluated_basis(obj, frames)


def rotation_angle_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    r = np.einsum("nji,njk->nik", a[:, :3, :3], b[:, :3, :3])
    cos = np.clip((np.trace(r, axis1=1, axis2=2) - 1) / 2, -1, 1)
    return np.degrees(np.arccos(cos))


def keyed_euler_z(values_deg, frames, name="Wheel", mode="XYZ"):
    obj = h.new_object(name, "MESH", mode)
    for f, v in zip(frames, values_deg):
        obj.rotation_euler = (0.0, 0.0, math.radians(v))
        obj.location = (0.02 * f, 0.0, 0.0)
        obj.keyframe_insert("rotation_euler", frame=f)
        obj.keyframe_insert("location", frame=f)
    h.select_only(obj)
    return obj


def z_turn(matrices: np.ndarray) -> np.ndarray:
    """Unwrapped rotation about Z (degrees) of matrices that turn about Z."""
    return np.degrees(np.unwrap(np.arctan2(matrices[:, 1, 0], matrices[:, 0, 0])))


SPINS = [
    ("0-360-720", [0, 360, 720], [1, 21, 41]),
    ("0-270", [0, 270], [1, 21]),
    ("wheel 0-800 in 5 keys", [0, 150, 400, 620, 800], [1, 8, 20, 31, 40]),
    ("backwards -400", [0, -200, -400], [1, 12, 25]),
]


@pytest.mark.parametrize("scheme", SCHEMES)
@pytest.mark.parametrize("label, values, frames", SPINS, ids=[s[0] for s in SPINS])
def test_spins_turn_as_far_and_the_same_way(sb, scheme, label, values, frames):
    obj = keyed_euler_z(values, frames)
    check = sorted(set(frames) | {0.5 * (a + b) for a, b in zip(frames, frames[1:])})
    blender = playback(obj, check)
    every = np.arange(frames[0], frames[-1] + 1.0)
    blender_every = playback(obj, every)
    assert bpy.ops.screwbender.smooth(scheme=scheme, levels=4) == {"FINISHED"}
    ours = playback(obj, check)
    off = rotation_angle_between(ours, blender)
    ours_every = playback(obj, every)
    turn_ours, turn_blender = z_turn(ours_every), z_turn(blender_every)
    print(f"{label} {scheme}: largest angle to Blender's playback at keys and span middles {off.max():.3f} deg; "
          f"total turn {turn_ours[-1] - turn_ours[0]:.1f} vs {turn_blender[-1] - turn_blender[0]:.1f} deg")
    assert off.max() < 2.0
    # the same way: the frame-to-frame turn has Blender's sign wherever Blender turns
    step_ours, step_blender = np.diff(turn_ours), np.diff(turn_blender)
    moving = np.abs(step_blender) > 1.0
    assert np.all(np.sign(step_ours[moving]) == np.sign(step_blender[moving]))
    assert abs((turn_ours[-1] - turn_ours[0]) - (turn_blender[-1] - turn_blender[0])) < 2.0


@pytest.mark.parametrize("scheme", SCHEMES)
def test_axis_angle_spin_of_540_degrees(sb, scheme):
    obj = h.new_object("Spinner", "MESH", "AXIS_ANGLE")
    axis = np.array([0.3, 0.2, 0.9]) / np.linalg.norm([0.3, 0.2, 0.9])
    frames = [1, 16, 31]
    for f, angle in zip(frames, [0.0, 270.0, 540.0]):
        obj.rotation_axis_angle = (math.radians(angle), *axis)
        obj.keyframe_insert("rotation_axis_angle", frame=f)
    h.select_only(obj)
    check = [1, 8.5, 16, 23.5, 31]
    blender = playback(obj, check)
    every = np.arange(1.0, 32.0)
    before = playback(obj, every)
    assert bpy.ops.screwbender.smooth(scheme=scheme) == {"FINISHED"}
    off = rotation_angle_between(playback(obj, check), blender)
    after = playback(obj, every)
    # the turn about the axis, accumulated frame to frame, and its direction
    def turned(m):
        steps = Rotation.from_matrix(np.einsum("nji,njk->nik", m[:-1, :3, :3], m[1:, :3, :3])).as_rotvec()
        return np.sum(steps @ axis)
    print(f"axis-angle 540 {scheme}: {off.max():.3f} deg off; turned {np.degrees(turned(after)):.1f} vs {np.degrees(turned(before)):.1f}")
    assert off.max() < 2.0
    assert abs(np.degrees(turned(after)) - 540.0) < 2.0


def still_frames_test(obj, held_frames, pop_frame, scheme):
    before_pop = playback(obj, [pop_frame - 1, pop_frame])
    assert bpy.ops.screwbender.smooth(scheme=scheme) == {"FINISHED"}
    held = playback(obj, held_frames)
    spread = np.abs(held - held[0]).max()
    after_pop = playback(obj, [pop_frame - 1, pop_frame])
    return spread, before_pop, after_pop


@pytest.mark.parametrize("scheme", SCHEMES)
def test_constant_hold_stays_still_and_pops(sb, scheme):
    obj = h.new_object("Ball", "MESH", "XYZ")
    keys = [(1, 0.0), (5, 2.0), (10, 4.0), (20, 8.0), (30, 9.0)]
    for f, x in keys:
        obj.location = (x, 0.5 * x, 0.0)
        obj.rotation_euler = (0.0, 0.1 * x, 0.0)
        obj.keyframe_insert("location", frame=f)
        obj.keyframe_insert("rotation_euler", frame=f)
    for fc in h.fcurves(obj):
        for kp in fc.keyframe_points:
            if kp.co[0] == 10:
                kp.interpolation = "CONSTANT"  # hold 10..19, pop at 20
    h.select_only(obj)
    spread, before, after = still_frames_test(obj, np.arange(10.0, 20.0), 20, scheme)
    print(f"CONSTANT hold {scheme}: held frames move by {spread:.1e}; pop {after[1][0, 3] - after[0][0, 3]:.3f} (Blender {before[1][0, 3] - before[0][0, 3]:.3f})")
    assert spread <= 2 * np.finfo(np.float32).eps * 8
    assert abs(after[0][0, 3] - 4.0) < 1e-6  # held at the key value
    np.testing.assert_allclose(after, before, atol=1e-5)  # the pop stays a pop


@pytest.mark.parametrize("scheme", SCHEMES)
def test_equal_key_hold_stays_still(sb, scheme):
    obj = h.new_object("Box", "MESH", "QUATERNION")
    rot = Rotation.from_euler("xyz", [[0, 0, 0], [0.3, 0.2, 0.5], [0.3, 0.2, 0.5], [0.9, -0.4, 1.2], [1.0, 0.0, 2.0]]).as_matrix()
    loc = np.array([[0, 0, 0], [2, 1, 0], [2, 1, 0], [4, 0, 1], [5, 2, 2]], dtype=float)
    h.key_poses(obj, [1, 8, 18, 26, 35], h.rigid(loc, rot))
    spread, _, _ = still_frames_test(obj, np.arange(8.0, 19.0), 26, scheme)
    print(f"equal-key hold {scheme}: held frames move by {spread:.1e}")
    assert spread <= 1e-6


def ease(kind: str):
    """One object keyed at two poses (frames 1, 25) with an easing span."""
    obj = h.new_object(f"Ease{kind}", "MESH", "XYZ")
    poses = h.rigid([[0, 0, 0], [6, 2, 1]], Rotation.from_euler("xyz", [[0, 0, 0], [0.4, 0.3, 1.2]]).as_matrix())
    h.key_poses(obj, [1, 25], poses)
    for fc in h.fcurves(obj):
        first, last = fc.keyframe_points[0], fc.keyframe_points[1]
        if kind == "EASE_IN_OUT":
            first.interpolation = "BEZIER"
        elif kind == "EXPO":
            first.interpolation = "EXPO"
            first.easing = "EASE_IN_OUT"
        elif kind == "HANDLES":
            first.handle_right_type = last.handle_left_type = "FREE"
            dv = last.co[1] - first.co[1]
            first.handle_right = (first.co[0] + 14.0, first.co[1] + 0.05 * dv)
            last.handle_left = (last.co[0] - 2.0, last.co[1] - 0.02 * dv)
        fc.update()
    h.select_only(obj)
    return obj


def travelled_fraction(matrices: np.ndarray, size: float) -> np.ndarray:
    """Fraction of the way travelled (the add-on's body metric), frame by frame."""
    a, b = matrices[:-1], matrices[1:]
    step = np.sqrt(np.sum((b[:, :3, 3] - a[:, :3, 3]) ** 2, axis=1)
                   + size ** 2 / 3 * np.sum((b[:, :3, :3] - a[:, :3, :3]) ** 2, axis=(1, 2)))
    done = np.concatenate(([0.0], np.cumsum(step)))
    return done / done[-1]


@pytest.mark.parametrize("kind", ["EASE_IN_OUT", "EXPO", "HANDLES"])
def test_timing_keys_keeps_the_pace_of_blenders_curves(sb, kind):
    obj = ease(kind)
    frames = np.arange(1.0, 26.0)
    fine = np.arange(1.0, 25.0001, 0.125)
    blender = playback(obj, fine)
    size = sb.keys.body_size(addon_module("blender.owners").Owner(obj))
    assert bpy.ops.screwbender.smooth(timing="keys", scheme="four_point") == {"FINISHED"}
    ours = playback(obj, fine)
    pick = np.isin(fine, frames)
    theirs_frac = travelled_fraction(blender, size)[pick]
    ours_frac = travelled_fraction(ours, size)[pick]
    off = np.abs(ours_frac - theirs_frac).max()
    constant_speed = np.abs(np.linspace(0, 1, len(frames)) - theirs_frac).max()
    print(f"{kind}: fraction of the span travelled, ours against Blender's: largest difference {100 * off:.2f} % "
          f"(constant pace would be {100 * constant_speed:.1f} % off)")
    assert off < 0.02
    # The curves are eased: a constant pace is far off theirs (measured 9.6 % for EASE_IN_OUT,
    # 28.7 % EXPO, 22.3 % HANDLES), well beyond the 2 % allowed above, so matching means
    # following the easing, not just moving at a steady pace.
    assert constant_speed > 2.5 * 0.02
    # and the path is the screw between the two keys (at the baked frames: between them
    # Blender interpolates the baked channels linearly)
    keys = playback(obj, [1, 25])
    along = polyscrew.interpolate(np.ascontiguousarray(keys[0]), np.ascontiguousarray(keys[1]),
                                  np.linspace(0, 1, 20001))
    baked = ours[pick]
    distance = np.min(np.linalg.norm(baked[:, None, :3, 3] - along[None, :, :3, 3], axis=2), axis=1)
    print(f"  baked poses off the screw by at most {distance.max():.1e}")
    assert distance.max() < 1e-3


def random_keyed(seed: int, mode: str, n: int = 7):
    rng = np.random.default_rng(seed)
    obj = h.new_object(f"Random{seed}", "MESH", mode)
    frames = np.cumsum(rng.integers(3, 12, n)).astype(float)
    rot = Rotation.from_rotvec(np.cumsum(rng.normal(0, 0.7, (n, 3)), axis=0)).as_matrix()
    h.key_poses(obj, frames, h.rigid(rng.uniform(-3, 3, (n, 3)), rot), rng.uniform(0.6, 1.6, (n, 3)))
    h.select_only(obj)
    return obj, frames


@pytest.mark.parametrize("mode", ["XYZ", "QUATERNION", "AXIS_ANGLE", "ZXY"])
def test_default_settings_hit_every_key_pose(sb, mode):
    obj, frames = random_keyed(len(mode), mode)
    keys = playback(obj, frames)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}  # the defaults
    hit = playback(obj, frames)
    off = np.abs(hit - keys).max()
    print(f"defaults on random keys ({mode}): largest difference at the keys {off:.1e}")
    assert off < 1e-5  # float32 keys, matrix entries of size up to ~3


def offset_walk(channels: str):
    """A walk cycle keyed over frames 1..25 that moves on by 2 along x each cycle (Repeat with
    Offset on `channels`: "location" or "all")."""
    obj = h.new_object("Walker", "MESH", "XYZ")
    for f, x, z, turn in [(1, 0.0, 0.0, 0.0), (7, 0.6, 0.3, 0.2), (13, 1.0, 0.0, 0.0), (19, 1.5, 0.3, -0.2), (25, 2.0, 0.0, 0.0)]:
        obj.location = (x, 0.1 * np.sin(f), z)
        obj.rotation_euler = (0.0, 0.0, turn)
        obj.keyframe_insert("location", frame=f)
        obj.keyframe_insert("rotation_euler", frame=f)
    for fc in h.fcurves(obj):
        if channels == "all" or fc.data_path == "location":
            mod = fc.modifiers.new("CYCLES")
            mod.mode_before = mod.mode_after = "REPEAT_OFFSET"
    h.select_only(obj)
    return obj


@pytest.mark.parametrize("channels", ["location", "all"])
def test_repeat_with_offset_goes_on(sb, channels, capfd):
    obj = offset_walk(channels)
    after_keys = np.arange(25.0, 25.0 + 3 * 24 + 1)
    blender = playback(obj, after_keys)
    within_keys = np.arange(1.0, 26.0)
    blender_within = playback(obj, within_keys)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert "Repeat with Offset" in capfd.readouterr().out  # the report says it was kept
    ours = playback(obj, after_keys)
    gap = np.linalg.norm(ours[:, :3, 3] - blender[:, :3, 3], axis=1)
    off = gap.max()
    # within the keys the smoothed motion differs from Blender's Bezier keys by the smoothing
    # itself; beyond them by no more (the walk goes on, nothing drifts)
    within = np.linalg.norm(playback(obj, within_keys)[:, :3, 3] - blender_within[:, :3, 3], axis=1).max()
    at_keys = gap[np.isin(after_keys, [25 + 6 * i for i in range(13)])].max()
    # the seam (frame 25, and every 24 frames) is as smooth as the rest
    every = np.arange(1.0, 25.0 + 2 * 24 + 1)
    x = playback(obj, every)[:, :3, 3]
    second = np.linalg.norm(x[2:] - 2 * x[1:-1] + x[:-2], axis=1)
    seams = [int(f - 2) for f in (25.0, 49.0)]  # second difference centred on the seam frame
    elsewhere = np.delete(second, seams)
    # the same smoothed motion without any seam: the keys extended by Blender's playback and
    # sampled straight through frames 1..73 by the add-on's own sampler
    source = obj.animation_data.action["screwbender_source"]
    motion = sb.keys.read(obj, "AUTO", action=source, slot=sb.channels.slot_identifier(obj), extend_to=(1.0, 73.0))
    options = sb.bake.Options()
    seamless = sb.bake.sample_poses(motion, every, options, obj)[0][:, :3, 3]
    smooth_second = np.linalg.norm(seamless[2:] - 2 * seamless[1:-1] + seamless[:-2], axis=1)
    print(f"Repeat with Offset ({channels}): over three cycles after the keys, distance to Blender's playback "
          f"{100 * at_keys:.4f} cm at the key frames, {100 * off:.3f} cm at most between them (within the keys "
          f"{100 * within:.3f} cm); second difference at the seams {second[seams].max():.4f} (the seamless motion "
          f"there {smooth_second[seams].max():.4f}), elsewhere up to {elsewhere.max():.4f}")
    assert at_keys < 0.01
    assert off <= within + 1e-3
    # no kink at the seams: with every channel cycling, the baked cycles there are the seamless
    # motion (to float32 keys); with location alone cycling, Blender holds the rotation after
    # the keys and so does the bake (the seamless motion, rotation held beyond the keys too,
    # bends differently there) ...
    if channels == "all":
        assert np.abs(second[seams] - smooth_second[seams]).max() < 1e-4
    # ... and no spike: within 10 % of the largest elsewhere (the seam is a key of the walk,
    # which bends most at its keys)
    assert second[seams].max() <= 1.1 * elsewhere.max()


def test_preview_and_insert_key_follow_spins_and_holds(sb):
    """The live preview shows, and Insert Key on Motion keys, the motion Smooth Motion bakes:
    spins turned the whole way, holds still."""
    from conftest import addon_module

    pd = addon_module("ops.preview_draw")
    obj = h.new_object("Wheel", "MESH", "XYZ")  # a spin, a hold (21-31), a spin
    for f, v, x in ((1, 0, 0.0), (21, 360, 1.0), (31, 360, 1.0), (51, 720, 2.0)):
        obj.rotation_euler, obj.location = (0.0, 0.0, math.radians(v)), (x, 0.0, 0.0)
        obj.keyframe_insert("rotation_euler", frame=f)
        obj.keyframe_insert("location", frame=f)
    h.select_only(obj)
    scene = bpy.context.scene
    scene.frame_set(1)  # the object shows its animation, as after keying in the UI
    scene.screwbender_preview.instances = 51  # one instance per frame 1..51
    obj.screwbender_preview = True
    try:
        pd.refresh(scene)
        batches = pd.CACHE.entries[obj.session_uid].batches
    finally:
        obj.screwbender_preview = False
        pd.sync()
    np.testing.assert_allclose(batches.instance_times, np.arange(1.0, 52.0))
    previewed = batches.instances
    h.select_only(obj)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    baked = playback(obj, np.arange(1.0, 52.0))
    off = rotation_angle_between(previewed, baked).max()
    moved = np.linalg.norm(previewed[:, :3, 3] - baked[:, :3, 3], axis=1).max()
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    # Insert Key on Motion inside the second spin keys the motion's pose, wound as the curve
    scene.frame_set(41)
    assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
    z = [fc for fc in h.fcurves(obj) if fc.data_path == "rotation_euler" and fc.array_index == 2][0]
    inserted = [kp.co[1] for kp in z.keyframe_points if kp.co[0] == 41][0]
    print(f"preview against the bake: {off:.4f} deg, {moved:.2e} units; inserted key at frame 41: {math.degrees(inserted):.2f} deg")
    assert off < 0.05 and moved < 1e-4
    assert abs(math.degrees(inserted) - 540.0) < 5.0, math.degrees(inserted)  # not 180
    held = baked[20:31]  # frames 21..31
    assert np.abs(held - held[0]).max() < 1e-6
