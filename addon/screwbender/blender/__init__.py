# SPDX-License-Identifier: GPL-3.0-or-later
"""The Blender layer: data in and out of Blender.

Every ``foreach_get``/``foreach_set`` (through :mod:`.bulk`), the action APIs of each Blender
version (:mod:`.channels`), transform owners (:mod:`.owners`), the all-or-nothing journal
(:mod:`.transaction`), and per feature the reading and writing around the pure layer's
computation.
"""
