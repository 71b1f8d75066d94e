# SPDX-License-Identifier: GPL-3.0-or-later
"""F-curve modifiers on transform curves: kept on the result of Smooth Motion.

Blender plays an F-curve as its keys, then its modifiers (Cycles first changes the time the
keys are read at; Noise, Limits, Generator, Envelope, Built-in Function and Stepped act on
what the keys make). Smoothing works on the motion the keys make (:mod:`curves` reads the
keys' own playback, with a first Cycles modifier), and the other modifiers are copied onto
the baked curves, every property in order (mute, influence, restricted range included), so
they act on the smoothed motion as they acted on the keys: a Noise still shakes, a Stepped
still steps, Limits still hold.

Where a modifier makes smoothing the keys meaningless, the owner is refused with the reason
(:func:`refusal`): a Generator or Built-in Function that replaces the keys (not Additive)
over their whole range at full influence (the keys do not make the motion), a Cycles
modifier that is not first in the stack (the keys' repetition then depends on the modifiers
above it).
"""

from __future__ import annotations

import bpy

from . import bulk

#: Modifier types copied onto the baked curves (a first Cycles modifier is the bake's own).
KEPT = ("NOISE", "STEPPED", "LIMITS", "GENERATOR", "FNGENERATOR", "ENVELOPE", "CYCLES")

#: Properties of every modifier that are not copied (read-only, or set by the copy itself).
_SKIPPED = {"rna_type", "type", "is_valid", "active"}

#: Names of transform properties and their components in the report.
_LABELS = {
    "location": ("location", "XYZ"),
    "rotation_euler": ("rotation", "XYZ"),
    "rotation_quaternion": ("rotation", "WXYZ"),
    "rotation_axis_angle": ("rotation", "WXYZ"),
    "scale": ("scale", "XYZ"),
}


def kind(modifier: bpy.types.FModifier) -> str:
    """The modifier's type as Blender's UI names it ("Noise", "Built-In Function")."""
    return bpy.types.FModifier.bl_rna.properties["type"].enum_items[modifier.type].name


def active(fcurve: bpy.types.FCurve) -> list[tuple[int, bpy.types.FModifier]]:
    """The modifiers Blender evaluates (not muted), with their place in the stack."""
    return [(i, m) for i, m in enumerate(fcurve.modifiers) if not m.mute]


def kept(fcurve: bpy.types.FCurve) -> list[bpy.types.FModifier]:
    """The modifiers of `fcurve` that are copied onto the baked curve: all of them (muted ones
    too, they stay as the animator left them) but a first Cycles modifier, which the bake
    writes itself."""
    mods = list(fcurve.modifiers)
    if mods and mods[0].type == "CYCLES":
        mods = mods[1:]
    return mods


def refusal(fcurve: bpy.types.FCurve, key_range: tuple[float, float]) -> str | None:
    """Why the modifiers of `fcurve` make smoothing its keys meaningless (None when they do
    not). `key_range` is the first and last key frame of the owner."""
    for index, mod in active(fcurve):
        name = f"{kind(mod)} modifier {mod.name!r}"
        if mod.type == "CYCLES" and index > 0:
            return (
                f"its {name} is not first in the modifier stack, so the keys' repetition depends on "
                "the modifiers above it: move it to the top"
            )
        if mod.type not in KEPT:
            return f"has a {name} the add-on does not know"
        if mod.type in ("GENERATOR", "FNGENERATOR") and not mod.use_additive:
            full = not mod.use_influence or mod.influence >= 1.0
            everywhere = not mod.use_restricted_range or (
                mod.frame_start <= key_range[0] and mod.frame_end >= key_range[1]
            )
            if full and everywhere:
                return (
                    f"its {name} replaces the keys (not Additive) over their whole range, so the keys do "
                    "not make this motion and smoothing them would change nothing: make it Additive, "
                    "restrict its frame range, or mute it"
                )
    return None


def keeps_map(fcurve: bpy.types.FCurve, a: float, c: float) -> bool:
    """Whether the modifiers of `fcurve` play its keys mapped by `a * value + c` as that same
    map of what they played before (a Frame Range's join writes the keys after the range a
    turn, or the twin Euler triple, away: :mod:`range_join`). Stepped and Cycles change only
    the time, an additive Noise or Generator only adds (a shift `c` passes through them);
    Limits, Envelope, a Generator that replaces the keys, a multiplying Noise do not."""
    same = abs(a - 1.0) <= 1e-6  # (a quaternion's map: its length matched, to rounding)
    if same and abs(c) <= 1e-9:
        return True
    for _, mod in active(fcurve):
        if mod.type in ("STEPPED", "CYCLES"):
            continue
        if same and (
            (mod.type == "NOISE" and mod.blend_type != "MULTIPLY")
            or (mod.type in ("GENERATOR", "FNGENERATOR") and mod.use_additive)
        ):
            continue
        return False
    return True


def _copy_properties(source, target) -> None:
    """Every writable RNA property of `source` onto `target` (same type), in RNA order;
    arrays as arrays; pointers and collections are left to the caller."""
    for prop in source.bl_rna.properties:
        name = prop.identifier
        if name in _SKIPPED or prop.is_readonly or prop.type in ("POINTER", "COLLECTION"):
            continue
        value = getattr(source, name)
        if getattr(prop, "is_array", False) or (prop.type == "FLOAT" and getattr(prop, "array_length", 0)):
            value = list(value)
        try:
            setattr(target, name, value)
        except (AttributeError, TypeError, ValueError):
            # a dynamic array (Generator coefficients) follows its size, set first: retried below
            pass


def copy_onto(modifiers: list[bpy.types.FModifier], fcurve: bpy.types.FCurve) -> None:
    """Appends a copy of each of `modifiers` (in order) to `fcurve`'s stack: every property,
    the Generator's coefficients and the Envelope's control points included."""
    for mod in modifiers:
        new = fcurve.modifiers.new(mod.type)
        if mod.type == "GENERATOR":
            new.poly_order = mod.poly_order
        if mod.type == "ENVELOPE":
            # the points' bounds through foreach_set: setting a point's min/max one by one runs
            # an update meant for modifiers on the point (crashes Blender now and then)
            points = mod.control_points
            for point in points:
                new.control_points.add(point.frame)
            for name in ("min", "max"):
                values = [0.0] * len(points)
                bulk.get(points, name, values)
                bulk.put(new.control_points, name, values)
        # twice: a restricted range's start and end clamp each other as they are set
        _copy_properties(mod, new)
        _copy_properties(mod, new)
        if mod.type == "GENERATOR":
            new.coefficients = list(mod.coefficients)


def describe(found: dict) -> list[str]:
    """Plain words for the modifiers kept on the curves `found` ((property, index) -> F-curve):
    "the Noise modifier on location", "the Limits modifier on rotation Z"."""
    by_kind: dict[tuple[str, str], list[int]] = {}
    for (prop, index), fcurve in found.items():
        for mod in kept(fcurve):
            label = (kind(mod), prop)
            if index not in by_kind.setdefault(label, []):
                by_kind[label].append(index)
    words = []
    for (name, prop), indices in by_kind.items():
        label, letters = _LABELS.get(prop, (prop, "XYZW"))
        keyed = sorted(i for p, i in found if p == prop)
        axes = "" if sorted(indices) == keyed and len(keyed) > 1 else " " + " and ".join(
            letters[i] if i < len(letters) else str(i) for i in sorted(indices)
        )
        words.append(f"the {name} modifier on {label}{axes}")
    return words
