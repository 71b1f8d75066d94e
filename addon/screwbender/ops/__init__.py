# SPDX-License-Identifier: GPL-3.0-or-later
"""Operators, settings, panels, menu entries and the preview's viewport drawing, on top of the
Blender layer: collect options, run the Blender layer's pipeline, report."""
