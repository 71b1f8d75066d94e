"""A small orthographic z-buffer rasterizer for the swept-region tests (numpy + numba).

Depth images: ``inf`` where nothing is covered, otherwise the smallest ``p . forward`` over
the triangles covering the pixel centre (the viewer looks along ``forward``). Pixel centres
are at half-integers; a pixel is covered when its centre is inside the triangle (edges
inclusive to a 1e-9 tolerance in barycentric coordinates, so shared edges leave no cracks).
Written for the tests only: an oracle independent of the Rust code.
"""

from __future__ import annotations

import numpy as np
from numba import njit, prange

#: Barycentric slack that closes cracks along shared edges.
INSIDE_SLACK = 1e-9


class View:
    """An orthographic camera looking along ``forward`` at a square window of ``size``
    (world units) centred on ``center``, ``res`` pixels wide."""

    def __init__(self, forward, center, size: float, res: int):
        f = np.asarray(forward, float)
        f = f / np.linalg.norm(f)
        helper = np.array([0.0, 0.0, 1.0]) if abs(f[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
        right = np.cross(f, helper)
        right /= np.linalg.norm(right)
        up = np.cross(right, f)  # right x up = -forward: counter-clockwise on screen = facing us
        self.forward, self.right, self.up = f, right, up
        self.res = res
        scale = res / size
        c = np.asarray(center, float)
        # screen = M @ [p, 1]: x, y in pixels, z depth.
        self.matrix = np.zeros((3, 4))
        self.matrix[0, :3] = right * scale
        self.matrix[0, 3] = -right @ c * scale + res / 2
        self.matrix[1, :3] = up * scale
        self.matrix[1, 3] = -up @ c * scale + res / 2
        self.matrix[2, :3] = f
        self.matrix[2, 3] = 0.0

    def empty(self) -> np.ndarray:
        return np.full((self.res, self.res), np.inf)


@njit(cache=True, fastmath=False)
def _raster(sx, sy, sz, tris, depth, cull):
    h, w = depth.shape
    for t in range(tris.shape[0]):
        i0, i1, i2 = tris[t, 0], tris[t, 1], tris[t, 2]
        x0, y0, z0 = sx[i0], sy[i0], sz[i0]
        x1, y1, z1 = sx[i1], sy[i1], sz[i1]
        x2, y2, z2 = sx[i2], sy[i2], sz[i2]
        area = (x1 - x0) * (y2 - y0) - (x2 - x0) * (y1 - y0)
        if area == 0.0 or (cull and area < 0.0):
            continue
        xmin = max(int(np.ceil(min(x0, x1, x2) - 0.5)), 0)
        xmax = min(int(np.floor(max(x0, x1, x2) - 0.5)), w - 1)
        ymin = max(int(np.ceil(min(y0, y1, y2) - 0.5)), 0)
        ymax = min(int(np.floor(max(y0, y1, y2) - 0.5)), h - 1)
        inv = 1.0 / area
        for y in range(ymin, ymax + 1):
            cy = y + 0.5
            for x in range(xmin, xmax + 1):
                cx = x + 0.5
                w0 = ((x1 - cx) * (y2 - cy) - (x2 - cx) * (y1 - cy)) * inv
                w1 = ((x2 - cx) * (y0 - cy) - (x0 - cx) * (y2 - cy)) * inv
                w2 = 1.0 - w0 - w1
                if w0 >= -1e-9 and w1 >= -1e-9 and w2 >= -1e-9:
                    z = w0 * z0 + w1 * z1 + w2 * z2
                    if z < depth[y, x]:
                        depth[y, x] = z


@njit(cache=True)
def _raster_instances(verts, tris, mats, depth, cull):
    n = verts.shape[0]
    sx = np.empty(n)
    sy = np.empty(n)
    sz = np.empty(n)
    for k in range(mats.shape[0]):
        m = mats[k]
        for i in range(n):
            px, py, pz = verts[i, 0], verts[i, 1], verts[i, 2]
            sx[i] = m[0, 0] * px + m[0, 1] * py + m[0, 2] * pz + m[0, 3]
            sy[i] = m[1, 0] * px + m[1, 1] * py + m[1, 2] * pz + m[1, 3]
            sz[i] = m[2, 0] * px + m[2, 1] * py + m[2, 2] * pz + m[2, 3]
        _raster(sx, sy, sz, tris, depth, cull)


@njit(cache=True, parallel=True)
def _raster_instances_views(verts, tris, mats, depth, cull):
    # mats (views, instances, 3, 4); depth (views, res, res): one view per thread.
    for k in prange(mats.shape[0]):
        _raster_instances(verts, tris, mats[k], depth[k], cull)


def instances_depth_images(views: list[View], vertices, triangles, poses, cull: bool = True) -> list[np.ndarray]:
    """:func:`instances_depth_image` for several views at once, in parallel over the views."""
    poses = np.asarray(poses, float)
    mats = np.stack([np.einsum("ij,mjk->mik", v.matrix, poses) for v in views])
    depth = np.stack([v.empty() for v in views])
    _raster_instances_views(
        np.ascontiguousarray(vertices, dtype=float),
        np.ascontiguousarray(triangles, dtype=np.int64),
        np.ascontiguousarray(mats),
        depth,
        cull,
    )
    return list(depth)


def depth_image(view: View, vertices, triangles, cull: bool = False) -> np.ndarray:
    """Depth image of one mesh (world coordinates)."""
    v = np.asarray(vertices, float)
    s = v @ view.matrix[:, :3].T + view.matrix[:, 3]
    depth = view.empty()
    _raster(
        np.ascontiguousarray(s[:, 0]),
        np.ascontiguousarray(s[:, 1]),
        np.ascontiguousarray(s[:, 2]),
        np.ascontiguousarray(triangles, dtype=np.int64),
        depth,
        cull,
    )
    return depth


def instances_depth_image(view: View, vertices, triangles, poses, cull: bool = True) -> np.ndarray:
    """Depth image of the union of the body ``(vertices, triangles)`` placed at every pose
    of ``poses`` (M, 4, 4). Back faces are culled (exact for closed outward meshes)."""
    poses = np.asarray(poses, float)
    mats = np.einsum("ij,mjk->mik", view.matrix, poses)  # (M, 3, 4): body -> screen
    depth = view.empty()
    _raster_instances(
        np.ascontiguousarray(vertices, dtype=float),
        np.ascontiguousarray(triangles, dtype=np.int64),
        np.ascontiguousarray(mats),
        depth,
        cull,
    )
    return depth


def fibonacci_directions(n: int) -> np.ndarray:
    """``n`` unit vectors spread evenly over the sphere."""
    i = np.arange(n) + 0.5
    z = 1.0 - 2.0 * i / n
    phi = np.pi * (1.0 + 5**0.5) * i
    r = np.sqrt(1.0 - z * z)
    return np.stack([r * np.cos(phi), r * np.sin(phi), z], axis=1)
