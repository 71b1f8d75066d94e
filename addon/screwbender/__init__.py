# SPDX-License-Identifier: GPL-3.0-or-later
"""ScrewBender: smooth an object's keyed motion into a coordinate-free screw motion.

Three layers, one folder each (an arrow is "may import"), after glTF-Blender-IO's ``io/`` and
``blender/``:

- :mod:`.ops` (operators, settings, panels, menus, the preview's drawing) -> :mod:`.blender`
  and :mod:`.pure`: collect options, run the Blender layer, report; every writing operator
  through :func:`.ops.pipeline.run` (one way of running and reporting).
- :mod:`.blender` (bpy: every ``foreach_get``/``foreach_set`` through :mod:`.blender.bulk`, the
  action APIs in :mod:`.blender.channels`, :mod:`.blender.owners`, the all-or-nothing
  :mod:`.blender.transaction`, per feature the reading and writing) -> :mod:`.pure`.
- :mod:`.pure` (numpy and ``polyscrew``, never bpy: plans, intent, timing, grids, reports),
  tested in ``tests/python`` without Blender.

The features: Smooth Motion and Revert (``blender/bake.py``, ``ops/bake_ops.py``), the live
preview and Insert Key on Motion (``blender/preview.py``, ``blender/insert_key.py``,
``ops/preview_ops.py``, ``ops/preview_draw.py``), swept regions (``blender/swept.py``,
``ops/swept_ops.py``), angular-velocity editing (``blender/angvel.py``, ``ops/angvel_ops.py``),
Remove Noise (``blender/denoise.py``, ``ops/denoise_ops.py``) and Reduce Keys
(``blender/reduce.py``, ``ops/reduce_ops.py``).
"""

from __future__ import annotations

import bpy

from .ops import angvel_ops, bake_ops, denoise_ops, preview_ops, reduce_ops, swept_ops

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
