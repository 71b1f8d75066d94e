"""`polyscrew.sweep_closed`: the swept region's boundary, closed and exact within its bound
(issue 29, item 2).

Independent references: the screw between two poses as the matrix exponential of
`scipy.linalg.logm` (test_sweep_tolerance's `screw_poses`), sampled densely; the bodies' exact
signed distances in closed form (a box; the L-prism as the union of two boxes; a torus, whose
polygon mesh lies within `TORUS_SAG` of it); the region's signed distance as the minimum over
the poses. Checked: every edge used once in each direction (closed, consistently oriented),
every vertex within the reported bound of the boundary, and the volume within 0.5 % of the
region's volume counted on a jittered grid (one sample per cell, inside when the minimum over
the motion is negative, refined where the coarse motion leaves it in doubt).
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numpy as np
import polyscrew
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from screws import screw_matrix  # noqa: E402  (tests/fixtures)
from test_sweep_tolerance import CUBE_T, CUBE_V, screw_poses  # noqa: E402


def box_sd(local, lo, hi):
    c, half = (lo + hi) / 2, (hi - lo) / 2
    q = np.abs(local - c) - half
    return np.linalg.norm(np.maximum(q, 0.0), axis=-1) + np.minimum(q.max(axis=-1), 0.0)


def cube_sd(local):
    return box_sd(local, np.zeros(3), np.ones(3))


L_H = 0.5


def l_prism():
    """The L (0,0) (2,0) (2,1) (1,1) (1,2) (0,2) extruded by `L_H` (outward triangles)."""
    ring = [(0, 0), (2, 0), (2, 1), (1, 1), (1, 2), (0, 2)]
    v = np.array([(x, y, 0.0) for x, y in ring] + [(x, y, L_H) for x, y in ring])
    t = []
    for a, b in [(4, 5), (5, 0), (0, 1), (1, 2)]:
        t += [[3, b, a], [9, a + 6, b + 6]]
    for i in range(6):
        j = (i + 1) % 6
        t += [[i, j, j + 6], [i, j + 6, i + 6]]
    return v, np.array(t)


def l_sd(local):
    """The union of the two boxes: exact outside, its sign right inside."""
    return np.minimum(box_sd(local, np.zeros(3), np.array([2.0, 1.0, L_H])),
                      box_sd(local, np.zeros(3), np.array([1.0, 2.0, L_H])))


TORUS_R, TORUS_r, TORUS_N, TORUS_M = 0.6, 0.22, 64, 32
#: The polygon torus lies within this of the smooth one (the sagittas of both circles).
TORUS_SAG = (TORUS_R + TORUS_r) * (1 - math.cos(math.pi / TORUS_N)) + TORUS_r * (1 - math.cos(math.pi / TORUS_M))


def torus():
    u = 2 * np.pi * np.arange(TORUS_N) / TORUS_N
    w = 2 * np.pi * np.arange(TORUS_M) / TORUS_M
    uu, ww = np.meshgrid(u, w, indexing="ij")
    r = TORUS_R + TORUS_r * np.cos(ww)
    v = np.stack([r * np.cos(uu), r * np.sin(uu), TORUS_r * np.sin(ww)], axis=-1).reshape(-1, 3)
    idx = lambda i, j: (i % TORUS_N) * TORUS_M + (j % TORUS_M)  # noqa: E731
    t = []
    for i in range(TORUS_N):
        for j in range(TORUS_M):
            t += [[idx(i, j), idx(i + 1, j), idx(i + 1, j + 1)], [idx(i, j), idx(i + 1, j + 1), idx(i, j + 1)]]
    return v, np.array(t)


def torus_sd(local):
    q = np.stack([np.linalg.norm(local[..., :2], axis=-1) - TORUS_R, local[..., 2]], axis=-1)
    return np.linalg.norm(q, axis=-1) - TORUS_r


LONG = np.array([np.eye(4), screw_matrix((0.0, 0.0, 1.0), (3.0, 0.5, 0.0), 2 * math.pi / 3, 1.0)])
HALF = np.array([np.eye(4), screw_matrix((0.3, 0.2, 1.0), (3.0, 0.0, 0.0), 0.999 * math.pi, 0.5)])
KEYS = np.array([np.eye(4), screw_matrix((0.2, 1, 0.3), (1, 0, 0), 1.1, 0.4),
                 screw_matrix((1, -0.3, 0.5), (0.5, 2, 0), 2.2, 1.0), screw_matrix((-0.4, 0.2, 1), (2, 1, 1), 3.0, 2.0)])
SMOOTH = polyscrew.subdivide(KEYS, "four_point", levels=3, closed=False)

#: name: (vertices, triangles, signed distance, poses, the body's own error, the cell as a
#: fraction of the body's extent: None for the former default, 1.5 %). The L-prism at the default cell (1.5 %)
#: is 0.64 % short in volume (its many sharp creases are cut by the flat faces): 1 % holds 0.5 %.
CASES = {
    "cube, 120-degree screw with slide": (CUBE_V, CUBE_T, cube_sd, LONG, 0.0, None),
    "L-prism, half turn": (*l_prism(), l_sd, HALF, 0.0, 0.01),
    "cube, smoothed polyscrew": (CUBE_V, CUBE_T, cube_sd, SMOOTH, 0.0, None),
    "torus, smoothed polyscrew": (*torus(), torus_sd, SMOOTH, TORUS_SAG, None),
}


#: The reference volume's grid cell, as a fraction of the body's extent (one jittered sample
#: per cell: the count's error is about the square root of the boundary cells' count times
#: half a cell's volume, below 0.1 % here).
REFERENCE_CELL = 0.03


def dense(poses, per_span):
    """The motion's poses, `per_span` intervals per screw (scipy's expm of logm)."""
    ts = np.linspace(0.0, 1.0, per_span + 1)[:-1]
    return np.concatenate([screw_poses(a, b, ts) for a, b in zip(poses[:-1], poses[1:])] + [poses[-1:]])


def region_sd(points, inv, sd, poses_per_chunk=16, points_per_chunk=1 << 16):
    """min over the poses (world -> body `inv`) of the body's signed distance at `points`."""
    best = np.full(len(points), np.inf)
    for start in range(0, len(points), points_per_chunk):
        part = points[start:start + points_per_chunk]
        for lo in range(0, len(inv), poses_per_chunk):
            m = inv[lo:lo + poses_per_chunk]
            local = np.swapaxes(m[:, :3, :3] @ part.T, 1, 2) + m[:, None, :3, 3]
            best[start:start + len(part)] = np.minimum(best[start:start + len(part)], sd(local).min(axis=0))
    return best


def is_closed_oriented(t):
    directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    forward, counts = np.unique(directed, axis=0, return_counts=True)
    backward = np.unique(directed[:, ::-1], axis=0)
    return bool(np.all(counts == 1)) and len(backward) == len(forward) and bool(np.all(backward == forward))


def mesh_volume(v, t):
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def crossings(points, inv, sd, poses_per_chunk=16, points_per_chunk=1 << 15):
    """Where the motion sampled at `inv` (world -> body) may take `points` inside the body.

    Returns (inside, undecided): inside when the body's signed distance is negative at a
    sampled pose; undecided when it is not, but some interval between two consecutive poses
    may still reach inside: a body-frame point moves along its screw by no more than the chord
    between the interval's ends, and `sd` is 1-Lipschitz, so along the interval `sd` stays above
    the larger of its two end values less that chord."""
    inside = np.zeros(len(points), dtype=bool)
    undecided = np.zeros(len(points), dtype=bool)
    for start in range(0, len(points), points_per_chunk):
        part = points[start:start + points_per_chunk]
        seen = np.zeros(len(part), dtype=bool)
        near = np.zeros(len(part), dtype=bool)
        for lo in range(0, max(len(inv) - 1, 1), poses_per_chunk):
            m = inv[lo:lo + poses_per_chunk + 1]  # one pose shared with the next chunk
            local = np.swapaxes(m[:, :3, :3] @ part.T, 1, 2) + m[:, None, :3, 3]
            d = sd(local)
            seen |= (d < 0).any(axis=0)
            chord = np.linalg.norm(np.diff(local, axis=0), axis=-1)
            near |= (np.maximum(d[:-1], d[1:]) <= chord).any(axis=0)
        inside[start:start + len(part)] = seen
        undecided[start:start + len(part)] = near & ~seen
    return inside, undecided


def reference_volume(v_body, poses, sd, cell, per_span=(8, 64, 1024)):
    """The region's volume: one jittered sample per grid cell of the region's box, inside when
    the body's signed distance `sd` is negative at a pose of the motion; the motion sampled
    coarsely first, and only the samples that an interval between coarse poses may still take
    inside (`crossings`) decided again on a finer motion, `per_span` intervals per screw at the
    last level."""
    corners = np.array([(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    lo_b, hi_b = v_body.min(axis=0), v_body.max(axis=0)
    body_box = lo_b + corners * (hi_b - lo_b)
    fine = dense(poses, per_span[-1])
    world = np.einsum("pij,nj->pni", fine[:, :3, :3], body_box) + fine[:, None, :3, 3]
    lo, hi = world.reshape(-1, 3).min(axis=0) - cell, world.reshape(-1, 3).max(axis=0) + cell
    shape = np.ceil((hi - lo) / cell).astype(int)
    grid = np.stack(np.meshgrid(*[np.arange(n) for n in shape], indexing="ij"), axis=-1).reshape(-1, 3)
    pts = lo + (grid + np.random.default_rng(3).random(grid.shape)) * cell
    undecided = np.arange(len(pts))
    inside = np.zeros(len(pts), dtype=bool)
    for level, k in enumerate(per_span):
        inv = fine if level + 1 == len(per_span) else dense(poses, k)
        inv = np.linalg.inv(inv)
        hit, maybe = crossings(pts[undecided], inv, sd)
        inside[undecided[hit]] = True
        undecided = undecided[maybe]
    return inside.sum() * cell**3


@pytest.mark.parametrize("name", list(CASES))
def test_closed_boundary_is_closed_exact_and_holds_the_volume(name):
    v, t, sd, poses, body_error, cell_rel = CASES[name]
    extent = np.linalg.norm(v.max(axis=0) - v.min(axis=0))
    start = time.process_time()
    # The cell given (None: the former default, 1.5 %; the tolerance's default is checked in
    # test_sweep_closed_tolerance.py and tests/blender/test_sweep_closed.py), the contoured mesh
    # as it is (Fewer Triangles, the default, is checked against it there). The torus's
    # reference sweeps the smooth torus the body is inscribed in: the contoured mesh is 0.44 %
    # short of it at the 1.5 % cell, and the collapses' chords on its curved parts cut another
    # 0.10 %, over this test's 0.5 % (measured at stop 44).
    cell = (cell_rel or polyscrew.DEFAULT_CLOSED_CELL) * extent
    cv, ct, info = polyscrew.sweep_closed(v, t, poses, cell=cell, info=True, decimate=False)
    cpu = time.process_time() - start
    assert info["cell"] == cell and info["tolerance"] == 0.0 and info["attempts"] == 1
    assert cv.dtype == np.float64 and ct.dtype == np.int64 and ct.min() >= 0 and ct.max() < len(cv)
    assert is_closed_oriented(ct), name
    # Every vertex on the boundary: the region's signed distance at it within the bound.
    sample = cv[np.random.default_rng(0).choice(len(cv), min(len(cv), 1500), replace=False)]
    inv = np.linalg.inv(dense(poses, max(64, 8192 // (len(poses) - 1))))
    worst = np.abs(region_sd(sample, inv, sd)).max()
    volume = mesh_volume(cv, ct)
    reference = reference_volume(v, poses, sd, cell=REFERENCE_CELL * extent)
    print(f"\n{name}: {len(ct)} triangles, cell {info['cell']:.4f}, {info['poses']} poses, cpu {cpu:.2f} s; "
          f"worst vertex {worst:.2e} (bound {info['error_bound']:.2e}, {100 * worst / extent:.2f} % of the extent); "
          f"volume {volume:.4f} against {reference:.4f} ({100 * (volume / reference - 1):+.2f} %)")
    assert worst <= info["vertex_bound"] + body_error and info["vertex_bound"] <= info["error_bound"]
    assert abs(volume / reference - 1) <= 0.005


def test_closed_refusals():
    open_cube = CUBE_T[:-1]
    with pytest.raises(ValueError, match="not closed"):
        polyscrew.sweep_closed(CUBE_V, open_cube, LONG)
    for cell in (0.0, -1.0, float("nan"), 1e-6):
        with pytest.raises(ValueError, match="cell"):
            polyscrew.sweep_closed(CUBE_V, CUBE_T, LONG, cell=cell)
    with pytest.raises(ValueError):
        polyscrew.sweep_closed(CUBE_V, CUBE_T, LONG[:1])


def test_a_finer_cell_is_closer():
    """Halving the cell shrinks the bound and the volume's departure (the cube on the long screw),
    the contoured mesh: the triangles grow as the cell's square."""
    coarse = polyscrew.sweep_closed(CUBE_V, CUBE_T, LONG, cell=0.05, info=True, decimate=False)
    fine = polyscrew.sweep_closed(CUBE_V, CUBE_T, LONG, cell=0.025, info=True, decimate=False)
    assert fine[2]["error_bound"] < coarse[2]["error_bound"]
    assert len(fine[1]) > 3 * len(coarse[1])
    assert is_closed_oriented(coarse[1]) and is_closed_oriented(fine[1])
