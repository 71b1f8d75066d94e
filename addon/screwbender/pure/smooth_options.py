# SPDX-License-Identifier: GPL-3.0-or-later
"""Smooth Motion's options: the schemes, timings, cycle and range modes an animator chooses
from (identifier, label, description), and :class:`Options`, everything the smoothing needs
besides the owners (read from the operator or the panel by `bake.options_from`)."""

from __future__ import annotations

from dataclasses import dataclass

#: Subdivision schemes: (identifier, label, description).
#: (The strays are measured by scripts/bench/measure_schemes.py: the demo scene and 20 random keyed
#: motions spanning about 6 units, at 4 levels.)
SCHEMES = (
    ("four_point", "4-Point", "Interpolating (the default): the motion passes through every key pose exactly (C1)"),
    (
        "bspline",
        "B-Spline",
        "Approximating: the smoothest motion (C2); it cuts inside the key poses and misses them, "
        "measured up to 2.1 units and 33 degrees on keys 6 units apart",
    ),
    (
        "jarek",
        "Jarek",
        "Between the two: smoother than 4-point (C2 in the limit), it misses the keys by about half "
        "as much as B-Spline (measured up to 1.2 units and 19 degrees on keys 6 units apart)",
    ),
)


#: Timing of the motion between keys.
TIMINGS = (
    ("smooth", "Smooth", "Velocity continuous across keys at uneven frames (monotone C1 time map)"),
    ("linear", "Linear", "Constant pace between two keys, pace changes at each key"),
    (
        "keys",
        "Keys",
        "The pace of Blender's own interpolation of the keys: within each span the motion has gone "
        "the same fraction of the way as Blender's curves (ease in/out, Expo, Back, custom handles "
        "keep their feel). Overshoot (Back, Elastic) is kept as pace, not as a path beyond the keys",
    ),
)


#: Whether the motion is a cycle.
CLOSED_MODES = (
    ("AUTO", "Auto", "Closed when a Cycles modifier is on the transform F-curves"),
    ("ON", "Closed", "Treat the keys as a cycle (a last key repeating the first one closes it)"),
    ("OFF", "Open", "Treat the keys as an open sequence, ignoring Cycles modifiers"),
)


#: Which frames get baked keys.
RANGE_MODES = (
    ("KEYS", "Keys", "Bake each object from its first to its last key (a cycle: over one period)"),
    ("SCENE", "Scene", "Bake the scene's frame range"),
    ("CUSTOM", "Custom", "Bake the frame range given by Start and End"),
)


@dataclass
class Options:
    """Everything the smoothing needs besides the objects."""

    scheme: str = "four_point"
    levels: int = 4
    timing: str = "keys"
    closed: str = "AUTO"
    #: Baked frame range; None bakes each object over its keys' range.
    frame_range: tuple[float, float] | None = None
    #: Frames between baked keys (1 frame, or less for subframes).
    step: float = 1.0
    #: "SCREW" (screw subdivision) or "FEATURE" (feature points, see :mod:`feature`).
    method: str = "SCREW"
    #: Feature points: "uniform" or "centripetal" spacing of the variational curves.
    parametrization: str = "uniform"
    #: Feature points: approximate the unselected keys (else every key is hit).
    approximate: bool = False
    #: Feature points: spring stiffness of the approximated keys (smaller is smoother).
    stiffness: float = 1.0
    #: Smooth the current action even when it is a result of Smooth Motion (else such an
    #: object's original keys are smoothed again, replacing the earlier result).
    smooth_result: bool = False
    #: Turns (:data:`intent.TURNS`): "AUTO" (typed spins as Blender plays them, flips the
    #: short way), "BLENDER" (every span as Blender plays it) or "SHORTEST".
    turns: str = "AUTO"
    #: "EVERY_STEP" (one key per baked frame) or "REDUCED" (the fewest keys within the
    #: tolerance `key_distance` (Blender units) and `key_angle` (radians): :mod:`reduce`).
    key_mode: str = "EVERY_STEP"
    key_distance: float = 0.001
    key_angle: float = 0.008726646259971648
