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
With `keys_only`, the other modifiers are left out: what the keys make is evaluated (Smooth
Motion smooths that and copies those modifiers onto its result, :mod:`modifiers`).

Enumerations are passed to `polyscrew` by name: Blender's RNA identifiers, mapped through
tables read from RNA (`bl_rna.properties[...].enum_items`), never Blender's internal values.
"""

from __future__ import annotations

from collections.abc import Sequence

import bpy
import numpy as np
import polyscrew

from ..pure.packed import Packed, evaluate_packed  # re-exported: the pure layer's, read here
from . import bulk


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


def problems(fcurve: bpy.types.FCurve, keys_only: bool = False) -> list[str]:
    """Why `fcurve` cannot be evaluated here as Blender plays it (empty when it can).
    `keys_only`: what the keys make (with a first Cycles modifier) is wanted, before Blender
    applies the other modifiers (Noise, Limits, ...): those are then no problem."""
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
        if keys_only and mod.type != "CYCLES":
            continue
        kind = bpy.types.FModifier.bl_rna.properties["type"].enum_items[mod.type].name
        where = "" if mod.type != "CYCLES" else " not first in the stack"
        found.append(
            f"has a {kind} modifier {mod.name!r}{where}, which the add-on cannot evaluate "
            "(mute, remove or apply it)"
        )
    return found



#: The RNA properties of a Cycles modifier passed on (the core's list: see
#: `polyscrew.evaluate_fcurves`).
CYCLES_PROPERTIES = polyscrew.CYCLES_PROPERTIES


def _cycles(fcurve: bpy.types.FCurve) -> dict | None:
    """The settings of `fcurve`'s active Cycles modifier (None when it has none)."""
    for index, mod in _active_modifiers(fcurve):
        if index == 0 and mod.type == "CYCLES":
            return {name: getattr(mod, name) for name in CYCLES_PROPERTIES}
    return None


def _codes(prop: str, raw: np.ndarray) -> np.ndarray:
    """Blender's enum values `raw` of `Keyframe.<prop>` as `polyscrew` codes (-1: unknown)."""
    table, _ = _table(prop)
    raw = raw.astype(np.int64)
    known = raw < len(table)
    return np.where(known, table[np.where(known, raw, 0)], -1)


def _unknown(
    prop: str, codes: np.ndarray, raw: np.ndarray, offsets: np.ndarray, fcurves: Sequence[bpy.types.FCurve]
) -> list[tuple[bpy.types.FCurve, str]]:
    """(curve, reason) for every key whose `Keyframe.<prop>` has no `polyscrew` code (-1 in
    `codes`, from the packed Blender values `raw`; curve c owns keys offsets[c]:offsets[c + 1])."""
    found = []
    for i in np.flatnonzero(codes < 0):
        c = int(np.searchsorted(offsets, i, side="right")) - 1
        name = _table(prop)[1].get(int(raw[i]), f"value {int(raw[i])}")
        found.append((fcurves[c], f"has {prop} {name!r}, which this polyscrew does not know"))
    return found


def _read(points, offsets: list[int], curves: Sequence[int], name: str, out: np.ndarray, width: int = 1) -> None:
    """`foreach_get(name)` of the curves `curves` (indices) straight into their part of `out`."""
    for c in curves:
        lo, hi = offsets[c], offsets[c + 1]
        if lo < hi:
            bulk.get(points[c], name, out[width * lo : width * hi])


def _read_codes(
    points, offsets: np.ndarray, bounds: list[int], curves: Sequence[int], name: str, fcurves, bad: list
) -> np.ndarray:
    """The enum `name` of the keys of `curves` (indices; the other keys' raw value 0) as
    `polyscrew` codes (`bounds`: `offsets` as a list). Keys whose value has no code join
    `bad`, and a non-empty `bad` (what was found before too) raises :class:`UnsupportedCurve`."""
    raw = np.zeros(int(offsets[-1]), dtype=np.uint8)
    _read(points, bounds, curves, name, raw)
    codes = _codes(name, raw)
    bad += _unknown(name, codes, raw, offsets, fcurves)
    if bad:
        raise UnsupportedCurve(bad)
    return codes


def read(fcurves: Sequence[bpy.types.FCurve], keys_only: bool = False) -> Packed:
    """The keys, extrapolation and Cycles modifier of every curve in `fcurves`, packed.

    One `foreach_get` per property and curve, straight into the packed arrays (float32 and,
    for the enums, unsigned bytes: Blender's own storage, so no conversion): `co`, both
    handles and `interpolation` always; `easing` only for curves with an easing
    interpolation, `back` only with BACK, `amplitude` and `period` only with ELASTIC (the
    others keep Blender's defaults, which nothing reads). Raises :class:`UnsupportedCurve`
    naming every curve that cannot be evaluated as Blender plays it (see :func:`problems`).
    `keys_only` packs what the keys make (with a first Cycles modifier), leaving the other
    modifiers out: Smooth Motion smooths that and keeps those modifiers (:mod:`modifiers`).
    """
    fcurves = list(fcurves)
    bad = [(fc, reason) for fc in fcurves for reason in problems(fc, keys_only)]
    points = [fc.keyframe_points for fc in fcurves]
    offsets = np.zeros(len(fcurves) + 1, dtype=np.int64)
    np.cumsum([len(p) for p in points], out=offsets[1:])
    k, bounds, every = int(offsets[-1]), offsets.tolist(), range(len(fcurves))

    interpolation = _read_codes(points, offsets, bounds, every, "interpolation", fcurves, bad)

    pairs = {name: np.zeros(2 * k, dtype=np.float32) for name in ("co", "handle_left", "handle_right")}
    for name, out in pairs.items():
        _read(points, bounds, every, name, out, width=2)

    # Which curves use the per-key easing parameters at all (one pass over all keys).
    names = polyscrew.INTERPOLATIONS
    starts = offsets[:-1][np.diff(offsets) > 0]
    def curves_with(mask: np.ndarray) -> list[int]:
        hits = np.zeros(len(fcurves), dtype=bool)
        if len(starts):
            hits[np.diff(offsets) > 0] = np.add.reduceat(mask, starts) > 0
        return np.flatnonzero(hits).tolist()

    easing_codes = np.zeros(k, dtype=np.int64)
    eased = curves_with(interpolation >= names.index("SINE"))
    if eased:
        easing_codes = _read_codes(points, offsets, bounds, eased, "easing", fcurves, bad)
    scalars = {
        "back": np.full(k, 1.70158, dtype=np.float32),
        "amplitude": np.full(k, 0.8, dtype=np.float32),
        "period": np.full(k, 4.1, dtype=np.float32),
    }
    _read(points, bounds, curves_with(interpolation == names.index("BACK")), "back", scalars["back"])
    elastic = curves_with(interpolation == names.index("ELASTIC"))
    _read(points, bounds, elastic, "amplitude", scalars["amplitude"])
    _read(points, bounds, elastic, "period", scalars["period"])
    return Packed(
        offsets=offsets,
        co=pairs["co"].reshape(-1, 2),
        handle_left=pairs["handle_left"].reshape(-1, 2),
        handle_right=pairs["handle_right"].reshape(-1, 2),
        interpolation=interpolation,
        easing=easing_codes,
        extrapolation=[fc.extrapolation for fc in fcurves],
        cycles=[_cycles(fc) for fc in fcurves],
        **scalars,
    )



def evaluate(fcurves: Sequence[bpy.types.FCurve], frames: np.ndarray) -> np.ndarray:
    """Every curve of `fcurves` at every frame of `frames`, as Blender plays them:
    float64 array (len(fcurves), len(frames)), equal to `fcurve.evaluate(frame)` (Blender's
    float32 values). One `polyscrew` call.

    Raises :class:`UnsupportedCurve` (a ValueError) naming every curve it cannot evaluate
    and why, before evaluating anything.
    """
    return evaluate_packed(read(fcurves), frames)
