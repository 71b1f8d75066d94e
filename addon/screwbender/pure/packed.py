# SPDX-License-Identifier: GPL-3.0-or-later
"""F-curve keys packed as `polyscrew.evaluate_fcurves` takes them, and their evaluation.

The Blender layer reads them (`curves.read`, one `foreach_get` per keyframe property and
curve); everything after that is arrays: Blender's playback of the packed curves at any frames
(:func:`evaluate_packed`), the owner's channels in :mod:`intent`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import polyscrew


@dataclass
class Packed:
    """The keys of several F-curves as `polyscrew.evaluate_fcurves` takes them."""

    #: (C + 1,) int64: curve c owns keys offsets[c]:offsets[c + 1].
    offsets: np.ndarray
    #: (K, 2) float32 each: key, left handle, right handle (frame, value).
    co: np.ndarray
    handle_left: np.ndarray
    handle_right: np.ndarray
    #: (K,) int64: codes into polyscrew.INTERPOLATIONS and polyscrew.EASINGS.
    interpolation: np.ndarray
    easing: np.ndarray
    #: (K,) float32: BACK overshoot, ELASTIC amplitude and period.
    back: np.ndarray
    amplitude: np.ndarray
    period: np.ndarray
    #: C names: "CONSTANT" or "LINEAR".
    extrapolation: list[str]
    #: C entries: None or the Cycles modifier's RNA properties.
    cycles: list[dict | None] = field(default_factory=list)

    def arguments(self) -> dict:
        """The keyword arguments of `polyscrew.evaluate_fcurves` (all but the times)."""
        return {
            "offsets": self.offsets,
            "co": self.co,
            "handle_left": self.handle_left,
            "handle_right": self.handle_right,
            "interpolation": self.interpolation,
            "easing": self.easing,
            "back": self.back,
            "amplitude": self.amplitude,
            "period": self.period,
            "extrapolation": self.extrapolation,
            "cycles": self.cycles if any(c is not None for c in self.cycles) else None,
        }


def evaluate_packed(packed: Packed, frames: np.ndarray) -> np.ndarray:
    """The packed curves at `frames` (any order, subframes allowed): (C, len(frames))."""
    times = np.ascontiguousarray(frames, dtype=np.float64).reshape(-1)
    return polyscrew.evaluate_fcurves(times, **packed.arguments())
