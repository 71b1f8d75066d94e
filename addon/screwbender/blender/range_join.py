# SPDX-License-Identifier: GPL-3.0-or-later
"""A Frame Range narrower than the keys: smooth that part, keep the rest (issue 24).

Outside the range the result plays exactly what the source played: the source keys there are
kept (values, handles, interpolation, easing); inside it, the smoothed motion. At each end the
smoothed motion starts (ends) at the source's pose there (:func:`cut`: the range's ends become
the first and last pose of the smoothed piece, taken from Blender's playback), so the two join
without a jump. Per curve (:func:`write`), the source span the range's end cuts is split there:

- BEZIER: the cubic Bezier segment (after Blender's own handle correction) is split by de
  Casteljau at the parameter where it reaches the end's frame: both halves trace exactly the
  source's curve; the split handles are FREE, and so are the handles of the source key next to
  the cut (Blender's automatic handles would otherwise move them when the curve is edited);
- LINEAR, CONSTANT: the same interpolation from the cut on plays the same values;
- an easing preset (Sine ... Elastic, Back) cannot be cut and still play the same: an end of
  the range inside such a span moves to the span's key inside the range (:func:`cut`), the
  whole span is kept, and the report says so.

Rotation channels: the baked values are continuous from the source's value at the start
(written as the same rotation the source's channels hold there: an axis-angle of the other
sign, an Euler angle a turn away), and a quaternion (the axis of an axis-angle) is scaled
along the range so that it has the source's length at both ends (Blender normalises them: the
poses are unchanged). Where the baked values end on another triple of the same rotation (an Euler channel a whole turn away, the twin Euler
triple, a quaternion of the other sign), the source keys after the range are written as that
same rotation (each channel mapped by `a * value + c`, which keeps every pose Blender plays):
no channel jumps at the join.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import bpy
import numpy as np
import polyscrew

from ..pure.bezier import _bezier, split_bezier  # noqa: F401  (re-exported: range_join.split_bezier)
from . import bulk, keys

_ENUM = bpy.types.Keyframe.bl_rna.properties
_INTERPOLATION = {name: _ENUM["interpolation"].enum_items[name].value for name in ("BEZIER", "LINEAR", "CONSTANT")}
_FREE = _ENUM["handle_left_type"].enum_items["FREE"].value

#: Key properties copied from the source: (name, numpy dtype, components).
_FIELDS = (
    ("co", np.float32, 2),
    ("handle_left", np.float32, 2),
    ("handle_right", np.float32, 2),
    ("interpolation", np.uint8, 1),
    ("easing", np.uint8, 1),
    ("handle_left_type", np.uint8, 1),
    ("handle_right_type", np.uint8, 1),
    ("type", np.uint8, 1),
    ("back", np.float32, 1),
    ("amplitude", np.float32, 1),
    ("period", np.float32, 1),
)

#: Blender's defaults of the easing parameters of a new key.
_DEFAULTS = {"back": 1.70158, "amplitude": 0.8, "period": 4.1}


@dataclass
class Join:
    """Where a bake over a Frame Range joins the source keys kept outside it."""

    start: float
    end: float
    #: Whether keys before `start` (after `end`) are kept: the range cuts the keys there.
    before: bool
    after: bool
    #: (property, array index) -> the source F-curve (keyed, not muted) of that channel.
    curves: dict
    #: The source's channels at (start, end) as Blender plays them: property -> (2, k).
    played: dict
    #: Ends moved off a span eased by a Blender preset ("start to the key at 13"), for the report.
    moved: list


def _span_table(fc: bpy.types.FCurve) -> tuple[np.ndarray, np.ndarray]:
    """Key frames and interpolation codes of `fc`."""
    n = len(fc.keyframe_points)
    co = np.zeros(2 * n, dtype=np.float32)
    bulk.get(fc.keyframe_points, "co", co)
    codes = np.zeros(n, dtype=np.uint8)
    bulk.get(fc.keyframe_points, "interpolation", codes)
    return co[0::2].astype(np.float64), codes


def _cuts_eased(table: tuple[np.ndarray, np.ndarray], frame: float) -> bool:
    """Whether `frame` falls inside (not on the keys of) a span eased by a Blender preset."""
    x, codes = table
    tol = keys.FRAME_TOLERANCE
    if not len(x) or np.any(np.abs(x - frame) <= tol) or frame < x[0] or frame > x[-1]:
        return False
    a = int(np.searchsorted(x, frame, side="right") - 1)
    return int(codes[a]) not in _INTERPOLATION.values()


def cut(
    motion: keys.KeyedMotion, frame_range: tuple[float, float] | None, fcurves: list, owner
) -> tuple[keys.KeyedMotion, Join | None]:
    """The part of `motion` inside `frame_range` as a motion of its own, and where it joins
    the rest; `(motion, None)` when the range does not cut the keys (no range, a range as wide
    as the keys or wider, a cycle: a cycle's range is baked over as before).

    The range's ends inside the keys become key poses taken from Blender's playback there (the
    curves `fcurves` evaluated: one `polyscrew` call), so the smoothed piece starts and ends on
    the source's pose. Raises :class:`keys.SmoothError` for a range that holds no span of keys.
    """
    if frame_range is None or motion.closed or motion.bake_range is not None or len(motion.frames) < 2:
        return motion, None
    tol = keys.FRAME_TOLERANCE
    start, end = float(frame_range[0]), float(frame_range[1])
    frames = motion.frames
    before, after = start > frames[0] + tol, end < frames[-1] - tol
    if not (before or after) or not end > start:  # (an empty range is refused by the bake)
        return motion, None
    if end <= frames[0] + tol or start >= frames[-1] - tol:
        raise keys.SmoothError(
            f"{owner.name}: the frame range {start:g} to {end:g} holds none of its motion (keys "
            f"{frames[0]:g} to {frames[-1]:g}): skipped"
        )
    keyed = {}
    for fc in fcurves:
        prop = owner.prop_of(fc.data_path)
        if prop is not None and not fc.mute and len(fc.keyframe_points):
            keyed[prop, fc.array_index] = fc
    # An end inside a span eased by one of Blender's presets moves to the next key inside the
    # range (such a span cannot be cut and still play the same): the whole span is kept.
    spans = [_span_table(fc) for fc in keyed.values()]
    key_frames = frames if motion.is_key is None else frames[motion.is_key]
    moved = []
    if before and any(_cuts_eased(table, start) for table in spans):
        later = [float(f) for f in key_frames if f > start + tol and not any(_cuts_eased(t, f) for t in spans)]
        start = later[0] if later else end
        moved.append(f"start to the key at {start:g}")
    if after and any(_cuts_eased(table, end) for table in spans):
        earlier = [float(f) for f in key_frames if f < end - tol and not any(_cuts_eased(t, f) for t in spans)]
        end = earlier[-1] if earlier else start
        moved.append(f"end to the key at {end:g}")
    if not end > start + tol:
        raise keys.SmoothError(
            f"{owner.name}: the frame range cuts spans eased by Blender's easing presets at both ends and "
            "holds no key between them: widen it to a key, or use Bezier keys: skipped"
        )
    before, after = start > frames[0] + tol, end < frames[-1] - tol
    inside = np.flatnonzero((frames > start + tol) & (frames < end - tol))
    lo = max(start, float(frames[0])) if before else float(frames[0])
    hi = min(end, float(frames[-1])) if after else float(frames[-1])
    # the range's ends on a key: that key; else a pose from the playback
    first = [] if before else [0]
    last = [] if after else [len(frames) - 1]
    rows = np.array(first + [int(r) for r in inside if r not in first + last] + last, dtype=int)
    new_frames = np.concatenate(([lo] if before else [], frames[rows], [hi] if after else []))
    played = _playback(motion, fcurves, owner, np.array([lo, hi]))
    mode = motion.rotation_mode
    end_poses = keys.compose(played["location"], keys.rotation_matrices(played[keys.rotation_path(mode)], mode))
    if not motion.located:
        end_poses[:, :3, 3] = 0.0
    end_scales = np.where(motion.scale_axes, played["scale"], motion.scales[0])
    poses, scales, is_key = [], [], []
    if before:
        poses.append(end_poses[0]), scales.append(end_scales[0]), is_key.append(False)
    poses += list(motion.poses[rows])
    scales += list(motion.scales[rows])
    is_key += list(motion.is_key[rows] if motion.is_key is not None else np.ones(len(rows), dtype=bool))
    if after:
        poses.append(end_poses[1]), scales.append(end_scales[1]), is_key.append(False)
    held = pops = None
    if motion.held is not None:
        # each new span lies in one source span: held as it; it pops only where that span ends
        mids = 0.5 * (new_frames[:-1] + new_frames[1:])
        span = np.clip(np.searchsorted(frames, mids, side="right") - 1, 0, len(frames) - 2)
        held = motion.held[span].copy()
        ends_on_key = np.abs(frames[span + 1] - new_frames[1:]) <= tol
        pops = motion.pops[span] & ends_on_key
    first_rotation = played[keys.rotation_path(mode)][0] if before else motion.first_rotation
    sub = dataclasses.replace(
        motion,
        frames=new_frames.astype(np.float64),
        poses=np.array(poses),
        scales=np.array(scales),
        first_rotation=np.array(first_rotation, dtype=np.float64),
        held=held,
        pops=pops,
        is_key=np.array(is_key, dtype=bool),
    )
    return sub, Join(start=lo, end=hi, before=before, after=after, curves=keyed, played=played, moved=moved)


def _playback(motion: keys.KeyedMotion, fcurves: list, owner, frames: np.ndarray) -> dict[str, np.ndarray]:
    """The owner's channels at `frames` as Blender plays them."""
    if motion.source is not None:
        return motion.source.channels(frames)
    mode = motion.rotation_mode
    out = {}
    for prop in keys.transform_paths(mode):
        static = np.array(getattr(owner.target, prop), dtype=np.float64)
        out[prop] = np.repeat(static[None], len(frames), axis=0)
    for fc in fcurves:  # curves polyscrew cannot play: Blender's own evaluate at the two ends
        prop = owner.prop_of(fc.data_path)
        if prop in out and not fc.mute and len(fc.keyframe_points) and fc.array_index < out[prop].shape[1]:
            out[prop][:, fc.array_index] = [fc.evaluate(float(f)) for f in frames]
    return out


# --- the source keys -------------------------------------------------------------------------


def _read_keys(fc: bpy.types.FCurve) -> dict[str, np.ndarray]:
    points = fc.keyframe_points
    n = len(points)
    out = {}
    for name, dtype, width in _FIELDS:
        values = np.zeros(n * width, dtype=dtype)
        bulk.get(points, name, values)
        out[name] = values.reshape(n, width) if width > 1 else values
    return out


def _take(table: dict[str, np.ndarray], rows) -> dict[str, np.ndarray]:
    return {name: values[rows].copy() for name, values in table.items()}


def _concat(tables: list[dict[str, np.ndarray]]) -> dict[str, np.ndarray]:
    return {name: np.concatenate([t[name] for t in tables]) for name, _, _ in _FIELDS}


def equivalence(source: np.ndarray, baked: np.ndarray, mode: str, prop: str) -> tuple[np.ndarray, np.ndarray] | None:
    """`(a, c)` with `a * source + c == baked` (per channel) for a map that keeps every rotation
    the channels of `prop` can play (identity for location and scale); None when no such map
    matches (the caller then writes the source value). The rotation maps are the core's
    (`polyscrew.same_rotation_map`: quaternion sign and length, axis-angle sign and whole turns,
    Euler whole turns and the twin triple)."""
    if prop != keys.rotation_path(mode):
        ones = np.ones(len(source))
        return ones, np.zeros_like(ones)
    return polyscrew.same_rotation_map(source, baked, mode)


def _map(table: dict[str, np.ndarray], a: float, c: float) -> None:
    for name in ("co", "handle_left", "handle_right"):
        table[name][:, 1] = (a * table[name][:, 1].astype(np.float64) + c).astype(np.float32)


def write(fcurve: bpy.types.FCurve, join: Join, frames: np.ndarray, values: np.ndarray,
          interpolation: np.ndarray, prop: str, index: int, column: int, source_ends: dict) -> None:
    """Keys `fcurve` (new, empty) with the baked keys (`frames`, `values` of one channel,
    `interpolation` codes) and, outside the range, the source keys of that channel kept.
    `source_ends[prop]` holds the maps `(a, c)` of :func:`equivalence` at the start and end
    (`column`: the channel's column in them)."""
    n = len(frames)
    baked = {name: np.zeros((n, w) if w > 1 else n, dtype=dt) for name, dt, w in _FIELDS[:4]}
    baked["co"][:, 0] = frames
    baked["co"][:, 1] = values
    baked["handle_left"][:] = baked["co"]
    baked["handle_right"][:] = baked["co"]
    baked["interpolation"][:] = interpolation
    baked["handle_left_type"] = np.full(n, _FREE, dtype=np.uint8)
    baked["handle_right_type"] = np.full(n, _FREE, dtype=np.uint8)
    write_keys(fcurve, join, baked, prop, index, column, source_ends)


def write_keys(fcurve: bpy.types.FCurve, join: Join, baked: dict, prop: str, index: int, column: int,
               source_ends: dict) -> None:
    """:func:`write` for keys made elsewhere (Keys: Reduced: Bezier keys with their handles):
    `baked` holds the keys inside the range as arrays named after :data:`_FIELDS` (missing
    ones: Blender's defaults); edited in place at its ends."""
    tol = keys.FRAME_TOLERANCE
    n = len(baked["co"])
    for name, dtype, width in _FIELDS:
        if name not in baked:
            baked[name] = np.zeros((n, width) if width > 1 else n, dtype=dtype)
            if name in _DEFAULTS:
                baked[name][:] = _DEFAULTS[name]
    parts = [baked]
    source = join.curves.get((prop, index))
    if source is not None:
        keys_ = _read_keys(source)
        x = keys_["co"][:, 0].astype(np.float64)
        maps = source_ends.get(prop, {})
        if join.before:
            a, c = (float(v[column]) for v in maps["start"]) if "start" in maps else (1.0, 0.0)
            kept = _take(keys_, x < join.start - tol)
            handle = _cut_before(keys_, x, join.start, baked, kept)
            _map(kept, a, c)
            if handle:  # the first baked key's left handle is the source's (split): the same map
                baked["handle_left"][0, 1] = np.float32(a * float(baked["handle_left"][0, 1]) + c)
            parts.insert(0, kept)
        if join.after:
            a, c = (float(v[column]) for v in maps["end"]) if "end" in maps else (1.0, 0.0)
            kept = _take(keys_, x > join.end + tol)
            handle = _cut_after(keys_, x, join.end, baked, kept)
            last = len(baked["co"]) - 1
            if handle:
                baked["handle_right"][last, 1] = np.float32(a * float(baked["handle_right"][last, 1]) + c)
            _map(kept, a, c)
            parts.append(kept)
    table = _concat(parts)
    points = fcurve.keyframe_points
    points.add(len(table["co"]))
    for name, dtype, _width in _FIELDS:
        data = table[name]
        bulk.put(points, name, data.ravel() if dtype == np.float32 else tuple(data.tolist()))


def _cut_before(keys_, x, start, baked, kept) -> bool:
    """Joins the source span cut by the range's start: edits `kept`'s last key and the first
    baked key; returns whether that key's left handle is the source's (to be mapped)."""
    tol = keys.FRAME_TOLERANCE
    on = np.flatnonzero(np.abs(x - start) <= tol)
    if len(on):  # a source key at the start: the baked key takes its left side
        k = int(on[0])
        baked["handle_left"][0] = keys_["handle_left"][k]
        return True
    later = np.flatnonzero(x > start + tol)
    if not len(kept["co"]):
        return False
    if not len(later):  # the source holds its last key's value from there: so does the result
        kept["interpolation"][-1] = _INTERPOLATION["CONSTANT"]
        return False
    a, b = len(kept["co"]) - 1, int(later[0])
    kind = int(keys_["interpolation"][a])
    if kind == _INTERPOLATION["BEZIER"]:
        p01, p012, _, _, _ = split_bezier(
            keys_["co"][a], keys_["handle_right"][a], keys_["handle_left"][b], keys_["co"][b], start
        )
        kept["handle_right"][a] = p01
        kept["handle_left_type"][a] = kept["handle_right_type"][a] = _FREE
        baked["handle_left"][0] = p012
        return True
    return False  # LINEAR, CONSTANT: the same from the cut on (an eased span is never cut)


def _cut_after(keys_, x, end, baked, kept) -> bool:
    """Joins the source span cut by the range's end (see :func:`_cut_before`)."""
    tol = keys.FRAME_TOLERANCE
    last = len(baked["co"]) - 1
    on = np.flatnonzero(np.abs(x - end) <= tol)
    if len(on):  # a source key at the end: the baked key takes its right side
        k = int(on[0])
        for name in ("handle_right", "interpolation", "easing", "back", "amplitude", "period"):
            baked[name][last] = keys_[name][k]
        return True
    earlier = np.flatnonzero(x < end - tol)
    if not len(kept["co"]) or not len(earlier):
        return False
    a, b = int(earlier[-1]), 0
    kind = int(keys_["interpolation"][a])
    baked["interpolation"][last] = kind
    if kind == _INTERPOLATION["BEZIER"]:
        _, _, _, p123, p23 = split_bezier(
            keys_["co"][a], keys_["handle_right"][a], kept["handle_left"][b], kept["co"][b], end
        )
        baked["handle_right"][last] = p123
        kept["handle_left"][b] = p23
        kept["handle_left_type"][b] = kept["handle_right_type"][b] = _FREE
        return True
    return False  # LINEAR, CONSTANT: the same from the cut on


def end_maps(join: Join, motion: keys.KeyedMotion, played: dict, values: dict, frames: np.ndarray) -> dict:
    """Per baked property: the maps (:func:`equivalence`) from the source's channels to the
    baked ones at the range's start and end. `played` holds the source's channels at
    (start, end), `values` the baked channels at `frames` (first and last rows are the ends);
    a quaternion (an axis-angle's axis) is first scaled in place to the source's length at both
    ends, by a factor that changes geometrically along the range."""
    mode = motion.rotation_mode
    path = keys.rotation_path(mode)
    normalised = polyscrew.NORMALISED_CHANNELS.get(mode)  # (the core's: a quaternion, an axis-angle's axis)
    if normalised is not None and path in values:
        part = slice(*normalised)
        baked = values[path]
        logs = []
        for row, src_row, cut_here in ((0, 0, join.before), (-1, 1, join.after)):
            have, want = np.linalg.norm(baked[row, part]), np.linalg.norm(played[path][src_row, part])
            logs.append(float(np.log(want / have)) if cut_here and have > 0.0 and want > 0.0 else 0.0)
        u = (frames - frames[0]) / max(float(frames[-1] - frames[0]), keys.FRAME_TOLERANCE)
        baked[:, part] *= np.exp((1.0 - u) * logs[0] + u * logs[1])[:, None]
    out = {}
    for prop, baked in values.items():
        maps = {}
        for side, row, src_row in (("start", 0, 0), ("end", -1, 1)):
            if not getattr(join, "before" if side == "start" else "after"):
                continue
            src = played[prop][src_row] if prop != "scale" else played["scale"][src_row, motion.scale_axes]
            identity = (np.ones_like(src), np.zeros_like(src))
            if side == "start":
                # the baked values written like the source's at the start (the whole bake mapped:
                # the same rotations), so that the keys before the range are kept as they are
                found = equivalence(baked[0], src, motion.rotation_mode, prop)
                if found is None:
                    baked[0] = src
                else:
                    baked[:] = found[0] * baked + found[1]
                maps[side] = identity
                continue
            found = equivalence(src, baked[row], motion.rotation_mode, prop)
            if found is None:  # no rotation-keeping map: the baked end takes the source's value
                baked[row] = src
                found = identity
            maps[side] = found
        out[prop] = maps
    return out
