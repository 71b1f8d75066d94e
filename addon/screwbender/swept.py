# SPDX-License-Identifier: GPL-3.0-or-later
"""Swept regions and clearance: Blender data in and out of `polyscrew.sweep`.

The pipeline, per object (Rossignac-Kim, "Swept volumes"):

1. :func:`body_mesh` reads the evaluated mesh (modifiers applied) as triangles in the
   object's local frame, scaled by the object's (constant) world scale;
2. :func:`world_poses` samples the object's rigid world motion: at every key of the action
   made by Smooth Motion where there is one, otherwise at every frame of the scene's range;
3. `polyscrew.sweep` builds the swept mesh (each pair of samples is one screw);
4. :func:`create_object` writes it into a new object of the "Swept Regions" collection,
   optionally closed into a manifold volume by Blender's voxel remesh.

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

from . import bake

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


def body_mesh(obj: bpy.types.Object, depsgraph: bpy.types.Depsgraph) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) in the object's local frame and triangles (T, 3) of its evaluated mesh."""
    if obj.type != "MESH":
        raise SweepError(f"{obj.name}: not a mesh object")
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        verts = np.empty(3 * len(mesh.vertices), dtype=np.float64)
        mesh.vertices.foreach_get("co", verts)
        tris = np.empty(3 * len(mesh.loop_triangles), dtype=np.int64)
        mesh.loop_triangles.foreach_get("vertices", tris)
    finally:
        evaluated.to_mesh_clear()
    return verts.reshape(-1, 3), tris.reshape(-1, 3)


def motion_frames(obj: bpy.types.Object, scene: bpy.types.Scene) -> np.ndarray:
    """The frames to sample: the keys of the smoothed action (Smooth Motion bakes one key per
    step, subframes included) where there is one, else every frame of the scene's range."""
    if bake.source_of(obj) is not None:
        from . import channels

        frames = sorted({round(k.co[0], 6) for fc in channels.object_fcurves(obj) for k in fc.keyframe_points})
        if len(frames) >= 2:
            return np.asarray(frames, dtype=np.float64)
    return np.arange(scene.frame_start, scene.frame_end + 1, dtype=np.float64)


def world_poses(obj: bpy.types.Object, scene: bpy.types.Scene, frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rigid world poses (N, 4, 4) of `obj` at `frames` and its world scale (3,), which must
    stay constant (a swept region is for rigid motion)."""
    frame, subframe = scene.frame_current, scene.frame_subframe
    poses, scales = [], []
    try:
        for f in frames:
            whole = math.floor(f)
            scene.frame_set(whole, subframe=float(f - whole))
            loc, rot, scale = obj.matrix_world.decompose()
            poses.append(np.array(Matrix.LocRotScale(loc, rot, None)))
            scales.append(np.array(scale))
    finally:
        scene.frame_set(frame, subframe=subframe)
    scales = np.array(scales)
    spread = np.abs(scales - scales[0]).max()
    if spread > SCALE_TOLERANCE * max(1.0, np.abs(scales).max()):
        raise SweepError(f"{obj.name}: its scale changes over the frame range (not a rigid motion)")
    return np.array(poses), scales[0]


def compute(obj: bpy.types.Object, context: bpy.types.Context, steps: int, caps: bool) -> Swept:
    """The swept mesh of `obj` along its world motion (nothing is created)."""
    scene = context.scene
    verts, tris = body_mesh(obj, context.evaluated_depsgraph_get())
    frames = motion_frames(obj, scene)
    if len(frames) < 2:
        raise SweepError(f"{obj.name}: the frame range has a single frame; a motion needs two poses")
    poses, scale = world_poses(obj, scene, frames)
    start = time.perf_counter()
    try:
        v, t = polyscrew.sweep(verts * scale, tris, poses, steps=steps, caps=caps)
    except ValueError as err:
        raise SweepError(f"{obj.name}: {err}") from err
    return Swept(obj, v, t, poses, time.perf_counter() - start)


def collection(scene: bpy.types.Scene) -> bpy.types.Collection:
    """The "Swept Regions" collection, created and linked to the scene when missing."""
    coll = bpy.data.collections.get(COLLECTION)
    if coll is None:
        coll = bpy.data.collections.new(COLLECTION)
    if coll.name not in scene.collection.children:
        scene.collection.children.link(coll)
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
        position.data.foreach_set("vector", co)
        corner_vert.data.foreach_set("value", corners)
    else:
        mesh.vertices.foreach_set("co", co)
        mesh.loops.foreach_set("vertex_index", corners)
    mesh.polygons.add(n)
    mesh.polygons.foreach_set("loop_start", np.arange(0, 3 * n, 3, dtype=np.int32))
    mesh.update(calc_edges=True)
    return mesh


def create_object(
    swept: Swept, context: bpy.types.Context, closed: bool, voxel_size: float
) -> bpy.types.Object:
    """A new object in the "Swept Regions" collection holding the swept mesh (world frame);
    `closed` turns it into a closed manifold volume with a voxel remesh of `voxel_size`."""
    name = f"{swept.obj.name} swept"
    mesh = mesh_from_arrays(name, swept.vertices, swept.triangles)
    obj = bpy.data.objects.new(name, mesh)
    collection(context.scene).objects.link(obj)
    obj[SOURCE_KEY] = swept.obj.name
    if closed:
        mod = obj.modifiers.new("Voxel Remesh", "REMESH")
        mod.mode = "VOXEL"
        mod.voxel_size = voxel_size
        mod.adaptivity = 0.0
        depsgraph = context.evaluated_depsgraph_get()
        depsgraph.update()
        remeshed = bpy.data.meshes.new_from_object(obj.evaluated_get(depsgraph))
        obj.modifiers.remove(mod)
        obj.data = remeshed
        remeshed.name = name
        bpy.data.meshes.remove(mesh)
        if len(remeshed.polygons) == 0:
            bpy.data.objects.remove(obj)
            bpy.data.meshes.remove(remeshed)
            raise SweepError(f"{swept.obj.name}: the voxel remesh gave an empty mesh (voxel size {voxel_size:g})")
    return obj


def triangle_count(mesh: bpy.types.Mesh) -> int:
    mesh.calc_loop_triangles()
    return len(mesh.loop_triangles)


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
    within the edge length for edge-to-edge). The open superset made by Build Swept Region
    without Closed Volume has no inside: only its surface counts."""
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
    mesh.polygons.foreach_set("select", mask)
    mesh.update()
