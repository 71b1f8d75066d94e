"""Where Smooth Motion's time goes when it bakes many objects (issue 16's scene-scale case).

The objects of scripts/bench/bench_bake.py (ten keys at uneven frames on location, XYZ Euler
rotation and scale) are smoothed with the default options (4-point, 4 levels, timing Keys)
in one Blender session:
  1. `--runs` times: Smooth Motion (wall clock), its phases timed apart (`keys.read`,
     `bake.sample_channels`, `bake.write`, each summed over the objects) and `nla.bake` of
     the same objects and frames; medians, per object, and the ratio;
  2. Blender's own read and write calls alone, as Smooth Motion makes them, on fresh
     objects (the floor the add-on cannot go below without fewer calls): reading each
     transform F-curve's keys (`keyframe_points.foreach_get` of co, both handles and
     interpolation, as `curves.read` does), and writing the result (`action.copy`, the
     transform curves removed, per baked curve `fcurves.new`, `keyframe_points.add`,
     `foreach_set` of co and interpolation, the action assigned);
  3. once under cProfile: the functions with the most time of their own, and that time
     grouped into `polyscrew` calls, `foreach_get` / `foreach_set`, numpy, and the add-on's
     own Python (cProfile does not see Blender's other RNA calls, `fcurves.new`,
     `keyframe_points.add` and property reads: they count in their Python caller).
Run with the bpy wheel after scripts/build_extension.sh:
    PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench/profile_bake.py [--objects 300] [--frames 250] [--runs 5]
"""

from __future__ import annotations

import argparse
import cProfile
import functools
import importlib
import io
import pstats
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_bake  # noqa: E402  (installs the built extension into a temporary Blender)

# isort: split
import bpy  # noqa: E402  (after bench_bake: it must install the extension first)

bake = bench_bake.bake
keys = importlib.import_module(bake.__name__.rsplit(".", 1)[0] + ".keys")

#: The phases timed apart: (module, function).
PHASES = ((keys, "read"), (bake, "sample_channels"), (bake, "write"))


def restore_sources(objects) -> None:
    """Gives the objects back their source actions (after Smooth Motion), for nla.bake."""
    for obj in objects:
        source = obj.animation_data.action[bake.SOURCE_KEY]
        bake.channels.assign(obj, source, obj.animation_data.action.get(bake.SOURCE_SLOT_KEY, ""))


def nla_bake(objects, frames: int) -> float:
    restore_sources(objects)
    bench_bake.select(objects)
    start = time.perf_counter()
    result = bpy.ops.nla.bake(
        frame_start=1, frame_end=frames, step=1, only_selected=True, visual_keying=False,
        clear_constraints=False, clear_parents=False, use_current_action=False, bake_types={"OBJECT"},
    )
    seconds = time.perf_counter() - start
    assert result == {"FINISHED"}, result
    return seconds


def timed_phases(spent: dict[str, float]) -> list:
    """Wraps the phases so that their wall-clock time adds up in `spent`; returns what to restore."""
    originals = []
    for module, name in PHASES:
        function = getattr(module, name)

        @functools.wraps(function)
        def wrapper(*args, _function=function, _name=name, **kwargs):
            start = time.perf_counter()
            try:
                return _function(*args, **kwargs)
            finally:
                spent[_name] = spent.get(_name, 0.0) + time.perf_counter() - start

        setattr(module, name, wrapper)
        originals.append((module, name, function))
    return originals


def run(count: int, frames: int, phases: bool) -> dict[str, float]:
    objects = bench_bake.keyed_objects(count, frames)
    bench_bake.select(objects)
    spent: dict[str, float] = {}
    originals = timed_phases(spent) if phases else []
    try:
        start = time.perf_counter()
        result = bake.smooth(objects, bake.Options())
        spent["smooth"] = time.perf_counter() - start
    finally:
        for module, name, function in originals:
            setattr(module, name, function)
    assert len(result.actions) == count and not result.skipped, result.skipped
    spent["nla"] = nla_bake(objects, frames)
    return spent


def blender_calls(count: int, frames: int) -> tuple[float, float]:
    """Seconds of Blender's own read and write calls for `count` fresh objects, as Smooth
    Motion makes them (see the module doc)."""
    import numpy as np

    channels = bake.channels
    objects = bench_bake.keyed_objects(count, frames)
    curves = [channels.object_fcurves(obj) for obj in objects]
    start = time.perf_counter()
    for listed in curves:
        for fc in listed:
            points = fc.keyframe_points
            n = len(points)
            for name in ("co", "handle_left", "handle_right"):
                points.foreach_get(name, np.empty(2 * n, dtype=np.float32))
            points.foreach_get("interpolation", np.empty(n, dtype=np.uint8))
    read = time.perf_counter() - start
    co = np.zeros(2 * frames, dtype=np.float32)
    co[0::2] = np.arange(1, frames + 1)
    linear = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value
    interpolation = (linear,) * frames
    start = time.perf_counter()
    for obj in objects:
        identifier = channels.slot_identifier(obj)
        copy = obj.animation_data.action.copy()
        bag = channels.ensure_container(copy, channels.find_slot(copy, identifier))
        for fc in channels.fcurves(bag):
            channels.remove_fcurve(bag, fc)
        for path in ("location", "rotation_euler", "scale"):
            for index in range(3):
                points = channels.new_fcurve(bag, path, index).keyframe_points
                points.add(frames)
                points.foreach_set("co", co)
                points.foreach_set("interpolation", interpolation)
        channels.assign(obj, copy, identifier)
    write = time.perf_counter() - start
    return read, write


#: cProfile's names of Blender's own calls, by the group they are counted in.
BLENDER_CALLS = {
    "foreach_get": "Blender: foreach_get",
    "foreach_set": "Blender: foreach_set",
}


def group_of(key: tuple[str, int, str]) -> str:
    filename, _line, name = key
    if "polyscrew" in name:
        return "polyscrew"
    if "bpy_prop_collection" in name or "bpy_struct" in name or "bpy_func" in name:
        method = name.split("'")[1] if "'" in name else name
        return BLENDER_CALLS.get(method, "Blender: other RNA methods cProfile sees")
    if "numpy" in filename or "numpy" in name:
        return "numpy"
    if "screwbender" in filename:
        return "add-on Python"
    return "other Python (builtins, dataclasses, ...)"


def profile(count: int, frames: int) -> None:
    objects = bench_bake.keyed_objects(count, frames)
    bench_bake.select(objects)
    profiler = cProfile.Profile()
    profiler.enable()
    bake.smooth(objects, bake.Options())
    profiler.disable()
    stats = pstats.Stats(profiler)
    text = io.StringIO()
    pstats.Stats(profiler, stream=text).sort_stats("tottime").print_stats(20)
    print(text.getvalue())
    groups: dict[str, float] = {}
    for key, (_cc, _nc, tottime, _ct, _callers) in stats.stats.items():
        groups[group_of(key)] = groups.get(group_of(key), 0.0) + tottime
    total = sum(groups.values())
    print(f"own time under cProfile, {total * 1e3:.0f} ms in all ({total / count * 1e3:.2f} ms per object):")
    for group, seconds in sorted(groups.items(), key=lambda item: -item[1]):
        print(f"  {group:55s} {seconds * 1e3:7.1f} ms  {seconds / total:5.1%}  {seconds / count * 1e6:6.0f} us/object")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", type=int, default=300)
    parser.add_argument("--frames", type=int, default=250)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    n, f = args.objects, args.frames
    print(f"Blender {bpy.app.version_string}: {n} objects x {f} frames, Smooth Motion with the default options")
    run(3, 20, phases=False)  # warm-up: the first Smooth Motion of a session imports and allocates
    rows = [run(n, f, phases=True) for _ in range(args.runs)]
    median = {k: statistics.median(r[k] for r in rows) for k in rows[0]}
    ratios = ", ".join(f"{r['nla'] / r['smooth']:.1f}x" for r in rows)
    print(f"median of {args.runs}: Smooth Motion {median['smooth'] * 1e3:.0f} ms ({median['smooth'] / n * 1e3:.2f} ms per object), "
          f"nla.bake {median['nla'] * 1e3:.0f} ms; ratio {median['nla'] / median['smooth']:.1f}x (per run {ratios})")
    for _module, name in PHASES:
        print(f"  {name:16s} {median[name] * 1e3:6.0f} ms  {median[name] / n * 1e6:5.0f} us/object")
    rest = median["smooth"] - sum(median[name] for _m, name in PHASES)
    print(f"  {'the rest':16s} {rest * 1e3:6.0f} ms  {rest / n * 1e6:5.0f} us/object")
    floors = [blender_calls(n, f) for _ in range(args.runs)]
    read, write = (statistics.median(x[i] for x in floors) for i in (0, 1))
    print(f"Blender's own calls alone (median of {args.runs}): reading the keys {read * 1e3:.0f} ms "
          f"({read / n * 1e6:.0f} us/object), writing the result {write * 1e3:.0f} ms ({write / n * 1e6:.0f} us/object)")
    profile(n, f)


if __name__ == "__main__":
    main()
