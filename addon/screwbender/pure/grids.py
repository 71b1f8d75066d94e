# SPDX-License-Identifier: GPL-3.0-or-later
"""The frames a bake writes: the Step grid over a range, its ends exact, every key frame added.

Smooth Motion bakes a key at `start`, every multiple of Step between, `end`, and every key
frame of the source inside (subframes included); angular-velocity editing bakes whole frames.
"""

from __future__ import annotations

import numpy as np

from .keyed import FRAME_TOLERANCE, SmoothError

#: Most keys one Smooth Motion may write (all objects together). Blender keeps about 60 bytes
#: per key (a BezTriple) plus the undo copy of the action: 20 million keys are about 2.5 GB.
MAX_KEYS = 20_000_000


def bake_frames(start: float, end: float, step: float) -> np.ndarray:
    """The baked frames: `start`, every multiple of `step` strictly between, and `end`.

    Keys sit on the scene's frame grid (whole frames for a step of 1, multiples of the step
    otherwise) and the range's ends, usually the first and last key, are always baked exactly,
    also when they are subframes (1.5 ... 20.6) or when the step does not divide the range
    (0.1 over 1..30: 10 * 0.1 is not 1.0 in floating point, so grid frames are `k / 10`).
    A grid frame closer than :data:`FRAME_TOLERANCE` to an end is that end.
    """
    if not step > 0.0:
        raise SmoothError(f"step must be positive, got {step:g}")
    if not end > start:
        raise SmoothError(f"frame range {start:g} to {end:g} is empty")
    count = (end - start) / step + 2
    if count > MAX_KEYS:
        raise SmoothError(
            f"frame range {start:g} to {end:g} at step {step:g} is {count:,.0f} frames; the most "
            f"Smooth Motion bakes is {MAX_KEYS:,} keys: raise Step or shorten the Frame Range"
        )
    tol = FRAME_TOLERANCE
    first, last = int(np.ceil((start + tol) / step)), int(np.floor((end - tol) / step))
    k = np.arange(first, last + 1, dtype=np.float64)
    per_frame = 1.0 / step
    if abs(per_frame - round(per_frame)) < 1e-9:  # 0.1, 0.2, 0.5, 1: grid frames k / n exactly
        grid = k / round(per_frame)
    else:
        grid = k * step
    grid = grid[(grid > start + tol) & (grid < end - tol)]
    return np.concatenate(([start], grid, [end]))


def with_key_frames(grid: np.ndarray, key_frames: np.ndarray) -> np.ndarray:
    """The baked frames `grid` (sorted, from :func:`bake_frames`) with every key frame of
    `key_frames` inside their range added: every key pose is a baked key, also at a subframe
    (a key at 12.5, keys every half frame of a 60 fps capture in a 30 fps scene). A grid frame
    closer than :data:`FRAME_TOLERANCE` to a key frame gives way to the key frame."""
    tol = FRAME_TOLERANCE
    key_frames = np.asarray(key_frames, dtype=np.float64)
    inside = key_frames[(key_frames > grid[0] + tol) & (key_frames < grid[-1] - tol)]
    if not len(inside):
        return grid
    at = np.minimum(np.searchsorted(grid, inside), len(grid) - 1)
    if np.array_equal(grid[at], inside):  # every key frame is a grid frame already
        return grid
    inside = np.unique(inside)
    # grid frames near a key frame are that key frame
    at = np.clip(np.searchsorted(inside, grid), 1, len(inside)) - 1
    near = np.minimum(np.abs(grid - inside[at]), np.abs(grid - inside[np.minimum(at + 1, len(inside) - 1)]))
    keep = near > tol
    keep[0] = keep[-1] = True  # the range's ends stay exact
    return np.unique(np.concatenate((grid[keep], inside)))
