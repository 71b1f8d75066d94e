# SPDX-License-Identifier: GPL-3.0-or-later
"""Swept regions and clearance: Blender data in and out of `polyscrew.sweep`.

The pipeline, per object (Rossignac-Kim, "Swept volumes"):

1. :func:`body_mesh` reads the evaluated mesh (modifiers applied) as triangles in the
   object's local frame, scaled by the object's (constant) world scale;
2. :func:`world_poses` samples the object's rigid world motion: at every key of the action
   made by Smooth Motion where there is one, otherwise at every frame of the scene's range;
   a mesh carried by a bone (:func:`bone_driver`: parented to it, or deformed rigidly by it
   through an Armature modifier) moves with the bone's world motion;
3. `polyscrew.sweep` builds the swept mesh (each pair of samples is one screw), each screw in
   the fewest steps that keep the swept surfaces within a tolerance of the exact ones (by
   default 0.2 % of the body's bounding radius);
   or, with Closed Volume, `polyscrew.sweep_closed` builds the region's boundary as a closed,
   consistently oriented, self-intersection-free mesh (slower: seconds, many more triangles);
4. :func:`create_object` writes it into a new object of the "Swept Regions" collection.

Steps 1 to 3 run for every object before anything is created, so a refusal leaves the scene
as it was. :func:`clearance` measures a swept region against another object with
`mathutils.bvhtree.BVHTree`.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass

import bpy
import numpy as np
import polyscrew
from mathutils import Matrix, Vector
from mathutils.bvhtree import BVHTree

from . import bake, bulk, channels, owners, transaction

#: Name of the collection that receives swept regions.
COLLECTION = "Swept Regions"
#: A world scale that varies by more than this (relative) over the frame range is refused.
SCALE_TOLERANCE = 1e-5
#: Custom property on a swept-region object: the name of the object it was swept from.
SOURCE_KEY = "screwbender_swept_from"


class SweepError(ValueError):
    """A refusal with a message for the user."""


@dataclass
class Swept:
    """One object's swept mesh, computed but not yet written into Blender."""

    obj: bpy.types.Object
    vertices: np.ndarray
    triangles: np.ndarray
    poses: np.ndarray
    seconds: float
    #: The tolerance asked for (world units) and the bound the sweep met (`polyscrew.sweep`'s
    #: `info`): every swept triangle within `error_bound` of the exact swept surface.
    tolerance: float = 0.0
    error_bound: float = 0.0
    #: The grid cell of a closed boundary (`polyscrew.sweep_closed`; 0 for the open sweep):
    #: every vertex then within `error_bound` of the exact swept boundary.
    cell: float = 0.0


def body_mesh(obj: bpy.types.Object, depsgraph: bpy.types.Depsgraph) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) in the object's local frame and triangles (T, 3) of its evaluated mesh."""
    if obj.type != "MESH":
        raise SweepError(f"{obj.name}: not a mesh object")
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        verts = np.empty(3 * len(mesh.vertices), dtype=np.float64)
        bulk.get(mesh.vertices, "co", verts)
        tris = np.empty(3 * len(mesh.loop_triangles), dtype=np.int64)
        bulk.get(mesh.loop_triangles, "vertices", tris)
    finally:
        evaluated.to_mesh_clear()
    return verts.reshape(-1, 3), tris.reshape(-1, 3)


# Meshes carried by a bone --------------------------------------------------------------

#: Modifiers that change a mesh's shape the same way wherever the mesh is (they use nothing
#: but the mesh itself): allowed anywhere in the stack of a mesh deformed by a bone.
SHAPE_ONLY_MODIFIERS = frozenset(
    {"SUBSURF", "MULTIRES", "BEVEL", "SOLIDIFY", "TRIANGULATE", "EDGE_SPLIT", "WEIGHTED_NORMAL", "WELD",
     "WIREFRAME", "DECIMATE", "UV_PROJECT", "UV_WARP"}
)
#: Blender's Armature modifier leaves a vertex whose weights sum to no more than this where it
#: is (`armature_deform.cc`: `contrib > 0.0001f`).
ARMATURE_WEIGHT_THRESHOLD = 1e-4


@dataclass
class BoneDriver:
    """The bone that carries a mesh: `armature.pose.bones[bone]`, through an Armature
    modifier (`deformed`) or as the mesh's parent bone."""

    armature: bpy.types.Object
    bone: str
    deformed: bool


def _before_armature_ok(mod: bpy.types.Modifier) -> bool:
    """Whether `mod`, before the Armature modifier, only builds the rest shape from the mesh
    itself (a mirror or array with no object)."""
    if mod.type == "MIRROR":
        return mod.mirror_object is None
    if mod.type == "ARRAY":
        return not mod.use_object_offset and mod.fit_type != "FIT_CURVE"
    return False


def bone_driver(obj: bpy.types.Object) -> BoneDriver | None:
    """The bone carrying the mesh `obj` rigidly, or None when no bone does (its own transform
    moves it); raises :class:`SweepError`, naming the mesh and why, for a bone deformation
    that is not rigid.

    Rigid: one Armature modifier (vertex groups, no envelopes, no mask group, not "multi")
    and every vertex weighted to one and the same deforming bone, which is not a curved
    B-Bone; no shape keys; other modifiers only those that shape the mesh by itself
    (:data:`SHAPE_ONLY_MODIFIERS`; before the Armature modifier also a mirror or array with
    no object). A vertex's weight need not be 1: Blender's Armature modifier divides by the
    sum of a vertex's weights, so a vertex weighted 0.5 to one bone alone follows it fully
    (only weights summing to no more than :data:`ARMATURE_WEIGHT_THRESHOLD` leave it behind).
    A mesh parented to a bone (no Armature modifier) is carried by it through its own world
    matrix.
    """
    name = obj.name
    if obj.parent is not None and obj.parent_type == "ARMATURE":
        raise SweepError(
            f"{name}: deformed through Armature Deform parenting; give it an Armature modifier instead "
            "(Object > Parent > Armature Deform adds one)"
        )
    modifiers = [m for m in obj.modifiers if m.show_viewport]
    armatures = [m for m in modifiers if m.type == "ARMATURE" and m.object is not None and m.object.type == "ARMATURE"]
    if not armatures:
        if obj.parent is not None and obj.parent_type == "BONE" and obj.parent.type == "ARMATURE" and obj.parent_bone:
            return BoneDriver(obj.parent, obj.parent_bone, False)
        return None
    if len(armatures) > 1:
        raise SweepError(
            f"{name}: deformed by {len(armatures)} Armature modifiers ({', '.join(m.name for m in armatures)}); "
            "a swept region needs a mesh carried rigidly by one bone"
        )
    mod = armatures[0]
    rig = mod.object
    why = ""
    if mod.use_bone_envelopes:
        why = f"its Armature modifier '{mod.name}' uses bone envelopes (they deform by distance to the bones)"
    elif not mod.use_vertex_groups:
        return None  # the modifier moves nothing
    elif mod.vertex_group:
        why = f"its Armature modifier '{mod.name}' is masked by vertex group '{mod.vertex_group}' (it blends with the rest shape)"
    elif mod.use_multi_modifier:
        why = f"its Armature modifier '{mod.name}' is a Multi Modifier (it blends with the modifiers before it)"
    if why:
        raise SweepError(f"{name}: {why}: not a rigid motion")
    index = modifiers.index(mod)
    for i, other in enumerate(modifiers):
        if other is mod or other.type in SHAPE_ONLY_MODIFIERS or (i < index and _before_armature_ok(other)):
            continue
        raise SweepError(
            f"{name}: its {other.type.replace('_', ' ').title()} modifier '{other.name}' may change its shape as it "
            "moves; a swept region needs a mesh carried rigidly by one bone (disable or apply it)"
        )
    keys_ = obj.data.shape_keys
    if keys_ is not None and len(keys_.key_blocks) > 1:
        raise SweepError(
            f"{name}: has {len(keys_.key_blocks) - 1} shape key(s), which change its shape; a swept region needs "
            "a mesh carried rigidly by one bone"
        )
    bone = _weighted_bone(obj, rig)
    data = rig.data.bones[bone]
    if data.bbone_segments > 1:
        raise SweepError(
            f"{name}: bone '{bone}' is a B-Bone with {data.bbone_segments} segments, which bends the mesh: "
            "not a rigid motion"
        )
    return BoneDriver(rig, bone, True)


def _weighted_bone(obj: bpy.types.Object, rig: bpy.types.Object) -> str:
    """The one deforming bone of `rig` every vertex of `obj` is weighted to; raises
    :class:`SweepError` naming the first vertex that is not."""
    name = obj.name
    deforming = {g.index: g.name for g in obj.vertex_groups if g.name in rig.data.bones and rig.data.bones[g.name].use_deform}
    # Blender has no bulk access to vertex weights (MeshVertex.groups has no foreach_get):
    # the weights are read vertex by vertex here, the one such loop of the add-on; nothing
    # is computed per vertex.
    weights = [
        sorted((deforming[g.group], g.weight) for g in v.groups if g.group in deforming and g.weight > 0.0)
        for v in obj.data.vertices
    ]
    found = None
    for i, entries in enumerate(weights):
        bones = sorted({b for b, _ in entries})
        total = sum(w for _, w in entries)
        if not bones or total <= ARMATURE_WEIGHT_THRESHOLD:
            raise SweepError(
                f"{name}: vertex {i} is weighted to no deforming bone of '{rig.name}' (it stays behind as the "
                "bones move): not a rigid motion"
            )
        if len(bones) > 1:
            listed = ", ".join(f"'{b}' {w:g}" for b, w in entries)
            raise SweepError(f"{name}: vertex {i} is weighted to {len(bones)} bones ({listed}): it bends, not a rigid motion")
        if found is None:
            found = bones[0]
        elif bones[0] != found:
            raise SweepError(
                f"{name}: its vertices follow different bones ('{found}', and '{bones[0]}' from vertex {i}): "
                "it bends, not a rigid motion"
            )
    if found is None:
        raise SweepError(f"{name}: has no vertices")
    return found


def carried_matrix(obj: bpy.types.Object, driver: BoneDriver | None) -> np.ndarray:
    """The world matrix the mesh's local coordinates go through at the current frame: its
    own `matrix_world`, or deformed by the bone through an Armature modifier
    `A B_pose B_rest^-1 A^-1 O` (A the armature's world matrix, B the bone's pose and rest
    matrices in armature space, O the mesh's world matrix: Blender's armature deform)."""
    world = np.array(obj.matrix_world, dtype=np.float64)
    if driver is None or not driver.deformed:
        return world
    rig = np.array(driver.armature.matrix_world, dtype=np.float64)
    pose_bone = driver.armature.pose.bones[driver.bone]
    deform = np.array(pose_bone.matrix, dtype=np.float64) @ np.linalg.inv(np.array(pose_bone.bone.matrix_local, dtype=np.float64))
    return rig @ deform @ np.linalg.inv(rig) @ world


def _carrier_frames(driver: BoneDriver, read: dict | None = None) -> list[float]:
    """The key frames of the smoothed action of the bone's armature that move the bone: its
    own transform curves, its parent bones' and the armature object's (`read`: see
    :func:`_key_frames`)."""
    rig = driver.armature
    chain, bone = {""}, rig.data.bones[driver.bone]
    while bone is not None:
        chain.add(bone.name)
        bone = bone.parent
    grouped = owners.curves_by_owner(channels.object_fcurves(rig))
    return _key_frames([fc for key in chain for fc in grouped.get(key, [])], read)


def _key_frames(fcurves: list, read: dict | None = None) -> list[float]:
    """The sorted distinct key frames (rounded to 1e-6) of `fcurves`: one foreach_get per curve.
    `read` (a dict the caller keeps over one run, by `fc.as_pointer()`) holds the frames of
    the curves read so far: meshes sharing an action or riding one rig read its curves once."""
    found = []
    for fc in fcurves:
        frames = None if read is None else read.get(fc.as_pointer())
        if frames is None:
            co = np.empty(2 * len(fc.keyframe_points), dtype=np.float32)
            bulk.get(fc.keyframe_points, "co", co)
            frames = co[0::2]
            if read is not None:
                read[fc.as_pointer()] = frames
        found.append(frames)
    if not found:
        return []
    return np.unique(np.round(np.concatenate(found).astype(np.float64), 6)).tolist()


def motion_frames(
    obj: bpy.types.Object, scene: bpy.types.Scene, driver: BoneDriver | None = None, read: dict | None = None
) -> np.ndarray:
    """The frames to sample: the keys of the smoothed action (Smooth Motion bakes one key per
    step, subframes included) where there is one (for a mesh carried by a bone, the keys of
    its armature's smoothed action moving that bone), else every frame of the scene's range.
    `read`: the key frames read so far in this run (:func:`_key_frames`)."""
    if driver is not None:
        if bake.source_of(driver.armature) is not None:
            frames = _carrier_frames(driver, read)
            if len(frames) >= 2:
                return np.asarray(frames, dtype=np.float64)
    elif bake.source_of(obj) is not None:
        frames = _key_frames(channels.object_fcurves(obj), read)
        if len(frames) >= 2:
            return np.asarray(frames, dtype=np.float64)
    return np.arange(scene.frame_start, scene.frame_end + 1, dtype=np.float64)


def world_poses(
    obj: bpy.types.Object, scene: bpy.types.Scene, frames: np.ndarray, driver: BoneDriver | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Rigid world poses (N, 4, 4) of `obj` (carried by `driver`, see :func:`carried_matrix`)
    at `frames` and its world scale (3,), which must stay constant (a swept region is for
    rigid motion)."""
    frame, subframe = scene.frame_current, scene.frame_subframe
    poses, scales = [], []
    try:
        for f in frames:
            whole = math.floor(f)
            scene.frame_set(whole, subframe=float(f - whole))
            loc, rot, scale = Matrix(carried_matrix(obj, driver).tolist()).decompose()
            poses.append(np.array(Matrix.LocRotScale(loc, rot, None)))
            scales.append(np.array(scale))
    finally:
        scene.frame_set(frame, subframe=subframe)
    scales = np.array(scales)
    spread = np.abs(scales - scales[0]).max()
    if spread > SCALE_TOLERANCE * max(1.0, np.abs(scales).max()):
        raise SweepError(f"{obj.name}: its scale changes over the frame range (not a rigid motion)")
    return np.array(poses), scales[0]


def compute(
    obj: bpy.types.Object,
    context: bpy.types.Context,
    steps: int,
    caps: bool,
    tolerance: float | None = None,
    read: dict | None = None,
    closed: bool = False,
    cell: float | None = None,
) -> Swept:
    """The swept mesh of `obj` along its world motion (nothing is created): each screw in the
    fewest steps (at least `steps`) within `tolerance` (world units; None: 0.2 % of the body's
    bounding radius; 0: exactly `steps`). `read`: a dict kept over one run of several objects
    (the key frames read so far: each curve is read once, :func:`_key_frames`). `closed`: the
    region's closed boundary instead (`polyscrew.sweep_closed`, grid `cell` in world units;
    None: 1.5 % of the body's extent; `steps`, `caps` and `tolerance` do not apply)."""
    scene = context.scene
    if obj.type != "MESH":
        raise SweepError(f"{obj.name}: not a mesh object")
    driver = bone_driver(obj)
    verts, tris = body_mesh(obj, context.evaluated_depsgraph_get())
    if driver is not None and driver.deformed:
        # The evaluated mesh is deformed by the bone's current pose: back into the frame the
        # bone carries, `C^-1 O v` (C: carried_matrix now, O: the mesh's world matrix).
        to_body = np.linalg.inv(carried_matrix(obj, driver)) @ np.array(obj.matrix_world, dtype=np.float64)
        verts = verts @ to_body[:3, :3].T + to_body[:3, 3]
    frames = motion_frames(obj, scene, driver, read)
    if len(frames) < 2:
        raise SweepError(f"{obj.name}: the frame range has a single frame; a motion needs two poses")
    poses, scale = world_poses(obj, scene, frames, driver)
    start = time.perf_counter()
    try:
        if closed:
            v, t, info = polyscrew.sweep_closed(verts * scale, tris, poses, cell=cell, info=True)
            return Swept(obj, v, t, poses, time.perf_counter() - start, 0.0, info["error_bound"], info["cell"])
        v, t, info = polyscrew.sweep(verts * scale, tris, poses, steps=steps, caps=caps, tolerance=tolerance, info=True)
    except ValueError as err:
        raise SweepError(f"{obj.name}: {err}") from err
    return Swept(obj, v, t, poses, time.perf_counter() - start, info["tolerance"], info["error_bound"])


def collection(scene: bpy.types.Scene, t: transaction.Transaction | None = None) -> bpy.types.Collection:
    """The "Swept Regions" collection, created and linked to the scene when missing (the
    linking undone by `t` when it fails: a new collection goes anyway, an existing one that
    was not linked is unlinked again)."""
    coll = bpy.data.collections.get(COLLECTION)
    if coll is None:
        coll = bpy.data.collections.new(COLLECTION)
    if coll.name not in scene.collection.children:
        scene.collection.children.link(coll)
        if t is not None:

            def unlink() -> None:
                if coll.name in scene.collection.children:
                    scene.collection.children.unlink(coll)

            t.on_rollback(unlink)
    return coll


def mesh_from_arrays(name: str, vertices: np.ndarray, triangles: np.ndarray) -> bpy.types.Mesh:
    """A new triangle mesh from (V, 3) vertices and (T, 3) triangles (bulk foreach_set; the
    indices are trusted: `polyscrew.sweep` returns them in range and non-degenerate)."""
    mesh = bpy.data.meshes.new(name)
    n = len(triangles)
    co = np.ascontiguousarray(vertices, dtype=np.float32).ravel()
    corners = np.ascontiguousarray(triangles, dtype=np.int32).ravel()
    mesh.vertices.add(len(vertices))
    mesh.loops.add(3 * n)
    position = mesh.attributes.get("position")
    corner_vert = mesh.attributes.get(".corner_vert")
    if position is not None and corner_vert is not None:
        # The generic attributes take raw buffers (MeshLoop.vertex_index goes item by item).
        bulk.put(position.data, "vector", co)
        bulk.put(corner_vert.data, "value", corners)
    else:
        bulk.put(mesh.vertices, "co", co)
        bulk.put(mesh.loops, "vertex_index", corners)
    mesh.polygons.add(n)
    bulk.put(mesh.polygons, "loop_start", np.arange(0, 3 * n, 3, dtype=np.int32))
    mesh.update(calc_edges=True)
    return mesh


def create_object(swept: Swept, context: bpy.types.Context, t: transaction.Transaction | None = None) -> bpy.types.Object:
    """A new object in the "Swept Regions" collection holding the swept mesh (world frame:
    the open sweep or, computed with `closed`, the closed boundary). `t` undoes the linking
    of the collection when the operator fails."""
    name = f"{swept.obj.name} swept"
    mesh = mesh_from_arrays(name, swept.vertices, swept.triangles)
    obj = bpy.data.objects.new(name, mesh)
    collection(context.scene, t).objects.link(obj)
    obj[SOURCE_KEY] = swept.obj.name
    return obj


def triangle_count(mesh: bpy.types.Mesh) -> int:
    mesh.calc_loop_triangles()
    return len(mesh.loop_triangles)


def mesh_triangles(mesh: bpy.types.Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) and loop triangles (T, 3) of `mesh` (bulk foreach_get)."""
    mesh.calc_loop_triangles()
    verts = np.empty(3 * len(mesh.vertices), dtype=np.float64)
    bulk.get(mesh.vertices, "co", verts)
    tris = np.empty(3 * len(mesh.loop_triangles), dtype=np.int64)
    bulk.get(mesh.loop_triangles, "vertices", tris)
    return verts.reshape(-1, 3), tris.reshape(-1, 3)


def created_triangles(swept: Swept) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) and triangles (T, 3) of the mesh made from `swept` by
    :func:`create_object`: what was written into it (float32, as the mesh holds it), not read
    back."""
    vertices = np.ascontiguousarray(swept.vertices, dtype=np.float32).astype(np.float64)
    return vertices, np.asarray(swept.triangles, dtype=np.int64)


# --- clearance ----------------------------------------------------------------------------


@dataclass
class Clearance:
    """The result of :func:`clearance`."""

    intersects: bool
    #: Smallest distance between the two surfaces (0 when they intersect).
    distance: float
    #: Polygon indices of each object that take part in an intersection.
    faces_a: list[int]
    faces_b: list[int]


def world_polygons(obj: bpy.types.Object, depsgraph: bpy.types.Depsgraph) -> tuple[list[Vector], list[tuple[int, ...]]]:
    """World-space vertices and polygons of the evaluated mesh (indices of `obj.data`'s
    polygons when there are no modifiers)."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mw = obj.matrix_world
        verts = [mw @ v.co for v in mesh.vertices]
        polys = [tuple(p.vertices) for p in mesh.polygons]
    finally:
        evaluated.to_mesh_clear()
    return verts, polys


def _nearest(tree: BVHTree, points: list[Vector]) -> float:
    best = math.inf
    for p in points:
        hit = tree.find_nearest(p)
        if hit[0] is not None and hit[3] < best:
            best = hit[3]
    return best


def is_closed(polys: list[tuple[int, ...]]) -> bool:
    """Whether every edge of the polygons is shared by exactly two of them (watertight)."""
    keys = [tuple(sorted((p[i], p[(i + 1) % len(p)]))) for p in polys for i in range(len(p))]
    if not keys:
        return False
    _, counts = np.unique(np.array(keys), axis=0, return_counts=True)
    return bool(np.all(counts == 2))


def inside(tree: BVHTree, point: Vector, scale: float) -> bool:
    """Whether `point` is inside the closed mesh of `tree`: odd number of crossings of a ray
    (in a direction unlikely to graze edges)."""
    direction = Vector((0.5773, 0.5774, 0.5773)).normalized()
    origin, crossings = point.copy(), 0
    for _ in range(10000):
        hit, _normal, _index, _dist = tree.ray_cast(origin, direction)
        if hit is None:
            break
        crossings += 1
        origin = hit + direction * (1e-7 * scale)
    return crossings % 2 == 1


def clearance(a: bpy.types.Object, b: bpy.types.Object, depsgraph: bpy.types.Depsgraph) -> Clearance:
    """Whether `a` and `b` intersect (BVH overlap of their polygons, or, for a closed mesh,
    one holding a vertex of the other inside) and their smallest distance (every vertex of
    each against the other's surface: exact for face-to-vertex and face-to-face closeness,
    within the edge length for edge-to-edge). The closed boundary made by Build Swept Region
    with Closed Volume has an inside (an object wholly within the region intersects it); the
    open superset made without it has none: only its surface counts."""
    va, pa = world_polygons(a, depsgraph)
    vb, pb = world_polygons(b, depsgraph)
    if not pa or not pb:
        raise SweepError(f"{a.name if not pa else b.name}: has no faces")
    ta = BVHTree.FromPolygons(va, pa, all_triangles=False)
    tb = BVHTree.FromPolygons(vb, pb, all_triangles=False)
    pairs = ta.overlap(tb)
    if pairs:
        return Clearance(True, 0.0, sorted({i for i, _ in pairs}), sorted({j for _, j in pairs}))
    scale = max((max(v) - min(v) for v in zip(*(va + vb))), default=1.0)
    for tree, polys, other in ((ta, pa, vb), (tb, pb, va)):
        if other and is_closed(polys) and inside(tree, other[0], scale):
            return Clearance(True, 0.0, [], [])
    distance = min(_nearest(ta, vb), _nearest(tb, va))
    return Clearance(False, distance, [], [])


def select_faces(obj: bpy.types.Object, faces: list[int]) -> None:
    """Selects exactly `faces` of `obj`'s mesh (Edit Mode shows them)."""
    mesh = obj.data
    mask = np.zeros(len(mesh.polygons), dtype=bool)
    mask[[f for f in faces if f < len(mask)]] = True
    bulk.put(mesh.polygons, "select", mask)
    mesh.update()
