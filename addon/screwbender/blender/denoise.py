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

from ..pure import denoise_data, intent
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
    #: The keys to write, per curve (:func:`plan_edits`).
    edits: list = field(default_factory=list)


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


def play_at_keys(motions: list[keys.KeyedMotion]) -> dict[int, dict[str, np.ndarray]]:
    """The channels of each motion's source at its key frames (per `id(motion)`), as Blender
    plays them: one `polyscrew.channels_many` call per set of key frames (motions keyed on
    the same frames, a capture, are one call)."""
    by_frames: dict[bytes, list[keys.KeyedMotion]] = {}
    for motion in motions:
        by_frames.setdefault(motion.frames.tobytes(), []).append(motion)
    out = {}
    for chosen in by_frames.values():
        for motion, played in zip(chosen, intent.channels_many([m.source for m in chosen], chosen[0].frames)):
            out[id(motion)] = played
    return out


def near_rotations(parts: list[Cleaned]) -> None:
    """Sets each part's `near`: its smoothed rotations as channels of its mode, each written
    like the original key value at its frame (its quaternion sign, its Euler twin and whole
    turns: spins and deliberate sign flips of the keys are kept). One
    `polyscrew.rotation_channels_near` call per rotation mode for all parts (row by row: the
    same values as one call per part)."""
    by_mode: dict[str, list[Cleaned]] = {}
    for c in parts:
        by_mode.setdefault(c.motion.rotation_mode, []).append(c)
    played = play_at_keys([c.motion for c in parts if _played_at_keys(c.motion)])
    for mode, chosen in by_mode.items():
        poses = np.concatenate([c.poses for c in chosen])
        reference = np.concatenate([_original_rotation(c.motion, played.get(id(c.motion)))[c.rows] for c in chosen])
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
    out, sparse = [], []
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
                sparse.append((c, stack[b]))
            out.append(c)
    if sparse:  # every sparse owner's keys drawn back in one call
        moved, limited = denoise_data.limit_moves(
            [source for _, source in sparse], [c.poses for c, _ in sparse], [c.pivot for c, _ in sparse],
            [np.sqrt(3.0) * c.rotation_noise for c, _ in sparse], [np.sqrt(3.0) * c.translation_noise for c, _ in sparse],
        )
        for (c, _), poses, count in zip(sparse, moved, limited):
            c.poses, c.limited = poses, count
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



def _original_rotation(motion: keys.KeyedMotion, played: dict | None = None) -> np.ndarray:
    """The original rotation channel values at every key frame of `motion` (K, k); `played`:
    the channels of `motion.source` at its key frames, when :func:`near_rotations` played
    them (None: this motion needs no playback)."""
    mode = motion.rotation_mode
    if motion.source is not None:
        if played is not None:
            return np.asarray(played[keys.rotation_path(mode)], dtype=np.float64)
        path = keys.rotation_path(mode)
        read, static = read_keys(motion), motion.source.static[path]
        out = np.empty((len(motion.frames), len(static)))
        for i in range(len(static)):
            points = read.get((path, i))
            out[:, i] = static[i] if points is None else points[0][:, 1]
        return out
    # Curves the add-on cannot evaluate: continuity from the first key's values.
    return polyscrew.rotation_channels(motion.poses, mode, previous=keys.continued(mode, motion.first_rotation))


def _played_at_keys(motion: keys.KeyedMotion) -> bool:
    """Whether the original rotation of `motion` at its key frames needs its playback: some
    rotation curve is cyclic or not keyed on every key frame (else its key values are what
    Blender plays there)."""
    if motion.source is None:
        return False
    path = keys.rotation_path(motion.rotation_mode)
    read = read_keys(motion)
    cycles = dict(zip(motion.source.columns, motion.source.packed.cycles))
    for i in range(len(motion.source.static[path])):
        points = read.get((path, i))
        if points is None:
            continue
        if cycles[path, i] is not None or not _same_frames(points[0][:, 0], motion.frames):
            return True
    return False


def _same_frames(a: np.ndarray, b: np.ndarray) -> bool:
    return len(a) == len(b) and np.array_equal(a, b)


@dataclass
class CurveEdit:
    """One curve's keys as Remove Noise writes them, prepared before anything is written."""

    data_path: str
    index: int
    #: The keys (K, 2) float32: co and both handles, as written.
    co: np.ndarray
    left: np.ndarray
    right: np.ndarray
    #: (K,) the keys outside the frame range (their handles kept).
    outside: np.ndarray


def plan_edits(parts: list[Cleaned], shown: dict) -> None:
    """Sets each part's `edits`: the keys of its location and rotation curves among `shown`
    (per (object pointer, bone): the curves the result copies, not muted) as they will be
    written: every key at a key frame of the motion gets its original key back (value and
    handles, from `originals`), and the smoothed keys (in the range, not held) the smoothed
    value at their frame, their handles moving with them. Reads only (nothing is written):
    what `keys.read` read, and on a rerun the keys of the curves of the earlier result.

    Every curve's keys of every part are packed into one array: their comparison with their
    motion's key frames (a capture's keys are its key frames), their rows, targets and moves
    are each one numpy pass over it, the rotation targets one `polyscrew.angles_near_many`
    call; only curves not keyed on their motion's key frames look for their rows alone."""
    curves = []  # (part index, curve, column of the owner's values, rotation?, co, left, right)
    for o, c in enumerate(parts):
        motion, owner = c.motion, c.owner
        path = keys.rotation_path(motion.rotation_mode)
        first = {path: 3, "location": 0}  # the owner's values: location x, y, z then the rotation channels
        width = {path: c.near.shape[1], "location": 3 if motion.located else 0}
        originals = {(fc.data_path, fc.array_index): fc for fc in c.originals}
        # What keys.read read (one foreach_get per property and curve): the original keys, and on
        # a first run also those of the result's curves (a copy of them): nothing is read again.
        read = read_keys(motion)
        for fc in shown.get((owner.obj.as_pointer(), owner.bone), []):
            prop = owner.prop_of(fc.data_path)
            if fc.mute or fc.array_index >= width.get(prop, 0) or not len(fc.keyframe_points):
                continue
            points = fc.keyframe_points
            was = read.get((prop, fc.array_index))
            if was is None or len(was[0]) != len(points):
                was = None
            if originals or was is None:  # a rerun: the result is a copy of an earlier result
                co, left, right = _points(fc), _points(fc, "handle_left"), _points(fc, "handle_right")
            else:
                co, left, right = was  # (copied when packed below)
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
            curves.append((o, fc, first[prop] + fc.array_index, prop == path, co, left, right))
    for c in parts:
        c.edits = []
    if not curves:
        return
    # Every part's key frames as rows of one table: which are smoothed, which in the range, and
    # the values the smoothed keys take (location, then the rotation channels, :func:`near_rotations`).
    counts = [len(c.motion.frames) for c in parts]
    base = np.cumsum([0] + counts[:-1])
    smoothed = np.zeros(sum(counts), dtype=bool)
    in_range = np.zeros(sum(counts), dtype=bool)
    values = np.zeros((sum(counts), 7))
    for c, b in zip(parts, base.tolist()):
        smoothed[b + c.rows[~c.held]] = True
        in_range[b + c.rows] = True
        values[b + c.rows, :3] = c.poses[:, :3, 3]
        values[b + c.rows, 3 : 3 + c.near.shape[1]] = c.near
    # The keys of every curve packed (copies of what was read).
    co = np.concatenate([k[4] for k in curves])
    left = np.concatenate([k[5] for k in curves])
    right = np.concatenate([k[6] for k in curves])
    sizes = np.array([len(k[4]) for k in curves])
    starts = np.concatenate(([0], np.cumsum(sizes)[:-1]))
    part_of = np.array([k[0] for k in curves])
    # Which curves are keyed on their motion's key frames (a capture): one comparison of all keys.
    fits = np.array(counts)[part_of] == sizes
    frames = np.concatenate([parts[o].motion.frames if fit else np.full(size, np.nan)
                             for o, fit, size in zip(part_of.tolist(), fits.tolist(), sizes.tolist())])
    same = np.logical_and.reduceat(co[:, 0] == frames, starts) & fits
    row = np.arange(len(co)) - np.repeat(starts, sizes)  # (a capture's keys are its rows)
    near = np.ones(len(co), dtype=bool)
    for k in np.flatnonzero(~same).tolist():  # keys on other frames: the nearest key frame of each
        lo, hi = starts[k], starts[k] + sizes[k]
        row[lo:hi], near[lo:hi] = nearest_rows(parts[part_of[k]].motion.frames, co[lo:hi, 0])
    row += np.repeat(base[part_of], sizes)
    edit = near & smoothed[row]
    outside = ~(near & in_range[row])
    target = values[row[edit], np.repeat([k[2] for k in curves], sizes)[edit]]
    # Each rotation key's target within half a turn of the key's own original value: one call.
    turned = np.flatnonzero([k[3] for k in curves])
    if len(turned):
        edited = np.concatenate(([0], np.cumsum(edit)))
        per_curve = edited[starts + sizes] - edited[starts]
        rotation = np.repeat([k[3] for k in curves], sizes)[edit]
        target[rotation] = polyscrew.angles_near_many(
            target[rotation], co[edit, 1][rotation], [parts[part_of[k]].motion.rotation_mode for k in turned.tolist()],
            np.array([curves[k][1].array_index for k in turned.tolist()], dtype=np.int64), per_curve[turned],
        )
    # The smoothed keys moved, their handles with them.
    delta = (target - co[edit, 1]).astype(np.float32)
    left[edit, 1] += delta
    right[edit, 1] += delta
    co[edit, 1] = target  # exact, not the sum
    bounds = starts[1:]
    for k, a, b, d, out in zip(curves, np.split(co, bounds), np.split(left, bounds), np.split(right, bounds),
                               np.split(outside, bounds)):
        parts[k[0]].edits.append(CurveEdit(k[1].data_path, k[1].array_index, a, b, d, out))


def _edit_keys(fcurves: list, cleaned: Cleaned) -> None:
    """Writes the owner's keys prepared by :func:`plan_edits` into its curves among `fcurves`
    (the result's copies of the curves planned): the keys, the handles unless `fc.update()`
    makes them, and outside the frame range the handles they had."""
    by_path = {(fc.data_path, fc.array_index): fc for fc in fcurves}
    for e in cleaned.edits:
        fc = by_path[e.data_path, e.index]
        points = fc.keyframe_points
        bulk.put(points, "co", e.co.ravel())
        if not _automatic_handles(points):  # (else `fc.update()` makes them from the keys)
            bulk.put(points, "handle_left", e.left.ravel())
            bulk.put(points, "handle_right", e.right.ravel())
        fc.update()
        if e.outside.any():  # (else no handle can have changed outside the range)
            _keep_handles_outside(fc, e.outside, e.left, e.right)


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
    prepared, plans, notes, rerun, shown_of = [], [], [], [], {}
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
            shown_of[owner.obj.as_pointer(), owner.bone] = shown.get(owner.bone, [])
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
    plan_edits(list(cleaned.values()), shown_of)
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
