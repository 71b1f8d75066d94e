"""Smooth Motion with Keys: Reduced keeps what issue 24 keeps with Every Step: a Frame Range
narrower than the keys keeps the source outside it, F-curve modifiers stay on the result and
act on it, unkeyed channels stay unkeyed. (Each part was built apart; these are the seams.)"""

from __future__ import annotations

import bpy
import numpy as np

import bake_helpers as h
from conftest import addon_module
from test_range_and_grid import curves_of, difference, grid, keyed, played


def test_reduced_with_a_narrower_range_keeps_the_keys_outside(sb):
    obj, _ = keyed("Ranged")
    source = obj.animation_data.action
    frames = grid(-2, 44)
    before = played(obj, frames)
    first_keys = {k: fc.keyframe_points[0].co[:] for k, fc in curves_of(obj).items()}
    result = bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10.0, frame_end=30.0, key_mode="REDUCED")
    assert result == {"FINISHED"}
    assert obj.animation_data.action is not source
    now = played(obj, frames)
    outside = (frames < 10.0) | (frames > 30.0)
    loc, ang = difference(now[outside], before[outside])
    print(f"\n[Reduced + Custom 10..30] outside the range {loc:.4f} mm, {ang:.5f} deg off the source")
    assert loc < 0.01 and ang < 1e-3, (loc, ang)
    # the keys before the range are still there (the first one of every curve)
    for key, co in first_keys.items():
        assert tuple(curves_of(obj)[key].keyframe_points[0].co) == tuple(co), key
    # the inside is the smoothed motion, not the source
    assert difference(now[~outside], before[~outside])[0] > 1.0


def test_reduced_keeps_a_noise_modifier_and_unkeyed_channels(sb):
    obj = h.new_object("Shaky", "MESH", "XYZ")
    frames = [1, 11, 21, 31]
    poses = h.rigid(np.array([[0, 0, 0], [2, 1, 0], [4, 0, 1], [6, 2, 0]], float), np.repeat(np.eye(3)[None], 4, 0))
    h.key_poses(obj, frames, poses)
    for fc in list(h.fcurves(obj)):  # location only: the rotation curves go
        if fc.data_path != "location":
            _remove(obj, fc)
    assert {fc.data_path for fc in h.fcurves(obj)} == {"location"}
    noise = curves_of(obj)["location", 0].modifiers.new("NOISE")
    noise.strength, noise.scale, noise.phase = 0.4, 3.0, 7.0
    times = np.arange(1.0, 31.0, 0.5)

    def shake(fc, modifier) -> np.ndarray:
        """The modifier's part of the curve's playback (muted and unmuted)."""
        on = np.array([fc.evaluate(t) for t in times])
        modifier.mute = True
        off = np.array([fc.evaluate(t) for t in times])
        modifier.mute = False
        return on - off

    source_shake = shake(curves_of(obj)["location", 0], noise)
    assert bpy.ops.screwbender.smooth(key_mode="REDUCED") == {"FINISHED"}
    result = curves_of(obj)
    assert {k[0] for k in result} == {"location"}, sorted(result)  # unkeyed rotation stays unkeyed
    mods = [m for m in result["location", 0].modifiers if m.type == "NOISE"]
    assert len(mods) == 1
    np.testing.assert_allclose((mods[0].strength, mods[0].scale, mods[0].phase), (0.4, 3.0, 7.0), rtol=1e-6)
    fc = result["location", 0]
    got = shake(fc, mods[0])
    print(f"\n[Reduced + Noise] keys {len(fc.keyframe_points)}; shake RMS {np.sqrt(np.mean(got**2)):.4f} "
          f"(source {np.sqrt(np.mean(source_shake**2)):.4f})")
    # the modifier acts on the reduced keys as it acted on the source's: the same shake
    np.testing.assert_allclose(got, source_shake, atol=1e-5)
    assert np.sqrt(np.mean(got**2)) > 0.01
    assert len(fc.keyframe_points) <= 31


def _remove(obj, fc) -> None:
    """Removes `fc` from the object's action whatever the action API (4.4+ channelbags)."""
    channels = addon_module("blender.channels")
    action = obj.animation_data.action
    bag = channels.ensure_container(action, channels.find_slot(action, channels.slot_identifier(obj)))
    channels.remove_fcurve(bag, fc)
