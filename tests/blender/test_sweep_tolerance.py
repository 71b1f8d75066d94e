"""Build Swept Region at its defaults: accuracy by a tolerance (issue 29, items 1 and 3).

The reference is independent of polyscrew: the poses Blender plays at the sampled frames
(`matrix_world`), the screw between two of them as the matrix exponential of the principal
logarithm of their relative transform (`scipy.linalg.logm`, closed-form SE(3) exponential),
and the cube's exact signed distance. Every probe point of the swept region (corners, edge
midpoints and centroids of its triangles) must lie within the reported tolerance of the cube's
surface at some pose along the motion; the area and the (closed) volume reported must be
Blender's own (`bmesh`).
"""

from __future__ import annotations

import math

import bmesh
import bpy
import numpy as np
import pytest
import scipy.linalg
from mathutils import Matrix, geometry
from scipy.spatial.transform import Rotation

import bake_helpers as h
from conftest import addon_module
from screws import screw_matrix

CUBE_V = [(x, y, z) for z in (-0.5, 0.5) for y in (-0.5, 0.5) for x in (-0.5, 0.5)]
CUBE_F = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]


def cube(name="Cube"):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(CUBE_V, [], CUBE_F)
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def key(obj, frame, matrix):
    obj.matrix_world = matrix
    obj.keyframe_insert("location", frame=frame)
    obj.keyframe_insert("rotation_euler", frame=frame)



def played_poses(obj, frames):
    scene = bpy.context.scene
    out = []
    for f in frames:
        whole = math.floor(f)
        scene.frame_set(whole, subframe=float(f - whole))
        out.append(np.array(obj.matrix_world))
    return np.array(out)


def se3_log(m):
    """The principal logarithm (w, v) of a rigid transform: `w` its rotation vector (scipy),
    `v = V(w)^-1 p` (`V` the left Jacobian of SO(3)); checked against `scipy.linalg.logm`."""
    w = Rotation.from_matrix(m[:3, :3]).as_rotvec()
    th = np.linalg.norm(w)
    wx = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    c = (1 - th * np.sin(th) / (2 * (1 - np.cos(th)))) / th**2 if th > 1e-9 else 1 / 12
    v = (np.eye(3) - 0.5 * wx + c * wx @ wx) @ m[:3, 3]
    xi = scipy.linalg.logm(m).real
    assert np.allclose(xi[:3, 3], v, atol=1e-5) and np.allclose([xi[2, 1], xi[0, 2], xi[1, 0]], w, atol=1e-5)
    return w, v


class Motion:
    """The screws between consecutive poses: `exp(t xi_i) a_i`, `xi_i = log(a_{i+1} a_i^-1)`."""

    def __init__(self, poses):
        self.a = poses[:-1]
        logs = [se3_log(b @ np.linalg.inv(a)) for a, b in zip(poses[:-1], poses[1:])]
        self.w = np.array([w for w, _ in logs])
        self.v = np.array([v for _, v in logs])

    def poses(self, span, t):
        """Poses (K, 4, 4) at parameters `t` (K,) on screws `span` (K,)."""
        w, v, a = self.w[span] * t[:, None], self.v[span] * t[:, None], self.a[span]
        th = np.linalg.norm(w, axis=1)
        wx = np.zeros((len(t), 3, 3))
        wx[:, 0, 1], wx[:, 0, 2], wx[:, 1, 2] = -w[:, 2], w[:, 1], -w[:, 0]
        wx -= wx.transpose(0, 2, 1)
        safe = np.where(th > 1e-12, th, 1.0)
        c1 = np.where(th > 1e-12, (1 - np.cos(th)) / safe**2, 0.5)
        c2 = np.where(th > 1e-12, (th - np.sin(th)) / safe**3, 1 / 6)
        vmat = np.eye(3) + c1[:, None, None] * wx + c2[:, None, None] * wx @ wx
        m = np.zeros((len(t), 4, 4))
        m[:, :3, :3] = Rotation.from_rotvec(w).as_matrix()
        m[:, :3, 3] = np.einsum("kij,kj->ki", vmat, v)
        m[:, 3, 3] = 1.0
        return m @ a


def sd_box(local, half):
    q = np.abs(local) - half
    return np.linalg.norm(np.maximum(q, 0.0), axis=-1) + np.minimum(q.max(axis=-1), 0.0)


def distance_along(motion, points, half, per_span=1024, fine=32, levels=2):
    """For each point the least |signed distance| to the box of half-size `half` over the motion:
    `per_span` samples per screw, then `levels` refinements of `fine` samples around the best."""
    spans = len(motion.a)
    grid_t = np.tile(np.arange(per_span + 1) / per_span, spans)
    grid_s = np.repeat(np.arange(spans), per_span + 1)
    inv = np.linalg.inv(motion.poses(grid_s, grid_t))
    best = np.full(len(points), np.inf)
    arg = np.zeros(len(points), dtype=int)
    for lo in range(0, len(inv), 512):
        chunk = inv[lo:lo + 512]
        local = np.einsum("pij,nj->pni", chunk[:, :3, :3], points) + chunk[:, None, :3, 3]
        d = np.abs(sd_box(local, half))
        i = d.argmin(axis=0)
        better = d[i, np.arange(len(points))] < best
        best = np.where(better, d[i, np.arange(len(points))], best)
        arg = np.where(better, lo + i, arg)
    span, t0 = grid_s[arg], grid_t[arg]
    width = 1.0 / per_span
    offsets = np.linspace(-1.0, 1.0, fine + 1)
    for _ in range(levels):
        ts = np.clip(t0[:, None] + width * offsets[None, :], 0.0, 1.0)
        m = np.linalg.inv(motion.poses(np.repeat(span, fine + 1), ts.ravel())).reshape(len(points), fine + 1, 4, 4)
        local = np.einsum("nkij,nj->nki", m[..., :3, :3], points) + m[..., :3, 3]
        d = np.abs(sd_box(local, half))
        j = d.argmin(axis=1)
        best = np.minimum(best, d[np.arange(len(points)), j])
        t0 = ts[np.arange(len(points)), j]
        width *= 2.0 / fine
    return best


def region_arrays(region):
    mesh = region.data
    mesh.calc_loop_triangles()
    v = np.empty(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", v)
    t = np.empty(3 * len(mesh.loop_triangles), dtype=np.int64)
    mesh.loop_triangles.foreach_get("vertices", t)
    mw = np.array(region.matrix_world)
    v = v.reshape(-1, 3) @ mw[:3, :3].T + mw[:3, 3]
    return v, t.reshape(-1, 3)


def probes(v, t, count, seed=0):
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    pts = np.concatenate([a, b, c, (a + b) / 2, (b + c) / 2, (c + a) / 2, (a + b + c) / 3])
    pts = np.unique(np.round(pts, 12), axis=0)
    if len(pts) > count:
        pts = pts[np.random.default_rng(seed).choice(len(pts), count, replace=False)]
    return pts


def swept_region():
    """The region the operator just made (it leaves it active and alone selected)."""
    region = bpy.context.view_layer.objects.active
    assert region.get("screwbender_swept_from") and list(bpy.context.selected_objects) == [region]
    return region


def long_screw(obj):
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 2
    start = np.eye(4)
    start[:3, 3] = (0.3, -0.2, 0.1)
    key(obj, 1, Matrix(start.tolist()))
    end = screw_matrix((0.3, 0.2, 1.0), (0.8, -1.2, 0.0), 2 * math.pi / 3, 1.0) @ start
    key(obj, 2, Matrix(end.tolist()))
    return [1.0, 2.0]


def smoothed(obj):
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 24
    mats = [np.eye(4), screw_matrix((0.2, 1, 0.3), (1, 0, 0), 1.1, 0.4),
            screw_matrix((1, -0.3, 0.5), (0.5, 2, 0), 2.2, 1.0), screw_matrix((-0.4, 0.2, 1), (2, 1, 1), 2.9, 2.0)]
    for f, m in zip((1, 8, 16, 24), mats):
        key(obj, f, Matrix(m.tolist()))
    h.select_only(obj)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    swept = addon_module("blender.swept")
    return list(swept.motion_frames(obj, scene))


@pytest.mark.parametrize("motion", ["long_screw", "smoothed"])
def test_defaults_keep_the_region_within_the_reported_tolerance(motion):
    body = cube()
    frames = {"long_screw": long_screw, "smoothed": smoothed}[motion](body)
    poses = played_poses(body, frames)
    h.select_only(body)
    # The open sweep's default tolerance (Closed Volume, the operator's default since issue 29
    # item 1, is tests/blender/test_sweep_closed.py's).
    assert bpy.ops.screwbender.sweep(closed=False) == {"FINISHED"}
    region = swept_region()
    tol, bound = region["screwbender_tolerance"], region["screwbender_error_bound"]
    expected_tol = 0.002 * 0.5 * math.sqrt(3.0)  # 0.2 % of half the unit cube's diagonal
    assert tol == pytest.approx(expected_tol, rel=1e-6)  # float32 vertices
    assert 0.0 < bound <= tol
    v, t = region_arrays(region)
    pts = probes(v, t, 2500)
    worst = distance_along(Motion(poses), pts, 0.5).max()
    print(f"\n{motion}: {len(frames) - 1} screws, tolerance {tol:.3e}, bound {bound:.3e}, {len(t)} triangles, "
          f"measured {worst:.3e} over {len(pts)} probes")
    assert worst <= tol * 1.01
    if motion == "long_screw":
        # The same motion with 2 steps per span (the former default): far outside it. (Not
        # measured on the smoothed motion, whose 23 short screws 2 steps already fit: 17 s of
        # the oracle per Blender for a figure nothing asserted.)
        h.select_only(body)
        assert bpy.ops.screwbender.sweep(steps=2, tolerance=1e6, closed=False) == {"FINISHED"}
        cv, ct = region_arrays(swept_region())
        worst_coarse = distance_along(Motion(poses), probes(cv, ct, 2500), 0.5).max()
        print(f"2 steps: {len(ct)} triangles, measured {worst_coarse:.3e}")
        assert worst_coarse > 10 * tol


def test_area_and_closed_volume_are_blenders_and_the_ui_shows_the_tolerance():
    body = cube()
    long_screw(body)
    h.select_only(body)
    assert bpy.ops.screwbender.sweep(closed=True, voxel_size=0.03) == {"FINISHED"}
    region = swept_region()
    bm = bmesh.new()
    bm.from_mesh(region.data)
    try:
        # The remeshed quads are not planar: the area of the triangles Blender splits them into.
        area = sum(geometry.area_tri(*(loop.vert.co for loop in tri)) for tri in bm.calc_loop_triangles())
        volume = bm.calc_volume(signed=True)
    finally:
        bm.free()
    print(f"\nclosed: area {region['screwbender_area']:.5f} (bmesh {area:.5f}), "
          f"volume {region['screwbender_volume']:.5f} (bmesh {volume:.5f})")
    assert region["screwbender_area"] == pytest.approx(area, rel=1e-6)
    assert region["screwbender_volume"] == pytest.approx(volume, rel=1e-5)  # bmesh sums in float32
    assert volume > 1.0  # more than the cube itself
    props = bpy.ops.screwbender.sweep.get_rna_type().properties
    assert props["tolerance"].subtype == "DISTANCE"
    assert props["steps"].is_hidden
    assert props["cell"].is_hidden and props["closed"].default
    # An open result has an area, no volume.
    h.select_only(body)
    assert bpy.ops.screwbender.sweep(closed=False) == {"FINISHED"}
    assert "screwbender_volume" not in swept_region()
    assert swept_region()["screwbender_area"] > 0.0
