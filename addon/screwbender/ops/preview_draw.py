# SPDX-License-Identifier: GPL-3.0-or-later
"""The live preview overlay: a `gpu` draw handler in the 3D Viewport, kept up to date.

- :func:`sync` installs the draw handler (`SpaceView3D.draw_handler_add`, POST_VIEW) and a
  `depsgraph_update_post` handler while at least one object has its preview on, and removes
  both as soon as none has: nothing is left behind.
- The depsgraph handler only checks the key hash of each previewed owner
  (:func:`preview.key_hash`): every previewed object, and for an armature its keyed bones
  (:func:`preview.preview_owners`); an owner is recomputed only when its hash changed, and
  the viewports are redrawn only then.
- :func:`draw_previews` draws the cached batches (also into an offscreen buffer:
  :func:`render_offscreen`). It reads Blender data and never writes any.

Batches are built in each owner's own space and drawn in the world as it is at the current
frame (:func:`owner_space`): an object under its parent's current world matrix
(`matrix_world @ matrix_basis^-1`), a bone under its armature object and its parent bones as
they are posed now (Blender's own bone transform, Inherit Rotation, Inherit Scale and Local
Location included). Moving a parent, or posing a parent bone, does not recompute anything.
The parents' own motion over time is not composed in: a bone's instances show its motion
relative to its parent, placed where the parent is at the current frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import gpu
import numpy as np
from bpy.app.handlers import persistent
from gpu_extras.batch import batch_for_shader
from mathutils import Matrix

from ..blender import bake, bulk, channels, owners, preview

#: The object property that turns an object's preview on.
OBJECT_PROP = "screwbender_preview"
#: The scene property holding the display settings.
SCENE_PROP = "screwbender_preview"

#: Builtin shader names, the same in Blender 4.2 and 5.x (4.0 dropped the "3D_" prefixes).
LINE_SHADER = "POLYLINE_UNIFORM_COLOR"
FACE_SHADER = "UNIFORM_COLOR"
#: Round points (Blender 4.4+); 4.2 draws square points with FACE_SHADER instead.
POINT_SHADERS = ("POINT_UNIFORM_COLOR", FACE_SHADER)

#: Opacity of the faint solid instances, relative to the instance colour's alpha.
SOLID_ALPHA = 0.25
#: Size of the key origin points, pixels.
KEY_POINT_SIZE = 8.0

#: The previews of all owners.
CACHE = preview.PreviewCache()

_draw_handle = None
#: owner cache key (:func:`preview.cache_key`) -> (batch key, {name: (batch, shader name)})
_gpu_batches: dict[int | tuple[int, str], tuple[tuple, dict]] = {}
#: object session_uid -> counter bumped when the depsgraph reports its geometry changed.
_geometry_generation: dict[int, int] = {}
_last_draw_error = ""


# Settings ---------------------------------------------------------------------------------


def preview_options(scene: bpy.types.Scene) -> preview.PreviewOptions:
    """The preview options of `scene`: Smooth Motion's panel settings (shared) and the
    preview's own display settings."""
    smooth = bake.options_from(scene.screwbender, scene)
    display = getattr(scene, SCENE_PROP)
    return preview.PreviewOptions(
        smooth=smooth,
        instances=display.instances,
        trajectory_points=display.trajectory_points,
        show_raw=display.show_raw,
    )


def smooth_options(scene: bpy.types.Scene) -> bake.Options:
    """Smooth Motion's options as set in the panel of `scene` (what Apply bakes with)."""
    return preview_options(scene).smooth


def current_frame(scene: bpy.types.Scene) -> float:
    """The scene's current frame, with its subframe."""
    return scene.frame_current + scene.frame_subframe


def auto_keying(scene: bpy.types.Scene) -> bool:
    """Whether auto-keying is on in `scene`."""
    return bool(scene.tool_settings.use_keyframe_insert_auto)


def enabled_objects(scene: bpy.types.Scene) -> list[bpy.types.Object]:
    """The objects of `scene` whose preview is on."""
    return [obj for obj in scene.objects if getattr(obj, OBJECT_PROP, False)]


def armature_mode(scene: bpy.types.Scene) -> str:
    """The panel's Armatures option: which owners of a previewed armature are shown."""
    return scene.screwbender.armature


def owners_with_curves(obj: bpy.types.Object, scene: bpy.types.Scene) -> list[tuple[owners.Owner, list]]:
    """The owners the preview of `obj` shows (:func:`preview.preview_owners`), each with its
    own transform F-curves (the object's curves grouped once, not searched per bone)."""
    curves = channels.object_fcurves(obj)
    by_owner = owners.curves_by_owner(curves)
    return [(o, by_owner.get(o.bone, [])) for o in preview.preview_owners(obj, armature_mode(scene), curves, by_owner)]


def previewed_owners(scene: bpy.types.Scene, objects: list[bpy.types.Object] | None = None) -> list[owners.Owner]:
    """Every owner previewed in `scene` (of `objects`, by default those with the preview on)."""
    objects = enabled_objects(scene) if objects is None else objects
    return [o for obj in objects for o, _ in owners_with_curves(obj, scene)]


def moved_unkeyed(scene: bpy.types.Scene, objects: list[bpy.types.Object]) -> list[str]:
    """Names of the owners of `objects` moved at a key frame and not keyed (the preview shows
    a live key)."""
    options = preview_options(scene)
    frame = current_frame(scene)
    auto = auto_keying(scene)
    return [
        owner.name
        for obj in objects
        for owner, curves in owners_with_curves(obj, scene)
        if preview.key_hash(owner, options, frame, auto, curves)[1] is not None
    ]


# Handlers ---------------------------------------------------------------------------------


def is_enabled() -> bool:
    """Whether the overlay's handlers are installed."""
    return _draw_handle is not None


def draw_handle():
    """The current draw handler handle (None when disabled): for tests."""
    return _draw_handle


def enable() -> None:
    """Installs the draw and depsgraph handlers (once)."""
    global _draw_handle
    if _draw_handle is None:
        _draw_handle = bpy.types.SpaceView3D.draw_handler_add(_draw_callback, (), "WINDOW", "POST_VIEW")
    if _on_depsgraph_update not in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.append(_on_depsgraph_update)
    tag_redraw()


def disable() -> None:
    """Removes the draw and depsgraph handlers and drops every cached batch."""
    global _draw_handle
    if _draw_handle is not None:
        bpy.types.SpaceView3D.draw_handler_remove(_draw_handle, "WINDOW")
        _draw_handle = None
    while _on_depsgraph_update in bpy.app.handlers.depsgraph_update_post:
        bpy.app.handlers.depsgraph_update_post.remove(_on_depsgraph_update)
    CACHE.forget()
    _gpu_batches.clear()
    _geometry_generation.clear()
    tag_redraw()


def sync(*_args) -> None:
    """Enables the overlay when any object has its preview on, disables it otherwise."""
    if any(getattr(obj, OBJECT_PROP, False) for obj in bpy.data.objects):
        enable()
    else:
        disable()


def tag_redraw() -> None:
    """Asks every 3D Viewport to redraw (nothing to do without windows)."""
    wm = bpy.context.window_manager
    if wm is None:
        return
    for window in wm.windows:
        for area in window.screen.areas:
            if area.type == "VIEW_3D":
                area.tag_redraw()


@persistent
def _on_depsgraph_update(scene: bpy.types.Scene, depsgraph: bpy.types.Depsgraph) -> None:
    changed = False
    for update in depsgraph.updates:
        if update.is_updated_geometry and isinstance(update.id, bpy.types.Object):
            uid = update.id.original.session_uid
            _geometry_generation[uid] = _geometry_generation.get(uid, 0) + 1
            changed = True
    changed = refresh(scene) or changed
    if changed:
        tag_redraw()
    if not CACHE.entries and not any(getattr(obj, OBJECT_PROP, False) for obj in bpy.data.objects):
        # The last previewed object was deleted. A handler must not remove itself while
        # Blender walks the handler list: disable from a timer instead (UI sessions only).
        if not bpy.app.timers.is_registered(_deferred_sync):
            bpy.app.timers.register(_deferred_sync, first_interval=0.0)


def _deferred_sync() -> None:
    sync()


def refresh(scene: bpy.types.Scene) -> bool:
    """Checks the key hash of every previewed owner of `scene`, recomputing those whose hash
    changed; returns whether any was recomputed. Forgets owners no longer previewed."""
    options = preview_options(scene)
    objects = enabled_objects(scene)
    frame = current_frame(scene)
    auto = auto_keying(scene)
    keep = set()
    memo: dict = {}  # the keys read in this refresh: each curve read once (shared actions too)
    pairs = [pair for obj in objects for pair in owners_with_curves(obj, scene)]
    preview.read_together(pairs, memo)  # every owner's curves in one pass
    for owner, _ in pairs:
        keep.add(preview.cache_key(owner))
    changed = any(recomputed for _, recomputed in CACHE.refresh_many(pairs, options, frame, auto, memo))
    CACHE.forget(keep)
    for uid in [u for u in _gpu_batches if u not in keep]:
        del _gpu_batches[uid]
    return changed


#: :func:`sync` as a handler that survives loading files.
sync_persistent = persistent(sync)


def register() -> None:
    """Installs the handlers that re-sync the overlay after loading a file, undo and redo."""
    for handlers in (bpy.app.handlers.load_post, bpy.app.handlers.undo_post, bpy.app.handlers.redo_post):
        if sync_persistent not in handlers:
            handlers.append(sync_persistent)


def unregister() -> None:
    """Removes every handler of the overlay."""
    disable()
    if bpy.app.timers.is_registered(_deferred_sync):
        bpy.app.timers.unregister(_deferred_sync)
    for handlers in (bpy.app.handlers.load_post, bpy.app.handlers.undo_post, bpy.app.handlers.redo_post):
        while sync_persistent in handlers:
            handlers.remove(sync_persistent)


def our_handlers() -> list[str]:
    """Names of `bpy.app.handlers` lists holding a function of this module: for tests."""
    found = []
    for name in dir(bpy.app.handlers):
        handlers = getattr(bpy.app.handlers, name)
        if isinstance(handlers, list) and any(getattr(f, "__module__", "") == __name__ for f in handlers):
            found.append(name)
    return found


# Drawing ----------------------------------------------------------------------------------


@dataclass
class _Style:
    style: str
    heavy_limit: int
    instance_color: tuple
    key_color: tuple
    trajectory_color: tuple
    raw_color: tuple
    line_width: float
    show_trajectory: bool
    show_keys: bool
    show_raw: bool


def _style(scene: bpy.types.Scene) -> _Style:
    s = getattr(scene, SCENE_PROP)
    return _Style(
        style=s.style,
        heavy_limit=s.heavy_limit,
        instance_color=tuple(s.instance_color),
        key_color=tuple(s.key_color),
        trajectory_color=tuple(s.trajectory_color),
        raw_color=tuple(s.raw_color),
        line_width=s.line_width,
        show_trajectory=s.show_trajectory,
        show_keys=s.show_keys,
        show_raw=s.show_raw,
    )


def parent_space(obj: bpy.types.Object) -> Matrix:
    """The world matrix of the space `matrix_basis` lives in, at the current frame.

    World space without a parent; `parent.matrix_world @ matrix_parent_inverse` under an
    object parent; for bone and vertex parents, the evaluated `matrix_world @ matrix_basis^-1`.
    (Constraints and delta transforms are not drawn.)
    """
    parent = obj.parent
    if parent is None:
        return Matrix.Identity(4)
    if obj.parent_type == "OBJECT":
        return parent.matrix_world @ obj.matrix_parent_inverse
    return obj.matrix_world @ obj.matrix_basis.inverted_safe()


def owner_space(owner: owners.Owner | bpy.types.Object) -> preview.Space:
    """Where the owner's own-space batches land in the world at the current frame.

    An object: :func:`parent_space`. A bone: the armature object's world matrix times
    Blender's own bone transform from the bone's local (`matrix_basis`) space to armature
    space (`Bone.convert_local_to_pose`, with the parent bone's current `PoseBone.matrix`),
    measured on a few probe matrices (:func:`preview.space_from_probes`). Constraints on the
    bone itself are not drawn; its parents' are, as they pose the parents now.
    """
    owner = owners.as_owner(owner)
    if not owner.bone:
        return preview.Space.of_matrix(np.array(parent_space(owner.obj), dtype=np.float64))
    pose_bone = owner.target
    bone = pose_bone.bone
    parent = pose_bone.parent

    def to_pose(matrix: np.ndarray) -> np.ndarray:
        m = Matrix(matrix.tolist())
        if parent is None:
            out = bone.convert_local_to_pose(m, bone.matrix_local)
        else:
            out = bone.convert_local_to_pose(
                m, bone.matrix_local, parent_matrix=parent.matrix, parent_matrix_local=parent.bone.matrix_local
            )
        return np.array(out, dtype=np.float64)

    moved = []
    for axis in range(3):
        m = np.eye(4)
        m[axis, 3] = 1.0
        moved.append(to_pose(m))
    world = np.array(owner.obj.matrix_world, dtype=np.float64)
    return preview.space_from_probes(world, to_pose(np.eye(4)), np.array(moved), to_pose(preview.CYCLE))


def _matrices(collection, name: str) -> np.ndarray:
    """(N, 4, 4) float64 of the 4x4 matrix property `name` of every item of `collection`, in
    one `foreach_get` (Blender stores matrices column by column)."""
    flat = np.empty(16 * len(collection), dtype=np.float32)
    bulk.get(collection, name, flat)
    return flat.reshape(-1, 4, 4).transpose(0, 2, 1).astype(np.float64)


def owner_spaces(obj: bpy.types.Object, shown: list[owners.Owner]) -> list[preview.Space]:
    """:func:`owner_space` of each of `shown` (owners of `obj`), the bones of the armature
    together: a bone that inherits its parent's whole transform (Inherit Rotation, Inherit
    Scale Full, Local Location: Blender's defaults) is in the space
    `A P_parent L_parent^-1 L` (A the armature's world matrix, P the parent's current
    `PoseBone.matrix`, L the rest `Bone.matrix_local`; `A L` for a root bone), read for all
    bones in two `foreach_get` calls; any other bone through :func:`owner_space`."""
    bones = [o for o in shown if o.bone]
    if not bones:
        return [owner_space(o) for o in shown]
    pose, rest = obj.pose.bones, obj.data.bones
    pose_index = {b.name: i for i, b in enumerate(pose)}
    rest_index = {b.name: i for i, b in enumerate(rest)}
    posed = _matrices(pose, "matrix")
    local = _matrices(rest, "matrix_local")
    world = np.array(obj.matrix_world, dtype=np.float64)
    out = []
    for owner in shown:
        data = rest[owner.bone] if owner.bone else None
        if data is None or not (data.use_inherit_rotation and data.inherit_scale == "FULL" and data.use_local_location):
            out.append(owner_space(owner))
            continue
        offset = local[rest_index[owner.bone]]
        if data.parent is not None:
            parent = data.parent.name
            offset = posed[pose_index[parent]] @ np.linalg.solve(local[rest_index[parent]], offset)
        out.append(preview.Space.of_matrix(world @ offset))
    return out


def _geometry_key(owner: owners.Owner, style: _Style) -> tuple:
    obj = owner.obj
    if owner.bone:
        return ("BONE", obj.data.name_full, owner.bone, obj.data.bones[owner.bone].length, style.style)
    data = obj.data
    counts = (len(data.vertices), len(data.edges)) if obj.type == "MESH" else ()
    return (
        obj.type, data.name_full if data is not None else "", counts,
        _geometry_generation.get(obj.session_uid, 0), style.style, style.heavy_limit,
    )


def owner_geometry(owner: owners.Owner, style: _Style) -> preview.Geometry:
    """What one instance of `owner` looks like: the object's shape (:func:`preview.object_geometry`)
    or the bone's (:func:`preview.bone_geometry`, its box for the Bounding Box display)."""
    if owner.bone:
        return preview.bone_geometry(owner.obj.data.bones[owner.bone].length, box=style.style == "BOX")
    heavy = 0 if style.style == "BOX" else style.heavy_limit
    return preview.object_geometry(owner.obj, heavy)


def world_batches(batches: preview.PreviewBatches, space: preview.Space) -> preview.PreviewBatches:
    """`batches` mapped into the world through `space` (for a space that is not one matrix)."""
    raw = batches.raw_instances is not None
    return preview.PreviewBatches(
        instance_times=batches.instance_times,
        instances=space.apply(batches.instances),
        trajectory_times=batches.trajectory_times,
        trajectory=space.apply_points(batches.trajectory),
        key_frames=batches.key_frames,
        keys=space.apply(batches.keys),
        raw_instances=space.apply(batches.raw_instances) if raw else None,
        raw_trajectory=space.apply_points(batches.raw_trajectory) if raw else None,
    )


def _point_shader() -> gpu.types.GPUShader:
    for name in POINT_SHADERS:
        try:
            return gpu.shader.from_builtin(name)
        except ValueError:  # not a builtin shader of this Blender
            continue
    raise ValueError(f"none of the shaders {POINT_SHADERS} is built in")


def _build(b: preview.PreviewBatches, geometry: preview.Geometry, style: _Style) -> dict:
    """GPU batches for one owner: {name: (batch, shader name)}."""
    out = {}
    line_shader = gpu.shader.from_builtin(LINE_SHADER)
    face_shader = gpu.shader.from_builtin(FACE_SHADER)
    point_shader = _point_shader()
    v = len(geometry.points)

    def lines(matrices: np.ndarray):
        return batch_for_shader(
            line_shader, "LINES", {"pos": preview.instance_vertices(geometry.points, matrices)},
            indices=preview.instance_indices(geometry.edges, v, len(matrices)),
        )

    if style.style == "SOLID" and len(geometry.tris):
        out["instances_solid"] = (
            batch_for_shader(
                face_shader, "TRIS", {"pos": preview.instance_vertices(geometry.points, b.instances)},
                indices=preview.instance_indices(geometry.tris, v, len(b.instances)),
            ),
            FACE_SHADER,
        )
    else:
        out["instances"] = (lines(b.instances), LINE_SHADER)
    out["keys"] = (lines(b.keys), LINE_SHADER)
    out["key_points"] = (
        batch_for_shader(point_shader, "POINTS", {"pos": b.keys[:, :3, 3].astype(np.float32)}),
        "points",
    )
    out["trajectory"] = (
        batch_for_shader(line_shader, "LINE_STRIP", {"pos": b.trajectory.astype(np.float32)}), LINE_SHADER
    )
    if b.raw_instances is not None:
        out["raw"] = (lines(b.raw_instances), LINE_SHADER)
        out["raw_trajectory"] = (
            batch_for_shader(line_shader, "LINE_STRIP", {"pos": b.raw_trajectory.astype(np.float32)}), LINE_SHADER
        )
    return out


def _batches_for(
    owner: owners.Owner, entry: preview.PreviewEntry, style: _Style, space: preview.Space | None = None
) -> dict:
    """The GPU batches of `owner`'s preview: in its own space, or with `space` (one that is
    not a single matrix) mapped into the world, rebuilt when that space changes."""
    key = (entry.digest, _geometry_key(owner, style), space.key() if space is not None else b"")
    cache_key = preview.cache_key(owner)
    cached = _gpu_batches.get(cache_key)
    if cached is not None and cached[0] == key:
        return cached[1]
    batches = entry.batches if space is None else world_batches(entry.batches, space)
    built = _build(batches, owner_geometry(owner, style), style)
    _gpu_batches[cache_key] = (key, built)
    return built


def _draw_one(batches: dict, style: _Style, viewport_size: tuple[float, float]) -> None:
    line = gpu.shader.from_builtin(LINE_SHADER)
    face = gpu.shader.from_builtin(FACE_SHADER)
    point = _point_shader()

    def draw_lines(name: str, color: tuple, width: float) -> None:
        if name not in batches:
            return
        line.bind()
        line.uniform_float("viewportSize", viewport_size)
        line.uniform_float("lineWidth", width)
        line.uniform_float("color", color)
        batches[name][0].draw(line)

    if "instances_solid" in batches:
        face.bind()
        r, g, bl, a = style.instance_color
        face.uniform_float("color", (r, g, bl, a * SOLID_ALPHA))
        batches["instances_solid"][0].draw(face)
    draw_lines("instances", style.instance_color, style.line_width)
    if style.show_raw:
        draw_lines("raw", style.raw_color, style.line_width)
        draw_lines("raw_trajectory", style.raw_color, style.line_width * 1.5)
    if style.show_trajectory:
        draw_lines("trajectory", style.trajectory_color, style.line_width * 2.0)
    if style.show_keys:
        draw_lines("keys", style.key_color, style.line_width * 2.0)
        point.bind()
        point.uniform_float("color", style.key_color)
        gpu.state.point_size_set(KEY_POINT_SIZE)
        batches["key_points"][0].draw(point)


def draw_previews(
    scene: bpy.types.Scene, view_layer: bpy.types.ViewLayer, viewport_size: tuple[float, float]
) -> int:
    """Draws the preview of every previewed, visible object of `scene` (for an armature, of
    its previewed bones and/or itself) with the current GPU matrices; returns how many
    owners were drawn."""
    options = preview_options(scene)
    style = _style(scene)
    frame = current_frame(scene)
    auto = auto_keying(scene)
    drawn = 0
    gpu.state.blend_set("ALPHA")
    gpu.state.depth_test_set("LESS_EQUAL")
    gpu.state.depth_mask_set(False)
    try:
        for obj in enabled_objects(scene):
            if not obj.visible_get(view_layer=view_layer):
                continue
            shown = owners_with_curves(obj, scene)
            entries = [CACHE.refresh(owner, options, frame, auto, curves)[0] for owner, curves in shown]
            drawable = [(owner, entry) for (owner, _), entry in zip(shown, entries) if entry.batches is not None]
            spaces = owner_spaces(obj, [owner for owner, _ in drawable])
            for (owner, entry), space in zip(drawable, spaces):
                matrix = space.matrix
                batches = _batches_for(owner, entry, style, None if matrix is not None else space)
                with gpu.matrix.push_pop():
                    if matrix is not None:
                        gpu.matrix.multiply_matrix(Matrix(matrix.tolist()))
                    _draw_one(batches, style, viewport_size)
                drawn += 1
    finally:
        gpu.state.point_size_set(1.0)
        gpu.state.depth_mask_set(True)
        gpu.state.depth_test_set("NONE")
        gpu.state.blend_set("NONE")
    return drawn


def _draw_callback() -> None:
    global _last_draw_error
    context = bpy.context
    try:
        viewport = gpu.state.viewport_get()
        draw_previews(context.scene, context.view_layer, (float(viewport[2]), float(viewport[3])))
        _last_draw_error = ""
    except Exception as err:  # never break the viewport; say it once
        message = f"ScrewBender preview: {type(err).__name__}: {err}"
        if message != _last_draw_error:
            print(message)
            _last_draw_error = message


def gpu_unavailable_reason() -> str:
    """Why offscreen drawing cannot work here ("" when it can)."""
    try:
        offscreen = gpu.types.GPUOffScreen(4, 4)
    except Exception as err:
        return f"{type(err).__name__}: {err}"
    offscreen.free()
    return ""


def render_offscreen(
    scene: bpy.types.Scene,
    view_layer: bpy.types.ViewLayer,
    view_matrix: Matrix,
    projection_matrix: Matrix,
    width: int,
    height: int,
    background: tuple = (1.0, 1.0, 1.0, 1.0),
) -> tuple[np.ndarray, int]:
    """The overlay drawn into a `gpu.types.GPUOffScreen`: (height, width, 4) float32 RGBA,
    bottom row first, and the number of objects drawn."""
    offscreen = gpu.types.GPUOffScreen(width, height)
    try:
        with offscreen.bind():
            framebuffer = gpu.state.active_framebuffer_get()
            framebuffer.clear(color=background, depth=1.0)
            with gpu.matrix.push_pop(), gpu.matrix.push_pop_projection():
                gpu.matrix.load_matrix(view_matrix)
                gpu.matrix.load_projection_matrix(projection_matrix)
                drawn = draw_previews(scene, view_layer, (float(width), float(height)))
            buffer = framebuffer.read_color(0, 0, width, height, 4, 0, "FLOAT")
            buffer.dimensions = width * height * 4
            pixels = np.array(buffer, dtype=np.float32).reshape(height, width, 4)
    finally:
        offscreen.free()
    return pixels, drawn
