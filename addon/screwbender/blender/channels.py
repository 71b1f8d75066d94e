# SPDX-License-Identifier: GPL-3.0-or-later
"""Where an object's F-curves live, in every action API the add-on supports.

The one place that knows which Blender has which action API; everything else in the add-on
(and the tests and demo scripts) goes through the functions here and never asks.

==========  =================================================================================
Blender     action API (signatures read from each bpy wheel's RNA)
==========  =================================================================================
4.2         legacy actions only: ``action.fcurves.new(data_path, index=0, action_group="")``,
            ``action.groups``; no slots (``AnimData.action_slot`` does not exist).
4.4, 4.5    slotted actions: ``action.slots.new(id_type, name)``, ``action.layers[0].strips[0]
            .channelbag(slot, ensure=False)``, ``channelbag.fcurves.new(data_path, index=0)``
            (no group argument: the group is made with ``channelbag.groups.new(name)`` and set
            with ``fcurve.group = group``). ``action.fcurves`` / ``action.groups`` remain as a
            proxy for the first slot's channelbag (it creates a slot "Legacy Slot" on demand).
5.0, 5.2    slotted actions only (``action.fcurves`` and ``action.groups`` are gone);
            ``channelbag.fcurves.new(data_path, index=0, group_name="")`` and
            ``channelbag.fcurves.ensure(...)`` with the same arguments.
==========  =================================================================================

A *container* ("bag") is what holds ``.fcurves`` and ``.groups`` for one animated data-block:
the action itself for a legacy action, the slot's channelbag for a slotted one.
"""

from __future__ import annotations

from typing import Any

import bpy

#: Name of the F-curve group Blender's own keying uses for object transforms.
TRANSFORM_GROUP = "Object Transforms"


def _new_parameters(type_names: tuple[str, ...]) -> frozenset[str]:
    """Parameter names of `<type>.new` for the first of `type_names` this Blender has."""
    for name in type_names:
        rna_type = getattr(bpy.types, name, None)
        if rna_type is not None:
            return frozenset(p.identifier for p in rna_type.bl_rna.functions["new"].parameters)
    return frozenset()


#: True when this Blender has slotted actions (4.4 and later).
HAS_SLOTS: bool = hasattr(bpy.types, "ActionSlot")
#: True when `action.fcurves` exists (4.2 to 4.5; on 4.4 and 4.5 a proxy for the first slot).
HAS_ACTION_FCURVES: bool = "fcurves" in bpy.types.Action.bl_rna.properties
#: True when a channelbag's `fcurves.new` takes `group_name` (5.0 and later; 4.4 called the
#: type ActionChannelBagFCurves).
NEW_TAKES_GROUP: bool = "group_name" in _new_parameters(
    ("ActionChannelbagFCurves", "ActionChannelBagFCurves")
)


def is_slotted(action: bpy.types.Action) -> bool:
    """True when `action` uses the slotted-action API (Blender 4.4 and later)."""
    return hasattr(action, "slots") and hasattr(action, "layers")


def assigned_slot(obj: bpy.types.ID) -> Any:
    """The action slot assigned to `obj` (None before 4.4 or when none is assigned)."""
    adt = getattr(obj, "animation_data", None)
    if adt is None:
        return None
    return getattr(adt, "action_slot", None)


def slot_identifier(obj: bpy.types.ID) -> str:
    """The identifier of the slot assigned to `obj` ("" before 4.4 or when none)."""
    slot = assigned_slot(obj)
    return slot.identifier if slot is not None else ""


def find_slot(action: bpy.types.Action, identifier: str) -> Any:
    """The slot of `action` named `identifier` (e.g. "OBCube"), or None (always None on 4.2)."""
    if not identifier or not is_slotted(action):
        return None
    return action.slots.get(identifier)


def ensure_slot(action: bpy.types.Action, owner: bpy.types.ID) -> Any:
    """The slot of `action` for the data-block `owner` (its type and name), made when missing.

    None for a legacy action (4.2), which has no slots.
    """
    if not is_slotted(action):
        return None
    for slot in action.slots:
        if slot.target_id_type == owner.id_type and slot.name_display == owner.name:
            return slot
    return action.slots.new(id_type=owner.id_type, name=owner.name)


def container(action: bpy.types.Action, slot: Any) -> Any:
    """The container holding `.fcurves` for `slot` in `action`, or None when there is none.

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
    if slot is None:
        raise ValueError(f"action {action.name!r}: a slotted action needs a slot for its F-curves")
    layer = action.layers[0] if len(action.layers) else action.layers.new("Layer")
    strip = layer.strips[0] if len(layer.strips) else layer.strips.new(type="KEYFRAME")
    return strip.channelbag(slot, ensure=True)


def containers(action: bpy.types.Action) -> list[tuple[str, Any]]:
    """Every container of `action` as (slot identifier, container): ("", action) when legacy."""
    if not is_slotted(action):
        return [("", action)]
    return [
        (bag.slot.identifier, bag)
        for layer in action.layers
        for strip in layer.strips
        for bag in strip.channelbags
    ]


def object_fcurves(obj: bpy.types.ID) -> list[bpy.types.FCurve]:
    """The F-curves that animate `obj` through its active action (empty when none)."""
    adt = getattr(obj, "animation_data", None)
    if adt is None or adt.action is None:
        return []
    bag = container(adt.action, assigned_slot(obj))
    return list(bag.fcurves) if bag is not None else []


def action_fcurves(action: bpy.types.Action, identifier: str = "") -> list[bpy.types.FCurve]:
    """The F-curves of `action` for the slot named `identifier` (4.4+; ignored for legacy
    actions), empty when it has none."""
    return fcurves(container(action, find_slot(action, identifier)))


def fcurves(bag: Any) -> list[bpy.types.FCurve]:
    """The F-curves of a container (none for None)."""
    return list(bag.fcurves) if bag is not None else []


def find_fcurve(bag: Any, data_path: str, index: int = 0) -> bpy.types.FCurve | None:
    """The F-curve of `bag` for (`data_path`, `index`), or None."""
    return bag.fcurves.find(data_path, index=index) if bag is not None else None


def ensure_group(bag: Any, name: str) -> bpy.types.ActionGroup:
    """The F-curve group `name` of `bag`, made when missing."""
    group = bag.groups.get(name)
    return group if group is not None else bag.groups.new(name)


def new_fcurve(
    bag: Any, data_path: str, index: int, group: str = TRANSFORM_GROUP, groups: dict | None = None
) -> bpy.types.FCurve:
    """Creates an F-curve in `bag` (an action or a channelbag), in F-curve group `group`.

    The group is made when missing; `group=""` puts the curve in no group. `groups`, when
    given, keeps the groups of `bag` found or made, per name, for the next curves (4.4 and
    4.5 look a group up by name per curve otherwise; the other versions take the name).
    """
    if isinstance(bag, bpy.types.Action):  # legacy (4.2), or the 4.4/4.5 proxy
        return bag.fcurves.new(data_path, index=index, action_group=group)
    if NEW_TAKES_GROUP:  # 5.0 and later
        return bag.fcurves.new(data_path, index=index, group_name=group)
    fcurve = bag.fcurves.new(data_path, index=index)  # 4.4 and 4.5
    if group:
        found = groups.get(group) if groups is not None else None
        if found is None:
            found = ensure_group(bag, group)
            if groups is not None:
                groups[group] = found
        fcurve.group = found
    return fcurve


def remove_fcurve(bag: Any, fcurve: bpy.types.FCurve) -> None:
    """Removes `fcurve` from `bag`."""
    bag.fcurves.remove(fcurve)


def remove_fcurve_at(bag: Any, data_path: str, index: int) -> None:
    """Removes the F-curve (`data_path`, `index`) from `bag` when it is there."""
    fcurve = find_fcurve(bag, data_path, index)
    if fcurve is not None:
        remove_fcurve(bag, fcurve)


def has_group(bag: Any, name: str = TRANSFORM_GROUP) -> bool:
    """Whether `bag` has an F-curve group `name`."""
    return bag.groups.get(name) is not None


def remove_group_if_empty(bag: Any, name: str = TRANSFORM_GROUP) -> None:
    """Removes the F-curve group `name` of `bag` when no F-curve is in it."""
    group = bag.groups.get(name)
    if group is not None and not any(fc.group == group for fc in bag.fcurves):
        bag.groups.remove(group)


def insert_key(fcurve: bpy.types.FCurve, frame: float, value: float) -> None:
    """Inserts (or replaces) a key of `fcurve` at `frame`, as Blender's keying does."""
    fcurve.keyframe_points.insert(frame, value)


def groups(bag: Any) -> list[str]:
    """The names of the F-curve groups of `bag`, in order."""
    return [g.name for g in bag.groups] if bag is not None else []


def assign(obj: bpy.types.ID, action: bpy.types.Action, identifier: str) -> None:
    """Makes `action` the active action of `obj`, on the slot named `identifier` (4.4+)."""
    adt = obj.animation_data_create()
    adt.action = action
    slot = find_slot(action, identifier)
    if slot is not None and adt.action_slot != slot:
        adt.action_slot = slot
