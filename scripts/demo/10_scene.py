"""Demo part 10: build the keyed demo scene and save it as out/demo_source.blend.

Four keyed objects (see demo_common.MOTIONS), keyed the way an animator keys them: Bezier
keys at uneven frames, cyclic motions with a Cycles modifier and the first pose repeated as
the last key.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bpy  # noqa: E402
import demo_common  # noqa: E402
from mathutils import Euler, Matrix, Quaternion, Vector  # noqa: E402


def wedge_mesh(name: str, length: float, width: float, height: float) -> bpy.types.Mesh:
    """A block tapering to a narrow nose along +X: its orientation reads at a glance."""
    l, w, h = length / 2, width / 2, height / 2
    verts = [
        (-l, -w, -h), (-l, w, -h), (-l, w, h), (-l, -w, h),  # back face
        (l, -w * 0.35, -h * 0.5), (l, w * 0.35, -h * 0.5), (l, w * 0.35, h * 0.5), (l, -w * 0.35, h * 0.5),
    ]
    faces = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], faces)
    return mesh


def pendulum_mesh() -> bpy.types.Mesh:
    """A flat bob at the origin and a rod up to the pivot at z = 3."""
    verts, faces = [], []

    def box(cx, cz, sx, sy, sz):
        base = len(verts)
        for dx, dy, dz in [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]:
            verts.append((cx + dx * sx, dy * sy, cz + dz * sz))
        faces.extend([tuple(base + i for i in f) for f in [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]])

    box(0.0, 1.6, 0.06, 0.06, 1.4)  # rod
    box(0.0, 0.0, 0.45, 0.2, 0.3)  # bob
    mesh = bpy.data.meshes.new("Pendulum")
    mesh.from_pydata(verts, [], faces)
    return mesh


def add_object(name: str, mesh: bpy.types.Mesh, mode: str) -> bpy.types.Object:
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    obj.rotation_mode = mode
    return obj


def key(obj: bpy.types.Object, frame: float, location, rotation) -> None:
    """Keys location and rotation; `rotation` is an Euler (XYZ) in degrees or a Quaternion."""
    obj.location = location
    if obj.rotation_mode == "QUATERNION":
        obj.rotation_quaternion = rotation
        obj.keyframe_insert("rotation_quaternion", frame=frame)
    else:
        obj.rotation_euler = Euler([math.radians(a) for a in rotation], obj.rotation_mode)
        obj.keyframe_insert("rotation_euler", frame=frame)
    obj.keyframe_insert("location", frame=frame)


def make_cyclic(obj: bpy.types.Object) -> None:
    for fc in demo_common.channels().object_fcurves(obj):
        fc.modifiers.new("CYCLES")


def build() -> None:
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.name = "ScrewBender demo"
    scene.frame_start, scene.frame_end = 1, 96

    # 1. The paper's L-shaped control cycle (Figure 1 f-j): eight poses, four of them rotated.
    lcycle = add_object("LCycle", wedge_mesh("LCycle", 1.2, 0.55, 0.35), "XYZ")
    corners = [(0, 0), (3, 0), (6, 0), (6, 2), (2, 2), (2, 6), (0, 6), (0, 3)]
    turns = {1: (0, 0, 90), 3: (0, 45, 180), 5: (60, 0, 90), 6: (0, -30, -90)}
    frames = [1, 13, 22, 37, 49, 57, 73, 85]
    for i, ((x, y), frame) in enumerate(zip(corners, frames)):
        key(lcycle, frame, (x, y, 0.0), turns.get(i, (0, 0, 0)))
    key(lcycle, 97, (0, 0, 0), (0, 0, 0))  # the first pose again closes the cycle
    make_cyclic(lcycle)

    # 2. A pendulum from two poses (Figure 7 left), keyed as an animator keys a bob: its
    # origin is the bob, so location and rotation both change and the swing about the pivot
    # is a screw that channel-by-channel interpolation does not follow.
    pendulum = add_object("Pendulum", pendulum_mesh(), "XYZ")
    pivot = Vector((14.0, 3.0, 4.0))
    for frame, angle in ((1, 50), (25, -50), (49, 50)):
        bob = pivot + Matrix.Rotation(math.radians(angle), 3, "Y") @ Vector((0.0, 0.0, -3.0))
        key(pendulum, frame, bob, (0, angle, 0))
    make_cyclic(pendulum)

    # 3. A block spinning through four poses (Figure 7 right): a quarter turn per key while it
    # goes round, rocking 40 degrees one way then the other; a full turn per cycle.
    block = add_object("SpinBlock", wedge_mesh("SpinBlock", 1.4, 0.6, 0.3), "XYZ")
    for i, frame in enumerate((1, 11, 21, 31, 41)):
        angle = 90 * i
        x, y = 3.0 * math.cos(math.radians(angle)), 3.0 * math.sin(math.radians(angle))
        rock = 40 if i % 2 == 0 else -40
        rotation = Euler((0, 0, math.radians(angle + 90))).to_matrix() @ Euler((math.radians(rock), 0, 0)).to_matrix()
        euler = rotation.to_euler("XYZ", Euler((0, 0, math.radians(angle + 90))))
        key(block, frame, (30 + x, 3 + y, 0.0), [math.degrees(a) for a in euler])
    make_cyclic(block)

    # 4. A mesh flown through six keys with uneven timing (open motion, quaternions).
    bpy.ops.mesh.primitive_monkey_add(size=1.2)
    flyer = bpy.context.object
    flyer.name = "Flyer"
    flyer.rotation_mode = "QUATERNION"
    path = [(1, (40, 0, 0)), (6, (43, 1.5, 1.0)), (20, (48, 7, 3.0)), (26, (46, 11, 4.0)), (50, (40, 10, 1.0)), (60, (37, 4, 0.0))]
    points = [Vector(p) for _, p in path]
    previous = None
    for i, (frame, location) in enumerate(path):
        # face the direction of flight (Suzanne looks down -Y), banked into the turn
        ahead = points[min(i + 1, len(points) - 1)] - points[max(i - 1, 0)]
        yaw = math.atan2(ahead.y, ahead.x) + math.pi / 2
        pitch = math.atan2(ahead.z, ahead.xy.length)
        bank = math.radians((-35, -20, 30, 45, 25, 0)[i])
        quat = Euler((-pitch, bank, yaw), "XYZ").to_quaternion()
        if previous is not None and quat.dot(previous) < 0:
            quat.negate()
        previous = quat
        key(flyer, frame, location, Quaternion(quat))

    for obj in scene.objects:
        obj.select_set(False)
    scene.frame_set(1)


def main() -> None:
    out = demo_common.out_dir()
    build()
    path = out / "demo_source.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    names = ", ".join(o.name for o in bpy.context.scene.objects)
    print(f"10_scene: {names} -> {path}")


if __name__ == "__main__":
    main()
