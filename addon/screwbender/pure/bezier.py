# SPDX-License-Identifier: GPL-3.0-or-later
"""A Bezier F-curve segment as Blender plays it (its handles corrected), cut at a frame: where a
Frame Range narrower than the keys joins the bake to the source keys kept outside it."""

from __future__ import annotations

import numpy as np


def _bezier(p0, p1, p2, p3):
    """Blender's correction of a Bezier segment's handles (BKE_fcurve_correct_bezpart): the
    handles are shortened so that together they are no longer than the segment in time."""
    p0, p1, p2, p3 = (np.asarray(p, dtype=np.float64) for p in (p0, p1, p2, p3))
    h1, h2 = p0 - p1, p3 - p2
    length, len1, len2 = p3[0] - p0[0], abs(h1[0]), abs(h2[0])
    if len1 + len2 > 0.0 and len1 + len2 > length:
        fac = length / (len1 + len2)
        p1, p2 = p0 - fac * h1, p3 - fac * h2
    return p0, p1, p2, p3


def split_bezier(p0, p1, p2, p3, frame: float) -> tuple[np.ndarray, ...]:
    """The Bezier segment (p0, p1, p2, p3) (2D points: frame, value), as Blender plays it, cut
    at `frame`: `(a1, a2, point, b1, b2)`, the left half `(p0, a1, a2, point)` and the right
    half `(point, b1, b2, p3)` (de Casteljau at the parameter where the segment's frame is
    `frame`, found by bisection: the corrected segment is monotone in time)."""
    p0, p1, p2, p3 = _bezier(p0, p1, p2, p3)
    lo, hi = 0.0, 1.0
    for _ in range(64):
        t = 0.5 * (lo + hi)
        s = 1.0 - t
        x = s * s * s * p0[0] + 3 * s * s * t * p1[0] + 3 * s * t * t * p2[0] + t * t * t * p3[0]
        if x < frame:
            lo = t
        else:
            hi = t
    t = 0.5 * (lo + hi)
    p01, p12, p23 = p0 + t * (p1 - p0), p1 + t * (p2 - p1), p2 + t * (p3 - p2)
    p012, p123 = p01 + t * (p12 - p01), p12 + t * (p23 - p12)
    point = p012 + t * (p123 - p012)
    return p01, p012, point, p123, p23
