# SPDX-License-Identifier: GPL-3.0-or-later
"""ScrewBender: smooth an object's keyed motion into a coordinate-free screw motion.

Modules: :mod:`channels` (legacy and slotted actions), :mod:`keys` (F-curves -> key poses),
:mod:`bake` (polyscrew sampling -> new action, revert), :mod:`operators`, :mod:`ui`.
Live preview: :mod:`preview` (batches, cache), :mod:`preview_draw` (gpu overlay),
:mod:`insert_key`, :mod:`preview_ui` (settings, panel, Apply Preview, Insert Key on Motion).
"""

from __future__ import annotations

import bpy

from . import angvel, operators, preview_ui, ui

_register_classes, _unregister_classes = bpy.utils.register_classes_factory(
    operators.classes + ui.classes + angvel.classes + preview_ui.classes
)


def register() -> None:
    _register_classes()
    ui.register_properties()
    preview_ui.register_properties()


def unregister() -> None:
    preview_ui.unregister_properties()
    ui.unregister_properties()
    _unregister_classes()
