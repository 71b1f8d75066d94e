"""Remove Noise's Blender and playback calls on a capture (issue 27): what it no longer does,
counted through wrappers, and the keys it writes the same as when it does it.

- A curve keyed on every key frame without modifiers plays its key values there: the key poses
  are read from them, not from the curves' playback (`intent.Source.channels`), and they are
  the playback's values bit for bit.
- Keys whose handles are all automatic (AUTO, AUTO_CLAMPED) get their handles from
  `fc.update()`: only `co` is written to them (one `foreach_set`, not three), and the keys
  are those written with the handles, bit for bit; a curve with other handles still gets its
  handles written.
"""

from __future__ import annotations

import bpy
import numpy as np
import pytest

import bake_helpers as h
from conftest import addon_module
from playback_rows import playing_rows
from test_noise_batch import FRAMES_A, noisy_keys, owners_of, written


def capture(count: int, mode: str = "XYZ", seed: int = 5) -> list[bpy.types.Object]:
    """`count` empties keyed on every frame of FRAMES_A (location and rotation in `mode`),
    in a fresh file, selected."""
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    rng = np.random.default_rng(seed)
    objects = []
    for i in range(count):
        ob = bpy.data.objects.new(f"Take{i}", None)
        bpy.context.scene.collection.objects.link(ob)
        noisy_keys(ob, FRAMES_A, mode, rng)
        objects.append(ob)
    h.select_only(*objects)
    return objects


def counting(monkeypatch, module, name: str, calls: list) -> None:
    """Wraps `module.name`, appending each call's positional arguments to `calls`."""
    original = getattr(module, name)

    def wrapper(*args, **kwargs):
        calls.append(args)
        return original(*args, **kwargs)

    monkeypatch.setattr(module, name, wrapper)


@pytest.mark.parametrize("mode", ["XYZ", "QUATERNION", "AXIS_ANGLE"])
def test_a_capture_is_read_from_its_key_values_not_its_playback(monkeypatch, mode):
    """Six owners keyed on every frame: no row of their playbacks played while Remove Noise
    reads them (the key frames of each before), and the key poses read are the playback's
    channels bit for bit. Keys on different frames per curve are still played (the
    playbacks' own counter, :mod:`playback_rows`, sees it)."""
    intent, keys = addon_module("pure.intent"), addon_module("blender.keys")
    capture(6, mode)
    calls: list = []
    counting(monkeypatch, intent.Source, "channels", calls)
    with playing_rows() as played:
        assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    assert len(calls) == 0 and played["rows"] == 0 and played["sources"] == 6, (
        f"{len(calls)} playbacks of a capture, {played}"
    )
    # The values read are those Blender plays at the key frames.
    for owner in owners_of(capture(2, mode)):
        motion = keys.read(owner, "OFF", analyse=False, key_values=True)
        played = motion.source.channels(motion.frames)
        poses = keys.compose(played["location"], keys.rotation_matrices(played[keys.rotation_path(mode)], mode))
        assert np.array_equal(motion.poses, poses)
        assert np.array_equal(motion.scales, played["scale"])
    # Location keyed on other frames than the rotation: the playback is read.
    calls.clear()
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    ob = bpy.data.objects.new("Sparse", None)
    bpy.context.scene.collection.objects.link(ob)
    noisy_keys(ob, FRAMES_A, mode, np.random.default_rng(2))
    for frame in FRAMES_A[1::2]:
        ob.keyframe_delete("location", frame=frame)
    h.select_only(ob)
    with playing_rows() as played:
        assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    assert played["rows"] >= len(FRAMES_A), played  # (the key frames at least)


def test_automatic_handles_are_left_to_update(monkeypatch):
    """Four objects keyed on every frame (AUTO_CLAMPED handles), one of them with FREE handles
    on its rotation curves: `co` written once per curve, the handles only to the three FREE
    curves (three writes per curve before), and every key, handle and handle type is what
    writing every curve's handles gives."""
    denoise, bulk = addon_module("blender.denoise"), addon_module("blender.bulk")

    def scene() -> list:
        objects = capture(4)
        for fc in addon_module("blender.channels").object_fcurves(objects[1]):
            if fc.data_path == "rotation_euler":
                for point in fc.keyframe_points:
                    point.handle_left_type = point.handle_right_type = "FREE"
        return objects

    objects = scene()
    puts: list = []
    counting(monkeypatch, bulk, "put", puts)
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    attrs = [args[1] for args in puts]
    assert attrs.count("co") == 4 * 6
    assert attrs.count("handle_left") == attrs.count("handle_right") == 3, attrs
    fast = {(o.obj.name, o.bone): written(o) for o in owners_of(objects)}
    # Every curve's handles written (as before): the same keys.
    objects = scene()
    monkeypatch.setattr(denoise, "_automatic_handles", lambda points: False)
    puts.clear()
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    assert [args[1] for args in puts].count("handle_left") == 4 * 6
    slow = {(o.obj.name, o.bone): written(o) for o in owners_of(objects)}
    assert fast == slow
