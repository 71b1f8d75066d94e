"""Remove Noise (issue 19): the operator on objects and bones, held keys, frame ranges,
sparse keys, Revert, undo, all or nothing; results compared with the known truth."""

from __future__ import annotations

import contextlib
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
    before = h.snapshot_action(source)
    for fc in h.fcurves(obj):  # nothing selected: every key is smoothed
        for kp in fc.keyframe_points:
            kp.select_control_point = False
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
    for fc in h.fcurves(obj):
        for kp in fc.keyframe_points:
            kp.select_control_point = bool(chosen[int(kp.co[0]) - 1])
    old = key_values(obj)
    assert bpy.ops.screwbender.denoise(range_mode="CUSTOM", frame_start=10, frame_end=110) == {"FINISHED"}
    new = key_values(obj)
    for path, points in old.items():
        same = ~chosen
        np.testing.assert_array_equal(new[path][same], points[same])  # held and outside: exactly kept
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
    module = addon_module("denoise")
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
        noisy_err = np.degrees(np.sqrt(np.mean((rot - clean[pb.name]) ** 2)))
        assert noisy_err < 0.6  # from 1 degree of noise per axis


def test_failure_halfway_changes_nothing(sb):
    a, _, _, _ = keyed_noisy("A", seed=5)
    b, _, _, _ = keyed_noisy("B", seed=6)
    h.select_only(a, b)
    module = addon_module("denoise")
    original = module._edit_keys
    calls = {"n": 0}

    def failing(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 2:
            raise RuntimeError("injected")
        return original(*args, **kwargs)

    before = h.snapshot_data()
    module._edit_keys = failing
    try:
        with pytest.raises(RuntimeError, match="Remove Noise failed .*nothing was changed"):
            bpy.ops.screwbender.denoise()
    finally:
        module._edit_keys = original
    assert calls["n"] == 2
    assert h.snapshot_data() == before


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
