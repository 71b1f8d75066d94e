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
Smooth Keys works on the selection; with nothing selected every key is smoothed. The report
says how many keys were held.

What it refuses (too few keys for Auto), where it limits itself (sparse keys move no more
than the noise estimated) and how pops are kept: :mod:`denoise_data`.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass, field

import bpy
import numpy as np
import polyscrew

from ..pure import denoise_data
from ..pure.reports import Outcome
from . import action_groups, bake, bulk, channels, feature, keys, owners, transaction
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
    #: "EVERY_STEP" (the keys stay keys) or "REDUCED" (then the fewest keys within the
    #: tolerance `key_distance` (Blender units) and `key_angle` (radians): :mod:`reduce`).
    key_mode: str = "EVERY_STEP"
    key_distance: float = 0.001
    key_angle: float = 0.008726646259971648


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
    #: On a rerun, the owner's curves holding the original keys (in the action Remove Noise
    #: starts from): every key of the result is written from them (a rerun replaces the earlier
    #: result). Empty on a first run: the result is a copy of those keys, read once already.
    originals: list = field(default_factory=list)
    #: What polyscrew chose.
    rotation_strength: float = 0.0
    translation_strength: float = 0.0
    #: The noise it estimated (per axis: radians, pose units) and the pivot (body coordinates).
    rotation_noise: float = 0.0
    translation_noise: float = 0.0
    pivot: np.ndarray = field(default_factory=lambda: np.zeros(3))
    #: Indices (into rows) of the first key after each pop the clip was cut at.
    pops: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=np.int64))
    #: Sparse keys: their median spacing (frames; 0 when dense) and how many keys were drawn
    #: back to within the noise estimated.
    sparse_spacing: float = 0.0
    limited: int = 0
    #: Why the owner is refused after all (sparse keys that are blocked poses), else None.
    refused: str | None = None
    #: The rotation channels written at the keys `rows` (len(rows), k), like the original key
    #: values (:func:`near_rotations`, one `polyscrew` call for all owners of a mode).
    near: np.ndarray | None = None


@dataclass
class Denoised(Outcome):
    """What Remove Noise did."""

    #: The strengths used (frames), per owner: (rotation, translation).
    strengths: list[tuple[float, float]] = field(default_factory=list)


#: The nearest key frame of a key (both neighbours), shared with Smooth Motion's selection.
nearest_rows = feature.nearest_rows


def _points(fc, attr: str = "co") -> np.ndarray:
    """One keyframe property of every key of `fc`, (n, 2) float32 (one foreach_get)."""
    points = fc.keyframe_points
    out = np.empty(2 * len(points), dtype=np.float32)
    bulk.get(points, attr, out)
    return out.reshape(-1, 2)


def selected_frames(owner: owners.Owner, fcurves: list, frames: np.ndarray, known: dict | None = None) -> np.ndarray:
    """Per key frame of `frames`: whether a key is selected there on the owner's transform
    curves (`known`: their key frames already read, per `fc.as_pointer()`)."""
    return feature.selected_frames(owner, fcurves, frames, known=known)


def read_keys(motion: keys.KeyedMotion) -> dict[tuple[str, int], tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """The keys :func:`keys.read` read for `motion`, per (property, array index): co,
    handle_left and handle_right, (K, 2) float32 each (views of its one read of each curve:
    copy before changing them); empty when the curves could not be packed (then read again)."""
    source = motion.source
    if source is None:
        return {}
    packed = source.packed
    bounds = packed.offsets.tolist()
    return {
        column: tuple(a[bounds[k] : bounds[k + 1]] for a in (packed.co, packed.handle_left, packed.handle_right))
        for k, column in enumerate(source.columns)
    }


def _known_frames(owner: owners.Owner, fcurves: list, motion: keys.KeyedMotion) -> dict[int, np.ndarray]:
    """The key frames of the curves among `fcurves` that :func:`keys.read` read for `motion`,
    per `fc.as_pointer()`."""
    read = read_keys(motion)
    known = {}
    for fc in fcurves:
        points = read.get((owner.prop_of(fc.data_path), fc.array_index))
        if points is not None and not fc.mute and len(points[0]) == len(fc.keyframe_points):
            known[fc.as_pointer()] = points[0][:, 0]
    return known


def _rows_in(frames: np.ndarray, frame_range: tuple[float, float] | None) -> np.ndarray:
    if frame_range is None:
        return np.arange(len(frames))
    start, end = frame_range
    tol = keys.FRAME_TOLERANCE
    return np.flatnonzero((frames >= start - tol) & (frames <= end + tol))


def prepare(
    owner: owners.Owner, fcurves: list, options: Options, action=None, slot: str = "", shown: list | None = None,
    motion: keys.KeyedMotion | SmoothError | None = None,
) -> tuple[keys.KeyedMotion, np.ndarray, np.ndarray]:
    """The owner's key poses (no analysis), the rows to smooth and which of them are held.
    `fcurves` hold the keys read; `shown` (default `fcurves`) the keys the user sees and
    selects (the earlier result, on a rerun from the original keys). `motion`: the owner's
    keys read already, as :func:`read_request` asks (:func:`keys.read_many` reads every
    owner's together; a :class:`SmoothError` is raised); None: read here."""
    if motion is None:
        motion = keys.read_many([read_request(owner, fcurves, action, slot)])[0]
    if isinstance(motion, SmoothError):
        raise motion
    rows = _rows_in(motion.frames, options.frame_range)
    if len(rows) < MIN_KEYS:
        raise SmoothError(
            f"{owner.name}: {len(rows)} key frame(s) in the frame range; Remove Noise needs at least 4: skipped"
        )
    refused = denoise_data.refusal(owner.name, motion.frames[rows], options.strength is None)
    if refused is not None:
        raise SmoothError(refused)
    shown = fcurves if shown is None else shown
    known = _known_frames(owner, shown, motion) if shown is fcurves else None  # (a rerun: the result shown)
    selected = selected_frames(owner, shown, motion.frames, known)[rows]
    held = ~selected if selected.any() else np.zeros(len(rows), dtype=bool)
    if held.all():
        raise SmoothError(f"{owner.name}: every key in the frame range is unselected (held): nothing to smooth: skipped")
    return motion, rows, held


def read_request(owner: owners.Owner, fcurves: list, action=None, slot: str = "") -> keys.Request:
    """How :func:`prepare` reads `owner`'s keys (its curves `fcurves`, of `action`'s slot
    `slot` when not the active action): no analysis, a capture from its key values."""
    return keys.Request(owner, "OFF", action=action, slot=slot, fcurves=fcurves, analyse=False, key_values=True)


def near_rotations(parts: list[Cleaned]) -> None:
    """Sets each part's `near`: its smoothed rotations as channels of its mode, each written
    like the original key value at its frame (its quaternion sign, its Euler twin and whole
    turns: spins and deliberate sign flips of the keys are kept). One
    `polyscrew.rotation_channels_near` call per rotation mode for all parts (row by row: the
    same values as one call per part)."""
    by_mode: dict[str, list[Cleaned]] = {}
    for c in parts:
        by_mode.setdefault(c.motion.rotation_mode, []).append(c)
    for mode, chosen in by_mode.items():
        poses = np.concatenate([c.poses for c in chosen])
        reference = np.concatenate([_original_rotation(c.motion)[c.rows] for c in chosen])
        near = polyscrew.rotation_channels_near(poses, mode, reference)
        bounds = np.cumsum([0] + [len(c.rows) for c in chosen]).tolist()
        for c, lo, hi in zip(chosen, bounds[:-1], bounds[1:]):
            c.near = near[lo:hi]


def clean(prepared: list[tuple[owners.Owner, keys.KeyedMotion, np.ndarray, np.ndarray, list]], options: Options) -> list[Cleaned]:
    """Denoises prepared owners (owner, motion, rows, held, the curves of the original keys),
    batching those keyed on the same frames with the same held keys into one
    `polyscrew.denoise` call. Raises SmoothError (with polyscrew's message)."""
    batches: dict[tuple, list] = {}
    for item in prepared:
        owner, motion, rows, held, _ = item
        key = (motion.frames[rows].tobytes(), held.tobytes())
        batches.setdefault(key, []).append(item)
    out = []
    for items in batches.values():
        _, motion, rows, held, _ = items[0]
        times = motion.frames[rows]
        stack = np.stack([m.poses[r] for _, m, r, _, _ in items])
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

        pivots = np.asarray(result.pivot, dtype=np.float64).reshape(-1, 3)
        pops = result.pops if len(items) > 1 else [result.pops]
        spacing = denoise_data.median_spacing(times)
        for b, (owner, motion, rows, held_b, originals) in enumerate(items):
            c = Cleaned(
                owner=owner, motion=motion, rows=rows, poses=poses[b], held=held_b, originals=originals,
                rotation_strength=per_body(result.rotation_strength, b),
                translation_strength=per_body(result.translation_strength, b),
                rotation_noise=per_body(result.rotation_noise, b),
                translation_noise=per_body(result.translation_noise, b),
                pivot=pivots[b], pops=np.asarray(pops[b], dtype=np.int64),
            )
            if spacing > denoise_data.SPARSE_SPACING:  # sparse: no key moves more than the noise
                c.sparse_spacing = spacing
                c.refused = denoise_data.blocked(owner.name, spacing, c.rotation_noise, c.translation_noise, stack[b])
                c.poses, c.limited = denoise_data.limit_moves(
                    stack[b], c.poses, c.pivot, np.sqrt(3.0) * c.rotation_noise, np.sqrt(3.0) * c.translation_noise
                )
            out.append(c)
    return out


def data_notes(c: Cleaned) -> list[str]:
    """What the report says about one owner's data: keys held by the selection, pops kept,
    sparse keys limited."""
    notes = []
    frames = c.motion.frames[c.rows]
    if c.held.any():
        notes.append(f"{c.owner.name}: {int(c.held.sum())} of {len(c.held)} keys held (not selected), "
                     f"{int((~c.held).sum())} smoothed")
    if len(c.pops):
        at = ", ".join(f"{frames[i]:g}" for i in c.pops[:5]) + (", ..." if len(c.pops) > 5 else "")
        notes.append(f"{c.owner.name}: {len(c.pops)} pop(s) kept (a jump far above the noise, at frame {at}): "
                     "the pieces between were smoothed apart")
    if c.sparse_spacing:
        notes.append(
            f"{c.owner.name}: keys {c.sparse_spacing:g} frames apart are sparse for Remove Noise: no key moved more "
            f"than the noise estimated ({np.degrees(np.sqrt(3.0) * c.rotation_noise):.3g} deg, "
            f"{np.sqrt(3.0) * c.translation_noise:.3g} units); {c.limited} key(s) drawn back to it. Smooth Motion "
            "(Approximate Keys) fits sparse keys"
        )
    return notes



def _rows(frames: np.ndarray, at: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`nearest_rows`, at once when the keys `at` are the key frames `frames` themselves
    (a curve keyed on every key frame: a capture)."""
    if len(at) == len(frames) and np.array_equal(at, frames):
        return np.arange(len(frames)), np.ones(len(frames), dtype=bool)
    return nearest_rows(frames, at)


def _original_rotation(motion: keys.KeyedMotion) -> np.ndarray:
    """The original rotation channel values at every key frame of `motion` (K, k)."""
    mode = motion.rotation_mode
    if motion.source is not None:
        path = keys.rotation_path(mode)
        read, static = read_keys(motion), motion.source.static[path]
        cycles = dict(zip(motion.source.columns, motion.source.packed.cycles))
        out = np.empty((len(motion.frames), len(static)))
        for i in range(len(static)):
            points = read.get((path, i))
            if points is None:
                out[:, i] = static[i]  # unkeyed: its own value
            elif cycles[path, i] is None and len(points[0]) == len(motion.frames) and np.array_equal(points[0][:, 0], motion.frames):
                out[:, i] = points[0][:, 1]  # keyed on every key frame: Blender plays its key values there
            else:
                return np.asarray(motion.source.channels(motion.frames)[path], dtype=np.float64)
        return out
    # Curves the add-on cannot evaluate: continuity from the first key's values.
    return polyscrew.rotation_channels(motion.poses, mode, previous=keys.continued(mode, motion.first_rotation))


def _edit_keys(fcurves: list, cleaned: Cleaned) -> None:
    """Writes the owner's location and rotation keys among `fcurves` (not muted): every key
    at a key frame of the motion gets its original key back (value and handles, from
    `cleaned.originals`), and the smoothed keys (in the range, not held) the smoothed value at
    their frame, their handles moving with them."""
    motion, owner = cleaned.motion, cleaned.owner
    mode = motion.rotation_mode
    path = keys.rotation_path(mode)
    smoothed_rows = cleaned.rows[~cleaned.held]
    smoothed = np.zeros(len(motion.frames), dtype=bool)
    smoothed[smoothed_rows] = True
    in_range = np.zeros(len(motion.frames), dtype=bool)
    in_range[cleaned.rows] = True
    if cleaned.near is None:
        near_rotations([cleaned])
    rotation = np.zeros((len(motion.frames), cleaned.near.shape[1]))
    # Each smoothed key written like the original key value (:func:`near_rotations`).
    rotation[cleaned.rows] = cleaned.near
    values = {path: rotation}
    if motion.located:
        location = np.zeros((len(motion.frames), 3))
        location[cleaned.rows] = cleaned.poses[:, :3, 3]
        values["location"] = location
    originals = {(fc.data_path, fc.array_index): fc for fc in cleaned.originals}
    # What keys.read read (one foreach_get per property and curve): the original keys, and on
    # a first run also those of the result's curves (a copy of them): nothing is read again.
    read = read_keys(motion)
    for fc in fcurves:
        prop = owner.prop_of(fc.data_path)
        if fc.mute or prop not in values or fc.array_index >= values[prop].shape[1] or not len(fc.keyframe_points):
            continue
        points = fc.keyframe_points
        was = read.get((prop, fc.array_index))
        if was is None or len(was[0]) != len(points):
            was = None
        if originals or was is None:  # a rerun: the result is a copy of an earlier result
            co, left, right = _points(fc), _points(fc, "handle_left"), _points(fc, "handle_right")
        else:
            co, left, right = (a.copy() for a in was)
        source = originals.get((fc.data_path, fc.array_index))
        if source is not None and source != fc and len(source.keyframe_points):
            # The original keys back (this curve is a copy of an earlier result).
            if was is None or len(was[0]) != len(source.keyframe_points):
                was = (_points(source), _points(source, "handle_left"), _points(source, "handle_right"))
            order = np.argsort(was[0][:, 0], kind="stable")
            index, hit = nearest_rows(was[0][order, 0], co[:, 0])
            index = order[index[hit]]
            co[hit, 1] = was[0][index, 1]
            left[hit] = was[1][index]
            right[hit] = was[2][index]
        row, near = _rows(motion.frames, co[:, 0])
        edit = near & smoothed[row]
        target = values[prop][row[edit], fc.array_index]
        if prop == path:  # an angle within half a turn of the key's own original value
            target = polyscrew.angles_near(target, co[edit, 1], mode, fc.array_index)
        delta = (target - co[edit, 1]).astype(np.float32)
        left[edit, 1] += delta
        right[edit, 1] += delta
        co[edit, 1] = target  # exact, not the sum
        bulk.put(points, "co", co.ravel())
        if not _automatic_handles(points):  # (else `fc.update()` makes them from the keys)
            bulk.put(points, "handle_left", left.ravel())
            bulk.put(points, "handle_right", right.ravel())
        fc.update()
        outside = ~(near & in_range[row])
        if outside.any():  # (else no handle can have changed outside the range)
            _keep_handles_outside(fc, outside, left, right)


_FREE = bpy.types.Keyframe.bl_rna.properties["handle_left_type"].enum_items["FREE"].value
#: Handle types that `fc.update()` computes from the keys alone (Blender's
#: `BKE_fcurve_handles_recalc`): a value written to such a handle is replaced.
_AUTOMATIC = np.zeros(256, dtype=bool)  # (indexed by the type's value)
_AUTOMATIC[[bpy.types.Keyframe.bl_rna.properties["handle_left_type"].enum_items[name].value
            for name in ("AUTO", "AUTO_CLAMPED")]] = True


def _automatic_handles(points) -> bool:
    """Whether both handles of every key of `points` are automatic (:data:`_AUTOMATIC`):
    two byte reads, cheaper than writing the handles that `fc.update()` would replace."""
    kinds = np.empty(len(points), dtype=np.uint8)
    for side in ("handle_left_type", "handle_right_type"):
        bulk.get(points, side, kinds)
        if not _AUTOMATIC[kinds].all():
            return False
    return True


def _keep_handles_outside(fc, outside: np.ndarray, left: np.ndarray, right: np.ndarray) -> None:
    """Gives the keys `outside` the frame range back the handles `left`, `right` they had
    when `fc.update()` recomputed automatic ones from their moved neighbours (the key next to
    the range), as FREE handles: outside the range the curve plays exactly what it played."""
    now_left, now_right = _points(fc, "handle_left"), _points(fc, "handle_right")
    changed = outside & (np.any(now_left != left, axis=1) | np.any(now_right != right, axis=1))
    if not changed.any():
        return
    points = fc.keyframe_points
    now_left[changed], now_right[changed] = left[changed], right[changed]
    for side in ("handle_left_type", "handle_right_type"):
        kinds = np.zeros(len(points), dtype=np.uint8)
        bulk.get(points, side, kinds)
        kinds[changed] = _FREE
        bulk.put(points, side, tuple(kinds.tolist()))
    bulk.put(points, "handle_left", now_left.ravel())
    bulk.put(points, "handle_right", now_right.ravel())


def remove_noise(
    selection: Iterable,
    options: Options,
    progress: Callable[[int, int], None] | None = None,
    t: transaction.Transaction | None = None,
) -> Denoised:
    """Removes the noise of the owners in `selection` (objects or :class:`owners.Owner`s);
    owners animated by one action get one new action. Everything is read and denoised before
    anything is written, and the writing is all or nothing."""
    groups, refused = action_groups.by_action(selection)
    skipped = [message for _, message in refused]
    prepared, plans, notes, rerun = [], [], [], []
    sharers: dict[tuple[int, str], list[str]] = {}
    # Every group's users in one pass over the scene's objects (one pass per group grew as
    # groups x objects), and every owner's transform curves read in one pass.
    users_all = bake.users_by_slot({group.action.as_pointer() for group in groups})
    listed_groups, requests = [], []
    for group in groups:
        current, identifier = group.action, group.identifier
        # (an edited result is denoised from the original keys again, as before)
        source, slot, _ = bake.source_action(current, identifier, "denoise", options.smooth_result, keep_edits=False)
        by_owner = owners.curves_by_owner(channels.action_fcurves(source, slot))
        # The keys the user sees and selects: those of the action shown (an earlier result).
        shown = by_owner if source is current else owners.curves_by_owner(channels.action_fcurves(current, identifier))
        listed_groups.append((source, slot, by_owner, shown))
        requests += [
            read_request(owner, by_owner.get(owner.bone, []), None if source is current else source, slot)
            for owner in {(o.obj.as_pointer(), o.bone): o for o in group.members}.values()
        ]
    # every owner's keys in one keys.read_many call (one read of all their curves, one polyscrew call)
    motions = iter(keys.read_many(requests))
    for i, group in enumerate(groups):
        members = group.members
        first = members[0].obj
        current, identifier = group.action, group.identifier
        source, slot, by_owner, shown = listed_groups[i]
        users = users_all.get((current.as_pointer(), identifier), [])
        done = []
        # Owners of the same curves (linked duplicates sharing the action): read and smoothed
        # once, their names reported with the first's (they get the result action too).
        first_of: dict[tuple[str, str], owners.Owner] = {}
        for owner in {(o.obj.as_pointer(), o.bone): o for o in members}.values():
            read = next(motions)
            twin = first_of.get((owner.bone, owner.rotation_mode))
            if twin is not None:
                sharers.setdefault((twin.obj.as_pointer(), twin.bone), []).append(owner.name)
                continue
            try:
                motion, rows, held = prepare(owner, by_owner.get(owner.bone, []), options,
                                             action=None if source is current else source, slot=slot,
                                             shown=shown.get(owner.bone, []), motion=read)
            except SmoothError as err:
                skipped.append(str(err))
                continue
            # the curves of the original keys, to write them back on a rerun (a first run edits a copy of them)
            prepared.append((owner, motion, rows, held, by_owner.get(owner.bone, []) if source is not current else []))
            first_of[owner.bone, owner.rotation_mode] = owner
            done.append(owner)
            if motion.kept:
                notes.append(f"{owner.name}: kept {'; '.join(motion.kept)}")
        if done:
            plans.append((users or [first], source, current, identifier, done))
            if source is not current:
                rerun.append(first.name)
        if progress is not None:
            progress(i + 1, 2 * len(groups))
    if rerun:
        notes.append(f"removed the noise of the original keys of {bake.summary(rerun)} again (replacing the earlier result)")
    cleaned = {(c.owner.obj.as_pointer(), c.owner.bone): c for c in clean(prepared, options)}
    for key, c in list(cleaned.items()):  # blocked poses after all: skipped, nothing written
        if c.refused is not None:
            skipped.append(c.refused)
            del cleaned[key]
    near_rotations(list(cleaned.values()))
    plans = [
        (objects, source, current, identifier, kept)
        for objects, source, current, identifier, done in plans
        if (kept := [o for o in done if (o.obj.as_pointer(), o.bone) in cleaned])
    ]

    def write(plan, t: transaction.Transaction) -> bpy.types.Action:
        objects, source, current, identifier, done = plan
        parts = [cleaned[(o.obj.as_pointer(), o.bone)] for o in done]

        def edit(bag, parts=parts) -> None:
            by_owner = owners.curves_by_owner(channels.fcurves(bag))  # one pass, not one per bone
            for part in parts:
                _edit_keys(by_owner.get(part.owner.bone, []), part)
            if options.key_mode == "REDUCED":
                from . import reduce

                results = reduce.reduce_bag(bag, [p.owner for p in parts], options.key_distance, options.key_angle)
                notes.append(reduce.summary(results))

        return bake.new_result(objects, source, current, identifier, t, edit, made_by="denoise")

    actions = action_groups.write_all(plans, write, t, progress, len(groups), 2 * len(groups))
    parts = list(cleaned.values())
    for c in parts:
        notes.extend(data_notes(c))
    return Denoised(
        actions=actions,
        owners=[name for key, c in cleaned.items() for name in (c.owner.name, *sharers.get(key, []))],
        skipped=skipped,
        notes=notes,
        strengths=[(c.rotation_strength, c.translation_strength) for c in parts],
    )
