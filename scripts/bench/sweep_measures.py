"""Measures of a swept region's mesh, shared by scripts/bench/bench_sweep_cases.py and by
scripts/bench/bench_sweep_peers.py, tested in tests/python/test_sweep_measures.py (numpy and scipy
only): surface samples, winding numbers, the directed Hausdorff distances between two point sets,
degenerate and self-intersecting faces, and the reference
surface of a region (marching cubes of the minimum over dense poses of the body's signed
distance, evaluated only near the boundary)."""

from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree


def sample_surface(v: np.ndarray, t: np.ndarray, spacing: float, seed: int = 0, cap: int = 3_000_000,
                   faces: bool = False):
    """Points on the triangles (about one per `spacing`^2 of area, at least each triangle's
    centroid, at most `cap` in all besides the centroids), uniform in each triangle; with
    `faces`, also the triangle of each point."""
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    area = 0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1)
    want = area.sum() / spacing**2
    scale = min(1.0, cap / max(want, 1.0))
    rng = np.random.default_rng(seed)
    counts = rng.poisson(area / spacing**2 * scale)
    idx = np.repeat(np.arange(len(t)), counts)
    r1, r2 = rng.random(len(idx)), rng.random(len(idx))
    flip = r1 + r2 > 1
    r1[flip], r2[flip] = 1 - r1[flip], 1 - r2[flip]
    pts = a[idx] + r1[:, None] * (b[idx] - a[idx]) + r2[:, None] * (c[idx] - a[idx])
    out = np.concatenate([(a + b + c) / 3, pts])
    return (out, np.concatenate([np.arange(len(t)), idx])) if faces else out


def winding_numbers(v: np.ndarray, t: np.ndarray, points: np.ndarray, chunk: int = 1 << 20) -> np.ndarray:
    """The closed mesh `(v, t)`'s winding number about each of `points`: its triangles' solid
    angles seen from the point (Van Oosterom and Strackee), summed, over 4 pi; about `chunk`
    point-triangle pairs at a time."""
    points = np.asarray(points, float)
    out = np.empty(len(points))
    step = max(1, chunk // max(1, len(t)))
    for lo in range(0, len(points), step):
        p = points[lo:lo + step, None, :]
        a, b, c = (v[t[:, k]][None] - p for k in range(3))
        la, lb, lc = (np.linalg.norm(x, axis=2) for x in (a, b, c))
        num = np.einsum("pij,pij->pi", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("pij,pij->pi", a, b) * lc + np.einsum("pij,pij->pi", b, c) * la
               + np.einsum("pij,pij->pi", c, a) * lb)
        out[lo:lo + step] = 2 * np.arctan2(num, den).sum(axis=1) / (4 * np.pi)
    return out


def point_triangle_distance(p: np.ndarray, a: np.ndarray, b: np.ndarray, c: np.ndarray) -> np.ndarray:
    """Row-wise distance from points `p` to triangles `abc` (the closest point by the triangle's
    Voronoi regions: Ericson, Real-Time Collision Detection, 5.1.5)."""
    ab, ac, ap = b - a, c - a, p - a
    d1, d2 = np.einsum("ij,ij->i", ab, ap), np.einsum("ij,ij->i", ac, ap)
    bp = p - b
    d3, d4 = np.einsum("ij,ij->i", ab, bp), np.einsum("ij,ij->i", ac, bp)
    cp = p - c
    d5, d6 = np.einsum("ij,ij->i", ab, cp), np.einsum("ij,ij->i", ac, cp)
    va, vb, vc = d3 * d6 - d5 * d4, d5 * d2 - d1 * d6, d1 * d4 - d3 * d2
    with np.errstate(divide="ignore", invalid="ignore"):
        denom = va + vb + vc
        v_in, w_in = vb / denom, vc / denom
        closest = a + v_in[:, None] * ab + w_in[:, None] * ac
        t_ab = d1 / (d1 - d3)
        t_ac = d2 / (d2 - d6)
        t_bc = (d4 - d3) / ((d4 - d3) + (d5 - d6))
    choices = [
        (d1 <= 0) & (d2 <= 0), (d3 >= 0) & (d4 <= d3), (d6 >= 0) & (d5 <= d6),
        (vc <= 0) & (d1 >= 0) & (d3 <= 0), (vb <= 0) & (d2 >= 0) & (d6 <= 0),
        (va <= 0) & ((d4 - d3) >= 0) & ((d5 - d6) >= 0),
    ]
    points = [a, b, c, a + t_ab[:, None] * ab, a + t_ac[:, None] * ac, b + t_bc[:, None] * (c - b)]
    done = np.zeros(len(p), dtype=bool)
    for cond, q in zip(choices, points):
        use = cond & ~done
        closest[use] = q[use]
        done |= use
    dist = np.linalg.norm(p - closest, axis=1)
    bad = ~np.isfinite(dist)  # a degenerate triangle: its nearest vertex
    if bad.any():
        dist[bad] = np.min([np.linalg.norm(x[bad] - p[bad], axis=1) for x in (a, b, c)], axis=0)
    return dist


def distance_to_mesh(points: np.ndarray, v: np.ndarray, t: np.ndarray, samples: np.ndarray, faces: np.ndarray,
                     k: int = 8, chunk: int = 1 << 18) -> np.ndarray:
    """The distance from each point to the mesh `v, t`: the least exact distance to the triangles
    of its `k` nearest surface `samples` (`faces`: their triangles), so never below the true
    distance and equal to it unless the nearest triangle holds none of those samples."""
    tree = cKDTree(samples)
    out = np.empty(len(points))
    for s in range(0, len(points), chunk):
        p = points[s:s + chunk]
        _, near = tree.query(p, k=k)
        tri = t[faces[near]].reshape(-1, 3)
        rep = np.repeat(p, k, axis=0)
        out[s:s + chunk] = point_triangle_distance(rep, v[tri[:, 0]], v[tri[:, 1]], v[tri[:, 2]]).reshape(-1, k).min(1)
    return out


def hausdorff(a: np.ndarray, b: np.ndarray, tree_b: cKDTree | None = None) -> tuple[float, float]:
    """Directed Hausdorff distances ``(max_a min_b |a - b|, max_b min_a |a - b|)`` between two
    point sets (N, 3) and (M, 3), by a k-d tree each way (`tree_b`: one already built on `b`).
    The two-sided Hausdorff distance is the larger of the two."""
    a, b = np.asarray(a, float), np.asarray(b, float)
    if len(a) == 0 or len(b) == 0:
        raise ValueError("hausdorff: both point sets must be non-empty")
    ab = (tree_b if tree_b is not None else cKDTree(b)).query(a, k=1)[0].max()
    ba = cKDTree(a).query(b, k=1)[0].max()
    return float(ab), float(ba)


def degenerate_faces(v: np.ndarray, t: np.ndarray, rel: float = 1e-12) -> int:
    """Faces with a repeated vertex or (almost) no area: twice the area below `rel` times the
    longest edge squared."""
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    longest = np.max([np.sum((b - a) ** 2, 1), np.sum((c - b) ** 2, 1), np.sum((a - c) ** 2, 1)], axis=0)
    twice = np.linalg.norm(np.cross(b - a, c - a), axis=1)
    same = (t[:, 0] == t[:, 1]) | (t[:, 1] == t[:, 2]) | (t[:, 2] == t[:, 0])
    return int(np.count_nonzero(same | (twice <= rel * longest)))


def _candidate_pairs(lo: np.ndarray, hi: np.ndarray, cell: float) -> np.ndarray:
    """Pairs (i < j) of boxes sharing a cell of a uniform grid of size `cell` and overlapping."""
    ilo, ihi = np.floor(lo / cell).astype(np.int64), np.floor(hi / cell).astype(np.int64)
    span = ihi - ilo + 1
    ids, keys = [], []
    base = ilo - ilo.min(axis=0)
    dims = base.max(axis=0) + span.max(axis=0) + 1
    for dx in range(int(span[:, 0].max())):
        for dy in range(int(span[:, 1].max())):
            for dz in range(int(span[:, 2].max())):
                sel = np.nonzero((span[:, 0] > dx) & (span[:, 1] > dy) & (span[:, 2] > dz))[0]
                cx, cy, cz = base[sel, 0] + dx, base[sel, 1] + dy, base[sel, 2] + dz
                ids.append(sel)
                keys.append((cx * dims[1] + cy) * dims[2] + cz)
    ids, keys = np.concatenate(ids), np.concatenate(keys)
    order = np.argsort(keys, kind="stable")
    ids, keys = ids[order], keys[order]
    pairs = []
    for k in range(1, len(keys)):
        same = np.nonzero(keys[k:] == keys[:-k])[0]
        if len(same) == 0:
            break
        pairs.append(np.stack([ids[same], ids[same + k]], axis=1))
    if not pairs:
        return np.zeros((0, 2), np.int64)
    p = np.sort(np.concatenate(pairs), axis=1)
    p = np.unique(p[:, 0] * len(lo) + p[:, 1])
    p = np.stack([p // len(lo), p % len(lo)], axis=1)
    overlap = np.all((lo[p[:, 0]] <= hi[p[:, 1]]) & (lo[p[:, 1]] <= hi[p[:, 0]]), axis=1)
    return p[overlap]


def _segments_cross_triangles(p, q, a, b, c, tol):
    """Whether segment pq passes through triangle abc (row-wise), strictly: the ends on
    opposite sides of its plane and the line inside all three edges, each by more than `tol`
    (relative volumes), so touching and coplanar pairs do not count."""
    def vol(w, x, y, z):
        return np.einsum("ij,ij->i", x - w, np.cross(y - w, z - w))

    scale = np.max(np.abs(np.concatenate([p, q, a, b, c], axis=1)), axis=1) + 1e-300
    s = scale**3 * tol
    dp, dq = vol(a, b, c, p), vol(a, b, c, q)
    sides = ((dp > s) & (dq < -s)) | ((dp < -s) & (dq > s))
    e1, e2, e3 = vol(p, q, a, b), vol(p, q, b, c), vol(p, q, c, a)
    inside = ((e1 > s) & (e2 > s) & (e3 > s)) | ((e1 < -s) & (e2 < -s) & (e3 < -s))
    return sides & inside


def self_intersecting_faces(v: np.ndarray, t: np.ndarray, tol: float = 1e-12, chunk: int = 1 << 20) -> int:
    """How many faces cross another face of the mesh: pairs found on a uniform grid (cell: the
    95th percentile of the faces' box sizes), faces that share a vertex skipped, and a pair
    counted when an edge of one passes strictly through the other (float64 orientation tests,
    `tol` relative: touching and coplanar contacts are not counted)."""
    if len(t) < 2:
        return 0
    tri = v[t]
    lo, hi = tri.min(axis=1), tri.max(axis=1)
    size = np.max(hi - lo, axis=1)
    cell = max(float(np.percentile(size, 95)), 1e-12)
    big = size > 4 * cell  # a few long faces: against every other face's box directly
    pairs = [_candidate_pairs(lo[~big], hi[~big], cell)]
    small_ids = np.nonzero(~big)[0]
    pairs[0] = small_ids[pairs[0]]
    for i in np.nonzero(big)[0]:
        j = np.nonzero(np.all((lo <= hi[i]) & (lo[i] <= hi), axis=1))[0]
        j = j[j != i]
        pairs.append(np.stack([np.minimum(i, j), np.maximum(i, j)], axis=1))
    p = np.concatenate(pairs)
    p = np.unique(p[:, 0] * len(t) + p[:, 1])
    p = np.stack([p // len(t), p % len(t)], axis=1)
    shared = (t[p[:, 0]][:, :, None] == t[p[:, 1]][:, None, :]).any(axis=(1, 2))
    p = p[~shared]
    hit = np.zeros(len(t), dtype=bool)
    for s in range(0, len(p), chunk):
        i, j = p[s:s + chunk, 0], p[s:s + chunk, 1]
        found = np.zeros(len(i), dtype=bool)
        for x, y in ((i, j), (j, i)):
            tx, ty = tri[x], tri[y]
            for k in range(3):
                found |= _segments_cross_triangles(tx[:, k], tx[:, (k + 1) % 3], ty[:, 0], ty[:, 1], ty[:, 2], tol)
        hit[i[found]] = True
        hit[j[found]] = True
    return int(np.count_nonzero(hit))


def region_surface(sd, body_box: np.ndarray, poses: np.ndarray, h: float, leaf: int = 4, top: int = 64,
                   with_projection: bool = True):
    """The boundary of the union of the body over `poses` (4 x 4, body -> world): marching cubes
    (scikit-image) of ``min over poses of sd(pose^-1 x)`` on a grid of spacing `h`, evaluated only
    in blocks of `leaf` cells that the boundary may cross. `sd` is the body's exact signed
    distance (1-Lipschitz) of body-frame points (..., 3); `body_box` (2, 3) its bounding box.

    A block (centre c, half diagonal r) is skipped when ``|min_p sd_p(c)| > r + h`` (no crossing
    in it), and a pose dropped from it when ``sd_p(c) > min(m + 2 r, 2 h + r)`` (it cannot be the
    minimum there, or not below `2 h`); the values are clamped to +-2 h, which leaves the zero set
    unchanged. Returns (vertices, triangles, blocks evaluated): the pieces of the blocks, consistently
    oriented, meeting on the blocks' shared faces (their vertices there repeated, not welded)."""
    from skimage.measure import marching_cubes

    corners = np.array([(x, y, z) for x in (0, 1) for y in (0, 1) for z in (0, 1)], float)
    box = body_box[0] + corners * (body_box[1] - body_box[0])
    world = np.einsum("pij,nj->pni", poses[:, :3, :3], box) + poses[:, None, :3, 3]
    lo = world.reshape(-1, 3).min(axis=0) - 3 * h
    n = np.ceil((world.reshape(-1, 3).max(axis=0) + 3 * h - lo) / h).astype(int)
    inv = np.linalg.inv(poses)
    rot, shift = inv[:, :3, :3], inv[:, :3, 3]
    clip = 2 * h

    def field(points, which):  # (N, 3) world points, pose indices -> min over them, clamped
        best = np.full(len(points), np.inf)
        for s in range(0, len(which), 64):
            w = which[s:s + 64]
            local = np.einsum("pij,nj->pni", rot[w], points) + shift[w][:, None]
            best = np.minimum(best, sd(local).min(axis=0))
        return np.clip(best, -clip, clip)

    def project(points, which, steps=4):  # Newton steps onto the zero set of the minimum
        for _ in range(steps):
            local = np.einsum("pij,nj->npi", rot[which], points) + shift[which][None]
            vals = sd(local)
            k = vals.argmin(axis=1)
            f = vals[np.arange(len(points)), k]
            r_k, s_k = rot[which][k], shift[which][k]
            grad = np.empty_like(points)
            for axis in range(3):
                e = np.zeros(3)
                e[axis] = 1e-7 * h
                up = sd(np.einsum("nij,nj->ni", r_k, points + e) + s_k)
                down = sd(np.einsum("nij,nj->ni", r_k, points - e) + s_k)
                grad[:, axis] = (up - down) / 2e-7 / h
            points = points - (f / np.maximum(np.sum(grad**2, axis=1), 1e-12))[:, None] * grad
        return points

    verts, faces, on, count, total = [], [], [], 0, 0

    stack = [(np.array([i, j, k]) * top, top, np.arange(len(poses)))
             for i in range(-(-n[0] // top)) for j in range(-(-n[1] // top)) for k in range(-(-n[2] // top))]
    while stack:
        idx, size, which = stack.pop()
        c = lo + (idx + size / 2) * h
        r = size * h * np.sqrt(3) / 2
        d = sd(np.einsum("pij,j->pi", rot[which], c) + shift[which])
        m = d.min()
        if m - r > h or m + r < -h:
            continue
        which = which[d <= min(m + 2 * r, clip + r)]
        if size > leaf:
            half = size // 2
            stack += [(idx + half * np.array(o), half, which) for o in corners.astype(int)]
            continue
        count += 1
        g = np.stack(np.meshgrid(*[np.arange(size + 1)] * 3, indexing="ij"), axis=-1).reshape(-1, 3)
        vals = field(lo + (idx + g) * h, which).reshape(size + 1, size + 1, size + 1)
        if vals.min() >= 0 or vals.max() <= 0:
            continue
        pv, pf, _, _ = marching_cubes(vals, 0.0, spacing=(h, h, h))
        faces.append(pf + total)
        total += len(pv)
        verts.append(pv + lo + idx * h)
        if with_projection:
            on.append(project(verts[-1], which))
    if not faces:
        return np.zeros((0, 3)), np.zeros((0, 3), np.int64), np.zeros((0, 3)), count
    return (np.concatenate(verts), np.concatenate(faces).astype(np.int64),
            np.concatenate(on) if on else np.zeros((0, 3)), count)
