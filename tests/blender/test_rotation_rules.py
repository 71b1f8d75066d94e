"""One home for each rule (issue 25, item 2), seen from Blender: Remove Noise writes
each smoothed key like the key the animator typed (`polyscrew.rotation_channels_near`, once the
add-on's numpy `_like_original`): spins beyond a turn, a deliberate quaternion sign flip and
the axis-angle angle beyond 2 pi are kept, per key. The written values are read back from the
F-curves and turned into matrices by Blender's own mathutils; the add-on's rotation table is
the core's (`polyscrew.ROTATION_MODES`) and Blender's, and so is the list of the Cycles modifier's
settings it reads (`polyscrew.CYCLES_PROPERTIES`)."""

from __future__ import annotations

import math

import bpy
import numpy as np
import polyscrew
import pytest
from mathutils import Euler, Quaternion

import bake_helpers as h

N = 60


def blender_matrix(values: np.ndarray, mode: str) -> np.ndarray:
    """The rotation matrix Blender makes of one set of channel values (mathutils)."""
    if mode == "QUATERNION":
        return np.array(Quaternion(values).normalized().to_matrix())
    if mode == "AXIS_ANGLE":
        return np.array(Quaternion(values[1:], values[0]).to_matrix())
    return np.array(Euler(values, mode).to_matrix())


def spinning_capture(mode: str, seed: int = 5) -> np.ndarray:
    """(N, width) key values of a noisy capture spinning about a tilted axis by three turns,
    as an animator's keys hold them: Euler angles and the axis-angle angle beyond 2 pi, and
    the quaternion keys' sign flipped by hand from the middle on."""
    rng = np.random.default_rng(seed)
    t = np.arange(N) / (N - 1)
    axis = np.array([0.2, 0.3, 1.0]) / np.linalg.norm([0.2, 0.3, 1.0])
    angle = 3.0 * 2.0 * np.pi * t + rng.normal(0.0, math.radians(0.5), N)
    if mode == "AXIS_ANGLE":
        return np.concatenate([angle[:, None], np.tile(axis, (N, 1))], axis=1)
    if mode == "QUATERNION":
        q = np.array([list(Quaternion(axis, a)) for a in angle])
        q[N // 2:] *= -1.0
        return q
    values = []
    for a in angle:
        e = Quaternion(axis, a).to_euler(mode)
        if values:
            e.make_compatible(Euler(values[-1], mode))
        values.append(list(e))
    return np.array(values)


def test_the_rotation_table_is_the_cores_and_blenders(sb):
    table = {mode: (path, 4 if path != "rotation_euler" else 3) for mode, path in sb.keys.ROTATION_PATHS.items()}
    assert table == polyscrew.ROTATION_MODES
    blender_modes = {item.identifier for item in bpy.types.Object.bl_rna.properties["rotation_mode"].enum_items}
    assert set(polyscrew.ROTATION_MODES) == blender_modes
    obj = h.new_object("Table", "EMPTY")
    for mode, (path, width) in polyscrew.ROTATION_MODES.items():
        obj.rotation_mode = mode
        assert len(getattr(obj, path)) == width, mode


@pytest.mark.parametrize("mode", ["QUATERNION", "AXIS_ANGLE", "XYZ", "ZXY"])
def test_remove_noise_writes_each_key_like_the_animators(sb, capfd, mode):
    name = f"Spin{mode}"
    obj = h.new_object(name, "EMPTY", mode)
    obj.animation_data_create().action = bpy.data.actions.new(f"{name}Action")
    path = sb.keys.rotation_path(mode)
    original = spinning_capture(mode)
    for frame, values in enumerate(original, start=1):
        obj.location = (0.01 * frame, 0.0, 0.0)
        setattr(obj, path, values)
        obj.keyframe_insert("location", frame=frame)
        obj.keyframe_insert(path, frame=frame)
    for fc in h.fcurves(obj):
        fc.keyframe_points.foreach_set("select_control_point", np.zeros(len(fc.keyframe_points), dtype=bool))
    h.select_only(obj)
    capfd.readouterr()
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    width = polyscrew.ROTATION_MODES[mode][1]
    frames, written = h.channel(obj, path, width)
    np.testing.assert_array_equal(frames, np.arange(1, N + 1, dtype=float))
    # the smoothed rotation is near the key's (Blender's matrices of both)
    turn = [
        math.degrees(math.acos(np.clip((np.trace(blender_matrix(w, mode).T @ blender_matrix(o, mode)) - 1) / 2, -1, 1)))
        for w, o in zip(written, original)
    ]
    # and is written like the key: the same sign, the same turn count
    if mode == "QUATERNION":
        like = np.sum(written * original, axis=1)
        assert (like > 0.99).all(), like.min()
        worst = float(np.abs(written - original).max())
    elif mode == "AXIS_ANGLE":
        assert (np.sum(written[:, 1:] * original[:, 1:], axis=1) > 0.99).all()
        worst = float(np.abs(written[:, 0] - original[:, 0]).max())
    else:
        worst = float(np.abs(written - original).max())
    print(f"{mode}: largest turn to the key {max(turn):.3f} deg; largest change of a key value {worst:.4f} "
          f"(keys span {np.ptp(original, axis=0).max():.1f})")
    assert max(turn) < 2.0
    assert worst < math.radians(5.0), worst


def test_the_cycles_properties_are_the_cores_and_blenders(sb):
    """The one list of the Cycles modifier's settings `evaluate_fcurves` reads: the add-on passes
    those (`curves.CYCLES_PROPERTIES`, once a copy of the binding's list), each an RNA property of
    Blender's FModifierCycles."""
    curves = sb.keys.curves
    assert curves.CYCLES_PROPERTIES == polyscrew.CYCLES_PROPERTIES
    rna = set(bpy.types.FModifierCycles.bl_rna.properties.keys())
    assert set(polyscrew.CYCLES_PROPERTIES) <= rna, set(polyscrew.CYCLES_PROPERTIES) - rna
    assert {"mode_before", "mode_after", "cycles_before", "cycles_after"} <= set(polyscrew.CYCLES_PROPERTIES)
