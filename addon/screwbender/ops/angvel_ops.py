# SPDX-License-Identifier: GPL-3.0-or-later
"""Add Angular Velocity Sketch and Fit Angular Velocity: the operators and their panel.
They collect options, call :mod:`angvel` and report."""

from __future__ import annotations

import bpy
from bpy.props import EnumProperty, FloatProperty, IntProperty

from ..blender import transaction
from ..blender.angvel import SPEED_PROP, STROKE_TIMINGS, add_sketch, fit, sphere_of
from ..blender.keys import SmoothError
from . import panels, pipeline


class SCREWBENDER_OT_add_angular_velocity_sketch(bpy.types.Operator):
    """Add a unit-sphere helper at the active object with its current angular velocity as an editable sketch: direction as a curve on the sphere, speed as a keyed property to shape in the Graph Editor"""

    bl_idname = "screwbender.add_angular_velocity_sketch"
    bl_label = "Add Angular Velocity Sketch"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode")
            return False
        if context.active_object is None:
            cls.poll_message_set("Make a keyed object active")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = context.active_object

        def work(progress: pipeline.Progress) -> bpy.types.Object:
            with transaction.atomic() as t:
                return add_sketch(context, obj, t)

        def report(sphere: bpy.types.Object) -> set[str]:
            self.report({"INFO"}, f"{obj.name}: edit the blue curve on {sphere.name} and its '{SPEED_PROP}' curve")
            return {"FINISHED"}

        return pipeline.run(self, "Add Angular Velocity Sketch", work, report, refusals=(SmoothError, ValueError))


class SCREWBENDER_OT_fit_angular_velocity(bpy.types.Operator):
    """Fit the active object's rotation to its angular velocity sketch, keeping the selected rotation keys (all when none is selected); location is left untouched, the old action is kept"""

    bl_idname = "screwbender.fit_angular_velocity"
    bl_label = "Fit Angular Velocity"
    bl_options = {"REGISTER", "UNDO"}

    alpha: FloatProperty(
        name="Smoothness (alpha)",
        default=0.002,
        min=0.0,
        soft_max=0.05,
        precision=4,
        description="Weight of the tangential acceleration: larger is smoother but follows the sketch less "
        "(the paper uses 0.002; 0.001-0.005 works well)",
    )
    delta: FloatProperty(
        name="Tolerance (delta)",
        default=0.1,
        min=1e-6,
        soft_max=1.0,
        description="Largest fit error allowed per fragment; variable frames are added where it is exceeded",
    )
    max_frames: IntProperty(
        name="Variable Frames",
        default=10,
        min=0,
        soft_max=30,
        description="Most control frames the fit may add between keys",
    )
    stroke_timing: EnumProperty(
        name="Stroke Timing",
        items=STROKE_TIMINGS,
        default="POINTS",
        description="How the direction stroke's points are spread from the first to the last frame",
    )

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode")
            return False
        obj = context.active_object
        if obj is None or sphere_of(obj) is None:
            cls.poll_message_set("Make an object with an angular velocity sketch active (Add Angular Velocity Sketch)")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        obj = context.active_object

        def work(progress: pipeline.Progress):
            with transaction.atomic() as t:
                return fit(context, obj, t, self.alpha, self.delta, self.max_frames, self.stroke_timing)

        def report(result) -> set[str]:
            self.report(
                {"INFO"},
                f"{obj.name}: fit error {result.fit_error:.4f} (delta {self.delta:g}), "
                f"{len(result.frame_times)} variable frames, {result.iterations} iterations",
            )
            return {"FINISHED"}

        return pipeline.run(self, "Fit Angular Velocity", work, report)


class VIEW3D_PT_screwbender_angular_velocity(panels.OperatorsPanel, panels.View3DSidebar, bpy.types.Panel):
    """Angular velocity editing in the 3D Viewport sidebar, Animation tab."""

    bl_label = "ScrewBender Angular Velocity"
    panel_operators = (
        (SCREWBENDER_OT_add_angular_velocity_sketch.bl_idname, "SPHERE"),
        (SCREWBENDER_OT_fit_angular_velocity.bl_idname, "FORCE_VORTEX"),
    )


classes = (
    SCREWBENDER_OT_add_angular_velocity_sketch,
    SCREWBENDER_OT_fit_angular_velocity,
    VIEW3D_PT_screwbender_angular_velocity,
)
