"""Benchmark: every writing operator against its floor, the Blender calls that no
implementation through Blender's Python API can avoid (issue 27, items 1 and 4).

For the same scenes, in one Blender session, each repetition times (A/B interleaved, wall
clock and the process's CPU time):
  the operator  through `bpy.ops` as a user calls it, every option at its default:
                Smooth Motion, Revert Smoothing, Remove Noise, Reduce Keys, Insert Key on
                Motion, Build Swept Region;
  its floor     only the Blender calls the operator cannot avoid:
                - read every source F-curve of the selected owners once: one `foreach_get` per
                  attribute per curve (`co` and `interpolation`: where the keys are and how
                  Blender plays between them), finding the curves included;
                - create the result: the action, its slot, layer, strip and channelbag where the
                  version has them (4.4+), its F-curves (`fcurves.new`, `keyframe_points.add`),
                  one `foreach_set` per written attribute, and assign the action (and slot);
                  the result's shape (curves and key counts, a swept mesh's vertices, loops and
                  faces) is the one the operator wrote in the same repetition, the values are
                  computed before the clock starts;
                written attributes: Smooth Motion `co`, `interpolation`; Remove Noise `co`,
                `handle_left`, `handle_right`; Reduce Keys those and `interpolation`,
                `handle_left_type`, `handle_right_type`; Insert Key on Motion one
                `keyframe_points.insert(..., options={'FAST'})` per keyed curve (no new action);
                Revert: assigning the previous action (and slot) to each owner; Build Swept
                Region: reading the evaluated mesh (`vertices` `co`, `loop_triangles`
                `vertices`) besides the curves, then a new mesh (`vertices.add`, `loops.add`,
                `polygons.add`, `foreach_set` of `co`, `vertex_index`, `loop_start`), a new
                object linked to the scene;
  Blender's own counterpart where one exists: `nla.bake` (OBJECT, or POSE in Pose Mode with
                every bone selected) for Smooth Motion, `graph.gaussian_smooth` for Remove Noise
                and `graph.decimate` (its defaults) for Reduce Keys, in the Graph Editor
                (`temp_override`), on the same keys and frames.
Before each call every owner gets a fresh copy of its source action (untimed) and everything
the call made is removed afterwards (untimed), so each call starts from the same scene.

Scenes (--quick: a smoke run of seconds with the smallest of each):
  sparse objects  a tetrahedron mesh per object keyed on location, XYZ Euler and (constant)
                  scale: 2 keys over 50 frames (1, 20, 100, 500, 2,000 objects), 10 uneven keys
                  over 250 (100 and 300 objects) and 1,000 frames (100 objects);
  sparse rigs     20, 100, 300 bones (chains of ten) keyed so, 10 keys over 250 frames, and
                  100 bones over 1,000 frames;
  dense objects   location and XYZ Euler keyed on every frame, a slow motion with a little
                  noise (a clean capture): 1, 20, 100, 500, 2,000 objects x 50 frames, 100 x 200;
  dense rigs      every bone's XYZ Euler and the root's location keyed so: 20, 100, 300 bones x
                  250 frames, 30 and 100 bones x 1,000 frames.
Build Swept Region runs on the sparse objects up to 25,000 objects x frames (above 1,000 in the
first run only: 100 objects x 50 and 250 frames), Reduce Keys and graph.decimate on scenes of up to 200,000 keys, and the scenes of 2,000
objects run once: the full run took 31 minutes on the shared 2-core machine at load 15 to 20
(about ten minutes expected on a quiet one, not measured); --case runs chosen scenes.

Each operator's time is given as a multiple of its floor (median over median of the same
run), Smooth Motion and Remove Noise also against Blender's counterpart; the growth
exponent against owners and frames is fitted per operator (bench_report.growth_exponent).
Writes JSON (--out, rendered into BENCHMARKS.md by scripts/bench/bench_report.py) and prints a table.
Run after scripts/build_extension.sh:
    PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench/bench_floor.py [--quick] [--out floor.json]
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "demo"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import demo_common  # noqa: E402

import bench_report  # noqa: E402

demo_common.blender_with_addon()
import bpy  # noqa: E402

from bench_denoise import graph_context as _graph_context  # noqa: E402  (the Graph Editor, headless)

SLOTTED = bpy.app.version >= (4, 4, 0)
READ_ATTRS = (("co", 2, np.float32), ("interpolation", 1, np.uint8))
#: What each operator's result holds per key, written once per attribute by its floor.
WRITE_ATTRS = {
    "smooth": ("co", "interpolation"),
    "denoise": ("co", "handle_left", "handle_right"),
    "reduce": ("co", "handle_left", "handle_right", "interpolation", "handle_left_type", "handle_right_type"),
}
#: Blender's counterpart of an operator (timed on the same keys), where one exists.
COUNTERPART = {"smooth": "nla_bake", "denoise": "gaussian_smooth", "reduce": "decimate"}
#: The operators' bpy.ops names (screwbender.*).
IDNAMES = {"smooth": "smooth", "revert": "revert", "denoise": "denoise", "reduce": "reduce_keys",
           "insert_key": "insert_key", "sweep": "sweep"}
OPERATORS, LABELS = bench_report.FLOOR_OPERATORS, bench_report.FLOOR_LABELS

#: (family, owners, frames, keys): sparse families keyed at `keys` uneven frames, dense ones on every frame.
FULL_CASES = (
    [("objects", n, 50, 2) for n in (1, 20, 100, 500, 2000)]
    + [("objects", 100, 250, 10), ("objects", 300, 250, 10), ("objects", 100, 1000, 10)]
    + [("rig", b, 250, 10) for b in (20, 100, 300)] + [("rig", 100, 1000, 10)]
    + [("dense_objects", n, 50, 0) for n in (1, 20, 100, 500, 2000)] + [("dense_objects", 100, 200, 0)]
    + [("dense_rig", b, 250, 0) for b in (20, 100, 300)] + [("dense_rig", b, 1000, 0) for b in (30, 100)]
)
QUICK_CASES = [("objects", 1, 50, 2), ("objects", 20, 50, 2), ("objects", 20, 100, 2), ("rig", 20, 100, 10),
               ("dense_objects", 1, 50, 0), ("dense_objects", 20, 50, 0), ("dense_rig", 20, 100, 0)]
#: Build Swept Region runs on scenes of up to this many objects x frames, in every run up to
#: SWEEP_EVERY_RUN, above it in the first run only (on a busy 2-core machine its own sweep took
#: about half a second per object over 50 frames, and grows with the frames).
SWEEP_MAX_OBJECT_FRAMES, SWEEP_EVERY_RUN = 25_000, 1_000
#: Reduce Keys and graph.decimate run on scenes of up to this many source keys (decimate takes
#: about 0.1 ms per key; scripts/bench/bench_reduce.py compares the two in full).
REDUCE_MAX_KEYS = 200_000
#: Scenes of this many owners or more run once (the full run stays near ten minutes).
ONE_RUN_OWNERS = 2000


# ------------------------------------------------------------------ scenes


def new_scene(frames: int) -> bpy.types.Scene:
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, frames
    return scene


def key_frames(frames: int, keys: int) -> list[int]:
    return sorted({1 + round(((k / (keys - 1)) ** 1.2) * (frames - 1)) for k in range(keys)})


def set_pose(target, u: float, n: int, scale: float) -> None:
    target.location = (scale * math.cos(4 * u + n), scale * math.sin(3 * u), 0.7 * scale * u + 0.01 * n)
    target.rotation_euler = (0.5 * math.sin(5 * u), 0.3 * u, 6 * u + n)
    target.scale = (1.2, 1.0, 0.8)  # keyed, constant: a rigid motion (Build Swept Region)


def sparse_objects(count: int, frames: int, keys: int) -> list[bpy.types.Object]:
    scene = new_scene(frames)
    mesh = bpy.data.meshes.new("Block")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], [], [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)])
    objects = []
    at = key_frames(frames, keys)
    for n in range(count):
        obj = bpy.data.objects.new(f"Body{n:04d}", mesh)
        scene.collection.objects.link(obj)
        for frame in at:
            set_pose(obj, (frame - 1) / (frames - 1), n, 3.0)
            for path in ("location", "rotation_euler", "scale"):
                obj.keyframe_insert(path, frame=frame)
        objects.append(obj)
    return objects


def armature(bones: int) -> bpy.types.Object:
    data = bpy.data.armatures.new("Rig")
    rig = bpy.data.objects.new("Rig", data)
    bpy.context.scene.collection.objects.link(rig)
    select([rig])
    bpy.ops.object.mode_set(mode="EDIT")
    previous = None
    for n in range(bones):
        chain, link = divmod(n, 10)
        bone = data.edit_bones.new(f"Bone{n:03d}")
        bone.head, bone.tail = (chain, 0.0, link), (chain, 0.0, link + 1.0)
        bone.parent = previous if link else None
        previous = bone
    bpy.ops.object.mode_set(mode="OBJECT")
    for pose_bone in rig.pose.bones:
        pose_bone.rotation_mode = "XYZ"
    return rig


def sparse_rig(bones: int, frames: int, keys: int) -> list[bpy.types.Object]:
    new_scene(frames)
    rig = armature(bones)
    for n, pose_bone in enumerate(rig.pose.bones):
        for frame in key_frames(frames, keys):
            set_pose(pose_bone, (frame - 1) / (frames - 1), n, 0.3)
            for path in ("location", "rotation_euler", "scale"):
                pose_bone.keyframe_insert(path, frame=frame)
    return [rig]


#: The noise of the dense scenes: 0.2 mm and 0.02 degrees per channel, a clean capture's jitter
#: (below Reduce Keys' default tolerance of 1 mm / 0.5 degrees on a body of 1 m: its default
#: use, a bake or a capture to thin out; louder noise keeps nearly every key).
NOISE_M, NOISE_DEG = 0.0002, 0.02


def fill_dense(targets, frames: int, location) -> None:
    """Keys every frame on XYZ Euler of each target (an object or a pose bone), and on the
    location of those in `location`: a slow motion plus a little noise, keys selected."""
    rng = np.random.default_rng(1)
    t = np.arange(1, frames + 1, dtype=float)
    co = np.empty(2 * frames, dtype=np.float32)
    co[0::2] = t
    selected = np.ones(frames, dtype=bool)
    for target in targets:
        target.keyframe_insert("rotation_euler", frame=1)
        if target in location:
            target.keyframe_insert("location", frame=1)
    for obj in {t.id_data for t in targets}:
        for k, fc in enumerate(curves_of(obj.animation_data.action)):
            rot = "rotation" in fc.data_path
            truth = (0.4 if rot else 0.5) * np.sin(t / (40.0 if rot else 60.0) + k)
            co[1::2] = truth + rng.normal(0, math.radians(NOISE_DEG) if rot else NOISE_M, frames)
            points = fc.keyframe_points
            points.add(frames - len(points))
            points.foreach_set("co", co)
            points.foreach_set("select_control_point", selected)
            fc.select = True
            fc.update()


def dense_objects(count: int, frames: int) -> list[bpy.types.Object]:
    scene = new_scene(frames)
    mesh = bpy.data.meshes.new("Block")
    mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], [], [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)])
    objects = []
    for n in range(count):
        obj = bpy.data.objects.new(f"Take{n:04d}", mesh)
        scene.collection.objects.link(obj)
        objects.append(obj)
    fill_dense(objects, frames, objects)
    return objects


def dense_rig(bones: int, frames: int) -> list[bpy.types.Object]:
    new_scene(frames)
    rig = armature(bones)
    fill_dense(list(rig.pose.bones), frames, rig.pose.bones[:1])
    return [rig]


def build(family: str, owners: int, frames: int, keys: int) -> list[bpy.types.Object]:
    if family == "objects":
        return sparse_objects(owners, frames, keys)
    if family == "rig":
        return sparse_rig(owners, frames, keys)
    if family == "dense_objects":
        return dense_objects(owners, frames)
    return dense_rig(owners, frames)


# ------------------------------------------------------------------ Blender's action APIs (the floor's own)


def curves_of(action) -> list:
    """Every F-curve of an action (all channelbags of a slotted one)."""
    if hasattr(action, "layers") and len(action.layers):
        return [fc for layer in action.layers for strip in layer.strips for bag in strip.channelbags
                for fc in bag.fcurves]
    return list(action.fcurves)


def assign(obj, action, slot=None) -> None:
    adt = obj.animation_data or obj.animation_data_create()
    adt.action = action
    if SLOTTED and action is not None:
        slot = slot if slot is not None else (action.slots[0] if len(action.slots) else None)
        if slot is not None and adt.action_slot != slot:
            adt.action_slot = slot


def select(objects) -> None:
    chosen = {o.name for o in objects}  # (names: a bpy_struct's hash is its Python wrapper's)
    bpy.context.view_layer.update()  # objects just linked: context.selected_objects sees them after a sync
    for obj in bpy.context.view_layer.objects:
        if obj is not None:  # (an object just removed, until the view layer syncs)
            obj.select_set(obj.name in chosen)
    bpy.context.view_layer.objects.active = objects[0]


class Stage:
    """The scene's owners with their pristine source actions; gives each owner a fresh copy
    before a call and removes what a call made after it (both untimed)."""

    def __init__(self, objects) -> None:
        self.objects = objects
        self.sources = {}
        for obj in objects:
            action = obj.animation_data.action
            action.use_fake_user = True
            self.sources[obj.name] = action
        self.keep_actions = {a.name for a in bpy.data.actions}
        self.keep_objects = {o.name for o in bpy.data.objects}
        self.keep_meshes = {m.name for m in bpy.data.meshes}
        self.keep_collections = {c.name for c in bpy.data.collections}

    def fresh(self) -> dict:
        copies = {}
        for obj in self.objects:
            copy = self.sources[obj.name].copy()
            assign(obj, copy)
            copies[obj.name] = copy
        select(self.objects)
        return copies

    def clean(self) -> None:
        if bpy.context.mode != "OBJECT":
            bpy.ops.object.mode_set(mode="OBJECT")
        for obj in self.objects:
            assign(obj, self.sources[obj.name])
        ids = [a for a in bpy.data.actions if a.name not in self.keep_actions]
        ids += [o for o in bpy.data.objects if o.name not in self.keep_objects]
        ids += [m for m in bpy.data.meshes if m.name not in self.keep_meshes]
        ids += [c for c in bpy.data.collections if c.name not in self.keep_collections]
        if ids:
            bpy.data.batch_remove(ids)
            bpy.context.view_layer.update()
        select(self.objects)


def result_shape(objects) -> dict:
    """{owner name: [(data_path, array_index, keys)]} of the actions the owners now hold."""
    return {obj.name: [(fc.data_path, fc.array_index, len(fc.keyframe_points))
                       for fc in curves_of(obj.animation_data.action)] for obj in objects}


def result_values(shape: dict, attrs) -> dict:
    """Values for the floor's writes, built before the clock starts: {keys: {attr: data}}."""
    out = {}
    for curves in shape.values():
        for _, _, n in curves:
            if n in out:
                continue
            co = np.empty((n, 2), dtype=np.float32)
            co[:, 0] = np.arange(1, n + 1)
            co[:, 1] = np.sin(co[:, 0] * 0.1)
            data = {"co": co.ravel(), "handle_left": (co - [0.3, 0.0]).astype(np.float32).ravel(),
                    "handle_right": (co + [0.3, 0.0]).astype(np.float32).ravel(),
                    "interpolation": (1,) * n, "handle_left_type": (0,) * n, "handle_right_type": (0,) * n}
            out[n] = {a: data[a] for a in attrs}
    return out


# ------------------------------------------------------------------ the floors


def read_keys(objects) -> int:
    """One foreach_get per attribute per source curve; returns the keys read."""
    total = 0
    for obj in objects:
        for fc in curves_of(obj.animation_data.action):
            points = fc.keyframe_points
            n = len(points)
            for attr, width, dtype in READ_ATTRS:
                points.foreach_get(attr, np.empty(width * n, dtype=dtype))
            total += n
    return total


def write_result(obj, curves, values: dict) -> None:
    """A new action holding `curves` (data_path, index, keys), assigned to `obj`."""
    action = bpy.data.actions.new(obj.name + "Floor")
    slot = None
    if SLOTTED:
        slot = action.slots.new(id_type=obj.id_type, name=obj.name)
        bag = action.layers.new("Layer").strips.new(type="KEYFRAME").channelbag(slot, ensure=True)
    else:
        bag = action
    for path, index, n in curves:
        points = bag.fcurves.new(path, index=index).keyframe_points
        points.add(n)
        for attr, data in values[n].items():
            points.foreach_set(attr, data)
    assign(obj, action, slot)


def floor_write(objects, shape: dict, values: dict) -> None:
    read_keys(objects)
    for obj in objects:
        write_result(obj, shape[obj.name], values)


def floor_insert(objects, frame: float, values: dict) -> None:
    read_keys(objects)
    for obj in objects:
        for fc, value in zip(curves_of(obj.animation_data.action), values[obj.name]):
            fc.keyframe_points.insert(frame, value, options={"FAST"})


def floor_sweep(objects, made: list[dict]) -> None:
    read_keys(objects)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    for obj in objects:
        mesh = obj.evaluated_get(depsgraph).data
        mesh.vertices.foreach_get("co", np.empty(3 * len(mesh.vertices), dtype=np.float32))
        mesh.loop_triangles.foreach_get("vertices", np.empty(3 * len(mesh.loop_triangles), dtype=np.int32))
    scene = bpy.context.scene
    for i, m in enumerate(made):  # names of their own: Blender's search for a free name grows with each clash
        mesh = bpy.data.meshes.new(f"FloorSwept{i:05d}")
        mesh.vertices.add(len(m["co"]) // 3)
        mesh.loops.add(len(m["vertex_index"]))
        mesh.polygons.add(len(m["loop_start"]))
        mesh.vertices.foreach_set("co", m["co"])
        mesh.loops.foreach_set("vertex_index", m["vertex_index"])
        mesh.polygons.foreach_set("loop_start", m["loop_start"])
        mesh.update()
        scene.collection.objects.link(bpy.data.objects.new(mesh.name, mesh))


def made_meshes(stage: Stage) -> list[dict]:
    """The vertices, loops and faces of the objects a call created (read untimed)."""
    out = []
    for obj in bpy.data.objects:
        if obj.name in stage.keep_objects or obj.type != "MESH":
            continue
        mesh = obj.data
        co = np.empty(3 * len(mesh.vertices), dtype=np.float32)
        mesh.vertices.foreach_get("co", co)
        vi = np.empty(len(mesh.loops), dtype=np.int32)
        mesh.loops.foreach_get("vertex_index", vi)
        ls = np.empty(len(mesh.polygons), dtype=np.int32)
        mesh.polygons.foreach_get("loop_start", ls)
        out.append({"co": co, "vertex_index": vi, "loop_start": ls})
    return out


# ------------------------------------------------------------------ Blender's counterparts


def graph_context() -> dict:
    return _graph_context(bpy)


def nla_bake(objects, frames: int) -> set:
    kw = dict(frame_start=1, frame_end=frames, step=1, only_selected=True, visual_keying=False,
              clear_constraints=False, clear_parents=False, use_current_action=False)
    if objects[0].type == "ARMATURE":
        return bpy.ops.nla.bake(bake_types={"POSE"}, channel_types={"LOCATION", "ROTATION", "SCALE"}, **kw)
    return bpy.ops.nla.bake(bake_types={"OBJECT"}, **kw)


def before_nla_bake(objects) -> None:
    if objects[0].type == "ARMATURE":
        bpy.ops.object.mode_set(mode="POSE")
        for pose_bone in objects[0].pose.bones:
            (pose_bone if hasattr(pose_bone, "select") else pose_bone.bone).select = True


# ------------------------------------------------------------------ timing


def timed(fn):
    wall, cpu = time.perf_counter(), time.process_time()
    out = fn()
    return time.perf_counter() - wall, time.process_time() - cpu, out


class Record:
    def __init__(self) -> None:
        self.data: dict[str, dict] = {}

    def add(self, name: str, key: str, wall: float, cpu: float) -> None:
        entry = self.data.setdefault(name, {})
        entry.setdefault(key, []).append(wall)
        entry.setdefault(key + "_cpu", []).append(cpu)

    def error(self, name: str, message: str) -> None:
        self.data.setdefault(name, {})["error"] = message


def snapshot(objects) -> list:
    """The keys of the first owner's current action (to see that a call changed them)."""
    out = []
    for fc in curves_of(objects[0].animation_data.action):
        co = np.empty(2 * len(fc.keyframe_points), dtype=np.float32)
        fc.keyframe_points.foreach_get("co", co)
        out.append(co)
    return out


def run_op(record: Record, name: str, call, objects) -> bool:
    """Times a bpy.ops call; an exception, a result other than FINISHED or a call that left the
    first owner's keys as they were is recorded as a failure."""
    before = snapshot(objects)
    try:
        wall, cpu, result = timed(call)
    except Exception as err:  # an operator that fails in the bench is reported, not fatal
        record.error(name, f"{type(err).__name__}: {str(err).splitlines()[0] if str(err) else ''}")
        return False
    if result != {"FINISHED"}:
        record.error(name, f"returned {sorted(result)}")
        return False
    after = snapshot(objects)
    if name not in ("revert", "sweep") and len(after) == len(before) and all(
            len(a) == len(b) and np.array_equal(a, b) for a, b in zip(after, before)):
        record.error(name, "returned FINISHED but left the keys as they were")
        return False
    record.add(name, "op", wall, cpu)
    return True


def one_repetition(stage: Stage, family: str, frames: int, record: Record, sweep: bool, reduce: bool = True) -> None:
    objects = stage.objects
    dense = family.startswith("dense")
    ops = bpy.ops.screwbender
    if not dense:
        # Smooth Motion, then its floor (the result's shape), then Revert and its floor.
        copies = stage.fresh()
        if run_op(record, "smooth", lambda: ops.smooth(), objects):
            shape = result_shape(objects)
            results = {o.name: o.animation_data.action for o in objects}
            wall, cpu, _ = timed(lambda: [assign(o, copies[o.name]) for o in objects])
            record.add("revert", "floor", wall, cpu)
            for o in objects:
                assign(o, results[o.name])
            run_op(record, "revert", lambda: ops.revert(), objects)
            stage.clean()
            values = result_values(shape, WRITE_ATTRS["smooth"])
            stage.fresh()
            wall, cpu, _ = timed(lambda: floor_write(objects, shape, values))
            record.add("smooth", "floor", wall, cpu)
        stage.clean()
        stage.fresh()
        before_nla_bake(objects)
        run_op(record, "nla_bake", lambda: nla_bake(objects, frames), objects)
        stage.clean()
        # Insert Key on Motion at a frame between keys.
        frame = frames // 2 + 1
        bpy.context.scene.frame_set(frame)
        stage.fresh()
        ok = run_op(record, "insert_key", lambda: ops.insert_key(), objects)
        stage.clean()
        if ok:
            stage.fresh()
            values = {o.name: [fc.evaluate(frame) for fc in curves_of(o.animation_data.action)] for o in objects}
            wall, cpu, _ = timed(lambda: floor_insert(objects, frame, values))
            record.add("insert_key", "floor", wall, cpu)
            stage.clean()
        if sweep:
            stage.fresh()
            if run_op(record, "sweep", lambda: ops.sweep(closed=False), objects):
                made = made_meshes(stage)
                stage.clean()
                stage.fresh()
                wall, cpu, _ = timed(lambda: floor_sweep(objects, made))
                record.add("sweep", "floor", wall, cpu)
            stage.clean()
        return
    ctx = graph_context()
    for name, counterpart in (("denoise", "gaussian_smooth"), ("reduce", "decimate"))[:2 if reduce else 1]:
        stage.fresh()
        if run_op(record, name, lambda: getattr(ops, IDNAMES[name])(), objects):
            shape = result_shape(objects)
            values = result_values(shape, WRITE_ATTRS[name])
            stage.clean()
            stage.fresh()
            wall, cpu, _ = timed(lambda: floor_write(objects, shape, values))
            record.add(name, "floor", wall, cpu)
        stage.clean()
        stage.fresh()

        def theirs():
            with bpy.context.temp_override(**ctx):
                return getattr(bpy.ops.graph, counterpart)()

        run_op(record, counterpart, theirs, objects)
        stage.clean()


def run_case(family: str, owners: int, frames: int, keys: int, repeat: int, sweep_max: int) -> dict:
    objects = build(family, owners, frames, keys)
    stage = Stage(objects)
    curves = sum(len(curves_of(o.animation_data.action)) for o in objects)
    source_keys = sum(len(fc.keyframe_points) for o in objects for fc in curves_of(o.animation_data.action))
    record = Record()
    reduce = source_keys <= REDUCE_MAX_KEYS
    start = time.perf_counter()
    for run in range(1 if owners >= ONE_RUN_OWNERS else repeat):
        sweep = family == "objects" and owners * frames <= sweep_max and (run == 0 or owners * frames <= SWEEP_EVERY_RUN)
        one_repetition(stage, family, frames, record, sweep, reduce)
    case = {"family": family, "owners": owners, "frames": frames, "keys": keys, "curves": curves,
            "source_keys": source_keys, "repeat": 1 if owners >= ONE_RUN_OWNERS else repeat, "seconds": time.perf_counter() - start, "ops": {}}
    for name, entry in record.data.items():
        out = {k: v for k, v in entry.items() if k != "error"}
        for key in list(out):
            out[key + "_median"] = statistics.median(out[key])
        if "error" in entry:
            out["error"] = entry["error"]
        case["ops"][name] = out
    return case


def describe(case: dict) -> str:
    what = {"objects": "objects", "rig": "bones", "dense_objects": "objects (dense)", "dense_rig": "bones (dense)"}
    return f"{case['owners']:,} {what[case['family']]} x {case['frames']:,} frames"


def print_case(case: dict) -> None:
    print(f"{describe(case)} ({case['curves']:,} curves, {case['source_keys']:,} keys; {case['seconds']:.1f} s)",
          flush=True)
    ops = case["ops"]
    for name in OPERATORS:
        if name not in ops:
            continue
        e = ops[name]
        if "op_median" not in e:
            print(f"  {LABELS[name]:22s} failed: {e.get('error')}")
            continue
        line = f"  {LABELS[name]:22s} {1e3 * e['op_median']:9.1f} ms"
        if "floor_median" in e:
            line += f"   floor {1e3 * e['floor_median']:8.1f} ms   x{e['op_median'] / e['floor_median']:.1f} floor"
        other = COUNTERPART.get(name)
        if other in ops and "op_median" in ops[other]:
            line += f"   {LABELS[other]} {1e3 * ops[other]['op_median']:.1f} ms ({ops[other]['op_median'] / e['op_median']:.1f}x ours)"
        print(line + (f"   [{e['error']}]" if "error" in e else ""))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="the smallest scenes, one run each (seconds)")
    parser.add_argument("--repeat", type=int, help="runs per case (medians count); default 3, --quick 1")
    parser.add_argument("--only", help="run only the cases whose family starts with this (objects, rig, dense)")
    parser.add_argument("--case", action="append", metavar="FAMILY:OWNERS:FRAMES[:KEYS]",
                        help="run this case instead (families: objects, rig, dense_objects, dense_rig); repeatable")
    parser.add_argument("--out", type=Path, help="write the results as JSON here")
    args = parser.parse_args()
    repeat = args.repeat or (1 if args.quick else 3)
    cases = QUICK_CASES if args.quick else FULL_CASES
    if args.case:
        cases = [(f, int(o), int(fr), int(k[0]) if k else 10) for f, o, fr, *k in (c.split(":") for c in args.case)]
    if args.only:
        cases = [c for c in cases if c[0].startswith(args.only)]
    start = time.perf_counter()
    load0 = os.getloadavg()
    date = time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime())
    print(f"Blender {bpy.app.version_string}: operators against their floor, {repeat} run(s) per case", flush=True)
    # One untimed pass over the smallest scene first: modules imported, caches warm.
    for family in ("objects", "dense_objects"):
        stage = Stage(build(family, 1, 20, 2))
        one_repetition(stage, family, 20, Record(), family == "objects")
    results = []
    for family, owners, frames, keys in cases:
        case = run_case(family, owners, frames, keys, repeat, 50 if args.quick else SWEEP_MAX_OBJECT_FRAMES)
        print_case(case)
        results.append(case)
    out = {"blender": bpy.app.version_string, "quick": args.quick, "repeat": repeat, "reduce_max_keys": REDUCE_MAX_KEYS,
           "date": date, "date_end": time.strftime("%Y-%m-%d %H:%M UTC", time.gmtime()),
           "load_start": " ".join(f"{x:.2f}" for x in load0),
           "load_end": " ".join(f"{x:.2f}" for x in os.getloadavg()),
           "seconds": time.perf_counter() - start, "cases": results}
    print(f"bench_floor: {out['seconds']:.0f} s")
    if args.out:
        args.out.write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
