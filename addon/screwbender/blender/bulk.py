# SPDX-License-Identifier: GPL-3.0-or-later
"""Every bulk read and write of Blender data, in one place: `foreach_get` and `foreach_set`.

The add-on reads keys, vertices and matrices and writes keys and meshes only through
:func:`get` and :func:`put` (no other module calls `foreach_get` / `foreach_set`), so there is
one place to see, count or change how Blender data crosses into numpy: tests wrap these two
functions to check that an operator reads each curve's keys once per run.
"""

from __future__ import annotations


def get(collection, attr: str, out) -> None:
    """`collection.foreach_get(attr, out)`: fills `out` (a flat numpy array or list of the
    collection's length times the property's width)."""
    collection.foreach_get(attr, out)


def put(collection, attr: str, values) -> None:
    """`collection.foreach_set(attr, values)`: one property of every item at once."""
    collection.foreach_set(attr, values)
