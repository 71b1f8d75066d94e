"""Benchmark: ScrewBender's bake against Blender's own `bpy.ops.nla.bake` and against a
`keyframe_insert` loop, same objects and frames.

Four cases, all in the same Blender session:
  1. one object baked over 100,000 frames;
  2. 100 objects baked over 1,000 frames;
  3. 300 objects baked over 250 frames (issue 16: a scene of many short animations, where
     the work per object counts more than the work per frame);
  4. a 100-bone rig (ten chains of ten bones) baked over 1,000 frames, against
     `nla.bake(bake_types={'POSE'})` of the same bones (Pose Mode, all bones selected).
Each object and bone has location, rotation (XYZ Euler) and scale keys (ten keys at uneven
frames), so every baker writes the same nine dense F-curves per object or bone, one key per
frame. ScrewBender's time covers everything the Smooth Motion operator does (reading keys,
polyscrew sampling, writing the new action); nla.bake's time is the operator call. The bone
case runs ours (Jarek 4 levels, once with timing Keys, the default, once with timing Smooth,
each on a fresh rig) and nla.bake back to back in each run (after one untimed warm-up
smoothing), and reports the medians of the runs and their ratios, wall-clock and the
process's CPU time (nla.bake's depsgraph evaluation runs on several threads).

The `keyframe_insert` loop is what a script author writes today: for each frame, set the
scene frame (`scene.frame_set`), set each object's location, rotation and scale from the
smoothed motion (the values ScrewBender samples, computed before the clock starts: only the
loop is timed) and `keyframe_insert` the three properties. Each insertion re-sorts and
recomputes the handles of the F-curve, so the loop grows faster than linearly in frames: it
is measured on one object over a few frame counts that finish (1,000, 2,000, 4,000; --quick:
250, 500, 1,000) and on 100 objects x 1,000 frames (--quick: 100 x 100), and its time at
100,000 frames (--quick: 10,000) is extrapolated from the fitted growth exponent (marked
"extrapolated" wherever it appears).

Writes the results as JSON (`--out`, rendered by scripts/bench/bench_report.py) and prints them.
Run with the bpy wheel after scripts/build_extension.sh (the add-on is installed from the
built .zip into a temporary Blender user directory):
    PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench/bench_bake.py [--quick] [--out bake.json]
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

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "demo"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import demo_common  # noqa: E402

import bench_report  # noqa: E402

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


#: The bone case's timings of the motion between keys: "keys" (the default since issue 17:
#: Blender's own pace, read from its curves) and "smooth" (a monotone C1 time map).
BONE_TIMINGS = ("keys", "smooth")


def smooth_bones(bones: int, frames: int, timing: str) -> tuple[float, float, bpy.types.Object]:
    """ScrewBender's Smooth Motion of every bone of a fresh rig (Object Mode, the armature
    selected, Armatures: Bones Only), Jarek 4 levels with `timing`: wall-clock and process CPU
    seconds, and the rig."""
    rig = keyed_rig(bones, frames)
    select([rig])
    owners = importlib.import_module(bake.__name__.rsplit(".", 1)[0] + ".owners")
    start, cpu = time.perf_counter(), time.process_time()
    selection = owners.selection(bpy.context, "BONES", bake.channels.object_fcurves)
    result = bake.smooth(selection, bake.Options(scheme="jarek", levels=4, timing=timing))
    ours, ours_cpu = time.perf_counter() - start, time.process_time() - cpu
    assert result.bones == bones and not result.skipped, result.skipped
    keys = sum(len(fc.keyframe_points) for fc in bake_fcurves(rig))
    assert keys == 9 * bones * frames, (keys, bones, frames)
    return ours, ours_cpu, rig


def run_bone_case(bones: int, frames: int) -> dict:
    """One run: ScrewBender's Smooth Motion of every bone of a fresh rig with each of
    :data:`BONE_TIMINGS`, then nla.bake POSE of the same bones over the same frames (on the
    last rig's source action). Wall-clock seconds and the process's CPU seconds (every thread
    of the process, so Blender's threaded depsgraph evaluation counts)."""
    out = {}
    for timing in BONE_TIMINGS:
        out[timing], out[f"{timing}_cpu"], rig = smooth_bones(bones, frames, timing)

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
    out["nla"], out["nla_cpu"] = time.perf_counter() - start, time.process_time() - cpu
    assert done == {"FINISHED"}, done
    bpy.ops.object.mode_set(mode="OBJECT")
    their_keys = sum(len(fc.keyframe_points) for fc in bake_fcurves(rig))
    assert their_keys == 9 * bones * frames, their_keys
    print(
        f"{bones:4d} bones     x {frames:6d} frames: nla.bake {out['nla']:7.3f} s (CPU {out['nla_cpu']:.3f} s); "
        + "; ".join(
            f"ScrewBender timing {t} {out[t]:.3f} s (CPU {out[t + '_cpu']:.3f} s), ratio {out['nla'] / out[t]:.1f}x "
            f"(CPU {out['nla_cpu'] / out[t + '_cpu']:.1f}x)"
            for t in BONE_TIMINGS
        )
        + f"  ({their_keys} keys each)"
    )
    return out


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
    parser.add_argument("--bone-phases", action="store_true",
                        help="where the bone case's Smooth Motion spends its time (phases, cProfile), nothing else")
    parser.add_argument("--out", type=Path, help="write the results as JSON here")
    args = parser.parse_args()
    if args.bone_phases:
        bone_phases()
        return
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
    result["bones"] = bone_case(args)
    if args.out:
        args.out.write_text(json.dumps(result, indent=1))


def bone_phases(bones: int = 100, frames: int = 1_000, runs: int = 3) -> dict:
    """Where Smooth Motion of the rig spends its time: process CPU seconds in reading
    (`keys.read`), sampling (`bake.sample_channels`) and writing (`bake.write`), medians of
    `runs` per timing; then the top of a cProfile (CPU time) of one timing-Keys run."""
    import cProfile
    import functools
    import io
    import pstats

    package = bake.__name__.rsplit(".", 1)[0]
    keys_module = importlib.import_module(package + ".keys")
    spent: dict[str, float] = {}

    def timed(module, name):
        function = getattr(module, name)

        @functools.wraps(function)
        def wrapper(*args, **kwargs):
            start = time.process_time()
            try:
                return function(*args, **kwargs)
            finally:
                spent[name] = spent.get(name, 0.0) + time.process_time() - start

        setattr(module, name, wrapper)
        return module, name, function

    smooth_bones(3, 20, "keys")  # warm-up: the first Smooth Motion of a session imports and allocates
    originals = [timed(keys_module, "read"), timed(bake, "sample_channels"), timed(bake, "write")]
    out = {}
    try:
        for timing in BONE_TIMINGS:
            rows = []
            for _ in range(runs):
                spent.clear()
                seconds, cpu, _rig = smooth_bones(bones, frames, timing)
                rows.append(dict(spent, total=cpu))
            out[timing] = {k: statistics.median(r[k] for r in rows) for k in rows[0]}
            print(f"  phases, timing {timing} (CPU, median of {runs}): "
                  + ", ".join(f"{k} {v * 1e3:.0f} ms" for k, v in out[timing].items()))
    finally:
        for module, name, function in originals:
            setattr(module, name, function)
    rig = keyed_rig(bones, frames)
    select([rig])
    owners = importlib.import_module(package + ".owners")
    # Reading every bone, each read scanning all the rig's curves, against the curves grouped
    # by owner once (what Smooth Motion does).
    every = [owners.Owner(rig, b.name) for b in rig.pose.bones]
    scans, grouped = [], []
    for _ in range(runs):
        start = time.process_time()
        for owner in every:
            keys_module.read(owner)
        scans.append(time.process_time() - start)
        start = time.process_time()
        by_owner = owners.curves_by_owner(bake.channels.object_fcurves(rig))
        for owner in every:
            keys_module.read(owner, fcurves=by_owner[owner.bone])
        grouped.append(time.process_time() - start)
    out["read_scanning"], out["read_grouped"] = statistics.median(scans), statistics.median(grouped)
    print(f"  reading {bones} bones (CPU, median of {runs}): each scanning all curves {out['read_scanning'] * 1e3:.0f} ms, "
          f"curves grouped by owner once {out['read_grouped'] * 1e3:.0f} ms")
    profile = cProfile.Profile(time.process_time)
    profile.enable()
    bake.smooth(owners.selection(bpy.context, "BONES", bake.channels.object_fcurves),
                bake.Options(scheme="jarek", levels=4, timing="keys"))
    profile.disable()
    text = io.StringIO()
    pstats.Stats(profile, stream=text).sort_stats("tottime").print_stats(12)
    print(text.getvalue())
    return out


def bone_case(args) -> dict:
    """The 100-bone rig x 1,000 frames (--quick: 100 frames): medians of --bone-runs runs."""
    bones, frames = 100, 1_000 // (10 if args.quick else 1)
    rig = keyed_rig(3, 20)  # warm-up: the first Smooth Motion of a session imports and allocates
    select([rig])
    owners = importlib.import_module(bake.__name__.rsplit(".", 1)[0] + ".owners")
    assert bake.smooth(owners.selection(bpy.context, "BONES", bake.channels.object_fcurves), bake.Options()).bones == 3
    runs = [run_bone_case(bones, frames) for _ in range(args.bone_runs)]
    median = {key: statistics.median(r[key] for r in runs) for key in runs[0]}
    for t in BONE_TIMINGS:
        per_run = ", ".join(f"{r['nla'] / r[t]:.1f}x" for r in runs)
        print(f"  median of {len(runs)}, timing {t}: ScrewBender {median[t]:.3f} s, nla.bake {median['nla']:.3f} s, "
              f"ratio {median['nla'] / median[t]:.1f}x (per run {per_run}); "
              f"CPU time {median[t + '_cpu']:.3f} s vs {median['nla_cpu']:.3f} s, "
              f"ratio {median['nla_cpu'] / median[t + '_cpu']:.1f}x")
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    if load is not None:
        print(f"  machine: {os.cpu_count()} CPUs, load average {load:.1f}")
    return {"bones": bones, "frames": frames, "runs": runs, "median": median, "timings": list(BONE_TIMINGS),
            "load": load}


if __name__ == "__main__":
    main()
