# SPDX-License-Identifier: GPL-3.0-or-later
"""Angular-velocity editing (Xie et al. 2011, "Sketch-based rotation editing").

The animator's workflow, without code:

1. **Add Angular Velocity Sketch** (`screwbender.add_angular_velocity_sketch`) on the active
   keyed object creates a unit-sphere helper at the object (a wire UV sphere, so the Curve
   Draw tool can project strokes onto its surface) holding
   - the *direction* sketch: a curve object on the sphere (blue), one point per frame of the
     keys' range, first made from the object's current angular velocity; edit its points on
     the sphere, or draw a new stroke into it in Edit Mode (the last spline is used; it runs
     from the first to the last frame of the range);
   - the *magnitude*: the keyed custom property `screwbender_speed` (rad/s) of the sphere,
     one key per frame, to shape in the Graph Editor.
2. Select the keys that must hold (in the rotation F-curves; none selected: all keys hold)
   and run **Fit Angular Velocity** (`screwbender.fit_angular_velocity`): the rotation over
   the range is fitted with `polyscrew.fit_angular_velocity` and baked into a new action
   (the old one is kept, Revert restores it); location and every other channel are copied
   untouched. The fitted angular velocity is drawn on the sphere in red next to the sketch.

Times are converted to seconds (`frame / fps`) so the paper's alpha and delta apply. This
module is the logic (sketch helpers, reading the sketch, the fit and its bake); the operators
and the panel are in :mod:`angvel_ops`.
"""

from __future__ import annotations

import bmesh
import bpy
import numpy as np
import polyscrew

from . import bake, bulk, channels, feature, keys, owners, transaction
from .keys import SmoothError

#: Custom property (on the sphere helper) whose F-curve is the magnitude sketch, rad/s.
SPEED_PROP = "screwbender_speed"
#: Custom properties linking the helpers: object -> sphere, sphere -> sketch and fit curves.
SPHERE_KEY = "screwbender_omega_sphere"
SKETCH_KEY = "screwbender_omega_sketch"
FIT_KEY = "screwbender_omega_fit"
RANGE_KEY = "screwbender_omega_range"
#: Viewport colours of the sketch (blue) and the fit (red), as in the paper's figures.
SKETCH_COLOR = (0.1, 0.3, 1.0, 1.0)
FIT_COLOR = (1.0, 0.1, 0.05, 1.0)
#: Half-width of the central difference used for the current angular velocity, frames.
DIFF_FRAMES = 0.05


def frames_per_second(scene: bpy.types.Scene) -> float:
    """Frames per second of `scene` (fps / fps_base)."""
    return scene.render.fps / scene.render.fps_base


def current_angular_velocity(motion: keys.KeyedMotion, frames: np.ndarray, fps: float) -> np.ndarray:
    """World-frame (parent-space) angular velocity, rad/s, of the smoothed keyed motion at `frames`.

    The motion is `polyscrew.sample` of the key poses (the add-on's default smoothing); the
    angular velocity is the central difference `log(R(f + h) R(f - h)^T) / 2h`
    (`polyscrew.turn_vectors`).
    """
    lo, hi = float(motion.frames[0]), float(motion.frames[-1])
    plus = polyscrew.sample(motion.poses, motion.frames, np.minimum(frames + DIFF_FRAMES, hi))
    minus = polyscrew.sample(motion.poses, motion.frames, np.maximum(frames - DIFF_FRAMES, lo))
    span = (np.minimum(frames + DIFF_FRAMES, hi) - np.maximum(frames - DIFF_FRAMES, lo)) / fps
    return polyscrew.turn_vectors(minus, plus) / span[:, None]


def _unit_rows(v: np.ndarray) -> np.ndarray:
    n = np.linalg.norm(v, axis=1, keepdims=True)
    return np.where(n > 0.0, v / np.where(n > 0.0, n, 1.0), [0.0, 0.0, 1.0])


def _set_curve_points(curve_obj: bpy.types.Object, points: np.ndarray) -> None:
    """Replaces the curve's splines by one poly spline through `points` (N, 3), local space."""
    data = curve_obj.data
    data.splines.clear()
    spline = data.splines.new("POLY")
    spline.points.add(len(points) - 1)
    co = np.ones((len(points), 4))
    co[:, :3] = points
    bulk.put(spline.points, "co", co.ravel())
    data.update_tag()


def _curve_object(name: str, sphere: bpy.types.Object, color: tuple, collection) -> bpy.types.Object:
    data = bpy.data.curves.new(name, "CURVE")
    data.dimensions = "3D"
    data.bevel_depth = 0.01
    material = bpy.data.materials.new(name)
    material.diffuse_color = color
    data.materials.append(material)
    obj = bpy.data.objects.new(name, data)
    obj.color = color
    obj.parent = sphere
    obj.hide_render = True
    collection.objects.link(obj)
    return obj


def sphere_of(obj: bpy.types.Object) -> bpy.types.Object | None:
    """The sketch sphere of `obj`, or None."""
    sphere = obj.get(SPHERE_KEY)
    return sphere if isinstance(sphere, bpy.types.Object) else None


def add_sketch(context: bpy.types.Context, obj: bpy.types.Object, t: transaction.Transaction) -> bpy.types.Object:
    """Creates the sphere helper, the direction sketch and the speed curve for `obj` (inside
    the transaction `t`).

    The sketch starts as the object's current angular velocity over its keys' range (one
    point and one speed key per frame), so an unedited sketch refits the current motion.
    Returns the sphere.
    """
    motion = keys.read(obj, "OFF")
    fps = frames_per_second(context.scene)
    start, end = float(motion.frames[0]), float(motion.frames[-1])
    frames = bake.bake_frames(start, end, 1.0)
    if frames[-1] < end:
        frames = np.append(frames, end)
    omega = current_angular_velocity(motion, frames, fps)
    collection = context.collection
    mesh = bpy.data.meshes.new(f"{obj.name}.omega_sphere")
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=32, v_segments=16, radius=1.0)
    bm.to_mesh(mesh)
    bm.free()
    sphere = bpy.data.objects.new(f"{obj.name}.omega_sphere", mesh)
    sphere.display_type = "WIRE"
    sphere.hide_render = True
    sphere.location = obj.matrix_world.translation
    collection.objects.link(sphere)
    sketch = _curve_object(f"{obj.name}.omega_sketch", sphere, SKETCH_COLOR, collection)
    _set_curve_points(sketch, _unit_rows(omega))
    # The magnitude: a keyed custom property of the sphere, one key per frame.
    sphere[SPEED_PROP] = float(np.linalg.norm(omega[0]))
    sphere.keyframe_insert(data_path=f'["{SPEED_PROP}"]', frame=start)
    fcurve = next(fc for fc in channels.object_fcurves(sphere) if fc.data_path == f'["{SPEED_PROP}"]')
    points = fcurve.keyframe_points
    points.add(len(frames) - len(points))
    co = np.empty((len(frames), 2))
    co[:, 0] = frames
    co[:, 1] = np.linalg.norm(omega, axis=1)
    bulk.put(points, "co", co.ravel())
    fcurve.update()
    sphere[SKETCH_KEY] = sketch
    sphere[RANGE_KEY] = [start, end]
    t.set_item(obj, SPHERE_KEY, sphere)
    return sphere


#: How the stroke's points are spread over the frame range.
STROKE_TIMINGS = (
    ("POINTS", "Per Point", "Points evenly spaced in time (the generated sketch: one point per frame)"),
    ("LENGTH", "By Length", "Time proportional to the angle travelled on the sphere (a hand-drawn stroke)"),
)
#: Points per Bezier segment when a drawn (Bezier) stroke is tessellated.
BEZIER_SAMPLES = 12


def _spline_points(spline) -> np.ndarray:
    """The spline's points in curve space: poly/NURBS points as they are, a Bezier spline
    tessellated (BEZIER_SAMPLES points per segment, as drawn)."""
    if spline.type != "BEZIER":
        co = np.empty(4 * len(spline.points))
        bulk.get(spline.points, "co", co)
        return co.reshape(-1, 4)[:, :3]
    n = len(spline.bezier_points)
    co, left, right = (np.empty(3 * n) for _ in range(3))
    bulk.get(spline.bezier_points, "co", co)
    bulk.get(spline.bezier_points, "handle_left", left)
    bulk.get(spline.bezier_points, "handle_right", right)
    co, left, right = co.reshape(n, 3), left.reshape(n, 3), right.reshape(n, 3)
    s = np.linspace(0.0, 1.0, BEZIER_SAMPLES, endpoint=False)[:, None]
    parts = [
        (1 - s) ** 3 * co[i] + 3 * (1 - s) ** 2 * s * right[i] + 3 * (1 - s) * s**2 * left[i + 1] + s**3 * co[i + 1]
        for i in range(n - 1)
    ]
    return np.concatenate(parts + [co[-1:]]) if parts else co


def read_sketch(sphere: bpy.types.Object, timing: str = "POINTS") -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The sketched target: frames (P,), directions (P, 3) in the sphere's frame, speeds (P,).

    The last spline of the sketch curve (the stroke drawn last) runs from the first to the
    last frame of the range, its points evenly spaced in time ("POINTS") or by the angle
    travelled on the sphere ("LENGTH"); directions are the points seen from the sphere's
    centre (normalised by `polyscrew`, so a stroke near the surface is fine); the speed is the
    `screwbender_speed` F-curve of the sphere at those frames.
    """
    sketch = sphere.get(SKETCH_KEY)
    if not isinstance(sketch, bpy.types.Object) or sketch.type != "CURVE" or not sketch.data.splines:
        raise SmoothError(f"{sphere.name}: its direction sketch curve is missing or empty")
    local = _spline_points(sketch.data.splines[-1])
    n = len(local)
    if n < 2:
        raise SmoothError(f"{sketch.name}: the sketch needs at least two points")
    # Sketch point -> world -> sphere frame (directions about the sphere's centre).
    to_sphere = np.array(sphere.matrix_world.inverted()) @ np.array(sketch.matrix_world)
    directions = local @ to_sphere[:3, :3].T + to_sphere[:3, 3]
    start, end = (float(v) for v in sphere[RANGE_KEY])
    if timing == "LENGTH":
        unit = _unit_rows(directions)
        step = polyscrew.direction_steps(unit)
        keep = np.concatenate(([True], step > 1e-9))  # repeated points would share a time
        directions, unit = directions[keep], unit[keep]
        travelled = np.concatenate(([0.0], np.cumsum(step[keep[1:]])))
        if len(directions) < 2 or travelled[-1] <= 0.0:
            raise SmoothError(f"{sketch.name}: the stroke does not move on the sphere")
        frames = start + (end - start) * travelled / travelled[-1]
    else:
        frames = np.linspace(start, end, n)
    fcurve = next(
        (fc for fc in channels.object_fcurves(sphere) if fc.data_path == f'["{SPEED_PROP}"]'), None
    )
    if fcurve is None:
        raise SmoothError(f"{sphere.name}: the speed curve ['{SPEED_PROP}'] is not keyed")
    speeds = np.array([fcurve.evaluate(f) for f in frames])
    return frames, directions, speeds


def selected_keys(obj: bpy.types.Object, motion: keys.KeyedMotion) -> np.ndarray:
    """Mask of the key frames with a selected key on a rotation F-curve (all when none is)."""
    path = keys.rotation_path(motion.rotation_mode)
    chosen = feature.selected_frames(owners.as_owner(obj), channels.object_fcurves(obj), motion.frames, props=(path,))
    return chosen if chosen.any() else np.ones(len(motion.frames), dtype=bool)


def fit(
    context: bpy.types.Context,
    obj: bpy.types.Object,
    t: transaction.Transaction,
    alpha: float = 0.002,
    delta: float = 0.1,
    max_frames: int = 10,
    timing: str = "POINTS",
) -> polyscrew.AngularVelocityFit:
    """Fits `obj`'s rotation to its sketch and bakes it into a new action; draws the fit.

    Everything is computed before anything changes: a refusal (SmoothError, with the
    polyscrew message) leaves the scene as it was; the writing happens inside `t`.
    """
    sphere = sphere_of(obj)
    if sphere is None:
        raise SmoothError(f"{obj.name}: no angular velocity sketch: add one first")
    motion = keys.read(obj, "OFF")
    fps = frames_per_second(context.scene)
    target_frames, directions, speeds = read_sketch(sphere, timing)
    # Directions are drawn in the sphere's frame; the fit works in the object's parent space.
    to_parent = np.array(sphere.matrix_world)[:3, :3]
    if obj.parent is not None:
        to_parent = np.array(obj.parent.matrix_world.inverted())[:3, :3] @ to_parent
    directions = directions @ to_parent.T
    start, end = float(motion.frames[0]), float(motion.frames[-1])
    # Every frame, and every key frame (keys on subframes are baked exactly too).
    frames = bake.bake_frames(start, end, 1.0)
    frames = np.union1d(frames, motion.frames)
    frames = frames[np.concatenate(([True], np.diff(frames) > keys.FRAME_TOLERANCE))]
    quats = polyscrew.rotation_channels(motion.poses, "QUATERNION")
    constrained = selected_keys(obj, motion)
    try:
        result = polyscrew.fit_angular_velocity(
            quats,
            motion.frames / fps,
            target_frames / fps,
            directions,
            constrained=constrained,
            alpha=alpha,
            delta=delta,
            max_frames=max_frames,
            sample_times=frames / fps,
            target_speed=speeds,
        )
        mode = motion.rotation_mode
        previous = keys.continued(mode, motion.first_rotation)
        matrices = polyscrew.rotation_matrices(result.quaternions, "QUATERNION")
        rotation = polyscrew.rotation_channels(matrices, mode, previous=previous)
    except ValueError as err:
        raise SmoothError(f"{obj.name}: {err}") from err
    baked = bake.Baked(
        owner=owners.Owner(obj), motion=motion, frames=frames, values={keys.rotation_path(mode): rotation}, cyclic=False
    )
    bake.write_one(baked, t)
    fit_curve = sphere.get(FIT_KEY)
    if not isinstance(fit_curve, bpy.types.Object):
        fit_curve = _curve_object(f"{obj.name}.omega_fit", sphere, FIT_COLOR, context.collection)
        t.set_item(sphere, FIT_KEY, fit_curve)
    else:  # the earlier fit's curve gets new data; the old data goes once everything worked
        old = fit_curve.data
        t.set(fit_curve, "data", old.copy())
        t.on_commit(lambda: bpy.data.curves.remove(old) if old.users == 0 else None)
    from_parent = np.linalg.inv(to_parent)
    _set_curve_points(fit_curve, _unit_rows(result.omega @ from_parent.T))
    return result
