"""bpy benchmark of Build Swept Region: a 100,000-triangle mesh over 64 screws.

Run with the bpy wheel and the built extension (as the demo scripts do):
    PYTHONPATH=<pylib>:.venv/bpy/<ver> .venv/bin/python scripts/bench/bench_sweep_blender.py
Prints the triangles in and out and the times of `polyscrew.sweep` alone and of the whole
operator (reading the evaluated mesh and the motion at 65 frames, sweeping, writing the new
mesh object), against stroboscopic instancing at the same pose density (64 x 8 + 1 linked
duplicates of the body: their triangles and the time to create them).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "demo"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import demo_common  # noqa: E402

demo_common.blender_with_addon()
import bpy  # noqa: E402
import numpy as np  # noqa: E402

import bench_shapes  # noqa: E402  (scripts/bench, numpy only)

STEPS = 8
SCREWS = 64




def main() -> None:
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    swept = __import__("bl_ext.user_default.screwbender.blender.swept", fromlist=["swept"])
    scene = bpy.context.scene
    v, t = bench_shapes.bumpy_torus(250, 200)
    mesh = swept.mesh_from_arrays("Bumpy", v, t)
    obj = bpy.data.objects.new("Bumpy", mesh)
    scene.collection.objects.link(obj)
    obj.rotation_mode = "XYZ"
    scene.frame_start, scene.frame_end = 1, SCREWS + 1
    for k in range(SCREWS + 1):
        s = k / SCREWS
        obj.location = (3 * math.cos(2 * math.pi * s), 3 * math.sin(2 * math.pi * s), 2 * s)
        obj.rotation_euler = (0.9 * s, 3.0 * s, 1.5 * s)
        obj.keyframe_insert("location", frame=k + 1)
        obj.keyframe_insert("rotation_euler", frame=k + 1)
    for o in bpy.context.view_layer.objects:
        o.select_set(o is obj)
    bpy.context.view_layer.objects.active = obj

    start = time.perf_counter()
    computed = swept.compute(obj, bpy.context, STEPS, True)
    compute_s = time.perf_counter() - start
    for o in bpy.context.view_layer.objects:
        o.select_set(o is obj)
    bpy.context.view_layer.objects.active = obj
    start = time.perf_counter()
    assert bpy.ops.screwbender.sweep(steps=STEPS, caps=True, closed=False) == {"FINISHED"}
    operator_s = time.perf_counter() - start
    region = bpy.context.view_layer.objects.active
    out_tris = swept.triangle_count(region.data)

    count = SCREWS * STEPS + 1
    start = time.perf_counter()
    coll = bpy.data.collections.new("Stroboscopic")
    scene.collection.children.link(coll)
    poses = computed.poses
    import polyscrew

    strobe = np.concatenate(
        [polyscrew.interpolate(a, b, np.linspace(0, 1, STEPS, endpoint=False)) for a, b in zip(poses, poses[1:])]
        + [poses[-1:]]
    )
    from mathutils import Matrix

    for k, p in enumerate(strobe):
        inst = bpy.data.objects.new(f"Bumpy {k}", mesh)
        inst.matrix_world = Matrix(p.tolist())
        coll.objects.link(inst)
    bpy.context.evaluated_depsgraph_get().update()
    strobe_s = time.perf_counter() - start
    print(
        f"bench_sweep_blender (Blender {bpy.app.version_string}): {len(t)} triangles, {SCREWS} screws, "
        f"{STEPS} steps: swept region {out_tris} triangles; polyscrew.sweep {computed.seconds:.3f} s, "
        f"read + sweep {compute_s:.3f} s, whole operator {operator_s:.3f} s; stroboscopic {count} "
        f"instances = {count * len(t)} triangles, created in {strobe_s:.3f} s"
    )


if __name__ == "__main__":
    main()
