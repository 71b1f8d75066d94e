"""Build Swept Region on a closed cube and an open plane (issue 29 follow-up).

- At the operator's defaults (Closed Volume left alone) both get a region: the cube its closed
  boundary (every edge in two faces, by bmesh; a volume, Blender's), the plane the open sweep
  (an area, no volume nor cell, the open sweep's default tolerance; the very mesh that Closed
  Volume off builds for it), and a warning names the plane and why;
- with Closed Volume turned on (`closed=True`), nothing is created and the error names the
  plane and how to get the open sweep; a script setting only another option falls back as the
  defaults do;
- one undo removes both regions.
"""

from __future__ import annotations

import bmesh
import bpy
import numpy as np
import pytest
from mathutils import Matrix

import bake_helpers as h
from screws import screw_matrix
from test_sweep_tolerance import cube, key, region_arrays

PLANE_V = [(-1.0, -1.0, 0.0), (1.0, -1.0, 0.0), (1.0, 1.0, 0.0), (-1.0, 1.0, 0.0)]


def plane(name="Plane"):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(PLANE_V, [], [(0, 1, 2, 3)])
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def animate(obj, offset):
    """Three keys over frames 1 to 3: a short screw, turning 20 degrees and sliding 0.3 a frame."""
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 3
    start = np.eye(4)
    start[:3, 3] = offset
    for i, frame in enumerate((1, 2, 3)):
        step = screw_matrix((0.2, 0.3, 1.0), (0.4, -0.2, 0.0), np.radians(20.0 * i), 0.3 * i)
        key(obj, frame, Matrix((step @ start).tolist()))


def scene_with_cube_and_plane():
    body, sheet = cube(), plane()
    animate(body, (0.0, 0.0, 0.0))
    animate(sheet, (3.0, 0.0, 0.0))
    h.select_only(body, sheet)
    return body, sheet


def regions():
    """The swept regions by the name of the object each was swept from."""
    coll = bpy.data.collections.get("Swept Regions")
    return {o["screwbender_swept_from"]: o for o in coll.objects} if coll else {}


def snapshot():
    return sorted(o.name for o in bpy.data.objects), sorted(m.name for m in bpy.data.meshes)


def reported(capfd):
    """The operator's reports printed since the last read (headless Blender prints them)."""
    return [line for line in capfd.readouterr().out.splitlines() if line.split(":")[0] in ("Info", "Warning", "Error")]


def every_edge_in_two_faces(obj):
    bm = bmesh.new()
    bm.from_mesh(obj.data)
    try:
        return all(e.is_manifold and e.is_contiguous for e in bm.edges), bm.calc_volume(signed=True)
    finally:
        bm.free()


def test_at_the_defaults_the_cube_gets_its_closed_boundary_and_the_plane_the_open_sweep(capfd):
    scene_with_cube_and_plane()
    capfd.readouterr()
    assert bpy.ops.screwbender.sweep() == {"FINISHED"}
    lines = reported(capfd)
    print(f"\n{bpy.app.version_string}: {lines}")
    warnings = [line for line in lines if line.startswith("Warning:")]
    made = regions()
    assert sorted(made) == ["Cube", "Plane"]
    boundary, sheet = made["Cube"], made["Plane"]
    closed, volume = every_edge_in_two_faces(boundary)
    assert closed
    assert boundary["screwbender_cell"] > 0.0
    assert boundary["screwbender_volume"] == pytest.approx(volume, rel=1e-5) and volume > 1.0
    # The plane's region: the open sweep (edges with one face), an area, no volume nor cell, the
    # open sweep's default tolerance (0.2 % of the bounding radius, half the diagonal: sqrt 2).
    open_edges, _ = every_edge_in_two_faces(sheet)
    assert not open_edges
    assert "screwbender_volume" not in sheet and "screwbender_cell" not in sheet
    assert sheet["screwbender_area"] > 0.0
    assert sheet["screwbender_tolerance"] == pytest.approx(0.002 * np.sqrt(2.0), rel=1e-6)  # float32 vertices
    # The warning names the plane alone, and why; it is the last report (the status bar's).
    assert len(warnings) == 1 and lines[-1] == warnings[0], lines
    assert "Plane: the mesh is not closed, built the open sweep (Closed Volume needs a closed mesh" in warnings[0]
    assert "Cube" not in warnings[0]
    # The very mesh Closed Volume off builds for the plane.
    v, t = region_arrays(sheet)
    h.select_only(bpy.data.objects["Plane"])
    assert bpy.ops.screwbender.sweep(closed=False) == {"FINISHED"}
    ov, ot = region_arrays(bpy.context.view_layer.objects.active)
    np.testing.assert_array_equal(ot, t)
    np.testing.assert_array_equal(ov, v)


def test_closed_volume_turned_on_refuses_the_plane_with_nothing_created(capfd):
    scene_with_cube_and_plane()
    before = snapshot()
    with pytest.raises(RuntimeError, match=r"Plane: the mesh is not closed.*turn it off for the open sweep") as error:
        bpy.ops.screwbender.sweep(closed=True)
    print(f"\n{bpy.app.version_string}: {error.value}")
    assert "Cube" not in str(error.value)
    assert snapshot() == before
    # A script setting another option leaves Closed Volume at its default: the plane falls back.
    capfd.readouterr()
    assert bpy.ops.screwbender.sweep(tolerance=0.02) == {"FINISHED"}
    assert any(line.startswith("Warning: Plane: the mesh is not closed") for line in reported(capfd))
    made = regions()
    assert sorted(made) == ["Cube", "Plane"]
    assert "screwbender_cell" in made["Cube"] and "screwbender_cell" not in made["Plane"]


def test_one_undo_removes_both_regions():
    scene_with_cube_and_plane()
    assert bpy.context.preferences.edit.undo_steps > 0
    bpy.ops.ed.undo_push(message="before sweeping")
    before = snapshot()
    # The second argument asks bpy.ops to push an undo step, as the UI does.
    assert bpy.ops.screwbender.sweep("EXEC_DEFAULT", True) == {"FINISHED"}
    assert sorted(regions()) == ["Cube", "Plane"]
    assert bpy.ops.ed.undo() == {"FINISHED"}
    assert regions() == {}
    assert snapshot() == before
