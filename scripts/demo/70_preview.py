"""Demo part 70: the live preview overlay, drawn offscreen by the add-on's own draw code.

Builds the demo scene (10_scene.build), turns the ScrewBender preview on for one object at a
time and draws the overlay into a `gpu.types.GPUOffScreen` through the add-on's
`preview_draw.render_offscreen` (the very function the viewport's draw handler calls), with
an orthographic camera fitted to the motion. Three panels side by side:

  1. Flyer, Jarek 5 levels, wireframe instances; the raw polyscrew (grey) beside it;
  2. Flyer, the same motion as faint solid instances;
  3. SpinBlock, a closed cycle of four poses, B-spline 5 levels.

Key poses in red, the origin's trajectory in orange. Writes out/preview_overlay.png. In background mode the `gpu` module refuses to draw until Blender
has a GPU context; a tiny Workbench render creates one (software OpenGL is enough). Where
even that fails, the script says why and writes no image.
"""

from __future__ import annotations

import importlib
import importlib.util
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import demo_common  # noqa: E402

demo_common.blender_with_addon()
import bpy  # noqa: E402
import numpy as np  # noqa: E402
from mathutils import Euler  # noqa: E402

pd = importlib.import_module("bl_ext.user_default.screwbender.ops.preview_draw")

PANEL = (800, 640)
#: Per panel: (object, scheme, levels, style, show raw, camera rotation in degrees).
PANELS = (
    ("Flyer", "jarek", 5, "WIRE", True, (50, 0, 20)),
    ("Flyer", "jarek", 5, "SOLID", False, (50, 0, 20)),
    ("SpinBlock", "bspline", 5, "WIRE", False, (40, 0, 0)),
)


def load_scene_builder():
    spec = importlib.util.spec_from_file_location("demo_scene", Path(__file__).resolve().parent / "10_scene.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def ensure_gpu() -> str:
    """"" when the gpu module can draw; else why not."""
    reason = pd.gpu_unavailable_reason()
    if not reason:
        return ""
    scene = bpy.data.scenes.new("gpu init")
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x = scene.render.resolution_y = 8
    camera = bpy.data.objects.new("gpu init camera", bpy.data.cameras.new("gpu init camera"))
    scene.collection.objects.link(camera)
    scene.camera = camera
    try:
        bpy.ops.render.render(scene=scene.name)
    except RuntimeError as err:
        return f"{reason}; Workbench render failed: {err}"
    finally:
        bpy.data.scenes.remove(scene)
    return pd.gpu_unavailable_reason()


def fitted_view(points: np.ndarray, degrees: tuple[float, float, float]):
    """View and projection matrices of an orthographic camera framing `points`."""
    scene = bpy.context.scene
    data = bpy.data.cameras.new("Preview camera")
    data.type = "ORTHO"
    data.clip_end = 1000.0
    camera = bpy.data.objects.new("Preview camera", data)
    scene.collection.objects.link(camera)
    camera.rotation_euler = Euler([math.radians(a) for a in degrees], "XYZ")
    scene.render.resolution_x, scene.render.resolution_y = PANEL
    bpy.context.view_layer.update()
    depsgraph = bpy.context.evaluated_depsgraph_get()
    location, scale = camera.camera_fit_coords(depsgraph, [float(c) for c in points.ravel()])
    # the camera looks down its local -Z: back it off along +Z so nothing is behind it
    camera.location = location + camera.matrix_world.to_3x3().col[2] * 100.0
    data.ortho_scale = scale * 1.25
    bpy.context.view_layer.update()
    view = camera.matrix_world.inverted()
    projection = camera.calc_matrix_camera(bpy.context.evaluated_depsgraph_get(), x=PANEL[0], y=PANEL[1])
    bpy.data.objects.remove(camera)
    bpy.data.cameras.remove(data)
    return view, projection


def panel(name: str, scheme: str, levels: int, style: str, raw: bool, degrees) -> np.ndarray:
    scene = bpy.context.scene
    scene.screwbender.scheme = scheme
    scene.screwbender.levels = levels
    scene.screwbender.timing = "smooth"
    scene.screwbender.range_mode = "KEYS"
    settings = scene.screwbender_preview
    settings.instances = 24
    settings.trajectory_points = 400
    settings.style = style
    settings.show_raw = raw
    settings.line_width = 1.5
    settings.instance_color = (0.1, 0.35, 0.85, 0.9 if style == "WIRE" else 1.0)
    settings.raw_color = (0.45, 0.45, 0.45, 0.55)
    settings.key_color = (0.85, 0.08, 0.08, 1.0)
    settings.trajectory_color = (1.0, 0.55, 0.0, 1.0)
    for obj in scene.objects:
        obj.screwbender_preview = obj.name == name
    obj = scene.objects[name]
    pd.refresh(scene)
    entry = pd.CACHE.entries[obj.session_uid]
    if entry.error:
        sys.exit(f"70_preview: {entry.error}")
    b = entry.batches
    reach = max(obj.dimensions) / 2 + 0.2
    corners = np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)]) * reach
    # the origins the overlay draws, each padded by the object's size
    origins = np.concatenate([b.trajectory, b.keys[:, :3, 3]])
    points = (origins[:, None, :] + corners[None]).reshape(-1, 3)
    view, projection = fitted_view(points, degrees)
    pixels, drawn = pd.render_offscreen(scene, bpy.context.view_layer, view, projection, *PANEL)
    assert drawn == 1
    print(
        f"70_preview: {name}, {scheme} {levels} levels, {style.lower()}: {len(b.instances)} instances, "
        f"{len(b.trajectory)} trajectory points, {len(b.keys)} keys"
    )
    return pixels


def save_png(pixels: np.ndarray, path: Path) -> None:
    height, width = pixels.shape[:2]
    image = bpy.data.images.new("preview overlay", width, height, alpha=True)
    image.pixels.foreach_set(np.ascontiguousarray(pixels, dtype=np.float32).ravel())
    image.filepath_raw = str(path)
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)


def main() -> None:
    out = demo_common.out_dir()
    load_scene_builder().build()
    reason = ensure_gpu()
    if reason:
        print(f"70_preview: skipped, no GPU drawing in this Blender: {reason}")
        return
    panels = [panel(*spec) for spec in PANELS]
    gap = np.ones((PANEL[1], 6, 4), dtype=np.float32)
    gap[..., :3] = 0.85
    image = np.concatenate(sum(([p, gap] for p in panels), [])[:-1], axis=1)
    path = out / "preview_overlay.png"
    save_png(image, path)
    print(f"70_preview: {path} ({image.shape[1]}x{image.shape[0]})")
    for obj in bpy.context.scene.objects:
        obj.screwbender_preview = False


if __name__ == "__main__":
    main()
