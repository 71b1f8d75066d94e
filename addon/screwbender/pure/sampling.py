# SPDX-License-Identifier: GPL-3.0-or-later
"""The smoothed motion of an owner at any frames: what Smooth Motion bakes, the preview draws
and Insert Key on Motion keys.

The key poses (:func:`keys.read`) are cut at held spans (:mod:`intent`) into pieces; each
piece is one `polyscrew` call (screw subdivision or feature points) for all its frames, held
frames keep their key pose. Timing "smooth" and "linear" map frames to the motion with
polyscrew's own time maps; timing "keys" gives each frame the parameter at which the smoothed
piece has travelled the same fraction of the span as Blender's playback has. The core chooses
between them (:func:`timed`: one `polyscrew.timed_frames` call for every timing).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import polyscrew

from . import keyed as keys

#: Steps per key span along which the travel of Blender's playback and of the smoothed motion
#: is measured (timing "keys"; the output frames inside a span are measured too): the core's
#: `polyscrew.PACE_SAMPLES`.
PACE_SAMPLES = polyscrew.PACE_SAMPLES


@dataclass
class Segment:
    """Consecutive output frames sampled the same way: a piece of keys `lo..hi` smoothed
    together, or the hold of key `lo` (`hi == lo`)."""

    lo: int
    hi: int
    #: Indices into the output frames (consecutive).
    rows: np.ndarray

    @property
    def held(self) -> bool:
        return self.hi == self.lo


def segments(motion: keys.KeyedMotion, frames: np.ndarray) -> list[Segment]:
    """The output `frames` (sorted) split into pieces and holds, in order.

    A frame belongs to the span starting at the last key at or before it (frames before the
    first key to the first span, after the last key to the last one); a span's frames are
    held when the span is. Pieces are the maximal runs of spans that are not held.
    """
    k = len(motion.frames)
    held = motion.held if motion.held is not None else np.zeros(max(k - 1, 0), dtype=bool)
    if k < 2 or motion.closed or not held.any():
        return [Segment(0, k - 1, np.arange(len(frames)))]
    span = np.clip(np.searchsorted(motion.frames, frames, side="right") - 1, 0, k - 2)
    # piece id per span: runs of non-held spans share one; each held span is its own
    piece_start = np.empty(k - 1, dtype=int)
    start = 0
    for i in range(k - 1):
        if held[i] or (i > 0 and held[i - 1]):
            start = i
        piece_start[i] = start
    out: list[Segment] = []
    boundaries = np.flatnonzero(np.diff(piece_start[span])) + 1
    for rows in np.split(np.arange(len(frames)), boundaries):
        if not len(rows):
            continue
        first_span = int(span[rows[0]])
        if held[first_span]:
            out.append(Segment(first_span, first_span, rows))
            continue
        lo = int(piece_start[first_span])
        hi = lo
        while hi < k - 1 and not held[hi]:
            hi += 1
        out.append(Segment(lo, hi, rows))
    return out


def _sub(motion: keys.KeyedMotion, lo: int, hi: int) -> keys.KeyedMotion:
    """The keys `lo..hi` of an open motion, as a motion of their own."""
    import dataclasses

    return dataclasses.replace(
        motion,
        frames=motion.frames[lo : hi + 1],
        poses=motion.poses[lo : hi + 1],
        scales=motion.scales[lo : hi + 1],
        held=None,
        closed=False,
        period=None,
    )


def timed(motion: keys.KeyedMotion, frames: np.ndarray, options, features=None, played: bool = False):
    """Where `motion` (one piece) is sampled for `frames` with the options' timing, chosen by
    the core for every timing: one `polyscrew.timed_frames` call, which returns
    `(key_times, times, period, timing, rows)` to sample the motion with.

    Smooth and Linear are maps of time: the keys at their frames, the frames themselves.
    Timing "keys" (`polyscrew.PACED_TIMINGS`) gives each frame the parameter at which the
    smoothed motion has travelled the same fraction of its span as Blender's own playback of
    the curves has there (`polyscrew.keys_parameters`; the fraction of time without Blender's
    curves); the motion is then sampled at those parameters, keys at 0..K-1, with linear
    timing. For the Feature Points method the smoothed motion's poses at
    `polyscrew.pace_parameters` are sampled here first. With `played` (and Blender's curves),
    `rows` are the playback's location and rotation at the frames it played (NaN elsewhere),
    which the departure measure then need not play again; else None.
    """
    playback = motion.source.playback if motion.source is not None else None
    poses, smooth = motion.poses, None
    if options.method == "FEATURE" and features is not None and options.timing in polyscrew.PACED_TIMINGS:
        k = len(motion.frames)
        u = polyscrew.pace_parameters(k if motion.closed else k - 1)
        poses, smooth = None, features(motion, np.arange(k, dtype=np.float64), u, float(k) if motion.closed else None)
    return polyscrew.timed_frames(
        motion.frames, frames, options.timing, size=motion.size, closed=motion.closed, period=motion.period,
        playback=playback, poses=poses, scheme=options.scheme, levels=options.levels, smooth=smooth,
        played=played and playback is not None,
    )


@dataclass
class Sampled:
    """The smoothed motion at the requested frames."""

    #: Rigid poses (T, 4, 4), or None when channels were asked for.
    poses: np.ndarray | None
    #: Location (T, 3) and rotation channels (T, k), when channels were asked for.
    location: np.ndarray | None
    rotation: np.ndarray | None
    #: Scales (T, 3) when scale is keyed (else None).
    scales: np.ndarray | None
    #: Per frame: in a held span that pops at its end (its baked keys must be CONSTANT).
    constant: np.ndarray
    #: With `played`: Blender's playback of the source (location, rotation: (T, 3 + k)) at the
    #: frames timing "Keys" played, NaN elsewhere (`polyscrew.Playback.measure_departure`).
    played: np.ndarray | None = None


def _put_poses(pose, rows, poses, location, mode, previous):
    """Writes the world poses `pose` (k, 4, 4) to `rows` of `poses`, or, when sampling channels
    (`poses` None), their location to `location` and returns their rotation channels
    (continued from `previous`); None without channels."""
    if poses is not None:
        poses[rows] = pose
        return None
    location[rows] = pose[:, :3, 3]
    return polyscrew.rotation_channels(pose, mode, previous=previous)


def sample(
    motion: keys.KeyedMotion,
    frames: np.ndarray,
    options,
    features=None,
    channels: bool = False,
    previous=None,
    played: bool = False,
) -> Sampled:
    """The smoothed motion at `frames` (any order; channels are continuous in time order from
    `previous`), as poses or, with `channels`, as Blender's location and rotation channels;
    and scales when keyed. With `played` (timing "keys", a motion with Blender's curves), also
    the playback's rows timing "keys" played at these frames (:attr:`Sampled.played`).

    One polyscrew call per piece for the motion (and per hold for channels), one for scale;
    timing "keys" computes each piece's parameters once for both. `features`: the Feature
    Points method's sampler (the Blender layer's `feature.sampler`), None for screw subdivision.
    """
    frames = np.asarray(frames, dtype=np.float64)
    if len(frames) > 1 and np.any(np.diff(frames) < 0.0):
        order = np.argsort(frames, kind="stable")
        done = sample(motion, frames[order], options, features, channels, previous, played)
        back = np.empty_like(order)
        back[order] = np.arange(len(order))
        return Sampled(
            poses=None if done.poses is None else done.poses[back],
            location=None if done.location is None else done.location[back],
            rotation=None if done.rotation is None else done.rotation[back],
            scales=None if done.scales is None else done.scales[back],
            constant=done.constant[back],
            played=None if done.played is None else done.played[back],
        )
    mode = motion.rotation_mode
    n = len(frames)
    poses = np.empty((n, 4, 4)) if not channels else None
    location = np.empty((n, 3)) if channels else None
    rotation = None
    scaled = motion.scale_keyed
    logs = _log_scales(motion)
    log_scales = np.empty((n, 3)) if scaled else None
    last_rotation = previous
    played_rows = None
    pieces = segments(motion, frames)
    constant = _constant(motion, pieces, n)
    for seg in pieces:
        # (every frame in one piece, the usual case: a slice, no index arrays to scatter through)
        rows = slice(None) if len(seg.rows) == n else seg.rows
        if seg.held:
            pose = np.repeat(motion.poses[seg.lo][None], len(seg.rows), axis=0)
            values = _put_poses(pose, rows, poses, location, mode, last_rotation)
            if scaled:
                log_scales[rows] = logs[seg.lo]
        else:
            whole = seg.lo == 0 and seg.hi == len(motion.frames) - 1
            piece = motion if whole else _sub(motion, seg.lo, seg.hi)
            key_times, at, period, timing, rows_played = timed(piece, frames[rows], options, features, played)
            if rows_played is not None:
                if len(seg.rows) == n:
                    played_rows = rows_played
                else:
                    if played_rows is None:
                        played_rows = np.full((n, rows_played.shape[1]), np.nan)
                    played_rows[rows] = rows_played
            spec = dict(scheme=options.scheme, levels=options.levels, closed=piece.closed, period=period, timing=timing)
            if options.method == "FEATURE" and features is not None:
                piece_poses = features(piece, key_times, at, spec["period"], spec["timing"])
                values = _put_poses(piece_poses, rows, poses, location, mode, last_rotation)
            elif channels:
                loc, values = polyscrew.sample_channels(piece.poses, key_times, at, mode, last_rotation, **spec)
                location[rows] = loc
            else:
                poses[rows] = polyscrew.sample(piece.poses, key_times, at, **spec)
            if scaled:
                log_scales[rows] = polyscrew.sample_vectors(logs[seg.lo : seg.hi + 1], key_times, at, **spec)
        if channels:
            if rotation is None:
                rotation = np.empty((n, values.shape[1]))
            rotation[rows] = values
            last_rotation = keys.continued(mode, values[-1])
    return Sampled(
        poses=poses, location=location, rotation=rotation, scales=_scales(motion, log_scales), constant=constant,
        played=played_rows,
    )


def _log_scales(motion: keys.KeyedMotion) -> np.ndarray | None:
    """The log-scale of the keyed axes of `motion`'s keys (positive), None when scale is not
    keyed; an unkeyed axis is not smoothed (it is the owner's own scale afterwards) and may be
    0 or negative: log(1) = 0 stands in for it."""
    return np.log(np.where(motion.scale_axes, motion.scales, 1.0)) if motion.scale_keyed else None


def _scales(motion: keys.KeyedMotion, log_scales: np.ndarray | None) -> np.ndarray | None:
    """The scales (T, 3) of sampled `log_scales` (None: scale not keyed): the keyed axes
    smoothed, the others the owner's own scale, possibly negative."""
    if log_scales is None:
        return None
    scales = np.empty((len(log_scales), 3))
    scales[:] = motion.scales[0]
    axes = motion.scale_axes
    scales[:, axes] = np.exp(log_scales[:, axes])
    return scales


def _constant(motion: keys.KeyedMotion, pieces: list[Segment], n: int) -> np.ndarray:
    """Per frame of `pieces` (n in all): in a held span that pops at its end."""
    constant = np.zeros(n, dtype=bool)
    if motion.pops is not None:
        for seg in pieces:
            if seg.held and motion.pops[seg.lo]:
                constant[seg.rows] = True
    return constant


def sample_many(
    items: list[tuple[keys.KeyedMotion, np.ndarray, np.ndarray | None]], options, poses: bool = False
) -> list[Sampled | None]:
    """:func:`sample` of many motions as channels with their played rows (the screw method):
    for each `(motion, frames, previous)` of `items` (frames sorted), what `sample(motion,
    frames, options, channels=True, previous=previous, played=True)` gives, to the bit, or
    None where the core refused that motion (sample it alone to learn why) and for frames out
    of order (:func:`sample` sorts them). With `poses`, what `sample(motion, frames, options)`
    gives (rigid poses, `previous` unused, no played rows), to the bit: a held frame is its
    key's own matrix, as there.

    One `polyscrew.sample_owners` call per rotation mode for every motion's pieces and holds
    (:func:`segments`), instead of calls per piece per motion."""
    out: list[Sampled | None] = [None] * len(items)
    by_mode: dict[str, list[int]] = {}
    for i, (motion, frames, _) in enumerate(items):
        if len(frames) < 1 or np.any(np.diff(frames) < 0.0):
            continue
        by_mode.setdefault(motion.rotation_mode, []).append(i)
    for mode, indices in by_mode.items():
        motions = [items[i][0] for i in indices]
        frames = [np.asarray(items[i][1], dtype=np.float64) for i in indices]
        pieces = [segments(m, f) for m, f in zip(motions, frames)]
        logs = [_log_scales(m) for m in motions]
        scaled = [log is not None for log in logs]
        width = len(motions[0].first_rotation)
        previous = np.full((len(indices), width), np.nan)
        for row, i in enumerate(indices):
            if items[i][2] is not None:
                previous[row] = items[i][2]
        table = np.array(
            [(s.lo, s.hi, s.rows[0], s.rows[-1] + 1) for p in pieces for s in p], dtype=np.int64
        ).reshape(-1, 4)
        counts = np.array([(len(m.frames), len(f), len(p)) for m, f, p in zip(motions, frames, pieces)], dtype=np.int64)
        try:
            location, rotation, log_scales, played, status = polyscrew.sample_owners(
                np.concatenate([m.poses for m in motions]), np.concatenate([m.frames for m in motions]),
                np.concatenate(frames), counts, table, mode,
                closed=np.array([m.closed for m in motions], dtype=np.int64),
                period=np.array([np.nan if m.period is None else m.period for m in motions]),
                size=np.array([np.nan if m.size is None else m.size for m in motions]),
                playbacks=[m.source.playback if m.source is not None else None for m in motions],
                previous=previous,
                log_scales=np.concatenate([np.zeros_like(m.scales) if log is None else log for m, log in zip(motions, logs)])
                if any(scaled) else None,
                scaled=np.array(scaled, dtype=np.int64),
                scheme=options.scheme, levels=options.levels, timing=options.timing, played=not poses,
                as_poses=poses,
            )
        except (ValueError, MemoryError):  # the batch as a whole refused (its memory, a key pose): each alone
            continue
        ends = np.cumsum(counts[:, 1])
        for row, i in enumerate(indices):
            if status[row] < 0:
                continue
            motion, rows = motions[row], slice(ends[row] - counts[row, 1], ends[row])
            scales = _scales(motion, log_scales[rows] if scaled[row] else None)
            constant = _constant(motion, pieces[row], int(counts[row, 1]))
            if poses:
                sampled = rotation[rows]
                for seg in pieces[row]:
                    if seg.held:  # (the core's hold is the key's rigid pose, through a quaternion)
                        sampled[seg.rows] = motion.poses[seg.lo]
                out[i] = Sampled(poses=sampled, location=None, rotation=None, scales=scales, constant=constant)
            else:
                out[i] = Sampled(
                    poses=None, location=location[rows], rotation=rotation[rows], scales=scales, constant=constant,
                    played=played[rows] if status[row] > 0 else None,
                )
    return out
