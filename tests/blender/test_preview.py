"""Live stroboscopic preview (issue 8): batches, live update, handlers, offscreen drawing,
scene data untouched, Apply Preview, Insert Key on Motion.

References are independent of the add-on's own reading: key poses are composed from the
F-curves' key values with scipy (bake_helpers.baked_matrices) and sampled with
`polyscrew.sample` directly.
"""

from __future__ import annotations

import math
import re

import bpy
import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

from bake_helpers import baked_matrices, channel, fcurves, key_poses, new_object, rigid, select_only, snapshot_action
from conftest import ADDON, addon_module

FRAMES = [1.0, 7.0, 20.0, 26.0, 41.0, 61.0]


def path_poses(n: int = len(FRAMES)) -> np.ndarray:
    """A tumbling path through space (rigid poses)."""
    out = []
    for i in range(n):
        rot = Rotation.from_euler("xyz", [0.5 * i, 0.3 * math.sin(i), 0.2 * i]).as_matrix()
        out.append(rigid([1.5 * i, 2.0 * math.sin(0.9 * i), 0.4 * i * i], rot)[0])
    return np.array(out)


def keyed_object(name: str = "Body", mode: str = "XYZ", scale: bool = False) -> bpy.types.Object:
    obj = new_object(name, mode=mode)
    scales = np.array([[1.0 + 0.1 * i, 1.0, 1.0 / (1.0 + 0.05 * i)] for i in range(len(FRAMES))]) if scale else None
    key_poses(obj, FRAMES, path_poses(), scales)
    scene = bpy.context.scene
    scene.frame_set(scene.frame_current)  # the object shows its animation, as after keying in the UI
    return obj


def set_smooth(scene, scheme="jarek", levels=3, timing="smooth") -> None:
    scene.screwbender.scheme = scheme
    scene.screwbender.levels = levels
    scene.screwbender.timing = timing
    scene.screwbender.range_mode = "KEYS"


@pytest.fixture
def pd():
    """The overlay module; the overlay is left disabled after each test."""
    module = addon_module("ops.preview_draw")
    yield module
    for obj in bpy.data.objects:
        obj.screwbender_preview = False
    module.sync()


def entry_of(pd, obj):
    pd.refresh(bpy.context.scene)
    entry = pd.CACHE.entries[obj.session_uid]
    assert entry.error == "", entry.error
    return entry.batches


def reference(obj, times, scheme, levels, timing, with_scale=False):
    """(rigid poses, scales or None) sampled with polyscrew from the F-curves' key values."""
    frames, matrices = baked_matrices(obj)
    poses = polyscrew.sample(matrices, frames, times, scheme=scheme, levels=levels, timing=timing)
    scales = None
    if with_scale:
        _, key_scales = channel(obj, "scale", 3)
        scales = np.exp(
            polyscrew.sample_vectors(np.log(key_scales), frames, times, scheme=scheme, levels=levels, timing=timing)
        )
    return poses, scales


# Batches --------------------------------------------------------------------------------


@pytest.mark.parametrize("scheme,levels,timing", [("jarek", 3, "smooth"), ("four_point", 5, "linear"), ("bspline", 4, "smooth")])
def test_batches_equal_polyscrew_sample(pd, scheme, levels, timing):
    scene = bpy.context.scene
    obj = keyed_object(scale=True)
    set_smooth(scene, scheme, levels, timing)
    scene.screwbender_preview.instances = 13
    scene.screwbender_preview.trajectory_points = 150
    scene.screwbender_preview.show_raw = True
    obj.screwbender_preview = True
    b = entry_of(pd, obj)

    instance_times = np.linspace(FRAMES[0], FRAMES[-1], 13)
    trajectory_times = np.linspace(FRAMES[0], FRAMES[-1], 150)
    np.testing.assert_allclose(b.instance_times, instance_times, rtol=0, atol=1e-12)
    np.testing.assert_allclose(b.trajectory_times, trajectory_times, rtol=0, atol=1e-12)

    poses, scales = reference(obj, instance_times, scheme, levels, timing, with_scale=True)
    expected = poses.copy()
    expected[:, :3, :3] *= scales[:, None, :]
    np.testing.assert_allclose(b.instances, expected, rtol=0, atol=1e-9)
    traj, _ = reference(obj, trajectory_times, scheme, levels, timing)
    np.testing.assert_allclose(b.trajectory, traj[:, :3, 3], rtol=0, atol=1e-9)

    frames, key_matrices = baked_matrices(obj, with_scale=True)
    np.testing.assert_array_equal(b.key_frames, frames)
    np.testing.assert_allclose(b.keys, key_matrices, rtol=0, atol=1e-9)

    raw, _ = reference(obj, instance_times, scheme, 0, "linear")
    np.testing.assert_allclose(b.raw_instances[:, :3, 3], raw[:, :3, 3], rtol=0, atol=1e-9)
    raw_traj, _ = reference(obj, trajectory_times, scheme, 0, "linear")
    np.testing.assert_allclose(b.raw_trajectory, raw_traj[:, :3, 3], rtol=0, atol=1e-9)


@pytest.mark.parametrize("closed", [False, True])
def test_preview_sampler_is_the_bakes(sb, closed):
    """bake.sample_poses (preview, Insert Key) and bake.sample_channels (Smooth Motion) give
    the same numbers, bit for bit."""
    obj = keyed_object(scale=True)
    if closed:
        for fc in fcurves(obj):
            fc.modifiers.new("CYCLES")
    options = sb.bake.Options(scheme="jarek", levels=4, timing="smooth", step=0.5)
    motion = sb.keys.read(obj, options.closed)
    assert motion.closed == closed
    baked = sb.bake.sample_channels(obj, motion, options)
    poses, scales = sb.bake.sample_poses(motion, baked.frames, options)
    np.testing.assert_array_equal(baked.values["location"], poses[:, :3, 3])
    np.testing.assert_array_equal(baked.values["scale"], scales)


def test_cycle_instances_leave_out_the_closing_pose(pd):
    scene = bpy.context.scene
    obj = new_object("Cycle")
    poses = path_poses(5)
    poses[-1] = poses[0]
    key_poses(obj, [1, 11, 21, 31, 41], poses)
    for fc in fcurves(obj):
        fc.modifiers.new("CYCLES")
    set_smooth(scene, "bspline", 4, "linear")
    scene.screwbender_preview.instances = 8
    obj.screwbender_preview = True
    b = entry_of(pd, obj)
    np.testing.assert_allclose(b.instance_times, 1 + 40 * np.arange(8) / 8, atol=1e-12)
    frames, key_matrices = baked_matrices(obj)
    expected = polyscrew.sample(
        key_matrices[:-1], frames[:-1], b.instance_times, scheme="bspline", levels=4, closed=True, period=40.0,
        timing="linear",
    )
    np.testing.assert_allclose(b.instances, expected, atol=1e-9)


def test_unpreviewable_keys_give_a_message_not_a_crash(pd):
    obj = new_object("Single")
    key_poses(obj, [5], path_poses(1))
    obj.screwbender_preview = True
    pd.refresh(bpy.context.scene)
    entry = pd.CACHE.entries[obj.session_uid]
    assert entry.batches is None and "only one key frame" in entry.error


def test_instance_geometry_wireframe_and_bounding_box(pd):
    preview = addon_module("blender.preview")
    obj = keyed_object()
    matrices = entry_of_enabled(pd, obj).instances
    mesh_points = np.array([v.co for v in obj.data.vertices])
    geometry = preview.object_geometry(obj, heavy_limit=100)
    assert geometry.kind == "MESH" and len(geometry.edges) == len(obj.data.edges)
    placed = preview.instance_vertices(geometry.points, matrices).reshape(len(matrices), -1, 3)
    expected = np.einsum("nij,vj->nvi", matrices[:, :3, :3], mesh_points) + matrices[:, None, :3, 3]
    np.testing.assert_allclose(placed, expected, rtol=0, atol=1e-5 * (1 + np.abs(expected).max()))
    indices = preview.instance_indices(geometry.edges, len(geometry.points), len(matrices))
    assert indices.shape == (len(matrices) * len(geometry.edges), 2) and indices.max() == placed.size // 3 - 1
    # a mesh above the vertex limit is drawn as its bounding box
    box = preview.object_geometry(obj, heavy_limit=3)
    assert box.kind == "BOX" and box.edges.shape == (12, 2) and box.tris.shape == (12, 3)
    np.testing.assert_allclose(box.points.min(axis=0), mesh_points.min(axis=0))
    np.testing.assert_allclose(box.points.max(axis=0), mesh_points.max(axis=0))
    lengths = np.linalg.norm(box.points[box.edges[:, 0]] - box.points[box.edges[:, 1]], axis=1)
    np.testing.assert_allclose(np.sort(lengths), np.repeat(np.sort(np.ptp(mesh_points, axis=0)), 4), rtol=1e-6)
    # an empty is drawn as its axes
    empty = bpy.data.objects.new("Empty", None)
    bpy.context.scene.collection.objects.link(empty)
    assert preview.object_geometry(empty, heavy_limit=100).kind == "AXES"


def entry_of_enabled(pd, obj):
    obj.screwbender_preview = True
    return entry_of(pd, obj)


# Live update ----------------------------------------------------------------------------


def test_editing_a_key_recomputes_through_the_depsgraph_handler(pd):
    scene = bpy.context.scene
    set_smooth(scene, "four_point", 4, "smooth")
    body = keyed_object("Body")
    other = keyed_object("Other")
    bystander = keyed_object("Bystander")  # preview off
    body.screwbender_preview = True
    other.screwbender_preview = True
    bpy.context.view_layer.update()
    count = dict(pd.CACHE.recomputed)
    before = entry_of(pd, body).instances.copy()

    # nothing changed: the handler only checks hashes
    bpy.context.view_layer.update()
    scene.frame_set(30)
    assert pd.CACHE.recomputed == count

    # a key of Body edited as in the Graph Editor: only Body recomputes, from the new keys
    curve = next(fc for fc in fcurves(body) if fc.data_path == "location" and fc.array_index == 2)
    curve.keyframe_points[3].co[1] += 2.0
    curve.keyframe_points[3].handle_left[1] += 2.0
    curve.keyframe_points[3].handle_right[1] += 2.0
    bpy.context.view_layer.update()
    assert pd.CACHE.recomputed["Body"] == count["Body"] + 1
    assert pd.CACHE.recomputed["Other"] == count["Other"]
    after = pd.CACHE.entries[body.session_uid].batches
    assert np.abs(after.instances - before).max() > 0.1
    poses, _ = reference(body, after.instance_times, "four_point", 4, "smooth")
    np.testing.assert_allclose(after.instances, poses, atol=1e-9)

    # editing and keying an unrelated object does not recompute Body
    bystander.location = (5.0, 5.0, 5.0)
    bystander.keyframe_insert("location", frame=70)
    other_curve = fcurves(other)[0]
    other_curve.keyframe_points[1].co[1] += 1.0
    bpy.context.view_layer.update()
    assert pd.CACHE.recomputed["Body"] == count["Body"] + 1
    assert pd.CACHE.recomputed["Other"] == count["Other"] + 1

    # a new key (what auto-keying does when the object is moved) recomputes Body
    body.location = (0.0, 0.0, 9.0)
    body.keyframe_insert("location", frame=33)
    bpy.context.view_layer.update()
    assert pd.CACHE.recomputed["Body"] == count["Body"] + 2
    # interpolation and easing parameters decide values between keys: they are hashed too
    point = curve.keyframe_points[1]
    point.interpolation = "ELASTIC"
    bpy.context.view_layer.update()
    assert pd.CACHE.recomputed["Body"] == count["Body"] + 3
    point.amplitude += 0.5
    bpy.context.view_layer.update()
    assert pd.CACHE.recomputed["Body"] == count["Body"] + 4
    count["Body"] += 2
    # a scheme change recomputes both previewed objects, and nothing else. (A scene setting
    # does not trigger a depsgraph update; the panel redraws the viewport, and every redraw
    # starts with this same hash check.)
    scene.screwbender.scheme = "bspline"
    assert pd.refresh(scene)
    assert pd.CACHE.recomputed["Body"] == count["Body"] + 3
    assert pd.CACHE.recomputed["Other"] == count["Other"] + 2
    assert "Bystander" not in pd.CACHE.recomputed


def test_moving_the_object_at_a_key_frame_previews_the_moved_key(pd):
    """While the user moves a key pose (before auto-keying writes it), the preview shows the
    motion with the object's current pose as that key; playback recomputes nothing."""
    scene = bpy.context.scene
    set_smooth(scene, "four_point", 3, "smooth")
    obj = keyed_object()
    obj.screwbender_preview = True
    scene.frame_set(20)  # the third key
    original = entry_of(pd, obj).instances.copy()
    count = pd.CACHE.recomputed["Body"]
    for frame in (19, 20, 21, 26, 7, 20):
        scene.frame_set(frame)
        bpy.context.view_layer.update()
    assert pd.CACHE.recomputed["Body"] == count
    action_before = snapshot_action(obj.animation_data.action)

    obj.location = (4.0, -1.0, 3.0)
    obj.rotation_euler = (0.3, -0.4, 1.1)
    bpy.context.view_layer.update()
    assert pd.CACHE.recomputed["Body"] == count + 1
    live = pd.CACHE.entries[obj.session_uid].batches
    frames, key_matrices = baked_matrices(obj)
    key_matrices[2] = rigid(
        np.array(obj.location), Rotation.from_euler("xyz", np.array(obj.rotation_euler)).as_matrix()
    )[0]
    expected = polyscrew.sample(key_matrices, frames, live.instance_times, scheme="four_point", levels=3, timing="smooth")
    np.testing.assert_allclose(live.instances, expected, atol=1e-9)
    np.testing.assert_allclose(live.keys[2], key_matrices[2], atol=1e-9)
    assert np.abs(live.instances - original).max() > 0.5
    assert snapshot_action(obj.animation_data.action) == action_before  # nothing keyed

    # Apply refuses to bake the keys while the preview shows an unkeyed pose
    with pytest.raises(RuntimeError, match="moved at a key frame but not keyed"):
        bpy.ops.screwbender.preview_apply()
    assert snapshot_action(obj.animation_data.action) == action_before

    # auto-keying the pose: the keyed motion is the one that was previewed (to float32)
    obj.keyframe_insert("location", frame=20)
    obj.keyframe_insert("rotation_euler", frame=20)
    bpy.context.view_layer.update()
    keyed = pd.CACHE.entries[obj.session_uid].batches
    np.testing.assert_allclose(keyed.instances, live.instances, atol=1e-5)
    # cancelling the move instead (frame re-evaluated) goes back to the keys' motion
    obj.location = (8.0, 8.0, 8.0)
    bpy.context.view_layer.update()
    assert pd.CACHE.entries[obj.session_uid].batches is not keyed
    scene.frame_set(20)  # a frame change fires no depsgraph update; the redraw's hash check sees it
    np.testing.assert_allclose(entry_of(pd, obj).instances, keyed.instances, atol=1e-12)


def test_with_auto_keying_moving_between_keys_previews_the_new_key(pd):
    scene = bpy.context.scene
    set_smooth(scene, "jarek", 3, "smooth")
    obj = keyed_object()
    obj.screwbender_preview = True
    scene.frame_set(33)  # between the keys at 26 and 41
    original = entry_of(pd, obj).instances.copy()
    obj.location = (2.0, 6.0, 1.0)
    bpy.context.view_layer.update()
    # auto-keying off: a move between keys is not a key; nothing changes
    np.testing.assert_array_equal(entry_of(pd, obj).instances, original)
    scene.tool_settings.use_keyframe_insert_auto = True
    bpy.context.view_layer.update()
    live = entry_of(pd, obj)
    frames, key_matrices = baked_matrices(obj)
    assert list(live.key_frames) == sorted(list(frames) + [33.0])
    current = rigid(np.array(obj.location), Rotation.from_euler("xyz", np.array(obj.rotation_euler)).as_matrix())
    expected = polyscrew.sample(
        np.insert(key_matrices, 4, current[0], axis=0), np.insert(frames, 4, 33.0), live.instance_times,
        scheme="jarek", levels=3, timing="smooth",
    )
    np.testing.assert_allclose(live.instances, expected, atol=1e-9)
    # what auto-keying writes on confirm is what was previewed
    obj.keyframe_insert("location", frame=33)
    obj.keyframe_insert("rotation_euler", frame=33)
    bpy.context.view_layer.update()
    np.testing.assert_allclose(entry_of(pd, obj).instances, live.instances, atol=1e-5)


def test_drawn_in_the_parents_space_without_recomputing(pd):
    """Batches are in the parent's space; drawn under the parent's world matrix they land on
    the object's world poses as Blender evaluates them, and moving the parent recomputes nothing."""
    scene = bpy.context.scene
    set_smooth(scene, "four_point", 3, "smooth")
    parent = bpy.data.objects.new("Parent", None)
    scene.collection.objects.link(parent)
    parent.location = (10.0, -3.0, 2.0)
    parent.rotation_euler = (0.4, 0.0, 1.2)
    parent.scale = (2.0, 2.0, 2.0)
    obj = keyed_object()
    obj.parent = parent
    obj.screwbender_preview = True
    bpy.context.view_layer.update()
    b = entry_of(pd, obj)
    count = pd.CACHE.recomputed["Body"]
    for i, frame in enumerate(FRAMES):
        scene.frame_set(int(frame))
        world = np.array(pd.parent_space(obj)) @ b.keys[i]
        np.testing.assert_allclose(world, np.array(obj.matrix_world), atol=1e-5)
    parent.location = (0.0, 5.0, 0.0)
    bpy.context.view_layer.update()
    pd.refresh(scene)
    assert pd.CACHE.recomputed["Body"] == count
    np.testing.assert_allclose(np.array(pd.parent_space(obj))[:3, 3], (0.0, 5.0, 0.0), atol=1e-6)


# Handlers -------------------------------------------------------------------------------


def test_enabling_and_disabling_leaves_no_handler_behind(pd):
    persistent = ["load_post", "redo_post", "undo_post"]  # re-sync after load/undo, while the add-on is on
    assert not pd.is_enabled() and pd.our_handlers() == persistent
    a = keyed_object("A")
    b = keyed_object("B")
    a.screwbender_preview = True
    handle = pd.draw_handle()
    assert handle is not None
    assert pd.our_handlers() == ["depsgraph_update_post"] + persistent
    b.screwbender_preview = True
    assert pd.draw_handle() is handle  # one handler for all objects
    a.screwbender_preview = False
    assert pd.is_enabled()
    b.screwbender_preview = False
    assert not pd.is_enabled() and pd.our_handlers() == persistent
    with pytest.raises(ValueError):  # Blender itself says the draw handler is gone
        bpy.types.SpaceView3D.draw_handler_remove(handle, "WINDOW")
    assert pd.CACHE.entries == {}

    # toggled many times: still nothing left behind
    for _ in range(5):
        a.screwbender_preview = True
        a.screwbender_preview = False
    assert not pd.is_enabled() and pd.our_handlers() == persistent

    # deleting the last previewed object: the depsgraph handler schedules the clean-up on a
    # timer (a handler must not remove itself mid-walk); timers do not run in background
    # mode, so the timer's call is made here
    doomed = keyed_object("Doomed")
    doomed.screwbender_preview = True
    bpy.context.view_layer.update()
    bpy.data.objects.remove(doomed)
    bpy.context.view_layer.update()
    assert bpy.app.timers.is_registered(pd._deferred_sync)
    bpy.app.timers.unregister(pd._deferred_sync)
    pd._deferred_sync()
    assert not pd.is_enabled() and pd.our_handlers() == persistent

    # disabling the add-on with the preview on removes every handler
    a.screwbender_preview = True
    handle = pd.draw_handle()
    bpy.ops.preferences.addon_disable(module=ADDON)
    try:
        assert pd.draw_handle() is None and pd.our_handlers() == []
        with pytest.raises(ValueError):
            bpy.types.SpaceView3D.draw_handler_remove(handle, "WINDOW")
    finally:
        bpy.ops.preferences.addon_enable(module=ADDON)


# Offscreen drawing ----------------------------------------------------------------------


def ensure_gpu(pd) -> str:
    """Makes the `gpu` module usable in background mode if this Blender can: a tiny Workbench
    render creates Blender's GPU context (bpy wheels refuse gpu calls before that). Returns
    why offscreen drawing is impossible ("" when possible)."""
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
        return f"{reason}; a Workbench render to create a GPU context failed: {err}"
    finally:
        bpy.data.scenes.remove(scene)
    later = pd.gpu_unavailable_reason()
    return f"{reason}; still after a Workbench render: {later}" if later else ""


def ortho_view(center, size: float):
    """View and projection matrices looking down -Z at `center`, `size` units across."""
    from mathutils import Matrix

    view = Matrix.Translation((-center[0], -center[1], -center[2] - 50.0))
    half = size / 2
    projection = Matrix(
        ((1 / half, 0, 0, 0), (0, 1 / half, 0, 0), (0, 0, -1 / 100.0, 0), (0, 0, 0, 1))
    )
    return view, projection


def test_offscreen_drawing(pd):
    reason = ensure_gpu(pd)
    if reason:
        pytest.skip(f"no GPU drawing in this Blender: {reason}")
    scene = bpy.context.scene
    set_smooth(scene, "jarek", 4, "smooth")
    settings = scene.screwbender_preview
    settings.instances = 10
    settings.instance_color = (0.0, 0.0, 1.0, 1.0)
    settings.key_color = (1.0, 0.0, 0.0, 1.0)
    settings.trajectory_color = (0.0, 1.0, 0.0, 1.0)
    obj = keyed_object()
    obj.screwbender_preview = True
    b = entry_of(pd, obj)
    pts = np.concatenate([b.trajectory, b.keys[:, :3, 3]])
    center = (pts.min(axis=0) + pts.max(axis=0)) / 2
    size = float(np.ptp(pts[:, :2], axis=0).max()) * 1.3 + 2.0
    view, projection = ortho_view(center, size)
    width = height = 200
    pixels, drawn = pd.render_offscreen(scene, bpy.context.view_layer, view, projection, width, height)
    assert drawn == 1 and pixels.shape == (height, width, 4)
    rgb = pixels[..., :3]
    blue = (rgb[..., 2] > 0.5) & (rgb[..., 0] < 0.5) & (rgb[..., 1] < 0.5)
    red = (rgb[..., 0] > 0.5) & (rgb[..., 1] < 0.5) & (rgb[..., 2] < 0.5)
    green = (rgb[..., 1] > 0.5) & (rgb[..., 0] < 0.5) & (rgb[..., 2] < 0.5)
    assert blue.sum() > 50 and red.sum() > 50 and green.sum() > 50, (blue.sum(), red.sum(), green.sum())
    # every key origin lands (within 2 pixels) on a key-coloured pixel where the projection puts it
    for p in b.keys[:, :3, 3]:
        x = (p[0] - center[0]) / size * width + width / 2
        y = (p[1] - center[1]) / size * height + height / 2
        window = red[max(0, int(y) - 2) : int(y) + 3, max(0, int(x) - 2) : int(x) + 3]
        assert window.any(), (p, x, y)
    # the draw handler's own callback (what the viewport calls) draws the same, without error
    import gpu

    offscreen = gpu.types.GPUOffScreen(width, height)
    try:
        with offscreen.bind():
            framebuffer = gpu.state.active_framebuffer_get()
            framebuffer.clear(color=(1.0, 1.0, 1.0, 1.0), depth=1.0)
            with gpu.matrix.push_pop(), gpu.matrix.push_pop_projection():
                gpu.matrix.load_matrix(view)
                gpu.matrix.load_projection_matrix(projection)
                pd._draw_callback()
            buffer = framebuffer.read_color(0, 0, width, height, 4, 0, "FLOAT")
            buffer.dimensions = width * height * 4
            from_callback = np.array(buffer, dtype=np.float32).reshape(height, width, 4)
    finally:
        offscreen.free()
    assert pd._last_draw_error == ""
    np.testing.assert_allclose(from_callback, pixels, atol=1e-6)
    # nothing drawn once the preview is off
    obj.screwbender_preview = False
    pixels, drawn = pd.render_offscreen(scene, bpy.context.view_layer, view, projection, width, height)
    assert drawn == 0 and np.all(pixels[..., :3] > 0.99)


# The preview never changes the scene's data ---------------------------------------------


def object_state(obj) -> dict:
    """Every RNA property value of `obj` (but its own preview switch) and its ID properties."""
    out = {}
    for prop in obj.bl_rna.properties:
        name = prop.identifier
        if name in ("rna_type", "screwbender_preview") or prop.type in ("POINTER", "COLLECTION"):
            continue
        value = getattr(obj, name)
        out[name] = repr(tuple(value) if hasattr(value, "__len__") and not isinstance(value, str) else value)
    out["matrix"] = np.array(obj.matrix_world).tobytes()
    out["id_props"] = repr({k: obj[k] for k in obj.keys() if k != "screwbender_preview"})
    return out


def scene_state() -> dict:
    return {
        "objects": {o.name: object_state(o) for o in bpy.data.objects},
        "actions": {a.name: (a.use_fake_user, a.users, snapshot_action(a)) for a in bpy.data.actions},
        "counts": {kind: len(getattr(bpy.data, kind)) for kind in ("objects", "meshes", "actions", "images", "scenes")},
    }


def test_preview_never_changes_scene_data(pd):
    scene = bpy.context.scene
    set_smooth(scene, "jarek", 4, "smooth")
    obj = keyed_object(scale=True)
    keyed_object("Other")
    scene.frame_set(12)
    start = scene_state()

    obj.screwbender_preview = True
    scene.screwbender_preview.show_raw = True
    for frame in (3, 20, 45):
        scene.frame_set(frame)
    scene.frame_set(12)
    bpy.context.view_layer.update()
    if not ensure_gpu(pd):
        pd.render_offscreen(scene, bpy.context.view_layer, *ortho_view((0, 0, 0), 20.0), 64, 64)
    assert scene_state() == start

    # the user's own edit, with the preview on: exactly the edit, nothing else
    curve = next(fc for fc in fcurves(obj) if fc.data_path == "location" and fc.array_index == 0)
    curve.keyframe_points[2].co[1] += 1.0
    scene.frame_set(12)
    edited = scene_state()
    curve.keyframe_points[2].co[1] -= 1.0
    scene.frame_set(12)
    assert scene_state() == start
    curve.keyframe_points[2].co[1] += 1.0
    bpy.context.view_layer.update()
    pd.refresh(scene)
    scene.frame_set(12)
    assert scene_state() == edited
    assert pd.CACHE.recomputed["Body"] >= 2

    obj.screwbender_preview = False
    assert scene_state() == edited


# Apply ----------------------------------------------------------------------------------


def test_apply_bakes_what_the_preview_shows(pd):
    scene = bpy.context.scene
    set_smooth(scene, "four_point", 4, "smooth")
    scene.screwbender.step = 1.0
    scene.screwbender_preview.instances = 13  # frames 1, 6, ..., 61: on the baked frames
    obj = keyed_object(scale=True)
    twin = keyed_object("Twin", scale=True)  # smoothed with the Smooth Motion operator
    obj.screwbender_preview = True
    b = entry_of(pd, obj)
    shown = b.instances.copy()
    select_only(twin)
    settings = scene.screwbender
    assert bpy.ops.screwbender.smooth(
        scheme=settings.scheme, levels=settings.levels, timing=settings.timing, closed=settings.closed,
        range_mode=settings.range_mode, step=settings.step,
    ) == {"FINISHED"}
    select_only()

    assert bpy.ops.screwbender.preview_apply() == {"FINISHED"}
    assert obj.animation_data.action.name.endswith(".smooth")
    assert not obj.screwbender_preview and not pd.is_enabled()
    frames, baked = baked_matrices(obj, with_scale=True)
    rows = np.searchsorted(frames, b.instance_times)
    np.testing.assert_array_equal(frames[rows], b.instance_times)
    # F-curves hold float32: equal to float32 rounding of what was shown
    np.testing.assert_allclose(baked[rows], shown, rtol=0, atol=2e-5 * (1 + np.abs(shown).max()))
    # and exactly (bit for bit) what Smooth Motion bakes with the same settings
    for curve in fcurves(obj):
        other = next(fc for fc in fcurves(twin) if (fc.data_path, fc.array_index) == (curve.data_path, curve.array_index))
        co = np.empty(2 * len(curve.keyframe_points), dtype=np.float32)
        co_twin = np.empty(2 * len(other.keyframe_points), dtype=np.float32)
        curve.keyframe_points.foreach_get("co", co)
        other.keyframe_points.foreach_get("co", co_twin)
        np.testing.assert_array_equal(co, co_twin)


def select_keys(obj, frames) -> None:
    """Selects the keys at `frames` on every transform curve of `obj`, deselects the others."""
    for curve in fcurves(obj):
        for point in curve.keyframe_points:
            point.select_control_point = any(abs(point.co[0] - f) < 1e-4 for f in frames)


def test_feature_points_method_previews_and_applies_the_feature_motion(pd):
    """With Method = Feature Points the preview shows the feature-point motion (what Apply and
    Smooth Motion bake), follows the key selection (selected keys approximated) and the mesh."""
    scene = bpy.context.scene
    set_smooth(scene, "jarek", 4, "smooth")
    settings = scene.screwbender
    settings.method, settings.approximate, settings.stiffness = "FEATURE", True, 0.5
    scene.screwbender_preview.instances = 13  # frames 1, 6, ..., 61: on the baked frames
    obj = keyed_object()
    select_keys(obj, [20.0, 41.0])
    obj.screwbender_preview = True
    b = entry_of(pd, obj)

    frames, matrices = baked_matrices(obj)
    co = np.array([v.co for v in obj.data.vertices], dtype=np.float64)
    stiffness = np.where(np.isin(frames, [20.0, 41.0]), 0.5, np.inf)
    expected = polyscrew.sample_feature(
        matrices, frames, b.instance_times, levels=4, feature_points=polyscrew.inertia_points(co),
        stiffness=stiffness, timing="smooth",
    )
    np.testing.assert_allclose(b.instances, expected, rtol=0, atol=1e-9)
    screw, _ = reference(obj, b.instance_times, "jarek", 4, "smooth")
    assert np.abs(b.instances - screw).max() > 1e-3  # not the screw method's motion
    shown = b.instances.copy()

    select_keys(obj, [20.0, 26.0, 41.0])  # one more approximated key: a new motion
    changed = entry_of(pd, obj)
    assert np.abs(changed.instances - shown).max() > 1e-4
    select_keys(obj, [20.0, 41.0])
    assert np.array_equal(entry_of(pd, obj).instances, shown)
    obj.data.vertices[3].co.z = 6.0  # another mesh: other inertia points
    assert np.abs(entry_of(pd, obj).instances - shown).max() > 1e-6
    obj.data.vertices[3].co.z = 3.0
    assert np.array_equal(entry_of(pd, obj).instances, shown)

    assert bpy.ops.screwbender.preview_apply() == {"FINISHED"}
    frames, baked = baked_matrices(obj)
    rows = np.searchsorted(frames, b.instance_times)
    np.testing.assert_allclose(baked[rows], shown, rtol=0, atol=2e-5 * (1 + np.abs(shown).max()))


# Insert Key on Motion -------------------------------------------------------------------


def motion_from_curves(obj, times, scheme, levels, timing) -> np.ndarray:
    frames, matrices = baked_matrices(obj)
    return polyscrew.sample(matrices, frames, times, scheme=scheme, levels=levels, timing=timing)


def change(a: np.ndarray, b: np.ndarray) -> tuple[float, float]:
    """Largest origin displacement and rotation angle between two pose sequences (scipy)."""
    move = np.linalg.norm(a[:, :3, 3] - b[:, :3, 3], axis=1).max()
    turn = (Rotation.from_matrix(a[:, :3, :3]).inv() * Rotation.from_matrix(b[:, :3, :3])).magnitude().max()
    return float(move), float(turn)


def insert(obj, frame: float, capfd) -> tuple[float, float]:
    """Runs Insert Key on Motion on `obj` at `frame`; returns the change it reported."""
    scene = bpy.context.scene
    scene.frame_set(int(frame), subframe=frame - int(frame))
    select_only(obj)
    capfd.readouterr()
    assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
    report = capfd.readouterr().out
    found = re.search(r"moved by at most (\S+) \(frame [^)]*\) and turned by at most (\S+) deg", report)
    assert found, report
    return float(found.group(1)), math.radians(float(found.group(2)))


@pytest.mark.parametrize("mode", ["XYZ", "QUATERNION", "AXIS_ANGLE"])
def test_insert_key_on_raw_polyscrew_keeps_the_motion(pd, mode, capfd):
    scene = bpy.context.scene
    set_smooth(scene, "jarek", 0, "linear")
    obj = keyed_object(mode=mode)
    frame = 13.0  # 6/13 of the way from the key at 7 to the key at 20
    times = np.linspace(FRAMES[0], FRAMES[-1], 200)
    before = motion_from_curves(obj, times, "jarek", 0, "linear")
    frames_before, keys_before = baked_matrices(obj)

    # In float64 the split screw is the same motion: the exact pose s(P1, 6/13, P2) as a key.
    exact = polyscrew.interpolate(keys_before[1], keys_before[2], 6.0 / 13.0)
    split = polyscrew.sample(
        np.insert(keys_before, 2, exact, axis=0), np.insert(frames_before, 2, frame), times,
        scheme="jarek", levels=0, timing="linear",
    )
    split_change = np.abs(split - before).max()
    assert split_change < 1e-9

    reported = insert(obj, frame, capfd)
    frames_after, keys_after = baked_matrices(obj)
    np.testing.assert_array_equal(frames_after, np.insert(frames_before, 2, frame))
    np.testing.assert_array_equal(np.delete(keys_after, 2, axis=0), keys_before)  # old keys untouched
    # F-curves store float32: the key read back is the exact pose rounded to float32 channels
    rounding = np.abs(keys_after[2] - exact).max()
    assert rounding < 1e-6
    after = motion_from_curves(obj, times, "jarek", 0, "linear")
    moved = np.abs(after - before).max()
    # ... and the motion moves by no more than that rounding, only between the neighbouring keys
    assert moved <= 2.0 * rounding + 1e-12, (moved, rounding)
    outside = (times <= FRAMES[1]) | (times >= FRAMES[2])
    assert np.abs(after[outside] - before[outside]).max() < 1e-12
    with capfd.disabled():
        print(
            f"\n{mode}: float64 split {split_change:.1e}; float32 key rounding {rounding:.2e}, motion change "
            f"at 200 frames {moved:.2e}, outside the split span {np.abs(after[outside] - before[outside]).max():.1e}, "
            f"reported {reported[0]:.2e} / {reported[1]:.2e} rad"
        )
    assert reported[0] <= 2.0 * rounding + 1e-12 and reported[1] < 1e-5


@pytest.mark.parametrize("timing", ["smooth", "linear"])
def test_insert_key_four_point_hits_the_key_and_reports_the_change(pd, timing, capfd):
    scene = bpy.context.scene
    set_smooth(scene, "four_point", 4, timing)
    obj = keyed_object(mode="QUATERNION")
    twin = keyed_object("Twin", mode="QUATERNION")
    frame = 30.5
    times = np.union1d(np.arange(1.0, 62.0), [frame])  # the frames the operator checks
    before = motion_from_curves(obj, times, "four_point", 4, timing)
    with addon_module("blender.transaction").atomic() as t:
        result = addon_module("blender.insert_key").insert_key(obj, frame, pd.smooth_options(scene), t)
    np.testing.assert_array_equal(result.checked_frames, times)
    frames_after, keys_after = baked_matrices(obj)
    new_key = keys_after[list(frames_after).index(frame)]
    after = motion_from_curves(obj, times, "four_point", 4, timing)
    # the new key is hit exactly by the refined motion
    np.testing.assert_allclose(after[times == frame][0], new_key, rtol=0, atol=1e-12)
    # it holds the old motion's pose there, to float32 rounding
    np.testing.assert_allclose(new_key, before[times == frame][0], rtol=0, atol=2e-6)
    # the motion changed slightly, and the reported change is the measured one
    measured = change(before, after)
    assert 1e-6 < measured[0] < 0.5, measured
    assert result.max_translation == pytest.approx(measured[0], rel=1e-9, abs=1e-12)
    assert result.max_angle == pytest.approx(measured[1], rel=1e-6, abs=1e-9)
    # the operator (on an identical twin) reports the same figures
    reported = insert(twin, frame, capfd)
    assert reported[0] == pytest.approx(result.max_translation, rel=5e-3)
    assert reported[1] == pytest.approx(result.max_angle, rel=5e-3)
    with capfd.disabled():
        print(f"\n4-point 4 levels, {timing} timing: moved {measured[0]:.4g}, turned {math.degrees(measured[1]):.4g} deg")
