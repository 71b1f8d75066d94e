# SPDX-License-Identifier: GPL-3.0-or-later
"""The pure layer: what to read, what the animator meant, which frames to bake, what to report.

numpy and ``polyscrew`` only, never ``bpy`` (``tests/python/test_pure_layer.py`` imports every
module here with ``bpy`` blocked); tested in ``tests/python`` without Blender.
"""
