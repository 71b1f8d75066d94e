"""Remove Noise (issue 19): the operator on objects and bones, held keys, frame ranges,
sparse keys, Revert, undo, all or nothing; results compared with the known truth."""

from __future__ import annotations

import math

import bpy
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h
from conftest import addon_module

N = 120


def truth(n: int = N) -> np.ndarray:
    """A slow orbit and dolly (location in metres, XYZ Euler radians): (n, 6)."""
    t = np.arange(n) / 24.0
    loc = np.stack([4 * np.cos(0.3 * t), 4 * np.sin(0.3 * t), 1.5 + 0.2 * t], axis=1)
    rot = np.stack([1.2 + 0.05 * np.sin(t), 0.02 * t, 0.3 * t + 1.6], axis=1)
    return np.concatenate([loc, rot], axis=1)


def keyed_noisy(name="Cam", seed=1, frames=None, sigma=(0.02, math.radians(0.5))):
    obj = h.new_object(name, "EMPTY", "XYZ")
    frames = np.arange(1, N + 1, dtype=float) if frames is None else frames
    clean = truth(int(frames[-1]))[(frames - 1).astype(int)]
    rng = np.random.default_rng(seed)
    noisy = clean + np.concatenate([rng.normal(0, sigma[0], (len(frames), 3)), rng.normal(0, sigma[1], (len(frames), 3))], axis=1)
    action = bpy.data.actions.new(f"{name}Action")
    obj.animation_data_create().action = action
    for f, v in zip(frames, noisy):  # keys as a capture writes them: one per frame
        obj.location, obj.rotation_euler = v[:3], v[3:]
        obj.keyframe_insert("location", frame=f)
        obj.keyframe_insert("rotation_euler", frame=f)
    h.select_only(obj)
    return obj, frames, clean, noisy


def key_values(obj) -> dict:
    return {(fc.data_path, fc.array_index): h.curve_points(fc) for fc in h.fcurves(obj)}


def matrices(values: np.ndarray) -> np.ndarray:
    """Rigid (n, 4, 4) from (n, 6) location + XYZ Euler."""
    m = np.zeros((len(values), 4, 4))
    m[:, :3, :3] = Rotation.from_euler("xyz", values[:, 3:]).as_matrix()
    m[:, :3, 3], m[:, 3, 3] = values[:, :3], 1.0
    return m


def channel_matrix(obj) -> tuple[np.ndarray, np.ndarray]:
    frames, loc = h.channel(obj, "location", 3)
    _, rot = h.channel(obj, "rotation_euler", 3)
    return frames, matrices(np.concatenate([loc, rot], axis=1))


def errors(est: np.ndarray, ref: np.ndarray) -> tuple[float, float]:
    loc = np.sqrt(np.mean(np.sum((est[:, :3, 3] - ref[:, :3, 3]) ** 2, axis=1)))
    r = np.einsum("nji,njk->nik", est[:, :3, :3], ref[:, :3, :3])
    ang = np.degrees(np.arccos(np.clip((np.trace(r, axis1=1, axis2=2) - 1) / 2, -1, 1)))
    return float(loc), float(np.sqrt(np.mean(ang**2)))


def test_remove_noise_brings_keys_closer_to_the_truth(sb, capfd):
    obj, frames, clean, noisy = keyed_noisy()
    source = obj.animation_data.action
    for fc in h.fcurves(obj):  # nothing selected: every key is smoothed
        for kp in fc.keyframe_points:
            kp.select_control_point = False
    before = h.snapshot_action(source)
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    out = capfd.readouterr().out
    assert "Removed noise from 1: Cam; strength chosen from the data: rotation" in out
    assert obj.animation_data.action != source
    assert h.snapshot_action(source) == before  # the original is kept as it was
    got_frames, smoothed = channel_matrix(obj)
    np.testing.assert_array_equal(got_frames, frames)  # the keys stay keys
    e_noisy = errors(matrices(noisy), matrices(clean))
    e_ours = errors(smoothed, matrices(clean))
    print(f"Remove Noise: location RMS {1000 * e_noisy[0]:.1f} -> {1000 * e_ours[0]:.1f} mm, "
          f"rotation RMS {e_noisy[1]:.3f} -> {e_ours[1]:.3f} deg")
    assert e_ours[0] < 0.6 * e_noisy[0] and e_ours[1] < 0.6 * e_noisy[1]
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == source


def test_unselected_keys_are_held_and_the_frame_range_is_kept(sb):
    obj, frames, clean, noisy = keyed_noisy(seed=2)
    chosen = (frames > 30) & (frames < 100)
    outside = frames <= 5  # selected too, but outside the frame range
    for fc in h.fcurves(obj):
        for kp in fc.keyframe_points:
            kp.select_control_point = bool((chosen | outside)[int(kp.co[0]) - 1])
    old = key_values(obj)
    assert bpy.ops.screwbender.denoise(range_mode="CUSTOM", frame_start=10, frame_end=110) == {"FINISHED"}
    new = key_values(obj)
    for path, points in old.items():
        same = ~chosen
        np.testing.assert_array_equal(new[path][same], points[same])  # held and outside: exactly kept
        np.testing.assert_array_equal(new[path][outside], points[outside])  # selected, outside the range
        assert np.abs(new[path][chosen, 1] - points[chosen, 1]).max() > 0  # the selected ones moved


def test_sparse_keys_are_approximated_and_keep_their_handles(sb):
    frames = np.array([1, 9, 20, 28, 41, 50, 63, 70, 84, 95], dtype=float)
    obj, _, clean, noisy = keyed_noisy(frames=frames, seed=3, sigma=(0.2, math.radians(4)))
    fc = h.fcurves(obj)[0]
    types = [kp.handle_left_type for kp in fc.keyframe_points]
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    fc = [f for f in h.fcurves(obj) if f.data_path == fc.data_path and f.array_index == fc.array_index][0]
    assert [kp.handle_left_type for kp in fc.keyframe_points] == types
    for kp in fc.keyframe_points:  # handles moved with their key
        assert kp.handle_left[0] < kp.co[0] < kp.handle_right[0]
    _, smoothed = channel_matrix(obj)
    assert errors(smoothed, matrices(clean))[0] < errors(matrices(noisy), matrices(clean))[0]


def test_bones_of_a_rig_in_one_call(sb):
    data = bpy.data.armatures.new("Rig")
    rig = bpy.data.objects.new("Rig", data)
    bpy.context.scene.collection.objects.link(rig)
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="EDIT")
    for i in range(4):
        b = data.edit_bones.new(f"B{i}")
        b.head, b.tail = (i, 0, 0), (i, 0, 1)
    bpy.ops.object.mode_set(mode="OBJECT")
    rng = np.random.default_rng(4)
    clean = {}
    for i, pb in enumerate(rig.pose.bones):
        pb.rotation_mode = "XYZ"
        c = truth()[:, 3:] * (0.3 + 0.2 * i) - np.array([1.2, 0.0, 1.6]) * (0.3 + 0.2 * i)
        clean[pb.name] = c
        noisy = c + rng.normal(0, math.radians(1.0), c.shape)
        for f, v in enumerate(noisy, start=1):
            pb.rotation_euler = v
            pb.keyframe_insert("rotation_euler", frame=f)
    h.select_only(rig)
    calls = {"n": 0}
    module = addon_module("blender.denoise")
    original = module.polyscrew.denoise

    def counting(*args, **kwargs):
        calls["n"] += 1
        return original(*args, **kwargs)

    module.polyscrew.denoise = counting
    try:
        assert bpy.ops.screwbender.denoise(armature="BONES") == {"FINISHED"}
    finally:
        module.polyscrew.denoise = original
    assert calls["n"] == 1  # four bones on the same frames: one batched call
    for pb in rig.pose.bones:
        _, rot = h.channel_from(rig, f'pose.bones["{pb.name}"].rotation_euler', 3)
        smoothed_err = np.degrees(np.sqrt(np.mean((rot - clean[pb.name]) ** 2)))
        assert smoothed_err < 0.6  # from 1 degree of noise per axis


def test_failure_halfway_changes_nothing(sb):
    a, _, _, _ = keyed_noisy("A", seed=5)
    b, _, _, _ = keyed_noisy("B", seed=6)
    h.select_only(a, b)
    module = addon_module("blender.denoise")
    original = module._edit_keys
    calls = {"n": 0}

    def failing(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 2:
            raise RuntimeError("injected")
        return original(*args, **kwargs)

    before = h.snapshot_data(key_selection=True)
    module._edit_keys = failing
    try:
        with pytest.raises(RuntimeError, match="Remove Noise failed .*nothing was changed"):
            bpy.ops.screwbender.denoise()
    finally:
        module._edit_keys = original
    assert calls["n"] == 2
    assert h.snapshot_data(key_selection=True) == before


def test_undo_restores_the_action(sb):
    obj, _, _, _ = keyed_noisy("U", seed=7)
    bpy.ops.ed.undo_push(message="before")
    assert bpy.ops.screwbender.denoise("EXEC_DEFAULT", True) == {"FINISHED"}
    assert obj.animation_data.action.name != "UAction"
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert bpy.data.objects["U"].animation_data.action.name == "UAction"


def test_too_few_keys_refused(sb):
    obj, _, _, _ = keyed_noisy("Few", frames=np.array([1.0, 5.0, 9.0]))
    with pytest.raises(RuntimeError, match="Few: 3 key frame\\(s\\) in the frame range; Remove Noise needs at least 4"):
        bpy.ops.screwbender.denoise()


def full_keys(obj) -> dict:
    """Per curve of `obj`'s action: its keys' co, handle_left and handle_right, (n, 6)."""
    out = {}
    for fc in h.fcurves(obj):
        kp = fc.keyframe_points
        parts = []
        for attr in ("co", "handle_left", "handle_right"):
            buf = np.empty(2 * len(kp), dtype=np.float32)
            kp.foreach_get(attr, buf)
            parts.append(buf.reshape(-1, 2))
        out[fc.data_path, fc.array_index] = np.concatenate(parts, axis=1)
    return out


def select_keys(obj, chosen) -> None:
    """Selects the keys of `obj`'s curves at the frames (1-based) where `chosen` is True."""
    for fc in h.fcurves(obj):
        flags = np.array([bool(chosen[int(round(kp.co[0])) - 1]) for kp in fc.keyframe_points])
        fc.keyframe_points.foreach_set("select_control_point", flags)


def test_a_rerun_starts_again_from_the_original_keys(sb):
    """A second run with a smaller frame range: the keys outside it are the original keys
    again (not the first run's smoothed ones), as "replacing the earlier result" promises."""
    obj, frames, _, _ = keyed_noisy("Again", seed=8)
    select_keys(obj, np.zeros(len(frames), dtype=bool))
    original = full_keys(obj)
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    first = full_keys(obj)
    assert all(np.abs(first[k][:, 1] - original[k][:, 1]).max() > 0 for k in original)  # the first run moved them
    assert bpy.ops.screwbender.denoise(range_mode="CUSTOM", frame_start=30, frame_end=90) == {"FINISHED"}
    second = full_keys(obj)
    inside = (frames >= 30) & (frames <= 90)
    # (the values: auto handles follow the moved keys nearby, Blender's handle rule)
    for k, keys in original.items():
        np.testing.assert_array_equal(second[k][~inside, :2], keys[~inside, :2])  # the original keys
        assert np.abs(second[k][inside, 1] - keys[inside, 1]).max() > 0


def test_a_rerun_holds_the_keys_unselected_on_the_result_shown(sb):
    """On a rerun the user selects keys on the result (what the Graph Editor shows), not on
    the original action: the selection is read there."""
    obj, frames, _, _ = keyed_noisy("Shown", seed=9)
    select_keys(obj, np.zeros(len(frames), dtype=bool))  # the original: nothing selected
    original = full_keys(obj)
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    chosen = (frames > 30) & (frames < 100)
    select_keys(obj, chosen)  # on the result shown
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    second = full_keys(obj)
    for k, keys in original.items():
        np.testing.assert_array_equal(second[k][~chosen, :2], keys[~chosen, :2])  # held: the original keys
        assert np.abs(second[k][chosen, 1] - keys[chosen, 1]).max() > 0


def spin_keys(name: str, frames: np.ndarray, z_degrees: np.ndarray, seed: int):
    """An empty (XYZ Euler) turning about Z through `z_degrees` (winding past a turn), with
    noise on every channel; nothing selected. Returns it and its Z rotation keys (radians)."""
    obj = h.new_object(name, "EMPTY", "XYZ")
    rng = np.random.default_rng(seed)
    z = np.radians(z_degrees) + rng.normal(0, math.radians(0.5), len(frames))
    obj.animation_data_create().action = bpy.data.actions.new(f"{name}Action")
    for f, zf in zip(frames, z):
        obj.location = rng.normal(0, 0.01, 3)
        obj.rotation_euler = (0.2 + rng.normal(0, 0.01), 0.1 + rng.normal(0, 0.01), zf)
        obj.keyframe_insert("location", frame=f)
        obj.keyframe_insert("rotation_euler", frame=f)
    h.select_only(obj)
    select_keys(obj, np.zeros(int(frames[-1]), dtype=bool))
    return obj, z


def z_keys(obj) -> np.ndarray:
    return [h.curve_points(fc)[:, 1] for fc in h.fcurves(obj) if fc.data_path == "rotation_euler" and fc.array_index == 2][0]


def test_a_spinning_object_keeps_its_winding(sb):
    """Euler Z keyed every frame from 0 to 1000 degrees: the smoothed curve winds as much."""
    frames = np.arange(1, 101, dtype=float)
    obj, z = spin_keys("Spinner", frames, np.linspace(0, 1000, 100), seed=10)
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    new = z_keys(obj)
    assert abs(math.degrees((new[-1] - new[0]) - (z[-1] - z[0]))) < 1.0
    assert np.abs(np.degrees(new - z)).max() < 5.0  # every key near its own value, not a turn off


def test_sparse_euler_keys_keep_their_spin_and_held_keys_their_values(sb):
    """Keys 270 degrees apart (a spin the animator keyed) come back 270 apart, not -90
    (continuity's choice); the held key at 370 degrees stays 370 degrees exactly."""
    frames = np.array([1, 11, 21, 31, 41, 51, 61], dtype=float)
    degrees = np.array([0, 270, 370, 640, 910, 1180, 1450], dtype=float)
    obj, z = spin_keys("Sparse", frames, degrees, seed=11)
    held = 21
    select_keys(obj, np.arange(1, 62) != held)
    before = full_keys(obj)
    # a light smoothing (the keys are ten frames apart): the test is about how keys are written
    assert bpy.ops.screwbender.denoise(auto_strength=False, strength=1.0) == {"FINISHED"}
    after = full_keys(obj)
    row = int(np.flatnonzero(frames == held)[0])
    for k in before:
        np.testing.assert_array_equal(after[k][row, :2], before[k][row, :2])  # the held key, exactly
    new = z_keys(obj)
    assert np.abs(np.degrees(new - z)).max() < 90.0  # each key near its own value: the spin is kept
    assert abs(math.degrees((new[-1] - new[0]) - (z[-1] - z[0]))) < 45.0


def test_quaternion_keys_keep_their_sign(sb):
    """Quaternion keys whose sign the animator flipped (q and -q: the same rotation, a
    different interpolation) keep their signs: each smoothed key is on the original's side."""
    obj = h.new_object("Quat", "EMPTY", "QUATERNION")
    obj.animation_data_create().action = bpy.data.actions.new("QuatAction")
    rng = np.random.default_rng(12)
    frames = np.arange(1, 61, dtype=float)
    angles = np.stack([0.3 + 0.02 * frames, 0.01 * frames, 0.05 * frames], axis=1) + rng.normal(0, 0.01, (60, 3))
    q = Rotation.from_euler("xyz", angles).as_quat()[:, [3, 0, 1, 2]]
    q[20:40] *= -1.0
    for f, value in zip(frames, q):
        obj.rotation_quaternion = value
        obj.keyframe_insert("rotation_quaternion", frame=f)
    h.select_only(obj)
    select_keys(obj, np.zeros(60, dtype=bool))
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    _, new = h.channel(obj, "rotation_quaternion", 4)
    dots = np.sum(new * q, axis=1)
    assert (dots > 0.99).all(), dots.min()


def test_keys_a_hair_after_a_frame_are_written(sb):
    """A curve keyed a hair (within the frame tolerance) after the other curves' frames: its
    keys are those frames' keys and are smoothed too (the nearest frame, on either side)."""
    obj, frames, _, _ = keyed_noisy("Hair", seed=13)
    fc = [f for f in h.fcurves(obj) if f.data_path == "location" and f.array_index == 0][0]
    co = h.curve_points(fc).astype(np.float32)
    co[:, 0] += np.float32(5e-5)
    fc.keyframe_points.foreach_set("co", co.ravel())
    fc.update()
    select_keys(obj, np.zeros(len(frames), dtype=bool))
    before = h.curve_points(fc)
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    after = [h.curve_points(f) for f in h.fcurves(obj) if f.data_path == "location" and f.array_index == 0][0]
    np.testing.assert_array_equal(after[:, 0], before[:, 0])
    assert (np.abs(after[1:-1, 1] - before[1:-1, 1]) > 0).mean() > 0.9  # smoothed, not skipped


def test_a_muted_curve_is_left_alone(sb):
    """keys.read ignores a muted curve; Remove Noise does not write it either."""
    obj, frames, _, _ = keyed_noisy("Muted", seed=14)
    select_keys(obj, np.zeros(len(frames), dtype=bool))
    fc = [f for f in h.fcurves(obj) if f.data_path == "location" and f.array_index == 2][0]
    fc.mute = True
    before = full_keys(obj)
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    after = full_keys(obj)
    np.testing.assert_array_equal(after["location", 2], before["location", 2])
    assert np.abs(after["location", 0][:, 1] - before["location", 0][:, 1]).max() > 0


def test_a_rerun_is_reported(sb, capfd):
    obj, frames, _, _ = keyed_noisy("Told", seed=15)
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    capfd.readouterr()
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    assert "removed the noise of the original keys of Told again (replacing the earlier result)" in capfd.readouterr().out
