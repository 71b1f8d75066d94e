# SPDX-License-Identifier: GPL-3.0-or-later
"""Panels and menu entries. They only draw."""


import bpy
from bpy.props import PointerProperty

from .operators import SCREWBENDER_OT_revert, SCREWBENDER_OT_smooth, draw_method

_OPTION_NAMES = (
    "method", "parametrization", "approximate", "stiffness",
    "scheme", "levels", "timing", "closed", "range_mode", "frame_start", "frame_end", "step",
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


class _SmoothPanel:
    bl_label = "ScrewBender"
    bl_region_type = "UI"

    def draw(self, context: bpy.types.Context) -> None:
        settings = context.scene.screwbender
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False
        draw_method(layout, settings)
        for name in ("scheme", "levels", "timing", "closed", "range_mode"):
            layout.prop(settings, name)
        if settings.range_mode == "CUSTOM":
            col = layout.column(align=True)
            col.prop(settings, "frame_start")
            col.prop(settings, "frame_end")
        layout.prop(settings, "step")
        op = layout.operator(SCREWBENDER_OT_smooth.bl_idname, icon="IPO_EASE_IN_OUT")
        for name in _OPTION_NAMES:
            setattr(op, name, getattr(settings, name))
        layout.operator(SCREWBENDER_OT_revert.bl_idname, icon="LOOP_BACK")


class VIEW3D_PT_screwbender(_SmoothPanel, bpy.types.Panel):
    """Smooth Motion in the 3D Viewport sidebar, Animation tab."""

    bl_space_type = "VIEW_3D"
    bl_category = "Animation"


class GRAPH_PT_screwbender(_SmoothPanel, bpy.types.Panel):
    """Smooth Motion in the Graph Editor sidebar."""

    bl_space_type = "GRAPH_EDITOR"
    bl_category = "ScrewBender"


def menu_func(self, context: bpy.types.Context) -> None:
    """Object > Animation menu entries."""
    self.layout.separator()
    self.layout.operator(SCREWBENDER_OT_smooth.bl_idname)
    self.layout.operator(SCREWBENDER_OT_revert.bl_idname)


classes = (ScrewBenderSettings, VIEW3D_PT_screwbender, GRAPH_PT_screwbender)


def register_properties() -> None:
    bpy.types.Scene.screwbender = PointerProperty(type=ScrewBenderSettings)
    bpy.types.VIEW3D_MT_object_animation.append(menu_func)


def unregister_properties() -> None:
    bpy.types.VIEW3D_MT_object_animation.remove(menu_func)
    del bpy.types.Scene.screwbender
