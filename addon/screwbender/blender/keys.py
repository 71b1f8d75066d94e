# SPDX-License-Identifier: GPL-3.0-or-later
"""Reading an object's keyed transform into arrays.

An object's key poses are its transform F-curves (location, rotation in the object's
rotation mode, scale) evaluated at the union of their key frames, in the object's own
(parent) space: exactly `obj.matrix_basis` at those frames (delta transforms aside, which
are left to the untouched `delta_*` channels). Rotation and location become rigid 4x4
poses for `polyscrew`; scale is kept apart, because the core only accepts rigid poses.

Nothing here changes Blender data; every problem raises :class:`SmoothError` with a message
meant for the animator.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import bpy
import numpy as np
import polyscrew

from ..pure import intent, packed_parts
from ..pure.keyed import (  # noqa: F401  (re-exported: the pure layer's key poses and rules, as keys.X)
    FRAME_TOLERANCE,
    REPEAT_TOLERANCE,
    ROTATION_PATHS,
    KeyedMotion,
    SmoothError,
    _union,
    baked_channels,
    compose,
    continued,
    key_motion,
    rotation_matrices,
    rotation_path,
    rotation_width,
    transform_paths,
)
from . import bulk, channels, curves, modifiers, owners


def _key_points(fcurve: bpy.types.FCurve) -> np.ndarray:
    """(K, 2) key frames and values of an F-curve."""
    co = np.empty(2 * len(fcurve.keyframe_points), dtype=np.float32)
    bulk.get(fcurve.keyframe_points, "co", co)
    return co.reshape(-1, 2).astype(np.float64)


def playing_strips(adt) -> list:
    """The NLA strips Blender plays under the action of `adt` (an AnimData): none when the
    NLA is off, never those of muted tracks or muted strips."""
    if adt is None or not getattr(adt, "use_nla", True):
        return []
    return [strip for track in adt.nla_tracks if not track.mute for strip in track.strips if not strip.mute]


def no_action(name: str, adt) -> str:
    """Why `name` (with the AnimData `adt`, maybe None) has nothing to smooth: no active
    action; when its motion lives in NLA strips, that, and what to do."""
    strips = [(track, strip) for track in adt.nla_tracks for strip in track.strips] if adt is not None else []
    if not strips:
        return f"{name}: no animation (no active action): skipped"
    track, strip = strips[0]
    more = f" and {len(strips) - 1} more" if len(strips) > 1 else ""
    return (
        f"{name}: its motion is in NLA strips ('{strip.name}' on track '{track.name}'{more}), not in an active "
        "action, and Smooth Motion smooths the active action: make the strip's action the active one "
        "(Action Editor), mute or delete the strip, smooth, then Push Down again: skipped"
    )


def check_editable(owner: owners.Owner | bpy.types.Object, checked: dict | None = None) -> None:
    """Raises :class:`SmoothError` unless `owner` (an object or a pose bone, see
    :mod:`owners`) has an editable action driving its transform. `checked`, a dict kept for
    one run, remembers the objects that passed the checks of the object (its bones are then
    checked for themselves alone: many bones of one rig)."""
    owner = owners.as_owner(owner)
    obj = owner.obj
    name = owner.name
    if not owner.exists():
        raise SmoothError(f"{name}: no such bone any more: skipped")
    adt = obj.animation_data
    passed = ("editable", obj.as_pointer())
    if checked is None or passed not in checked:
        _check_object(obj, adt, name)
        if checked is not None:
            checked[passed] = True
    paths = {owner.path(p) for p in transform_paths(owner.rotation_mode)}
    driven = sorted(f"{d.data_path}[{d.array_index}]" for d in adt.drivers if d.data_path in paths)
    if driven:
        raise SmoothError(f"{name}: drivers on {', '.join(driven)}: skipped")


def _check_object(obj: bpy.types.Object, adt, name: str) -> None:
    """:func:`check_editable`'s checks of the object (`adt` its animation data), the owner named `name`."""
    if obj.library is not None or getattr(obj, "override_library", None) is not None:
        raise SmoothError(f"{name}: object is linked from a library and cannot be edited: skipped")
    if adt is None or adt.action is None:
        raise SmoothError(no_action(name, adt))
    action = adt.action
    if action.library is not None or not getattr(action, "is_editable", True):
        raise SmoothError(f"{name}: action '{action.name}' is linked from a library and cannot be edited: skipped")
    if getattr(adt, "use_tweak_mode", False):
        raise SmoothError(
            f"{name}: is in NLA tweak mode (editing a strip's action): exit it first (NLA Editor, Tab): skipped"
        )
    solo = [track.name for track in adt.nla_tracks if track.is_solo]
    if solo and getattr(adt, "use_nla", True):
        raise SmoothError(
            f"{name}: NLA track '{solo[0]}' is Solo, so Blender plays that track alone and not the action: "
            "turn Solo off to smooth the action: skipped"
        )
    strips = len(playing_strips(adt))
    if strips:
        raise SmoothError(
            f"{name}: has {strips} NLA strip(s) that play under the action; the baked action would not be "
            "what the NLA plays (mute their tracks to smooth the action alone): skipped"
        )


def read(
    owner: owners.Owner | bpy.types.Object,
    closed: str = "AUTO",
    action: bpy.types.Action | None = None,
    slot: str = "",
    extend_to: tuple[float, float] | None = None,
    fcurves: list | None = None,
    analyse: bool = True,
    turns: str = "AUTO",
    packed: tuple[list, curves.Packed] | None = None,
    cache: dict | None = None,
    key_values: bool = False,
) -> KeyedMotion:
    """The key poses of `owner`: an object, or a pose bone (an :class:`owners.Owner`).

    `closed` is "AUTO" (closed when a Cycles modifier is on a transform F-curve), "ON" or
    "OFF". For a closed motion whose last key repeats the first pose, that key only closes the
    period: it is dropped from the poses and `period` is its distance from the first key.
    `action` (with the slot identifier `slot`, 4.4+) reads the keys of another action than the
    active one, with the object's own values for unkeyed channels (re-smoothing reads the
    original keys under a smoothed result). `analyse=False` reads the key poses alone (no spins,
    holds or extended cycles: what Remove Noise needs). `extend_to` is the frame range to be covered
    when a Cycles modifier plays the keys on (Repeat with Offset, Mirror): the keys are
    extended by Blender's playback over it, plus :data:`intent.EXTRA_CYCLES` on each side.
    `fcurves`, when given, are the F-curves to read from instead (the caller's grouping by
    owner, :func:`owners.curves_by_owner`: many bones of one action are then read without
    scanning all its curves for each bone). `turns` is the option Turns (:data:`intent.TURNS`):
    which spans Blender's playback turns the long way round are followed (spins) and which
    are taken the short way (flips, reported in `removed`). `cache`, a dict the caller keeps
    for one run, holds the keys read per set of curves: objects sharing an action (linked
    duplicates) read its curves once. `packed`: (curves, their keys) that the caller has read
    with `curves.read(curves, keys_only=True)` already (the preview's key hash): used, not read
    again, when `curves` are the transform curves read here. `key_values`: when every curve is
    keyed on every key frame without modifiers (a capture), the channels are its key values,
    which is what Blender plays there, without evaluating the playback (Remove Noise).

    Raises :class:`SmoothError` for anything the add-on cannot smooth, also for curves that
    `polyscrew` refuses to play (a NaN key or handle, keys out of time order, too many keys):
    the caller skips that owner and tells why.
    """
    got = read_many(
        [Request(owners.as_owner(owner), closed, action, slot, extend_to, fcurves, analyse, turns, packed, key_values)],
        cache,
    )[0]
    if isinstance(got, SmoothError):
        raise got
    return got


@dataclass
class Request:
    """One owner to read and how (the arguments of :func:`read` but `cache`)."""

    owner: owners.Owner
    closed: str = "AUTO"
    action: bpy.types.Action | None = None
    slot: str = ""
    extend_to: tuple[float, float] | None = None
    fcurves: list | None = None
    analyse: bool = True
    turns: str = "AUTO"
    packed: tuple[list, curves.Packed] | None = None
    key_values: bool = False


def read_many(requests: list[Request], cache: dict | None = None) -> list[KeyedMotion | SmoothError]:
    """:func:`read` of every owner of `requests` (each with its own options), in order: its
    :class:`KeyedMotion`, or the :class:`SmoothError` saying why it is skipped (the same
    motion and the same message as :func:`read` of that owner alone).

    Every owner is looked up in Blender as :func:`read` does (its checks, its transform
    curves); the curves of all of them are read in ONE `curves.read` call (one `foreach_get`
    per attribute per curve; curves shared by owners, or read before into `cache` or given
    as `packed`, not again), and ONE `polyscrew.read_owners` call builds every owner's
    playback and returns its key frames, channels and key poses there, its spans' analysis
    (:func:`intent.analyse_turns`) and its playback at the frames that analysis adds to spins.
    Python per owner remains for the rare paths (extended cycles, Turns: Shortest) and the
    report's words. An
    owner the batch refuses (curves `polyscrew` cannot play, a keyed scale not positive, ...)
    is read alone afterwards (:func:`_read`), which says why.
    """
    cache = {} if cache is None else cache
    out: list = [None] * len(requests)
    plans = []
    for i, request in enumerate(requests):
        try:
            plans.append((i, _plan(request, cache)))
        except SmoothError as err:
            out[i] = err
    alone = set()
    parts = _parts([plan for _, plan in plans], cache, alone)
    batch = [(i, plan) for i, plan in plans if plan.read_key not in alone]
    if batch:
        for (i, _), got in zip(batch, _read_batch([plan for _, plan in batch], parts)):
            out[i] = got
    for i, plan in plans:
        if out[i] is None:  # refused by the batch, or curves it cannot pack: alone, for its own message
            out[i] = _read_alone(plan.request, cache)
    return out


@dataclass
class _Plan:
    """What :func:`_plan` found of one owner in Blender."""

    request: Request
    #: (property, index) -> its keyed, unmuted transform curve, in the order listed.
    found: dict
    located: bool
    #: The curves' identity: (column, pointer) pairs.
    read_key: tuple
    #: The curves with modifiers, and the Cycles modes (before, after) per curve.
    modified: dict
    modes: dict
    statics: dict
    extended: bool


def _plan(request: Request, cache: dict) -> _Plan:
    """The Blender lookups :func:`_read` makes for `request`'s owner before reading its keys;
    raises :class:`SmoothError` as it does."""
    owner = request.owner
    check_editable(owner, cache)
    found, located = _found(owner, request.action, request.slot, request.fcurves)
    modified = {key: fc for key, fc in found.items() if len(fc.modifiers)}
    modes = _cycle_modes(modified)
    paths = transform_paths(owner.rotation_mode)
    statics = {path: np.array(getattr(owner.target, path), dtype=np.float64) for path in paths}
    extended = request.closed == "AUTO" and any(m in intent.EXTENDED_CYCLES for pair in modes.values() for m in pair)
    read_key = tuple((key, fc.as_pointer()) for key, fc in found.items())
    return _Plan(request, found, located, read_key, modified, modes, statics, extended)


def _found(owner: owners.Owner, action, slot: str, fcurves: list | None) -> tuple[dict, bool]:
    """:func:`keyed_curves` of the owner's curves (`fcurves`, or those of `action`'s slot
    `slot`, or of its active action); :class:`SmoothError` when it has none."""
    if fcurves is None:
        fcurves = channels.object_fcurves(owner.obj) if action is None else channels.action_fcurves(action, slot)
    found, located = keyed_curves(owner, fcurves)
    if not found:
        paths = transform_paths(owner.rotation_mode)
        raise SmoothError(f"{owner.name}: no keyed transform channels (location, {paths[1]}, scale): skipped")
    return found, located


def keyed_curves(owner: owners.Owner, listed: list) -> tuple[dict, bool]:
    """The curves :func:`read` reads of `owner` among `listed`, per (property, index), in
    their order: its transform curves, keyed and not muted (no location for a connected
    bone); and whether its location moves it."""
    paths = transform_paths(owner.rotation_mode)
    # A bone connected to its parent ignores its location (Blender's BKE_pchan_to_mat4): its
    # pose has no translation, and its location curves are not the bake's business.
    located = not owner.bone or not owner.obj.data.bones[owner.bone].use_connect
    found = {}
    for fc in listed:
        prop = owner.prop_of(fc.data_path)
        if prop in paths and not fc.mute and len(fc.keyframe_points) > 0 and (located or prop != "location"):
            found[prop, fc.array_index] = fc
    return found, located


def _cycle_modes(modified: dict) -> dict:
    """(property, index) -> the (mode_before, mode_after) of the first unmuted Cycles modifier
    of each curve of `modified` that has one."""
    modes = {}
    for key, fc in modified.items():
        for modifier in fc.modifiers:
            if modifier.type == "CYCLES" and not modifier.mute:
                modes[key] = (modifier.mode_before, modifier.mode_after)
                break
    return modes


def _parts(plans: list[_Plan], cache: dict, alone: set) -> dict:
    """Per `read_key` of `plans`, its curves' packed keys: from `cache` or the request's
    `packed`, the others read in one `curves.read` call (into `cache`). The read keys of
    curves that cannot be packed join `alone` (their owners read alone, which says why)."""
    parts, wanted = {}, {}
    for plan in plans:
        key = plan.read_key
        if key in parts or key in wanted:
            continue
        chosen = list(plan.found.values())
        given = plan.request.packed
        if key in cache:
            if cache[key][0] is None:
                alone.add(key)
            else:
                parts[key] = cache[key][0]
        elif given is not None and [fc.as_pointer() for fc in given[0]] == [fc.as_pointer() for fc in chosen]:
            parts[key] = given[1]
        else:
            wanted[key] = chosen
    while wanted:
        union = [fc for chosen in wanted.values() for fc in chosen]
        try:
            packed = curves.read(union, keys_only=True)
        except curves.UnsupportedCurve as err:
            bad = {fc.as_pointer() for fc, _ in err.problems}
            refused = [k for k, chosen in wanted.items() if any(fc.as_pointer() in bad for fc in chosen)] or list(wanted)
            for key in refused:
                alone.add(key)
                del wanted[key]
            continue
        start = 0
        for key, chosen in wanted.items():
            parts[key] = packed_parts.subset(packed, list(range(start, start + len(chosen))))
            cache[key] = (parts[key], None, None)
            start += len(chosen)
        break
    return parts


def _read_batch(plans: list[_Plan], parts: dict) -> list[KeyedMotion | SmoothError | None]:
    """Each plan's key motion from one `polyscrew.read_owners` call (None: refused, to be
    read alone), or the :class:`SmoothError` its finishing raised."""
    order = list(dict.fromkeys(plan.read_key for plan in plans))
    joined = packed_parts.joined([parts[key] for key in order]) if len(order) > 1 else parts[order[0]]
    starts, at = {}, 0
    for key in order:
        starts[key] = at
        at += len(parts[key].offsets) - 1
    columns = [column for key in order for column, _ in key]
    ranges = np.array([(starts[p.read_key], len(p.read_key)) for p in plans], dtype=np.int64).reshape(-1, 2)
    unkeyed = np.zeros((len(plans), 10))
    for o, plan in enumerate(plans):
        mode = plan.request.owner.rotation_mode
        rotation = plan.statics[rotation_path(mode)]
        unkeyed[o, :3] = plan.statics["location"]
        unkeyed[o, 3 : 3 + len(rotation)] = rotation
        unkeyed[o, 7:] = plan.statics["scale"]
    request = [plan.request for plan in plans]
    playbacks, frames, counts, location, rotation, scale, poses, spans, status = polyscrew.read_owners(
        ranges, columns, unkeyed, [plan.request.owner.rotation_mode for plan in plans],
        located=np.array([p.located for p in plans], dtype=np.int64),
        key_values=np.array([r.key_values and not p.modified for r, p in zip(request, plans)], dtype=np.int64),
        turns=[r.turns if r.analyse and not p.extended else None for r, p in zip(request, plans)],
        **joined.arguments(),
    )
    held, pops, turn, flips, inserted, inserted_counts, at_location, at_rotation, at_scale = spans
    key_at = np.concatenate(([0], np.cumsum(counts)))
    span_at = np.concatenate(([0], np.cumsum(np.where(status == 1, np.maximum(counts - 1, 0), 0))))
    inserted_at = np.concatenate(([0], np.cumsum(inserted_counts)))
    out = []
    for o, plan in enumerate(plans):
        if status[o] < 0:
            out.append(None)
            continue
        k0, k1 = int(key_at[o]), int(key_at[o + 1])
        mode = plan.request.owner.rotation_mode
        w = rotation_width(mode)
        analysed = None
        if status[o] == 1:
            s0, s1 = int(span_at[o]), int(span_at[o + 1])
            i0, i1 = int(inserted_at[o]), int(inserted_at[o + 1])
            played = {"location": at_location[i0:i1], rotation_path(mode): np.ascontiguousarray(at_rotation[i0:i1, :w]),
                      "scale": at_scale[i0:i1]}
            analysed = (held[s0:s1], pops[s0:s1], turn[s0:s1], inserted[i0:i1], flips[s0:s1], played)
        read = _Read(
            frames[k0:k1], location[k0:k1], np.ascontiguousarray(rotation[k0:k1, :w]), scale[k0:k1], poses[k0:k1],
            parts[plan.read_key], playbacks[o], analysed,
        )
        try:
            out.append(_finish(plan, read))
        except SmoothError as err:
            out.append(err)
        except ValueError as err:  # polyscrew refusing the poses of a rare path
            out.append(SmoothError(f"{plan.request.owner.name}: {err}: skipped"))
    return out


@dataclass
class _Read:
    """What `polyscrew.read_owners` read of one owner."""

    frames: np.ndarray
    location: np.ndarray
    rotation: np.ndarray
    scale: np.ndarray
    poses: np.ndarray
    packed: curves.Packed
    playback: object
    spans: tuple | None


def _finish(plan: _Plan, read: _Read) -> KeyedMotion:
    """The key motion of a plan from what the batch read (:func:`_read`'s steps after the
    playback: the modifiers' checks, the options, :func:`key_motion`)."""
    request, owner = plan.request, plan.request.owner
    mode = owner.rotation_mode
    paths = transform_paths(mode)
    frames = read.frames
    stacked = _stacked(owner, plan.modified, (float(frames[0]), float(frames[-1])))
    source = intent.Source(
        packed=read.packed, columns=list(plan.found), static=plan.statics, mode=mode, rotation_path=paths[1],
        located=plan.located, made=read.playback,
    )
    scale_axes = np.array([("scale", i) in plan.found for i in range(3)])
    cyclic = bool(plan.modes)
    closed = request.closed
    is_closed = (cyclic and not plan.extended) if closed == "AUTO" else closed == "ON"
    kept = modifiers.describe({key: plan.found[key] for key in stacked})
    return key_motion(
        owner.name, mode, frames, read.poses, read.location, read.rotation, read.scale, scale_axes, source,
        plan.modes, cyclic, plan.extended, is_closed, kept, request.extend_to, request.analyse, request.turns,
        plan.located, owner, body_size(owner), stacked, frozenset(plan.found), spans=read.spans,
    )


def _stacked(owner: owners.Owner, modified: dict, key_range: tuple[float, float]) -> dict:
    """The modifiers kept on top of the smoothed curves, per (property, index) of `modified`
    (the curves with modifiers); :class:`SmoothError` for a modifier that cannot be kept
    over the keys' range `key_range`."""
    for (prop, index), fc in modified.items():
        reason = modifiers.refusal(fc, key_range)
        if reason is not None:
            raise SmoothError(f"{owner.name}: {owner.path(prop)}[{index}]: {reason}: skipped")
    return {key: stack for key, stack in ((key, modifiers.kept(fc)) for key, fc in modified.items()) if stack}


def _read_alone(request: Request, cache: dict) -> KeyedMotion | SmoothError:
    """:func:`_read` of one request: its key motion, or the :class:`SmoothError` saying why not."""
    owner = request.owner
    try:
        return _read(
            owner, request.closed, request.action, request.slot, request.extend_to, request.fcurves,
            request.analyse, request.turns, cache, request.packed, request.key_values,
        )
    except SmoothError as err:
        return err
    except ValueError as err:  # polyscrew refusing the curves or the key poses
        return SmoothError(f"{owner.name}: {err}: skipped")


def _read(
    owner: owners.Owner,
    closed: str,
    action: bpy.types.Action | None,
    slot: str,
    extend_to: tuple[float, float] | None,
    fcurves: list | None,
    analyse: bool,
    turns: str = "AUTO",
    cache: dict | None = None,
    given: tuple[list, curves.Packed] | None = None,
    key_values: bool = False,
) -> KeyedMotion:
    """:func:`read`, raising `ValueError` for what `polyscrew` refuses."""
    check_editable(owner, cache)
    target = owner.target
    name = owner.name
    mode = owner.rotation_mode
    paths = transform_paths(mode)
    found, located = _found(owner, action, slot, fcurves)
    # Each curve's keys are read once (issue 27): packed for Blender's playback, and the key
    # frames and values taken from that; only curves it cannot play are read for their keys alone.
    columns = list(found)
    notes = []
    read_key = tuple((key, fc.as_pointer()) for key, fc in found.items()) if cache is not None else None
    if read_key is not None and read_key in cache:
        packed, note, points = cache[read_key]
        if points is None:  # (read by read_many: the key points taken from the packed keys)
            co, bounds = packed.co.astype(np.float64), packed.offsets.tolist()
            points = {key: co[bounds[i] : bounds[i + 1]] for i, key in enumerate(columns)}
    else:
        note = None
        try:
            chosen = [found[c] for c in columns]
            if given is not None and [fc.as_pointer() for fc in given[0]] == [fc.as_pointer() for fc in chosen]:
                packed = given[1]
            else:
                packed = curves.read(chosen, keys_only=True)
        except curves.UnsupportedCurve as err:
            packed = None
            note = f"{err}: smoothed from the key values alone (spins, holds and easing not read)"
            points = {key: _key_points(fc) for key, fc in found.items()}
        else:
            co, bounds = packed.co.astype(np.float64), packed.offsets.tolist()
            points = {key: co[bounds[i] : bounds[i + 1]] for i, key in enumerate(columns)}
        if read_key is not None:
            cache[read_key] = (packed, note, points)
    if note is not None:
        notes.append(note)
    frames = _union([p[:, 0] for p in points.values()])
    if len(frames) < 2:
        raise SmoothError(f"{name}: only one key frame ({frames[0]:g}); smoothing needs at least two: skipped")
    # F-curve modifiers: smoothing works on what the keys make, the modifiers are kept on top
    modified = {key: fc for key, fc in found.items() if len(fc.modifiers)}
    stacked = _stacked(owner, modified, (float(frames[0]), float(frames[-1])))

    statics = {path: np.array(getattr(target, path), dtype=np.float64) for path in paths}
    source = None
    if packed is not None:
        try:
            source = intent.Source(
                packed=packed, columns=columns, static=statics, mode=mode, rotation_path=paths[1], located=located
            )
        except ValueError as err:  # polyscrew.Playback refuses the keys: say which curve ("curve 2")
            named = _curves_named(str(err), [f"{owner.path(prop)}[{index}]" for prop, index in columns])
            raise SmoothError(f"{name}: {named}: skipped") from err

    def evaluate(path: str, size: int) -> np.ndarray:
        """The channels at the key frames (source-less: a loop over keys, not frames)."""
        out = np.empty((len(frames), size))
        for i in range(size):
            fc = found.get((path, i))
            if fc is None:
                out[:, i] = statics[path][i]
            elif (path, i) not in modified and np.array_equal(points[path, i][:, 0], frames):
                out[:, i] = points[path, i][:, 1]  # keyed on every key frame: its key values
            else:
                out[:, i] = [fc.evaluate(f) for f in frames]
        return out

    # Curves keyed on every key frame without modifiers play their key values there (a
    # capture): with `key_values`, taken as they are, without evaluating the playback.
    every_frame = key_values and not modified and all(np.array_equal(p[:, 0], frames) for p in points.values())
    if source is not None and not every_frame:
        at_keys = source.channels(frames)
        location, rotation, scale = at_keys["location"], at_keys[paths[1]], at_keys["scale"]
    else:
        location = evaluate("location", 3) if located else np.zeros((len(frames), 3))
        rotation = evaluate(paths[1], rotation_width(mode))
        scale = evaluate("scale", 3)
    for label, values in (("location", location), (paths[1], rotation), ("scale", scale)):
        if not np.all(np.isfinite(values)):
            raise SmoothError(f"{name}: {label} has a non-finite key value: skipped")
    scale_axes = np.array([("scale", i) in found for i in range(3)])
    bad = np.argwhere((scale <= 0.0) & scale_axes)
    if len(bad):
        k, axis = bad[0]
        raise SmoothError(
            f"{name}: scale {'XYZ'[axis]} is {scale[k, axis]:g} at frame {frames[k]:g}; "
            "zero or negative scale cannot be smoothed when it is keyed (a static negative scale, "
            "a mirrored object, can): skipped"
        )

    poses = compose(location, rotation_matrices(rotation, mode))
    modes = _cycle_modes(modified)  # (property, index) -> Cycles modifier (mode_before, mode_after)
    cyclic = bool(modes)
    extended = (
        source is not None
        and closed == "AUTO"
        and any(mode_ in intent.EXTENDED_CYCLES for pair in modes.values() for mode_ in pair)
    )
    is_closed = (cyclic and not extended) if closed == "AUTO" else closed == "ON"
    kept = list(notes) + modifiers.describe({key: found[key] for key in stacked})
    return key_motion(
        name, mode, frames, poses, location, rotation, scale, scale_axes, source, modes, cyclic, extended, is_closed,
        kept, extend_to, analyse, turns, located, owner, body_size(owner), stacked, frozenset(found),
    )


def _curves_named(message: str, names: list[str]) -> str:
    """`message` of `polyscrew`, its "curve N" (an index into the curves passed) as the
    curve's data path, "location[0]"."""

    def name(match: re.Match) -> str:
        index = int(match.group(1))
        return f"curve {names[index]}" if index < len(names) else match.group(0)

    return re.sub(r"\bcurve (\d+)\b", name, message)



def body_size(owner: owners.Owner) -> float:
    """Half the largest dimension of the owner's body: an object's bounding box (scaled), a
    bone's length; 1 for a body without extent."""
    if owner.bone:
        length = owner.obj.data.bones[owner.bone].length
        return 0.5 * length if length > 0.0 else 1.0
    obj = owner.obj
    extent = float(max(obj.dimensions)) if obj.type != "EMPTY" else float(getattr(obj, "empty_display_size", 1.0)) * 2.0
    return 0.5 * extent if extent > 0.0 else 1.0
