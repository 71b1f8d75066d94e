# SPDX-License-Identifier: GPL-3.0-or-later
"""Smooth Motion and Revert Smoothing: the operators, their panel settings, panels and menu
entries. Operators collect options, call :mod:`bake` and report; panels only draw."""


import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty

from ..blender import bake, channels, feature, owners, reduce, transaction
from ..pure import intent
from . import panels, pipeline, reduce_ops
from .pipeline import report_notes, report_skipped  # noqa: F401  (bake_ops.report_*: the pipeline's)


def report_smoothed(operator: bpy.types.Operator, result: bake.Smoothed, verb: str) -> set[str]:
    """Reports what Smooth Motion did in one readable line (plus skipped objects and notes)."""

    def line() -> str:
        names = result.owners
        if result.bones == len(names):
            what = "bone(s)"
        elif result.bones:
            what = "bone(s) and object(s)"
        else:
            what = "object(s)"
        count = len(result.actions)
        shared = f" ({count} new action{'s' if count != 1 else ''})" if count != len(names) else ""
        return f"{verb} {len(names)} {what}: {bake.summary(names)}{shared}"

    return pipeline.report_outcome(operator, result, line)


def draw_method(layout: bpy.types.UILayout, settings) -> None:
    """The Method option and, for Feature Points, its own options (operator and panel)."""
    layout.prop(settings, "method")
    if settings.method == "FEATURE":
        layout.prop(settings, "parametrization")
        layout.prop(settings, "approximate")
        row = layout.row()
        row.active = settings.approximate
        row.prop(settings, "stiffness")


def draw_options(layout: bpy.types.UILayout, settings) -> None:
    """Every Smooth Motion option (the operator's redo panel and the sidebar panel)."""
    draw_method(layout, settings)
    for name in ("scheme", "levels", "timing", "turns", "closed", "range_mode"):
        layout.prop(settings, name)
    if settings.range_mode == "CUSTOM":
        col = layout.column(align=True)
        col.prop(settings, "frame_start")
        col.prop(settings, "frame_end")
    layout.prop(settings, "step")
    reduce_ops.draw_key_options(layout, settings)
    layout.prop(settings, "armature")
    layout.prop(settings, "smooth_result")


class SCREWBENDER_OT_smooth(reduce_ops.SelectionOperator, bpy.types.Operator):
    """Replace the keyed motion of the selected objects by a smooth screw motion through their key poses, baked into a new action (the old one is kept)"""

    bl_idname = "screwbender.smooth"
    bl_label = "Smooth Motion"
    bl_options = {"REGISTER", "UNDO"}

    method: EnumProperty(
        name="Method",
        items=feature.METHODS,
        default="SCREW",
        description="How the key poses become a smooth motion",
    )
    parametrization: EnumProperty(
        name="Spacing",
        items=feature.PARAMETRIZATIONS,
        default="uniform",
        description="Feature Points: how the keys are spaced along the variational curves",
    )
    approximate: BoolProperty(
        name="Approximate Keys",
        default=False,
        description="Feature Points: pass near the selected keys instead of through them (for noisy "
        "or roughly blocked keys; select them in the Graph Editor or Dope Sheet as for Smooth Keys, "
        "new keys are selected). Unselected keys, and the first and last key of an open motion, "
        "are hit exactly",
    )
    stiffness: FloatProperty(
        name="Stiffness",
        default=1.0,
        min=0.0,
        soft_max=100.0,
        description="Feature Points, Approximate Keys: how hard the selected keys pull the motion "
        "(spring lambda of variational subdivision). Small is smoother and strays further from the "
        "keys; large comes close to hitting them",
    )
    scheme: EnumProperty(
        name="Scheme",
        items=bake.SCHEMES,
        default="four_point",
        description="Subdivision scheme that refines the key poses into the smooth motion",
    )
    levels: IntProperty(
        name="Levels",
        default=4,
        min=0,
        max=10,
        soft_max=7,
        description="Subdivision levels: each one doubles the number of poses between two keys "
        "(4 is smooth to the eye; 0 gives the plain screw between keys)",
    )
    timing: EnumProperty(
        name="Timing",
        items=bake.TIMINGS,
        default="keys",
        description="How time runs between keys at uneven frames",
    )
    turns: EnumProperty(
        name="Turns",
        items=intent.TURNS,
        default="AUTO",
        description="Where Blender's playback of the keys turns the long way round: Auto keeps the "
        "spins you typed (a key value beyond -180..180 degrees, 0 to 270, 0/360/720) and takes flips "
        "the short way (Euler wraps of keys set from matrices: both keys inside -180..180 and the same "
        "rotation, 360 degrees off or the twin Euler triple, at least 45 degrees closer; quaternion "
        "keys of opposite sign), and reports them; As Blender Plays follows every span as Blender "
        "plays it; Shortest takes the short screw between every two key poses",
    )
    closed: EnumProperty(
        name="Cycle",
        items=bake.CLOSED_MODES,
        default="AUTO",
        description="Whether the keys form a cycle",
    )
    range_mode: EnumProperty(
        name="Frame Range",
        items=bake.RANGE_MODES,
        default="KEYS",
        description="Which frames get baked keys",
    )
    frame_start: FloatProperty(
        name="Start", default=1.0, description="First baked frame (Custom frame range)"
    )
    frame_end: FloatProperty(
        name="End", default=250.0, description="Last baked frame (Custom frame range)"
    )
    step: FloatProperty(
        name="Step",
        default=1.0,
        min=0.01,
        soft_max=10.0,
        description="Frames between two baked keys: 1 bakes every frame, less bakes subframes "
        "(for motion blur). Baked keys sit on multiples of the step, plus the first and last frame",
    )
    armature: EnumProperty(
        name="Armatures",
        items=owners.ARMATURE_MODES,
        default="BOTH",
        description="Object Mode, selected armatures: smooth their keyed bones (hidden bones only when "
        "selected), the armature object's own keys, or both. In Pose Mode the selected bones are smoothed",
    )
    smooth_result: BoolProperty(
        name="Smooth Result",
        default=False,
        description="On an object whose action is already a result of Smooth Motion, smooth that "
        "result itself (Revert then returns to it). Off: smooth the original keys again with these "
        "options, replacing the earlier result (one Revert returns to the original); a result edited "
        "since it was made (keys moved, added or deleted) is smoothed as it is and kept, never deleted",
    )
    key_mode: EnumProperty(
        name="Keys",
        items=reduce.KEY_MODES,
        default="EVERY_STEP",
        description="Every Step: one key per baked frame. Reduced: the fewest Bezier keys within the tolerance "
        "(editable keys), in the same operator",
    )
    key_distance: reduce_ops.distance_property()
    key_angle: reduce_ops.angle_property()

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        draw_options(layout, self)

    def smooth_options(self, context: bpy.types.Context) -> bake.Options:
        """The add-on's options from this operator's properties."""
        return bake.options_from(self, context.scene)

    def execute(self, context: bpy.types.Context) -> set[str]:
        selection = owners.selection(context, self.armature, channels.object_fcurves)
        options = self.smooth_options(context)
        # bake.smooth counts its own steps (two per action): the bar shows their fraction
        return pipeline.run(
            self, "Smooth Motion", lambda progress: bake.smooth(selection, options, progress),
            lambda result: report_smoothed(self, result, "Smoothed"), context,
        )


class SCREWBENDER_OT_revert(bpy.types.Operator):
    """Give the selected objects back the action they had before Smooth Motion"""

    bl_idname = "screwbender.revert"
    bl_label = "Revert Smoothing"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if not any(bake.source_of(obj) is not None for obj in context.selected_objects):
            cls.poll_message_set("No selected object has an action made by Smooth Motion")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        def work(progress: pipeline.Progress) -> tuple[list[bpy.types.Object], list[str]]:
            with transaction.atomic() as t:
                return bake.revert(sorted(context.selected_objects, key=lambda o: o.name), t)

        return pipeline.run(self, "Revert Smoothing", work, lambda done: self.report_reverted(context, *done))

    def report_reverted(self, context: bpy.types.Context, reverted: list, kept: list[str]) -> set[str]:
        selected = {o.name for o in context.selected_objects}
        names = {o.name for o in reverted}
        others = sorted(names - selected)
        also = f" (and {bake.summary(others)}, which shared its action)" if others else ""
        self.report({"INFO"}, f"Restored the original action of {bake.summary(sorted(names & selected))}{also}")
        if kept:
            self.report({"INFO"}, f"kept the edited result {bake.summary(kept)} (fake user): it was edited after it was made")
        return {"FINISHED"}


_OPTION_NAMES = (
    "method", "parametrization", "approximate", "stiffness",
    "scheme", "levels", "timing", "closed", "range_mode", "frame_start", "frame_end", "step",
    "armature", "smooth_result", "turns", "key_mode", "key_distance", "key_angle",
)


def _same_property(name: str):
    """A scene setting with the same name, default and tooltip as the operator's property."""
    prop = SCREWBENDER_OT_smooth.__annotations__[name]
    return prop.function(**prop.keywords)


class ScrewBenderSettings(bpy.types.PropertyGroup):
    """The panel's Smooth Motion options, stored in the scene."""

    method: _same_property("method")
    parametrization: _same_property("parametrization")
    approximate: _same_property("approximate")
    stiffness: _same_property("stiffness")
    scheme: _same_property("scheme")
    levels: _same_property("levels")
    timing: _same_property("timing")
    closed: _same_property("closed")
    range_mode: _same_property("range_mode")
    frame_start: _same_property("frame_start")
    frame_end: _same_property("frame_end")
    step: _same_property("step")
    armature: _same_property("armature")
    smooth_result: _same_property("smooth_result")
    turns: _same_property("turns")
    key_mode: _same_property("key_mode")
    key_distance: _same_property("key_distance")
    key_angle: _same_property("key_angle")


class _SmoothPanel:
    bl_label = "ScrewBender"

    def draw(self, context: bpy.types.Context) -> None:
        settings = context.scene.screwbender
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        draw_options(layout, settings)
        op = layout.operator(SCREWBENDER_OT_smooth.bl_idname, icon="IPO_EASE_IN_OUT")
        for name in _OPTION_NAMES:
            setattr(op, name, getattr(settings, name))
        layout.operator(SCREWBENDER_OT_revert.bl_idname, icon="LOOP_BACK")


class VIEW3D_PT_screwbender(_SmoothPanel, panels.View3DSidebar, bpy.types.Panel):
    """Smooth Motion in the 3D Viewport sidebar, Animation tab."""


class GRAPH_PT_screwbender(_SmoothPanel, panels.GraphSidebar, bpy.types.Panel):
    """Smooth Motion in the Graph Editor sidebar."""


def menu_func(self, context: bpy.types.Context) -> None:
    """Object > Animation menu entries."""
    self.layout.separator()
    self.layout.operator(SCREWBENDER_OT_smooth.bl_idname)
    self.layout.operator(SCREWBENDER_OT_revert.bl_idname)


classes = (SCREWBENDER_OT_smooth, SCREWBENDER_OT_revert, ScrewBenderSettings, VIEW3D_PT_screwbender, GRAPH_PT_screwbender)


def register_properties() -> None:
    bpy.types.Scene.screwbender = PointerProperty(type=ScrewBenderSettings)
    bpy.types.VIEW3D_MT_object_animation.append(menu_func)


def unregister_properties() -> None:
    bpy.types.VIEW3D_MT_object_animation.remove(menu_func)
    del bpy.types.Scene.screwbender
