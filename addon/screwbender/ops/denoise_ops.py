# SPDX-License-Identifier: GPL-3.0-or-later
"""Remove Noise: the operator and its panel. It collects options, calls :mod:`denoise` and
reports; the panel only draws."""

from __future__ import annotations

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty

from ..blender import bake, channels, denoise, owners, reduce
from . import panels, pipeline, reduce_ops


class SCREWBENDER_OT_denoise(reduce_ops.SelectionOperator, bpy.types.Operator):
    """Remove the jitter of captured keys (camera tracks, motion capture, baked simulations) from the selected objects or bones: the rigid motion itself is smoothed, the same in any coordinate frame, with the strength chosen from the data. The keys stay keys (their values move), the old action is kept"""

    bl_idname = "screwbender.denoise"
    bl_label = "Remove Noise"
    bl_options = {"REGISTER", "UNDO"}

    auto_strength: BoolProperty(
        name="Auto Strength",
        default=True,
        description="Choose the strength from the data (generalised cross-validation, rotation and "
        "translation apart); the values chosen are shown below after the run",
    )
    strength: FloatProperty(
        name="Strength",
        default=2.0,
        min=0.0,
        soft_max=20.0,
        subtype="TIME_ABSOLUTE",
        description="Smoothing time in frames: motion faster than about 6 times this per cycle is "
        "removed (0 leaves the keys as they are). Used when Auto Strength is off. Every value is served; "
        "above 100 key spacings it acts as 100 spacings (the strength used is shown below)",
    )
    range_mode: EnumProperty(
        name="Frame Range",
        items=(
            ("KEYS", "All Keys", "Smooth every key"),
            ("SCENE", "Scene", "Smooth the keys in the scene's frame range (the others are kept)"),
            ("CUSTOM", "Custom", "Smooth the keys between Start and End (the others are kept)"),
        ),
        default="KEYS",
        description="Which keys are smoothed; keys outside are kept as they are",
    )
    frame_start: FloatProperty(name="Start", default=1.0, description="First smoothed frame (Custom)")
    frame_end: FloatProperty(name="End", default=250.0, description="Last smoothed frame (Custom)")
    armature: EnumProperty(
        name="Armatures",
        items=owners.ARMATURE_MODES,
        default="BOTH",
        description="Object Mode, selected armatures: their keyed bones, their own keys, or both. "
        "In Pose Mode the selected bones",
    )
    smooth_result: BoolProperty(
        name="Smooth Result",
        default=False,
        description="On an action that is already a result of Remove Noise, smooth that result "
        "(else the original keys again, replacing the earlier result)",
    )
    key_mode: EnumProperty(
        name="Keys",
        items=reduce.KEY_MODES,
        default="EVERY_STEP",
        description="Every Step: the keys stay keys. Reduced: then the fewest Bezier keys within the tolerance "
        "(editable keys), in the same operator",
    )
    key_distance: reduce_ops.distance_property()
    key_angle: reduce_ops.angle_property()
    # Shown after the run (the redo panel): what Auto chose, or what was used.
    rotation_strength: FloatProperty(
        name="Rotation Strength", description="The strength used for rotation, frames (output)"
    )
    translation_strength: FloatProperty(
        name="Translation Strength", description="The strength used for translation, frames (output)"
    )

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        layout.prop(self, "auto_strength")
        row = layout.row()
        row.active = not self.auto_strength
        row.prop(self, "strength")
        layout.prop(self, "range_mode")
        if self.range_mode == "CUSTOM":
            col = layout.column(align=True)
            col.prop(self, "frame_start")
            col.prop(self, "frame_end")
        layout.prop(self, "armature")
        layout.prop(self, "smooth_result")
        reduce_ops.draw_key_options(layout, self)
        col = layout.column()
        col.enabled = False
        col.prop(self, "rotation_strength")
        col.prop(self, "translation_strength")

    def denoise_options(self, context: bpy.types.Context) -> denoise.Options:
        if self.range_mode == "SCENE":
            frame_range = (float(context.scene.frame_start), float(context.scene.frame_end))
        elif self.range_mode == "CUSTOM":
            frame_range = (self.frame_start, self.frame_end)
        else:
            frame_range = None
        return denoise.Options(
            strength=None if self.auto_strength else self.strength,
            frame_range=frame_range,
            smooth_result=self.smooth_result,
            key_mode=self.key_mode,
            key_distance=self.key_distance,
            key_angle=self.key_angle,
        )

    def execute(self, context: bpy.types.Context) -> set[str]:
        selection = owners.selection(context, self.armature, channels.object_fcurves)
        options = self.denoise_options(context)
        # remove_noise counts its own steps (two per action)
        return pipeline.run(
            self, "Remove Noise", lambda progress: denoise.remove_noise(selection, options, progress),
            lambda result: pipeline.report_outcome(self, result, lambda: self.strength_line(result)), context,
        )

    def strength_line(self, result: denoise.Denoised) -> str:
        """The run's summary line; the strengths used are set on the operator (Redo panel)."""
        rotation = sorted(s[0] for s in result.strengths)
        translation = sorted(s[1] for s in result.strengths)
        self.rotation_strength = rotation[len(rotation) // 2]
        self.translation_strength = translation[len(translation) // 2]
        spread = "" if len(rotation) == 1 else " (median over them)"
        how = "chosen from the data" if self.auto_strength else "given"
        return (
            f"Removed noise from {len(result.owners)}: {bake.summary(result.owners)}; strength {how}: rotation "
            f"{self.rotation_strength:.3g}, translation {self.translation_strength:.3g} frames{spread}"
        )


VIEW3D_PT_screwbender_denoise, GRAPH_PT_screwbender_denoise = panels.operator_panels(
    __name__, "denoise", "Remove Noise", SCREWBENDER_OT_denoise.bl_idname, "MOD_SMOOTH",
    "Strength is chosen from the data; select keys to hold the others",
)


def menu_func(self, context: bpy.types.Context) -> None:
    """Object > Animation menu entry."""
    self.layout.operator(SCREWBENDER_OT_denoise.bl_idname)


classes = (SCREWBENDER_OT_denoise, VIEW3D_PT_screwbender_denoise, GRAPH_PT_screwbender_denoise)


def register_properties() -> None:
    bpy.types.VIEW3D_MT_object_animation.append(menu_func)


def unregister_properties() -> None:
    bpy.types.VIEW3D_MT_object_animation.remove(menu_func)
