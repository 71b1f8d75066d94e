"""`polyscrew.sweep`'s tolerance (issue 29, item 1) and the add-on's sweep report (item 3).

- `tolerance=None` is 0.2 % of the body's bounding radius, a float is a length, 0 is exactly
  `steps` per screw; `steps` stays a minimum; `info` reports the bound met;
- the bound holds against an independent reference: the screw between two poses as the
  matrix exponential of `scipy.linalg.logm` of their relative transform (sampled densely) and
  the box's exact signed distance;
- `sweep_report.measures`: area and volume of a closed mesh against scipy's convex hull.
"""

from __future__ import annotations

import math

import numpy as np
import polyscrew
import pytest
import scipy.linalg
from scipy.spatial import ConvexHull
from scipy.spatial.transform import Rotation

from pure_layer import module
from screws import screw_matrix  # (tests/fixtures)

sweep_report = module("sweep_report")  # the add-on's pure layer: no bpy

CUBE_V = np.array([(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
CUBE_T = np.array([[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4], [2, 6, 3], [3, 6, 7],
                   [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]])



LONG = np.array([np.eye(4), screw_matrix((0.3, 0.2, 1.0), (0.5, -1.0, 0.0), 2 * math.pi / 3, 1.0)])


def sd_box(local):
    q = np.abs(local - 0.5) - 0.5
    return np.linalg.norm(np.maximum(q, 0.0), axis=-1) + np.minimum(q.max(axis=-1), 0.0)


def screw_poses(a, b, ts):
    """`expm(t logm(b a^-1)) a` for every t of `ts` (K, 4, 4): the SE(3) exponential in closed
    form (Rodrigues and the left Jacobian), checked against `scipy.linalg.expm`."""
    xi = scipy.linalg.logm(b @ np.linalg.inv(a)).real
    w, v = np.array([xi[2, 1], xi[0, 2], xi[1, 0]]), xi[:3, 3]
    wx = xi[:3, :3]
    th = np.linalg.norm(w) * ts
    c1 = (1 - np.cos(th)) / np.where(th > 0, th, 1) ** 2
    c2 = (th - np.sin(th)) / np.where(th > 0, th, 1) ** 3
    tw = ts[:, None, None] * wx
    jac = np.eye(3) + c1[:, None, None] * tw + c2[:, None, None] * tw @ tw
    m = np.zeros((len(ts), 4, 4))
    m[:, :3, :3] = Rotation.from_rotvec(ts[:, None] * w).as_matrix()
    m[:, :3, 3] = np.einsum("kij,j->ki", jac, v) * ts[:, None]
    m[:, 3, 3] = 1.0
    for k in (1, len(ts) // 2, len(ts) - 1):
        assert np.allclose(m[k], scipy.linalg.expm(ts[k] * xi), atol=1e-9)
    return m @ a


def worst_distance(sv, st, a, b, samples=20000):
    """Largest, over corners, edge midpoints and centroids (1,500 of them), of the least
    |signed distance| to the cube over `samples` poses `expm(t logm(b a^-1)) a`."""
    p0, p1, p2 = sv[st[:, 0]], sv[st[:, 1]], sv[st[:, 2]]
    pts = np.unique(np.concatenate([p0, p1, p2, (p0 + p1) / 2, (p1 + p2) / 2, (p2 + p0) / 2, (p0 + p1 + p2) / 3]), axis=0)
    pts = pts[np.random.default_rng(1).choice(len(pts), min(len(pts), 1500), replace=False)]
    inv = np.linalg.inv(screw_poses(a, b, np.linspace(0.0, 1.0, samples)))
    best = np.full(len(pts), np.inf)
    for lo in range(0, samples, 250):
        chunk = inv[lo:lo + 250]
        local = np.einsum("pij,nj->pni", chunk[:, :3, :3], pts) + chunk[:, None, :3, 3]
        best = np.minimum(best, np.abs(sd_box(local)).min(axis=0))
    return best.max()


def test_tolerance_argument_and_info():
    tol = polyscrew.DEFAULT_SWEEP_TOLERANCE * 0.5 * math.sqrt(3)
    sv, st, info = polyscrew.sweep(CUBE_V, CUBE_T, LONG, info=True)
    assert info["tolerance"] == pytest.approx(tol, rel=1e-12)
    assert 0 < info["error_bound"] <= info["tolerance"] and info["max_steps"] > 8
    assert len(polyscrew.sweep(CUBE_V, CUBE_T, LONG)) == 2  # without info: as before
    # 0: exactly `steps`; a coarse tolerance never goes below `steps`.
    for steps in (1, 2, 5):
        _, _, exact = polyscrew.sweep(CUBE_V, CUBE_T, LONG, steps=steps, tolerance=0, info=True)
        assert (exact["max_steps"], exact["tolerance"], exact["error_bound"]) == (steps, 0.0, 0.0)
        _, _, loose = polyscrew.sweep(CUBE_V, CUBE_T, LONG, steps=steps, tolerance=10.0, info=True)
        assert loose["max_steps"] == steps
    # A finer tolerance takes more steps.
    _, _, fine = polyscrew.sweep(CUBE_V, CUBE_T, LONG, tolerance=tol / 10, info=True)
    assert fine["max_steps"] > info["max_steps"] and fine["error_bound"] <= tol / 10
    for bad in (-1.0, math.nan, math.inf):
        with pytest.raises(ValueError, match="tolerance"):
            polyscrew.sweep(CUBE_V, CUBE_T, LONG, tolerance=bad)
    with pytest.raises(TypeError, match="tolerance"):
        polyscrew.sweep(CUBE_V, CUBE_T, LONG, tolerance="fine")
    with pytest.raises(TypeError, match="info"):
        polyscrew.sweep(CUBE_V, CUBE_T, LONG, info="yes")


@pytest.mark.parametrize("tolerance", [None, 0.01])
def test_bound_holds_against_scipy_screws(tolerance):
    sv, st, info = polyscrew.sweep(CUBE_V, CUBE_T, LONG, tolerance=tolerance, info=True)
    worst = worst_distance(sv, st, LONG[0], LONG[1])
    cv, ct = polyscrew.sweep(CUBE_V, CUBE_T, LONG, steps=2, tolerance=0)
    coarse = worst_distance(cv, ct, LONG[0], LONG[1])
    print(f"\ntolerance {info['tolerance']:.3e}: bound {info['error_bound']:.3e}, measured {worst:.3e}, "
          f"{len(st)} triangles, {info['max_steps']} steps; 2 steps: measured {coarse:.3e}, {len(ct)} triangles")
    # The reference's sampling (20,000 poses over 120 degrees, radius < 3) adds < 2e-4.
    assert worst <= info["error_bound"] + 2e-4
    assert coarse > 10 * info["tolerance"]


def test_measures_of_a_closed_mesh_match_scipy():
    rng = np.random.default_rng(3)
    pts = rng.normal(size=(200, 3))
    hull = ConvexHull(pts)
    tris = hull.simplices.copy()
    # Orient every hull triangle outward.
    centre = pts.mean(axis=0)
    a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
    flip = np.einsum("ij,ij->i", np.cross(b - a, c - a), a - centre) < 0
    tris[flip] = tris[flip][:, ::-1]
    m = sweep_report.measures(pts, tris)
    assert m.closed
    assert m.area == pytest.approx(hull.area, rel=1e-12)
    assert m.volume == pytest.approx(hull.volume, rel=1e-12)
    # Turned inside out: negative volume; a hole: open, no volume.
    assert sweep_report.measures(pts, tris[:, ::-1]).volume == pytest.approx(-hull.volume, rel=1e-12)
    opened = sweep_report.measures(pts, tris[1:])
    assert not opened.closed and opened.volume is None
    # Inconsistent orientation is not closed either.
    mixed = tris.copy()
    mixed[0] = mixed[0][::-1]
    assert not sweep_report.is_closed(mixed)


def test_is_closed_agrees_with_a_row_wise_edge_count_on_broken_meshes():
    """`is_closed` packs each directed edge into one integer; a row-wise `np.unique` of the
    edge pairs (the former code, the oracle here) must say the same on closed hulls and on
    each way of breaking them: a hole, a flipped face, a repeated face, a face in a second
    copy shifted to indices beyond the first, large and negative index offsets."""

    from test_sweep_closed import is_closed_oriented as oracle

    rng = np.random.default_rng(7)
    seen = {True: 0, False: 0}
    for trial in range(40):
        pts = rng.normal(size=(30 + trial, 3))
        tris = ConvexHull(pts).simplices.copy()
        a, b, c = pts[tris[:, 0]], pts[tris[:, 1]], pts[tris[:, 2]]
        flip = np.einsum("ij,ij->i", np.cross(b - a, c - a), a - pts.mean(axis=0)) < 0
        tris[flip] = tris[flip][:, ::-1]
        k = rng.integers(len(tris))
        flipped = tris.copy()
        flipped[k] = flipped[k][::-1]
        two = np.concatenate([tris, tris + len(pts)])  # two closed shells: closed
        for t in (tris, tris[1:], flipped, np.concatenate([tris, tris[k : k + 1]]), two, two[:-1],
                  tris + 10**9, tris - 5, np.concatenate([tris, tris])):
            assert sweep_report.is_closed(t) == oracle(t)
            seen[oracle(t)] += 1
    assert seen[True] >= 80 and seen[False] >= 200  # both answers exercised


def test_summary_names_tolerance_area_and_volume():
    text = sweep_report.summary(1, 6536, 0.05, 2.1, 0.00173, 0.00164, 12.3, 5.08)
    assert "tolerance 0.00173 (met within 0.00164)" in text and "area 12.3" in text and "volume 5.08" in text
    assert "volume" not in sweep_report.summary(1, 10, 0.0, 0.1, 0.001, 0.001, 1.0, None)
