"""Benchmark: Remove Noise (the operator) on a 100-bone rig x 1,000 frames of noisy keys,
against Blender's own `graph.gaussian_smooth` on the same curves, in one Blender session
(issue 19's speed target: at least 10x faster).

The rig: 100 bones, each keyed on every frame (XYZ Euler, one key per frame, a slow sway plus
0.5 degrees of noise per axis), the root's location too: 303 F-curves of 1,000 keys. Ours:
`bpy.ops.screwbender.denoise()` on the armature (Object Mode, every bone; automatic strength;
reading, one batched polyscrew.denoise call, writing the keys into a new action). Blender's:
`graph.gaussian_smooth` at its defaults on every key of those curves, run headless with
`bpy.context.temp_override` on the largest area switched to the Graph Editor. Each run starts
from the same noisy keys; medians of the runs (wall clock and the process's CPU time).

Run: PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench_denoise_rig.py [--runs 3] [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent / "demo"))
import demo_common  # noqa: E402

demo_common.blender_with_addon()
import bpy  # noqa: E402

from bench_denoise import fcurves  # noqa: E402  (the same curve lookup and Graph Editor context)
from bench_denoise import graph_context as _graph_context  # noqa: E402


def graph_context():
    return _graph_context(bpy)

BONES, FRAMES = 100, 1000


def rig() -> bpy.types.Object:
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, FRAMES
    data = bpy.data.armatures.new("Rig")
    obj = bpy.data.objects.new("Rig", data)
    scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode="EDIT")
    for i in range(BONES):
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


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=3)
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    ours, theirs = [], []
    for _ in range(args.runs):
        obj = rig()
        result = {}

        def run_ours():
            result["r"] = bpy.ops.screwbender.denoise(armature="BONES")

        ours.append(timed(run_ours))
        assert result["r"] == {"FINISHED"}, result
        obj = rig()
        ctx = graph_context()

        def run_theirs():
            with bpy.context.temp_override(**ctx):
                result["g"] = bpy.ops.graph.gaussian_smooth()

        theirs.append(timed(run_theirs))
        assert result["g"] == {"FINISHED"}, result
        curves = len(fcurves(obj))
    med = lambda xs, i: float(np.median([x[i] for x in xs]))  # noqa: E731
    out = {
        "blender": bpy.app.version_string, "bones": BONES, "frames": FRAMES, "curves": curves, "runs": args.runs,
        "ours_wall": med(ours, 0), "ours_cpu": med(ours, 1), "gaussian_wall": med(theirs, 0), "gaussian_cpu": med(theirs, 1),
    }
    print(f"Blender {out['blender']}: {BONES} bones x {FRAMES} frames ({curves} F-curves), medians of {args.runs} runs")
    print(f"  Remove Noise (automatic strength)  {1000 * out['ours_wall']:8.1f} ms wall, {1000 * out['ours_cpu']:8.1f} ms CPU")
    print(f"  graph.gaussian_smooth (defaults)   {1000 * out['gaussian_wall']:8.1f} ms wall, {1000 * out['gaussian_cpu']:8.1f} ms CPU")
    print(f"  ratio (Gaussian / ours): {out['gaussian_wall'] / out['ours_wall']:.1f}x wall, {out['gaussian_cpu'] / out['ours_cpu']:.1f}x CPU")
    if args.json:
        args.json.write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
