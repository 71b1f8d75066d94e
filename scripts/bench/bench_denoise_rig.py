"""Benchmark: Remove Noise (the operator) on rigs of 30 and 100 bones x 1,000 frames of noisy
keys, against Blender's own `graph.gaussian_smooth` on the same curves, in one Blender session
(issue 27's goal: Remove Noise within 2 times the Gaussian's time).

The rig: N bones (`--bones`, default 30 and 100), each keyed on every frame (XYZ Euler, one key
per frame, a slow sway plus 0.5 degrees of noise per axis), the root's location too: 3 N + 3
F-curves of 1,000 keys. Ours:
`bpy.ops.screwbender.denoise()` on the armature (Object Mode, every bone; automatic strength;
reading, one batched polyscrew.denoise call, writing the keys into a new action). Blender's:
`graph.gaussian_smooth` at its defaults on every key of those curves, run headless with
`bpy.context.temp_override` on the largest area switched to the Graph Editor. Each run starts
from the same noisy keys, the two alternating (ours, Gaussian, ours, ...); medians of the runs
(wall clock and the process's CPU time) and their ratio. `--profile N` prints the top N entries
of a cProfile of one more run of ours; `--reads` counts the keyframe reads of one more run of
ours per F-curve and property (every `bulk.get`: issue 27's read-once rule).

Run: PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench/bench_denoise_rig.py [--bones 30,100] [--runs 5]
     [--profile 25] [--reads] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "demo"))
import demo_common  # noqa: E402

demo_common.blender_with_addon()
import bpy  # noqa: E402

from bench_denoise import fcurves  # noqa: E402  (the same curve lookup and Graph Editor context)
from bench_denoise import graph_context as _graph_context  # noqa: E402


def graph_context():
    return _graph_context(bpy)

BONES, FRAMES = (30, 100), 1000


def rig(bones: int) -> bpy.types.Object:
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, FRAMES
    data = bpy.data.armatures.new("Rig")
    obj = bpy.data.objects.new("Rig", data)
    scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode="EDIT")
    for i in range(bones):
        b = data.edit_bones.new(f"B{i:03d}")
        b.head, b.tail = (i % 10, i // 10, 0.0), (i % 10, i // 10, 1.0)
    bpy.ops.object.mode_set(mode="OBJECT")
    for pb in obj.pose.bones:
        pb.rotation_mode = "XYZ"
        pb.keyframe_insert("rotation_euler", frame=1)
    obj.pose.bones[0].keyframe_insert("location", frame=1)
    rng = np.random.default_rng(1)
    t = np.arange(1, FRAMES + 1, dtype=float)
    co = np.empty(2 * FRAMES, dtype=np.float32)
    co[0::2] = t
    for k, fc in enumerate(fcurves(obj)):
        truth = 0.4 * np.sin(t / 40.0 + k) if "rotation" in fc.data_path else 0.5 * np.sin(t / 60.0 + k)
        noise = math.radians(0.5) if "rotation" in fc.data_path else 0.01
        co[1::2] = truth + rng.normal(0, noise, FRAMES)
        points = fc.keyframe_points
        points.add(FRAMES - len(points))
        points.foreach_set("co", co)
        points.foreach_set("select_control_point", np.ones(FRAMES, dtype=bool))
        fc.select = True
        fc.update()
    return obj


def timed(fn) -> tuple[float, float]:
    wall, cpu = time.perf_counter(), time.process_time()
    fn()
    return time.perf_counter() - wall, time.process_time() - cpu


def run_ours() -> None:
    result = bpy.ops.screwbender.denoise(armature="BONES")
    assert result == {"FINISHED"}, result


def run_gaussian(ctx: dict) -> None:
    with bpy.context.temp_override(**ctx):
        result = bpy.ops.graph.gaussian_smooth()
    assert result == {"FINISHED"}, result


def profile(bones: int, top: int) -> None:
    """The top entries (cumulative time) of a cProfile of one run of ours."""
    import cProfile
    import pstats

    rig(bones)
    profiler = cProfile.Profile()
    profiler.runcall(run_ours)
    print(f"cProfile of Remove Noise, {bones} bones x {FRAMES} frames (top {top}, cumulative):")
    pstats.Stats(profiler).sort_stats("cumulative").print_stats(top)
    pstats.Stats(profiler).sort_stats("tottime").print_stats(top)


def count_reads(bones: int) -> dict:
    """Keyframe reads of one run of ours: per (property): how many curves were read once, twice, ..."""
    from collections import Counter

    bulk = sys.modules["bl_ext.user_default.screwbender.blender.bulk"]
    rig(bones)
    original, reads = bulk.get, Counter()

    def get(collection, attr, out):
        owner = getattr(collection, "data", None)
        if owner is not None and owner.rna_type.identifier == "FCurve":
            reads[(owner.id_data.name, owner.data_path, owner.array_index, attr)] += 1
        return original(collection, attr, out)

    bulk.get = get
    try:
        run_ours()
    finally:
        bulk.get = original
    per: dict = {}
    for (_, _, _, attr), n in reads.items():
        per.setdefault(attr, Counter())[n] += 1
    print(f"keyframe reads of Remove Noise, {bones} bones: {sum(reads.values())} bulk.get calls on "
          f"{len({k[:3] for k in reads})} curves; per property {{times read: curves}}:")
    for attr, hist in sorted(per.items()):
        print(f"  {attr:22s} {dict(sorted(hist.items()))}")
    return {"calls": sum(reads.values()), "max_per_curve_property": max(reads.values(), default=0)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--bones", default=",".join(map(str, BONES)), help="rig sizes, comma-separated")
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--profile", type=int, default=0, metavar="N", help="print the top N of a cProfile")
    parser.add_argument("--reads", action="store_true", help="count the keyframe reads of one run")
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    cases = []
    for bones in (int(b) for b in args.bones.split(",")):
        ours, theirs = [], []
        for _ in range(args.runs):  # alternating, each from the same noisy keys
            rig(bones)
            ours.append(timed(run_ours))
            obj = rig(bones)
            ctx = graph_context()
            theirs.append(timed(lambda: run_gaussian(ctx)))
        med = lambda xs, i: float(np.median([x[i] for x in xs]))  # noqa: E731
        out = {
            "bones": bones, "frames": FRAMES, "curves": len(fcurves(obj)), "runs": args.runs,
            "ours_wall": med(ours, 0), "ours_cpu": med(ours, 1), "gaussian_wall": med(theirs, 0),
            "gaussian_cpu": med(theirs, 1),
        }
        out["ratio_wall"] = out["ours_wall"] / out["gaussian_wall"]
        print(f"Blender {bpy.app.version_string}: {bones} bones x {FRAMES} frames ({out['curves']} F-curves), "
              f"medians of {args.runs} runs")
        print(f"  Remove Noise (automatic strength)  {1000 * out['ours_wall']:8.1f} ms wall, {1000 * out['ours_cpu']:8.1f} ms CPU")
        print(f"  graph.gaussian_smooth (defaults)   {1000 * out['gaussian_wall']:8.1f} ms wall, {1000 * out['gaussian_cpu']:8.1f} ms CPU")
        print(f"  Remove Noise / Gaussian: {out['ratio_wall']:.2f}x wall, {out['ours_cpu'] / out['gaussian_cpu']:.2f}x CPU "
              f"(goal: at most 2x)")
        if args.reads:
            out["reads"] = count_reads(bones)
        if args.profile:
            profile(bones, args.profile)
        cases.append(out)
    if args.json:
        args.json.write_text(json.dumps({"blender": bpy.app.version_string, "cases": cases}, indent=1))


if __name__ == "__main__":
    main()
