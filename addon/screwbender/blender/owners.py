# SPDX-License-Identifier: GPL-3.0-or-later
"""Transform owners: what has a keyed rigid transform. An object, or a pose bone of an
armature object: two kinds of one thing, so reading, baking, preview and Insert Key have one
code path for both.

An owner is an animated ID (the object: its action holds the curves) plus a data-path
prefix: `""` for the object's own `location`, `rotation_*`, `scale`, or
`pose.bones["name"].` for a bone's. The transform lives in the owner's own space: the
parent's space for an object (`matrix_basis`, delta transforms aside), the bone's rest pose
for a bone (`PoseBone.matrix_basis`).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import bpy

from . import channels


def _quoted(name: str) -> str:
    """`name` quoted for a data path, as Blender writes it (`bpy.utils.escape_identifier`)."""
    return bpy.utils.escape_identifier(name)


@dataclass(frozen=True)
class Owner:
    """An object (`bone == ""`) or one of its pose bones."""

    obj: bpy.types.Object
    bone: str = ""

    @property
    def target(self):
        """What holds the transform properties: the object or the pose bone."""
        return self.obj.pose.bones[self.bone] if self.bone else self.obj

    @functools.cached_property
    def prefix(self) -> str:
        """The data-path prefix of the owner's F-curves in the object's action (computed once:
        reading and baking a bone asks for it for every curve)."""
        return f'pose.bones["{_quoted(self.bone)}"].' if self.bone else ""

    @property
    def rotation_mode(self) -> str:
        return self.target.rotation_mode

    @property
    def name(self) -> str:
        """The name messages use: "Cube", or "Rig: Forearm.L" for a bone."""
        return f"{self.obj.name}: {self.bone}" if self.bone else self.obj.name

    @property
    def group(self) -> str:
        """The F-curve group of the owner's transform curves (Blender's convention: "Object
        Transforms", one group per bone)."""
        return self.bone or channels.TRANSFORM_GROUP

    def path(self, prop: str) -> str:
        """The full data path of the owner's property `prop` ("location", ...)."""
        return self.prefix + prop

    def prop_of(self, data_path: str) -> str | None:
        """The owner's property a data path animates, or None when it is not the owner's."""
        if not data_path.startswith(self.prefix):
            return None
        prop = data_path[len(self.prefix):]
        return None if "." in prop or "[" in prop else prop

    def exists(self) -> bool:
        """Whether the owner is still there (a bone may have been renamed or deleted)."""
        return not self.bone or (self.obj.pose is not None and self.bone in self.obj.pose.bones)


def as_owner(thing) -> Owner:
    """An :class:`Owner` from an owner or an object (the object itself)."""
    return thing if isinstance(thing, Owner) else Owner(thing)


#: Which owners of a selected armature object Smooth Motion takes, in Object Mode.
ARMATURE_MODES = (
    ("BOTH", "Bones and Object", "Smooth the armature object's own keys and those of its keyed bones"),
    ("BONES", "Bones Only", "Smooth only the keyed bones of selected armatures"),
    ("OBJECT", "Object Only", "Smooth only the armature object's own keys, not its bones"),
)

#: Every transform property the add-on may read or bake.
TRANSFORM_PROPS = ("location", "rotation_quaternion", "rotation_axis_angle", "rotation_euler", "scale")


def _bone_of(data_path: str) -> tuple[str, str] | None:
    """(bone name, property) of a pose bone transform data path, else None."""
    head = 'pose.bones["'
    if not data_path.startswith(head):
        return None
    end = data_path.find('"].', len(head))
    while end != -1 and data_path[end - 1] == "\\":  # an escaped quote inside the name
        end = data_path.find('"].', end + 1)
    if end == -1:
        return None
    prop = data_path[end + 3:]
    if prop not in TRANSFORM_PROPS:
        return None
    name = data_path[len(head):end].replace('\\"', '"').replace("\\\\", "\\")
    return name, prop


def keyed_bones(obj: bpy.types.Object, fcurves, grouped: dict | None = None) -> list[str]:
    """The bones of armature `obj` with keyed transform curves among `fcurves` (or in
    `grouped`, their :func:`curves_by_owner`), in the armature's bone order."""
    if obj.type != "ARMATURE" or obj.pose is None:
        return []
    keyed = set()
    if grouped is not None:
        keyed = {bone for bone, curves in grouped.items() if bone and any(len(fc.keyframe_points) for fc in curves)}
    else:
        for fc in fcurves:
            found = _bone_of(fc.data_path)
            if found is not None and len(fc.keyframe_points):
                keyed.add(found[0])
    return [b.name for b in obj.pose.bones if b.name in keyed]


def curves_by_owner(fcurves) -> dict[str, list]:
    """The transform F-curves among `fcurves` grouped by owner: bone name -> that bone's
    location, rotation and scale curves, "" -> the object's own. One pass over the curves,
    so that reading many bones of one action does not scan every curve once per bone."""
    out: dict[str, list] = {}
    for fc in fcurves:
        path = fc.data_path
        if path in TRANSFORM_PROPS:
            out.setdefault("", []).append(fc)
            continue
        found = _bone_of(path)
        if found is not None:
            out.setdefault(found[0], []).append(fc)
    return out


def is_hidden(obj: bpy.types.Object, bone: str) -> bool:
    """Whether a bone is hidden, or in bone collections that are all hidden."""
    data = obj.data.bones.get(bone)
    if data is None:
        return True
    if data.hide:
        return True
    collections = list(getattr(data, "collections", ()))
    if collections:
        return not any(getattr(c, "is_visible_effectively", getattr(c, "is_visible", True)) for c in collections)
    return False


def is_selected(obj: bpy.types.Object, bone: str) -> bool:
    """Whether a bone is selected (the pose bone's flag where Blender has one, else the bone's)."""
    pose_bone = obj.pose.bones.get(bone)
    if pose_bone is not None and hasattr(pose_bone, "select"):
        return bool(pose_bone.select)
    data = obj.data.bones.get(bone)
    return bool(data is not None and data.select)


def has_own_keys(obj: bpy.types.Object, fcurves) -> bool:
    """Whether `obj`'s own transform (not its bones') is keyed among `fcurves`."""
    return any(fc.data_path in TRANSFORM_PROPS and len(fc.keyframe_points) for fc in fcurves)


def poll_selection(cls, context: bpy.types.Context, objects=None) -> bool:
    """An operator's poll for owners: selected bones in Pose Mode, selected objects in
    Object Mode (the message says which, and what to do). `objects(context)`, when given,
    lists the Object Mode objects that count (default: the selected ones)."""
    if context.mode == "POSE":
        if not context.selected_pose_bones:
            cls.poll_message_set("Select one or more keyed bones")
            return False
        return True
    if context.mode != "OBJECT":
        cls.poll_message_set("Switch to Object Mode (objects) or Pose Mode (bones)")
        return False
    if not (objects(context) if objects is not None else context.selected_objects):
        cls.poll_message_set("Select one or more keyed objects")
        return False
    return True


def selection(context: bpy.types.Context, armature: str = "BOTH", fcurves_of=None) -> list[Owner]:
    """The owners Smooth Motion works on, as the animator expects.

    Pose Mode: the selected pose bones. Object Mode: each selected object; for an armature,
    per `armature` ("BOTH", "BONES", "OBJECT", see :data:`ARMATURE_MODES`) its own keys
    and/or all its keyed bones, leaving hidden bones and bones in hidden bone collections
    alone unless they are selected. `fcurves_of(obj)` lists an object's F-curves.
    """
    if context.mode == "POSE":
        bones = context.selected_pose_bones or []
        return sorted((Owner(b.id_data, b.name) for b in bones), key=lambda o: (o.obj.name, o.bone))
    out = []
    for obj in sorted(context.selected_objects, key=lambda o: o.name):
        curves = fcurves_of(obj) if fcurves_of is not None and obj.type == "ARMATURE" else []
        out += of_object(obj, armature, curves)
    return out


def of_object(obj: bpy.types.Object, armature: str = "BOTH", fcurves=(), grouped: dict | None = None) -> list[Owner]:
    """The owners of one object that Smooth Motion takes in Object Mode: the object itself;
    for an armature, per `armature` (:data:`ARMATURE_MODES`), its own keys and/or its keyed
    bones among `fcurves` (its F-curves; `grouped`: their :func:`curves_by_owner` when the
    caller has it), hidden bones and bones in hidden collections only when selected; the
    armature itself when nothing is keyed (reading it says so)."""
    if obj.type != "ARMATURE" or armature == "OBJECT":
        return [Owner(obj)]
    out = []
    own = armature == "BOTH" and has_own_keys(obj, fcurves if grouped is None else grouped.get("", []))
    if own:
        out.append(Owner(obj))
    bones = [b for b in keyed_bones(obj, fcurves, grouped) if not is_hidden(obj, b) or is_selected(obj, b)]
    out += [Owner(obj, b) for b in bones]
    if not bones and not own:
        out.append(Owner(obj))  # nothing keyed: read it to say so
    return out
