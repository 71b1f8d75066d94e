# SPDX-License-Identifier: GPL-3.0-or-later
"""Reduce Keys: the operator and its panels. It collects options, calls :mod:`reduce` and
reports; the panels only draw."""

from __future__ import annotations

import math

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty

from ..blender import bake, channels, owners, reduce
from . import panels, pipeline


def distance_property(name: str = "Distance") -> FloatProperty:
    """The tolerance's distance (scene units; the default is 1 mm at Unit Scale 1, set to
    1 mm at the scene's unit scale when an operator is invoked from the interface)."""
    return FloatProperty(
        name=name,
        default=reduce.DEFAULT_DISTANCE_M,
        min=1e-9,
        soft_max=1.0,
        precision=4,
        subtype="DISTANCE",
        unit="LENGTH",
        description="Reduced keys: no point of the body (an object's bounding box, a bone's length) moves further "
        "than this from the dense motion, in world space (default 1 mm in the scene's units)",
    )


def angle_property(name: str = "Angle") -> FloatProperty:
    """The tolerance's angle (radians, shown in degrees; default half a degree)."""
    return FloatProperty(
        name=name,
        default=reduce.DEFAULT_ANGLE,
        min=1e-9,
        soft_max=math.radians(10.0),
        subtype="ANGLE",
        description="Reduced keys: no rotation differs more than this from the dense motion (default 0.5 degrees)",
    )


def set_default_distance(operator: bpy.types.Operator, context: bpy.types.Context, name: str) -> None:
    """Sets the operator's distance `name` to 1 mm at the scene's unit scale unless it was given."""
    if not operator.properties.is_property_set(name):
        setattr(operator, name, reduce.default_distance(context.scene))


class SelectionOperator:
    """An operator on the selected objects or bones (its `poll` says why it cannot run) whose
    tolerance distance `distance_name` is 1 mm at the scene's unit scale when it is invoked from
    the interface (see :func:`set_default_distance`)."""

    distance_name = "key_distance"

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        return owners.poll_selection(cls, context)

    def invoke(self, context: bpy.types.Context, event) -> set[str]:
        set_default_distance(self, context, self.distance_name)
        return self.execute(context)


class SCREWBENDER_OT_reduce_keys(SelectionOperator, bpy.types.Operator):
    """Replace the dense keys of the selected objects or bones (a bake, a capture, a Smooth Motion or Remove Noise result) by the fewest Bezier keys whose playback stays within a tolerance in world space; the old action is kept"""

    bl_idname = "screwbender.reduce_keys"
    bl_label = "Reduce Keys"
    bl_options = {"REGISTER", "UNDO"}

    distance: distance_property()
    angle: angle_property()
    armature: EnumProperty(
        name="Armatures",
        items=owners.ARMATURE_MODES,
        default="BOTH",
        description="Object Mode, selected armatures: their keyed bones, their own keys, or both. "
        "In Pose Mode the selected bones",
    )
    per_channel: BoolProperty(
        name="Per Channel",
        default=False,
        description="Key each channel on frames of its own (fewest keys in all, as Decimate keys them). "
        "Off: an owner's channels are keyed on the same frames (fewest key frames: one column per pose "
        "in the Dope Sheet)",
    )
    reduce_result: BoolProperty(
        name="Reduce Result",
        default=False,
        description="On an action that is already a result of Reduce Keys, reduce that result "
        "(else the original keys again, replacing the earlier result)",
    )

    distance_name = "distance"

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        col = layout.column(align=True)
        col.prop(self, "distance")
        col.prop(self, "angle")
        layout.prop(self, "per_channel")
        layout.prop(self, "armature")
        layout.prop(self, "reduce_result")

    def execute(self, context: bpy.types.Context) -> set[str]:
        selection = owners.selection(context, self.armature, channels.object_fcurves)
        options = reduce.Options(
            distance=self.distance, angle=self.angle, reduce_result=self.reduce_result, per_channel=self.per_channel
        )
        return pipeline.run(
            self, "Reduce Keys", lambda progress: reduce.reduce_keys(selection, options, progress),
            lambda result: pipeline.report_outcome(self, result, lambda: self.summary_line(result)), context,
        )

    def summary_line(self, result: reduce.Result) -> str:
        share = 100.0 * result.keys_after / max(result.frames, 1)
        return (
            f"Reduced the keys of {len(result.owners)}: {bake.summary(result.owners)}: {result.keys_before:,} key frames "
            f"-> {result.keys_after:,} ({share:.1f} % of the frames); largest error "
            f"{result.distance_error:.3g} (tolerance {self.distance:.3g}) and "
            f"{math.degrees(result.angle_error):.3g} degrees (tolerance {math.degrees(self.angle):.3g})"
        )


VIEW3D_PT_screwbender_reduce, GRAPH_PT_screwbender_reduce = panels.operator_panels(
    __name__, "reduce", "Reduce Keys", SCREWBENDER_OT_reduce_keys.bl_idname, "IPO_BEZIER",
    "Tolerance in world space: 1 mm and 0.5 degrees by default",
)


def draw_key_options(layout: bpy.types.UILayout, settings) -> None:
    """Keys: Every Step / Reduced and its tolerance (Smooth Motion and Remove Noise)."""
    layout.prop(settings, "key_mode")
    if settings.key_mode == "REDUCED":
        col = layout.column(align=True)
        col.prop(settings, "key_distance")
        col.prop(settings, "key_angle")


def menu_func(self, context: bpy.types.Context) -> None:
    """Object > Animation menu entry."""
    self.layout.operator(SCREWBENDER_OT_reduce_keys.bl_idname)


classes = (SCREWBENDER_OT_reduce_keys, VIEW3D_PT_screwbender_reduce, GRAPH_PT_screwbender_reduce)


def register_properties() -> None:
    bpy.types.VIEW3D_MT_object_animation.append(menu_func)


def unregister_properties() -> None:
    bpy.types.VIEW3D_MT_object_animation.remove(menu_func)
