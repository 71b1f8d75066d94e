# SPDX-License-Identifier: GPL-3.0-or-later
"""What the animator meant between the keys: spins, holds and pops, easing, cycles with offset.

Key values alone lose most of what an animator puts into F-curves. The owner's transform
curves are evaluated as Blender plays them (:mod:`curves` reads them; a `polyscrew.Playback`,
built once per owner, evaluates them exactly as `polyscrew.evaluate_fcurves` does) and read
for the following, each one `polyscrew` call per owner (`polyscrew.analyse_spans`,
`polyscrew.keys_parameters`: the numbers are done in the Rust core):

- **Spins.** A screw between two key poses is the short one (at most half a turn). Where the
  Euler or axis-angle channels turn further within a span (a wheel keyed 0, 360, 720
  degrees), poses taken from Blender's own playback at subframes are added to the keys
  where they turn more than :data:`WIND_LIMIT` (and in the neighbouring spans of such a
  spin that turn more than :data:`WIND_STEP`), until every screw span there turns at most
  :data:`WIND_STEP`: the motion turns as far and the same way as the channels say.
  Quaternion keys keep the shortest arc (no sign flips), which is what quaternion users
  expect (unless Turns is As Blender Plays).
- **Flips** are not spins. Keys set from matrices (a script setting `matrix_basis`, an
  importer, a visual-keyed bake) have Euler values inside -180..180 degrees; where a channel
  wraps (111.5 -> -141.1) Blender's playback turns the long way round. The option *Turns*
  (:data:`TURNS`) decides: Auto (the default) takes such a span the short way when both keys
  lie inside -180..180 and an equivalent triple (360 added, or the twin triple) is at least
  :data:`WRAP_MARGIN` closer to the previous key, and quaternion keys with opposite signs
  the short way, while spins the animator typed (a value beyond the range, 0 -> 270, 0 / 360
  / 720, or a jump no equivalent triple explains) turn as Blender plays them; As Blender
  Plays follows every span as Blender plays it (flips and quaternion sign flips too);
  Shortest takes the short screw between every two key poses. The removed flips are
  reported with their frames.
- **Departure.** After a bake the result is measured against Blender's playback of the
  source at every baked frame (`polyscrew.measure_departures`, one call for all the owners
  of a Smooth Motion, :func:`departures`; `polyscrew.Playback.measure_departure` for one,
  comparing with the playback timing "Keys" has played already at those frames): where it
  departs by more than :data:`DEPARTURE_DEGREES` or :data:`DEPARTURE_FRACTION` of the
  owner's size, the report names the owner, the frames and the size (:func:`departure_note`).
- **Holds and pops.** A span where every channel stays still (CONSTANT interpolation, or
  equal keys with flat handles) is held: its frames keep the key pose exactly, the motion is
  cut there into pieces smoothed as open sequences (each keeps its end poses), and when the
  pose jumps at the next key (a CONSTANT pop) the baked keys of the span are CONSTANT too.
- **Pace ("Keys" timing).** Within each span, the fraction of the span's smoothed motion
  reached at a frame equals the fraction of the way Blender's own curves have gone at that
  frame, both measured as distance travelled by the body (the root mean square displacement
  of six points at +-size along its axes, `sqrt(|dt|^2 + size^2/3 |dR|_F^2)`): ease in/out,
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

from dataclasses import InitVar, dataclass, field

import numpy as np
import polyscrew

from .packed import Packed

#: A span whose channels turn further than this (radians, 150 degrees) along Blender's
#: playback gets poses from that playback added inside it: the screw between its keys alone,
#: the shortest one, would turn less (at half a turn and beyond: the other way round).
#: (The core's constant, as every one below: `polyscrew.WIND_LIMIT`.)
WIND_LIMIT = polyscrew.WIND_LIMIT

#: The turn of each screw span a spinning run of spans is cut into (at most; radians, 45
#: degrees): the spin span and its neighbours turning more than this, so the screw spans of
#: a spin are short and about equal (approximating schemes then stay within a degree of the
#: keys).
WIND_STEP = polyscrew.WIND_STEP

#: Samples of Blender's playback per key span when looking for holds and turns (more in a
#: span whose rotation channels change a lot: one per 10 degrees).
SPAN_SAMPLES = polyscrew.SPAN_SAMPLES

#: At most this many samples per span for a spinning span (one every 10 degrees of channel
#: change, at least :data:`SPAN_SAMPLES`).
MAX_SPAN_SAMPLES = polyscrew.MAX_SPAN_SAMPLES

#: A channel that moves by less than this (relative to its size, plus an absolute floor of the
#: same size) over a span is still.
HOLD_TOLERANCE = polyscrew.HOLD_TOLERANCE

#: Turns (the option): how spans that Blender's playback turns the long way round are
#: smoothed. (identifier, label, description)
TURNS = (
    (
        "AUTO",
        "Auto",
        "Spins you typed turn as Blender plays them (a key value beyond -180..180, 0 to 270, "
        "0/360/720); flips take the short way: Euler wraps (both keys inside -180..180 and the same "
        "rotation 360 degrees off, or its twin Euler triple, at least 45 degrees closer to the "
        "previous key, as keys set from matrices have) and quaternion keys of opposite sign. "
        "The report says how many flips were removed and where",
    ),
    (
        "BLENDER",
        "As Blender Plays",
        "Every span turns as Blender plays its curves: spins, Euler wraps and quaternion sign "
        "flips alike",
    ),
    ("SHORTEST", "Shortest", "The short screw (at most half a turn) between every two key poses, spins included"),
)

#: An Euler span is a wrap when an equivalent triple of its second key is at least this much
#: closer (radians, 45 degrees, sum over the three angles) to the first key: `polyscrew.WRAP_MARGIN`.
WRAP_MARGIN = polyscrew.WRAP_MARGIN

#: The report names an owner whose result departs from Blender's playback of the source by
#: more than this angle (degrees) ...
DEPARTURE_DEGREES = 5.0

#: ... or more than this fraction of the owner's size (:func:`keys.body_size`, half its
#: largest dimension) in location.
DEPARTURE_FRACTION = 0.05

#: A key span baked at more frames than this is measured at this many of them, evenly spaced
#: (its first and last included): between two keys the result and Blender's playback are
#: smooth, and a bake of 100,000 frames then costs no more to measure than one of a few
#: thousand. A frame not measured departs as its nearest measured frame does.
DEPARTURE_SPAN_FRAMES = 64

#: Cycles modifier modes whose playback beyond the keys is not the keys repeated: the
#: motion is extended by Blender's playback and baked with the same modifier.
EXTENDED_CYCLES = ("REPEAT_OFFSET", "MIRROR")

#: Cycles of Blender's playback added on each side of an extended cycle: the subdivision's
#: support at any level stays within them.
EXTRA_CYCLES = 2

#: Most cycles an extended motion is unrolled over (a frame range far beyond the keys).
MAX_CYCLES = 1000


@dataclass
class Source:
    """An owner's transform channels as Blender plays them: its curves, packed for
    `polyscrew.evaluate_fcurves`, and the values of the channels without a curve; and the
    same as a `polyscrew.Playback`, built once, that evaluates them."""

    packed: Packed
    #: (property, array index) of each packed curve.
    columns: list[tuple[str, int]]
    #: property -> its values on the owner (used where a channel has no curve).
    static: dict[str, np.ndarray]
    #: The owner's rotation mode and rotation property.
    mode: str
    rotation_path: str
    #: Whether location moves the owner (not for a connected bone).
    located: bool
    #: The curves, channels and static values in the core (raises ValueError for curves
    #: `polyscrew` refuses).
    playback: polyscrew.Playback = field(init=False, repr=False)
    #: The playback of these curves and values when it is made already (`polyscrew.read_owners`).
    made: InitVar[polyscrew.Playback | None] = None

    def __post_init__(self, made: polyscrew.Playback | None) -> None:
        if made is not None:
            self.playback = made
            return
        self.playback = polyscrew.Playback(
            channels=self.columns, unkeyed=self.unkeyed(), mode=self.mode, located=self.located,
            **self.packed.arguments(),
        )

    def unkeyed(self) -> np.ndarray:
        """The owner's own values of all its channels: location, rotation, scale."""
        return np.concatenate([self.static["location"], self.static[self.rotation_path], self.static["scale"]])

    def channels(self, frames: np.ndarray) -> dict[str, np.ndarray]:
        """location (T, 3), rotation (T, k) and scale (T, 3) at `frames`, as Blender plays them."""
        return self._named(self.playback.channels(np.asarray(frames, dtype=np.float64)))

    def _named(self, played: tuple[np.ndarray, np.ndarray, np.ndarray]) -> dict[str, np.ndarray]:
        location, rotation, scale = played
        return {"location": location, self.rotation_path: rotation, "scale": scale}


def channels_many(sources: list[Source], frames: np.ndarray) -> list[dict[str, np.ndarray]]:
    """:meth:`Source.channels` of every source at the same `frames`, bit for bit, in one
    `polyscrew.channels_many` call."""
    played = polyscrew.channels_many([s.playback for s in sources], np.asarray(frames, dtype=np.float64))
    return [s._named(p) for s, p in zip(sources, played)]


def analyse_spans(
    source: Source,
    frames: np.ndarray,
    rotation_matrices=None,
    compose=None,
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Per key span of `frames` (K,): whether it is held, whether the pose pops at its end,
    its turn (radians, from Blender's playback), and the subframes where poses must be added
    so that no screw span turns more than :data:`WIND_LIMIT` (Euler and axis-angle only).

    One `polyscrew.analyse_spans` call (the rules: that function's documentation and
    :mod:`intent`'s). `rotation_matrices` and `compose` are not used any more (the core
    converts rotations itself); they stay so that callers need not change.
    """
    return polyscrew.analyse_spans(source.playback, np.asarray(frames, dtype=np.float64))


def analyse_turns(
    source: Source, frames: np.ndarray, turns: str = "AUTO"
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """:func:`analyse_spans` under the option Turns (:data:`TURNS`), and per span whether it
    is a flip (an Euler wrap or a quaternion sign flip, by its key values). One
    `polyscrew.analyse_turns` call."""
    return polyscrew.analyse_turns(source.playback, np.asarray(frames, dtype=np.float64), turns)


def frame_runs(frames: np.ndarray, limit: int = 4) -> str:
    """"12-18, 30-37 and 2 more": the runs of consecutive entries of `frames` (sorted frames
    of one grid, or (start, end) pairs when 2-D), the first `limit` of them."""
    frames = np.asarray(frames, dtype=np.float64)
    if frames.ndim == 2:
        starts, ends = frames[:, 0], frames[:, 1]
    else:
        if not len(frames):
            return ""
        gaps = np.diff(frames)
        step = np.min(gaps) if len(gaps) else 1.0
        cut = np.flatnonzero(gaps > 1.5 * step) + 1
        starts = frames[np.concatenate(([0], cut))]
        ends = frames[np.concatenate((cut - 1, [len(frames) - 1]))]
    words = [f"{a:g}" if a == b else f"{a:g}-{b:g}" for a, b in zip(starts[:limit].tolist(), ends[:limit].tolist())]
    more = f" and {len(starts) - limit} more" if len(starts) > limit else ""
    return ", ".join(words) + more


@dataclass
class Departure:
    """How far a result departs from Blender's playback of the source, at its baked frames."""

    #: Largest angle (degrees) and distance (units) over the frames.
    degrees: float
    distance: float
    #: The frames where it departs by more than the thresholds.
    frames: np.ndarray


def departure(
    source: Source,
    size: float,
    frames: np.ndarray,
    location: np.ndarray | None,
    rotation: np.ndarray,
    key_frames: np.ndarray | None = None,
    played: np.ndarray | None = None,
) -> Departure:
    """The departure of the channels `location` (T, 3; None for a connected bone) and
    `rotation` (T, k) at `frames` (T, sorted) from Blender's playback of `source`: one
    `polyscrew.Playback.measure_departure` call; frames above :data:`DEPARTURE_DEGREES` or
    :data:`DEPARTURE_FRACTION` of `size`. With the motion's `key_frames`, a span baked at
    more than :data:`DEPARTURE_SPAN_FRAMES` frames is measured at that many of them (a frame
    not measured departs as its nearest measured frame). `played`: the playback's rows at
    `frames` the bake has played already (:attr:`sampling.Sampled.played`, NaN elsewhere):
    those frames are not played again (the same result)."""
    frames = np.asarray(frames, dtype=np.float64)
    if location is None:
        location = np.zeros((len(frames), 3))
    degrees, distance, over = source.playback.measure_departure(
        frames, location, rotation, degrees=DEPARTURE_DEGREES, distance=DEPARTURE_FRACTION * size,
        played=played, key_frames=key_frames, most=DEPARTURE_SPAN_FRAMES,
    )
    return Departure(degrees=degrees, distance=distance, frames=frames[over])


def departures(
    items: list[tuple[Source, float, np.ndarray, np.ndarray | None, np.ndarray, np.ndarray | None, np.ndarray | None]],
) -> list[Departure]:
    """:func:`departure` of each `(source, size, frames, location, rotation, key_frames,
    played)` of `items`, the same figures to the bit, in one `polyscrew.measure_departures`
    call for all of them (the owners' rows one after the other, NaN played rows where an
    owner has none). When the batch is refused (a bad owner, its memory) each item is
    measured alone, so that a refusal raises what :func:`departure` raises."""
    if not items:
        return []
    frames = [np.asarray(item[2], dtype=np.float64) for item in items]
    rotations = [np.asarray(item[4], dtype=np.float64) for item in items]
    counts = np.array([len(f) for f in frames], dtype=np.int64)
    location = np.concatenate([np.zeros((len(f), 3)) if item[3] is None else item[3] for item, f in zip(items, frames)])
    played = None
    if any(item[6] is not None for item in items):
        played = np.concatenate([
            np.full(len(f) * (3 + r.shape[1]), np.nan) if item[6] is None else np.ravel(item[6])
            for item, f, r in zip(items, frames, rotations)
        ])
    keyed = any(item[5] is not None for item in items)
    try:
        degrees, distance, over = polyscrew.measure_departures(
            [item[0].playback for item in items], np.concatenate(frames), counts, location,
            np.concatenate([r.ravel() for r in rotations]),
            degrees=np.full(len(items), DEPARTURE_DEGREES),
            distances=np.array([DEPARTURE_FRACTION * item[1] for item in items], dtype=np.float64),
            played=played,
            key_frames=np.concatenate([item[5] for item in items if item[5] is not None] or [np.zeros(0)])
            if keyed else None,
            key_counts=np.array([-1 if item[5] is None else len(item[5]) for item in items], dtype=np.int64)
            if keyed else None,
            most=DEPARTURE_SPAN_FRAMES,
        )
    except (ValueError, MemoryError):  # each alone: the refused one raises its own error
        return [departure(source, size, f, loc, rot, keys, rows) for (source, size, f, loc, rot, keys, rows) in items]
    ends = np.cumsum(counts).tolist()
    return [
        Departure(degrees=d, distance=x, frames=f[over[end - len(f) : end]])
        for d, x, f, end in zip(degrees.tolist(), distance.tolist(), frames, ends)
    ]


def departure_note(name: str, found: Departure, size: float, causes: list[str]) -> str | None:
    """The report's line for an owner whose result departs from Blender's playback (None when
    it stays within the thresholds): the owner, the largest angle and distance (and the
    distance as a percentage of its size), the frames, and what may cause it."""
    if not len(found.frames):
        return None
    why = f" ({'; '.join(causes)})" if causes else ""
    return (
        f"{name}: departs from what Blender played by up to {found.degrees:.1f} degrees and "
        f"{found.distance:.3g} units ({100.0 * found.distance / size:.0f} % of its size) at frames "
        f"{frame_runs(found.frames)}{why}"
    )
