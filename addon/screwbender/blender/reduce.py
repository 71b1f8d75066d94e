# SPDX-License-Identifier: GPL-3.0-or-later
"""Reduce Keys: a dense motion (a Smooth Motion or Remove Noise result, an `nla.bake` result,
an imported capture) -> the fewest Bezier keys whose playback by Blender stays within a
tolerance of it in world space, `polyscrew.reduce_keys`.

The pipeline, as for every writing operator of the add-on:

1. read: every selected owner's transform curves once (:func:`keys.read`, which packs them
   for `polyscrew.evaluate_fcurves` with one `foreach_get` per attribute and curve), then the
   dense motion as Blender plays it (the owner's `polyscrew.Playback`) at every frame of the
   key range, plus its subframe keys: rigid poses in channel space (an object's parent
   space, a bone's `matrix_basis`), scale apart;
2. compute: ONE `polyscrew.reduce_keys` call for all owners of the operator keyed over the
   same frames (a rig, a capture; owners keyed over other ranges are a call each, so that
   each keeps its own range, which a Cycles modifier repeats). Bones whose parent
   bone is reduced with them are given `parents` and `offsets` (the rest matrices: Blender's
   `parent.matrix_local^-1 @ bone.matrix_local`), a root bone the armature object when that
   is reduced too (`offset = bone.matrix_local`), so the tolerance holds in world space along
   every chain (up to the owners' scale, which is not a rigid motion); objects are roots;
3. write: a copy of the current action whose reduced transform curves replace the dense ones
   (key values, Bezier handles and handle types, interpolation and easing as `reduce_keys`
   returned them; each curve's extrapolation, Cycles modifier, group, colour and flags kept),
   every other curve copied; the source kept and recorded for Revert (:func:`bake.new_result`,
   made by "reduce"), all or nothing.

Smooth Motion and Remove Noise with *Keys: Reduced* call :func:`reduce_bakes` (on Smooth
Motion's dense channels, before anything is written) and :func:`reduce_bag` (on the keys
Remove Noise has just written, inside its transaction).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import bpy
import numpy as np
import polyscrew

from ..pure import intent
from ..pure.reduce_plan import (  # noqa: F401  (re-exported: reduce.Options, reduce.KEY_MODES, ...)
    DEFAULT_ANGLE,
    DEFAULT_DISTANCE_M,
    DEPARTURE_SHARE,
    KEY_MODES,
    MAX_FRAMES,
    PROBES,
    RETRIES,
    Batch,
    Curve,
    Item,
    Options,
    Reduced,
    _body_error,
    _chain_order,
    _mul,
    _pad4,
    _probe_times,
    _rigid,
    _rigid_inverse,
    dense_frames,
)
from ..pure.reports import Outcome
from . import action_groups, bake, bulk, channels, keys, modifiers, owners, range_join, transaction
from .keys import SmoothError


def default_distance(scene: bpy.types.Scene) -> float:
    """1 mm in Blender units at the scene's unit scale (`unit_settings.scale_length`)."""
    scale = float(scene.unit_settings.scale_length)
    return DEFAULT_DISTANCE_M / scale if scale > 0.0 else DEFAULT_DISTANCE_M


def body_radius(owner: owners.Owner) -> float:
    """How far the owner's body reaches from its origin: an object's bounding box corner
    furthest from its origin (its scale applied), an empty's display size, a bone's length."""
    if owner.bone:
        return float(owner.obj.data.bones[owner.bone].length)
    obj = owner.obj
    if obj.type == "EMPTY":
        return float(obj.empty_display_size) * float(max(abs(s) for s in obj.scale))
    corners = np.array([tuple(c) for c in obj.bound_box], dtype=np.float64) * np.abs(np.array(obj.scale))
    return float(np.max(np.linalg.norm(corners, axis=1))) if len(corners) else 0.0


def parents_of(items: list[Item]) -> tuple[np.ndarray | None, np.ndarray | None]:
    """`parents` and `offsets` for `polyscrew.reduce_keys`: a bone whose parent bone is in the
    batch (and inherits its rotation) is that bone's child through the rest matrices; a root
    bone is the armature object's child when that is in the batch. None when no owner has a
    parent in the batch."""
    index = {(it.owner.obj.as_pointer(), it.owner.bone): i for i, it in enumerate(items)}
    parents = np.full(len(items), -1, dtype=np.int64)
    offsets = np.tile(np.eye(4), (len(items), 1, 1))
    for i, it in enumerate(items):
        if not it.owner.bone:
            continue
        bone = it.owner.obj.data.bones[it.owner.bone]
        if not bone.use_inherit_rotation:
            continue
        ptr = it.owner.obj.as_pointer()
        if bone.parent is not None:
            j = index.get((ptr, bone.parent.name))
            if j is not None:
                parents[i] = j
                offsets[i] = _mul(_rigid_inverse(_rigid(bone.parent.matrix_local)), _rigid(bone.matrix_local))
        else:
            j = index.get((ptr, ""))
            if j is not None:
                parents[i], offsets[i] = j, _rigid(bone.matrix_local)
    if not (parents >= 0).any():
        return None, None
    return parents, offsets


def solve(
    items: list[Item], frames: np.ndarray, options: Options, cyclic: bool = False, between: str = "screw"
) -> list[Reduced]:
    """One `polyscrew.reduce_keys` call for every item (all at `frames`; `between`: the
    core's reference between two frames). Raises SmoothError with polyscrew's message."""
    parents, offsets = parents_of(items)
    scaled = any(it.channels[2] for it in items)
    try:
        r = polyscrew.reduce_keys(
            np.stack([it.poses for it in items]),
            np.ascontiguousarray(frames, dtype=np.float64),
            [it.mode for it in items],
            # (one owner: a float; a size-1 array would be tried as a scalar first, which numpy
            # deprecates)
            float(items[0].radius) if len(items) == 1 else np.array([it.radius for it in items], dtype=np.float64),
            float(options.distance),
            float(options.angle),
            scales=np.stack([it.scales for it in items]) if scaled else None,
            channels=np.stack([it.channels for it in items]),
            parents=parents,
            offsets=offsets,
            constant=np.stack([it.constant for it in items]) if any(it.constant.any() for it in items) else None,
            cyclic=cyclic,
            start=np.stack([it.start for it in items]),
            per_channel=bool(options.per_channel),
            between=between,
        )
    except (ValueError, TypeError, MemoryError) as err:
        names = ", ".join(it.owner.name for it in items[:3]) + (" ..." if len(items) > 3 else "")
        raise SmoothError(f"{names}: {err}") from err
    offsets_ = np.asarray(r["offsets"]).tolist()
    owner_of = np.asarray(r["owner"])
    wanted = [set(it.written) for it in items]
    curves: list[dict] = [{} for _ in items]
    codes = {name: np.asarray(r[name]) for name in ("co", "handle_left", "handle_right", "interpolation", "easing",
                                                     "handle_type")}
    # Every curve as Blender takes it, converted once for all curves (not once per curve).
    interpolation = _enum("interpolation")[codes["interpolation"]]
    easing = _enum("easing")[codes["easing"]]
    eased_before = np.concatenate(([0], np.cumsum(codes["easing"] != 0)))  # (per curve: any eased key)
    eased = (eased_before[offsets_[1:]] - eased_before[offsets_[:-1]]) > 0
    blender = {
        "co": codes["co"].astype(np.float32),
        "handle_left": codes["handle_left"].astype(np.float32),
        "handle_right": codes["handle_right"].astype(np.float32),
        "interpolation_bytes": interpolation.astype(np.uint8),
        "interpolation": interpolation.tolist(),
        "easing": easing.tolist(),
        "handle_type": _enum("handle_left_type")[codes["handle_type"]].tolist(),
    }
    for c, (b, path, index) in enumerate(zip(owner_of.tolist(), r["path"], np.asarray(r["index"]).tolist())):
        if (path, index) not in wanted[b]:
            continue
        lo, hi = offsets_[c], offsets_[c + 1]
        part = {name: values[lo:hi] for name, values in codes.items()}
        written = {name: values[lo:hi] for name, values in blender.items()}
        written["eased"] = bool(eased[c])
        curves[b][path, index] = Curve(**part, written=written)
    return [
        Reduced(
            item=it, curves=curves[b], keys=int(r["keys"][b]),
            distance_error=float(r["distance_error"][b]), angle_error=float(r["angle_error"][b]),
        )
        for b, it in enumerate(items)
    ]


# Reading ---------------------------------------------------------------------------------


def _items(members: list[tuple[owners.Owner, keys.KeyedMotion]], frames: np.ndarray) -> list[Item]:
    """Each owner's dense motion at `frames` as Blender plays its curves, and its playback at
    the probes of every span: one `polyscrew.channels_many` call for every owner (frames and
    probes together), one `rotation_matrices` call per rotation mode. Raises SmoothError for
    the first owner whose playback is not finite or whose keyed scale is not positive."""
    n = len(frames)
    probes = _probe_times(frames)
    before_end = frames[1:] - np.minimum(1e-3, 0.01 * np.diff(frames))
    times = np.concatenate([frames, probes, before_end])
    played_all = intent.channels_many([motion.source for _, motion in members], times)
    read = []
    for (owner, motion), played in zip(members, played_all):
        rot_path = keys.rotation_path(motion.rotation_mode)
        location = played["location"] if motion.located else np.zeros_like(played["location"])
        rotation, scale = played[rot_path], played["scale"]
        for label, values in (("location", location), (rot_path, rotation), ("scale", scale)):
            if not np.all(np.isfinite(values)):
                raise SmoothError(f"{owner.name}: {label} is not finite between the keys: skipped")
        if np.any((scale <= 0.0) & motion.scale_axes):
            raise SmoothError(f"{owner.name}: keyed scale reaches zero or below: Reduce Keys needs a positive scale: skipped")
        read.append((location, rotation, scale))
    # The rotation matrices of every owner of a mode in one call (row by row: the same values).
    matrices: list = [None] * len(members)
    by_mode: dict[str, list[int]] = {}
    for k, (_, motion) in enumerate(members):
        by_mode.setdefault(motion.rotation_mode, []).append(k)
    for mode, chosen in by_mode.items():
        stacked = keys.rotation_matrices(np.concatenate([read[k][1] for k in chosen]), mode)
        for k, m in zip(chosen, np.split(stacked, len(chosen))):
            matrices[k] = m
    out = []
    for (owner, motion), (location, rotation, scale), rotations in zip(members, read, matrices):
        mode = motion.rotation_mode
        rot_path = keys.rotation_path(mode)
        # Steps: the channels hold the first frame's values exactly through the span (at the
        # probes and just before its end) and jump at its end (a CONSTANT pop).
        stacked = np.concatenate([location, rotation, scale], axis=1)
        at, inside = stacked[:n], stacked[n:].reshape(len(PROBES) + 1, n - 1, -1)
        steps = np.all(inside == at[None, :-1], axis=(0, 2)) & np.any(at[1:] != at[:-1], axis=1)
        # Linear spans: the channels at the probes on the straight line between the frames
        chord = np.stack([at[:-1] + f * (at[1:] - at[:-1]) for f in PROBES])
        linear = np.all(np.abs(inside[: len(PROBES)] - chord) <= 1e-6 * (1.0 + np.abs(chord)), axis=(0, 2))
        columns = set(motion.source.columns)
        located = motion.located and any(p == "location" for p, _ in columns)
        rotated = any(p == rot_path for p, _ in columns)
        size = keys.rotation_width(mode)
        scale_axes = motion.scale_axes
        written = [("location", i) for i in range(3)] if located else []
        written += [(rot_path, i) for i in range(size)] if rotated else []
        written += [("scale", int(i)) for i in np.flatnonzero(scale_axes)]
        poses = keys.compose(location, rotations)
        scales = np.where(scale_axes, scale, 1.0)
        m = n + len(probes)
        out.append(Item(
            owner=owner,
            mode=mode,
            poses=poses[:n],
            scales=scales[:n],
            channels=np.array([located, rotated, bool(scale_axes.any())]),
            constant=steps,
            start=_pad4(rotation[0]),
            radius=body_radius(owner),
            written=written,
            keys_before=len(motion.frames),
            cyclic=motion.cyclic,
            probe_poses=poses[n:m],
            probe_scales=scales[n:m],
            linear=linear,
            whole=int(np.sum(np.abs(frames - np.round(frames)) < keys.FRAME_TOLERANCE)),
        ))
    return out


def _with_probes(items: list[Item], frames: np.ndarray, flagged: np.ndarray) -> tuple[np.ndarray, list[Item]]:
    """The items with the probes of the `flagged` spans as dense frames too: Blender's
    playback there was read with the frames (`probe_poses`), not read again. The spans cut
    are no steps (a step is never flagged)."""
    chosen = np.concatenate([np.flatnonzero(flagged) + k * len(flagged) for k in range(len(PROBES))])
    merged = np.concatenate([frames, _probe_times(frames)[chosen]])
    order = np.argsort(merged, kind="stable")
    spans = np.searchsorted(frames, merged[order][:-1], side="right") - 1
    out = []
    for it in items:
        poses = np.concatenate([it.poses, it.probe_poses[chosen]])[order]
        scales = np.concatenate([it.scales, it.probe_scales[chosen]])[order]
        out.append(dataclasses.replace(
            it, poses=poses, scales=scales, constant=it.constant[spans] & ~flagged[spans],
            linear=it.linear[spans], probe_poses=None, probe_scales=None,
        ))
    return merged[order], out


def departure(items: list[Item], frames: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per span between dense frames: how far Blender's playback of the dense keys at the
    probes departs from the core's reference there (the screw between the frames, one
    `polyscrew.sample_many` call for all owners, levels 0, linear timing), over all owners, in world
    space along the chains: (distance, angle) as the core measures them, `|dt| + 2 r sin(a/2)`
    (+ `r |ds|` with scale) and `a`."""
    probes = _probe_times(frames)
    spans = len(frames) - 1
    parents, offsets = parents_of(items)
    world_ref, world_play = {}, {}
    dist = np.zeros(spans)
    ang = np.zeros(spans)
    # every owner's screws between its frames at the probes, in one call
    refs = polyscrew.sample_many(
        np.concatenate([it.poses for it in items]), frames, probes, levels=0, timing="linear"
    ).reshape(len(items), len(probes), 4, 4)
    for i in _chain_order(parents, len(items)):
        it = items[i]
        ref = refs[i]
        play = it.probe_poses
        if parents is not None and parents[i] >= 0:
            j = int(parents[i])
            ref = _mul(world_ref[j], _mul(offsets[i], ref))
            play = _mul(world_play[j], _mul(offsets[i], play))
        world_ref[i], world_play[i] = ref, play
        d, theta = _body_error(ref, play, it.radius)
        if it.channels[2]:
            lin = np.concatenate([it.scales[:-1] + f * np.diff(it.scales, axis=0) for f in PROBES])
            d = d + it.radius * np.linalg.norm(it.probe_scales - lin, axis=1)
        dist = np.maximum(dist, d.reshape(len(PROBES), spans).max(axis=0))
        ang = np.maximum(ang, theta.reshape(len(PROBES), spans).max(axis=0))
    return dist, ang


def read_motion(owner: owners.Owner, fcurves: list, action=None, slot: str = "") -> keys.KeyedMotion:
    """The owner's keys, read once (no analysis; a capture's key poses from its key values,
    which is what Blender plays at its key frames); refuses curves Blender plays in a way the
    add-on cannot evaluate (the reduced keys must match Blender's playback)."""
    got = read_motions([(owner, fcurves, action, slot)])[0]
    if isinstance(got, SmoothError):
        raise got
    return got


def read_motions(items: list[tuple[owners.Owner, list, object, str]]) -> list[keys.KeyedMotion | SmoothError]:
    """:func:`read_motion` of every (owner, its curves, the action read or None, its slot) of
    `items` in one :func:`keys.read_many` call: its motion, or the error refusing it."""
    got = keys.read_many([
        keys.Request(owner, "OFF", action=action, slot=slot, fcurves=fcurves, analyse=False, key_values=True)
        for owner, fcurves, action, slot in items
    ])
    return [
        SmoothError(f"{owner.name}: {'; '.join(m.kept)}; Reduce Keys needs Blender's playback: skipped")
        if isinstance(m, keys.KeyedMotion) and m.source is None else m
        for (owner, *_), m in zip(items, got)
    ]


def _located_children(items: list[Item], members: list) -> list[Item]:
    """Bones reduced with their parent whose location Blender plays (not connected) key their
    location too, unkeyed in the source or not: the reduction keys there the small
    translations that make up for their parents' errors, so that the tolerance holds in world
    space (a bone that can only turn would carry its parent's error at its head)."""
    parents, _ = parents_of(items)
    if parents is None:
        return items
    for it, (_, motion), parent in zip(items, members, parents):
        if parent >= 0 and motion.located and not it.channels[0]:
            it.channels[0] = True
            it.written = [("location", i) for i in range(3)] + it.written
    return items


def batches(pairs: list[tuple[owners.Owner, keys.KeyedMotion]], options: Options) -> list[Batch]:
    """The (owner, motion) pairs as items at their dense frames, one batch per set of dense
    frames (owners keyed over the same range: a rig, a capture, are one batch; an owner keeps
    its own range, which a Cycles modifier repeats). Spans where Blender's playback departs
    from the screw between the frames by more than :data:`DEPARTURE_SHARE` of the tolerance
    get their probes as dense frames too; the departure left is the batch's margin. A batch
    is one cycle when every owner's curves repeat and its first pose is its last."""
    grouped: dict[bytes, tuple[np.ndarray, list]] = {}
    for owner, motion in pairs:
        frames = dense_frames([motion.frames])
        grouped.setdefault(frames.tobytes(), (frames, []))[1].append((owner, motion))
    out = []
    for frames, members in grouped.values():
        items = _located_children(_items(members, frames), members)
        steps = np.any([it.constant for it in items], axis=0)
        between, margin = "screw", (0.0, 0.0)
        if np.all(np.all([it.linear for it in items], axis=0) | steps):
            # LINEAR keys on every frame of every owner (a bake: Smooth Motion's Every Step,
            # nla.bake): Blender plays the straight line in channel space between two frames,
            # which is the core's "linear" reference (to float32 rounding)
            between = "linear"
        else:
            # Bezier keys (a capture, keyframe_insert), LINEAR spans among them: the screw
            # between the frames, and where Blender's playback departs from it, its probes
            dist, ang = departure(items, frames)
            flagged = ((dist > DEPARTURE_SHARE * options.distance) | (ang > DEPARTURE_SHARE * options.angle)) & ~steps
            # the departure left: at the probes of the spans kept whole (a cut span's probes are
            # dense frames now; steps are the core's own)
            kept = ~flagged & ~steps
            margin = (float(dist[kept].max(initial=0.0)), float(ang[kept].max(initial=0.0)))
            if flagged.any():
                frames, items = _with_probes(items, frames, flagged)
        cyclic = all(
            it.cyclic
            and np.allclose(it.poses[0], it.poses[-1], atol=1e-6 * (1.0 + np.abs(it.poses[:, :3, 3]).max()))
            and np.allclose(it.scales[0], it.scales[-1], atol=1e-6)
            for it in items
        )
        out.append(Batch(items=items, frames=frames, cyclic=cyclic, margin=margin, between=between))
    return out


def solve_batch(batch: Batch, options: Options) -> list[Reduced]:
    """:func:`solve` with the batch's margin taken off the tolerance, asked again with a
    tolerance scaled down where the result misses it (the chains of connected bones: a bone
    that cannot move its head carries its parent's error there). The errors are the core's
    own: Blender's evaluation of the reduced curves (bit-identical to `FCurve.evaluate`) at
    every frame and at 1/4, 1/2, 3/4 of every span against the core's reference, in world
    space along the chains, a connected bone's head included (a second evaluation of every
    curve here agreed with it to 1e-12 and was dropped, issue 26). They are reported plus
    the margin: a bound of the error against Blender's playback of the dense keys at every
    frame and at the probes (none for LINEAR sources, whose playback is the core's "linear"
    reference, nor for Smooth Motion's "cubic" one)."""
    distance = max(options.distance - batch.margin[0], 0.5 * options.distance)
    angle = max(options.angle - batch.margin[1], 0.5 * options.angle)
    inner = Options(distance=distance, angle=angle, per_channel=options.per_channel)
    for attempt in range(RETRIES + 1):
        results = solve(batch.items, batch.frames, inner, batch.cyclic, batch.between)
        over = max(
            max(r.distance_error for r in results) / distance, max(r.angle_error for r in results) / angle
        )
        if over <= 1.0 + 1e-6 or attempt == RETRIES:
            break
        inner = Options(
            distance=inner.distance * 0.95 / over, angle=inner.angle * 0.95 / over, per_channel=options.per_channel
        )
    for r in results:
        r.distance_error += batch.margin[0]
        r.angle_error += batch.margin[1]
    return results


# Writing ---------------------------------------------------------------------------------


def _enum_values(prop: str, names: tuple[str, ...]) -> np.ndarray:
    """Blender's RNA values of `Keyframe.<prop>` for polyscrew's codes (index into `names`)."""
    items = bpy.types.Keyframe.bl_rna.properties[prop].enum_items
    return np.array([items[name].value for name in names], dtype=np.int64)


_ENUMS: dict[str, np.ndarray] = {}


def _enum(prop: str) -> np.ndarray:
    if prop not in _ENUMS:
        names = {
            "interpolation": polyscrew.INTERPOLATIONS,
            "easing": polyscrew.EASINGS,
            "handle_left_type": polyscrew.HANDLE_TYPES,
        }[prop]
        _ENUMS[prop] = _enum_values(prop, tuple(names))
    return _ENUMS[prop]


#: F-curve properties kept when a curve's keys are replaced.
_KEPT = ("extrapolation", "color_mode", "color", "hide", "lock", "select", "auto_smoothing")


def write_curve(
    bag, owner: owners.Owner, prop: str, index: int, curve: Curve, cycle: tuple | None = None,
    digests: dict | None = None,
) -> None:
    """Replaces the curve (`prop`, `index`) of `owner` in `bag` (made when missing) by the
    reduced keys: co, handles, interpolation, easing, handle types (one `foreach_set` each).
    The old curve's extrapolation, modifiers, group, colour and flags are kept; `cycle`
    (mode_before, mode_after) adds a Cycles modifier to a new curve. `digests` gets the
    curve's :func:`bake.curve_digest` per (data path, index), from the arrays written."""
    path = owner.path(prop)
    old = channels.find_fcurve(bag, path, index)
    kept, group = {}, owner.group
    if old is not None:
        kept = {name: getattr(old, name) for name in _KEPT if hasattr(old, name)}
        kept["color"] = tuple(old.color)
        group = old.group.name if old.group is not None else ""
        # the old modifiers' settings, read before the curve goes, set on the new one below
        snapshot = []
        for m in old.modifiers:
            values = {}
            for p in m.bl_rna.properties:
                if p.is_readonly or p.identifier in ("rna_type", "type"):
                    continue
                if p.type in ("BOOLEAN", "INT", "FLOAT", "ENUM"):
                    value = getattr(m, p.identifier)
                    values[p.identifier] = tuple(value) if hasattr(value, "__len__") and not isinstance(value, str) else value
            snapshot.append((m.type, values))
        channels.remove_fcurve(bag, old)
    else:
        snapshot = [("CYCLES", {"mode_before": cycle[0], "mode_after": cycle[1]})] if cycle else []
    fc = channels.new_fcurve(bag, path, index, group)
    written = curve.written  # (prepared by :func:`solve` for every curve at once)
    points = fc.keyframe_points
    points.add(len(curve.co))
    co = written["co"].ravel()
    bulk.put(points, "co", co)
    left, right = written["handle_left"].ravel(), written["handle_right"].ravel()
    bulk.put(points, "handle_left", left)
    bulk.put(points, "handle_right", right)
    bulk.put(points, "interpolation", tuple(written["interpolation"]))
    if digests is not None:
        digests[path, index] = bake.curve_digest(co, written["interpolation_bytes"], left, right)
    if written["eased"]:
        bulk.put(points, "easing", tuple(written["easing"]))
    types = tuple(written["handle_type"])
    bulk.put(points, "handle_left_type", types)
    bulk.put(points, "handle_right_type", types)
    for name, value in kept.items():
        with contextlib.suppress(AttributeError, TypeError, ValueError):
            setattr(fc, name, value)
    for kind, values in snapshot:
        modifier = fc.modifiers.new(kind)
        for name, value in values.items():
            with contextlib.suppress(AttributeError, TypeError, ValueError):
                setattr(modifier, name, value)
    # Keys are sorted and their handles are the fitted ones: no fcurve.update(), which would
    # recompute them.


def write_reduced(
    bag, reduced: Reduced, cycle_modes: dict | None = None, cyclic: bool = False, digests: dict | None = None
) -> None:
    """Every reduced curve of one owner into `bag` (`digests`: see :func:`write_curve`)."""
    for (prop, index), curve in reduced.curves.items():
        cycle = None
        if cycle_modes and (prop, index) in cycle_modes:
            cycle = cycle_modes[prop, index]
        elif cyclic:
            cycle = ("REPEAT", "REPEAT")
        write_curve(bag, reduced.item.owner, prop, index, curve, cycle, digests)


def write_joined(bag, part) -> None:
    """Smooth Motion, Keys: Reduced over a Frame Range narrower than the keys: each reduced
    curve of `part` (:class:`bake.Baked`, its transform curves already removed from `bag`)
    joined to the source keys kept outside the range as a dense bake is
    (:func:`range_join.write_keys`: the span the range's end cuts split there); the handles of
    the reduced keys at the range's ends are FREE (the joined handles stay as written)."""
    free = _enum("handle_left_type")[polyscrew.HANDLE_TYPES.index("FREE")]
    for (prop, index), curve in part.reduced.curves.items():
        types = _enum("handle_left_type")[curve.handle_type].astype(np.uint8)
        types[[0, -1]] = free
        inner = {
            "co": np.asarray(curve.co, dtype=np.float32),
            "handle_left": np.asarray(curve.handle_left, dtype=np.float32),
            "handle_right": np.asarray(curve.handle_right, dtype=np.float32),
            "interpolation": _enum("interpolation")[curve.interpolation].astype(np.uint8),
            "easing": _enum("easing")[curve.easing].astype(np.uint8),
            "handle_left_type": types,
            "handle_right_type": types.copy(),
        }
        fcurve = channels.new_fcurve(bag, part.owner.path(prop), index, part.owner.group)
        column = next(c for c, i in part.columns(prop) if i == index)
        range_join.write_keys(fcurve, part.join, inner, prop, index, column, part.end_maps or {})
        stack = part.motion.modifiers.get((prop, index)) if part.motion.modifiers else None
        if stack:
            modifiers.copy_onto(stack, fcurve)


# The operator's pipeline -----------------------------------------------------------------


@dataclass
class Result(Outcome):
    """What Reduce Keys did."""

    keys_before: int = 0
    keys_after: int = 0
    frames: int = 0
    distance_error: float = 0.0
    angle_error: float = 0.0


def reduce_keys(
    selection: Iterable,
    options: Options,
    progress: Callable[[int, int], None] | None = None,
    t: transaction.Transaction | None = None,
) -> Result:
    """Reduces the keys of the owners in `selection` (objects or :class:`owners.Owner`s);
    owners animated by one action get one new action. Everything is read and reduced (one
    `polyscrew.reduce_keys` call) before anything is written; the writing is all or nothing."""
    groups, refused = action_groups.by_action(selection)
    skipped = [message for _, message in refused]
    pairs, plans, notes, rerun, edited = [], [], [], [], []
    # Every group's users in one pass over the scene's objects (`bake.users_of` per group grew
    # as groups x objects: Reduce Keys of many objects grew as objects^1.29).
    users = bake.users_by_slot({group.action.as_pointer() for group in groups})
    sources, wanted = [], []
    for group in groups:
        current, identifier = group.action, group.identifier
        source, slot, was_edited = bake.source_action(current, identifier, "reduce", options.reduce_result)
        if was_edited:
            # the animator changed the result: the edit is the new source, never thrown away
            edited.append(f"'{current.name}'")
        by_owner = owners.curves_by_owner(channels.action_fcurves(source, slot))
        sources.append(source)
        wanted += [
            (owner, by_owner.get(owner.bone, []), None if source is current else source, slot)
            for owner in {(o.obj.as_pointer(), o.bone): o for o in group.members}.values()
        ]
    motions = iter(read_motions(wanted))  # every owner's keys in one read and one polyscrew call
    for group, source in zip(groups, sources):
        members = group.members
        first = members[0].obj
        current, identifier = group.action, group.identifier
        done = []
        for owner in {(o.obj.as_pointer(), o.bone): o for o in members}.values():
            motion = next(motions)
            if isinstance(motion, SmoothError):
                skipped.append(str(motion))
                continue
            pairs.append((owner, motion))
            done.append(owner)
        if done:
            plans.append((users.get((current.as_pointer(), identifier)) or [first], source, current, identifier, done))
            if source is not current:
                rerun.append(first.name)
    if rerun:
        notes.append(f"reduced the original keys of {bake.summary(rerun)} again (replacing the earlier result)")
    if edited:
        notes.append(
            f"{bake.summary(edited)} edited after Reduce Keys made it (keys moved, added or deleted): reduced the "
            "edited keys and kept them (Revert returns to them, a second Revert to the original)"
        )
    if not pairs:
        return Result(actions=[], owners=[], skipped=skipped, notes=notes)
    if progress is not None:
        progress(1, 3)
    reduced = {
        (r.item.owner.obj.as_pointer(), r.item.owner.bone): r
        for batch in batches(pairs, options)
        for r in solve_batch(batch, options)
    }
    if progress is not None:
        progress(2, 3)

    def write(plan, t: transaction.Transaction) -> bpy.types.Action:
        objects, source, current, identifier, done = plan
        parts = [reduced[(o.obj.as_pointer(), o.bone)] for o in done]

        digests: dict = {}

        def edit(bag, parts=parts, digests=digests) -> None:
            for part in parts:
                write_reduced(bag, part, digests=digests)

        return bake.new_result(objects, source, current, identifier, t, edit, made_by="reduce", digests=digests)

    actions = action_groups.write_all(plans, write, t)
    parts = list(reduced.values())
    return Result(
        actions=actions,
        owners=[p.item.owner.name for p in parts],
        skipped=skipped,
        notes=notes,
        keys_before=sum(p.item.keys_before for p in parts),
        keys_after=sum(p.keys for p in parts),
        frames=sum(len(dense_frames([m.frames])) for _, m in pairs),
        distance_error=max(p.distance_error for p in parts),
        angle_error=max(p.angle_error for p in parts),
    )


# Smooth Motion and Remove Noise with Keys: Reduced -----------------------------------------


def summary(results: list[Reduced]) -> str:
    """The report's line for Keys: Reduced: key frames, the share of the frames, errors."""
    frames = sum(r.item.whole or len(r.item.poses) for r in results)
    keys_ = sum(r.keys for r in results)
    return (
        f"keys reduced to {keys_:,} key frames ({100.0 * keys_ / max(frames, 1):.1f} % of {frames:,} frames); largest "
        f"error {max(r.distance_error for r in results):.3g} and {math.degrees(max(r.angle_error for r in results)):.3g} degrees"
    )


def _bake_item(part) -> Item:
    """A Smooth Motion part (:class:`bake.Baked`) as an item: its baked channels as poses."""
    motion, owner = part.motion, part.owner
    mode = motion.rotation_mode
    rotation = part.values[keys.rotation_path(mode)]
    n = len(part.frames)
    location = part.values.get("location", np.zeros((n, 3)))
    scales = np.ones((n, 3))
    if "scale" in part.values:
        scales[:, motion.scale_axes] = part.values["scale"]
    constant = np.zeros(n - 1, dtype=bool) if part.constant is None else np.asarray(part.constant[:-1], bool)
    return Item(
        owner=owner, mode=mode, poses=keys.compose(location, keys.rotation_matrices(rotation, mode)),
        scales=scales, channels=np.array(["location" in part.values, True, "scale" in part.values]),
        constant=constant, start=_pad4(rotation[0]), radius=body_radius(owner), written=part.written, whole=n,
    )


def smoothed_batch(parts: list, cyclic: bool) -> Batch:
    """Smooth Motion's parts baked at the same frames as one batch: the reference is the
    smoothed motion at every baked frame and, between two frames, the cubic through the baked
    poses each side (`between="cubic"`, checked by the core at 1/4, 1/2, 3/4 of every span):
    the smooth curve the baked poses sample. (Not the screw between two frames: that has a
    corner at every frame, which kept nearly every frame of a sparse motion; not the subdivided
    polyscrew between frames either: after its levels it is a chain of screws with a corner
    every 1/16 of a key span, which a smooth curve follows only with a key near every corner.)"""
    return Batch(items=[_bake_item(part) for part in parts], frames=parts[0].frames, cyclic=cyclic, between="cubic")


def reduce_bakes(bakes: list, distance: float, angle: float) -> str:
    """Smooth Motion, Keys: Reduced: reduces the dense channels of every part of `bakes`
    (:class:`bake.ActionBake`) before anything is written, setting each part's `reduced`.
    One `polyscrew.reduce_keys` call per set of baked frames (usually one: all owners of the
    operator), asked again with a smaller tolerance where the result misses it
    (:func:`solve_batch`), against the smoothed motion (:func:`smoothed_batch`). A part over
    a Frame Range narrower than the keys is reduced inside the range (its writing joins the
    source keys kept outside it, :func:`write_joined`). Returns the report's line
    (:func:`summary`)."""
    by_frames: dict[tuple, list] = {}
    for action_bake in bakes:
        for part in action_bake.parts:
            by_frames.setdefault((part.frames.tobytes(), bool(part.cyclic)), []).append(part)
    options = Options(distance=distance, angle=angle)
    for (_, cyclic), parts in by_frames.items():
        batch = smoothed_batch(parts, cyclic)
        for part, result in zip(parts, solve_batch(batch, options)):
            part.reduced = result
    results = [part.reduced for b in bakes for part in b.parts if part.reduced is not None]
    return summary(results) if results else "keys not reduced"


def reduce_bag(bag, members: list[owners.Owner], distance: float, angle: float) -> list[Reduced]:
    """Remove Noise, Keys: Reduced: the transform curves of `members` in `bag` (the new
    action, just written) replaced by their reduction (one `polyscrew.reduce_keys` call).
    Raises SmoothError (the caller's transaction undoes everything)."""
    by_owner = owners.curves_by_owner(channels.fcurves(bag))
    motions = read_motions([(o, by_owner.get(o.bone, []), None, "") for o in members])
    refused = next((m for m in motions if isinstance(m, SmoothError)), None)
    if refused is not None:
        raise refused
    pairs = list(zip(members, motions))
    options = Options(distance=distance, angle=angle)
    results = [r for batch in batches(pairs, options) for r in solve_batch(batch, options)]
    for result in results:
        write_reduced(bag, result)
    return results
