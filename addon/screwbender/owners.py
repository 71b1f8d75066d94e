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

from dataclasses import dataclass

import bpy

#: F-curve group names Blender's own keying uses: objects' transforms, and one group per bone.
OBJECT_GROUP = "Object Transforms"


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

    @property
    def prefix(self) -> str:
        """The data-path prefix of the owner's F-curves in the object's action."""
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
        """The F-curve group of the owner's transform curves (Blender's convention)."""
        return self.bone or OBJECT_GROUP

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
