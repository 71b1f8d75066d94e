"""Insert Key on Motion and Build Swept Region make their polyscrew calls for all owners
together (issue 27): Insert Key every owner's new rotation values in one
`rotation_channels_each` call per rotation mode and every owner's comparison in one
`turn_vectors` call; Build Swept Region every object's rotation matrices in one
`rotation_matrices` call per rotation mode (the sweep of each body stays its own). Counted
(6 and 24 owners make the same calls) and compared with the former per-owner calls (keys,
values, reports and meshes the same to the bit), not timed (speed: scripts/bench/profile_floor.py).
"""

from __future__ import annotations

import types

import bpy
import numpy as np
import polyscrew
import pytest

import bake_helpers as h
import bone_helpers as bh
from conftest import addon_module
from test_insert_batch import BONES, rig
from test_read_once_more import keys_of
from test_smooth_batch import varied_scene
from test_speed_smooth import keyed

MODES = ("XYZ", "QUATERNION", "AXIS_ANGLE")


def counting_every_call(monkeypatch) -> dict[str, int]:
    """Wraps every function of the polyscrew module (the module object the add-on imports)
    to count its calls by name."""
    calls: dict[str, int] = {}
    for name in dir(polyscrew):
        original = getattr(polyscrew, name)
        if not isinstance(original, types.BuiltinFunctionType):
            continue

        def counted(*args, _name=name, _original=original, **kwargs):
            calls[_name] = calls.get(_name, 0) + 1
            return _original(*args, **kwargs)

        monkeypatch.setattr(polyscrew, name, counted)
    return calls


def insert_calls(monkeypatch, n: int) -> dict[str, int]:
    objects = [keyed(f"Calls{n}_{i}", seed=i, mode=MODES[i % 3], scale=i % 2 == 0) for i in range(n)]
    bpy.context.scene.frame_set(9)
    h.select_only(*objects)
    with monkeypatch.context() as m:
        calls = counting_every_call(m)
        assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
    assert all(np.any(h.curve_points(fc)[:, 0] == 9.0) for o in objects for fc in h.fcurves(o))
    return calls


def test_six_and_twenty_four_objects_make_the_same_insert_key_calls(monkeypatch):
    """Insert Key on 6, then 24 objects in three rotation modes: the same polyscrew calls, one
    `rotation_channels_each` per mode and one `turn_vectors` (before: one `rotation_channels`
    and one `turn_vectors` per object, 6 then 24)."""
    six = insert_calls(monkeypatch, 6)
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    twenty_four = insert_calls(monkeypatch, 24)
    print(f"Insert Key on Motion, 6 objects: {six}; 24 objects: {twenty_four}")
    assert six == twenty_four
    assert six["rotation_channels_each"] == 3 and six["turn_vectors"] == 1
    assert "rotation_channels" not in six


def per_owner_calls(monkeypatch, ik) -> None:
    """The former arithmetic: one `rotation_channels(pose, mode, previous=...)` call per
    owner, one `turn_vectors` call per owner."""
    rotation_channels, turn_vectors = polyscrew.rotation_channels, polyscrew.turn_vectors

    def each(rotations, mode, previous):
        rows = [rotation_channels(rotations[i : i + 1], mode, previous=previous[i])[0] for i in range(len(rotations))]
        return np.array(rows, dtype=np.float64)

    def changes(pairs):
        return [(np.linalg.norm(b[:, :3, 3] - a[:, :3, 3], axis=1), np.linalg.norm(turn_vectors(a, b), axis=1))
                for a, b in pairs]

    monkeypatch.setattr(polyscrew, "rotation_channels_each", each)
    monkeypatch.setattr(ik, "pose_changes", changes)


@pytest.mark.parametrize(("timing", "frame"), [("keys", 13.5), ("smooth", 11.0), ("linear", 7.25)])
def test_insert_key_keys_values_and_reports_are_the_per_owner_ones(monkeypatch, timing, frame):
    """The same varied scene (every kind of rotation mode, scale, a hold, a cycle, linked
    duplicates) and rig twice, keyed by the operator: batched, and with the former per-owner
    `rotation_channels` and `turn_vectors` calls. Every curve's keys and handles, every
    owner's keyed values and facts, and the operator's reports are the same to the bit."""
    ik = addon_module("blender.insert_key")
    operator = addon_module("ops.preview_ops").SCREWBENDER_OT_insert_key
    report_inserted = operator.report_inserted
    found = {}
    for way in ("batched", "per owner"):
        told: list = []

        def recording(self, scene, at, results, errors, _told=told):
            fake = types.SimpleNamespace(report=lambda kind, message: _told.append((set(kind), message)))
            report_inserted(fake, scene, at, results, errors)
            _told.append([(o.name, r.values, r.max_translation, r.max_angle, r.worst_frame) for o, r in results])
            return report_inserted(self, scene, at, results, errors)

        with monkeypatch.context() as m:
            m.setattr(operator, "report_inserted", recording)
            if way == "per owner":
                per_owner_calls(m, ik)
            bpy.context.scene.frame_set(int(frame), subframe=frame - int(frame))
            objects = varied_scene(f"{way}{frame}")
            h.select_only(*objects)
            assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
            armature = rig(f"Rig{way}{frame}")
            h.select_only(armature)
            bpy.ops.object.mode_set(mode="POSE")
            bh.select_bones(armature, list(BONES))
            try:
                assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
            finally:
                bpy.ops.object.mode_set(mode="OBJECT")
        found[way] = ([keys_of(o) for o in objects + [armature]], told)
    (keys_b, told_b), (keys_p, told_p) = found["batched"], found["per owner"]
    for batched, alone in zip(keys_b, keys_p):
        assert batched.keys() == alone.keys()
        for name in batched:
            assert all(a.tobytes() == b.tobytes() for a, b in zip(batched[name], alone[name])), name
    messages = [[x for x in told if isinstance(x, tuple)] for told in (told_b, told_p)]
    assert len(messages[0]) == len(objects) + len(BONES)
    assert [m.replace("batched", "") for _, m in messages[0]] == [m.replace("per owner", "") for _, m in messages[1]]
    facts = [[x for x in told if isinstance(x, list)] for told in (told_b, told_p)]
    for run_b, run_p in zip(*facts):
        for (name, values, *rest), (name_p, values_p, *rest_p) in zip(run_b, run_p):
            assert name.replace("batched", "") == name_p.replace("per owner", "") and rest == rest_p
            assert values.keys() == values_p.keys()
            assert all(values[p].tobytes() == values_p[p].tobytes() for p in values), name
    print(f"timing {timing}, frame {frame}: {len(messages[0])} reports the same, e.g. {messages[0][0][1]}")


def swept_scene(count: int, tag: str) -> list:
    """`count` meshes keyed in three rotation modes (every other one at a static scale), every
    third parented to the one before (its world matrix composed from both)."""
    objects = [keyed(f"Swept{tag}{i}", seed=40 + i, mode=MODES[i % 3]) for i in range(count)]
    for i in range(0, count, 2):
        objects[i].scale = (1.5, 1.5, 1.5)  # a static scale: a rigid motion still
    for i in range(2, count, 3):
        objects[i].parent = objects[i - 1]
    return objects


def test_six_and_twenty_four_objects_make_the_same_swept_calls(monkeypatch):
    """Build Swept Region (the open sweep: these bodies are open meshes) on 6, then 24 objects
    in three rotation modes (some parented): besides the one `sweep` per object, the same polyscrew calls; one `rotation_matrices` per
    rotation mode (before: one per object, and one more per parent)."""
    got = {}
    for n in (6, 24):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        objects = swept_scene(n, str(n))
        h.select_only(*objects)
        with monkeypatch.context() as m:
            calls = counting_every_call(m)
            assert bpy.ops.screwbender.sweep(closed=False) == {"FINISHED"}
        assert calls.pop("sweep") == n
        got[n] = calls
    print(f"Build Swept Region, 6 objects: {got[6]}; 24 objects: {got[24]}")
    assert got[6] == got[24]
    assert got[6]["rotation_matrices"] == 3


def test_swept_meshes_are_the_per_owner_ones(monkeypatch):
    """A scene of meshes in three rotation modes, some parented, and a box carried by a
    bone (the rig's object and two bones in its chain): Build Swept Region's meshes (vertices and triangles) and poses are the same to the
    bit when every owner's matrices come from its own `rotation_matrices` call (the former
    way: `_Evaluated.bases` made nothing)."""
    from test_bone_sweep import rig_with_prop

    swept = addon_module("blender.swept")
    objects = swept_scene(7, "S")
    _, prop = rig_with_prop()
    objects.append(prop)
    found = {}
    for way in ("batched", "per owner"):
        with monkeypatch.context() as m:
            calls = counting_every_call(m)
            if way == "per owner":
                m.setattr(swept._Evaluated, "bases", lambda self, owners: None)
            computed = swept.compute_all(objects, bpy.context, 2, True)
        found[way] = [(s.vertices.tobytes(), s.triangles.tobytes(), s.poses.tobytes()) for s in computed]
        print(f"{way}: {calls.get('rotation_matrices')} rotation_matrices calls")
        # per owner: 8 meshes, the armature, Arm, and Hand twice (`pose` asked for its basis twice)
        assert calls["rotation_matrices"] == (3 if way == "batched" else 12)
    assert found["batched"] == found["per owner"]
