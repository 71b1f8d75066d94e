"""Benchmark: Reduce Keys (the operator) against Blender's `graph.decimate` (issue 26), five
clips, three tolerances, both results checked by Blender's own playback in world space.

Clips (built here, every one at real-world size in metres, so each tolerance is taken as it
is: the clips' own scale is 1):
- camera: a camera track, 600 frames keyed on every frame (a dolly and orbit with a handheld
  wobble and 0.05 mm / 0.005 degrees of solver noise); the camera body 0.2 m across;
- walk: a 13-bone character walking 8 s (192 frames), keyed on every frame;
- bvh: a 22-joint motion-capture clip (300 frames at 30 fps, 0.01 degrees of sensor noise per
  joint) written as a BVH file and imported with `bpy.ops.import_anim.bvh`;
- demo: the demo scene (scripts/demo/10_scene.py) baked by Smooth Motion (Jarek, 5 levels,
  timing Smooth: the demo's variant), four objects, LINEAR keys on every frame;
- rig100: 100 bones (ten chains of ten, 0.1 m each) keyed on every frame 1..1,000.
Tolerances: 0.5 mm / 0.05 degrees, 1 mm / 0.5 degrees, 5 mm / 1 degree.

Ours: `bpy.ops.screwbender.reduce_keys(distance, angle)` on the clip's owners (timed: the
whole operator), with the channels of an owner keyed on shared frames (the default) and
Per Channel. Theirs: `bpy.ops.graph.decimate(mode='ERROR', remove_error_margin=m)`, every
other option at its default, headless through `bpy.context.temp_override` with the largest
area of the Animation screen switched to the Graph Editor and its WINDOW region, every key
selected, the dope sheet's `show_only_selected` off; its margin is searched (between 1e-6
and 0.1, to a factor of 1.046: the resolution of 8 bisection steps in log scale) for the
largest value whose result still meets the same world-space tolerance, by regula falsi on
the logarithms with every trial shared between tolerances (:func:`search_margin`: about
half the decimate calls of bisection); the search checks with `polyscrew.evaluate_fcurves`,
Blender's own evaluation bit for bit, composed along the bone chains in numpy; the time is
that of one decimate call at the best margin. On rig100 one decimate call takes a minute or
more (decimate works curve by curve, about 0.2 s per curve of 1,000 keys here, so running it
per chain would not be faster): its margin is searched on the clip's first 200 frames (the
same motion) and then run once on the whole clip per margin found (a smaller margin, x0.7,
up to twice, when the whole clip misses the tolerance). Both results are checked by Blender's own playback: `scene.frame_set`
at every frame and three subframes between frames, every owner's `matrix_world` (a bone:
`matrix_world @ PoseBone.matrix`), against the dense clip's own playback at the same
samples: the largest distance of any point of the body (an object's bounding box corners and
origin, a bone's head and tail) and the largest rotation angle.

Keys: keyframe points over the owners' transform curves (what Blender stores and the animator
edits; Decimate keys each curve on its own frames), and key frames (distinct frames per owner)
as a fraction of the frames (each owner's own key range). Also: Smooth Motion with Keys: Reduced against Every Step (time).

Run: PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench/bench_reduce.py [--json out.json] [--quick]
(--why-demo: only the measurement of why the demo bake keeps most of its frames, :func:`why_demo`)
"""

from __future__ import annotations

import argparse
import importlib
import importlib.util
import json
import math
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "demo"))
import demo_common  # noqa: E402

demo_common.blender_with_addon()
import bpy  # noqa: E402
import polyscrew  # noqa: E402

ADDON = "bl_ext.user_default.screwbender"
channels = importlib.import_module(f"{ADDON}.blender.channels")
curves = importlib.import_module(f"{ADDON}.blender.curves")

TOLERANCES = ((0.0005, 0.05), (0.001, 0.5), (0.005, 1.0))  # metres, degrees
#: Float32 world matrices in Blender's playback: what a check may add to the tolerance.
SLACK = 1e-5
TRANSFORM = ("location", "rotation_euler", "rotation_quaternion", "rotation_axis_angle", "scale")
ROTATION_PATHS = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}


def rotation_path(mode: str) -> str:
    return ROTATION_PATHS.get(mode, "rotation_euler")


def new_scene(frames: int) -> bpy.types.Scene:
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, frames
    return scene


def select(objects) -> None:
    for obj in bpy.context.view_layer.objects:
        obj.select_set(obj in objects)
    bpy.context.view_layer.objects.active = objects[0]


def key_dense(target, paths_values: dict, frames: np.ndarray) -> None:
    """Keys `target` (an object or a pose bone) on every frame: one key inserted per channel,
    then every key written at once (foreach_set), handles recomputed (auto clamped)."""
    for path, values in paths_values.items():
        setattr(target, path, values[0])
        target.keyframe_insert(path, frame=float(frames[0]))
    obj = target.id_data
    prefix = "" if isinstance(target, bpy.types.Object) else target.path_from_id() + "."
    by_path = {(fc.data_path, fc.array_index): fc for fc in channels.object_fcurves(obj)}
    co = np.empty(2 * len(frames), dtype=np.float32)
    co[0::2] = frames
    for path, values in paths_values.items():
        for i in range(values.shape[1]):
            fc = by_path[prefix + path, i]
            points = fc.keyframe_points
            points.add(len(frames) - len(points))
            co[1::2] = values[:, i]
            points.foreach_set("co", co)
            fc.update()


def euler(rot) -> np.ndarray:
    """(N, 3) XYZ Euler angles, continuous, from scipy rotations."""
    return np.unwrap(rot.as_euler("xyz"), axis=0)


# Clips ---------------------------------------------------------------------------------------


def clip_camera(n: int = 600):
    from scipy.spatial.transform import Rotation

    new_scene(n)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.display_size = 0.2
    bpy.context.scene.collection.objects.link(cam)
    rng = np.random.default_rng(7)
    t = np.arange(n) / 24.0
    loc = np.stack([6 * np.cos(0.12 * t), -6 * np.sin(0.12 * t), 1.6 + 0.3 * np.sin(0.2 * t)], axis=1)
    loc += 0.01 * np.stack([np.sin(2.1 * t), np.sin(1.7 * t + 1), np.sin(2.9 * t + 2)], axis=1)
    loc += rng.normal(0, 0.00005, loc.shape)
    ang = np.stack([1.35 + 0.05 * np.sin(0.3 * t), 0.004 * np.sin(2.3 * t), 0.12 * t + 1.57], axis=1)
    ang += np.radians(0.3) * np.stack([np.sin(1.9 * t), np.sin(2.5 * t + 1), np.sin(1.3 * t + 2)], axis=1)
    rot = Rotation.from_euler("xyz", ang) * Rotation.from_rotvec(rng.normal(0, np.radians(0.005), (n, 3)))
    key_dense(cam, {"location": loc, "rotation_euler": euler(rot)}, np.arange(1, n + 1, dtype=float))
    return {"name": "camera", "label": "camera track (600 frames)", "owners": [(cam, "")], "select": [cam],
            "armature": "OBJECT", "captured": True}


def armature(name: str, bones) -> bpy.types.Object:
    """bones: (name, parent, head, tail, connected)."""
    data = bpy.data.armatures.new(name)
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    select([obj])
    bpy.ops.object.mode_set(mode="EDIT")
    made = {}
    for bone_name, parent, head, tail, connected in bones:
        b = data.edit_bones.new(bone_name)
        b.head, b.tail = head, tail
        if parent:
            b.parent = made[parent]
            b.use_connect = connected
        made[bone_name] = b
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj


def clip_walk(n: int = 192):
    new_scene(n)
    bones = [
        ("Hips", None, (0, 0, 1.0), (0, 0, 1.1), False),
        ("Spine", "Hips", (0, 0, 1.1), (0, 0, 1.45), True),
        ("Head", "Spine", (0, 0, 1.45), (0, 0, 1.75), True),
    ]
    for side, x in (("L", 0.1), ("R", -0.1)):
        bones += [
            (f"Thigh.{side}", "Hips", (x, 0, 1.0), (x, 0, 0.55), False),
            (f"Shin.{side}", f"Thigh.{side}", (x, 0, 0.55), (x, 0, 0.1), True),
            (f"Foot.{side}", f"Shin.{side}", (x, 0, 0.1), (x, -0.15, 0.0), True),
            (f"Arm.{side}", "Spine", (2 * x, 0, 1.4), (2.2 * x, 0, 1.12), False),
            (f"Fore.{side}", f"Arm.{side}", (2.2 * x, 0, 1.12), (2.3 * x, -0.05, 0.86), True),
        ]
    rig = armature("Walker", bones)
    t = np.arange(n) / 24.0
    w = 2 * np.pi / 1.1  # a stride every 1.1 s
    frames = np.arange(1, n + 1, dtype=float)
    for pb in rig.pose.bones:
        pb.rotation_mode = "XYZ"
    hips = rig.pose.bones["Hips"]
    key_dense(hips, {
        "location": np.stack([0.02 * np.sin(w * t), 1.3 * t, 0.03 * np.cos(2 * w * t)], axis=1),
        "rotation_euler": np.stack([0.05 * np.sin(2 * w * t), 0.04 * np.sin(w * t), 0.08 * np.sin(w * t)], axis=1),
    }, frames)
    for name, values in {
        "Spine": lambda s: np.stack([0.05 + 0.03 * np.sin(2 * w * t), 0 * t, -0.1 * np.sin(w * t)], axis=1),
        "Head": lambda s: np.stack([-0.03 * np.sin(2 * w * t), 0 * t, 0.06 * np.sin(w * t)], axis=1),
    }.items():
        key_dense(rig.pose.bones[name], {"rotation_euler": values(0)}, frames)
    for side, phase in (("L", 0.0), ("R", np.pi)):
        swing = np.sin(w * t + phase)
        rots = {
            "Thigh": np.stack([0.45 * swing, 0 * t, 0.02 * swing], axis=1),
            "Shin": np.stack([-0.6 * np.clip(np.sin(w * t + phase - 1.2), 0, None) - 0.05, 0 * t, 0 * t], axis=1),
            "Foot": np.stack([0.25 * np.sin(w * t + phase + 0.6), 0 * t, 0 * t], axis=1),
            "Arm": np.stack([-0.35 * swing, 0 * t, 0.05 + 0 * t], axis=1),
            "Fore": np.stack([-0.3 - 0.2 * np.clip(-swing, 0, None), 0 * t, 0 * t], axis=1),
        }
        for part, values in rots.items():
            key_dense(rig.pose.bones[f"{part}.{side}"], {"rotation_euler": values}, frames)
    return {"name": "walk", "label": "walk (13 bones, 192 frames)", "owners": [(rig, b.name) for b in rig.pose.bones],
            "select": [rig], "armature": "BONES", "captured": True}


BVH_JOINTS = [  # name, parent, offset (cm)
    ("Hips", None, (0, 0, 0)), ("Spine", "Hips", (0, 10, 0)), ("Spine1", "Spine", (0, 12, 0)),
    ("Spine2", "Spine1", (0, 12, 0)), ("Neck", "Spine2", (0, 14, 0)), ("Head", "Neck", (0, 10, 0)),
    ("LShoulder", "Spine2", (4, 12, 0)), ("LArm", "LShoulder", (14, 0, 0)), ("LForeArm", "LArm", (28, 0, 0)),
    ("LHand", "LForeArm", (25, 0, 0)),
    ("RShoulder", "Spine2", (-4, 12, 0)), ("RArm", "RShoulder", (-14, 0, 0)), ("RForeArm", "RArm", (-28, 0, 0)),
    ("RHand", "RForeArm", (-25, 0, 0)),
    ("LUpLeg", "Hips", (9, -6, 0)), ("LLeg", "LUpLeg", (0, -42, 0)), ("LFoot", "LLeg", (0, -41, 0)),
    ("LToe", "LFoot", (0, -6, 12)),
    ("RUpLeg", "Hips", (-9, -6, 0)), ("RLeg", "RUpLeg", (0, -42, 0)), ("RFoot", "RLeg", (0, -41, 0)),
    ("RToe", "RFoot", (0, -6, 12)),
]


def write_bvh(path: Path, n: int) -> None:
    """A 22-joint BVH: a dancing figure (sums of slow sines per joint angle) with 0.01 degrees
    of sensor noise per angle and 0.2 mm on the root; 30 frames per second; ZXY rotations."""
    rng = np.random.default_rng(11)
    children: dict = {}
    for name, parent, _ in BVH_JOINTS:
        children.setdefault(parent, []).append(name)
    offsets = {name: off for name, _, off in BVH_JOINTS}
    lines = ["HIERARCHY"]

    def joint(name: str, depth: int) -> None:
        pad = "  " * depth
        lines.append(f"{pad}{'ROOT' if depth == 0 else 'JOINT'} {name}")
        lines.append(f"{pad}{{")
        lines.append(f"{pad}  OFFSET {' '.join(f'{v:.4f}' for v in offsets[name])}")
        if depth == 0:
            lines.append(f"{pad}  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation Yrotation")
        else:
            lines.append(f"{pad}  CHANNELS 3 Zrotation Xrotation Yrotation")
        kids = children.get(name, [])
        for kid in kids:
            joint(kid, depth + 1)
        if not kids:
            lines.append(f"{pad}  End Site")
            lines.append(f"{pad}  {{")
            lines.append(f"{pad}    OFFSET 0.0000 5.0000 0.0000")
            lines.append(f"{pad}  }}")
        lines.append(f"{pad}}}")

    joint("Hips", 0)
    t = np.arange(n) / 30.0
    columns = [20 * np.sin(0.4 * t), 95 + 3 * np.sin(3.0 * t), 60 * t]
    columns = [c + rng.normal(0, 0.02, n) for c in columns]  # 0.2 mm
    for k, (_name, _, _) in enumerate(BVH_JOINTS):
        for axis in range(3):
            amp = 25.0 if axis == 1 else 12.0
            f1, f2 = 0.7 + 0.13 * ((k + axis) % 7), 1.9 + 0.11 * ((2 * k + axis) % 5)
            angle = amp * np.sin(f1 * t + k + axis) + 0.3 * amp * np.sin(f2 * t + 2 * k)
            columns.append(angle + rng.normal(0, 0.01, n))
    motion = np.stack(columns, axis=1)
    lines += ["MOTION", f"Frames: {n}", "Frame Time: 0.0333333"]
    lines += [" ".join(f"{v:.5f}" for v in row) for row in motion]
    path.write_text("\n".join(lines) + "\n")


def clip_bvh(n: int = 300):
    new_scene(n)
    path = Path(tempfile.mkdtemp(prefix="bench-reduce-")) / "dance.bvh"
    write_bvh(path, n)
    assert bpy.ops.import_anim.bvh(filepath=str(path), global_scale=0.01, frame_start=1) == {"FINISHED"}
    rig = next(o for o in bpy.context.scene.objects if o.type == "ARMATURE")
    select([rig])
    return {"name": "bvh", "label": f"BVH capture ({len(rig.pose.bones)} bones, {n} frames)",
            "owners": [(rig, b.name) for b in rig.pose.bones], "select": [rig], "armature": "BONES", "captured": True}


def load_demo_scene() -> None:
    spec = importlib.util.spec_from_file_location("demo_scene", Path(__file__).resolve().parents[1] / "demo" / "10_scene.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    module.build()


def clip_demo():
    load_demo_scene()
    objects = [o for o in bpy.context.scene.objects if o.animation_data is not None]
    select(objects)
    assert bpy.ops.screwbender.smooth(scheme="jarek", levels=5, timing="smooth") == {"FINISHED"}
    # the bakes are the clip: keep them as the objects' actions (the originals stay behind)
    return {"name": "demo", "label": "demo scene, Smooth Motion bake (4 objects)",
            "owners": [(o, "") for o in objects], "select": objects, "armature": "OBJECT", "captured": False}


def clip_rig100(n: int = 1000):
    new_scene(n)
    bones = []
    for c in range(10):
        for k in range(10):
            z = 0.1 * k
            bones.append((f"C{c}B{k}", f"C{c}B{k - 1}" if k else None, (0.3 * c, 0, z), (0.3 * c, 0, z + 0.1), bool(k)))
    rig = armature("Rig100", bones)
    frames = np.arange(1, n + 1, dtype=float)
    t = frames / 24.0
    for i, pb in enumerate(rig.pose.bones):
        pb.rotation_mode = "XYZ"
        f = 0.3 + 0.05 * (i % 7)
        values = {"rotation_euler": np.stack([0.3 * np.sin(f * t + i), 0.2 * np.sin(1.3 * f * t + 2 * i),
                                              0.25 * np.sin(0.7 * f * t + 3 * i)], axis=1)}
        if not rig.data.bones[pb.name].use_connect:
            values["location"] = np.stack([0.2 * np.sin(0.2 * t + i), 0.1 * np.sin(0.3 * t), 0.05 * t], axis=1)
        key_dense(pb, values, frames)
    return {"name": "rig100", "label": "100-bone rig (1,000 frames)", "owners": [(rig, b.name) for b in rig.pose.bones],
            "select": [rig], "armature": "BONES", "captured": False}


CLIPS = (clip_camera, clip_walk, clip_bvh, clip_demo, clip_rig100)
#: Clips whose decimate margin is searched on their first WINDOW frames.
WINDOWED = ("rig100",)
WINDOW = 200


# Playback and checks -----------------------------------------------------------------------


def owner_curves(obj, bone: str) -> dict:
    prefix = f'pose.bones["{bone}"].' if bone else ""
    return {(fc.data_path[len(prefix):], fc.array_index): fc for fc in channels.object_fcurves(obj)
            if fc.data_path.startswith(prefix) and "." not in fc.data_path[len(prefix):]
            and "[" not in fc.data_path[len(prefix):]}


def body_points(obj, bone: str) -> np.ndarray:
    if bone:
        return np.array([[0, 0, 0], [0, obj.data.bones[bone].length, 0]], dtype=np.float64)
    return np.concatenate([np.array([tuple(c) for c in obj.bound_box]), np.zeros((1, 3))])


def samples(first: float, last: float) -> np.ndarray:
    whole = np.arange(first, last + 1e-9)
    return np.concatenate([(whole[:-1, None] + np.array([0, 0.25, 0.5, 0.75])).ravel(), whole[-1:]])


def blender_playback(owners, times) -> np.ndarray:
    """(owners, times, 4, 4) world matrices from Blender's own playback (frame_set): an
    object's `matrix_world`, a bone's `matrix_world @ PoseBone.matrix` (every bone's matrix
    read at once: `pose.bones.foreach_get("matrix")`, column-major)."""
    scene = bpy.context.scene
    out = np.empty((len(owners), len(times), 4, 4))
    rigs = {}
    for i, (obj, bone) in enumerate(owners):
        if bone:
            names = [b.name for b in obj.pose.bones]
            rigs.setdefault(obj.name, (obj, []))[1].append((i, names.index(bone)))
    objects = [(i, obj) for i, (obj, bone) in enumerate(owners) if not bone]
    buffers = {name: np.empty(16 * len(obj.pose.bones), dtype=np.float32) for name, (obj, _) in rigs.items()}
    for k, time_ in enumerate(times):
        whole = int(math.floor(time_))
        scene.frame_set(whole, subframe=float(time_ - whole))
        for i, obj in objects:
            out[i, k] = np.array(obj.matrix_world)
        for name, (obj, members) in rigs.items():
            buf = buffers[name]
            obj.pose.bones.foreach_get("matrix", buf)
            mats = buf.reshape(-1, 4, 4).transpose(0, 2, 1).astype(np.float64)
            world = np.array(obj.matrix_world)
            for i, j in members:
                out[i, k] = world @ mats[j]
    return out


def fast_playback(owners, times) -> np.ndarray:
    """The same from the F-curves: `polyscrew.evaluate_fcurves` (Blender's evaluation bit for
    bit, through the add-on's curves.py) composed along the bone chains in numpy (the clips
    have no constraints, no scale keys, every bone inheriting its parent's rotation)."""
    out = np.empty((len(owners), len(times), 4, 4))
    poses: dict = {}
    order = sorted(range(len(owners)), key=lambda i: len(owners[i][0].data.bones[owners[i][1]].parent_recursive)
                   if owners[i][1] else 0)
    for i in order:
        obj, bone = owners[i]
        target = obj.pose.bones[bone] if bone else obj
        mode = target.rotation_mode
        rot_path = rotation_path(mode)
        found = owner_curves(obj, bone)
        cols = [(p, j) for p in ("location", rot_path) for j in range(len(getattr(target, p)))]
        keyed = [c for c in cols if c in found]
        values = curves.evaluate([found[c] for c in keyed], times) if keyed else np.zeros((0, len(times)))
        table = {c: values[k] for k, c in enumerate(keyed)}
        def col(c):
            return table[c] if c in table else np.full(len(times), getattr(target, c[0])[c[1]])
        loc = np.stack([col(("location", j)) for j in range(3)], axis=1)
        rot = np.stack([col((rot_path, j)) for j in range(len(getattr(target, rot_path)))], axis=1)
        basis = np.tile(np.eye(4), (len(times), 1, 1))
        basis[:, :3, :3] = polyscrew.rotation_matrices(rot, mode)
        if not bone or not obj.data.bones[bone].use_connect:
            basis[:, :3, 3] = loc
        if bone:
            data = obj.data.bones[bone]
            rest = np.array(data.matrix_local)
            if data.parent is not None:
                parent = poses[(obj.as_pointer(), data.parent.name)]
                local = np.linalg.inv(np.array(data.parent.matrix_local)) @ rest
                pose = parent @ local @ basis
            else:
                pose = rest @ basis
            poses[(obj.as_pointer(), bone)] = pose
            out[i] = np.array(obj.matrix_world) @ pose
        else:
            parent = np.array(obj.parent.matrix_world) @ np.array(obj.matrix_parent_inverse) if obj.parent else np.eye(4)
            out[i] = parent @ basis
    return out


def world_errors(owners, ref, got) -> tuple[np.ndarray, np.ndarray]:
    """(owners, times) largest distance of a body point and rotation angle (radians)."""
    dist = np.empty(ref.shape[:2])
    ang = np.empty(ref.shape[:2])
    for i, (obj, bone) in enumerate(owners):
        p = body_points(obj, bone)
        ph = np.concatenate([p, np.ones((len(p), 1))], axis=1)
        a, b = ref[i] @ ph.T, got[i] @ ph.T
        dist[i] = np.linalg.norm((a - b)[:, :3], axis=1).max(axis=1)
        ra = ref[i][:, :3, :3] / np.linalg.norm(ref[i][:, :3, :3], axis=1, keepdims=True)
        rb = got[i][:, :3, :3] / np.linalg.norm(got[i][:, :3, :3], axis=1, keepdims=True)
        rel = np.einsum("nji,njk->nik", ra, rb)
        ang[i] = np.arccos(np.clip((np.trace(rel, axis1=1, axis2=2) - 1) / 2, -1, 1))
    return dist, ang


def counts(owners) -> tuple[int, int]:
    """Keyframe points over the owners' transform curves, and key frames (distinct per owner)."""
    points = frames = 0
    for obj, bone in owners:
        found = owner_curves(obj, bone)
        per = []
        for (path, _), fc in found.items():
            if path in TRANSFORM:
                co = np.empty(2 * len(fc.keyframe_points), dtype=np.float32)
                fc.keyframe_points.foreach_get("co", co)
                per.append(co[0::2])
                points += len(fc.keyframe_points)
        frames += len(np.unique(np.round(np.concatenate(per), 3))) if per else 0
    return points, frames


# Running ---------------------------------------------------------------------------------------


class Clip:
    def use(self, actions: dict) -> None:
        """Every object on the given actions (a decimate trial's result)."""
        for obj in self.objects:
            channels.assign(obj, actions[obj.name], self.slots[obj.name])

    def __init__(self, spec: dict):
        self.__dict__.update(spec)
        self.objects = sorted({o for o, _ in self.owners}, key=lambda o: o.name)
        self.dense = {o.name: o.animation_data.action for o in self.objects}
        self.slots = {o.name: channels.slot_identifier(o) for o in self.objects}
        for action in self.dense.values():
            action.use_fake_user = True
        first = min(float(fc.keyframe_points[0].co.x) for o in self.objects for fc in channels.object_fcurves(o))
        last = max(float(fc.keyframe_points[-1].co.x) for o in self.objects for fc in channels.object_fcurves(o))
        self.first, self.last = first, last
        self.times = samples(first, last)
        self.frames = int(round(last - first)) + 1
        # frames per owner: its own key range (the demo's objects have ranges of their own)
        self.owner_frames = 0
        for obj, bone in self.owners:
            found = [fc for (p, _), fc in owner_curves(obj, bone).items() if p in TRANSFORM]
            lo = min(fc.keyframe_points[0].co.x for fc in found)
            hi = max(fc.keyframe_points[-1].co.x for fc in found)
            self.owner_frames += int(round(hi - lo)) + 1

    def restore(self) -> None:
        """Every object back on a fresh copy of its dense action."""
        for obj in self.objects:
            channels.assign(obj, self.dense[obj.name].copy(), self.slots[obj.name])

    def select_all_keys(self) -> None:
        for obj in self.objects:
            for fc in channels.object_fcurves(obj):
                fc.select, fc.hide = True, False
                n = len(fc.keyframe_points)
                fc.keyframe_points.foreach_set("select_control_point", np.ones(n, dtype=bool))


def graph_context() -> dict:
    win = bpy.context.window_manager.windows[0]
    area = max(win.screen.areas, key=lambda a: a.width * a.height)
    area.type = "GRAPH_EDITOR"
    area.spaces.active.dopesheet.show_only_selected = False
    region = next(r for r in area.regions if r.type == "WINDOW")
    return dict(window=win, area=area, region=region)


def decimate(clip: Clip, margin: float) -> float:
    clip.restore()
    select(clip.objects)
    clip.select_all_keys()
    ctx = graph_context()
    start = time.perf_counter()
    with bpy.context.temp_override(**ctx):
        result = bpy.ops.graph.decimate(mode="ERROR", remove_error_margin=margin)
    elapsed = time.perf_counter() - start
    assert result == {"FINISHED"}, result
    return elapsed


def ours(clip: Clip, distance: float, angle: float, per_channel: bool = False) -> float:
    clip.restore()
    select(clip.objects)
    start = time.perf_counter()
    result = bpy.ops.screwbender.reduce_keys(distance=distance, angle=math.radians(angle), armature=clip.armature,
                                             per_channel=per_channel)
    elapsed = time.perf_counter() - start
    assert result == {"FINISHED"}, result
    return elapsed


def measure(clip: Clip, ref: np.ndarray, distance: float, angle: float, elapsed: float) -> dict:
    got = blender_playback(clip.owners, clip.times)
    dist, ang = world_errors(clip.owners, ref, got)
    within = (dist <= distance + SLACK) & (ang <= math.radians(angle) + SLACK)
    whole = np.abs(clip.times - np.round(clip.times)) < 1e-9
    points, frames = counts(clip.owners)
    return {"points": points, "keyframes": frames, "fraction": frames / clip.owner_frames,
            "time": elapsed, "distance": float(dist.max()), "angle": float(math.degrees(ang.max())),
            "within": float(within.mean()), "samples": int(within.size),
            "within_frames": float(within[:, whole].mean()),
            "distance_frames": float(dist[:, whole].max()), "angle_frames": float(math.degrees(ang[:, whole].max()))}


#: Decimate's margins are searched between these (log scale) ...
MARGINS = (1e-6, 0.1)
#: ... to this resolution: the largest margin that meets a tolerance and one at most this
#: factor larger that does not (8 bisection steps over MARGINS: 10^5^(1/256)).
RESOLUTION = 1e5 ** (1 / 256)


def search_margin(clip: Clip, fast_ref: np.ndarray, tolerances, resolution: float = RESOLUTION) -> dict:
    """Per tolerance: the largest decimate margin whose result meets it (by the fast check),
    to `resolution`, and among the margins tried that meet it the one with the fewest keys.

    The tolerances are taken from the smallest up and every trial is kept (decimate is
    deterministic): a margin that meets a tolerance meets the larger ones, so each search
    starts from the bracket the trials so far give. A bracket is found by steps of x4 from a
    guess (the tolerance's distance in metres, or the smaller tolerance's margin), then closed
    by regula falsi on log(margin) against log(error / tolerance) (decimate's error grows about
    as a power of its margin), each trial followed by one a resolution step across, so that the
    bracket closes from both sides around the predicted margin. Each trial
    keeps its time and its decimated actions (checked by Blender's playback afterwards)."""
    cache: dict[float, tuple[float, float, int]] = {}
    kept: dict[float, tuple[float, dict]] = {}

    def trial(margin: float) -> tuple[float, float, int]:
        if margin not in cache:
            elapsed = decimate(clip, margin)
            got = fast_playback(clip.owners, clip.times)
            dist, ang = world_errors(clip.owners, fast_ref, got)
            cache[margin] = (float(dist.max()), float(ang.max()), counts(clip.owners)[0])
            kept[margin] = (elapsed, {o.name: o.animation_data.action for o in clip.objects})
        return cache[margin]

    best = {}
    lowest, highest = MARGINS
    for distance, angle in sorted(tolerances):
        def ratio(m: float) -> float:
            d, a, _ = trial(m)
            return max(d / distance, a / math.radians(angle), 1e-12)

        def known(feasible: bool) -> list[float]:
            return sorted(m for m in cache if (max(cache[m][0] / distance, cache[m][1] / math.radians(angle)) <= 1.0)
                          == feasible)

        ok, bad = known(True), known(False)
        lo = ok[-1] if ok else None
        hi = next((m for m in bad if lo is None or m > lo), None)
        if lo is None and hi is None:
            m = min(max(distance, lowest), highest)
            lo, hi = (m, None) if ratio(m) <= 1.0 else (None, m)
        while lo is None:  # down from the smallest failing margin
            m = max(hi / 4.0, lowest)
            if ratio(m) <= 1.0:
                lo = m
            elif m <= lowest:
                break
            else:
                hi = m
        if lo is None:
            best[distance, angle] = None
            continue
        while hi is None and lo < highest:  # up from the largest margin that meets it
            m = min(lo * 4.0, highest)
            if ratio(m) <= 1.0:
                lo = m
            else:
                hi = m
        while hi is not None and hi / lo > resolution:
            # where log(error / tolerance) reaches 0 on the line through the bracket's ends (the
            # error grows about as a power of the margin), kept a resolution step inside it
            a, b = math.log(lo), math.log(hi)
            ra, rb = math.log(ratio(lo)), math.log(ratio(hi))
            x = a + (b - a) * (0.0 - ra) / (rb - ra) if rb > ra else 0.5 * (a + b)
            step = math.log(resolution)
            if b - a <= 2.0 * step:
                x = 0.5 * (a + b)
            x = min(max(x, a + step), b - step)
            m = math.exp(x)
            if ratio(m) <= 1.0:  # and one resolution step up: the bracket may close there
                lo, across = m, m * resolution
                if across < hi:
                    if ratio(across) <= 1.0:
                        lo = across
                    else:
                        hi = across
            else:
                hi, across = m, m / resolution
                if across > lo:
                    if ratio(across) <= 1.0:
                        lo = across
                    else:
                        hi = across
        feasible = [(v[2], m) for m, v in cache.items() if v[0] <= distance and v[1] <= math.radians(angle)]
        best[distance, angle] = min(feasible)[1]  # the fewest keys among the margins that meet it
    return {"best": best, "trials": len(cache), "kept": kept}


def smooth_timing(runs: int) -> list[dict]:
    """Smooth Motion, Keys: Every Step against Reduced (default tolerance): the demo scene and a
    100-bone rig keyed every 10 frames over 1,000 frames; medians of `runs`."""
    out = []
    for label, build in (("demo scene (4 objects)", "demo"), ("100-bone rig, keys every 10 frames (1,000 frames)", "rig")):
        times = {"EVERY_STEP": [], "REDUCED": []}
        keys = {}
        for _ in range(runs):
            for mode in times:
                if build == "demo":
                    load_demo_scene()
                    objects = [o for o in bpy.context.scene.objects if o.animation_data is not None]
                    kw = {}
                else:
                    new_scene(1000)
                    bones = [(f"B{i}", None, (0.3 * (i % 10), 0.3 * (i // 10), 0), (0.3 * (i % 10), 0.3 * (i // 10), 0.1), False)
                             for i in range(100)]
                    rig = armature("Sparse", bones)
                    frames = np.arange(1, 1001, 10, dtype=float)
                    for i, pb in enumerate(rig.pose.bones):
                        pb.rotation_mode = "XYZ"
                        t = frames / 24.0
                        key_dense(pb, {"rotation_euler": np.stack([0.5 * np.sin(0.4 * t + i), 0.3 * np.cos(0.5 * t),
                                                                   0.2 * np.sin(0.3 * t + 2 * i)], axis=1)}, frames)
                    objects, kw = [rig], {"armature": "BONES"}
                select(objects)
                start = time.perf_counter()
                result = bpy.ops.screwbender.smooth(key_mode=mode, **kw)
                times[mode].append(time.perf_counter() - start)
                assert result == {"FINISHED"}, result
                owners = [(o, b.name) for o in objects if o.type == "ARMATURE" for b in o.pose.bones] or \
                    [(o, "") for o in objects]
                keys[mode] = counts(owners)[0]
        out.append({"case": label, "every_step": float(np.median(times["EVERY_STEP"])),
                    "reduced": float(np.median(times["REDUCED"])), "every_keys": keys["EVERY_STEP"],
                    "reduced_keys": keys["REDUCED"], "runs": runs})
        print(f"  Smooth Motion, {label}: Every Step {1000 * out[-1]['every_step']:.0f} ms ({keys['EVERY_STEP']:,} keys), "
              f"Reduced {1000 * out[-1]['reduced']:.0f} ms ({keys['REDUCED']:,} keys)", flush=True)
    return out


def why_demo() -> None:
    """Why Reduce Keys keeps most frames of the demo scene's Smooth Motion bake (issue 26, item 3).

    The bench's demo clip is Smooth Motion's Every Step result on the demo scene: LINEAR keys on
    every frame. Blender plays straight lines in channel space between them, and the bench checks
    the reduced keys against that playback at every frame and three subframes between frames, as
    Reduce Keys does (`between="linear"`). A Bezier curve spanning several frames must then pass
    within the tolerance of the polyline's corners and of its chords' quarter points; where the
    polyline turns by more than the tolerance allows (its second difference over 8, the gap at a
    chord's middle between the polyline and any smooth curve through its corners), no key can be
    left out there.

    For each object of the clip, read through the add-on's own Reduce Keys reading
    (`blender/reduce.py`: the dense poses and the body radius) and measured with numpy:
    - its body radius, its speed (largest distance any point of the body moves in a frame) and turn
      (degrees a frame);
    - the share of the frames where the polyline's corner gap `|d2|/8` (translation plus radius
      times the rotation's second difference, on the body) exceeds each tolerance's distance (a
      lower bound on the key frames against the LINEAR playback, from the corners alone);
    - the key frames `polyscrew.reduce_keys` keeps per reference between frames: "linear" (the
      bake's playback: what the bench measures), "screw" (the screw between frames), "cubic" (the
      smooth curve through the baked poses: what Smooth Motion with Keys: Reduced measures).
    """
    red = importlib.import_module(f"{ADDON}.blender.reduce")
    owners = importlib.import_module(f"{ADDON}.blender.owners")
    clip = clip_demo()
    print(f"Blender {bpy.app.version_string}: the demo scene's Smooth Motion bake (Every Step, LINEAR keys)")
    for obj, _ in clip["owners"]:
        owner = owners.as_owner(obj)
        motion = red.read_motion(owner, channels.object_fcurves(obj))
        batch = red.batches([(owner, motion)], red.Options())[0]
        item, frames = batch.items[0], batch.frames
        poses = item.poses
        r = item.radius
        step = np.linalg.norm(np.diff(poses[:, :3, 3], axis=0), axis=1)
        rel = np.einsum("nji,njk->nik", poses[:-1, :3, :3], poses[1:, :3, :3])
        turn = np.degrees(np.arccos(np.clip((np.trace(rel, axis1=1, axis2=2) - 1) / 2, -1, 1)))
        # the corner gap on the body: points at the radius along the three axes, and the origin
        points = np.concatenate([np.zeros((1, 3)), r * np.eye(3), -r * np.eye(3)])
        world = np.einsum("nij,pj->npi", poses[:, :3, :3], points) + poses[:, None, :3, 3]
        gap = np.linalg.norm(world[:-2] - 2 * world[1:-1] + world[2:], axis=2).max(axis=1) / 8.0
        print(
            f"  {obj.name}: {len(frames)} frames, radius {r:.3f}, up to {1e3 * (step + np.radians(turn) * r).max():.1f} mm "
            f"and {turn.max():.2f} degrees a frame (median {1e3 * np.median(step + np.radians(turn) * r):.1f} mm, "
            f"{np.median(turn):.2f} degrees); corner gap median {1e3 * np.median(gap):.2f} mm, "
            f"max {1e3 * gap.max():.2f} mm; between={batch.between}"
        )
        for distance, angle in TOLERANCES:
            corners = float(np.mean(gap > distance))
            line = f"    {1e3 * distance:g} mm / {angle:g} deg: corner gap above the distance at {corners:.0%} of the frames;"
            for between in ("linear", "screw", "cubic"):
                options = red.Options(distance=distance, angle=np.radians(angle))
                result = red.solve(batch.items, frames, options, batch.cyclic, between)[0]
                line += f" {between} {result.keys} key frames ({result.keys / len(frames):.0%})"
            print(line, flush=True)



def window_search(out: Path, resolution: float) -> None:
    """The margin search of the windowed clips (:data:`WINDOWED`, one per process: the
    `--clips` given) on their first :data:`WINDOW` frames, written to `out` as JSON."""
    name = next(n for n in WINDOWED if n in sys.argv)
    window = Clip(globals()[f"clip_{name}"](n=WINDOW))
    search = search_margin(window, fast_playback(window.owners, window.times), TOLERANCES, resolution)
    out.write_text(json.dumps({"best": [[list(k), v] for k, v in search["best"].items()], "trials": search["trials"]}))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path)
    parser.add_argument("--quick", action="store_true", help="a coarser margin search, one timing run")
    parser.add_argument("--clips", nargs="*", help="only these clips (camera walk bvh demo rig100)")
    parser.add_argument("--window-search", type=Path, help=argparse.SUPPRESS)  # (the child process below)
    parser.add_argument("--why-demo", action="store_true",
                        help="only: why the demo bake keeps most frames (its motion per frame, the LINEAR "
                             "polyline's corners, key frames per reference between frames)")
    args = parser.parse_args()
    # the margin's resolution: that of `steps` bisection steps over MARGINS (log scale)
    steps = 5 if args.quick else 8
    resolution = (MARGINS[1] / MARGINS[0]) ** (1 / 2**steps)
    started = time.perf_counter()
    report = {"blender": bpy.app.version_string, "tolerances": TOLERANCES, "steps": steps, "slack": SLACK, "clips": [],
              "resolution": resolution}
    if args.why_demo:
        why_demo()
        return
    if args.window_search is not None:
        window_search(args.window_search, resolution)
        return
    print(f"Blender {bpy.app.version_string}: Reduce Keys against graph.decimate (margin searched to a factor "
          f"{resolution:.3f}, the resolution of {steps} bisection steps)")
    # The windowed clips' margin searches (minutes of decimate calls) run in a second Blender
    # process meanwhile (the machine's second core): the figures are the same, the wall time
    # about that of the longer of the two
    children = {}
    for name in WINDOWED:
        if not args.clips or name in args.clips:
            out = Path(tempfile.mkdtemp(prefix="bench-reduce-")) / f"{name}.json"
            command = [sys.executable, __file__, "--window-search", str(out), "--clips", name]
            children[name] = (subprocess.Popen(command + (["--quick"] if args.quick else [])), out)
    for build in CLIPS:
        if args.clips and build.__name__.removeprefix("clip_") not in args.clips:
            continue
        name = build.__name__.removeprefix("clip_")
        window = None
        if name in WINDOWED:
            # decimate takes minutes on the whole clip: its margin is searched on the clip's
            # first WINDOW frames (the same motion), then checked on the whole clip
            process, out = children[name]
            if process.wait() != 0:
                sys.exit(f"bench_reduce: the margin search of {name} failed")
            found = json.loads(out.read_text())
            window = True
            search = {"best": {tuple(k): v for k, v in found["best"]}, "trials": found["trials"], "kept": {}}
        clip = Clip(build())
        ref = blender_playback(clip.owners, clip.times)
        fast_ref = fast_playback(clip.owners, clip.times)
        agreement = float(np.abs(fast_ref - ref).max())
        if window is None:
            search = search_margin(clip, fast_ref, TOLERANCES, resolution)
        entry = {"name": clip.name, "label": clip.label, "owners": len(clip.owners), "frames": clip.frames,
                 "owner_frames": clip.owner_frames,
                 "captured": clip.captured, "samples": len(clip.times), "fast_agreement": agreement,
                 "decimate_trials": search["trials"], "searched_on": f"first {WINDOW} frames" if window else "the clip",
                 "cases": []}
        whole: dict[float, tuple[float, dict]] = {}  # windowed: decimate on the whole clip, per margin
        for distance, angle in TOLERANCES:
            case = {"distance": distance, "angle": angle}
            case["ours"] = measure(clip, ref, distance, angle, ours(clip, distance, angle))
            case["ours_per_channel"] = measure(clip, ref, distance, angle, ours(clip, distance, angle, True))
            margin = search["best"][distance, angle]
            if margin is None:
                case["decimate"] = None
            elif window is None:
                elapsed, actions = search["kept"][margin]
                clip.use(actions)
                case["decimate"] = measure(clip, ref, distance, angle, elapsed)
                case["decimate"]["margin"] = margin
            else:
                for _attempt in range(3):  # smaller margins while the whole clip misses it
                    if margin in whole:  # (another tolerance's margin: decimate's result is the same)
                        elapsed, actions = whole[margin]
                        clip.use(actions)
                    else:
                        elapsed = decimate(clip, margin)
                        whole[margin] = (elapsed, {o.name: o.animation_data.action for o in clip.objects})
                    case["decimate"] = measure(clip, ref, distance, angle, elapsed)
                    case["decimate"]["margin"] = margin
                    if case["decimate"]["within"] >= 1.0:
                        break
                    margin *= 0.7
            entry["cases"].append(case)
            o, d, pc = case["ours"], case["decimate"], case["ours_per_channel"]
            theirs = (f"decimate (margin {d['margin']:.3g}) {d['points']:,} keys, {d['fraction']:.1%} "
                      f"of frames, {1000 * d['time']:.0f} ms, error {1000 * d['distance']:.3g} mm / {d['angle']:.3g} deg, "
                      f"{d['within']:.2%} within") if d else "decimate: no margin meets it"
            print(f"  {clip.name} {1000 * distance:g} mm / {angle:g} deg: ours {o['points']:,} keys, {o['fraction']:.1%} of "
                  f"frames, {1000 * o['time']:.0f} ms, error {1000 * o['distance']:.3g} mm / {o['angle']:.3g} deg, "
                  f"{o['within']:.2%} within; per channel {pc['points']:,} keys, {pc['fraction']:.1%} of frames, "
                  f"{1000 * pc['time']:.0f} ms, {pc['within']:.2%} within; {theirs}", flush=True)
        clip.restore()
        entry["dense_points"] = counts(clip.owners)[0]
        report["clips"].append(entry)
    report["smooth"] = smooth_timing(1 if args.quick else 3)
    report["seconds"] = time.perf_counter() - started
    print(f"bench_reduce: {report['seconds']:.0f} s")
    if args.json:
        args.json.write_text(json.dumps(report, indent=1))


if __name__ == "__main__":
    main()
