"""Issue 25 item 1: one way for every writing operator (`ops/pipeline.py`).

Every writing operator (Smooth Motion, Revert, Remove Noise, Reduce Keys, Insert Key on Motion,
Build Swept Region, Check Clearance, Add Angular Velocity Sketch, Fit Angular Velocity, Apply
Preview) runs its work through `pipeline.run` once per run (counted around real runs), and the
pipeline's reports are the one kind: a refusal is the animator's message with nothing
changed, an unexpected failure inside the work is undone and reported as a failure.
"""

from __future__ import annotations

import math

import bpy
import numpy as np
import pytest

import bake_helpers as h
from conftest import addon_module

pipeline = addon_module("ops.pipeline")


@pytest.fixture
def runs(monkeypatch):
    """The `what` of every `pipeline.run` call, in order."""
    seen: list[str] = []
    real = pipeline.run

    def counted(operator, what, *args, **kwargs):
        seen.append(what)
        return real(operator, what, *args, **kwargs)

    monkeypatch.setattr(pipeline, "run", counted)
    return seen


def keyed_cube(name: str = "Body", frames: int = 40) -> bpy.types.Object:
    obj = h.new_object(name)
    t = np.linspace(0.0, 1.0, 5)
    turns = [[[math.cos(2 * s), -math.sin(2 * s), 0], [math.sin(2 * s), math.cos(2 * s), 0], [0, 0, 1]] for s in t]
    poses = h.rigid([(3 * s, math.sin(3 * s), 0.5 * s) for s in t], turns)
    h.key_poses(obj, np.linspace(1, frames, 5), poses)
    return obj


def test_every_writing_operator_runs_through_the_pipeline(runs):
    obj = keyed_cube()
    other = keyed_cube("Other")
    other.location.x += 40.0  # keyed: moved in the scene by a new key below
    other.keyframe_insert("location", frame=1)
    h.select_only(obj)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert bpy.ops.screwbender.reduce_keys() == {"FINISHED"}
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    bpy.context.scene.frame_set(17)
    assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
    assert bpy.ops.screwbender.sweep(steps=2, closed=False) == {"FINISHED"}
    region = bpy.context.view_layer.objects.active
    h.select_only(region, other)
    bpy.context.view_layer.objects.active = region
    assert bpy.ops.screwbender.check_clearance() == {"FINISHED"}
    h.select_only(obj)
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.screwbender.add_angular_velocity_sketch() == {"FINISHED"}
    h.select_only(obj)
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.screwbender.fit_angular_velocity() == {"FINISHED"}
    other.screwbender_preview = True
    h.select_only(other)
    assert bpy.ops.screwbender.preview_apply() == {"FINISHED"}
    other.screwbender_preview = False
    addon_module("ops.preview_draw").sync()
    print("pipeline runs:", runs)
    assert runs == [
        "Smooth Motion", "Revert Smoothing", "Smooth Motion", "Reduce Keys", "Remove Noise", "Insert Key on Motion",
        "Build Swept Region", "Check Clearance", "Add Angular Velocity Sketch", "Fit Angular Velocity",
        "Apply Preview",
    ]


def test_a_refusal_is_the_message_and_nothing_changes(runs):
    still = h.new_object("Still")  # no animation: Smooth Motion refuses it
    h.select_only(still)
    before = h.snapshot_data()
    with pytest.raises(RuntimeError, match="Still: no animation"):
        bpy.ops.screwbender.smooth()
    assert runs == ["Smooth Motion"]
    assert h.snapshot_data() == before


def test_a_failure_inside_the_work_is_undone_and_reported(monkeypatch, runs):
    obj = keyed_cube()
    h.select_only(obj)
    before = h.snapshot_data()
    bake = addon_module("blender.bake")
    real = bake.write

    def fail(*args, **kwargs):
        real(*args, **kwargs)  # the new action is made, then the run fails
        raise OSError("disk on fire")

    monkeypatch.setattr(bake, "write", fail)
    with pytest.raises(RuntimeError, match=r"Smooth Motion failed \(OSError: disk on fire\); nothing was changed"):
        bpy.ops.screwbender.smooth()
    assert runs == ["Smooth Motion"]
    assert h.snapshot_data() == before


def test_owners_grouped_by_action_and_refused_once():
    """`action_groups.by_action`: linked duplicates (one action) are one group, in the order
    given; an owner without an action is refused with `keys.no_action`'s reason."""
    groups_ = addon_module("blender.action_groups")
    a = keyed_cube("A")
    twin = a.copy()  # a linked duplicate: the same action
    bpy.context.scene.collection.objects.link(twin)
    b = keyed_cube("B")
    still = h.new_object("Still")
    found, refused = groups_.by_action([b, a, still, twin])
    assert [(g.action.name, [o.name for o in g.members]) for g in found] == [
        (b.animation_data.action.name, ["B"]), (a.animation_data.action.name, ["A", twin.name]),
    ]
    assert [(o.name, why) for o, why in refused] == [("Still", "Still: no animation (no active action): skipped")]


@pytest.mark.parametrize("operator", ["smooth", "denoise", "reduce_keys"])
def test_smooth_denoise_and_reduce_group_and_write_through_one_driver(monkeypatch, operator):
    """Smooth Motion, Remove Noise and Reduce Keys each group the owners once and write every
    new action in one `write_all` (one transaction): one call each per run, whatever the count
    of owners; the linked duplicate gets the one new action of its group."""
    groups_ = addon_module("blender.action_groups")
    calls = {"by_action": 0, "write_all": 0, "written": 0}
    by_action, write_all = groups_.by_action, groups_.write_all

    def counted_groups(selection):
        calls["by_action"] += 1
        return by_action(selection)

    def counted_write(plans, *args, **kwargs):
        calls["write_all"] += 1
        calls["written"] += len(plans)
        return write_all(plans, *args, **kwargs)

    monkeypatch.setattr(groups_, "by_action", counted_groups)
    monkeypatch.setattr(groups_, "write_all", counted_write)
    a, b = keyed_cube("A"), keyed_cube("B", frames=30)
    twin = a.copy()
    bpy.context.scene.collection.objects.link(twin)
    h.select_only(a, b, twin)
    if operator != "smooth":  # dense keys for Remove Noise and Reduce Keys: a Smooth Motion result
        assert bpy.ops.screwbender.smooth() == {"FINISHED"}
        calls.update(by_action=0, write_all=0, written=0)
    assert getattr(bpy.ops.screwbender, operator)() == {"FINISHED"}
    print(operator, calls)
    assert calls == {"by_action": 1, "write_all": 1, "written": 2}
    assert twin.animation_data.action == a.animation_data.action != b.animation_data.action
