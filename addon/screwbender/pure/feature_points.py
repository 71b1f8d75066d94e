# SPDX-License-Identifier: GPL-3.0-or-later
"""The "Feature Points" method of Smooth Motion (Hofer-Pottmann-Ravani), its parts without Blender.

The method's options, a bone's body (a box around it), the spring per key that Approximate
Keys gives, and which key frame each of a curve's keys lands on. The Blender layer
(`blender/feature.py`) reads the body's points and the key selection and makes the one
`polyscrew.sample_feature` call per piece.
"""

from __future__ import annotations

import numpy as np

from .keyed import FRAME_TOLERANCE, KeyedMotion

#: Smoothing methods: (identifier, label, description).
METHODS = (
    (
        "SCREW",
        "Screw Subdivision",
        "Subdivide the key poses as screws (ScrewBender): coordinate-free, reproduces screw motions exactly",
    ),
    (
        "FEATURE",
        "Feature Points",
        "Run C2 variational curves through the key positions of the mesh's inertia points and fit the rigid "
        "object to them at every frame (Hofer-Pottmann-Ravani); can approximate noisy keys. Scheme then "
        "smooths only scale",
    ),
)


#: Parameter spacing of the variational curves.
PARAMETRIZATIONS = (
    ("uniform", "Uniform", "Keys equally spaced along the curves (the paper's uniform scheme)"),
    (
        "centripetal",
        "Centripetal",
        "Spacing by the square root of how far the object moves between keys: less change of "
        "speed where keys are unevenly far apart",
    ),
)


def nearest_rows(frames: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per frame of `at`: the index of the nearest frame of `frames` (sorted, not empty), and
    whether it is the same frame (within :data:`FRAME_TOLERANCE`). Both neighbours are
    looked at (a key a hair before or after a frame is that frame's key)."""
    at = np.asarray(at, dtype=np.float64)
    last = len(frames) - 1
    right = np.clip(np.searchsorted(frames, at), 0, last)
    left = np.clip(right - 1, 0, last)
    index = np.where(np.abs(frames[left] - at) < np.abs(frames[right] - at), left, right)
    return index, np.abs(frames[index] - at) < FRAME_TOLERANCE


#: A bone's feature points are those of a box around it, this wide per unit of bone length.
BONE_BOX_WIDTH = 0.1


def bone_points(length: float) -> np.ndarray:
    """The eight corners of a box around a bone of `length` in its own space (head at the
    origin, the bone along +Y): the bone's body for the Feature Points method."""
    w = BONE_BOX_WIDTH * length
    return np.array([(x, y, z) for x in (-w, w) for y in (0.0, length) for z in (-w, w)])


def key_stiffness(motion: KeyedMotion, selected: np.ndarray, approximate: bool, stiffness: float):
    """Spring lambda per key: None (hit every key) unless `approximate`; then selected keys get
    `stiffness`, unselected keys and the ends of an open motion are hit (inf)."""
    if not approximate:
        return None
    lam = np.where(selected, float(stiffness), np.inf)
    if not motion.closed:
        lam[0] = lam[-1] = np.inf
    return lam
