# SPDX-License-Identifier: GPL-3.0-or-later
"""The operators: collect options, call :mod:`bake`, report. No logic of their own."""


import bpy
from bpy.props import EnumProperty, FloatProperty, IntProperty

from . import bake
from .keys import SmoothError

RANGE_MODES = (
    ("KEYS", "Keys", "Bake each object from its first to its last key (a cycle: over one period)"),
    ("SCENE", "Scene", "Bake the scene's frame range"),
    ("CUSTOM", "Custom", "Bake the frame range given by Start and End"),
)


def _report_skipped(operator: bpy.types.Operator, skipped: list[str], level: str) -> None:
    for message in skipped:
        operator.report({level}, message)


class SCREWBENDER_OT_smooth(bpy.types.Operator):
    """Replace the keyed motion of the selected objects by a smooth screw motion through their key poses, baked into a new action (the old one is kept)"""

    bl_idname = "screwbender.smooth"
    bl_label = "Smooth Motion"
    bl_options = {"REGISTER", "UNDO"}

    scheme: EnumProperty(
        name="Scheme",
        items=bake.SCHEMES,
        default="jarek",
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
        default="smooth",
        description="How time runs between keys at uneven frames",
    )
    closed: EnumProperty(
        name="Cycle",
        items=bake.CLOSED_MODES,
        default="AUTO",
        description="Whether the keys form a cycle",
    )
    range_mode: EnumProperty(
        name="Frame Range",
        items=RANGE_MODES,
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
        "(for motion blur)",
    )

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode")
            return False
        if not context.selected_objects:
            cls.poll_message_set("Select one or more keyed objects")
            return False
        return True

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        for name in ("scheme", "levels", "timing", "closed", "range_mode"):
            layout.prop(self, name)
        if self.range_mode == "CUSTOM":
            col = layout.column(align=True)
            col.prop(self, "frame_start")
            col.prop(self, "frame_end")
        layout.prop(self, "step")

    def smooth_options(self, context: bpy.types.Context) -> bake.Options:
        """The add-on's options from this operator's properties."""
        if self.range_mode == "SCENE":
            frame_range = (float(context.scene.frame_start), float(context.scene.frame_end))
        elif self.range_mode == "CUSTOM":
            frame_range = (self.frame_start, self.frame_end)
        else:
            frame_range = None
        return bake.Options(
            scheme=self.scheme,
            levels=self.levels,
            timing=self.timing,
            closed=self.closed,
            frame_range=frame_range,
            step=self.step,
        )

    def execute(self, context: bpy.types.Context) -> set[str]:
        objects = sorted(context.selected_objects, key=lambda o: o.name)
        wm = context.window_manager
        wm.progress_begin(0, 2 * len(objects))
        try:
            actions, skipped = bake.smooth(
                objects, self.smooth_options(context), lambda done, _total: wm.progress_update(done)
            )
        except SmoothError as err:
            self.report({"ERROR"}, str(err))
            return {"CANCELLED"}
        finally:
            wm.progress_end()
        if not actions:
            _report_skipped(self, skipped, "ERROR")
            return {"CANCELLED"}
        _report_skipped(self, skipped, "WARNING")
        names = ", ".join(a.name for a in actions)
        self.report({"INFO"}, f"Smoothed {len(actions)} object(s) into {names}")
        return {"FINISHED"}


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
        reverted = []
        for obj in context.selected_objects:
            if bake.source_of(obj) is not None:
                bake.revert(obj)
                reverted.append(obj.name)
        self.report({"INFO"}, f"Restored the original action of {', '.join(sorted(reverted))}")
        return {"FINISHED"}


classes = (SCREWBENDER_OT_smooth, SCREWBENDER_OT_revert)
