# SPDX-License-Identifier: GPL-3.0-or-later
"""An owner's key poses as arrays (:class:`KeyedMotion`), and the rules that hold without Blender.

The Blender layer (`blender/keys.py`) reads them from the F-curves; from here on the motion is
arrays: rigid poses and scales at the key frames, what the animator meant between them (holds,
pops, spins), and the baked channels of a rotation mode. :class:`SmoothError` is the one error
the add-on reports to the animator as the reason an owner was skipped.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import polyscrew

from . import intent

#: Rotation modes and the property holding the rotation in each.
ROTATION_PATHS = {
    "QUATERNION": "rotation_quaternion",
    "AXIS_ANGLE": "rotation_axis_angle",
    "XYZ": "rotation_euler",
    "XZY": "rotation_euler",
    "YXZ": "rotation_euler",
    "YZX": "rotation_euler",
    "ZXY": "rotation_euler",
    "ZYX": "rotation_euler",
}


#: Two key frames closer than this (in frames) are the same frame.
FRAME_TOLERANCE = 1e-4


#: A last key whose pose and scale differ from the first by less than this (per matrix entry,
#: relative to the motion's size) repeats the first pose: it closes a cyclic motion's period.
REPEAT_TOLERANCE = 1e-5


class SmoothError(ValueError):
    """Input the add-on refuses, with a message naming the object and the reason."""


@dataclass
class KeyedMotion:
    """The key poses of one object, ready for `polyscrew.sample`."""

    #: Key frames, strictly increasing, shape (K,).
    frames: np.ndarray
    #: Rigid poses (translation and rotation) at those frames, shape (K, 4, 4).
    poses: np.ndarray
    #: Scale at those frames, shape (K, 3): keyed axes positive, an unkeyed axis is the object's
    #: own (constant) scale, which may be negative (a mirrored object).
    scales: np.ndarray
    #: Which scale axes are keyed (unkeyed scale is left alone), shape (3,).
    scale_axes: np.ndarray
    #: The object's rotation mode ("QUATERNION", "AXIS_ANGLE" or an Euler order).
    rotation_mode: str
    #: The rotation channel values at the first key (for sign and Euler continuity).
    first_rotation: np.ndarray
    #: Whether the motion is a cycle.
    closed: bool
    #: Cycle length in frames for a closed motion (None for an open one).
    period: float | None
    #: Whether a Cycles modifier was found on the transform curves.
    cyclic: bool
    #: What was read: the object or pose bone.
    owner: object | None = None  # the Blender layer's owners.Owner (carried, never looked into here)
    #: Whether the owner's location moves it (not for a bone connected to its parent, whose
    #: location Blender ignores: its poses have no translation and no location is baked).
    located: bool = True
    #: The owner's curves as Blender plays them (None when they hold something the add-on
    #: cannot evaluate: the motion is then made of the key values alone).
    source: intent.Source | None = None
    #: Per key span: held (the pose stays still over it), and popping at its end.
    held: np.ndarray | None = None
    pops: np.ndarray | None = None
    #: Per key: an animator's key (False: a pose taken from Blender's playback inside a spin).
    is_key: np.ndarray | None = None
    #: The frames baked by default, when they are not the keys' range (an extended cycle).
    bake_range: tuple[float, float] | None = None
    #: Cycles modifier modes (before, after) per (property, index), for the baked curves of a
    #: cycle baked over one period.
    cycle_modes: dict | None = None
    #: The body's size (travel of rotations, timing "keys"): half its largest dimension.
    size: float = 1.0
    #: What was found and kept, for the report ("2 holds", "a spin", ...).
    kept: list[str] = field(default_factory=list)
    #: What was taken out, for the report ("2 flip(s) ... at frames 11-21, 31-41").
    removed: list[str] = field(default_factory=list)
    #: Why the result may depart from Blender's playback (flips removed, non-normalised
    #: quaternion keys), for the departure report.
    causes: list[str] = field(default_factory=list)
    #: F-curve modifiers copied onto the baked curves, per (property, index): every modifier
    #: of the source curve but a first Cycles one (:mod:`modifiers`).
    modifiers: dict = field(default_factory=dict)
    #: (property, array index) of the curves the keys were read from (keyed, not muted).
    keyed: frozenset = frozenset()

    @property
    def scale_keyed(self) -> bool:
        """Whether any scale channel is keyed."""
        return bool(self.scale_axes.any())

    @property
    def frame_range(self) -> tuple[float, float]:
        """First and last key frame, including the key closing a cycle (an extended cycle: the
        keys' own period)."""
        if self.bake_range is not None:
            return self.bake_range
        end = self.frames[0] + self.period if self.period is not None else self.frames[-1]
        return float(self.frames[0]), float(end)


def rotation_path(mode: str) -> str:
    """The rotation property animated in rotation mode `mode`."""
    return ROTATION_PATHS[mode]


def transform_paths(mode: str) -> tuple[str, str, str]:
    """Location, rotation (for `mode`) and scale property names."""
    return ("location", rotation_path(mode), "scale")


def baked_channels(mode: str, located: bool, scale_axes: np.ndarray) -> list[tuple[str, int]]:
    """(property, array index) of every channel a bake writes: location (unless `located` is
    false), every rotation channel of `mode`, the keyed scale axes."""
    rotation = rotation_path(mode)
    out = [("location", i) for i in range(3)] if located else []
    out += [(rotation, i) for i in range(4 if mode in ("QUATERNION", "AXIS_ANGLE") else 3)]
    return out + [("scale", int(i)) for i in np.flatnonzero(scale_axes)]


def rotation_matrices(values: np.ndarray, mode: str) -> np.ndarray:
    """(N, 3, 3) rotation matrices from (N, k) rotation channel values in Blender's `mode`.

    Follows Blender: quaternions (w, x, y, z) are normalised (zero gives the identity),
    axis-angle is (angle, x, y, z) with the axis normalised (zero gives the identity), and
    Euler order "XYZ" means X is applied first: `R = Rz Ry Rx`. One `polyscrew` call
    (`polyscrew.rotation_matrices`; ValueError for values that are not finite).
    """
    if mode not in ROTATION_PATHS:
        raise SmoothError(f"unknown rotation mode {mode!r}")
    return polyscrew.rotation_matrices(np.asarray(values, dtype=np.float64), mode)


def compose(locations: np.ndarray, rotations: np.ndarray, scales: np.ndarray | None = None) -> np.ndarray:
    """(N, 4, 4) matrices `T R S` from (N, 3) locations, (N, 3, 3) rotations, (N, 3) scales."""
    n = locations.shape[0]
    out = np.zeros((n, 4, 4))
    out[:, :3, :3] = rotations if scales is None else rotations * scales[:, None, :]
    out[:, :3, 3] = locations
    out[:, 3, 3] = 1.0
    return out


def _union(frames: list[np.ndarray]) -> np.ndarray:
    merged = np.unique(np.concatenate(frames))
    keep = np.concatenate(([True], np.diff(merged) > FRAME_TOLERANCE))
    return merged[keep]
