# SPDX-License-Identifier: GPL-3.0-or-later
"""What an animator's F-curves do between their keys, at any frames, in one `polyscrew` call.

Blender's own `FCurve.evaluate(frame)` costs a Python call per curve and frame; this module
reads the keys of many curves at once (`keyframe_points.foreach_get`, one call per property
and curve, no loop over keys) and evaluates them at every frame with
`polyscrew.evaluate_fcurves`, which mirrors Blender's evaluation operation by operation
(float32, the same key search, handle correction, cubic solver and easing formulas), so the
values are Blender's own: CONSTANT holds, LINEAR, BEZIER with any handles, the eleven easings
with their AUTO defaults and `back` / `amplitude` / `period`, CONSTANT and LINEAR
extrapolation, and a Cycles modifier (every mode before and after, cycle counts, restricted
frame range, influence).

What it cannot evaluate is refused, never approximated: :func:`problems` lists why a curve is
out of scope (another active modifier, named with its type and name: Generator, Built-in
Function, Envelope, Noise, Limits, Stepped; a muted curve or muted group, which Blender does
not play; a driver; baked sample points; no keys; an interpolation this `polyscrew` does not
know), and :func:`read` / :func:`evaluate` raise :class:`UnsupportedCurve` naming every such
curve and reason. Muted modifiers are ignored, as Blender ignores them. The caller decides
what to do (report it to the animator, or fall back to key values only for that object).

Enumerations are passed to `polyscrew` by name: Blender's RNA identifiers, mapped through
tables read from RNA (`bl_rna.properties[...].enum_items`), never Blender's internal values.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

import bpy
import numpy as np
import polyscrew


class UnsupportedCurve(ValueError):
    """F-curves `polyscrew` cannot evaluate as Blender does.

    The message names each curve (`data_path[index]`) and the reason; :attr:`problems` holds
    `(fcurve, reason)` pairs for callers that handle them one by one.
    """

    def __init__(self, problems: list[tuple[bpy.types.FCurve, str]]):
        self.problems = problems
        lines = [f"{curve_name(fc)}: {reason}" for fc, reason in problems]
        super().__init__("cannot evaluate these F-curves as Blender does: " + "; ".join(lines))


def curve_name(fcurve: bpy.types.FCurve) -> str:
    """`data_path[array_index]`, how the messages name a curve."""
    return f"{fcurve.data_path}[{fcurve.array_index}]"


def _code_table(struct: type, prop: str, names: Sequence[str]) -> tuple[np.ndarray, dict[int, str]]:
    """Blender's internal enum values of `struct.prop` -> codes of `polyscrew` (index in
    `names`), -1 for an identifier `polyscrew` does not know; and value -> identifier."""
    items = struct.bl_rna.properties[prop].enum_items
    table = np.full(max(item.value for item in items) + 1, -1, dtype=np.int64)
    identifiers = {}
    for item in items:
        identifiers[item.value] = item.identifier
        if item.identifier in names:
            table[item.value] = names.index(item.identifier)
    return table, identifiers


_TABLES: dict[str, tuple[np.ndarray, dict[int, str]]] = {}


def _table(prop: str) -> tuple[np.ndarray, dict[int, str]]:
    """The code table of `Keyframe.<prop>` ("interpolation" or "easing"), built once."""
    if prop not in _TABLES:
        names = polyscrew.INTERPOLATIONS if prop == "interpolation" else polyscrew.EASINGS
        _TABLES[prop] = _code_table(bpy.types.Keyframe, prop, names)
    return _TABLES[prop]


def _active_modifiers(fcurve: bpy.types.FCurve) -> list[tuple[int, bpy.types.FModifier]]:
    """The modifiers Blender evaluates (not muted), with their place in the stack."""
    return [(i, m) for i, m in enumerate(fcurve.modifiers) if not m.mute]


def problems(fcurve: bpy.types.FCurve) -> list[str]:
    """Why `fcurve` cannot be evaluated here as Blender plays it (empty when it can)."""
    found = []
    if getattr(fcurve, "driver", None) is not None:
        found.append("is a driver (its input is not time)")
    if fcurve.mute:
        found.append("is muted (Blender does not play it)")
    group = fcurve.group
    if group is not None and getattr(group, "mute", False):
        found.append(f"its group {group.name!r} is muted (Blender does not play it)")
    if len(fcurve.sampled_points):
        found.append("holds baked sample points, not keyframes")
    if not len(fcurve.keyframe_points):
        found.append("has no keyframes")
    for index, mod in _active_modifiers(fcurve):
        if mod.type == "CYCLES" and index == 0:
            continue
        kind = mod.type.replace("_", " ").title()
        where = "" if mod.type != "CYCLES" else " not first in the stack"
        found.append(
            f"has a {kind} modifier {mod.name!r}{where}, which the add-on cannot evaluate "
            "(mute, remove or apply it)"
        )
    return found


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


#: The RNA properties of a Cycles modifier passed on (see `polyscrew.evaluate_fcurves`).
CYCLES_PROPERTIES = (
    "mode_before",
    "mode_after",
    "cycles_before",
    "cycles_after",
    "use_restricted_range",
    "frame_start",
    "frame_end",
    "blend_in",
    "blend_out",
    "use_influence",
    "influence",
)


def _cycles(fcurve: bpy.types.FCurve) -> dict | None:
    """The settings of `fcurve`'s active Cycles modifier (None when it has none)."""
    for index, mod in _active_modifiers(fcurve):
        if index == 0 and mod.type == "CYCLES":
            return {name: getattr(mod, name) for name in CYCLES_PROPERTIES}
    return None


def _codes(fcurve: bpy.types.FCurve, prop: str, raw: np.ndarray) -> tuple[np.ndarray, str | None]:
    """`raw` Blender enum values of `Keyframe.<prop>` as `polyscrew` codes, and the first
    identifier `polyscrew` does not know (None when all are known)."""
    table, identifiers = _table(prop)
    known = (raw >= 0) & (raw < len(table))
    codes = np.where(known, table[np.clip(raw, 0, len(table) - 1)], -1)
    if (codes < 0).any():
        value = int(raw[np.argmax(codes < 0)])
        return codes, identifiers.get(value, f"value {value}")
    return codes, None


def read(fcurves: Sequence[bpy.types.FCurve]) -> Packed:
    """The keys, extrapolation and Cycles modifier of every curve in `fcurves`, packed.

    Raises :class:`UnsupportedCurve` naming every curve that cannot be evaluated as Blender
    plays it (see :func:`problems`).
    """
    bad = [(fc, reason) for fc in fcurves for reason in problems(fc)]
    counts = [len(fc.keyframe_points) for fc in fcurves]
    offsets = np.zeros(len(fcurves) + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    k = int(offsets[-1])
    pairs = {name: np.zeros((k, 2), dtype=np.float32) for name in ("co", "handle_left", "handle_right")}
    scalars = {name: np.zeros(k, dtype=np.float32) for name in ("back", "amplitude", "period")}
    enums = {name: np.zeros(k, dtype=np.int64) for name in ("interpolation", "easing")}
    for c, fc in enumerate(fcurves):
        lo, hi = int(offsets[c]), int(offsets[c + 1])
        points = fc.keyframe_points
        for name, array in pairs.items():
            flat = np.empty(2 * (hi - lo), dtype=np.float32)
            points.foreach_get(name, flat)
            array[lo:hi] = flat.reshape(-1, 2)
        for name, array in scalars.items():
            points.foreach_get(name, array[lo:hi])
        for name, array in enums.items():
            raw = np.empty(hi - lo, dtype=np.int32)
            points.foreach_get(name, raw)
            array[lo:hi], unknown = _codes(fc, name, raw.astype(np.int64))
            if unknown is not None:
                bad.append((fc, f"has {name} {unknown!r}, which this polyscrew does not know"))
    if bad:
        raise UnsupportedCurve(bad)
    return Packed(
        offsets=offsets,
        extrapolation=[fc.extrapolation for fc in fcurves],
        cycles=[_cycles(fc) for fc in fcurves],
        **pairs,
        **scalars,
        **enums,
    )


def evaluate_packed(packed: Packed, frames: np.ndarray) -> np.ndarray:
    """The packed curves at `frames` (any order, subframes allowed): (C, len(frames))."""
    times = np.ascontiguousarray(frames, dtype=np.float64).reshape(-1)
    return polyscrew.evaluate_fcurves(times, **packed.arguments())


def evaluate(fcurves: Sequence[bpy.types.FCurve], frames: np.ndarray) -> np.ndarray:
    """Every curve of `fcurves` at every frame of `frames`, as Blender plays them:
    float64 array (len(fcurves), len(frames)), equal to `fcurve.evaluate(frame)` (Blender's
    float32 values). One `polyscrew` call.

    Raises :class:`UnsupportedCurve` (a ValueError) naming every curve it cannot evaluate
    and why, before evaluating anything.
    """
    return evaluate_packed(read(fcurves), frames)
