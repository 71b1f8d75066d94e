"""Scene building and checking helpers for the ScrewBender Blender tests.

The reference conversions from channel values to matrices use scipy (double precision),
independent of the add-on's own numpy conversions and of mathutils (single precision).
"""

from __future__ import annotations

from collections.abc import Sequence

import bpy
import numpy as np
from scipy.spatial.transform import Rotation

from conftest import addon_module

EULER_ORDERS = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")
ROTATION_MODES = ("QUATERNION", "AXIS_ANGLE") + EULER_ORDERS
ROTATION_PATH = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}


def rotation_path(mode: str) -> str:
    return ROTATION_PATH.get(mode, "rotation_euler")


def rotation_from_matrix(matrix: np.ndarray, mode: str) -> list[float]:
    """Channel values of `mode` for a rotation matrix (scipy)."""
    rot = Rotation.from_matrix(matrix)
    if mode == "QUATERNION":
        x, y, z, w = rot.as_quat()
        return [w, x, y, z]
    if mode == "AXIS_ANGLE":
        vec = rot.as_rotvec()
        angle = float(np.linalg.norm(vec))
        axis = vec / angle if angle > 0 else np.array([0.0, 0.0, 1.0])
        return [angle, *axis]
    # lowercase = extrinsic = Blender's order; scipy lists angles in sequence order, Blender as x, y, z
    angles = rot.as_euler(mode.lower())
    return [float(angles[mode.index(axis)]) for axis in "XYZ"]


def rotation_to_matrices(values: np.ndarray, mode: str) -> np.ndarray:
    """(N, 3, 3) rotation matrices from (N, k) channel values (scipy)."""
    values = np.asarray(values, dtype=np.float64)
    if mode == "QUATERNION":
        q = values / np.linalg.norm(values, axis=1)[:, None]
        return Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()
    if mode == "AXIS_ANGLE":
        axis = values[:, 1:] / np.linalg.norm(values[:, 1:], axis=1)[:, None]
        return Rotation.from_rotvec(axis * values[:, :1]).as_matrix()
    in_sequence = values[:, ["XYZ".index(axis) for axis in mode]]
    return Rotation.from_euler(mode.lower(), in_sequence).as_matrix()


def compose(location, rotation3, scale=None) -> np.ndarray:
    n = len(location)
    out = np.zeros((n, 4, 4))
    out[:, :3, :3] = rotation3 if scale is None else rotation3 * np.asarray(scale)[:, None, :]
    out[:, :3, 3] = location
    out[:, 3, 3] = 1.0
    return out


def rigid(location, rotation3) -> np.ndarray:
    return compose(np.asarray(location, dtype=np.float64).reshape(-1, 3), np.asarray(rotation3).reshape(-1, 3, 3))


def new_object(name: str = "Body", kind: str = "MESH", mode: str = "XYZ") -> bpy.types.Object:
    """A new object of `kind` (MESH, EMPTY, CAMERA, LIGHT) linked into the scene and selected."""
    if kind == "MESH":
        data = bpy.data.meshes.new(name)
        data.from_pydata([(0, 0, 0), (1, 0, 0), (0, 2, 0), (0, 0, 3)], [], [(0, 1, 2), (0, 1, 3), (0, 2, 3), (1, 2, 3)])
    elif kind == "CAMERA":
        data = bpy.data.cameras.new(name)
    elif kind == "LIGHT":
        data = bpy.data.lights.new(name, "POINT")
    else:
        data = None
    obj = bpy.data.objects.new(name, data)
    bpy.context.scene.collection.objects.link(obj)
    obj.rotation_mode = mode
    select_only(obj)
    return obj


def select_only(*objects: bpy.types.Object) -> None:
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    for obj in objects:
        obj.select_set(True)
    if objects:
        bpy.context.view_layer.objects.active = objects[0]


def continuous(value: list[float], previous: list[float] | None, mode: str) -> list[float]:
    """Rotation channel values as an animator keys them: quaternion signs continuous, Euler
    angles compatible with the previous key (mathutils), axis-angle axis not flipped."""
    if previous is None:
        return value
    if mode == "QUATERNION" and np.dot(value, previous) < 0:
        return [-v for v in value]
    if mode == "AXIS_ANGLE" and np.dot(value[1:], previous[1:]) < 0:
        return [2 * np.pi - value[0]] + [-v for v in value[1:]]
    if mode in EULER_ORDERS:
        from mathutils import Euler

        euler = Euler(value, mode)
        euler.make_compatible(Euler(previous, mode))
        return list(euler)
    return value


def key_poses(obj, frames: Sequence[float], poses: np.ndarray, scales: np.ndarray | None = None) -> None:
    """Keys location, rotation (in the object's mode) and optionally scale at `frames`."""
    mode = obj.rotation_mode
    path = rotation_path(mode)
    previous = None
    for i, frame in enumerate(frames):
        obj.location = poses[i, :3, 3]
        value = continuous(rotation_from_matrix(poses[i, :3, :3], mode), previous, mode)
        setattr(obj, path, value)
        previous = value
        obj.keyframe_insert("location", frame=frame)
        obj.keyframe_insert(path, frame=frame)
        if scales is not None:
            obj.scale = scales[i]
            obj.keyframe_insert("scale", frame=frame)


def fcurves(obj) -> list[bpy.types.FCurve]:
    """The F-curves of `obj`'s active action and slot (the add-on's channels.py, any version)."""
    return addon_module("blender.channels").object_fcurves(obj)


def curve_points(fcurve) -> np.ndarray:
    co = np.empty(2 * len(fcurve.keyframe_points), dtype=np.float32)
    fcurve.keyframe_points.foreach_get("co", co)
    return co.reshape(-1, 2).astype(np.float64)


def channel(obj, path: str, size: int) -> tuple[np.ndarray, np.ndarray]:
    """(frames, values (N, size)) of the baked curves of `path`; all components share frames."""
    curves = {fc.array_index: fc for fc in fcurves(obj) if fc.data_path == path}
    assert sorted(curves) == list(range(size)), f"{obj.name}: {path} curves {sorted(curves)}"
    points = [curve_points(curves[i]) for i in range(size)]
    for p in points[1:]:
        np.testing.assert_array_equal(p[:, 0], points[0][:, 0])
    return points[0][:, 0], np.stack([p[:, 1] for p in points], axis=1)


def baked_matrices(obj, with_scale: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """(frames, (N, 4, 4)) composed from the object's baked F-curve key values (scipy)."""
    mode = obj.rotation_mode
    frames, location = channel(obj, "location", 3)
    rot_frames, rotation = channel(obj, rotation_path(mode), 4 if mode in ROTATION_PATH else 3)
    np.testing.assert_array_equal(frames, rot_frames)
    scale = channel(obj, "scale", 3)[1] if with_scale else None
    return frames, compose(location, rotation_to_matrices(rotation, mode), scale)


def evaluated_basis(obj, frames: Sequence[float]) -> np.ndarray:
    """`obj.matrix_basis` at each frame (Blender's own evaluation of the active action)."""
    scene = bpy.context.scene
    out = []
    for frame in frames:
        whole = int(np.floor(frame))
        scene.frame_set(whole, subframe=float(frame - whole))
        out.append(np.array(obj.matrix_basis, dtype=np.float64))
    return np.array(out)


def snapshot_action(action, key_selection: bool = True) -> dict:
    """Everything about an action's F-curves that smoothing must not change (with
    `key_selection`, which keys are selected too)."""
    if action is None:
        return {}
    channels = addon_module("blender.channels")
    bags = [(slot, channels.fcurves(bag), channels.groups(bag)) for slot, bag in channels.containers(action)]
    out = {"name": action.name, "library": action.library, "bags": []}
    for identifier, curves, groups in bags:
        entry = {"slot": identifier, "groups": groups, "curves": []}
        for fc in curves:
            kp = fc.keyframe_points
            data = {}
            for attr, width, dtype in (
                ("co", 2, np.float32), ("handle_left", 2, np.float32), ("handle_right", 2, np.float32),
                ("interpolation", 1, np.int32), ("handle_left_type", 1, np.int32),
                ("handle_right_type", 1, np.int32), ("easing", 1, np.int32), ("type", 1, np.int32),
                *((("select_control_point", 1, bool),) if key_selection else ()),
            ):
                buf = np.empty(width * len(kp), dtype=dtype)
                kp.foreach_get(attr, buf)
                data[attr] = buf.tobytes()
            entry["curves"].append(
                {
                    "path": (fc.data_path, fc.array_index),
                    "group": fc.group.name if fc.group else None,
                    "extrapolation": fc.extrapolation,
                    "mute": fc.mute,
                    "modifiers": [(m.type, m.mute) for m in fc.modifiers],
                    "keys": data,
                }
            )
        out["bags"].append(entry)
    return out


def snapshot_scene() -> dict:
    """Objects, their actions, all actions' F-curves and fake users: what must survive a refusal.

    Object transforms are taken after evaluating the animation at the current frame.
    """
    scene = bpy.context.scene
    scene.frame_set(scene.frame_current)
    return {
        "objects": {
            o.name: (
                o.animation_data.action.name if o.animation_data and o.animation_data.action else None,
                tuple(o.location), tuple(o.scale), tuple(o.rotation_euler), tuple(o.rotation_quaternion),
            )
            for o in bpy.data.objects
        },
        "actions": {a.name: (a.use_fake_user, snapshot_action(a)) for a in bpy.data.actions},
    }


def circle_poses(thetas: np.ndarray, radius: float, pitch: float, tilt: np.ndarray) -> np.ndarray:
    """Poses `Screw(theta) L0` of a helix about the world Z axis (pitch 0: a circle).

    `L0` sits at (radius, 0, 0) with orientation `tilt`; Screw(theta) rotates by theta about Z
    and slides pitch * theta along it.
    """
    rz = Rotation.from_euler("z", np.asarray(thetas)[:, None]).as_matrix()
    location = np.einsum("nij,j->ni", rz, [radius, 0.0, 0.0])
    location[:, 2] += pitch * thetas
    return compose(location, rz @ tilt)


def screw_deviation(poses: np.ndarray, radius: float, pitch: float, tilt: np.ndarray) -> np.ndarray:
    """Per pose: the distance to the nearest pose of the helix (max abs matrix entry).

    The helix pose is found from the pose's rotation: theta = angle of `R tilt^T` about Z.
    """
    relative = poses[:, :3, :3] @ tilt.T
    thetas = np.unwrap(np.arctan2(relative[:, 1, 0], relative[:, 0, 0]))
    # choose the turn that matches the height (for a helix)
    if pitch != 0.0:
        turns = np.round((poses[:, 2, 3] / pitch - thetas) / (2 * np.pi))
        thetas = thetas + 2 * np.pi * turns
    ideal = circle_poses(thetas, radius, pitch, tilt)
    return np.abs(poses - ideal).max(axis=(1, 2))


def _id_props(id_block) -> dict:
    """An ID's custom properties, ID pointers by name (comparable across snapshots)."""
    out = {}
    for key in id_block.keys():
        value = id_block[key]
        if isinstance(value, bpy.types.ID):
            value = ("ID", value.name)
        elif hasattr(value, "to_dict"):
            value = value.to_dict()
        elif hasattr(value, "to_list"):
            value = value.to_list()
        out[key] = value
    return out


def snapshot_data(key_selection: bool = False) -> dict:
    """The names and contents of every action, object, mesh, curve, material and collection,
    object selection and the active object: what an operator that fails must leave exactly
    as it was (compare two snapshots with ==). `key_selection` adds which keys are selected
    (off by default: some tests change it themselves between their snapshots)."""
    scene = bpy.context.scene
    layer = bpy.context.view_layer
    scene.frame_set(scene.frame_current)

    def slot(o):
        adt = o.animation_data
        s = getattr(adt, "action_slot", None) if adt else None
        return s.identifier if s is not None else ""

    objects = {}
    for o in bpy.data.objects:
        adt = o.animation_data
        objects[o.name] = {
            "action": adt.action.name if adt and adt.action else None,
            "has_animation_data": adt is not None,
            "slot": slot(o),
            "matrix_basis": np.array(o.matrix_basis).round(6).tolist(),
            "data": o.data.name if o.data else None,
            "parent": o.parent.name if o.parent else None,
            "selected": o.select_get() if o.name in layer.objects else None,
            "props": _id_props(o),
            "preview": bool(getattr(o, "screwbender_preview", False)),
        }
    meshes = {}
    for m in bpy.data.meshes:
        select = np.empty(len(m.polygons), dtype=bool)
        m.polygons.foreach_get("select", select)
        co = np.empty(3 * len(m.vertices), dtype=np.float32)
        m.vertices.foreach_get("co", co)
        meshes[m.name] = (len(m.vertices), len(m.polygons), co.tobytes(), select.tobytes(), m.users)
    curves = {}
    for c in bpy.data.curves:
        curves[c.name] = [
            np.array([tuple(p.co) for p in s.points]).round(6).tolist() for s in c.splines
        ]
    return {
        "objects": objects,
        "active": layer.objects.active.name if layer.objects.active else None,
        "actions": {
            a.name: (a.use_fake_user, a.users, _id_props(a), snapshot_action(a, key_selection))
            for a in bpy.data.actions
        },
        "meshes": meshes,
        "curves": curves,
        "materials": sorted(m.name for m in bpy.data.materials),
        "collections": {c.name: sorted(o.name for o in c.objects) for c in bpy.data.collections},
        "scene_collections": sorted(c.name for c in scene.collection.children),
    }


def channel_from(obj, path: str, size: int) -> tuple[np.ndarray, np.ndarray]:
    """(frames, values (N, size)) of the curves of `path` (any data path, bones included)."""
    curves = {fc.array_index: fc for fc in fcurves(obj) if fc.data_path == path}
    assert sorted(curves) == list(range(size)), f"{obj.name}: {path} curves {sorted(curves)}"
    points = [curve_points(curves[i]) for i in range(size)]
    return points[0][:, 0], np.stack([p[:, 1] for p in points], axis=1)
