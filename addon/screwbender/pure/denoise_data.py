# SPDX-License-Identifier: GPL-3.0-or-later
"""Remove Noise knows its data (issue 24): what it refuses, where it limits itself, and what
it reports. Pure (numpy, no bpy).

Remove Noise is for dense keys (a capture: a key every frame or so). The rules, per owner:

- **Too few keys.** With fewer than :data:`MIN_AUTO_KEYS` keys in the frame range the noise
  cannot be told from the motion (generalised cross-validation on a handful of keys takes
  the motion itself for noise: on four blocked keys it chose 20 frames and moved them by up
  to 1,114 mm / 65.8 degrees). With Auto Strength such an owner is refused, and the message
  points to Smooth Motion (Approximate Keys) or a given Strength; sparse keys are refused
  whatever the strength (the limit below needs a noise estimate); dense keys with a given
  Strength are smoothed.
- **Sparse keys** (the median spacing of the keys in the range above
  :data:`SPARSE_SPACING` frames): smoothed, but no key moves more than the noise estimated
  (``polyscrew.denoise``'s ``rotation_noise`` and ``translation_noise``, per axis: a key's
  rotation moves at most ``sqrt(3)`` times the first, its pivot point at most ``sqrt(3)``
  times the second, the size of one noise vector): a key beyond is drawn back towards its
  original pose (:func:`limit_moves`), and the report says how many. On sparse keys the noise
  is estimated from the keys themselves: blocked poses of a fast motion look like huge
  noise (twelve keys 90 to 270 degrees apart: 40 degrees per axis), so sparse keys whose
  estimated noise exceeds :data:`MAX_SPARSE_ROTATION_NOISE` or
  :data:`MAX_SPARSE_TRANSLATION_NOISE` of their path's extent are refused as blocked poses
  (:func:`blocked`), pointing to Smooth Motion.
- **Pops** are cut by ``polyscrew.denoise`` itself (``Denoised.pops``); the report names their
  frames.
- **Held keys**: the report says how many keys the selection held.
"""

from __future__ import annotations

import numpy as np
import polyscrew

#: Auto Strength (and sparse keys, whatever the strength) need at least this many keys in
#: the frame range (GCV of a third-order spline has n - 3 degrees of freedom to tell noise
#: from motion).
MIN_AUTO_KEYS = 7

#: Keys further apart than this (median spacing, frames) are sparse for Remove Noise.
SPARSE_SPACING = 2.0

#: Sparse keys whose rotation noise is estimated above this (radians per axis: 10 degrees,
#: far above any capture's) are blocked poses, not noisy samples...
MAX_SPARSE_ROTATION_NOISE = np.radians(10.0)

#: ... and so are sparse keys whose position noise is estimated above this fraction of the
#: extent of their path.
MAX_SPARSE_TRANSLATION_NOISE = 0.1


def median_spacing(frames: np.ndarray) -> float:
    """The median spacing of increasing key frames (0 for fewer than two)."""
    frames = np.asarray(frames, dtype=np.float64)
    return float(np.median(np.diff(frames))) if len(frames) > 1 else 0.0


def refusal(name: str, frames: np.ndarray, auto: bool) -> str | None:
    """Why Remove Noise refuses the keys at `frames` (in the frame range) of owner `name`
    (None: it does not)."""
    count = len(frames)
    if count >= MIN_AUTO_KEYS:
        return None
    spacing = median_spacing(frames)
    if spacing > SPARSE_SPACING:
        return (
            f"{name}: {count} keys {spacing:g} frames apart are too few and too sparse to tell noise from motion "
            f"(Remove Noise needs {MIN_AUTO_KEYS} keys, a frame or two apart); it is for dense captured keys: use "
            "Smooth Motion (Approximate Keys to pass near noisy keys): skipped"
        )
    if auto:
        return (
            f"{name}: {count} keys in the frame range are too few to choose a strength from the data "
            f"(Auto Strength needs {MIN_AUTO_KEYS}); Remove Noise is for dense captured keys: use Smooth Motion "
            "(Approximate Keys to pass near noisy keys), or turn Auto Strength off and give a Strength: skipped"
        )
    return None


def blocked(name: str, spacing: float, rotation_noise: float, translation_noise: float, poses: np.ndarray) -> str | None:
    """Why sparse keys (`poses`, (n, 4, 4), `spacing` frames apart) with the noise estimated
    are refused as blocked poses (None: they are not)."""
    extent = float(np.linalg.norm(poses[:, :3, 3] - poses[0, :3, 3], axis=1).max())
    if rotation_noise > MAX_SPARSE_ROTATION_NOISE or translation_noise > MAX_SPARSE_TRANSLATION_NOISE * extent:
        return (
            f"{name}: keys {spacing:g} frames apart that differ by far more than noise (estimated "
            f"{np.degrees(rotation_noise):.3g} deg, {translation_noise:.3g} units per axis) are blocked poses, not a "
            "capture; Remove Noise is for dense captured keys: use Smooth Motion (Approximate Keys to pass near noisy "
            "keys): skipped"
        )
    return None


def limit_moves(
    sources: list[np.ndarray], smoothed: list[np.ndarray], pivots: list[np.ndarray], rotation_bounds: list[float],
    translation_bounds: list[float],
) -> tuple[list[np.ndarray], list[int]]:
    """Per owner: its `smoothed` poses (n, 4, 4) with every pose that moved from its `sources`
    pose by more than its bounds (a rotation angle, radians; a distance of its pivot point)
    drawn back towards its source pose by the fraction a that brings both within them: the
    rotation by a of its turn (about the same axis), the pivot a of the way along its straight
    move. Returns each owner's poses and how many were drawn back (one
    `polyscrew.partial_moves_many` call for all owners: each owner's `partial_moves`, bit for
    bit)."""
    counts = np.array([len(p) for p in smoothed], dtype=np.int64)
    poses, cut = polyscrew.partial_moves_many(
        np.concatenate(sources), np.concatenate(smoothed), counts, np.array(pivots, dtype=np.float64).reshape(-1, 3),
        np.array(rotation_bounds, dtype=np.float64), np.array(translation_bounds, dtype=np.float64),
    )
    bounds = np.cumsum(counts)[:-1]
    return np.split(poses, bounds), [int(c.sum()) for c in np.split(cut, bounds)]
