"""Issue 25 item 1: one way for every writing operator (`ops/pipeline.py`).

Smooth Motion, Revert, Remove Noise, Reduce Keys, Build Swept Region and Fit Angular Velocity
each run their work through `pipeline.run` once per run (counted around real runs), and the
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
    h.select_only(obj)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert bpy.ops.screwbender.reduce_keys() == {"FINISHED"}
    assert bpy.ops.screwbender.denoise() == {"FINISHED"}
    assert bpy.ops.screwbender.sweep(steps=2) == {"FINISHED"}
    h.select_only(obj)
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.screwbender.add_angular_velocity_sketch() == {"FINISHED"}
    h.select_only(obj)
    bpy.context.view_layer.objects.active = obj
    assert bpy.ops.screwbender.fit_angular_velocity() == {"FINISHED"}
    print("pipeline runs:", runs)
    assert runs == [
        "Smooth Motion", "Revert Smoothing", "Smooth Motion", "Reduce Keys", "Remove Noise",
        "Build Swept Region", "Fit Angular Velocity",
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
