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

import bpy
import numpy as np

from ..pure import intent
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
    owner = owners.as_owner(owner)
    try:
        return _read(owner, closed, action, slot, extend_to, fcurves, analyse, turns, cache, packed, key_values)
    except SmoothError:
        raise
    except ValueError as err:  # polyscrew refusing the curves or the key poses
        raise SmoothError(f"{owner.name}: {err}: skipped") from err


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
    obj, target = owner.obj, owner.target
    name = owner.name
    mode = owner.rotation_mode
    paths = transform_paths(mode)
    if fcurves is not None:
        listed = fcurves
    else:
        listed = channels.object_fcurves(obj) if action is None else channels.action_fcurves(action, slot)
    # A bone connected to its parent ignores its location (Blender's BKE_pchan_to_mat4): its
    # pose has no translation, and its location curves are not the bake's business.
    located = not owner.bone or not obj.data.bones[owner.bone].use_connect
    found = {}
    for fc in listed:
        prop = owner.prop_of(fc.data_path)
        if prop in paths and not fc.mute and len(fc.keyframe_points) > 0 and (located or prop != "location"):
            found[prop, fc.array_index] = fc
    if not found:
        raise SmoothError(f"{name}: no keyed transform channels (location, {paths[1]}, scale): skipped")
    # Each curve's keys are read once (issue 27): packed for Blender's playback, and the key
    # frames and values taken from that; only curves it cannot play are read for their keys alone.
    columns = list(found)
    notes = []
    read_key = tuple((key, fc.as_pointer()) for key, fc in found.items()) if cache is not None else None
    if read_key is not None and read_key in cache:
        packed, note, points = cache[read_key]
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
    key_range = (float(frames[0]), float(frames[-1]))
    modified = {key: fc for key, fc in found.items() if len(fc.modifiers)}
    for (prop, index), fc in modified.items():
        reason = modifiers.refusal(fc, key_range)
        if reason is not None:
            raise SmoothError(f"{name}: {owner.path(prop)}[{index}]: {reason}: skipped")
    stacked = {key: stack for key, stack in ((key, modifiers.kept(fc)) for key, fc in modified.items()) if stack}

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
    modes = {}  # (property, index) -> Cycles modifier (mode_before, mode_after)
    for key, fc in modified.items():
        for modifier in fc.modifiers:
            if modifier.type == "CYCLES" and not modifier.mute:
                modes[key] = (modifier.mode_before, modifier.mode_after)
                break
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
