# SPDX-License-Identifier: GPL-3.0-or-later
"""What the animator meant between the keys: spins, holds and pops, easing, cycles with offset.

Key values alone lose most of what an animator puts into F-curves. The owner's transform
curves are evaluated as Blender plays them (:mod:`curves`: `polyscrew.evaluate_fcurves`,
one call for all curves and frames) and read for:

- **Spins.** A screw between two key poses is the short one (at most half a turn). Where the
  Euler or axis-angle channels turn further within a span (a wheel keyed 0, 360, 720
  degrees), poses taken from Blender's own playback at subframes are added to the keys
  where they turn more than :data:`WIND_LIMIT` (and in the neighbouring spans of such a
  spin that turn more than :data:`WIND_STEP`), until every screw span there turns at most
  :data:`WIND_STEP`: the motion turns as far and the same way as the channels say. Quaternion keys keep the shortest arc (no sign flips),
  which is what quaternion users expect.
- **Holds and pops.** A span where every channel stays still (CONSTANT interpolation, or
  equal keys with flat handles) is held: its frames keep the key pose exactly, the motion is
  cut there into pieces smoothed as open sequences (each keeps its end poses), and when the
  pose jumps at the next key (a CONSTANT pop) the baked keys of the span are CONSTANT too.
- **Pace ("Keys" timing).** Within each span, the fraction of the span's smoothed motion
  reached at a frame equals the fraction of the way Blender's own curves have gone at that
  frame, both measured as distance travelled by the body (:func:`travel`): ease in/out,
  EXPO, BACK and custom handles keep their feel while the path becomes a screw path.
  Overshoot (BACK, ELASTIC) counts as distance travelled: the pace follows it, the path
  stays within the span.
- **Cycles.** A Cycles modifier in Repeat with Offset (a walk that moves on) or Mirror mode
  is played by Blender beyond the keys: the keys are extended by Blender's own playback over
  neighbouring cycles and smoothed as an open sequence, so the seam is smooth and the
  baked curves repeat with the same modifier.

Nothing here writes Blender data.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from . import curves

#: A span whose channels turn further than this (radians) along Blender's playback gets poses
#: from that playback added inside it: the screw between its keys alone, the shortest one,
#: would turn less (at half a turn and beyond: the other way round).
WIND_LIMIT = np.radians(150.0)

#: The turn of each screw span a spinning run of spans is cut into (at most; radians): the
#: spin span and its neighbours turning more than this, so the screw spans of a spin are
#: short and about equal (approximating schemes then stay within a degree of the keys).
WIND_STEP = np.radians(45.0)

#: Samples of Blender's playback per key span when looking for holds and turns (more in a
#: span whose rotation channels change a lot: one per 10 degrees).
SPAN_SAMPLES = 8

#: At most this many samples per span for a spinning span (one every 10 degrees of channel
#: change, at least :data:`SPAN_SAMPLES`).
MAX_SPAN_SAMPLES = 4096

#: A channel that moves by less than this (relative to its size, plus an absolute floor of the
#: same size) over a span is still.
HOLD_TOLERANCE = 1e-6

#: Cycles modifier modes whose playback beyond the keys is not the keys repeated: the
#: motion is extended by Blender's playback and baked with the same modifier.
EXTENDED_CYCLES = ("REPEAT_OFFSET", "MIRROR")

#: Cycles of Blender's playback added on each side of an extended cycle: the subdivision's
#: support at any level stays within them.
EXTRA_CYCLES = 2

#: Most cycles an extended motion is unrolled over (a frame range far beyond the keys).
MAX_CYCLES = 1000


def rotation_angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Angles (radians) of the rotations taking each `a[i]` to `b[i]`, (N, 3, 3) each."""
    relative = np.einsum("nji,njk->nik", a, b)
    cos = np.clip((np.trace(relative, axis1=1, axis2=2) - 1.0) / 2.0, -1.0, 1.0)
    skew = np.stack(
        [relative[:, 2, 1] - relative[:, 1, 2], relative[:, 0, 2] - relative[:, 2, 0], relative[:, 1, 0] - relative[:, 0, 1]],
        axis=1,
    )
    return np.arctan2(np.linalg.norm(skew, axis=1) / 2.0, cos)


def travel(a: np.ndarray, b: np.ndarray, size: float) -> np.ndarray:
    """How far a body moves from pose `a[i]` to `b[i]` ((N, 4, 4) each): the root mean square
    displacement of the six points at +-`size` along its axes,
    `sqrt(|t_b - t_a|^2 + size^2 / 3 |R_b - R_a|_F^2)` (the cross terms cancel)."""
    dt = b[:, :3, 3] - a[:, :3, 3]
    dr = b[:, :3, :3] - a[:, :3, :3]
    return np.sqrt(np.sum(dt * dt, axis=1) + size * size / 3.0 * np.sum(dr * dr, axis=(1, 2)))


@dataclass
class Source:
    """An owner's transform channels as Blender plays them: its curves, packed for
    `polyscrew.evaluate_fcurves`, and the values of the channels without a curve."""

    packed: curves.Packed
    #: (property, array index) of each packed curve.
    columns: list[tuple[str, int]]
    #: property -> its values on the owner (used where a channel has no curve).
    static: dict[str, np.ndarray]
    #: The owner's rotation mode and rotation property.
    mode: str
    rotation_path: str
    #: Whether location moves the owner (not for a connected bone).
    located: bool
    #: Cycles modifier mode after the keys per curve ("" when none).
    cycles_after: list[str] = field(default_factory=list)
    cycles_before: list[str] = field(default_factory=list)

    def channels(self, frames: np.ndarray) -> dict[str, np.ndarray]:
        """location (T, 3), rotation (T, k) and scale (T, 3) at `frames`, as Blender plays them."""
        frames = np.asarray(frames, dtype=np.float64)
        values = curves.evaluate_packed(self.packed, frames) if self.columns else np.zeros((0, len(frames)))
        out = {}
        for prop in ("location", self.rotation_path, "scale"):
            static = self.static[prop]
            block = np.empty((len(frames), len(static)))
            block[:] = static
            out[prop] = block
        for row, (prop, index) in enumerate(self.columns):
            out[prop][:, index] = values[row]
        if not self.located:
            out["location"][:] = 0.0
        return out


def analyse_spans(
    source: Source,
    frames: np.ndarray,
    rotation_matrices,
    compose,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per key span of `frames` (K,): whether it is held, whether the pose pops at its end,
    its turn (radians, from Blender's playback), and the subframes where poses must be added
    so that no screw span turns more than :data:`WIND_LIMIT` (Euler and axis-angle only).

    `rotation_matrices(values, mode)` and `compose(location, rotations)` are :mod:`keys`'
    conversions (passed in to keep this module free of them).
    """
    k = len(frames)
    spans = k - 1
    at_keys = source.channels(frames)
    rotation = at_keys[source.rotation_path]
    # Samples per span: more where the rotation channels change a lot (spins).
    if source.mode in ("QUATERNION",):
        counts = np.full(spans, SPAN_SAMPLES)
    else:
        change = np.abs(np.diff(rotation, axis=0))
        change = change[:, 1:] if source.mode == "AXIS_ANGLE" else change
        degrees = np.degrees(change.sum(axis=1)) if source.mode != "AXIS_ANGLE" else np.degrees(np.abs(np.diff(rotation[:, 0])))
        counts = np.clip(np.ceil(degrees / 10.0).astype(int), SPAN_SAMPLES, MAX_SPAN_SAMPLES)
    # Sample frames: for each span, `count` points from its start (included) to its end (excluded).
    starts = np.repeat(frames[:-1], counts)
    widths = np.repeat(np.diff(frames), counts)
    offsets = np.concatenate([np.arange(c) / c for c in counts])
    span_of = np.repeat(np.arange(spans), counts)
    sample_frames = starts + widths * offsets
    played = source.channels(sample_frames)
    # Holds: every channel equal to its value at the span's start over the whole span.
    held = np.ones(spans, dtype=bool)
    for prop, values in played.items():
        start_values = at_keys[prop][span_of]
        scale = np.abs(start_values) + 1.0
        moving = np.abs(values - start_values) > HOLD_TOLERANCE * scale
        held &= ~np.bincount(span_of, weights=moving.any(axis=1), minlength=spans).astype(bool)
    pops = np.zeros(spans, dtype=bool)
    for prop, values in at_keys.items():
        scale = np.abs(values[:-1]) + 1.0
        pops |= (np.abs(values[1:] - values[:-1]) > HOLD_TOLERANCE * scale).any(axis=1)
    pops &= held
    # Turns: the rotation between consecutive samples, accumulated per span.
    rot = rotation_matrices(played[source.rotation_path], source.mode)
    end_rot = rotation_matrices(rotation[1:], source.mode)
    following = np.concatenate([rot[1:], end_rot[-1:]])
    last = np.cumsum(counts) - 1  # the last sample of each span: next is the span's end
    following[last] = end_rot
    steps = rotation_angles(rot, following)
    turn = np.bincount(span_of, weights=steps, minlength=spans)
    added = []
    if source.mode != "QUATERNION":
        spinning = (turn > WIND_LIMIT) & ~held
        # the runs of spans turning more than WIND_STEP around each spin
        for span in np.flatnonzero(spinning):
            left = span
            while left > 0 and turn[left - 1] > WIND_STEP and not held[left - 1]:
                left -= 1
                spinning[left] = True
            right = span
            while right < spans - 1 and turn[right + 1] > WIND_STEP and not held[right + 1]:
                right += 1
                spinning[right] = True
        for span in np.flatnonzero(spinning):
            pieces = int(np.ceil(turn[span] / WIND_STEP))
            mask = span_of == span
            cumulative = np.concatenate(([0.0], np.cumsum(steps[mask])))
            where = np.concatenate((sample_frames[mask], [frames[span + 1]]))
            targets = turn[span] * np.arange(1, pieces) / pieces
            added.append(np.interp(targets, cumulative, where))
    inserted = np.concatenate(added) if added else np.zeros(0)
    return held, pops, turn, inserted


def pace_fractions(
    source_poses: np.ndarray, span_of: np.ndarray, time_fraction: np.ndarray, size: float, spans: int
) -> np.ndarray:
    """For samples of Blender's playback (poses, sorted by span and time; `span_of` their
    span, `time_fraction` their place in it), the fraction of its span's travel done at each
    sample: 0 at the span's start, 1 at its end. Over a span where the playback does not move
    the fraction of time stands in."""
    step = np.zeros(len(span_of))
    same = np.concatenate(([False], span_of[1:] == span_of[:-1]))
    step[1:] = travel(source_poses[:-1], source_poses[1:], size)
    step[~same] = 0.0
    done = np.cumsum(step)
    first = np.searchsorted(span_of, np.arange(spans))
    done -= done[np.clip(first, 0, len(done) - 1)][span_of]
    total = np.zeros(spans)
    np.maximum.at(total, span_of, done)
    moving = total[span_of] > 0.0
    return np.where(moving, done / np.where(moving, total[span_of], 1.0), time_fraction)
