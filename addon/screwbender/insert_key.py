# SPDX-License-Identifier: GPL-3.0-or-later
"""Insert Key on Motion: key the smoothed motion's own pose at a frame, to refine locally.

Rossignac-Kim: "interpolations should be stable under sub-sampling". Inserting, at frame f,
the pose the motion has there changes nothing for the raw polyscrew (0 levels, linear
timing): the screw from P_i to P_{i+1} split at s(P_i, a, P_{i+1}) gives two screws that
trace exactly the same poses (`(M^a)^v = M^(a v)`). With subdivision the refined motion
moves slightly; :func:`insert_key` measures by how much, by sampling the motion read back
from the F-curves before and after, at every whole frame of the keyed range and at f.

Keys are written with `FCurve.keyframe_points.insert` on every keyed transform channel
(location and rotation always, scale when it is keyed), in the owner's rotation mode and
continuous with the curve there (quaternion sign, compatible Euler angles). F-curves store
float32: the inserted pose is the motion's pose rounded to float32 channel values.

The owner is an object or a pose bone (:mod:`owners`): a bone is keyed in its own space
(`matrix_basis`), its curves in the F-curve group named after it, as Blender keys bones; a
bone connected to its parent gets no location key (Blender ignores its location).
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np
import polyscrew

from . import bake, channels, keys, owners, transaction
from .keys import SmoothError


@dataclass
class InsertResult:
    """What one insertion did."""

    frame: float
    #: property name -> the inserted channel values.
    values: dict[str, np.ndarray]
    #: Largest displacement of the owner's origin (a bone's head) over the checked frames, in
    #: its own space (an object's parent space, a bone's rest space; scene units).
    max_translation: float
    #: Largest rotation between the old and new orientation over the checked frames (radians).
    max_angle: float
    #: Frame where the largest displacement happens.
    worst_frame: float
    #: The frames the motion was compared at.
    checked_frames: np.ndarray


def check_frames(before: keys.KeyedMotion, frame: float) -> np.ndarray:
    """Every whole frame of the keyed range (widened to include `frame`), and `frame`."""
    start, end = before.frame_range
    start, end = min(start, frame), max(end, frame)
    whole = np.arange(np.ceil(start), np.floor(end) + 1.0)
    return np.union1d(whole, [frame])


def pose_change(a: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per pose: origin displacement |t_b - t_a| and rotation angle of `R_a^T R_b` (radians)."""
    translation = np.linalg.norm(b[:, :3, 3] - a[:, :3, 3], axis=1)
    angle = np.linalg.norm(polyscrew.turn_vectors(a, b), axis=1)  # exact near 0 and pi
    return translation, angle


def _current_values(target, curves: dict, path: str, size: int, frame: float) -> np.ndarray:
    static = np.array(getattr(target, path), dtype=np.float64)
    return np.array(
        [curves[(path, i)].evaluate(frame) if (path, i) in curves else static[i] for i in range(size)]
    )


def insert_key(
    owner: owners.Owner | bpy.types.Object, frame: float, options: bake.Options, t: transaction.Transaction
) -> InsertResult:
    """Keys the pose the smoothed motion of `owner` (an object or a pose bone) has at `frame`
    on its transform channels (inside the transaction `t`: the curves get their old keys back
    if anything fails later).

    Raises :class:`SmoothError` (nothing changed) when the keys cannot be smoothed.
    """
    owner = owners.as_owner(owner)
    name = owner.name
    before = keys.read(owner, options.closed, turns=options.turns)
    frames = check_frames(before, frame)
    try:
        poses_before, _ = bake.sample_poses(before, frames, options, owner)
        pose, scale = bake.sample_poses(before, np.array([frame], dtype=np.float64), options, owner)
    except ValueError as err:
        raise SmoothError(f"{name}: {err}") from err

    mode = owner.rotation_mode
    rotation_path = keys.rotation_path(mode)
    size = keys.rotation_width(mode)
    curves = {}
    for fc in channels.object_fcurves(owner.obj):
        prop = owner.prop_of(fc.data_path)
        if prop is not None:
            curves[(prop, fc.array_index)] = fc
    previous = _current_values(owner.target, curves, rotation_path, size, frame)
    values = {
        "location": pose[0, :3, 3].copy(),
        rotation_path: polyscrew.rotation_channels(pose, mode, previous=previous)[0],
    }
    if not before.located:
        del values["location"]  # a connected bone: Blender ignores its location
    if before.scale_keyed:
        values["scale"] = scale[0]  # only its keyed axes are keyed again (below)

    adt = owner.obj.animation_data
    bag = channels.ensure_container(adt.action, channels.assigned_slot(owner.obj))
    for path, vector in values.items():
        for index, value in enumerate(vector):
            if path == "scale" and not before.scale_axes[index]:
                continue  # unkeyed scale stays unkeyed (a mirrored object's static -1 included)
            fcurve = curves.get((path, index))
            if fcurve is None:
                fcurve = t.new_fcurve(bag, owner.path(path), index, owner.group)
            else:
                t.keep_keys(fcurve)
            channels.insert_key(fcurve, frame, float(value))

    after = keys.read(owner, options.closed, turns=options.turns)
    try:
        poses_after, _ = bake.sample_poses(after, frames, options, owner)
    except ValueError as err:
        raise SmoothError(f"{name}: {err}") from err
    translation, angle = pose_change(poses_before, poses_after)
    worst = int(np.argmax(translation))
    return InsertResult(
        frame=frame,
        values=values,
        max_translation=float(translation.max()),
        max_angle=float(angle.max()),
        worst_frame=float(frames[worst]),
        checked_frames=frames,
    )
