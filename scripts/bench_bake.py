"""Benchmark: ScrewBender's bake against Blender's own `bpy.ops.nla.bake` and against a
`keyframe_insert` loop, same objects and frames.

Three cases, all in the same Blender session:
  1. one object baked over 100,000 frames;
  2. 100 objects baked over 1,000 frames;
  3. a 100-bone rig (ten chains of ten bones) baked over 1,000 frames, against
     `nla.bake(bake_types={'POSE'})` of the same bones (Pose Mode, all bones selected).
Each object and bone has location, rotation (XYZ Euler) and scale keys (ten keys at uneven
frames), so every baker writes the same nine dense F-curves per object or bone, one key per
frame. ScrewBender's time covers everything the Smooth Motion operator does (reading keys,
polyscrew sampling, writing the new action); nla.bake's time is the operator call. The bone
case runs ours and nla.bake back to back on a fresh rig in each run (after one untimed
warm-up smoothing), and reports the medians of the runs and their ratio.

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
import importlib
import json
import math
import os
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


def keyed_rig(bones: int, frames: int) -> bpy.types.Object:
    """An armature of `bones` bones in chains of ten (each bone the child of the previous one,
    not connected: its location counts), every bone keyed like the objects above."""
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    data = bpy.data.armatures.new("Rig")
    rig = bpy.data.objects.new("Rig", data)
    scene.collection.objects.link(rig)
    select([rig])
    bpy.ops.object.mode_set(mode="EDIT")
    previous = None
    for n in range(bones):
        chain, link = divmod(n, 10)
        bone = data.edit_bones.new(f"Bone{n:03d}")
        bone.head, bone.tail = (chain, 0.0, link), (chain, 0.0, link + 1.0)
        bone.parent = previous if link else None
        previous = bone
    bpy.ops.object.mode_set(mode="OBJECT")
    for n, pose_bone in enumerate(rig.pose.bones):
        pose_bone.rotation_mode = "XYZ"
        for k in range(10):
            u = (k / 9) ** 1.2  # uneven key spacing
            frame = 1 + round(u * (frames - 1))
            pose_bone.location = (0.3 * math.cos(4 * u + n), 0.3 * math.sin(3 * u), 0.2 * u)
            pose_bone.rotation_euler = (0.5 * math.sin(5 * u), 0.3 * u, 6 * u + n)
            pose_bone.scale = (1 + 0.3 * math.sin(7 * u), 1.0, 1 + 0.2 * u)
            for path in ("location", "rotation_euler", "scale"):
                pose_bone.keyframe_insert(path, frame=frame)
    scene.frame_start, scene.frame_end = 1, frames
    return rig


def run_bone_case(bones: int, frames: int) -> tuple[float, float, float, float]:
    """One run: ScrewBender's Smooth Motion of every bone (Object Mode, the armature selected,
    Armatures: Bones Only), then nla.bake POSE of the same bones over the same frames.
    Returns wall-clock seconds (ours, nla.bake) and the process's CPU seconds (ours, nla.bake:
    every thread of the process, so Blender's threaded depsgraph evaluation counts)."""
    rig = keyed_rig(bones, frames)
    select([rig])
    owners = importlib.import_module(bake.__name__.rsplit(".", 1)[0] + ".owners")
    start, cpu = time.perf_counter(), time.process_time()
    selection = owners.selection(bpy.context, "BONES", bake.channels.object_fcurves)
    result = bake.smooth(selection, bake.Options(scheme="jarek", levels=4))
    ours, ours_cpu = time.perf_counter() - start, time.process_time() - cpu
    assert result.bones == bones and not result.skipped, result.skipped
    keys = sum(len(fc.keyframe_points) for fc in bake_fcurves(rig))

    # Blender's baker on the source action, the same bones and frames
    adt = rig.animation_data
    bake.channels.assign(rig, adt.action[bake.SOURCE_KEY], adt.action.get(bake.SOURCE_SLOT_KEY, ""))
    bpy.ops.object.mode_set(mode="POSE")
    for pose_bone in rig.pose.bones:
        (pose_bone if hasattr(pose_bone, "select") else pose_bone.bone).select = True
    start, cpu = time.perf_counter(), time.process_time()
    done = bpy.ops.nla.bake(
        frame_start=1, frame_end=frames, step=1, only_selected=True, visual_keying=False,
        clear_constraints=False, clear_parents=False, use_current_action=False, bake_types={"POSE"},
        channel_types={"LOCATION", "ROTATION", "SCALE"},
    )
    theirs, theirs_cpu = time.perf_counter() - start, time.process_time() - cpu
    assert done == {"FINISHED"}, done
    bpy.ops.object.mode_set(mode="OBJECT")
    their_keys = sum(len(fc.keyframe_points) for fc in bake_fcurves(rig))
    assert keys == their_keys == 9 * bones * frames, (keys, their_keys)
    print(
        f"{bones:4d} bones     x {frames:6d} frames: ScrewBender {ours:7.3f} s, nla.bake {theirs:7.3f} s, "
        f"ratio {theirs / ours:6.1f}x; CPU {ours_cpu:6.3f} s vs {theirs_cpu:6.3f} s, {theirs_cpu / ours_cpu:5.1f}x  "
        f"(keys: {keys} vs {their_keys})"
    )
    return ours, theirs, ours_cpu, theirs_cpu


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
    parser.add_argument("--bone-runs", type=int, default=5, help="runs of the bone case (medians count)")
    parser.add_argument("--only-bones", action="store_true", help="run the bone case only")
    parser.add_argument("--out", type=Path, help="write the results as JSON here")
    args = parser.parse_args()
    if args.only_bones:
        result = {"blender": bpy.app.version_string, "quick": args.quick, "bones": bone_case(args)}
        if args.out:
            args.out.write_text(json.dumps(result, indent=1))
        return
    scale = 10 if args.quick else 1
    print(f"Blender {bpy.app.version_string}, bake over every frame, jarek 4 levels")
    result = {"blender": bpy.app.version_string, "quick": args.quick, "repeat": args.repeat,
              "cases": [], "loop_series": []}
    ratios = []
    for count, frames in ((1, 100_000 // scale), (100, 1_000 // scale)):
        runs = [run_case(count, frames) for _ in range(args.repeat)]
        ours, theirs = min(r[0] for r in runs), min(r[1] for r in runs)
        print(f"  best of {args.repeat}: ScrewBender {ours:.3f} s, nla.bake {theirs:.3f} s, ratio {theirs / ours:.1f}x")
        ratios.append(theirs / ours)
        result["cases"].append({"objects": count, "frames": frames, "ours": ours, "nla": theirs})
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
    result["bones"] = bone_case(args)
    if args.out:
        args.out.write_text(json.dumps(result, indent=1))


def bone_case(args) -> dict:
    """The 100-bone rig x 1,000 frames (--quick: 100 frames): medians of --bone-runs runs."""
    bones, frames = 100, 1_000 // (10 if args.quick else 1)
    rig = keyed_rig(3, 20)  # warm-up: the first Smooth Motion of a session imports and allocates
    select([rig])
    owners = importlib.import_module(bake.__name__.rsplit(".", 1)[0] + ".owners")
    assert bake.smooth(owners.selection(bpy.context, "BONES", bake.channels.object_fcurves), bake.Options()).bones == 3
    runs = [run_bone_case(bones, frames) for _ in range(args.bone_runs)]
    ours, theirs, ours_cpu, theirs_cpu = (statistics.median(r[i] for r in runs) for i in range(4))
    print(f"  median of {len(runs)}: ScrewBender {ours:.3f} s, nla.bake {theirs:.3f} s, ratio {theirs / ours:.1f}x "
          f"(per run {', '.join(f'{r[1] / r[0]:.1f}x' for r in runs)}); CPU time {ours_cpu:.3f} s vs "
          f"{theirs_cpu:.3f} s, ratio {theirs_cpu / ours_cpu:.1f}x")
    if hasattr(os, "getloadavg"):
        print(f"  machine: {os.cpu_count()} CPUs, load average {os.getloadavg()[0]:.1f}")
    return {"bones": bones, "frames": frames, "runs": len(runs),
            "ours_runs": [r[0] for r in runs], "nla_runs": [r[1] for r in runs],
            "ours_cpu_runs": [r[2] for r in runs], "nla_cpu_runs": [r[3] for r in runs],
            "ours": ours, "nla": theirs, "ours_cpu": ours_cpu, "nla_cpu": theirs_cpu,
            "load": os.getloadavg()[0] if hasattr(os, "getloadavg") else None}


if __name__ == "__main__":
    main()
