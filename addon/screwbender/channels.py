# SPDX-License-Identifier: GPL-3.0-or-later
"""Where an object's F-curves live, in both action APIs.

Blender 4.2 keeps F-curves directly on the action (`action.fcurves`). Blender 4.4 and later
use slotted actions: the F-curves of one animated data-block live in a channelbag,
`action.layers[0].strips[0].channelbag(slot)`, and 5.0 no longer has `action.fcurves` at
all. Everything else in the add-on goes through the few functions here, so it never asks
which API it is talking to.
"""

from __future__ import annotations

from typing import Any

import bpy

#: Name of the F-curve group Blender's own keying uses for object transforms.
TRANSFORM_GROUP = "Object Transforms"


def is_slotted(action: bpy.types.Action) -> bool:
    """True when `action` uses the slotted-action API (Blender 4.4 and later)."""
    return hasattr(action, "slots") and hasattr(action, "layers")


def assigned_slot(obj: bpy.types.Object) -> Any:
    """The action slot assigned to `obj` (None before 4.4 or when none is assigned)."""
    adt = obj.animation_data
    if adt is None:
        return None
    return getattr(adt, "action_slot", None)


def container(action: bpy.types.Action, slot: Any) -> Any:
    """The object holding `.fcurves` for `slot` in `action`, or None when there is none.

    Legacy actions are their own container; a slotted action has one channelbag per slot.
    """
    if not is_slotted(action):
        return action
    if slot is None:
        return None
    for layer in action.layers:
        for strip in layer.strips:
            bag = strip.channelbag(slot)
            if bag is not None:
                return bag
    return None


def ensure_container(action: bpy.types.Action, slot: Any) -> Any:
    """Like :func:`container`, creating the layer, strip and channelbag when missing."""
    if not is_slotted(action):
        return action
    layer = action.layers[0] if len(action.layers) else action.layers.new("Layer")
    strip = layer.strips[0] if len(layer.strips) else layer.strips.new(type="KEYFRAME")
    return strip.channelbag(slot, ensure=True)


def object_fcurves(obj: bpy.types.Object) -> list[bpy.types.FCurve]:
    """The F-curves that animate `obj` through its active action (empty when none)."""
    adt = obj.animation_data
    if adt is None or adt.action is None:
        return []
    bag = container(adt.action, assigned_slot(obj))
    return list(bag.fcurves) if bag is not None else []


def action_fcurves(action: bpy.types.Action, identifier: str = "") -> list[bpy.types.FCurve]:
    """The F-curves of `action` for the slot named `identifier` (4.4+; ignored for legacy
    actions), empty when it has none."""
    slot = action.slots.get(identifier) if is_slotted(action) and identifier else None
    bag = container(action, slot)
    return list(bag.fcurves) if bag is not None else []


def remove_fcurve(bag: Any, data_path: str, index: int) -> None:
    """Removes the F-curve (`data_path`, `index`) from `bag` when it is there."""
    fcurve = bag.fcurves.find(data_path, index=index)
    if fcurve is not None:
        bag.fcurves.remove(fcurve)


def has_group(bag: Any, name: str = TRANSFORM_GROUP) -> bool:
    """Whether `bag` (an action or a channelbag) has an F-curve group `name`."""
    return bag.groups.get(name) is not None


def remove_group_if_empty(bag: Any, name: str = TRANSFORM_GROUP) -> None:
    """Removes the F-curve group `name` of `bag` when no F-curve is in it."""
    group = bag.groups.get(name)
    if group is not None and not any(fc.group == group for fc in bag.fcurves):
        bag.groups.remove(group)


def new_fcurve(bag: Any, data_path: str, index: int, group: str = TRANSFORM_GROUP) -> bpy.types.FCurve:
    """Creates an F-curve in `bag` (an action or a channelbag), in F-curve group `group`."""
    if isinstance(bag, bpy.types.Action):
        return bag.fcurves.new(data_path, index=index, action_group=group)
    return bag.fcurves.new(data_path, index=index, group_name=group)


def insert_key(fcurve: bpy.types.FCurve, frame: float, value: float) -> None:
    """Inserts (or replaces) a key of `fcurve` at `frame`, as Blender's keying does."""
    fcurve.keyframe_points.insert(frame, value)


def slot_identifier(obj: bpy.types.Object) -> str:
    """The identifier of the slot assigned to `obj` ("" before 4.4 or when none)."""
    slot = assigned_slot(obj)
    return slot.identifier if slot is not None else ""


def assign(obj: bpy.types.Object, action: bpy.types.Action, identifier: str) -> None:
    """Makes `action` the active action of `obj`, on the slot named `identifier` (4.4+)."""
    adt = obj.animation_data_create()
    adt.action = action
    if identifier and is_slotted(action):
        slot = action.slots.get(identifier)
        if slot is not None and adt.action_slot != slot:
            adt.action_slot = slot
