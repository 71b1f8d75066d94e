"""Test bodies shared by the sweep benchmarks (numpy only, so they load inside Blender too),
and the playback that takes the most samples per span (`spinning_playback`)."""

from __future__ import annotations

import numpy as np


def torus(n: int, m: int, big: float = 0.6, small: float = 0.22, bumps: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """A torus of `n x m` quads about z (radii `big` and `small`, the tube's radius scaled by
    ``1 + bumps sin(5 u) cos(3 w)``): vertices (n m, 3), whose ring `i` at angle ``u = 2 pi i / n``
    is vertices ``i m .. i m + m - 1``, and outward triangles (2 n m, 3) int64."""
    u = 2 * np.pi * np.arange(n) / n
    w = 2 * np.pi * np.arange(m) / m
    uu, ww = np.meshgrid(u, w, indexing="ij")
    s = small * (1.0 + bumps * np.sin(5 * uu) * np.cos(3 * ww))
    r = big + s * np.cos(ww)
    v = np.stack([r * np.cos(uu), r * np.sin(uu), s * np.sin(ww)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    i, j = i.ravel(), j.ravel()
    a, b = i * m + j, ((i + 1) % n) * m + j
    c, d = ((i + 1) % n) * m + (j + 1) % m, i * m + (j + 1) % m
    return v, np.vstack([np.c_[a, b, c], np.c_[a, c, d]]).astype(np.int64)


def bumpy_torus(n: int, m: int) -> tuple[np.ndarray, np.ndarray]:
    """The bumpy torus of benches/sweep.rs with `n x m` quads: vertices (n m, 3) and outward
    triangles (2 n m, 3) int64."""
    return torus(n, m, bumps=0.25)


def spinning_playback(k: int):
    """A `polyscrew.Playback` of nine LINEAR curves over `k` keys one frame apart, the three
    Euler angles turning 10,000 radians per frame, and its key frames: every span takes
    `polyscrew.MAX_SPAN_SAMPLES` samples in `analyse_spans`."""
    import polyscrew as ps

    f = np.arange(k, dtype=float)
    cols = [(p, i) for p in ("location", "rotation_euler", "scale") for i in range(3)]
    values = {"location": 0.1 * f, "rotation_euler": 1e4 * f, "scale": 1 + 0 * f}
    co = np.concatenate([np.stack([f, values[p]], 1) for p, _ in cols])
    n = len(co)
    pb = ps.Playback(channels=cols, unkeyed=np.array([0, 0, 0, 0, 0, 0, 1, 1, 1.0]), mode="XYZ",
                     offsets=np.arange(0, n + 1, k), co=co, handle_left=co - [1, 0], handle_right=co + [1, 0],
                     interpolation=np.full(n, ps.INTERPOLATIONS.index("LINEAR")), easing=np.zeros(n, int))
    return pb, f
