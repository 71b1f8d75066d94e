"""Issue 27: Build Swept Region's world poses without one `frame_set` per frame per object.

Where transform curves alone move an object (and its parents, and the bone carrying it), its
world poses are its curves evaluated in one `polyscrew` call and composed as Blender does
(`swept.world_poses_all`); they must equal `matrix_world` (the carried matrix of a mesh an
Armature modifier moves) read after `scene.frame_set` at every frame, subframes included. An
object with a constraint is played by Blender instead, and the frames are set once for all
such objects together (counted with a `frame_change_post` handler).
"""

from __future__ import annotations

import bpy
import numpy as np
from mathutils import Matrix

import bake_helpers as h
from bone_helpers import armature, key_bone, random_poses
from conftest import addon_module

FRAMES = np.arange(1.0, 24.01, 0.5)  # every frame and every half frame


def keyed(obj, seed: int, mode: str = "XYZ", scale: bool = False) -> None:
    """Bezier keys on location and rotation (and a constant non-unit scale) at uneven frames."""
    obj.rotation_mode = mode
    poses = random_poses(4, seed, reach=0.8)
    h.key_poses(obj, [1, 7, 15, 24], poses, np.full((4, 3), 1.5) if scale else None)


def mesh(name: str) -> bpy.types.Object:
    return h.new_object(name, "MESH")


def played(obj, frames, deform=None) -> np.ndarray:
    """What Blender plays: `matrix_world` (or the carried matrix of a bone's Armature
    modifier, `A B_pose B_rest^-1 A^-1 O`) after `frame_set`, frame by frame."""
    scene = bpy.context.scene
    out = []
    for f in frames:
        scene.frame_set(int(np.floor(f)), subframe=float(f - np.floor(f)))
        world = np.array(obj.matrix_world)
        if deform is not None:
            rig, bone = deform
            pb = rig.pose.bones[bone]
            a = np.array(rig.matrix_world)
            world = a @ np.array(pb.matrix) @ np.linalg.inv(np.array(pb.bone.matrix_local)) @ np.linalg.inv(a) @ world
        out.append(world)
    scene.frame_set(1)
    return np.array(out)


def posed_counting_frame_sets(items) -> tuple[list, list]:
    """`swept.world_poses_all(items)` and the frames Blender was set to meanwhile."""
    sets = []
    handler = lambda scene, *args: sets.append(scene.frame_current)  # noqa: E731
    bpy.app.handlers.frame_change_post.append(handler)
    try:
        posed = addon_module("blender.swept").world_poses_all(items, bpy.context.scene)
    finally:
        bpy.app.handlers.frame_change_post.remove(handler)
    return posed, sets


def scene_with_every_chain():
    """An object; a child (with a parent inverse) of an animated parent; a rig parented to an
    animated empty, in Pose Mode, with a mesh parented to a bone (below a connected one) and a
    mesh deformed by another through an Armature modifier."""
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 24
    body = mesh("Body")
    keyed(body, 1, scale=True)
    parent = h.new_object("Parent", "EMPTY", "QUATERNION")
    keyed(parent, 2, "QUATERNION")
    child = mesh("Child")
    child.parent = parent
    child.matrix_parent_inverse = Matrix.Translation((0.3, -0.2, 0.5)) @ Matrix.Rotation(0.4, 4, "X")
    keyed(child, 3, "ZXY")
    rig = armature(bones=(("Root", None, False), ("Arm", "Root", False), ("Hand", "Arm", True)), holder=True)
    keyed(rig.parent, 4)
    for i, bone in enumerate(("Root", "Arm", "Hand")):
        key_bone(rig, bone, [1, 9, 24], random_poses(3, 10 + i, reach=0.4), mode=("XYZ", "QUATERNION", "YZX")[i])
    prop = mesh("Prop")
    prop.parent, prop.parent_type, prop.parent_bone = rig, "BONE", "Hand"
    skin = mesh("Skin")
    group = skin.vertex_groups.new(name="Arm")
    group.add(list(range(len(skin.data.vertices))), 1.0, "REPLACE")
    modifier = skin.modifiers.new("Armature", "ARMATURE")
    modifier.object = rig
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    return {"Body": (body, None), "Child": (child, None), "Prop": (prop, None), "Skin": (skin, (rig, "Arm"))}


def test_world_poses_from_the_curves_equal_blenders_matrix_world_at_every_frame():
    swept = addon_module("blender.swept")
    scene = bpy.context.scene
    cases = scene_with_every_chain()
    items, expected = [], {}
    for name, (obj, deform) in cases.items():
        items.append((obj, FRAMES, swept.bone_driver(obj)))
        expected[name] = played(obj, FRAMES, deform)
    plan = swept._plan([(obj, driver) for obj, _, driver in items], scene, None, True)
    assert all(chain is not None for chain in plan.chains), "every chain read from its curves"
    assert items[3][2] is not None and items[3][2].deformed and items[2][2] is not None
    posed, sets = posed_counting_frame_sets(items)
    assert sets == [], "no frame_set on the fast path"
    for (name, _), (poses, scale) in zip(cases.items(), posed):
        got = poses.copy()
        got[:, :3, :3] *= scale[None, None, :]
        error = np.abs(got - expected[name]).max()
        print(f"{name}: largest difference from matrix_world over {len(FRAMES)} frames {error:.2e}")
        assert error < 1e-5, name
        np.testing.assert_allclose(np.einsum("nji,njk->nik", poses[:, :3, :3], poses[:, :3, :3]),
                                   np.broadcast_to(np.eye(3), (len(FRAMES), 3, 3)), atol=1e-12)


def test_an_object_with_a_constraint_is_played_once_per_frame_for_all():
    """Two objects with a constraint (and one without): those two take the frame_set path,
    which sets each frame once for both; their poses equal matrix_world there too."""
    swept = addon_module("blender.swept")
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 24
    leader = mesh("Leader")
    keyed(leader, 5)
    followers = []
    for i in range(2):
        follower = mesh(f"Follower{i}")
        keyed(follower, 6 + i)
        constraint = follower.constraints.new("COPY_LOCATION")
        constraint.target = leader
        constraint.use_offset = True
        followers.append(follower)
    frames = np.arange(1.0, 25.0)
    items = [(o, frames, None) for o in (leader, *followers)]
    plan = swept._plan([(o, None) for o, _, _ in items], scene, None, True)
    assert plan.chains[0] is not None and plan.chains[1] is None and plan.chains[2] is None
    expected = [played(o, frames) for o in followers]
    posed, sets = posed_counting_frame_sets(items)
    print(f"frame_set calls for 2 constrained objects x {len(frames)} frames: {len(sets)}")
    assert len(sets) == len(frames) + 1  # each frame once, then the current frame back
    for (poses, scale), want in zip(posed[1:], expected):
        got = poses.copy()
        got[:, :3, :3] *= scale[None, None, :]
        assert np.abs(got - want).max() < 1e-5
