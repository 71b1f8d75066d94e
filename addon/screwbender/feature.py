# SPDX-License-Identifier: GPL-3.0-or-later
"""The "Feature Points" method of Smooth Motion (Hofer-Pottmann-Ravani).

Instead of subdividing the key poses as screws, the six inertia points of the object's mesh
(or of a unit frame, for objects without a mesh) are carried by the key poses; their
homologous positions run on Kobbelt's variational curves (C2), interpolating every key or
approximating some of them with a spring, and at every baked frame the rigid object is
registered (Horn's method) to the distorted points. All of it is one
`polyscrew.sample_feature` call per object; this module only gathers its inputs.

Per-key stiffness comes from the key selection, as for the Graph Editor's Smooth Keys: keys
selected on any transform F-curve (Graph Editor or Dope Sheet) are approximated with the
Stiffness option, unselected keys are hit exactly, and so are the first and last key of an
open motion. Freshly inserted keys are selected, so by default every inner key is
approximated.
"""

from __future__ import annotations

import bpy
import numpy as np
import polyscrew

from . import channels, keys

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


def selected_keys(obj: bpy.types.Object, frames: np.ndarray) -> np.ndarray:
    """Per key frame: whether a key is selected there on any transform F-curve of `obj`."""
    selected = np.zeros(len(frames), dtype=bool)
    paths = keys.transform_paths(obj.rotation_mode)
    for fcurve in channels.object_fcurves(obj):
        points = fcurve.keyframe_points
        if fcurve.data_path not in paths or fcurve.mute or len(points) == 0:
            continue
        co = np.empty(2 * len(points), dtype=np.float32)
        points.foreach_get("co", co)
        flags = np.empty(len(points), dtype=bool)
        points.foreach_get("select_control_point", flags)
        for frame in co[0::2][flags].astype(np.float64):
            nearest = int(np.argmin(np.abs(frames - frame)))
            if abs(frames[nearest] - frame) < keys.FRAME_TOLERANCE:
                selected[nearest] = True
    return selected


def feature_points(obj: bpy.types.Object, scale: np.ndarray) -> np.ndarray | None:
    """The six inertia points of `obj`'s mesh in the frame of its rigid pose (vertices times
    `scale`), or None (a unit frame's points) without a mesh or for a degenerate one."""
    if obj.type != "MESH" or len(obj.data.vertices) < 3:
        return None
    co = np.empty(3 * len(obj.data.vertices), dtype=np.float64)
    obj.data.vertices.foreach_get("co", co)
    try:
        return polyscrew.inertia_points(co.reshape(-1, 3) * scale)
    except ValueError:  # all vertices on a line: no rotation about it is defined by them
        return None


def key_stiffness(motion: keys.KeyedMotion, selected: np.ndarray, approximate: bool, stiffness: float):
    """Spring lambda per key: None (hit every key) unless `approximate`; then selected keys get
    `stiffness`, unselected keys and the ends of an open motion are hit (inf)."""
    if not approximate:
        return None
    lam = np.where(selected, float(stiffness), np.inf)
    if not motion.closed:
        lam[0] = lam[-1] = np.inf
    return lam


def sample_poses(obj: bpy.types.Object, motion: keys.KeyedMotion, frames: np.ndarray, options) -> np.ndarray:
    """The feature-point motion of `obj` at `frames`: (len(frames), 4, 4) rigid poses.

    `options` is a :class:`bake.Options`. Raises ValueError from `polyscrew`.
    """
    # Mean scale over the keys (a static negative scale, a mirrored object, keeps its sign).
    mean_scale = np.sign(motion.scales[0]) * np.exp(np.log(np.abs(motion.scales)).mean(axis=0))
    return polyscrew.sample_feature(
        motion.poses,
        motion.frames,
        frames,
        levels=options.levels,
        closed=motion.closed,
        feature_points=feature_points(obj, mean_scale),
        parametrization=options.parametrization,
        stiffness=key_stiffness(motion, selected_keys(obj, motion.frames), options.approximate, options.stiffness),
        period=motion.period,
        timing=options.timing,
    )
