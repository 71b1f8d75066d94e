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
from dataclasses import dataclass, field

import bpy
import numpy as np
import polyscrew

from . import bulk, channels, curves, intent, modifiers, owners

#: Rotation modes and the property holding the rotation in each (the core's table,
#: `polyscrew.ROTATION_MODES`: name -> (property, width)).
ROTATION_PATHS = {mode: prop for mode, (prop, _) in polyscrew.ROTATION_MODES.items()}

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
    owner: owners.Owner | None = None
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


def rotation_width(mode: str) -> int:
    """How many channels the rotation has in mode `mode` (4 or 3)."""
    return polyscrew.ROTATION_MODES[mode][1]


def transform_paths(mode: str) -> tuple[str, str, str]:
    """Location, rotation (for `mode`) and scale property names."""
    return ("location", rotation_path(mode), "scale")


def baked_channels(mode: str, located: bool, scale_axes: np.ndarray) -> list[tuple[str, int]]:
    """(property, array index) of every channel a bake writes: location (unless `located` is
    false), every rotation channel of `mode`, the keyed scale axes."""
    rotation = rotation_path(mode)
    out = [("location", i) for i in range(3)] if located else []
    out += [(rotation, i) for i in range(rotation_width(mode))]
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


def _key_points(fcurve: bpy.types.FCurve) -> np.ndarray:
    """(K, 2) key frames and values of an F-curve."""
    co = np.empty(2 * len(fcurve.keyframe_points), dtype=np.float32)
    bulk.get(fcurve.keyframe_points, "co", co)
    return co.reshape(-1, 2).astype(np.float64)


def _union(frames: list[np.ndarray]) -> np.ndarray:
    merged = np.unique(np.concatenate(frames))
    keep = np.concatenate(([True], np.diff(merged) > FRAME_TOLERANCE))
    return merged[keep]


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
    again, when `curves` are the transform curves read here.

    Raises :class:`SmoothError` for anything the add-on cannot smooth, also for curves that
    `polyscrew` refuses to play (a NaN key or handle, keys out of time order, too many keys):
    the caller skips that owner and tells why.
    """
    owner = owners.as_owner(owner)
    try:
        return _read(owner, closed, action, slot, extend_to, fcurves, analyse, turns, cache, packed)
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

    if source is not None:
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
    bake_range = None
    if extended:
        # Blender plays the keys on, shifted (offset) or mirrored, beyond their range: take
        # that playback over neighbouring cycles as keys of an open motion.
        first, last = float(frames[0]), float(frames[-1])
        cycle = last - first
        before, after = intent.EXTRA_CYCLES, intent.EXTRA_CYCLES
        if extend_to is not None:
            before += max(0, int(np.ceil((first - extend_to[0]) / cycle)))
            after += max(0, int(np.ceil((extend_to[1] - last) / cycle)))
        if before + after > intent.MAX_CYCLES:
            raise SmoothError(
                f"{name}: the frame range spans {before + after} cycles of its Cycles modifier; "
                f"at most {intent.MAX_CYCLES} are baked: shorten the Frame Range: skipped"
            )
        frames = np.concatenate(
            [frames[:-1] + c * cycle for c in range(-before, after + 1)] + [frames[-1:] + after * cycle]
        )
        played = source.channels(frames)
        location, rotation, scale = played["location"], played[paths[1]], played["scale"]
        poses = compose(location, rotation_matrices(rotation, mode))
        bake_range = (first, last)
        kept.append(f"the Cycles modifier's {_cycle_words(modes)} (the motion goes on beyond the keys)")

    held = pops = None
    is_key = np.ones(len(frames), dtype=bool)
    removed, causes = [], []
    if mode == "QUATERNION" and np.abs(np.linalg.norm(rotation, axis=1) - 1.0).max() > 1e-3:
        causes.append("non-normalised quaternion keys: Blender's playback interpolates their components")
    if source is not None and analyse:
        held, pops, turn, inserted, flips = intent.analyse_turns(source, frames, turns)
        followed = ~held & ((~flips & (mode != "QUATERNION")) if turns == "AUTO" else (turns == "BLENDER"))
        # Shortest: typed turns whose short screw turns less far than Blender's playback
        shortened = np.zeros(len(held), dtype=bool)
        if turns == "SHORTEST":
            short = np.linalg.norm(polyscrew.turn_vectors(poses[:-1], poses[1:]), axis=1)
            longer = (turn > intent.WIND_LIMIT) & (turn > short + intent.WRAP_MARGIN)
            shortened = ~held & longer & ~flips
        spans = np.stack([frames[:-1], frames[1:]], axis=1)
        if bake_range is not None:  # an extended cycle: report the keys' own period once
            once = (spans[:, 0] >= bake_range[0]) & (spans[:, 0] < bake_range[1])
            flips, shortened = flips & once, shortened & once
        elif extend_to is not None and not is_closed:
            # a Frame Range narrower than the keys smooths the spans it reaches; the source keys
            # outside it are kept as they are (range_join), their flips too: not reported
            inside = (spans[:, 1] > extend_to[0] + FRAME_TOLERANCE) & (spans[:, 0] < extend_to[1] - FRAME_TOLERANCE)
            flips, shortened = flips & inside, shortened & inside
        if flips.any():
            where = intent.frame_runs(spans[flips])
            if turns == "BLENDER":
                kept.append(f"{int(flips.sum())} flip(s) as Blender plays them (Turns: As Blender Plays) at frames {where}")
            else:
                what = "Euler wrap(s)" if mode != "QUATERNION" else "quaternion sign flip(s)"
                removed.append(f"{int(flips.sum())} flip(s) ({what} taken the short way) at frames {where}")
                causes.append("flips removed")
        if shortened.any():
            removed.append(f"{int(shortened.sum())} spin(s) taken the short way (Turns: Shortest) at frames "
                           f"{intent.frame_runs(spans[shortened])}")
            causes.append("spins taken the short way")
        if len(inserted):
            spins = int(np.sum((turn > intent.WIND_LIMIT) & followed))
            played = source.channels(inserted)
            order = np.argsort(np.concatenate([frames, inserted]), kind="stable")
            parent = np.clip(np.searchsorted(frames, np.concatenate([frames, inserted])[order][:-1], side="right") - 1, 0, len(frames) - 2)
            frames = np.concatenate([frames, inserted])[order]
            location = np.concatenate([location, played["location"]])[order]
            rotation = np.concatenate([rotation, played[paths[1]]])[order]
            scale = np.concatenate([scale, played["scale"]])[order]
            is_key = np.concatenate([is_key, np.zeros(len(inserted), dtype=bool)])[order]
            poses = compose(location, rotation_matrices(rotation, mode))
            held, pops = held[parent], pops[parent]
            kept.append(f"{spins} spin(s) over half a turn or more ({len(inserted)} poses from Blender's playback added)")
        if held.any():
            popping = int(pops.sum())
            kept.append(f"{int(held.sum())} hold(s)" + (f", {popping} with a pop" if popping else ""))
        if scale_axes.any():
            bad = np.argwhere((scale <= 0.0) & scale_axes)
            if len(bad):
                raise SmoothError(f"{name}: keyed scale reaches {scale[tuple(bad[0])]:g} between keys: skipped")

    period = None
    if is_closed:
        size = 1.0 + float(np.max(np.abs(location)))
        repeats = np.allclose(poses[-1], poses[0], atol=REPEAT_TOLERANCE * size) and np.allclose(
            np.log(scale[-1, scale_axes]), np.log(scale[0, scale_axes]), atol=REPEAT_TOLERANCE
        )  # (keyed scale is positive; an unkeyed axis is the same at every key, maybe 0)
        if repeats:
            if len(frames) < 3:
                raise SmoothError(f"{name}: a cycle needs two distinct key poses: skipped")
            period = float(frames[-1] - frames[0])
            frames, poses, scale, rotation, is_key = frames[:-1], poses[:-1], scale[:-1], rotation[:-1], is_key[:-1]
        else:
            # no closing key: the last key returns to the first after the mean key spacing
            user_keys = int(is_key.sum())
            period = float(frames[-1] - frames[0]) * user_keys / (user_keys - 1)
            if held is not None:  # the span from the last key back to the first moves
                held, pops = np.append(held, False), np.append(pops, False)
        if held is not None and held.any():
            # A cycle with holds: cut at them, as an open motion over neighbouring periods.
            first = float(frames[0])
            reps = intent.EXTRA_CYCLES
            shifts = [c * period for c in range(-reps, reps + 1)]
            count = len(frames)
            frames = np.concatenate([frames + d for d in shifts] + [frames[:1] + (reps + 1) * period])
            poses = np.concatenate([poses] * len(shifts) + [poses[:1]])
            scale = np.concatenate([scale] * len(shifts) + [scale[:1]])
            is_key = np.concatenate([is_key] * len(shifts) + [is_key[:1]])
            held, pops = np.tile(held, len(shifts)), np.tile(pops, len(shifts))
            rotation = rotation[np.arange(len(frames)) % count]
            bake_range = (first, first + period)
            # every curve the bake writes repeats, keyed or not (an unkeyed location axis
            # moves along the screw path too), as every column of a cycle without holds does
            modes = {key: ("REPEAT", "REPEAT") for key in baked_channels(mode, located, scale_axes)} if cyclic else {}
            is_closed, period = False, None
    start_index = 0
    if bake_range is not None:
        start_index = int(np.argmin(np.abs(frames - bake_range[0])))
    return KeyedMotion(
        frames=frames,
        poses=poses,
        scales=scale,
        scale_axes=scale_axes,
        rotation_mode=mode,
        first_rotation=rotation[start_index].copy(),
        closed=is_closed,
        period=period,
        cyclic=cyclic,
        owner=owner,
        located=located,
        source=source,
        held=held,
        pops=pops,
        is_key=is_key,
        bake_range=bake_range,
        cycle_modes=modes if bake_range is not None else None,
        size=body_size(owner),
        kept=kept,
        removed=removed,
        causes=causes,
        modifiers=stacked,
        keyed=frozenset(found),
    )


def _curves_named(message: str, names: list[str]) -> str:
    """`message` of `polyscrew`, its "curve N" (an index into the curves passed) as the
    curve's data path, "location[0]"."""

    def name(match: re.Match) -> str:
        index = int(match.group(1))
        return f"curve {names[index]}" if index < len(names) else match.group(0)

    return re.sub(r"\bcurve (\d+)\b", name, message)


def _cycle_words(modes: dict) -> str:
    names = sorted({m for pair in modes.values() for m in pair if m in intent.EXTENDED_CYCLES})
    return " and ".join(n.replace("_", " ").title().replace("Offset", "with Offset") for n in names)


def body_size(owner: owners.Owner) -> float:
    """Half the largest dimension of the owner's body: an object's bounding box (scaled), a
    bone's length; 1 for a body without extent."""
    if owner.bone:
        length = owner.obj.data.bones[owner.bone].length
        return 0.5 * length if length > 0.0 else 1.0
    obj = owner.obj
    extent = float(max(obj.dimensions)) if obj.type != "EMPTY" else float(getattr(obj, "empty_display_size", 1.0)) * 2.0
    return 0.5 * extent if extent > 0.0 else 1.0
