"""Every owner's keys read in one batched pass (issue 27): `keys.read_many` reads the curves
of every owner in one `curves.read` and one `polyscrew.read_owners` call, and gives, to the
bit, what reading each owner alone gives (`keys._read_alone`: the step-by-step read, one
Playback, channels, rotation_matrices and analyse_turns call per owner): every array field
and every string of each `KeyedMotion`, its source (packed keys, columns, values, what its
playback plays), on a varied scene (objects and bones, connected bones, cycles with and
without offset, modifiers, captures, linked duplicates sharing an action, owners refused
among good ones); the operators that read keys write the same keys as when every owner is
read alone; and the reading makes the same polyscrew calls for 8 owners as for 32.
"""

from __future__ import annotations

import dataclasses

import bpy
import numpy as np
import polyscrew
import pytest

import bake_helpers as h
import bone_helpers as bh
from conftest import addon_module
from test_speed_smooth import keyed


def varied_scene(suffix: str = "") -> list:
    """Objects in every rotation mode (scale keyed on some), a hold, a spin of two turns, an
    Euler wrap, cycles (Repeat; Repeat with Offset), a Noise modifier kept on top, a capture
    (keyed on every key frame), two linked duplicates sharing an action, a rig with a
    connected bone; and owners refused: keys out of time order, one key frame, a keyed scale
    of 0, a curve the add-on cannot play (in a muted group: read from its key values)."""
    made = []
    for i, mode in enumerate(("XYZ", "QUATERNION", "AXIS_ANGLE", "ZXY", "YZX", "XZY", "YXZ", "ZYX")):
        made.append(keyed(f"Var{mode}{suffix}", seed=100 + i, mode=mode, scale=i % 2 == 1))
    held = h.new_object(f"Held{suffix}")
    poses = h.rigid(np.array([[0, 0, 0], [1, 0, 0], [1, 0, 0], [3, 1, 0], [4, 2, 1.0]]), np.stack([np.eye(3)] * 5))
    h.key_poses(held, [1, 5, 12, 16, 22], poses)
    made.append(held)
    spin = h.new_object(f"Spin{suffix}")
    for frame, angle in ((1, 0.0), (11, 6.0), (21, 12.5)):
        spin.rotation_euler = (0.0, 0.0, angle)
        spin.keyframe_insert("rotation_euler", frame=frame)
        spin.location = (angle * 0.1, 0.0, 0.0)
        spin.keyframe_insert("location", frame=frame)
    made.append(spin)
    wrap = h.new_object(f"Wrap{suffix}")
    for frame, angle in ((1, 2.8), (9, -2.9), (17, -2.5)):
        wrap.rotation_euler = (0.2, 0.1, angle)
        wrap.keyframe_insert("rotation_euler", frame=frame)
    made.append(wrap)
    for name, mode in (("Cycle", "REPEAT"), ("Walk", "REPEAT_OFFSET")):
        cycle = keyed(f"{name}{suffix}", seed=7 + len(name))
        for fc in h.fcurves(cycle):
            fc.modifiers.new("CYCLES").mode_after = mode
        made.append(cycle)
    noisy = keyed(f"Noisy{suffix}", seed=31)
    h.fcurves(noisy)[0].modifiers.new("NOISE")
    made.append(noisy)
    take = h.new_object(f"Take{suffix}", mode="QUATERNION")
    rng = np.random.default_rng(3)
    for frame in range(1, 13):
        take.location = rng.normal(size=3)
        take.rotation_quaternion = rng.normal(size=4)
        take.keyframe_insert("location", frame=frame)
        take.keyframe_insert("rotation_quaternion", frame=frame)
    made.append(take)
    twin = keyed(f"Twin{suffix}", seed=8)
    other = twin.copy()  # a linked duplicate: the same action, its own rotation mode's values
    other.name = f"TwinCopy{suffix}"
    other.scale = (2.0, 1.0, 0.5)
    bpy.context.scene.collection.objects.link(other)
    made += [twin, other]
    disordered = keyed(f"Disordered{suffix}", seed=41)
    points = h.fcurves(disordered)[0].keyframe_points
    points[1].co.x, points[2].co.x = points[2].co.x, points[1].co.x  # (no update: out of time order)
    one = h.new_object(f"One{suffix}")
    one.keyframe_insert("location", frame=3)
    flat = keyed(f"Flat{suffix}", seed=43, scale=True)
    for fc in h.fcurves(flat):
        if fc.data_path == "scale":
            fc.keyframe_points[1].co.y = 0.0
    unplayable = keyed(f"Unplayable{suffix}", seed=47)
    _, bag = next(iter(addon_module("blender.channels").containers(unplayable.animation_data.action)))
    muted = bag.groups.new("Muted")
    h.fcurves(unplayable)[1].group = muted
    muted.mute = True  # (Blender does not play the curve: the add-on reads its key values)
    made += [disordered, one, flat, unplayable]
    rig = bh.armature(f"Rig{suffix}")
    for n, bone in enumerate(("Upper", "Fore", "Hand")):
        bh.key_bone(rig, bone, [1, 6, 13, 20], bh.random_poses(4, seed=30 + n, gentle=True),
                    mode=("XYZ", "QUATERNION", "ZXY")[n])
    made.append(rig)
    return made


def dense_scene(suffix: str = "") -> list:
    """Noisy captures (every frame keyed) in four rotation modes, one keyed on every other
    frame in location, linked duplicates, a capture refused (keys out of time order) and a
    rig whose bones are captures (a connected one): what Remove Noise reads."""
    from test_noise_batch import FRAMES_A, noisy_keys

    rng = np.random.default_rng(17)
    made = []
    for mode in ("XYZ", "QUATERNION", "AXIS_ANGLE", "ZXY", "XYZ"):
        ob = h.new_object(f"Dense{mode}{len(made)}{suffix}", mode=mode)
        noisy_keys(ob, FRAMES_A, mode, rng)
        made.append(ob)
    for frame in FRAMES_A[1::2]:
        made[-1].keyframe_delete("location", frame=frame)
    other = made[0].copy()
    other.name = f"DenseCopy{suffix}"
    bpy.context.scene.collection.objects.link(other)
    made.append(other)
    points = h.fcurves(made[1])[0].keyframe_points
    points[1].co.x, points[2].co.x = points[2].co.x, points[1].co.x  # (no update: out of time order)
    rig = bh.armature(f"Rig{suffix}")
    for n, bone in enumerate(("Upper", "Fore", "Hand")):
        poses = bh.random_poses(40, seed=70 + n, gentle=True)
        bh.key_bone(rig, bone, list(range(1, 41)), poses, mode=("XYZ", "QUATERNION", "ZXY")[n])
    made.append(rig)
    return made


def owners_of(objects: list) -> list:
    owners = addon_module("blender.owners")
    out = []
    for obj in objects:
        if obj.type == "ARMATURE":
            out += [owners.Owner(obj, bone.name) for bone in obj.pose.bones]
        else:
            out.append(owners.Owner(obj))
    return out


def same(a, b, where: str) -> None:
    """`a` and `b` equal: arrays to the bit (dtype, shape, bytes), the rest by value."""
    if isinstance(a, np.ndarray) or isinstance(b, np.ndarray):
        a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
        assert a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes(), where
    elif isinstance(a, tuple | list) and a and isinstance(a[0], np.ndarray):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            same(x, y, f"{where}[{i}]")
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"


def same_motion(a, b, name: str) -> None:
    """Every field of two KeyedMotions, their sources to the bit (and what they play)."""
    keyed_ = addon_module("pure.keyed")
    for f in dataclasses.fields(keyed_.KeyedMotion):
        x, y = getattr(a, f.name), getattr(b, f.name)
        where = f"{name}: {f.name}"
        if f.name == "owner":
            assert x.name == y.name, where
        elif f.name == "modifiers":
            assert repr(x) == repr(y), where
        elif f.name == "source":
            assert (x is None) == (y is None), where
            if x is None:
                continue
            for attr in ("columns", "mode", "rotation_path", "located"):
                same(getattr(x, attr), getattr(y, attr), f"{where}.{attr}")
            for path in x.static:
                same(x.static[path], y.static[path], f"{where}.static[{path}]")
            for attr, value in x.packed.arguments().items():
                same(value, getattr(y.packed, attr) if attr != "cycles" else y.packed.arguments()["cycles"],
                     f"{where}.packed.{attr}")
            assert x.playback.rows_evaluated == y.playback.rows_evaluated, f"{where}: rows played"
            for i, (p, q) in enumerate(zip(x.channels(a.frames).values(), y.channels(b.frames).values())):
                same(p, q, f"{where}.channels[{i}]")
        else:
            same(x, y, where)


OPTIONS = [
    dict(),
    dict(closed="ON", turns="BLENDER"),
    dict(closed="OFF", turns="SHORTEST", extend_to=(3.0, 40.0)),
    dict(analyse=False, key_values=True),
    dict(closed="AUTO", turns="AUTO", extend_to=(-30.0, 60.0)),
]


@pytest.mark.parametrize("options", OPTIONS, ids=[str(i) for i in range(len(OPTIONS))])
def test_read_many_is_each_owner_read_alone_to_the_bit(options):
    keys = addon_module("blender.keys")
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    owners = owners_of(varied_scene())
    requests = [keys.Request(o, **options) for o in owners]
    got = keys.read_many(requests, cache={})
    refused, read = [], 0
    for request, batched in zip(requests, got):
        alone = keys._read_alone(keys.Request(request.owner, **options), {})
        name = request.owner.name
        assert type(batched) is type(alone), f"{name}: {batched!r} / {alone!r}"
        if isinstance(alone, keys.SmoothError):
            assert str(batched) == str(alone), name
            refused.append(name)
        else:
            same_motion(batched, alone, name)
            read += 1
    print(f"{options}: {read} owners read the same, refused the same: {refused}")
    assert {"Disordered", "One", "Flat"} <= set(refused) and read >= 20
    # the owner whose curve cannot be played is read from its key values, with the note
    unplayable = got[[o.name for o in owners].index("Unplayable")]
    assert unplayable.source is None and "smoothed from the key values alone" in " ".join(unplayable.kept)


def every_alone(monkeypatch) -> None:
    """Makes `keys.read_many` read every owner alone (the step-by-step read)."""
    keys = addon_module("blender.keys")

    def alone(requests, cache=None):
        cache = {} if cache is None else cache
        return [keys._read_alone(r, cache) for r in requests]

    monkeypatch.setattr(keys, "read_many", alone)


def digests(objects) -> list[str]:
    bake, channels = addon_module("blender.bake"), addon_module("blender.channels")
    out = []
    for obj in objects:
        adt = obj.animation_data
        if adt is not None and adt.action is not None:
            out.append(f"{obj.name[:-1]}:{bake.keys_digest(adt.action, channels.slot_identifier(obj))}")
    return out


@pytest.mark.parametrize("operator", ["smooth", "denoise", "reduce_keys", "insert_key"])
def test_operators_write_the_keys_of_owners_read_alone(monkeypatch, operator):
    """The same varied scene twice (dense captures for Remove Noise): run with the batched
    read, and with every owner read alone: the same keys (digests of every result)."""
    results = {}
    for way in ("batched", "alone"):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        bpy.context.scene.frame_set(9)
        scene = dense_scene if operator == "denoise" else varied_scene
        objects = scene("b" if way == "batched" else "a")
        if way == "alone":
            every_alone(monkeypatch)
        h.select_only(*objects[:-1])
        ran = getattr(bpy.ops.screwbender, operator)()
        assert ran == {"FINISHED"}, (operator, way)
        rig = objects[-1]
        h.select_only(rig)
        bpy.ops.object.mode_set(mode="POSE")
        bh.select_bones(rig, ["Upper", "Fore", "Hand"])
        assert getattr(bpy.ops.screwbender, operator)() == {"FINISHED"}
        bpy.ops.object.mode_set(mode="OBJECT")
        results[way] = digests(objects)
        monkeypatch.undo()
    assert results["batched"] == results["alone"]
    print(f"{operator}: {len(results['alone'])} actions, the same keys")


#: polyscrew's functions the reading of keys calls (per owner before the batch).
READERS = ("read_owners", "Playback", "analyse_turns", "analyse_spans", "rotation_matrices", "turn_vectors",
           "evaluate_fcurves")


def counting(monkeypatch) -> dict[str, int]:
    calls = dict.fromkeys(READERS, 0)
    for name in READERS:
        original = getattr(polyscrew, name)

        def counted(*args, _name=name, _original=original, **kwargs):
            calls[_name] += 1
            return _original(*args, **kwargs)

        monkeypatch.setattr(polyscrew, name, counted)
    return calls


@pytest.mark.parametrize("way", ["batched", "alone"])
def test_reading_makes_as_many_polyscrew_calls_for_32_owners_as_for_8(monkeypatch, way):
    """`keys.read_many` of 8 and of 32 objects (and a rig's bones): one `read_owners` call
    and nothing else per owner; read alone (the former path, forced) the calls grow with the
    owners, which is what the counter must see."""
    keys = addon_module("blender.keys")
    counts = []
    for n in (8, 32):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        objects = [keyed(f"Count{i}", seed=i, mode=("XYZ", "QUATERNION", "AXIS_ANGLE", "ZXY")[i % 4], scale=i % 2 == 0)
                   for i in range(n)]
        rig = bh.armature("CountRig")
        for b, bone in enumerate(("Upper", "Fore", "Hand")):
            bh.key_bone(rig, bone, [1, 6, 13, 20], bh.random_poses(4, seed=60 + b, gentle=True))
        requests = [keys.Request(o) for o in owners_of(objects + [rig])]
        if way == "alone":
            every_alone(monkeypatch)
        calls = counting(monkeypatch)
        got = addon_module("blender.keys").read_many(requests)
        monkeypatch.undo()
        assert all(isinstance(m, keys.KeyedMotion) for m in got)
        counts.append(dict(calls))
    print(f"{way}: 8 objects {counts[0]}, 32 objects {counts[1]}")
    if way == "batched":
        assert counts[0] == counts[1] and counts[0]["read_owners"] == 1 and sum(counts[0].values()) == 1
    else:
        assert counts[1]["Playback"] - counts[0]["Playback"] == 24  # (the counter sees per-owner calls)


@pytest.mark.parametrize("operator", ["smooth", "denoise", "reduce_keys", "insert_key"])
def test_an_operator_reads_many_objects_in_one_polyscrew_call(monkeypatch, operator):
    """Each operator that reads keys makes one `read_owners` call for 6 or for 24 objects (two
    for Insert Key on Motion: before and after keying) and no per-owner Playback."""
    counts = []
    for n in (6, 24):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        bpy.context.scene.frame_set(9)
        objects = [keyed(f"Op{i}", seed=i, mode=("XYZ", "QUATERNION")[i % 2]) for i in range(n)]
        if operator == "denoise":  # (captures: Remove Noise refuses sparse keys)
            from test_noise_batch import FRAMES_A, noisy_keys

            rng = np.random.default_rng(n)
            for i, ob in enumerate(objects):
                ob.animation_data_clear()
                noisy_keys(ob, FRAMES_A, ("XYZ", "QUATERNION")[i % 2], rng)
        h.select_only(*objects)
        calls = counting(monkeypatch)
        assert getattr(bpy.ops.screwbender, operator)() == {"FINISHED"}
        monkeypatch.undo()
        counts.append((calls["read_owners"], calls["Playback"]))
    print(f"{operator}: (read_owners, Playback) 6 objects {counts[0]}, 24 objects {counts[1]}")
    assert counts[0] == counts[1] == ((2 if operator == "insert_key" else 1), 0)
