# SPDX-License-Identifier: GPL-3.0-or-later
"""Reduce Keys without Blender: its options and tolerances, the dense frames it reads, the items
and results of one `polyscrew.reduce_keys` call, and the rigid-matrix and body-error measures
it checks the reduced curves with.

The Blender layer (`blender/reduce.py`) reads the owners' playback and rigs into :class:`Item`s
and writes the :class:`Reduced` curves.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .keyed import FRAME_TOLERANCE, SmoothError

#: The default tolerance: 1 mm (at the scene's unit scale, :func:`default_distance`) and half
#: a degree: below what an animator sees at any usual framing.
DEFAULT_DISTANCE_M = 0.001


DEFAULT_ANGLE = math.radians(0.5)


#: Smooth Motion and Remove Noise: which keys they write.
KEY_MODES = (
    ("EVERY_STEP", "Every Step", "One key per baked frame (per Step), as nla.bake writes them"),
    (
        "REDUCED",
        "Reduced",
        "The fewest Bezier keys whose playback stays within the tolerance of the result in world space "
        "(editable keys), in the same operator",
    ),
)


#: Most dense frames one Reduce Keys reads per owner (a longer range is refused).
MAX_FRAMES = 1_000_000


@dataclass
class Options:
    """What Reduce Keys needs besides the owners."""

    #: Largest distance (Blender units) any point of the body may move from the dense motion.
    distance: float = DEFAULT_DISTANCE_M
    #: Largest rotation difference (radians).
    angle: float = DEFAULT_ANGLE
    #: On an action that is already a result of Reduce Keys: reduce that result (else the
    #: original keys again, replacing the earlier result).
    reduce_result: bool = False
    #: Each channel keyed on frames of its own (fewer keys in all); default: an owner's
    #: channels keyed on the same frames (fewer key frames, one column per pose).
    per_channel: bool = False


@dataclass
class Item:
    """One owner's dense motion, ready for `polyscrew.reduce_keys`."""

    owner: object  # the Blender layer's owners.Owner
    mode: str
    #: (N, 4, 4) rigid poses in channel space and (N, 3) positive scales at the batch's frames.
    poses: np.ndarray
    scales: np.ndarray
    #: Which of location, rotation, scale the owner keys.
    channels: np.ndarray
    #: (N - 1,) spans that are steps (CONSTANT pops) in the source.
    constant: np.ndarray
    #: The rotation channel values at the first frame (4,), as the source has them.
    start: np.ndarray
    radius: float
    #: (property, index) of the curves to write.
    written: list[tuple[str, int]]
    #: Key frames before (distinct frames over its transform curves).
    keys_before: int = 0
    #: Whether its curves repeat (Cycles modifier).
    cyclic: bool = False
    #: Blender's playback at the probes of every span (:func:`departure`), when read.
    probe_poses: np.ndarray | None = None
    probe_scales: np.ndarray | None = None
    #: (N - 1,) spans Blender plays as a straight line in channel space (LINEAR keys).
    linear: np.ndarray | None = None
    #: Whole frames among the dense frames (quarter frames aside), for the report.
    whole: int = 0


@dataclass
class Curve:
    """One reduced F-curve: keys (K, 2) and handles, enums as Blender's RNA identifiers' codes."""

    co: np.ndarray
    handle_left: np.ndarray
    handle_right: np.ndarray
    interpolation: np.ndarray
    easing: np.ndarray
    handle_type: np.ndarray
    #: The curve as Blender takes it (what `foreach_set` writes: flat float32 keys and
    #: handles, Blender's enum values), prepared for every curve of a call at once by the
    #: Blender layer; None until then.
    written: dict | None = None


@dataclass
class Reduced:
    """One owner's reduced curves and what was measured."""

    item: Item
    #: (property, index) -> its curve (only those in `item.written`).
    curves: dict[tuple[str, int], Curve]
    keys: int
    distance_error: float
    angle_error: float


def _rigid(matrix) -> np.ndarray:
    """A 4x4 rigid matrix from a Blender matrix (float32 rest matrices: rotation made exactly
    orthonormal by the polar decomposition, translation kept)."""
    m = np.array(matrix, dtype=np.float64)
    u, _, vt = np.linalg.svd(m[:3, :3])
    rot = u @ vt
    if np.linalg.det(rot) < 0:
        u[:, -1] *= -1
        rot = u @ vt
    out = np.eye(4)
    out[:3, :3], out[:3, 3] = rot, m[:3, 3]
    return out


def _mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """`a @ b` for (stacks of) 4x4 matrices (`np.matmul`: of `einsum`, a sum of products and
    `matmul`, the fastest on stacks of 3,000 here)."""
    return np.matmul(a, b)


def _rigid_inverse(m: np.ndarray) -> np.ndarray:
    """The inverse of a rigid 4x4 matrix: `[R^T, -R^T t]`."""
    out = np.eye(4)
    out[:3, :3] = m[:3, :3].T
    out[:3, 3] = -m[:3, :3].T @ m[:3, 3]
    return out


def _body_error(ref: np.ndarray, play: np.ndarray, radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Per pose of `ref` and `play` (n, 4, 4): the bound on how far a point within `radius` of
    the origin moves between them, ``|dt| + 2 radius sin(theta / 2)``, and the rotation angle
    `theta` between them (the measure `polyscrew.reduce_keys` keeps within its tolerance)."""
    trace = np.sum(ref[:, :3, :3] * play[:, :3, :3], axis=(1, 2))  # trace(ref_R^T play_R)
    theta = np.arccos(np.clip((trace - 1.0) / 2.0, -1.0, 1.0))
    return np.linalg.norm(ref[:, :3, 3] - play[:, :3, 3], axis=1) + 2.0 * radius * np.sin(0.5 * theta), theta


def _pad4(values: np.ndarray) -> np.ndarray:
    out = np.zeros(4)
    out[: len(values)] = values
    return out


def dense_frames(key_frames: list[np.ndarray]) -> np.ndarray:
    """Every whole frame from the first key to the last of all owners, plus every key frame
    (subframe keys included), strictly increasing (frames closer than
    :data:`FRAME_TOLERANCE` are one)."""
    first = min(float(f[0]) for f in key_frames)
    last = max(float(f[-1]) for f in key_frames)
    if last - first > MAX_FRAMES:
        raise SmoothError(f"keys from frame {first:g} to {last:g}: Reduce Keys reads at most {MAX_FRAMES:,} frames")
    whole = np.arange(math.ceil(first), math.floor(last) + 1, dtype=np.float64)
    merged = np.unique(np.concatenate([whole] + [np.asarray(f, dtype=np.float64) for f in key_frames]))
    keep = np.concatenate(([True], np.diff(merged) > FRAME_TOLERANCE))
    return merged[keep]


#: Fractions of a span between two dense frames where Blender's playback of the dense keys
#: is compared with the screw between the frames (the core's reference between them).
PROBES = (0.25, 0.5, 0.75)


#: A span whose playback by Blender departs from the screw between its frames by more than
#: this share of the tolerance (the ease of a first or last key, a fast swing) gets the
#: playback at :data:`PROBES` as dense poses too; the largest departure of the other spans is
#: taken off the tolerance given to the core, so that the reduced keys stay within the
#: tolerance of Blender's own playback of the dense keys at every frame and at the probes.
#: (Between the frames of Bezier keys on every frame, Blender's playback and the screw differ
#: by a third of a millimetre on a body 3.7 m across moving a few centimetres a frame, by a
#: millimetre on a leg swinging 6 degrees a frame: the share trades dense frames, up to four
#: times as many, against tolerance left to the core.)
DEPARTURE_SHARE = 0.25


def _probe_times(frames: np.ndarray) -> np.ndarray:
    """The probes of every span, fraction by fraction: (len(PROBES) * (N - 1),)."""
    a, width = frames[:-1], np.diff(frames)
    return np.concatenate([a + f * width for f in PROBES])


def _chain_order(parents: np.ndarray | None, count: int) -> list[int]:
    """Owner indices, every parent before its children."""
    if parents is None:
        return list(range(count))
    order, seen = [], set()

    def visit(i: int) -> None:
        if i in seen:
            return
        if parents[i] >= 0:
            visit(int(parents[i]))
        seen.add(i)
        order.append(i)

    for i in range(count):
        visit(i)
    return order


@dataclass
class Batch:
    """Owners reduced together: their items at the batch's dense frames."""

    items: list[Item]
    frames: np.ndarray
    #: Whether the batch is one cycle.
    cyclic: bool
    #: The largest departure of Blender's playback from the core's reference left in the
    #: batch (distance, angle): taken off the tolerance given to the core.
    margin: tuple[float, float] = (0.0, 0.0)
    #: The core's reference between two frames (`polyscrew.reduce_keys`' `between`).
    between: str = "screw"


#: Most times :func:`solve_batch` asks the core again, with a smaller tolerance, when the
#: reduced curves measured here exceed it (the chains of connected bones: a bone that cannot
#: move its head carries its parent's error there).
RETRIES = 2
