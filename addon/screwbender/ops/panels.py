# SPDX-License-Identifier: GPL-3.0-or-later
"""What the add-on's sidebar panels share: where they sit (mixins that set the space, region
and tab) and the panel that only shows its operators. A panel is `class X(mixins...,
bpy.types.Panel)` with its `bl_label` and what it shows."""

from __future__ import annotations

import bpy


class View3DSidebar:
    """A panel in the 3D Viewport sidebar, Animation tab."""

    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Animation"


class GraphSidebar:
    """A panel in the Graph Editor sidebar, ScrewBender tab."""

    bl_space_type = "GRAPH_EDITOR"
    bl_region_type = "UI"
    bl_category = "ScrewBender"


class OperatorsPanel:
    """A panel that shows operators (`panel_operators`: (`bl_idname`, icon) pairs, in order)
    and a line of hint below them (none where `panel_hint` is empty)."""

    panel_operators: tuple[tuple[str, str], ...] = ()
    panel_hint = ""

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        for idname, icon in self.panel_operators:
            layout.operator(idname, icon=icon)
        if self.panel_hint:
            layout.label(text=self.panel_hint)


def operator_panels(module: str, name: str, label: str, operator: str, icon: str, hint: str) -> tuple[type, type]:
    """The two panels of one operator (`bl_idname` `operator`, shown with `icon`), made in
    `module`: `VIEW3D_PT_screwbender_<name>` in the 3D Viewport sidebar, labelled
    "ScrewBender <label>", with the line `hint` below the button, and
    `GRAPH_PT_screwbender_<name>` in the Graph Editor sidebar, labelled `label`."""
    shown = ((operator, icon),)
    view3d = type(
        f"VIEW3D_PT_screwbender_{name}",
        (OperatorsPanel, View3DSidebar, bpy.types.Panel),
        {
            "__doc__": f"{label} in the 3D Viewport sidebar, Animation tab.",
            "__module__": module,
            "bl_label": f"ScrewBender {label}",
            "panel_operators": shown,
            "panel_hint": hint,
        },
    )
    graph = type(
        f"GRAPH_PT_screwbender_{name}",
        (OperatorsPanel, GraphSidebar, bpy.types.Panel),
        {"__doc__": f"{label} in the Graph Editor sidebar.", "__module__": module, "bl_label": label, "panel_operators": shown},
    )
    return view3d, graph
