"""Issue 24, items 1, 3 and 7: a Frame Range smooths a part and keeps the rest; every key is a
baked frame; channels the source did not key stay unkeyed.

Every figure is measured against Blender's own playback of the source action
(`matrix_basis` after `frame_set`, and `FCurve.evaluate`), and printed (pytest -s) for the
closing note's table: in mm (the scenes are in metres) and degrees.
"""

from __future__ import annotations

import bpy
import numpy as np
import pytest

import bake_helpers as h
import bone_helpers as b
from conftest import addon_module

#: float32 keys: values of a few units agree to this (m, rad).
F32 = 2e-6


def random_poses(n: int, seed: int, reach: float = 2.0) -> np.ndarray:
    """`n` poses wandering over a few metres, rotations within about 60 degrees of each other."""
    rng = np.random.default_rng(seed)
    from scipy.spatial.transform import Rotation

    rot = Rotation.from_rotvec(np.cumsum(rng.normal(0.0, 0.35, (n, 3)), axis=0))
    out = np.zeros((n, 4, 4))
    out[:, :3, :3] = rot.as_matrix()
    out[:, :3, 3] = np.cumsum(rng.normal(0.0, reach / 2, (n, 3)), axis=0)
    out[:, 3, 3] = 1.0
    return out


def difference(a: np.ndarray, b_: np.ndarray) -> tuple[float, float]:
    """Largest location difference (mm) and rotation angle (degrees) between pose lists."""
    loc = np.linalg.norm(a[:, :3, 3] - b_[:, :3, 3], axis=1)
    ra, rb = a[:, :3, :3], b_[:, :3, :3]
    ra = ra / np.linalg.norm(ra, axis=1, keepdims=True)
    rb = rb / np.linalg.norm(rb, axis=1, keepdims=True)
    r = np.einsum("nji,njk->nik", ra, rb)
    ang = np.degrees(np.arccos(np.clip((np.trace(r, axis1=1, axis2=2) - 1) / 2, -1, 1)))
    return float(loc.max() * 1000.0), float(ang.max())


def played(obj, frames, action=None) -> np.ndarray:
    """`matrix_basis` at `frames` as Blender plays `action` (default: the object's own)."""
    adt = obj.animation_data
    old = adt.action
    slot = getattr(adt, "action_slot", None)
    if action is not None:
        adt.action = action
        if slot is not None and getattr(adt, "action_slot", None) is None:
            adt.action_slot = action.slots[0]
    try:
        return h.evaluated_basis(obj, frames)
    finally:
        if action is not None:
            adt.action = old
            if slot is not None:
                adt.action_slot = slot


def keyed(name="Body", mode="XYZ", frames=(1, 7, 13, 19, 25, 31, 37, 40), interpolation="BEZIER", seed=3):
    obj = h.new_object(name, "MESH", mode)
    poses = random_poses(len(frames), seed)
    h.key_poses(obj, frames, poses)
    for fc in h.fcurves(obj):
        for kp in fc.keyframe_points:
            kp.interpolation = interpolation
            if interpolation == "SINE":
                kp.easing = "EASE_IN_OUT"
        fc.update()
    return obj, poses


def key_table(fc) -> dict:
    points = fc.keyframe_points
    n = len(points)
    out = {}
    for name, width in (("co", 2), ("handle_left", 2), ("handle_right", 2)):
        a = np.zeros(n * width, dtype=np.float32)
        points.foreach_get(name, a)
        out[name] = a.reshape(n, width)
    out["interpolation"] = [kp.interpolation for kp in points]
    out["easing"] = [kp.easing for kp in points]
    return out


def curves_of(obj, action=None) -> dict:
    """(data path, index) -> F-curve of `obj`'s action, or of `action` (its first slot)."""
    if action is None:
        listed = h.fcurves(obj)
    else:
        slot = action.slots[0].identifier if hasattr(action, "slots") and len(action.slots) else ""
        listed = addon_module("blender.channels").action_fcurves(action, slot)
    return {(fc.data_path, fc.array_index): fc for fc in listed}


def grid(lo, hi, per_frame=4):
    return np.arange(lo * per_frame, hi * per_frame + 1) / per_frame


# --- item 1: a Frame Range smooths a part and keeps the rest ------------------------------------


RANGES = [
    ("CUSTOM", 10.0, 30.0, "BEZIER", "XYZ"),
    ("SCENE", 5.0, 35.0, "BEZIER", "XYZ"),
    ("CUSTOM", 10.0, 30.0, "BEZIER", "QUATERNION"),
    ("CUSTOM", 10.5, 29.25, "LINEAR", "ZXY"),
    ("CUSTOM", 10.0, 30.0, "CONSTANT", "XYZ"),
    ("CUSTOM", 10.0, 30.0, "SINE", "YZX"),
    ("CUSTOM", 13.0, 31.0, "BEZIER", "XYZ"),  # the range's ends on keys
    ("CUSTOM", -5.0, 30.0, "BEZIER", "AXIS_ANGLE"),  # from before the first key: only the end cuts
    ("CUSTOM", 10.0, 30.0, "BEZIER", "AXIS_ANGLE"),
]


@pytest.mark.parametrize("range_mode, start, end, interpolation, mode", RANGES)
def test_frame_range_smooths_a_part_and_keeps_the_rest(capsys, range_mode, start, end, interpolation, mode):
    scene = bpy.context.scene
    obj, _ = keyed(mode=mode, interpolation=interpolation)
    source = obj.animation_data.action
    before_keys = {key: key_table(fc) for key, fc in curves_of(obj).items()}
    if range_mode == "SCENE":
        scene.frame_start, scene.frame_end = int(start), int(end)
    frames = grid(-2, 44)
    source_played = played(obj, frames)
    result = bpy.ops.screwbender.smooth(range_mode=range_mode, frame_start=start, frame_end=end)
    assert result == {"FINISHED"}
    assert obj.animation_data.action is not source
    now = played(obj, frames)
    outside = (frames < start) | (frames > end)
    loc, ang = difference(now[outside], source_played[outside])
    # the join: the pose at the range's ends, and the largest step across them
    ends = np.array([start, end])
    end_loc, end_ang = difference(played(obj, ends), played(obj, ends, source))
    fine = np.linspace(start - 0.05, start + 0.05, 11)
    steps = np.linalg.norm(np.diff(played(obj, fine)[:, :3, 3], axis=0), axis=1).max() * 1000
    fine_end = np.linspace(end - 0.05, end + 0.05, 11)
    steps_end = np.linalg.norm(np.diff(played(obj, fine_end)[:, :3, 3], axis=0), axis=1).max() * 1000
    inside_moved = difference(now[~outside], source_played[~outside])
    with capsys.disabled():
        print(
            f"\n[range {range_mode} {start:g}..{end:g} {interpolation} {mode}] outside the range: {loc:.4f} mm, "
            f"{ang:.5f} deg off the source; at the ends {end_loc:.4f} mm, {end_ang:.5f} deg; largest step of 0.01 "
            f"frame across the ends {steps:.3f} / {steps_end:.3f} mm; inside (smoothed) {inside_moved[0]:.1f} mm"
        )
    assert loc < 0.01 and ang < 1e-3, (loc, ang)
    assert end_loc < 0.01 and end_ang < 1e-3, (end_loc, end_ang)
    if interpolation != "CONSTANT":  # (CONSTANT keys are holds: smoothing keeps them)
        assert inside_moved[0] > 1.0  # the inside is smoothed: it is not the source
    # no jump at the joins: a step of 0.01 frame is a small part of the motion's speed
    speed = np.linalg.norm(np.diff(now[:, :3, 3], axis=0), axis=1).max() * 1000 / 0.25
    assert steps < 0.05 * speed and steps_end < 0.05 * speed, (steps, steps_end, speed)
    # the source keys outside the range are kept: frames, values, interpolation, easing
    after_keys = {key: key_table(fc) for key, fc in curves_of(obj).items()}
    tol = 1e-4
    for key, table in before_keys.items():
        new = after_keys[key]
        for side in (table["co"][:, 0] < start - tol, table["co"][:, 0] > end + tol):
            rows = np.flatnonzero(side)
            kept = [np.flatnonzero(np.abs(new["co"][:, 0] - table["co"][r, 0]) < tol) for r in rows]
            assert all(len(k) == 1 for k in kept), key
            idx = np.array([k[0] for k in kept], dtype=int)
            np.testing.assert_array_equal(new["co"][idx], table["co"][rows], err_msg=str(key))
            assert [new["interpolation"][i] for i in idx] == [table["interpolation"][r] for r in rows], key
            assert [new["easing"][i] for i in idx] == [table["easing"][r] for r in rows], key
            # handles kept (the key next to the cut: its far handle)
            inner = slice(None, -1) if side[0] else slice(1, None)
            np.testing.assert_allclose(new["handle_left"][idx][inner], table["handle_left"][rows][inner], atol=F32)
            np.testing.assert_allclose(new["handle_right"][idx][inner], table["handle_right"][rows][inner], atol=F32)
    # the source action itself is untouched
    for key, table in before_keys.items():
        np.testing.assert_array_equal(key_table(curves_of(obj, source)[key])["co"], table["co"])


def test_a_channel_keyed_only_outside_the_range_is_split_exactly(capsys):
    """Scale keyed at frames 1 and 40 only: its one Bezier span is cut at both ends of the range."""
    obj, _ = keyed()
    for frame, value in ((1, (1.0, 1.5, 0.8)), (40, (2.0, 0.7, 1.1))):
        obj.scale = value
        obj.keyframe_insert("scale", frame=frame)
    frames = grid(-2, 44)
    was = played(obj, frames)
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30) == {"FINISHED"}
    now = played(obj, frames)
    outside = (frames < 10) | (frames > 30)
    scale_off = float(np.abs(np.linalg.norm(now[:, :3, :3], axis=1) - np.linalg.norm(was[:, :3, :3], axis=1))[outside].max())
    loc, ang = difference(now[outside], was[outside])
    with capsys.disabled():
        print(f"\n[range, scale keyed at 1 and 40 only] outside: {loc:.4f} mm, {ang:.5f} deg, scale {scale_off:.1e}")
    assert scale_off < 1e-6 and loc < 0.01 and ang < 1e-3
    scale_frames = sorted(kp.co[0] for fc in h.fcurves(obj) if fc.data_path == "scale" for kp in fc.keyframe_points)
    assert scale_frames[0] == 1.0 and scale_frames[-1] == 40.0


def test_the_report_says_the_range_was_smoothed_and_the_rest_kept(capfd):
    obj, _ = keyed()
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30) == {"FINISHED"}
    out = capfd.readouterr()
    text = out.out + out.err
    assert "smoothed frames 10 to 30 of Body" in text and "keys outside the range kept" in text, text


def test_a_range_without_motion_is_refused():
    obj, _ = keyed()
    source = obj.animation_data.action
    with pytest.raises(RuntimeError, match="frame range 50 to 60 holds none of its motion"):
        bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=50, frame_end=60)
    assert obj.animation_data.action is source


def test_an_end_inside_an_eased_span_moves_to_its_key_and_says_so(capfd):
    obj, _ = keyed(interpolation="SINE")
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30) == {"FINISHED"}
    text = "".join(capfd.readouterr())
    assert "smoothed frames 13 to 25 of Body (moved its start to the key at 13 and end to the key at 25" in text, text


def test_range_on_a_bone_keeps_the_keys_outside(capsys):
    rig = b.armature(holder=True)
    frames = [1, 6, 12, 18, 24, 30, 36, 40]
    b.key_bone(rig, "Upper", frames, b.random_poses(len(frames), 5), mode="QUATERNION")
    bpy.ops.object.mode_set(mode="POSE")
    b.select_bones(rig, ["Upper"])
    source = rig.animation_data.action
    pb = rig.pose.bones["Upper"]
    times = grid(0, 42)

    def basis():
        out = []
        for f in times:
            bpy.context.scene.frame_set(int(np.floor(f)), subframe=float(f - np.floor(f)))
            out.append(np.array(pb.matrix_basis))
        return np.array(out)

    was = basis()
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=9.5, frame_end=27) == {"FINISHED"}
    assert rig.animation_data.action is not source
    now = basis()
    outside = (times < 9.5) | (times > 27)
    loc, ang = difference(now[outside], was[outside])
    with capsys.disabled():
        print(f"\n[range on a bone 9.5..27] outside the range: {loc:.4f} mm, {ang:.5f} deg off the source")
    assert loc < 0.01 and ang < 1e-3
    assert difference(now[~outside], was[~outside])[0] > 1.0
    bpy.ops.object.mode_set(mode="OBJECT")


def test_remove_noise_keeps_the_keys_outside_and_joins_at_the_ends(capsys):
    """Remove Noise follows the same rule: keys outside the range untouched (so every frame
    there plays the source), the motion continuous across the range's ends."""
    obj = h.new_object("Cam", "EMPTY", "XYZ")
    rng = np.random.default_rng(4)
    n = 80
    t = np.arange(n) / 24.0
    clean = np.stack([4 * np.cos(0.3 * t), 4 * np.sin(0.3 * t), 1.5 + 0.2 * t, 1.2 + 0.05 * np.sin(t), 0.02 * t, 0.3 * t], axis=1)
    noisy = clean + np.concatenate([rng.normal(0, 0.02, (n, 3)), rng.normal(0, 0.01, (n, 3))], axis=1)
    obj.animation_data_create().action = bpy.data.actions.new("CamAction")
    for f, v in zip(range(1, n + 1), noisy):
        obj.location, obj.rotation_euler = v[:3], v[3:]
        obj.keyframe_insert("location", frame=f)
        obj.keyframe_insert("rotation_euler", frame=f)
    h.select_only(obj)
    before = {key: key_table(fc) for key, fc in curves_of(obj).items()}
    frames = np.arange(1, n + 1, dtype=float)
    fine = grid(1, n)
    fine_outside = (fine <= 19) | (fine >= 61)  # (between keys 19 and 20 the curve reaches the moved key 20)
    was = played(obj, frames)
    was_fine = played(obj, fine[fine_outside])
    assert bpy.ops.screwbender.denoise(range_mode="CUSTOM", frame_start=20, frame_end=60) == {"FINISHED"}
    now = played(obj, frames)
    loc, ang = difference(played(obj, fine[fine_outside]), was_fine)
    with capsys.disabled():
        print(f"\n[remove noise 20..60] outside (every quarter frame): {loc:.4f} mm, {ang:.5f} deg off the source")
    after = {key: key_table(fc) for key, fc in curves_of(obj).items()}
    for key, table in before.items():
        rows = (table["co"][:, 0] < 20) | (table["co"][:, 0] > 60)
        for name in ("co", "handle_left", "handle_right"):
            np.testing.assert_array_equal(after[key][name][rows], table[name][rows], err_msg=f"{key} {name}")
        assert [after[key]["interpolation"][i] for i in np.flatnonzero(rows)] == [
            table["interpolation"][i] for i in np.flatnonzero(rows)
        ]
    # joined: the step across each end is no larger than the steps of the source around it
    step = np.linalg.norm(np.diff(now[:, :3, 3], axis=0), axis=1) * 1000
    source_step = np.linalg.norm(np.diff(was[:, :3, 3], axis=0), axis=1) * 1000
    across = step[[18, 59]]  # frames 19 -> 20 and 60 -> 61
    with capsys.disabled():
        print(
            f"\n[remove noise 20..60] step across the ends "
            f"{across[0]:.1f} / {across[1]:.1f} mm (the source's largest step {source_step.max():.1f} mm)"
        )
    assert loc == 0.0 and ang < 1e-4
    assert across.max() <= source_step.max()


# --- item 3: every key is a baked frame ------------------------------------------------------------


KEY_TIMINGS = [
    ("a key at 12.5, 29.97 fps", (30000, 1001), [1.0, 12.5, 24.0]),
    ("keys at 11.01, 21.02, 31.03", (24, 1), [1.0, 11.01, 21.02, 31.03, 40.0]),
    ("keys every half frame", (30, 1), list(np.arange(1.0, 21.0, 0.5))),
]


@pytest.mark.parametrize("label, fps, frames", KEY_TIMINGS, ids=[k[0] for k in KEY_TIMINGS])
def test_every_key_is_a_baked_frame(capsys, label, fps, frames):
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = fps[0], fps[1]
    obj = h.new_object("Body", "MESH", "XYZ")
    seed = 11
    rng = np.random.default_rng(seed)
    poses = random_poses(len(frames), seed, reach=0.6 if len(frames) > 10 else 2.0)
    if len(frames) > 10:  # a capture: large turns between half frames
        from scipy.spatial.transform import Rotation

        poses[:, :3, :3] = Rotation.from_rotvec(np.cumsum(rng.normal(0, 0.3, (len(frames), 3)), axis=0)).as_matrix()
    h.key_poses(obj, frames, poses)
    source = obj.animation_data.action
    keys_played = played(obj, frames)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert obj.animation_data.action is not source
    now = played(obj, frames)
    loc, ang = difference(now, keys_played)
    baked_frames = h.channel(obj, "location", 3)[0]
    with capsys.disabled():
        print(f"\n[{label}] largest miss of the key poses with the defaults: {loc:.4f} mm, {ang:.5f} deg")
    for f in frames:
        assert np.min(np.abs(baked_frames - f)) < 1e-4, f"key frame {f} is not a baked frame"
    assert loc < 0.01 and ang < 1e-3, (loc, ang)
    # the grid is still there: every whole frame between the first and last key
    whole = np.arange(np.ceil(frames[0]), np.floor(frames[-1]) + 1)
    assert all(np.min(np.abs(baked_frames - f)) < 1e-4 for f in whole)


# --- item 7: unkeyed stays unkeyed -----------------------------------------------------------------


def _keyed_paths(obj, prefix=""):
    return sorted((fc.data_path[len(prefix):], fc.array_index) for fc in h.fcurves(obj) if fc.data_path.startswith(prefix))


@pytest.mark.parametrize("what", ["location", "rotation", "scale_xy", "quaternion_rotation"])
def test_unkeyed_channels_stay_unkeyed(capsys, what):
    mode = "QUATERNION" if what == "quaternion_rotation" else "XYZ"
    obj = h.new_object("Body", "MESH", mode)
    obj.rotation_euler = (0.3, -0.2, 0.1)
    obj.rotation_quaternion = (0.9, 0.1, 0.3, -0.2)
    obj.location = (0.5, 1.0, -2.0)
    obj.scale = (1.0, 1.0, 1.7)
    poses = random_poses(5, 21)
    frames = [1, 8, 15, 22, 30]
    path = h.rotation_path(mode)
    for i, f in enumerate(frames):
        if what == "location":
            obj.location = poses[i, :3, 3]
            obj.keyframe_insert("location", frame=f)
        elif what in ("rotation", "quaternion_rotation"):
            setattr(obj, path, h.continuous(h.rotation_from_matrix(poses[i, :3, :3], mode), list(getattr(obj, path)), mode))
            obj.keyframe_insert(path, frame=f)
        else:
            obj.scale = (1.0 + 0.2 * i, 2.0 - 0.1 * i, 1.7)
            obj.keyframe_insert("scale", index=0, frame=f)
            obj.keyframe_insert("scale", index=1, frame=f)
    source = obj.animation_data.action
    keyed_before = _keyed_paths(obj)
    times = np.array(frames, dtype=float)
    was = played(obj, times)
    was_full = np.array([np.array(obj.matrix_basis)])
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert obj.animation_data.action is not source
    keyed_after = _keyed_paths(obj)
    now = played(obj, times)
    loc, ang = difference(now, was)
    scale_err = float(np.abs(np.linalg.norm(now[:, :3, :3], axis=1) - np.linalg.norm(was[:, :3, :3], axis=1)).max())
    with capsys.disabled():
        print(f"\n[unkeyed, {what} keyed] curves before {keyed_before}, after {keyed_after}; key poses hit to "
              f"{loc:.4f} mm, {ang:.5f} deg, scale {scale_err:.2e}")
    assert keyed_after == keyed_before
    assert loc < 0.01 and ang < 1e-3 and scale_err < 1e-5
    del was_full


def test_unkeyed_bone_channels_stay_unkeyed(capsys):
    rig = b.armature(holder=False)
    pb = rig.pose.bones["Upper"]
    pb.rotation_mode = "XYZ"
    pb.rotation_euler = (0.2, 0.1, -0.3)
    frames = [1, 10, 20, 30]
    for i, f in enumerate(frames):
        pb.location = (0.3 * i, np.sin(i), 0.1 * i * i)
        pb.keyframe_insert("location", frame=f)
    bpy.ops.object.mode_set(mode="POSE")
    b.select_bones(rig, ["Upper"])
    prefix = 'pose.bones["Upper"].'
    before = _keyed_paths(rig, prefix)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    after = _keyed_paths(rig, prefix)
    got = []
    for f in frames:
        bpy.context.scene.frame_set(f)
        got.append((tuple(pb.location), tuple(pb.rotation_euler)))
    with capsys.disabled():
        print(f"\n[unkeyed bone channels] curves before {before}, after {after}")
    assert after == before
    for i, (location, rotation) in enumerate(got):
        np.testing.assert_allclose(location, (0.3 * i, np.sin(i), 0.1 * i * i), atol=F32)
        np.testing.assert_allclose(rotation, (0.2, 0.1, -0.3), atol=F32)
    bpy.ops.object.mode_set(mode="OBJECT")


def test_a_range_bake_failing_halfway_changes_nothing_and_undo_restores():
    """The joined write runs in Smooth Motion's transaction: a failure after some of its curves
    are written leaves `bpy.data` as it was; a finished run is one undo step."""
    a, _ = keyed("A")
    b_obj, _ = keyed("B", seed=4)
    h.select_only(a, b_obj)
    module = addon_module("blender.range_join")
    original = module.write
    calls = {"n": 0}

    def failing(*args, **kwargs):
        original(*args, **kwargs)
        calls["n"] += 1
        if calls["n"] == 8:  # A's six curves written, then two of B's
            raise RuntimeError("injected failure in range_join.write")

    before = h.snapshot_data(key_selection=True)
    module.write = failing
    try:
        with pytest.raises(RuntimeError, match="nothing was changed"):
            bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30)
    finally:
        module.write = original
    assert calls["n"] == 8
    assert h.snapshot_data(key_selection=True) == before
    source_name = a.animation_data.action.name
    bpy.ops.ed.undo_push(message="before")
    assert bpy.ops.screwbender.smooth(
        "EXEC_DEFAULT", True, range_mode="CUSTOM", frame_start=10, frame_end=30
    ) == {"FINISHED"}
    assert a.animation_data.action.name.endswith(".smooth")
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert bpy.data.objects["A"].animation_data.action.name == source_name
