"""Demo part 30: stroboscopic Workbench renders of out/demo.blend, side by side.

For each demo motion, the object is drawn at evenly spaced frames (blue at the start of the
motion to orange at the end; the key poses in red) once per variant, in panels side by side:
Blender's own Bezier interpolation of the keys, the raw polyscrew (one screw per key span),
and the ScrewBender subdivisions. Writes out/demo_<motion>.png (`scripts/demo.sh
--update-docs` copies them to docs/images/ for the README).
"""

from __future__ import annotations

import colorsys
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bpy  # noqa: E402
import demo_common  # noqa: E402
import numpy as np  # noqa: E402
from mathutils import Euler, Matrix, Vector  # noqa: E402

SOURCE_LABEL = "Blender Bezier keys"

#: Per motion: (panels, sample frames (start, end, step), camera rotation in degrees, title).
SHOTS = {
    "LCycle": (
        ("Raw polyscrew", "4-point", "B-spline", "Jarek"),
        (1, 97, 1.5),
        (28, 0, 0),
        "L-shaped cycle of 8 poses (4 rotated): raw polyscrew and the three subdivisions, 5 levels",
    ),
    "Pendulum": (
        (SOURCE_LABEL, "Raw polyscrew", "4-point"),
        (1, 25, 1),
        (90, 0, 0),
        "Pendulum keyed at its bob from two poses: a screw keeps the rod on its pivot",
    ),
    "SpinBlock": (
        (SOURCE_LABEL, "Raw polyscrew", "B-spline"),
        (1, 41, 2),
        (30, 0, 0),
        "Block spinning through four poses, rocking 40 degrees each way: B-spline from four poses, as in the paper",
    ),
    "Flyer": (
        (SOURCE_LABEL, "Raw polyscrew", "Jarek"),
        (1, 60, 2),
        (30, 0, 15),
        "Six keys at uneven frames (1, 6, 20, 26, 50, 60), every 2nd frame drawn: spacing shows speed",
    ),
}
PANEL_LABELS = {"Raw polyscrew": "raw polyscrew", "4-point": "4-point", "B-spline": "B-spline", "Jarek": "Jarek"}
PANEL_PIXELS = (640, 760)
#: Share of a panel's height for the motion (the rest: label, speed graph, title).
MOTION_SHARE = 0.66
KEY_COLOR = (0.85, 0.08, 0.08, 1.0)


def time_color(u: float) -> tuple[float, float, float, float]:
    """Blue at u = 0 to orange at u = 1."""
    r, g, b = colorsys.hsv_to_rgb(0.62 - 0.54 * u, 0.75, 0.95)
    return (r, g, b, 1.0)


def world_matrices(obj: bpy.types.Object, frames: np.ndarray) -> list[Matrix]:
    scene = bpy.context.scene
    out = []
    for frame in frames:
        whole = math.floor(frame)
        scene.frame_set(whole, subframe=float(frame - whole))
        out.append(obj.matrix_world.copy())
    return out


def key_frames(obj: bpy.types.Object) -> list[float]:
    curves = demo_common.channels().object_fcurves(obj)
    return sorted({round(k.co[0], 3) for fc in curves for k in fc.keyframe_points})


def mesh_points(mesh: bpy.types.Mesh) -> np.ndarray:
    co = np.empty(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def add_instance(scene, mesh, matrix: Matrix, color, name: str) -> None:
    inst = bpy.data.objects.new(name, mesh)
    inst.matrix_world = matrix
    inst.color = color
    scene.collection.objects.link(inst)


def obj_of(source_scene, motion: str, panel: str) -> bpy.types.Object:
    return source_scene.objects[motion if panel == SOURCE_LABEL else f"{motion}.{panel}"]


def origin_speed(obj: bpy.types.Object, start: float, end: float) -> tuple[np.ndarray, np.ndarray]:
    """(times, distance the object's origin moves from frame to frame): the speed on screen."""
    times = np.arange(start, end + 1e-9, 1.0)
    positions = np.array([m.translation for m in world_matrices(obj, times)])
    speed = np.linalg.norm(np.diff(positions, axis=0), axis=1)
    return (times[:-1] + times[1:]) / 2, speed


def tilt(obj: bpy.types.Object, start: float, end: float) -> tuple[np.ndarray, np.ndarray]:
    """(times, angle in degrees between the object's local Z axis and the world Z axis)."""
    times = np.arange(start, end + 1e-9, 0.5)
    z = np.array([m.to_3x3().normalized().col[2] for m in world_matrices(obj, times)])
    return times, np.degrees(np.arccos(np.clip(z[:, 2], -1.0, 1.0)))


#: What the graph under each panel shows: (function, caption).
GRAPHS = {"speed": (origin_speed, "speed"), "tilt": (tilt, "tilt")}
GRAPH_OF = {"SpinBlock": "tilt"}


def add_polyline(scene, points: list[Vector], thickness: float, color) -> None:
    curve = bpy.data.curves.new("line", "CURVE")
    curve.dimensions = "3D"
    curve.bevel_depth = thickness
    spline = curve.splines.new("POLY")
    spline.points.add(len(points) - 1)
    spline.points.foreach_set("co", [c for p in points for c in (p.x, p.y, p.z, 1.0)])
    line = bpy.data.objects.new("line", curve)
    line.color = color
    scene.collection.objects.link(line)


def add_text(scene, text: str, location: Vector, rotation: Euler, size: float, color) -> None:
    curve = bpy.data.curves.new(f"label {text}", "FONT")
    curve.body = text
    curve.size = size
    curve.align_x = "CENTER"
    label = bpy.data.objects.new(f"label {text}", curve)
    label.location = location
    label.rotation_euler = rotation
    label.color = color
    scene.collection.objects.link(label)


def render_shot(source_scene, motion: str, out: Path) -> Path:
    panels, (start, end, step), camera_degrees, title = SHOTS[motion]
    frames = np.arange(start, end - 1e-9, step)
    source = source_scene.objects[motion]
    keys = [f for f in key_frames(source) if start <= f <= end]
    mesh = source.data
    key_matrices = world_matrices(source, keys)
    tracks = {}
    for panel in panels:
        tracks[panel] = world_matrices(obj_of(source_scene, motion, panel), frames)

    camera_rotation = Euler([math.radians(a) for a in camera_degrees], "XYZ")
    to_camera = camera_rotation.to_matrix().transposed()
    from_camera = to_camera.transposed()
    points = mesh_points(mesh)
    # extent of the whole motion in the camera's view (x right, y up)
    seen = np.concatenate(
        [
            points @ np.array(to_camera @ m.to_3x3()).T + np.array(to_camera @ m.translation)
            for m in [m for track in tracks.values() for m in track] + key_matrices
        ]
    )
    low, high = seen.min(axis=0), seen.max(axis=0)
    width = (high[0] - low[0]) * 1.1 + 0.5
    height = (high[1] - low[1]) * 1.1 + 0.5
    # panel layout (camera units): label on top, the motion, the speed graph, the title
    aspect = PANEL_PIXELS[0] / PANEL_PIXELS[1]
    panel_height = max(height / MOTION_SHARE, width / aspect)
    panel_width = panel_height * aspect
    top = (low[1] + high[1]) / 2 + height / 2 + 0.07 * panel_height
    bottom = top - panel_height
    mid_x = (low[0] + high[0]) / 2
    depth = high[2] + 1.0

    def at(x: float, y: float) -> Vector:
        """World point of camera-plane coordinates (x, y)."""
        return from_camera @ Vector((x, y, depth))

    right = from_camera @ Vector((1.0, 0.0, 0.0))
    back = from_camera @ Vector((0.0, 0.0, 1.0))

    scene = bpy.data.scenes.new(f"Render {motion}")
    # the speed graph covers every key (a whole cycle), the strobe possibly less
    all_keys = key_frames(source)
    graph_start, graph_end = all_keys[0], all_keys[-1]
    graph, caption = GRAPHS[GRAPH_OF.get(motion, "speed")]
    speeds = {panel: graph(obj_of(source_scene, motion, panel), graph_start, graph_end) for panel in panels}
    top_speed = max(float(v[1].max()) for v in speeds.values())
    text_size = panel_height * 0.045
    for i, panel in enumerate(panels):
        shift = Matrix.Translation(right * (i * panel_width))
        n = len(tracks[panel])
        for j, matrix in enumerate(tracks[panel]):
            add_instance(scene, mesh, shift @ matrix, time_color(j / max(n - 1, 1)), f"{panel} {j}")
        for j, matrix in enumerate(key_matrices):
            add_instance(scene, mesh, shift @ matrix, KEY_COLOR, f"{panel} key {j}")
        x0 = mid_x + i * panel_width
        add_text(scene, PANEL_LABELS.get(panel, panel), at(x0, top - 0.055 * panel_height), camera_rotation, text_size, (0.1, 0.1, 0.1, 1.0))
        # speed of the object's origin (or its tilt) over time, same scale in every panel;
        # key frames in red
        left, span = x0 - 0.42 * panel_width, 0.84 * panel_width
        base, tall = bottom + 0.12 * panel_height, 0.12 * panel_height
        times, speed = speeds[panel]
        u = (times - graph_start) / (graph_end - graph_start)
        add_polyline(scene, [at(left + span * a, base + tall * b / top_speed) for a, b in zip(u, speed)], 0.0035 * panel_height, (0.1, 0.1, 0.1, 1.0))
        add_polyline(scene, [at(left, base), at(left + span, base)], 0.0015 * panel_height, (0.6, 0.6, 0.6, 1.0))
        for k in all_keys:
            a = (k - graph_start) / (graph_end - graph_start)
            add_polyline(scene, [at(left + span * a, base - 0.012 * panel_height), at(left + span * a, base + 0.012 * panel_height)], 0.002 * panel_height, KEY_COLOR)
        add_text(scene, f"{caption}, frames {graph_start:g}-{graph_end:g}", at(x0, base - 0.035 * panel_height), camera_rotation, text_size * 0.55, (0.4, 0.4, 0.4, 1.0))
    total_width = panel_width * len(panels)
    add_text(
        scene, title, at(mid_x + (len(panels) - 1) * panel_width / 2, bottom + 0.025 * panel_height),
        camera_rotation, text_size * 0.9, (0.25, 0.25, 0.25, 1.0),
    )
    centre = at(mid_x, (top + bottom) / 2)

    camera_data = bpy.data.cameras.new(f"Camera {motion}")
    camera_data.type = "ORTHO"
    camera_data.ortho_scale = total_width
    camera_data.clip_end = 1000.0
    camera = bpy.data.objects.new(f"Camera {motion}", camera_data)
    camera.rotation_euler = camera_rotation
    camera.location = centre + right * ((len(panels) - 1) * panel_width / 2) + back * 100.0
    camera_data.clip_end = 1000.0
    scene.collection.objects.link(camera)
    scene.camera = camera

    world = bpy.data.worlds.new(f"World {motion}")
    world.color = (1.0, 1.0, 1.0)
    scene.world = world
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x = PANEL_PIXELS[0] * len(panels)
    scene.render.resolution_y = PANEL_PIXELS[1]
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.image_settings.color_mode = "RGB"
    scene.render.image_settings.compression = 100
    scene.view_settings.view_transform = "Standard"
    scene.display.render_aa = "8"
    shading = scene.display.shading
    shading.light = "STUDIO"
    shading.color_type = "OBJECT"
    shading.show_object_outline = True
    shading.object_outline_color = (0.15, 0.15, 0.15)
    shading.show_specular_highlight = False
    path = out / f"demo_{motion.lower()}.png"
    scene.render.filepath = str(path)
    bpy.ops.render.render(write_still=True, scene=scene.name)
    return path


def main() -> None:
    out = demo_common.out_dir()
    bpy.ops.wm.open_mainfile(filepath=str(out / "demo.blend"))
    source_scene = bpy.context.scene
    for motion in SHOTS:
        path = render_shot(source_scene, motion, out)
        print(f"30_render: {path}")


if __name__ == "__main__":
    main()
