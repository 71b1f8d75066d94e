"""Benchmark: ScrewBender's bake against Blender's own `bpy.ops.nla.bake` and against a
`keyframe_insert` loop, same objects and frames.

The cases, all in the same Blender session:
  1. one object baked over 100,000 frames;
  2. 100 objects baked over 1,000 frames;
  3. 300 objects baked over 250 frames (issue 16: a scene of many short animations, where
     the work per object counts more than the work per frame).
Each object has location, rotation (XYZ Euler) and scale keys (ten keys at uneven frames),
so every baker writes the same ten dense F-curves per object, one key per frame.
ScrewBender's time covers everything the Smooth Motion operator does (reading keys,
polyscrew sampling, writing the new action); nla.bake's time is the operator call.

The `keyframe_insert` loop is what a script author writes today: for each frame, set the
scene frame (`scene.frame_set`), set each object's location, rotation and scale from the
smoothed motion (the values ScrewBender samples, computed before the clock starts: only the
loop is timed) and `keyframe_insert` the three properties. Each insertion re-sorts and
recomputes the handles of the F-curve, so the loop grows faster than linearly in frames: it
is measured on one object over a few frame counts that finish (1,000, 2,000, 4,000; --quick:
250, 500, 1,000) and on 100 objects x 1,000 frames (--quick: 100 x 100), and its time at
100,000 frames (--quick: 10,000) is extrapolated from the fitted growth exponent (marked
"extrapolated" wherever it appears).

Writes the results as JSON (`--out`, rendered by scripts/bench_report.py) and prints them.
Run with the bpy wheel after scripts/build_extension.sh (the add-on is installed from the
built .zip into a temporary Blender user directory):
    PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench_bake.py [--quick] [--out bake.json]
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent / "demo"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_report  # noqa: E402
import demo_common  # noqa: E402

bake = demo_common.blender_with_addon()
import bpy  # noqa: E402


def keyed_objects(count: int, frames: int) -> list[bpy.types.Object]:
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    mesh = bpy.data.meshes.new("Block")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], [], [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)])
    objects = []
    for n in range(count):
        obj = bpy.data.objects.new(f"Body{n:03d}", mesh)
        scene.collection.objects.link(obj)
        for k in range(10):
            u = (k / 9) ** 1.2  # uneven key spacing
            frame = 1 + round(u * (frames - 1))
            obj.location = (3 * math.cos(4 * u + n), 3 * math.sin(3 * u), u * 2 + 0.01 * n)
            obj.rotation_euler = (0.5 * math.sin(5 * u), 0.3 * u, 6 * u + n)
            obj.scale = (1 + 0.3 * math.sin(7 * u), 1.0, 1 + 0.2 * u)
            for path in ("location", "rotation_euler", "scale"):
                obj.keyframe_insert(path, frame=frame)
        objects.append(obj)
    scene.frame_start, scene.frame_end = 1, frames
    return objects


def select(objects) -> None:
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj in objects)
    bpy.context.view_layer.objects.active = objects[0]


def run_case(count: int, frames: int) -> tuple[float, float]:
    objects = keyed_objects(count, frames)
    select(objects)
    start = time.perf_counter()
    result = bake.smooth(objects, bake.Options(scheme="jarek", levels=4))
    ours = time.perf_counter() - start
    assert len(result.actions) == count and not result.skipped, result.skipped
    keys = sum(len(fc.keyframe_points) for fc in bake_fcurves(objects[0]))

    # Blender's baker on the same (source) actions and frames
    for obj in objects:
        from_action = obj.animation_data.action[bake.SOURCE_KEY]
        bake.channels.assign(obj, from_action, obj.animation_data.action.get(bake.SOURCE_SLOT_KEY, ""))
    select(objects)
    start = time.perf_counter()
    result = bpy.ops.nla.bake(
        frame_start=1, frame_end=frames, step=1, only_selected=True, visual_keying=False,
        clear_constraints=False, clear_parents=False, use_current_action=False, bake_types={"OBJECT"},
    )
    theirs = time.perf_counter() - start
    assert result == {"FINISHED"}, result
    their_keys = sum(len(fc.keyframe_points) for fc in bake_fcurves(objects[0]))
    print(
        f"{count:4d} object(s) x {frames:6d} frames: ScrewBender {ours:7.3f} s, nla.bake {theirs:7.3f} s, "
        f"ratio {theirs / ours:6.1f}x  (keys per object: {keys} vs {their_keys})"
    )
    return ours, theirs


def keyframe_insert_loop(count: int, frames: int) -> float:
    """Seconds of the `keyframe_insert` loop over `count` fresh objects and `frames` frames."""
    objects = keyed_objects(count, frames)
    action_bakes, skipped, _notes = bake.prepare(objects, bake.Options(scheme="jarek", levels=4))
    bakes = [part for b in action_bakes for part in b.parts]
    assert len(bakes) == count and not skipped, skipped
    # The smoothed values, as Python lists, before the clock starts.
    rows = []
    for baked in bakes:
        paths = list(baked.values)
        rows.append((baked.obj, paths, [baked.values[p].tolist() for p in paths]))
        baked.obj.animation_data.action = None
    scene = bpy.context.scene
    times = bakes[0].frames.tolist()
    start = time.perf_counter()
    for i, frame in enumerate(times):
        scene.frame_set(int(frame))
        for obj, paths, values in rows:
            for path, column in zip(paths, values):
                setattr(obj, path, column[i])
                obj.keyframe_insert(path, frame=frame)
    seconds = time.perf_counter() - start
    keys = sum(len(fc.keyframe_points) for fc in bake_fcurves(objects[0]))
    assert keys == 9 * frames, (keys, frames)
    print(f"{count:4d} object(s) x {frames:6d} frames: keyframe_insert loop {seconds:8.3f} s (keys per object: {keys})")
    return seconds


def bake_fcurves(obj):
    return bake.channels.object_fcurves(obj)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a tenth of the frames (a smoke run)")
    parser.add_argument("--repeat", type=int, default=3, help="runs per case; the best time of each baker counts")
    parser.add_argument("--out", type=Path, help="write the results as JSON here")
    args = parser.parse_args()
    scale = 10 if args.quick else 1
    print(f"Blender {bpy.app.version_string}, bake over every frame, jarek 4 levels")
    result = {"blender": bpy.app.version_string, "quick": args.quick, "repeat": args.repeat,
              "cases": [], "loop_series": []}
    ratios = []
    for count, frames in ((1, 100_000 // scale), (100, 1_000 // scale), (300, 250 // scale)):
        runs = [run_case(count, frames) for _ in range(args.repeat)]
        ours, theirs = min(r[0] for r in runs), min(r[1] for r in runs)
        print(f"  best of {args.repeat}: ScrewBender {ours:.3f} s, nla.bake {theirs:.3f} s, ratio {theirs / ours:.1f}x")
        ours_median, theirs_median = statistics.median(r[0] for r in runs), statistics.median(r[1] for r in runs)
        print(f"  median of {args.repeat}: ScrewBender {ours_median:.3f} s, nla.bake {theirs_median:.3f} s, "
              f"ratio {theirs_median / ours_median:.1f}x")
        ratios.append(theirs / ours)
        result["cases"].append({"objects": count, "frames": frames, "ours": ours, "nla": theirs,
                                "ours_median": ours_median, "nla_median": theirs_median})
    print(f"ScrewBender is {min(ratios):.0f}x to {max(ratios):.0f}x faster than nla.bake (best of {args.repeat} runs each)")

    # The keyframe_insert loop: once per size (it is slow), at sizes that finish.
    series = [250, 500, 1_000] if args.quick else [1_000, 2_000, 4_000]
    for frames in series:
        result["loop_series"].append({"objects": 1, "frames": frames, "seconds": keyframe_insert_loop(1, frames)})
    for case in result["cases"]:
        measured = next((r for r in result["loop_series"]
                         if r["objects"] == case["objects"] and r["frames"] == case["frames"]), None)
        if measured is None and case["objects"] > 1:
            seconds = keyframe_insert_loop(case["objects"], case["frames"])
            result["loop_series"].append({"objects": case["objects"], "frames": case["frames"], "seconds": seconds})
            measured = result["loop_series"][-1]
        if measured is not None:
            case["loop"], case["loop_extrapolated"] = measured["seconds"], False
        else:
            one = [r for r in result["loop_series"] if r["objects"] == case["objects"]]
            value, p = bench_report.extrapolate([r["frames"] for r in one], [r["seconds"] for r in one], case["frames"])
            case["loop"], case["loop_extrapolated"], case["loop_exponent"] = value, True, p
            print(f"{case['objects']:4d} object(s) x {case['frames']:6d} frames: keyframe_insert loop about "
                  f"{value:.0f} s (extrapolated from {len(one)} sizes, time ~ frames^{p:.2f})")
        print(f"  keyframe_insert loop / ScrewBender: {case['loop'] / case['ours']:.0f}x"
              + (" (extrapolated)" if case["loop_extrapolated"] else ""))
    if args.out:
        args.out.write_text(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
