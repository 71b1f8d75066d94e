"""Test bodies shared by the sweep benchmarks (numpy only, so they load inside Blender too)."""

from __future__ import annotations

import numpy as np


def bumpy_torus(n: int, m: int) -> tuple[np.ndarray, np.ndarray]:
    """The bumpy torus of benches/sweep.rs with `n x m` quads: vertices (n m, 3) and outward
    triangles (2 n m, 3) int64."""
    u = 2 * np.pi * np.arange(n) / n
    w = 2 * np.pi * np.arange(m) / m
    uu, ww = np.meshgrid(u, w, indexing="ij")
    s = 0.22 * (1.0 + 0.25 * np.sin(5 * uu) * np.cos(3 * ww))
    r = 0.6 + s * np.cos(ww)
    v = np.stack([r * np.cos(uu), r * np.sin(uu), s * np.sin(ww)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    i, j = i.ravel(), j.ravel()
    a, b = i * m + j, ((i + 1) % n) * m + j
    c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
    return v, np.vstack([np.c_[a, b, c], np.c_[a, c, d]]).astype(np.int64)
