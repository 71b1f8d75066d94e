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

from collections.abc import Callable

import bpy
import numpy as np
import polyscrew

from ..pure.feature_points import (  # noqa: F401  (re-exported: feature.METHODS, ...)
    BONE_BOX_WIDTH,
    METHODS,
    PARAMETRIZATIONS,
    bone_points,
    key_stiffness,
    nearest_rows,
)
from . import bulk, channels, keys, owners


def selected_frames(
    owner: owners.Owner,
    fcurves: list,
    frames: np.ndarray,
    props: tuple[str, ...] | None = None,
    skip_muted: bool = False,
    known: dict | None = None,
) -> np.ndarray:
    """Per key frame of `frames`: whether a key is selected there on the owner's curves among
    `fcurves` of the properties `props` (default: its transform properties), muted curves
    left out with `skip_muted`. One foreach_get per curve, no loop over keys; `known`: the
    key frames the caller has read already, per curve (`fc.as_pointer()`), not read again."""
    chosen = np.zeros(len(frames), dtype=bool)
    paths = set(keys.transform_paths(owner.rotation_mode) if props is None else props)
    for fc in fcurves:
        points = fc.keyframe_points
        if owner.prop_of(fc.data_path) not in paths or (skip_muted and fc.mute) or not len(points):
            continue
        flags = np.empty(len(points), dtype=bool)
        bulk.get(points, "select_control_point", flags)
        if not flags.any():
            continue
        at = None if known is None else known.get(fc.as_pointer())
        if at is None:
            co = np.empty(2 * len(points), dtype=np.float32)
            bulk.get(points, "co", co)
            at = co[0::2]
        if len(at) == len(frames) and np.array_equal(at, frames):  # keyed on every frame: a capture
            chosen |= flags
            continue
        index, hit = nearest_rows(frames, at[flags])
        chosen[index[hit]] = True
    return chosen


def selected_keys(owner: owners.Owner | bpy.types.Object, frames: np.ndarray) -> np.ndarray:
    """Per key frame: whether a key is selected there on any (not muted) transform F-curve of
    `owner`."""
    owner = owners.as_owner(owner)
    return selected_frames(owner, channels.object_fcurves(owner.obj), frames, skip_muted=True)


def feature_points(owner: owners.Owner | bpy.types.Object, scale: np.ndarray) -> np.ndarray | None:
    """The six inertia points of the owner's body in the frame of its rigid pose: an object's
    mesh (vertices times `scale`), a bone's box of its length (:func:`bone_points`); None (a
    unit frame's points) for an object without a mesh or with a degenerate one."""
    owner = owners.as_owner(owner)
    if owner.bone:
        length = owner.obj.data.bones[owner.bone].length
        if not length > 0.0:
            return None
        return polyscrew.inertia_points(bone_points(length) * scale)
    obj = owner.obj
    if obj.type != "MESH" or len(obj.data.vertices) < 3:
        return None
    co = np.empty(3 * len(obj.data.vertices), dtype=np.float64)
    bulk.get(obj.data.vertices, "co", co)
    try:
        return polyscrew.inertia_points(co.reshape(-1, 3) * scale)
    except ValueError:  # all vertices on a line: no rotation about it is defined by them
        return None


def check_approximate(owner: owners.Owner | bpy.types.Object, motion: keys.KeyedMotion, stiffness: float) -> None:
    """Refuses what Approximate Keys cannot do sensibly, with the reason: a Stiffness of 0 (the
    selected keys would pull nothing: the motion would ignore them), and no selected key (there
    is nothing to approximate; every key would be hit as without the option)."""
    owner = owners.as_owner(owner)
    if not stiffness > 0.0:
        raise keys.SmoothError(
            f"{owner.name}: Approximate Keys with Stiffness 0 would ignore the selected keys "
            "altogether: use a small positive Stiffness (0.001 is very smooth), or Remove Noise "
            "for captured keys"
        )
    if not selected_keys(owner, motion.frames).any():
        raise keys.SmoothError(
            f"{owner.name}: Approximate Keys: no key of its transform curves is selected; select "
            "the keys to approximate (Graph Editor or Dope Sheet) or turn the option off: skipped"
        )


def sample_poses_at(
    owner: owners.Owner | bpy.types.Object,
    motion: keys.KeyedMotion,
    key_times: np.ndarray,
    times: np.ndarray,
    options,
    period: float | None = None,
    timing: str = "linear",
) -> np.ndarray:
    """The feature-point motion of `owner`'s keys (`motion`) at `times`, the keys placed at
    `key_times` (their frames, or their parameters 0..K-1 with linear timing): (len(times), 4, 4).

    `options` is a :class:`bake.Options`. Raises ValueError from `polyscrew`.
    """
    # Mean scale over the keys (a static negative scale, a mirrored object, keeps its sign).
    mean_scale = np.sign(motion.scales[0]) * np.exp(np.log(np.abs(motion.scales)).mean(axis=0))
    return polyscrew.sample_feature(
        motion.poses,
        key_times,
        times,
        levels=options.levels,
        closed=motion.closed,
        feature_points=feature_points(owner, mean_scale),
        parametrization=options.parametrization,
        stiffness=key_stiffness(motion, selected_keys(owner, motion.frames), options.approximate, options.stiffness),
        period=period,
        timing=timing,
    )


def sample_poses(
    owner: owners.Owner | bpy.types.Object, motion: keys.KeyedMotion, frames: np.ndarray, options
) -> np.ndarray:
    """The feature-point motion of `owner` at `frames`, keys at their own frames with the
    options' timing: (len(frames), 4, 4) rigid poses (see :func:`sample_poses_at`)."""
    return sample_poses_at(owner, motion, motion.frames, frames, options, motion.period, options.timing)


def sampler(owner: owners.Owner | bpy.types.Object, options) -> Callable | None:
    """The Feature Points sampler that :func:`sampling.sample` (pure) calls per piece of `owner`'s
    motion: `(piece, key_times, times, period=None, timing="linear") -> poses`, reading the
    body's points and the key selection here; None with the Screw method or without an owner."""
    if options.method != "FEATURE" or owner is None:
        return None
    owner = owners.as_owner(owner)

    def sample(piece, key_times: np.ndarray, times: np.ndarray, period: float | None = None, timing: str = "linear"):
        return sample_poses_at(owner, piece, key_times, times, options, period, timing)

    return sample
