# SPDX-License-Identifier: GPL-3.0-or-later
"""An owner's key poses as arrays (:class:`KeyedMotion`), and the rules that hold without Blender.

The Blender layer (`blender/keys.py`) reads them from the F-curves; from here on the motion is
arrays: rigid poses and scales at the key frames, what the animator meant between them (holds,
pops, spins), and the baked channels of a rotation mode. :class:`SmoothError` is the one error
the add-on reports to the animator as the reason an owner was skipped.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import polyscrew

from . import intent

#: Rotation modes and the property holding the rotation in each (the core's table,
#: `polyscrew.ROTATION_MODES`: name -> (property, width)).
ROTATION_PATHS = {mode: prop for mode, (prop, _) in polyscrew.ROTATION_MODES.items()}

#: Two key frames closer than this (in frames) are the same frame (the core's,
#: `polyscrew.KEY_FRAME_TOLERANCE`).
FRAME_TOLERANCE = polyscrew.KEY_FRAME_TOLERANCE

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
    owner: object | None = None  # the Blender layer's owners.Owner (carried, never looked into here)
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


def continued(mode: str, values: np.ndarray | None) -> np.ndarray | None:
    """What rotation channels in mode `mode` continue from (`previous` of
    `polyscrew.rotation_channels` and `sample_channels`): `values`, or None for a mode whose
    channels start from their own first rotation (the core's rule,
    `polyscrew.CONTINUED_ROTATION_MODES`: axis-angle)."""
    return values if mode in polyscrew.CONTINUED_ROTATION_MODES else None


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


def _union(frames: list[np.ndarray]) -> np.ndarray:
    merged = np.unique(np.concatenate(frames))
    keep = np.concatenate(([True], np.diff(merged) > FRAME_TOLERANCE))
    return merged[keep]


def key_motion(
    name: str,
    mode: str,
    frames: np.ndarray,
    poses: np.ndarray,
    location: np.ndarray,
    rotation: np.ndarray,
    scale: np.ndarray,
    scale_axes: np.ndarray,
    source: intent.Source | None,
    modes: dict,
    cyclic: bool,
    extended: bool,
    is_closed: bool,
    kept: list[str],
    extend_to: tuple[float, float] | None,
    analyse: bool,
    turns: str,
    located: bool,
    owner: object,
    size: float,
    stacked: dict,
    keyed: frozenset,
    spans: tuple | None = None,
) -> KeyedMotion:
    """The key motion of the owner `name` from what the Blender layer read (`keys.read`): the
    channels and rigid `poses` at the key `frames`, its curves as Blender plays them (`source`,
    None for key values alone), the Cycles modifier modes per curve (`modes`; `extended`: one
    that plays the keys on beyond their range), and the options (`extend_to`, `analyse`,
    `turns`; `is_closed` decided from them).

    An extended cycle becomes an open motion over neighbouring cycles; with `analyse`, spans
    are told apart (holds, pops, spins followed with poses from Blender's playback inserted,
    Euler wraps and quaternion sign flips taken the short way, as `turns` says) and reported in
    `kept`/`removed`/`causes`; a closed motion's closing key becomes its period, and a cycle with
    holds is tiled over neighbouring periods as an open motion. Raises :class:`SmoothError`.
    `owner`, `size`, `stacked` (the modifiers kept per curve) and `keyed` are carried into the
    result as they are. `spans`: what `intent.analyse_turns(source, frames, turns)` returns
    and `source.channels` at its inserted frames, when the caller has them already
    (`polyscrew.read_owners`; never for an extended cycle, whose frames change here).
    """
    paths = transform_paths(mode)
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
        if spans is None:
            held, pops, turn, inserted, flips = intent.analyse_turns(source, frames, turns)
            at_inserted = None
        else:
            held, pops, turn, inserted, flips, at_inserted = spans
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
            played = source.channels(inserted) if at_inserted is None else at_inserted
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
        size=size,
        kept=kept,
        removed=removed,
        causes=causes,
        modifiers=stacked,
        keyed=keyed,
    )


def _cycle_words(modes: dict) -> str:
    names = sorted({m for pair in modes.values() for m in pair if m in intent.EXTENDED_CYCLES})
    return " and ".join(n.replace("_", " ").title().replace("Offset", "with Offset") for n in names)
