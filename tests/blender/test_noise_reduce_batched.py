"""Remove Noise and Reduce Keys make a constant number of `polyscrew` calls, whatever the
number of owners (issue 27, item 3), and the batch functions they call write exactly the
keys of one single-owner call per owner.

- The calls: every function of the `polyscrew` module and `Source.channels` are counted
  through wrappers while each operator runs on 6 and on 18 owners (objects in four rotation
  modes, captures and sparse keys); the calls `keys.read` makes (another step, batched apart)
  are left out. The counts are the same for 6 and 18 owners (before: one `angles_near` per
  rotation curve, one playback per owner whose keys are played, one `sample`,
  `rotation_matrices` and playback per owner of Reduce Keys).
- The keys: a varied scene (objects in all kinds of rotation modes, captures, sparse keys,
  keys on other frames per curve, a Cycles modifier, keyed scale, a linked duplicate, a rig
  with connected bones in its own modes, keys held by the selection) under every option set of both operators
  (Strength, Frame Range, Keys: Reduced, a rerun; tolerances, per channel, a rerun): every
  key, handle, handle type, interpolation and easing, and the report, bit for bit the same
  when each batch function is replaced by a loop of the single-owner function over its parts
  (`angles_near`, `partial_moves`, `sample`, `Playback.channels`).

`NOISE27E_DUMP=<file>` writes the keys and reports of every option set to a JSON file
instead (to compare two builds of the add-on: run it with SCREWBENDER_EXTENSION_ZIP).
"""

from __future__ import annotations

import hashlib
import json
import math
import os

import bpy
import numpy as np
import pytest

import bake_helpers as h
from conftest import addon_module
from test_noise_batch import build, noisy_keys, owners_of

FRAMES = [float(f) for f in range(1, 61)]
SPARSE = [float(f) for f in range(1, 62, 4)]
MODES = ("XYZ", "ZXY", "QUATERNION", "AXIS_ANGLE", "YXZ", "QUATERNION")


def takes(count: int, seed: int = 4, sparse: int = 3) -> list:
    """`count` objects keyed on every frame (captures), in turn in each mode of MODES, every
    `sparse`-th one sparse (a key every 4 frames)."""
    rng = np.random.default_rng(seed)
    objects = []
    for i in range(count):
        ob = bpy.data.objects.new(f"T{i:02d}", None)
        bpy.context.scene.collection.objects.link(ob)
        noisy_keys(ob, SPARSE if i % sparse == sparse - 1 else FRAMES, MODES[i % len(MODES)], rng)
        objects.append(ob)
    return objects


def varied() -> list:
    """The varied scene of the module's documentation, in a fresh file: its objects
    (:func:`test_noise_batch.build`'s, with sparse keys, keys on other frames per curve, a
    Cycles modifier and keyed scale besides)."""
    objects = build() + takes(3, sparse=1)
    channels = addon_module("blender.channels")
    rng = np.random.default_rng(8)
    # keys on other frames per curve: location on every other frame only
    other = bpy.data.objects.new("Other", None)
    bpy.context.scene.collection.objects.link(other)
    noisy_keys(other, FRAMES, "XZY", rng)
    for f in FRAMES[1::2]:
        other.keyframe_delete("location", frame=f)
    # a Cycles modifier on every transform curve, keyed scale on another
    cycled = bpy.data.objects.new("Cycled", None)
    bpy.context.scene.collection.objects.link(cycled)
    noisy_keys(cycled, FRAMES, "XYZ", rng)
    for fc in channels.object_fcurves(cycled):
        fc.modifiers.new("CYCLES")
    scaled = bpy.data.objects.new("Scaled", None)
    bpy.context.scene.collection.objects.link(scaled)
    noisy_keys(scaled, FRAMES, "QUATERNION", rng)
    for f in FRAMES:
        scaled.scale = (1.0 + 0.1 * math.sin(f / 9.0) + rng.normal(0, 0.002), 1.0, 1.0)
        scaled.keyframe_insert("scale", index=0, frame=f)
    return objects + [other, cycled, scaled]


def keys_of(objects) -> dict:
    """Every curve's keys of the objects' actions: co, handles, handle types, interpolation,
    easing, as a hash of their bytes per curve (and the action's name)."""
    out = {}
    for ob in objects:
        action = ob.animation_data.action
        out[ob.name, "action"] = action.name
        for fc in h.fcurves(ob):
            points = fc.keyframe_points
            digest = hashlib.sha256()
            for attr, width, kind in (("co", 2, np.float32), ("handle_left", 2, np.float32),
                                      ("handle_right", 2, np.float32), ("handle_left_type", 1, np.uint8),
                                      ("handle_right_type", 1, np.uint8), ("interpolation", 1, np.uint8),
                                      ("easing", 1, np.uint8)):
                values = np.empty(width * len(points), dtype=kind)
                points.foreach_get(attr, values)
                digest.update(values.tobytes())
            out[ob.name, fc.data_path, fc.array_index] = digest.hexdigest()
    return out


def report_of(result) -> dict:
    fields = {name: getattr(result, name) for name in ("owners", "skipped", "notes")}
    for name in ("strengths", "keys_before", "keys_after", "distance_error", "angle_error"):
        if hasattr(result, name):
            fields[name] = repr(getattr(result, name))
    return fields


def runs_of(operator, sets: dict) -> dict:
    """`operator(owners, options)` on the varied scene under each option set (a list of
    options: runs one after the other): its keys and reports per set."""
    out = {}
    for name, runs in sets.items():
        objects = varied()
        reports = [report_of(operator(owners_of(objects), options)) for options in runs]
        out[name] = {"keys": {"|".join(map(str, k)): v for k, v in keys_of(objects).items()}, "reports": reports}
    return out


def noise_runs() -> dict:
    """Remove Noise under each of its option sets."""
    denoise = addon_module("blender.denoise")
    return runs_of(denoise.remove_noise, {
        "auto": [denoise.Options()],
        "strength": [denoise.Options(strength=2.0)],
        "range": [denoise.Options(frame_range=(10.0, 40.0))],
        "reduced": [denoise.Options(key_mode="REDUCED", key_distance=0.01, key_angle=math.radians(1.0))],
        "rerun": [denoise.Options(strength=1.5), denoise.Options(strength=3.0)],
        "rerun_result": [denoise.Options(strength=1.5), denoise.Options(strength=1.5, smooth_result=True)],
    })


def reduce_runs() -> dict:
    """Reduce Keys under each of its option sets."""
    reduce = addon_module("blender.reduce")
    return runs_of(reduce.reduce_keys, {
        "default": [reduce.Options()],
        "loose": [reduce.Options(distance=0.02, angle=math.radians(2.0))],
        "per_channel": [reduce.Options(distance=0.01, angle=math.radians(1.0), per_channel=True)],
        "rerun": [reduce.Options(distance=0.01), reduce.Options(distance=0.03)],
        "rerun_result": [reduce.Options(distance=0.01), reduce.Options(distance=0.03, reduce_result=True)],
    })


def part_by_part(monkeypatch) -> None:
    """Each batch function replaced by a loop of the single-owner function over its parts."""
    import polyscrew

    def angles_near_many(values, reference, modes, channels, counts):
        bounds = np.cumsum([0, *counts])
        return np.concatenate([np.zeros(0)] + [
            polyscrew.angles_near(values[lo:hi], reference[lo:hi], mode, int(channel))
            for mode, channel, lo, hi in zip(modes, channels, bounds[:-1], bounds[1:])
        ])

    def partial_moves_many(source, target, counts, pivots, max_angles, max_distances):
        bounds = np.cumsum([0, *counts])
        parts = [polyscrew.partial_moves(source[lo:hi], target[lo:hi], pivot, a, d)
                 for lo, hi, pivot, a, d in zip(bounds[:-1], bounds[1:], pivots, max_angles, max_distances)]
        return np.concatenate([p for p, _ in parts]), np.concatenate([c for _, c in parts])

    def sample_many(poses, key_times, times, scheme="jarek", levels=4, timing="smooth"):
        k = len(key_times)
        return np.concatenate([polyscrew.sample(poses[i:i + k], key_times, times, scheme, levels, timing=timing)
                               for i in range(0, len(poses), k)])

    def channels_many(playbacks, frames):
        return [playback.channels(frames) for playback in playbacks]

    for name, loop in (("angles_near_many", angles_near_many), ("partial_moves_many", partial_moves_many),
                       ("sample_many", sample_many), ("channels_many", channels_many)):
        monkeypatch.setattr(polyscrew, name, loop)


@pytest.mark.parametrize("runs", [noise_runs, reduce_runs], ids=["remove_noise", "reduce_keys"])
def test_batched_calls_write_what_one_call_per_owner_writes(monkeypatch, runs):
    """Every option set: the keys and reports of the batch functions are those of one
    single-owner call per part, bit for bit (and the keys changed)."""
    dump = os.environ.get("NOISE27E_DUMP")
    batched = runs()
    if dump:
        with open(f"{dump}.{runs.__name__}.json", "w") as f:
            json.dump(batched, f, indent=1, sort_keys=True, default=str)
        return
    part_by_part(monkeypatch)
    alone = runs()
    assert batched.keys() == alone.keys()
    for name in batched:
        assert batched[name]["reports"] == alone[name]["reports"], name
        assert batched[name]["keys"] == alone[name]["keys"], name
        print(f"{runs.__name__} {name}: {len(batched[name]['keys'])} curves the same; "
              f"report {batched[name]['reports'][-1]['owners'][:3]}..., skipped {batched[name]['reports'][-1]['skipped']}")
    objects = varied()
    before = keys_of(objects)
    assert {"|".join(map(str, k)): v for k, v in before.items()} != batched["auto" if "auto" in batched else "default"]["keys"]


def counted_calls(monkeypatch, operator, owners_) -> dict:
    """Runs `operator(owners_)` counting every `polyscrew` function call and every
    `Source.channels` call outside `keys.read`; the counts per name."""
    import polyscrew

    keys, intent = addon_module("blender.keys"), addon_module("pure.intent")
    calls: dict[str, int] = {}
    inside = [0]

    def wrap(name, original):
        def call(*args, **kwargs):
            if not inside[0]:
                calls[name] = calls.get(name, 0) + 1
            return original(*args, **kwargs)

        return call

    for name in dir(polyscrew):
        value = getattr(polyscrew, name)
        if callable(value) and not isinstance(value, type) and not name.startswith("_"):
            monkeypatch.setattr(polyscrew, name, wrap(name, value))
    monkeypatch.setattr(intent.Source, "channels", wrap("Source.channels", intent.Source.channels))
    read = keys.read

    def reading(*args, **kwargs):
        inside[0] += 1
        try:
            return read(*args, **kwargs)
        finally:
            inside[0] -= 1

    monkeypatch.setattr(keys, "read", reading)
    result = operator(owners_)
    assert result.owners and not result.skipped, result.skipped
    monkeypatch.undo()
    return calls


@pytest.mark.parametrize("name", ["remove_noise", "reduce_keys"])
def test_the_polyscrew_calls_do_not_grow_with_the_owners(monkeypatch, name):
    """6 and 18 owners (four rotation modes, captures and sparse keys): the same `polyscrew`
    calls, outside `keys.read`."""
    denoise, reduce = addon_module("blender.denoise"), addon_module("blender.reduce")
    operator = {
        "remove_noise": lambda o: denoise.remove_noise(o, denoise.Options()),
        "reduce_keys": lambda o: reduce.reduce_keys(o, reduce.Options(distance=0.01)),
    }[name]
    counts = []
    for count in (6, 18):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        objects = takes(count)
        counts.append(counted_calls(monkeypatch, operator, owners_of(objects)))
    print(f"{name}: 6 owners {counts[0]}; 18 owners {counts[1]}")
    assert counts[0] == counts[1], counts
