# SPDX-License-Identifier: GPL-3.0-or-later
"""ScrewBender: smooth an object's keyed motion into a coordinate-free screw motion.

One naming rule: ``<feature>.py`` is the logic of a feature (bpy data in, bpy data out, no
operator, panel or property group), ``<feature>_ops.py`` its operators, settings, panels and
menu entries (collect options, call the logic, report), ``<feature>_draw.py`` its viewport
drawing. The features:

- Smooth Motion and Revert: :mod:`bake` + :mod:`bake_ops`; beneath them :mod:`keys`
  (F-curves -> key poses), :mod:`channels` (the action APIs of every Blender version) and
  :mod:`feature` (the Feature Points method).
- Live preview: :mod:`preview` + :mod:`preview_ops` + :mod:`preview_draw`, with
  :mod:`insert_key` (Insert Key on Motion).
- Swept regions and clearance: :mod:`swept` + :mod:`swept_ops`.
- Angular-velocity editing: :mod:`angvel` + :mod:`angvel_ops`.
- Remove Noise (captured keys): :mod:`denoise` + :mod:`denoise_ops`.
- Reduce Keys (dense keys -> the fewest within a world-space tolerance): :mod:`reduce` +
  :mod:`reduce_ops`.
"""

from __future__ import annotations

import bpy

from . import angvel_ops, bake_ops, denoise_ops, preview_ops, reduce_ops, swept_ops

_register_classes, _unregister_classes = bpy.utils.register_classes_factory(
    bake_ops.classes + angvel_ops.classes + swept_ops.classes + preview_ops.classes + denoise_ops.classes
    + reduce_ops.classes
)


def register() -> None:
    _register_classes()
    bake_ops.register_properties()
    preview_ops.register_properties()
    denoise_ops.register_properties()
    reduce_ops.register_properties()


def unregister() -> None:
    reduce_ops.unregister_properties()
    denoise_ops.unregister_properties()
    preview_ops.unregister_properties()
    bake_ops.unregister_properties()
    _unregister_classes()
