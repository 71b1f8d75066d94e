# SPDX-License-Identifier: GPL-3.0-or-later
"""Remove Noise: coordinate-free smoothing of captured keys (camera solves, motion capture,
baked simulations), `polyscrew.denoise` on the owner's key poses.

Per owner (an object or a pose bone) the transform keys in the frame range are read as rigid
poses at the union of their key frames (:func:`keys.read`, without the spin and hold analysis
of Smooth Motion), smoothed together (owners keyed on the same frames with the same held keys
go into one batched call: a motion-capture rig is one call), and written back **into the
keys themselves**: each key of a location or rotation curve gets the smoothed value at its
frame and its handles move with it, so the curves keep their keys, interpolation and handle
types (sparse keys are approximated, dense ones filtered). Keys outside the frame range, scale
and every other curve are left as they were. Like Smooth Motion the result is a new action
(the original is kept and Revert restores it), written all or nothing.

Held keys: when the user selects keys on an owner's transform curves (Graph Editor, Dope
Sheet), the selected ones are smoothed and the unselected ones held exactly, as Blender's
Smooth Keys works on the selection; with nothing selected every key is smoothed.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import bpy
import numpy as np
import polyscrew

from . import bake, channels, keys, owners, transaction
from .keys import SmoothError


#: The fewest keys in the frame range Remove Noise smooths (a third difference needs four).
MIN_KEYS = 4


@dataclass
class Options:
    """What Remove Noise needs besides the owners."""

    #: The smoothing time tau in frames (motion faster than about 2 pi tau per cycle is
    #: removed); None chooses it from the data (rotation and translation apart).
    strength: float | None = None
    #: Frames whose keys are smoothed; None: every key.
    frame_range: tuple[float, float] | None = None
    #: On an action that is already a result of Remove Noise: smooth that result (else the
    #: original keys again).
    smooth_result: bool = False


@dataclass
class Cleaned:
    """One owner's denoised key poses, before anything is written."""

    owner: owners.Owner
    motion: keys.KeyedMotion
    #: Indices (into motion.frames) of the keys that were smoothed.
    rows: np.ndarray
    #: The smoothed poses at those keys (len(rows), 4, 4).
    poses: np.ndarray
    #: The held keys among them.
    held: np.ndarray
    #: What polyscrew chose and estimated.
    rotation_strength: float = 0.0
    translation_strength: float = 0.0
    rotation_noise: float = 0.0
    translation_noise: float = 0.0


@dataclass
class Denoised:
    """What Remove Noise did."""

    actions: list[bpy.types.Action]
    owners: list[str]
    skipped: list[str]
    notes: list[str] = field(default_factory=list)
    #: The strengths used (frames), per owner: (rotation, translation).
    strengths: list[tuple[float, float]] = field(default_factory=list)


def selected_frames(owner: owners.Owner, fcurves: list, frames: np.ndarray) -> np.ndarray:
    """Per key frame of `frames`: whether a key is selected there on the owner's transform
    curves."""
    chosen = np.zeros(len(frames), dtype=bool)
    paths = set(keys.transform_paths(owner.rotation_mode))
    for fc in fcurves:
        if owner.prop_of(fc.data_path) not in paths or not len(fc.keyframe_points):
            continue
        points = fc.keyframe_points
        co = np.empty(2 * len(points), dtype=np.float32)
        points.foreach_get("co", co)
        flags = np.empty(len(points), dtype=bool)
        points.foreach_get("select_control_point", flags)
        picked = co[0::2][flags].astype(np.float64)
        at = np.clip(np.searchsorted(frames, picked), 0, len(frames) - 1)
        for candidate in (at, np.clip(at - 1, 0, len(frames) - 1)):  # the nearest key frame
            hit = np.abs(frames[candidate] - picked) < keys.FRAME_TOLERANCE
            chosen[candidate[hit]] = True
    return chosen


def _rows_in(frames: np.ndarray, frame_range: tuple[float, float] | None) -> np.ndarray:
    if frame_range is None:
        return np.arange(len(frames))
    start, end = frame_range
    tol = keys.FRAME_TOLERANCE
    return np.flatnonzero((frames >= start - tol) & (frames <= end + tol))


def prepare(owner: owners.Owner, fcurves: list, options: Options, action=None, slot: str = "") -> tuple[keys.KeyedMotion, np.ndarray, np.ndarray]:
    """The owner's key poses (no analysis), the rows to smooth and which of them are held."""
    motion = keys.read(owner, "OFF", action=action, slot=slot, fcurves=fcurves, analyse=False)
    rows = _rows_in(motion.frames, options.frame_range)
    if len(rows) < MIN_KEYS:
        raise SmoothError(
            f"{owner.name}: {len(rows)} key frame(s) in the frame range; Remove Noise needs at least 4: skipped"
        )
    selected = selected_frames(owner, fcurves, motion.frames)[rows]
    held = ~selected if selected.any() else np.zeros(len(rows), dtype=bool)
    if held.all():
        raise SmoothError(f"{owner.name}: every key in the frame range is unselected (held): nothing to smooth: skipped")
    return motion, rows, held


def clean(prepared: list[tuple[owners.Owner, keys.KeyedMotion, np.ndarray, np.ndarray]], options: Options) -> list[Cleaned]:
    """Denoises prepared owners, batching those keyed on the same frames with the same held
    keys into one `polyscrew.denoise` call. Raises SmoothError (with polyscrew's message)."""
    batches: dict[tuple, list] = {}
    for item in prepared:
        owner, motion, rows, held = item
        key = (motion.frames[rows].tobytes(), held.tobytes())
        batches.setdefault(key, []).append(item)
    out = []
    for items in batches.values():
        _, motion, rows, held = items[0]
        times = motion.frames[rows]
        stack = np.stack([m.poses[r] for _, m, r, _ in items])
        try:
            result = polyscrew.denoise(
                stack if len(items) > 1 else stack[0], times, strength=options.strength,
                held=held if held.any() else None,
            )
        except ValueError as err:
            raise SmoothError(f"{', '.join(o.name for o, *_ in items[:3])}: {err}") from err
        poses = result.poses if len(items) > 1 else result.poses[None]

        def per_body(value, b):
            value = np.asarray(value, dtype=np.float64)
            return float(value.reshape(-1)[b] if value.size > 1 else value.reshape(-1)[0])

        for b, (owner, motion, rows, held_b) in enumerate(items):
            out.append(
                Cleaned(
                    owner=owner, motion=motion, rows=rows, poses=poses[b], held=held_b,
                    rotation_strength=per_body(result.rotation_strength, b),
                    translation_strength=per_body(result.translation_strength, b),
                    rotation_noise=per_body(result.rotation_noise, b),
                    translation_noise=per_body(result.translation_noise, b),
                )
            )
    return out


def _edit_keys(fcurves: list, cleaned: Cleaned) -> None:
    """Writes the smoothed values into the keys of the owner's location and rotation curves
    among `fcurves` (frames in the range), moving each key's handles with it."""
    motion, owner = cleaned.motion, cleaned.owner
    mode = motion.rotation_mode
    frames = motion.frames[cleaned.rows]
    previous = None if mode == "AXIS_ANGLE" else _channels_at(motion, cleaned.rows[0])
    rotation = polyscrew.rotation_channels(cleaned.poses, mode, previous=previous)
    values = {keys.rotation_path(mode): rotation}
    if motion.located:
        values["location"] = cleaned.poses[:, :3, 3]
    for fc in fcurves:
        prop = owner.prop_of(fc.data_path)
        if prop not in values or fc.array_index >= values[prop].shape[1]:
            continue
        points = fc.keyframe_points
        n = len(points)
        co = np.empty(2 * n, dtype=np.float32)
        points.foreach_get("co", co)
        co = co.reshape(-1, 2)
        at = np.searchsorted(frames, co[:, 0].astype(np.float64))
        at = np.clip(at, 0, len(frames) - 1)
        near = np.abs(frames[at] - co[:, 0]) < keys.FRAME_TOLERANCE
        if not near.any():
            continue
        delta = np.zeros(n, dtype=np.float64)
        delta[near] = values[prop][at[near], fc.array_index] - co[near, 1]
        left = np.empty(2 * n, dtype=np.float32)
        right = np.empty(2 * n, dtype=np.float32)
        points.foreach_get("handle_left", left)
        points.foreach_get("handle_right", right)
        for array in (co, left.reshape(-1, 2), right.reshape(-1, 2)):
            array[:, 1] += delta.astype(np.float32)
        co[near, 1] = values[prop][at[near], fc.array_index]  # exact, not the sum
        points.foreach_set("co", co.ravel())
        points.foreach_set("handle_left", left)
        points.foreach_set("handle_right", right)
        fc.update()


def _channels_at(motion: keys.KeyedMotion, row: int) -> np.ndarray:
    """The rotation channel values the owner has at key `row` (for continuity of the new ones)."""
    if motion.source is not None:
        return motion.source.channels(motion.frames[row : row + 1])[keys.rotation_path(motion.rotation_mode)][0]
    return motion.first_rotation


def remove_noise(
    selection: Iterable,
    options: Options,
    progress: Callable[[int, int], None] | None = None,
    t: transaction.Transaction | None = None,
) -> Denoised:
    """Removes the noise of the owners in `selection` (objects or :class:`owners.Owner`s);
    owners animated by one action get one new action. Everything is read and denoised before
    anything is written, and the writing is all or nothing."""
    selection = [owners.as_owner(item) for item in selection]
    groups: dict[tuple, list[owners.Owner]] = {}
    skipped = []
    for owner in selection:
        adt = owner.obj.animation_data
        if adt is None or adt.action is None:
            skipped.append(f"{owner.name}: no animation (no active action): skipped")
            continue
        groups.setdefault((adt.action.as_pointer(), channels.slot_identifier(owner.obj)), []).append(owner)
    prepared, plans = [], []
    for i, members in enumerate(groups.values()):
        first = members[0].obj
        current = first.animation_data.action
        identifier = channels.slot_identifier(first)
        source, slot = current, identifier
        found = bake.original_of(current, "denoise")
        if found is not None and not options.smooth_result:
            source, slot = found
        listed = channels.action_fcurves(source, slot)
        by_owner = owners.curves_by_owner(listed)
        users = bake.users_of(current, identifier)
        done = []
        for owner in {(o.obj.as_pointer(), o.bone): o for o in members}.values():
            try:
                motion, rows, held = prepare(owner, by_owner.get(owner.bone, []), options,
                                             action=None if source is current else source, slot=slot)
            except SmoothError as err:
                skipped.append(str(err))
                continue
            prepared.append((owner, motion, rows, held))
            done.append(owner)
        if done:
            plans.append((users or [first], source, current, identifier, done))
        if progress is not None:
            progress(i + 1, 2 * len(groups))
    cleaned = {(c.owner.obj.as_pointer(), c.owner.bone): c for c in clean(prepared, options)}
    actions = []
    with contextlib.ExitStack() as stack:
        if t is None:
            t = stack.enter_context(transaction.atomic())
        for i, (objects, source, current, identifier, done) in enumerate(plans):
            parts = [cleaned[(o.obj.as_pointer(), o.bone)] for o in done]

            def edit(bag, parts=parts) -> None:
                by_owner = owners.curves_by_owner(channels.fcurves(bag))  # one pass, not one per bone
                for part in parts:
                    _edit_keys(by_owner.get(part.owner.bone, []), part)

            actions.append(bake.new_result(objects, source, current, identifier, t, edit, made_by="denoise"))
            if progress is not None:
                progress(len(groups) + i + 1, 2 * len(groups))
    parts = list(cleaned.values())
    return Denoised(
        actions=actions,
        owners=[c.owner.name for c in parts],
        skipped=skipped,
        strengths=[(c.rotation_strength, c.translation_strength) for c in parts],
    )
