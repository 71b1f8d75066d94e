"""Smooth Motion measures every owner's departure from Blender's playback in one polyscrew
call (issue 27: `intent.departures`, `polyscrew.measure_departures`), whatever the number of
owners, and reports and writes what the owner-by-owner measure did, to the character.
"""

from __future__ import annotations

import bpy
import polyscrew
import pytest

import bake_helpers as h
from conftest import addon_module
from test_smooth_batch import counting_calls, result_digests, smooth_varied_scene
from test_speed_smooth import keyed


def counting_departures(monkeypatch):
    """Counts the add-on's departure measures: `polyscrew.measure_departures` (the batch) and
    `intent.departure` (the add-on's only caller of `Playback.measure_departure`, one owner:
    a pyo3 method cannot be wrapped itself). Returns what gives the counts so far."""
    batch = counting_calls(monkeypatch, ("measure_departures",))
    alone = counting_calls(monkeypatch, ("departure",), addon_module("pure.intent"))
    return lambda: batch | alone


def test_six_and_twenty_four_objects_make_the_same_departure_calls(monkeypatch):
    """The departure measure costs one polyscrew call per Smooth Motion, not one per owner
    (owner by owner, 6 objects made 6 calls and 24 made 24)."""
    made = {}
    for count in (6, 24):
        objects = [keyed(f"Dep{count}_{i}", seed=i, mode=("XYZ", "QUATERNION", "AXIS_ANGLE")[i % 3]) for i in range(count)]
        h.select_only(*objects)
        calls = counting_departures(monkeypatch)
        assert bpy.ops.screwbender.smooth(scheme="jarek") == {"FINISHED"}
        assert all(o.animation_data.action.name.endswith(".smooth") for o in objects)
        made[count] = calls()
        monkeypatch.undo()
    print(f"departure calls: {made}")
    assert made[6] == made[24] == {"measure_departures": 1, "departure": 0}


def reports(capfd) -> list[str]:
    return [line for line in capfd.readouterr().out.splitlines() if line.split(":")[0] in ("Info", "Warning", "Error", "ScrewBender")]


@pytest.mark.parametrize("scheme", ["four_point", "jarek"])
def test_batched_departures_report_and_write_what_each_owner_alone_did(monkeypatch, capfd, scheme):
    """The varied scene of test_smooth_batch twice: with the batch, and with
    `polyscrew.measure_departures` refusing (so `intent.departures` measures every owner
    alone, as before the batch): the same report lines (with the scenes' suffix taken out)
    and the same written keys; some owners depart (their lines are in the report)."""
    intent = addon_module("pure.intent")
    got = {}
    for way in ("batched", "alone"):
        capfd.readouterr()
        alone = []
        if way == "alone":
            def refuse(*args, **kwargs):
                raise ValueError("measure_departures: refused (the test)")

            original = intent.departure

            def counted(*args, **kwargs):
                alone.append(1)
                return original(*args, **kwargs)

            monkeypatch.setattr(polyscrew, "measure_departures", refuse)
            monkeypatch.setattr(intent, "departure", counted)
        owners = smooth_varied_scene(way, gentle=False, scheme=scheme)
        got[way] = ([line.replace(way, "") for line in reports(capfd)], result_digests(owners))
        if way == "alone":
            assert len(alone) == len(owners) - 2 + 3  # (every owner alone: the twins share one action, 3 bones)
            monkeypatch.undo()
    assert got["batched"] == got["alone"]
    departs = [line for line in got["batched"][0] if "departs from what Blender played" in line]
    print(f"scheme {scheme}: {len(got['alone'][1])} results identical; {len(departs)} departure lines")
    if scheme == "jarek":
        assert departs
