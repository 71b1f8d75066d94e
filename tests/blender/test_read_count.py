"""The read counter itself: it sees the add-on's reads, and no module reads around it."""

from __future__ import annotations

import re
from pathlib import Path

import bpy
import numpy as np

from conftest import addon_module
from read_count import counting_reads, read_more_than_once

ADDON = Path(__file__).resolve().parents[2] / "addon" / "screwbender"


def test_no_module_reads_or_writes_around_bulk():
    direct = re.compile(r"^\s*[\w.\[\]]+\.foreach_(get|set)\(", re.M)
    offenders = [p.name for p in ADDON.glob("*.py") if p.name != "bulk.py" and direct.search(p.read_text())]
    assert offenders == []


def test_counter_counts_reads_per_curve_and_property():
    ob = bpy.data.objects.new("Counted", None)
    bpy.context.scene.collection.objects.link(ob)
    for frame in (1, 5, 9):
        ob.location = (frame, 0, 0)
        ob.keyframe_insert("location", frame=frame)
    bulk = addon_module("blender.bulk")
    fc = addon_module("blender.channels").object_fcurves(ob)[0]
    co = np.empty(6, dtype=np.float32)
    with counting_reads() as reads:
        bulk.get(fc.keyframe_points, "co", co)
        bulk.get(fc.keyframe_points, "co", co)
        bulk.get(fc.keyframe_points, "interpolation", np.empty(3, dtype=np.int32))
    assert co[::2].tolist() == [1, 5, 9]
    assert reads[(ob.animation_data.action.name, "location", fc.array_index, "co")] == 2
    assert read_more_than_once(reads) == {(ob.animation_data.action.name, "location", fc.array_index, "co"): 2}
    # Outside the block the counter is gone: the add-on's own function is back.
    bulk.get(fc.keyframe_points, "co", co)
    assert reads[(ob.animation_data.action.name, "location", fc.array_index, "co")] == 2
