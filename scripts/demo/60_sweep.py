"""Demo part 60: the region swept by a smoothed demo motion, built by Build Swept Region.

Opens out/demo.blend (from 20_smooth.py), sweeps the Jarek-smoothed Flyer and SpinBlock with
the installed extension's `screwbender.sweep` operator (the smoothed motion at its baked
keys, 1 step per span: the baked keys are one frame apart), and renders with Workbench, side by side: a few instances of the
body along the motion over the translucent swept region, and the swept region alone.
Prints triangles and time, against the triangles of stroboscopic instancing at every baked
key. Writes out/demo_sweep_<motion>.png.
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import demo_common  # noqa: E402

demo_common.blender_with_addon()
import bpy  # noqa: E402
import numpy as np  # noqa: E402
from mathutils import Euler, Matrix, Vector  # noqa: E402

#: Motion -> (camera rotation in degrees, number of instances drawn, title).
SHOTS = {
    "Flyer": ((30, 0, 15), 7, "Region swept by the Flyer (Jarek-smoothed, 6 keys): Build Swept Region"),
    "SpinBlock": ((30, 0, 0), 6, "Region swept by the spinning block (Jarek-smoothed, 4 keys)"),
}
PANEL_PIXELS = (760, 720)
REGION_COLOR = (0.30, 0.55, 0.90, 1.0)
BODY_COLOR = (0.95, 0.55, 0.15, 1.0)


def sweep(obj: bpy.types.Object) -> tuple[bpy.types.Object, float]:
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    start = time.perf_counter()
    result = bpy.ops.screwbender.sweep(steps=1, caps=True, closed=False)
    seconds = time.perf_counter() - start
    if result != {"FINISHED"}:
        sys.exit(f"60_sweep: Build Swept Region failed on {obj.name}")
    return bpy.context.view_layer.objects.active, seconds


def world_points(obj: bpy.types.Object) -> np.ndarray:
    co = np.empty(3 * len(obj.data.vertices))
    obj.data.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    mw = np.array(obj.matrix_world)
    return co @ mw[:3, :3].T + mw[:3, 3]


def render(source_scene, motion: str, obj: bpy.types.Object, region: bpy.types.Object, out: Path) -> Path:
    camera_degrees, count, title = SHOTS[motion]
    swept = demo_common_module_swept()
    frames = swept.motion_frames(obj, source_scene)
    picks = frames[np.linspace(0, len(frames) - 1, count).round().astype(int)]
    matrices = []
    for f in picks:
        whole = math.floor(f)
        source_scene.frame_set(whole, subframe=float(f - whole))
        matrices.append(obj.matrix_world.copy())

    camera_rotation = Euler([math.radians(a) for a in camera_degrees], "XYZ")
    to_camera = camera_rotation.to_matrix().transposed()
    pts = world_points(region)
    seen = pts @ np.array(to_camera).T
    low, high = seen.min(axis=0), seen.max(axis=0)
    width = (high[0] - low[0]) * 1.15 + 0.5
    height = (high[1] - low[1]) * 1.25 + 0.5
    panel_width = max(width, height * PANEL_PIXELS[0] / PANEL_PIXELS[1])
    panel_height = panel_width * PANEL_PIXELS[1] / PANEL_PIXELS[0]
    right = Vector(to_camera.transposed() @ Vector((1.0, 0.0, 0.0)))
    up = Vector(to_camera.transposed() @ Vector((0.0, 1.0, 0.0)))
    back = Vector(to_camera.transposed() @ Vector((0.0, 0.0, 1.0)))

    scene = bpy.data.scenes.new(f"Sweep {motion}")
    mesh = obj.data
    shift = Matrix.Translation(right * panel_width)
    for i, m in enumerate(matrices):
        inst = bpy.data.objects.new(f"{motion} instance {i}", mesh)
        inst.matrix_world = m
        inst.color = BODY_COLOR
        scene.collection.objects.link(inst)
    for k, matrix in enumerate((Matrix.Identity(4), shift)):
        view = bpy.data.objects.new(f"{motion} region {k}", region.data)
        view.matrix_world = matrix
        view.color = REGION_COLOR[:3] + ((0.35,) if k == 0 else (1.0,))
        scene.collection.objects.link(view)

    centre_cam = Vector(((low[0] + high[0]) / 2, (low[1] + high[1]) / 2, high[2]))
    centre = Vector(to_camera.transposed() @ centre_cam)
    text_size = panel_height * 0.05
    for i, label in enumerate(("instances over the swept region", "swept region")):
        curve = bpy.data.curves.new(f"label {i}", "FONT")
        curve.body = label
        curve.size = text_size
        curve.align_x = "CENTER"
        text = bpy.data.objects.new(f"label {i}", curve)
        text.location = centre + right * (i * panel_width) + up * (panel_height / 2 - text_size * 1.6)
        text.rotation_euler = camera_rotation
        text.color = (0.1, 0.1, 0.1, 1.0)
        scene.collection.objects.link(text)
    curve = bpy.data.curves.new("title", "FONT")
    curve.body = title
    curve.size = text_size * 0.75
    curve.align_x = "CENTER"
    text = bpy.data.objects.new("title", curve)
    text.location = centre + right * (panel_width / 2) - up * (panel_height / 2 - text_size * 0.9)
    text.rotation_euler = camera_rotation
    text.color = (0.25, 0.25, 0.25, 1.0)
    scene.collection.objects.link(text)

    camera_data = bpy.data.cameras.new(f"Camera {motion}")
    camera_data.type = "ORTHO"
    camera_data.ortho_scale = 2 * panel_width
    camera_data.clip_end = 1000.0
    camera = bpy.data.objects.new(f"Camera {motion}", camera_data)
    camera.rotation_euler = camera_rotation
    camera.location = centre + right * (panel_width / 2) + back * 100.0
    scene.collection.objects.link(camera)
    scene.camera = camera
    world = bpy.data.worlds.new(f"World {motion}")
    world.color = (1.0, 1.0, 1.0)
    scene.world = world
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x = 2 * PANEL_PIXELS[0]
    scene.render.resolution_y = PANEL_PIXELS[1]
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.view_settings.view_transform = "Standard"
    scene.display.render_aa = "8"
    shading = scene.display.shading
    shading.light = "STUDIO"
    shading.color_type = "OBJECT"
    shading.show_xray = False
    shading.show_object_outline = True
    shading.object_outline_color = (0.15, 0.15, 0.15)
    shading.show_specular_highlight = False
    path = out / f"demo_sweep_{motion.lower()}.png"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True, scene=scene.name)
    return path


def demo_common_module_swept():
    import importlib

    return importlib.import_module("bl_ext.user_default.screwbender.blender.swept")


def main() -> None:
    out = demo_common.out_dir()
    bpy.ops.wm.open_mainfile(filepath=str(out / "demo.blend"))
    source_scene = bpy.context.scene
    for motion in SHOTS:
        obj = source_scene.objects[f"{motion}.Jarek"]
        region, seconds = sweep(obj)
        swept = demo_common_module_swept()
        n_frames = len(swept.motion_frames(obj, source_scene))
        obj.data.calc_loop_triangles()
        body_tris = len(obj.data.loop_triangles)
        region.data.calc_loop_triangles()
        tris = len(region.data.loop_triangles)
        print(
            f"60_sweep: {motion}: {body_tris} triangles over {n_frames - 1} screws -> swept region "
            f"{tris} triangles in {seconds:.3f} s (operator); stroboscopic instances at every "
            f"baked key: {n_frames * body_tris} triangles"
        )
        path = render(source_scene, motion, obj, region, out)
        print(f"60_sweep: {path}")
    bpy.ops.wm.save_as_mainfile(filepath=str(out / "demo_sweep.blend"))


if __name__ == "__main__":
    main()
