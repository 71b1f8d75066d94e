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

Each source curve is read once per run (issue 27): its keys are packed once
(:func:`curves.read`); that read also serves as the undo snapshot (the transaction puts back
the keys, handles and count of every curve it keyed), and the motion after the insertion is
that read with the new key spliced in: Blender recomputes the handles of the new key and of
its two neighbours only (and, on a cyclic curve, of the first and last two keys), which are
read back one by one, not the whole curve (the new key whole, the others their handles). A curve with Auto Handle Smoothing
(`auto_smoothing`: every handle may move) has its handles read again in full. Many owners of
one action (a rig's bones) share one pass over its curves (:func:`owners.curves_by_owner`).

Every owner of one run goes through the phases together (:func:`insert_keys`): the motions
before the insertions are sampled in one `polyscrew.sample_owners` call per rotation mode, and
so are the motions after (:func:`bake.sample_poses_many`), instead of two samplings per owner;
every owner's new rotation values are converted in one `polyscrew.rotation_channels_each` call
per rotation mode (:func:`_rotations`), and every owner's motion before and after compared in
one `polyscrew.turn_vectors` call (:func:`pose_changes`).
"""

from __future__ import annotations

from dataclasses import dataclass

import bpy
import numpy as np
import polyscrew

from ..pure.packed_parts import PER_KEY as _PER_KEY
from ..pure.packed_parts import joined as _joined
from ..pure.packed_parts import one as _one
from . import bake, bulk, channels, curves, keys, owners, transaction
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
    return pose_changes([(a, b)])[0]


def pose_changes(pairs: list[tuple[np.ndarray, np.ndarray]]) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`pose_change` of every `(a, b)` of `pairs`, the turns of all of them in one
    `polyscrew.turn_vectors` call (row by row: the same values as one call per pair)."""
    if not pairs:
        return []
    a = np.concatenate([a for a, _ in pairs])
    b = np.concatenate([b for _, b in pairs])
    translation = np.linalg.norm(b[:, :3, 3] - a[:, :3, 3], axis=1)
    angle = np.linalg.norm(polyscrew.turn_vectors(a, b), axis=1)  # exact near 0 and pi
    bounds = np.cumsum([len(a) for a, _ in pairs])[:-1]
    return list(zip(np.split(translation, bounds), np.split(angle, bounds)))


def _current_values(target, curves: dict, path: str, size: int, frame: float) -> np.ndarray:
    static = np.array(getattr(target, path), dtype=np.float64)
    return np.array(
        [curves[(path, i)].evaluate(frame) if (path, i) in curves else static[i] for i in range(size)]
    )


def _transform_curves(owner: owners.Owner, listed: list) -> list:
    """The curves :func:`keys.read` reads for `owner` among `listed`, in its order (keyed
    transform curves, not muted; no location for a connected bone)."""
    return list(keys.keyed_curves(owner, listed)[0].values())


def _key_codes(point) -> tuple[int, int]:
    """`polyscrew` codes of one keyframe's interpolation and easing (ValueError: unknown)."""
    return polyscrew.INTERPOLATIONS.index(point.interpolation), polyscrew.EASINGS.index(point.easing)


def _spliced(fcurve: bpy.types.FCurve, before: curves.Packed, frame: float) -> curves.Packed:
    """The packed keys of `fcurve` after a key was inserted at `frame`, from its keys `before`
    (one curve, packed): the new key added (or the replaced one updated) and the keys whose
    handles Blender recomputed read back one by one."""
    points = fcurve.keyframe_points
    n, m = int(before.offsets[-1]), len(points)
    x = before.co[:, 0]
    if m == n + 1:
        i = int(np.searchsorted(x, frame))
        rows = np.concatenate([np.arange(i), [min(i, n - 1)], np.arange(i, n)])  # a row for the new key
    elif m == n:
        i = int(np.argmin(np.abs(x - frame)))
        rows = np.arange(n)
    else:  # not a single insertion: read the curve as it is now
        return curves.read([fcurve], keys_only=True)
    after = curves.Packed(
        offsets=np.array([0, m], dtype=np.int64), extrapolation=list(before.extrapolation), cycles=list(before.cycles),
        **{name: getattr(before, name)[rows] for name in _PER_KEY},
    )
    window = {j for j in (i - 1, i, i + 1) if 0 <= j < m}
    if before.cycles and before.cycles[0] is not None:
        window |= {j for j in (0, 1, m - 2, m - 1) if 0 <= j < m}  # cycle-aware handles wrap
    for j in sorted(window):
        point = points[j]
        after.handle_left[j] = point.handle_left
        after.handle_right[j] = point.handle_right
        if j == i:  # the new (or replaced) key: all of it; the others only had their handles recomputed
            after.co[j] = point.co
            after.interpolation[j], after.easing[j] = _key_codes(point)
            after.back[j], after.amplitude[j], after.period[j] = point.back, point.amplitude, point.period
    if getattr(fcurve, "auto_smoothing", "NONE") != "NONE":  # every handle may have moved
        for name in ("handle_left", "handle_right"):
            flat = np.empty(2 * m, dtype=np.float32)
            bulk.get(points, name, flat)
            getattr(after, name)[:] = flat.reshape(-1, 2)
    return after


def _keep_packed(t: transaction.Transaction, fcurve: bpy.types.FCurve, before: curves.Packed, frame: float) -> None:
    """On failure, `fcurve` (one curve, packed `before`) gets its keys back: the key inserted
    at `frame` removed, every key's position and handles as they were (the keys' other
    properties are not touched by an insertion)."""
    n = int(before.offsets[-1])
    saved = {name: getattr(before, name).reshape(-1).copy() for name in ("co", "handle_left", "handle_right")}
    inserted = int(np.searchsorted(before.co[:, 0], frame))

    def undo() -> None:
        points = fcurve.keyframe_points
        if len(points) == n + 1:
            points.remove(points[inserted], fast=True)
        for name, values in saved.items():
            bulk.put(points, name, values)
        fcurve.update()

    t.on_rollback(undo)


def insert_key(
    owner: owners.Owner | bpy.types.Object,
    frame: float,
    options: bake.Options,
    t: transaction.Transaction,
    fcurves: list | None = None,
    known: dict | None = None,
) -> InsertResult:
    """Keys the pose the smoothed motion of `owner` (an object or a pose bone) has at `frame`
    on its transform channels (inside the transaction `t`: the curves get their old keys back
    if anything fails later): :func:`insert_keys` of one owner.

    `fcurves`: the owner's transform curves when the caller has grouped them
    (:func:`owners.curves_by_owner`). `known`: as in :func:`insert_keys`.

    Raises :class:`SmoothError` (nothing changed) when the keys cannot be smoothed.
    """
    owner = owners.as_owner(owner)
    listed = list(channels.object_fcurves(owner.obj) if fcurves is None else fcurves)
    (outcome,) = insert_keys([(owner, listed)], frame, options, t, known)
    if isinstance(outcome, SmoothError):
        raise outcome
    return outcome


def _footprint(owner: owners.Owner) -> tuple:
    """What the curves `owner` keys are known by: its action, slot and bone (linked
    duplicates share them)."""
    adt = owner.obj.animation_data
    action = adt.action.as_pointer() if adt is not None and adt.action is not None else None
    return action, channels.slot_identifier(owner.obj), owner.bone


def _rounds(footprints: list[tuple]) -> list[list[int]]:
    """The indices of `footprints` (one per owner, :func:`_footprint`) in rounds, in order: an
    owner keying the curves of an earlier owner (a linked duplicate) goes in the round after
    that owner's, so that it reads and samples the keys inserted before it, as one owner after
    another would."""
    rounds: list[list[int]] = []
    last: dict[tuple, int] = {}  # footprint -> the last round holding it
    for i, footprint in enumerate(footprints):
        r = last.get(footprint, -1) + 1
        if r == len(rounds):
            rounds.append([])
        rounds[r].append(i)
        last[footprint] = r
    return rounds


@dataclass
class _Keying:
    """One owner's insertion on its way through :func:`insert_keys`' phases."""

    owner: owners.Owner
    listed: list
    chosen: list
    packed: curves.Packed | None
    before: keys.KeyedMotion
    frames: np.ndarray
    #: The owner's curves by (property, index) and its new rotation values (:func:`_rotations`).
    by_prop: dict | None = None
    rotation: np.ndarray | None = None
    #: Set by the insertion: the owner's nested transaction, values keyed, curves keyed and made.
    one: transaction.Transaction | None = None
    values: dict | None = None
    keyed: list | None = None
    made: list | None = None
    given: tuple | None = None


def insert_keys(
    requests: list[tuple[owners.Owner, list]],
    frame: float,
    options: bake.Options,
    t: transaction.Transaction,
    known: dict | None = None,
) -> list[InsertResult | SmoothError]:
    """Keys, for each `(owner, its curves)` of `requests` (:func:`owners.curves_by_owner`'s
    lists), the pose its smoothed motion has at `frame` (see :func:`insert_key`); returns per
    request its :class:`InsertResult` or the :class:`SmoothError` refusing it (that owner left
    unchanged: its keys are inserted in a transaction nested in `t`, undone when it fails).

    In phases, for every owner together: read every owner's keys, sample every motion before
    (one `polyscrew.sample_owners` call per rotation mode: :func:`bake.sample_poses_many`),
    insert each owner's keys, read every owner's keys after, sample every motion after, compare.
    Linked duplicates keying the same curves go in later rounds (:func:`_rounds`). `known`, a
    dict the caller keeps over one run: the packed keys per set of curves read or keyed so far
    (owners sharing an action read it once, and see the keys inserted).
    """
    known = {} if known is None else known
    out: list[InsertResult | SmoothError | None] = [None] * len(requests)
    footprints = [_footprint(owner) for owner, _ in requests]
    made: dict[tuple, list] = {}  # footprint -> the curves earlier rounds made for it
    for indices in _rounds(footprints):
        # (a later round's owner lists the curves made for its footprint, as a fresh grouping would)
        this = [
            (requests[i][0], list(requests[i][1]) + [fc for fc in made.get(footprints[i], []) if fc not in requests[i][1]])
            for i in indices
        ]
        outcomes, keyed = _insert_round(this, frame, options, t, known)
        for i, outcome, keying in zip(indices, outcomes, keyed):
            out[i] = outcome
            if keying is not None and keying.made:
                made.setdefault(footprints[i], []).extend(keying.made)
    return out


def _read_before(
    requests: list[tuple[owners.Owner, list]], frame: float, options: bake.Options, known: dict
) -> list[_Keying | SmoothError]:
    """The keys of every owner of `requests` ((owner, its curves)) before the insertion, in
    one :func:`keys.read_many` call (each curve packed once: `known` holds the curves packed
    before, by their pointers)."""
    chosen = [_transform_curves(owner, listed) for owner, listed in requests]
    given = [known.get(tuple(fc.as_pointer() for fc in c)) for c in chosen]
    read = keys.read_many([
        keys.Request(owner, options.closed, fcurves=listed, turns=options.turns, packed=(c, g) if g is not None else None)
        for (owner, listed), c, g in zip(requests, chosen, given)
    ])
    out = []
    for (owner, listed), c, before in zip(requests, chosen, read):
        if isinstance(before, SmoothError):
            out.append(before)
            continue
        source = before.source
        same = source is not None and source.columns == [(owner.prop_of(fc.data_path), fc.array_index) for fc in c]
        packed = source.packed if same else None  # (None: keys.read read the key values alone)
        out.append(_Keying(owner, listed, c, packed, before, check_frames(before, frame)))
    return out


def _insert_round(
    requests: list[tuple[owners.Owner, list]], frame: float, options: bake.Options, t: transaction.Transaction,
    known: dict,
) -> tuple[list[InsertResult | SmoothError], list[_Keying | None]]:
    """:func:`insert_keys` of owners that key different curves; also each owner's keying
    where it succeeded (else None)."""
    out: list[InsertResult | SmoothError | None] = [None] * len(requests)
    done: list[_Keying | None] = [None] * len(requests)
    work: list[tuple[int, _Keying]] = []
    for i, keying in enumerate(_read_before([(owner, list(listed)) for owner, listed in requests], frame, options, known)):
        if isinstance(keying, SmoothError):
            out[i] = keying
        else:
            work.append((i, keying))
    before = bake.sample_poses_many([(k.owner, k.before, k.frames) for _, k in work], options)
    sampled = []
    for (i, keying), got in zip(work, before):
        if isinstance(got, SmoothError):
            out[i] = got
        else:
            sampled.append((i, keying, got))
    _rotations([(keying, poses) for _, keying, (poses, _) in sampled], frame)
    opened = []
    try:
        for _, keying, (poses, scales) in sampled:
            keying.one = transaction.Transaction(t)
            opened.append(keying.one)
            _insert(keying, poses, scales, frame)
        reread = []
        read = keys.read_many([
            keys.Request(keying.owner, options.closed, fcurves=keying.listed, turns=options.turns, packed=keying.given)
            for _, keying, _ in sampled
        ])
        for (i, keying, _), after in zip(sampled, read):
            if isinstance(after, SmoothError):
                out[i] = after
            else:
                reread.append((i, keying, after))
        after = bake.sample_poses_many([(k.owner, a, k.frames) for _, k, a in reread], options)
        poses_after = {i: got for (i, _, _), got in zip(reread, after)}
        compared = []
        for i, keying, (poses, _) in sampled:
            got = poses_after.get(i, out[i])
            if isinstance(got, SmoothError):
                out[i] = got
                opened.remove(keying.one)
                problems = keying.one.rollback()
                if problems:
                    raise transaction.RolledBack(f"{got}; undoing it also failed: {'; '.join(problems)}") from got
                continue
            opened.remove(keying.one)
            keying.one.commit()
            if keying.given is not None:
                known[tuple(fc.as_pointer() for fc in keying.given[0])] = keying.given[1]
            compared.append((i, keying, poses, got[0]))
            done[i] = keying
        changes = pose_changes([(before, after) for _, _, before, after in compared])
        for (i, keying, _, _), change in zip(compared, changes):
            out[i] = _result(keying, change, frame)
    except BaseException:
        for one in opened:  # the parent undoes them with everything else
            one.commit()
        raise
    return out, done


def _at(keying: _Keying, frame: float) -> int:
    """The row of `frame` among `keying`'s compared frames."""
    return int(np.searchsorted(keying.frames, frame))


def _rotations(sampled: list[tuple[_Keying, np.ndarray]], frame: float) -> None:
    """Sets, for every `(keying, poses sampled before)` of `sampled`, its owner's curves by
    (property, index) (`by_prop`) and its new rotation values at `frame` (`rotation`): the
    pose sampled at `frame` in the owner's rotation mode, continued from the values its
    curves (or its static channels) have there. One `polyscrew.rotation_channels_each` call
    per rotation mode for every owner, row by row the same values as one
    `rotation_channels(pose, mode, previous=...)` call per owner."""
    by_mode: dict[str, list[tuple[_Keying, np.ndarray, np.ndarray]]] = {}
    for keying, poses in sampled:
        owner = keying.owner
        keying.by_prop = {}
        for fc in keying.listed:
            prop = owner.prop_of(fc.data_path)
            if prop is not None:
                keying.by_prop[(prop, fc.array_index)] = fc
        mode = owner.rotation_mode
        previous = _current_values(owner.target, keying.by_prop, keys.rotation_path(mode), keys.rotation_width(mode), frame)
        by_mode.setdefault(mode, []).append((keying, poses[_at(keying, frame)], previous))
    for mode, rows in by_mode.items():
        values = polyscrew.rotation_channels_each(
            np.stack([pose for _, pose, _ in rows]), mode, np.stack([previous for _, _, previous in rows])
        )
        for (keying, _, _), row in zip(rows, values):
            keying.rotation = row


def _insert(keying: _Keying, poses: np.ndarray, scales: np.ndarray | None, frame: float) -> None:
    """Inserts the keys of `keying`'s owner at `frame` (inside `keying.one`), the pose sampled
    before at `frame` (among the compared frames: sampling is per frame, the same values as
    sampling `frame` alone) with the rotation values :func:`_rotations` set, and splices them
    into its packed keys (`keying.given`)."""
    owner, listed, chosen, packed, before = keying.owner, keying.listed, keying.chosen, keying.packed, keying.before
    t, by_prop = keying.one, keying.by_prop
    at = _at(keying, frame)
    pose = poses[at : at + 1]
    scale = scales[at : at + 1] if scales is not None else None
    values = {
        "location": pose[0, :3, 3].copy(),
        keys.rotation_path(owner.rotation_mode): keying.rotation,
    }
    if not before.located:
        del values["location"]  # a connected bone: Blender ignores its location
    if before.scale_keyed:
        values["scale"] = scale[0]  # only its keyed axes are keyed again (below)

    column = {fc.as_pointer(): c for c, fc in enumerate(chosen)} if packed is not None else {}
    adt = owner.obj.animation_data
    bag = channels.ensure_container(adt.action, channels.assigned_slot(owner.obj))
    keyed, made = [], []
    for path, vector in values.items():
        for index, value in enumerate(vector):
            if path == "scale" and not before.scale_axes[index]:
                continue  # unkeyed scale stays unkeyed (a mirrored object's static -1 included)
            fcurve = by_prop.get((path, index))
            if fcurve is None:
                fcurve = t.new_fcurve(bag, owner.path(path), index, owner.group)
                made.append(fcurve)
            elif fcurve.as_pointer() in column:
                _keep_packed(t, fcurve, _one(packed, column[fcurve.as_pointer()]), frame)
            else:
                t.keep_keys(fcurve)
            channels.insert_key(fcurve, frame, float(value))
            keyed.append(fcurve.as_pointer())
    keying.values, keying.made = values, made

    if packed is not None:  # the keys now: the read above with the new keys spliced in
        listed_after = listed + made
        chosen_after = _transform_curves(owner, listed_after)
        keyed_set = set(keyed)
        parts, unread = [], []
        for fc in chosen_after:
            c = column.get(fc.as_pointer())
            if c is None:
                unread.append(fc)  # a curve without keys before: never read
                parts.append(None)
            elif fc.as_pointer() in keyed_set:
                parts.append(_spliced(fc, _one(packed, c), frame))
            else:
                parts.append(_one(packed, c))
        if unread:
            fresh = curves.read(unread, keys_only=True)
            ones = iter(_one(fresh, c) for c in range(len(unread)))
            parts = [p if p is not None else next(ones) for p in parts]
        keying.given = (chosen_after, _joined(parts))
        keying.listed = listed_after


def _result(keying: _Keying, change: tuple[np.ndarray, np.ndarray], frame: float) -> InsertResult:
    """What the insertion of `keying` did: the motion compared before and after
    (:func:`pose_change` of the poses before and after)."""
    translation, angle = change
    worst = int(np.argmax(translation))
    return InsertResult(
        frame=frame,
        values=keying.values,
        max_translation=float(translation.max()),
        max_angle=float(angle.max()),
        worst_frame=float(keying.frames[worst]),
        checked_frames=keying.frames,
    )
