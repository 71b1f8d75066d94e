"""Build Swept Region and Check Clearance in Blender (issue 4).

- the closed volume (voxel remesh) is manifold and watertight by bmesh's own checks and
  contains every vertex of the body at every sampled frame and between frames;
- a box sliding past a wall at a known gap: the right distance and "no"; one that hits it:
  "yes" and the colliding faces selected;
- bad input (empty mesh, zero-area triangle, NaN vertex, one-frame motion) is refused with a
  clear message and creates nothing.
"""

from __future__ import annotations

import math

import bmesh
import bpy
import numpy as np
import polyscrew
import pytest
from mathutils import Vector
from mathutils.bvhtree import BVHTree

import bake_helpers as h

CUBE_V = [(x, y, z) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
CUBE_F = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]


def mesh_object(name, verts, faces, location=(0, 0, 0), scale=(1, 1, 1)):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    obj.location = location
    obj.scale = scale
    return obj


def key(obj, frame, location, rotation=(0, 0, 0)):
    obj.location = location
    obj.rotation_euler = rotation
    obj.keyframe_insert("location", frame=frame)
    obj.keyframe_insert("rotation_euler", frame=frame)


def swept_objects():
    coll = bpy.data.collections.get("Swept Regions")
    return list(coll.objects) if coll else []


def world_vertices(obj, frame):
    scene = bpy.context.scene
    whole = math.floor(frame)
    scene.frame_set(whole, subframe=float(frame - whole))
    mw = np.array(obj.matrix_world)
    v = np.array([tuple(p.co) for p in obj.data.vertices])
    return v @ mw[:3, :3].T + mw[:3, 3], mw


def test_closed_volume_is_manifold_watertight_and_contains_the_instances():
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 24
    body = mesh_object("Body", CUBE_V, CUBE_F, scale=(1.0, 0.6, 0.4))
    bevel = body.modifiers.new("Bevel", "BEVEL")  # the evaluated mesh is swept
    bevel.width = 0.05
    key(body, 1, (0, 0, 0), (0, 0, 0))
    key(body, 12, (1.5, 0.5, 0.3), (0.4, 0.2, 1.2))
    key(body, 24, (3.0, -0.5, 1.0), (0.9, -0.3, 2.4))
    h.select_only(body)
    voxel = 0.04
    assert bpy.ops.screwbender.sweep(steps=4, caps=True, closed=True, voxel_size=voxel) == {"FINISHED"}
    (region,) = swept_objects()
    assert region["screwbender_swept_from"] == "Body"
    bm = bmesh.new()
    bm.from_mesh(region.data)
    try:
        assert len(bm.faces) > 0
        non_manifold = sum(not e.is_manifold for e in bm.edges)
        boundary = sum(e.is_boundary for e in bm.edges)
        bad_verts = sum(not v.is_manifold for v in bm.verts)
        print(f"\nclosed volume: {len(bm.faces)} faces, non-manifold edges {non_manifold}, "
              f"boundary edges {boundary}, non-manifold vertices {bad_verts}")
        assert non_manifold == 0 and boundary == 0 and bad_verts == 0
        assert all(len(e.link_faces) == 2 for e in bm.edges)
        volume = bm.calc_volume(signed=True)
        assert volume > 0
        tree = BVHTree.FromBMesh(bm)
    finally:
        bm.free()
    # Every vertex of the (bevelled) body at every frame and at 4 points of each screw
    # between frames lies inside, or within one voxel of the surface.
    depsgraph = bpy.context.evaluated_depsgraph_get()
    poses = []
    for f in range(scene.frame_start, scene.frame_end + 1):
        scene.frame_set(f)
        poses.append(np.array(body.matrix_world.normalized()))
    dense = [polyscrew.interpolate(a, b, np.linspace(0, 1, 4, endpoint=False)) for a, b in zip(poses, poses[1:])]
    dense = np.concatenate(dense + [poses[-1][None]])
    scale = np.array(body.scale)
    ev = body.evaluated_get(depsgraph).to_mesh()
    local = np.array([tuple(v.co) for v in ev.vertices]) * scale
    body.evaluated_get(depsgraph).to_mesh_clear()
    worst = -math.inf
    for pose in dense:
        for p in local @ pose[:3, :3].T + pose[:3, 3]:
            loc, normal, _, dist = tree.find_nearest(Vector(p))
            signed = (Vector(p) - loc).dot(normal)
            worst = max(worst, signed)
    print(f"instances: {len(dense)} poses x {len(local)} vertices, worst signed distance outside {worst:.4f} (voxel {voxel})")
    assert worst <= voxel


@pytest.mark.parametrize("closed", [False, True])
def test_clearance_of_a_box_sliding_past_a_wall(closed):
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 20
    box = mesh_object("Box", CUBE_V, CUBE_F)
    key(box, 1, (0, -3, 0))
    key(box, 20, (0, 3, 0), (0, 0, 0))
    gap = 0.7
    wall = mesh_object("Wall", CUBE_V, CUBE_F, location=(0.5 + gap + 0.1, 0, 0), scale=(0.2, 4, 4))
    hit = mesh_object("Post", CUBE_V, CUBE_F, location=(0.3, 1.0, 0), scale=(0.2, 0.2, 4))
    h.select_only(box)
    voxel = 0.05
    assert bpy.ops.screwbender.sweep(steps=2, closed=closed, voxel_size=voxel) == {"FINISHED"}
    (region,) = swept_objects()
    h.select_only(region, wall, hit)
    assert bpy.ops.screwbender.check_clearance() == {"FINISHED"}
    distances = region["screwbender_clearance"].to_dict()
    intersects = list(region["screwbender_intersects"])
    print(f"\nclosed={closed}: distances {distances}, intersects {intersects}")
    tol = voxel if closed else 1e-5
    assert abs(distances["Wall"] - gap) <= tol
    assert intersects == ["Post"] and distances["Post"] == 0.0
    selected = [p.index for p in region.data.polygons if p.select]
    assert selected, "colliding faces not selected"
    # The selected faces are where the post stands (x about 0.3 to 0.5 on the region's side).
    centers = np.array([tuple(region.data.polygons[i].center) for i in selected])
    assert np.all(np.abs(centers[:, 1] - 1.0) < 0.6 + 2 * tol)
    assert any(p.select for p in hit.data.polygons)
    assert not any(p.select for p in wall.data.polygons)


def test_clearance_sees_an_object_inside_a_closed_volume():
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 10
    box = mesh_object("Box", CUBE_V, CUBE_F, scale=(2, 2, 2))
    key(box, 1, (0, -2, 0))
    key(box, 10, (0, 2, 0))
    pebble = mesh_object("Pebble", CUBE_V, CUBE_F, location=(0.1, 0.5, 0.1), scale=(0.1, 0.1, 0.1))
    h.select_only(box)
    assert bpy.ops.screwbender.sweep(steps=2, closed=True, voxel_size=0.05) == {"FINISHED"}
    (region,) = swept_objects()
    h.select_only(region, pebble)
    assert bpy.ops.screwbender.check_clearance() == {"FINISHED"}
    assert list(region["screwbender_intersects"]) == ["Pebble"]
    assert region["screwbender_clearance"]["Pebble"] == 0.0


def snapshot():
    return (
        sorted(o.name for o in bpy.data.objects),
        sorted(m.name for m in bpy.data.meshes),
        sorted(c.name for c in bpy.data.collections),
    )


def refuse(match):
    before = snapshot()
    with pytest.raises(RuntimeError, match=match) as error:
        bpy.ops.screwbender.sweep()
    print(f"\n{bpy.app.version_string}: {error.value}")
    assert snapshot() == before


def moving(obj):
    key(obj, 1, (0, 0, 0))
    key(obj, 10, (1, 2, 0), (0, 0, 1))
    h.select_only(obj)


def test_empty_mesh_refused():
    moving(mesh_object("Empty", [], []))
    refuse(r"Empty: .*the mesh has no vertices")


def test_zero_area_triangle_refused():
    moving(mesh_object("Flat", [(0, 0, 0), (1, 0, 0), (2, 0, 0)], [(0, 1, 2)]))
    refuse(r"Flat: .*triangle 0\b.*zero area")


def test_nan_vertex_refused():
    obj = mesh_object("Bad", CUBE_V, CUBE_F)
    obj.data.vertices[3].co = (float("nan"), 0.0, 0.0)
    moving(obj)
    refuse(r"Bad: .*vertex 3 is NaN")


def test_single_frame_refused():
    scene = bpy.context.scene
    scene.frame_start = scene.frame_end = 1
    moving(mesh_object("Still", CUBE_V, CUBE_F))
    refuse(r"Still: .*single frame")


def test_one_of_two_bad_creates_nothing(monkeypatch):
    """The faceless mesh is refused before the closed cube (seconds at the defaults) is
    computed: the open sweeps run first."""
    from conftest import addon_module

    swept = addon_module("blender.swept")
    closed_calls = []
    sweep_closed = swept.polyscrew.sweep_closed
    monkeypatch.setattr(swept.polyscrew, "sweep_closed", lambda *a, **k: closed_calls.append(1) or sweep_closed(*a, **k))
    moving(mesh_object("Good", CUBE_V, CUBE_F))
    bad = mesh_object("Nothing", [], [])
    key(bad, 1, (0, 0, 0))
    key(bad, 10, (1, 0, 0))
    h.select_only(*[bpy.data.objects["Good"], bad])
    refuse(r"Nothing: ")
    assert closed_calls == []


def test_sweeps_the_smoothed_motion_at_its_baked_keys():
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 30
    body = mesh_object("Body", CUBE_V, CUBE_F)
    key(body, 1, (0, 0, 0))
    key(body, 10, (2, 1, 0), (0, 0, 1.5))
    key(body, 30, (4, -1, 1), (0.5, 0, 3.0))
    h.select_only(body)
    assert bpy.ops.screwbender.smooth(step=0.5) == {"FINISHED"}
    from conftest import addon_module

    swept = addon_module("blender.swept")
    frames = swept.motion_frames(body, scene)
    np.testing.assert_allclose(frames, np.arange(1, 30.25, 0.5))
    assert bpy.ops.screwbender.sweep(steps=2, closed=False) == {"FINISHED"}
    (region,) = swept_objects()
    # Every baked pose's box corners lie on the region's vertices' bounding box or inside.
    v = np.array([tuple(p.co) for p in region.data.vertices])
    lo, hi = v.min(axis=0), v.max(axis=0)
    for f in frames[::7]:
        w, _ = world_vertices(body, f)
        assert np.all(w >= lo - 1e-5) and np.all(w <= hi + 1e-5)
