"""Build Swept Region for a mesh carried by a bone (issue 18, item 6).

A prop deformed rigidly by one bone (an Armature modifier, every vertex weighted to that
bone) is swept along the bone's world motion: the sampled poses are the rigid poses that
carry the prop's rest mesh onto Blender's own deformed mesh at every frame (Kabsch fit with
scipy, independent of the add-on), the closed region holds every instance of the deformed
mesh, and every vertex of the open region lies on an instance between two frames. A prop
parented to a bone moves with it. Anything that bends the mesh is refused, naming the mesh
and why, and creates nothing.
"""

from __future__ import annotations

import bpy
import numpy as np
import polyscrew
import pytest
from mathutils import Vector
from mathutils.bvhtree import BVHTree
from scipy.spatial.transform import Rotation

import bake_helpers as h
from bone_helpers import armature, key_bone, random_poses
from conftest import addon_module

CUBE_V = [(x, y, z) for z in (-0.2, 0.2) for y in (-0.3, 0.3) for x in (-0.1, 0.1)]
CUBE_F = [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]
LAST = 24


def rig_with_prop(weights=None, parent_bone: bool = False):
    """A two-bone arm (Arm, and Hand not connected to it) whose armature object moves too;
    a box prop at the hand, carried by the Hand bone through an Armature modifier (every
    vertex weighted 1.0, or `weights`: per vertex {bone: weight}) or, with `parent_bone`,
    parented to the bone."""
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, LAST
    rig = armature(bones=(("Arm", None, False), ("Hand", "Arm", False)), holder=False)
    key_bone(rig, "Arm", [1, 12, LAST], random_poses(3, 4, reach=0.0))
    key_bone(rig, "Hand", [1, 10, LAST], random_poses(3, 9, reach=0.3))
    for frame, x in ((1, 0.0), (LAST, 1.5)):
        rig.location = (x, 0.0, 0.0)
        rig.keyframe_insert("location", frame=frame)
    mesh = bpy.data.meshes.new("Prop")
    hand = np.array(rig.data.bones["Hand"].head_local)
    mesh.from_pydata([tuple(np.array(v) + hand + (0.3, 0.0, 0.4)) for v in CUBE_V], [], CUBE_F)
    prop = bpy.data.objects.new("Prop", mesh)
    scene.collection.objects.link(prop)
    prop.parent = rig
    if parent_bone:
        prop.parent_type, prop.parent_bone = "BONE", "Hand"
        prop.matrix_parent_inverse = (rig.matrix_world @ rig.pose.bones["Hand"].matrix).inverted()
    else:
        groups = {name: prop.vertex_groups.new(name=name) for name in ("Arm", "Hand", "Paint")}
        groups["Paint"].add(list(range(8)), 0.3, "REPLACE")  # not a bone: ignored by the modifier
        for i in range(8):
            for bone, w in (weights[i] if weights else {"Hand": 1.0}).items():
                groups[bone].add([i], w, "REPLACE")
        prop.modifiers.new("Armature", "ARMATURE").object = rig
        prop.modifiers.new("Triangulate", "TRIANGULATE")  # shapes the mesh by itself: allowed
    h.select_only(prop)
    scene.frame_set(5)
    return rig, prop


def deformed_world(prop, frame: int) -> np.ndarray:
    """Blender's own deformed mesh of `prop` at `frame`, in the world."""
    scene = bpy.context.scene
    scene.frame_set(frame)
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = prop.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    co = np.empty(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", co)
    evaluated.to_mesh_clear()
    world = np.array(prop.matrix_world)
    return co.reshape(-1, 3) @ world[:3, :3].T + world[:3, 3]


def kabsch(rest: np.ndarray, world: np.ndarray) -> np.ndarray:
    """The rigid pose carrying `rest` onto `world` (scipy), and how far it misses."""
    a, b = rest.mean(axis=0), world.mean(axis=0)
    rot, _ = Rotation.align_vectors(world - b, rest - a)
    pose = h.rigid(b - rot.apply(a), rot.as_matrix())[0]
    return pose


def rest_vertices(prop) -> np.ndarray:
    return np.array([tuple(v.co) for v in prop.data.vertices])


def swept_objects():
    coll = bpy.data.collections.get("Swept Regions")
    return list(coll.objects) if coll else []


def test_a_prop_deformed_by_a_bone_is_swept_along_the_bones_world_motion():
    rig, prop = rig_with_prop()
    swept = addon_module("blender.swept")
    rest = rest_vertices(prop)
    frames = range(1, LAST + 1)
    poses, misfit = [], 0.0
    for f in frames:
        world = deformed_world(prop, f)
        pose = kabsch(rest, world)
        poses.append(pose)
        misfit = max(misfit, np.abs(rest @ pose[:3, :3].T + pose[:3, 3] - world).max())
    poses = np.array(poses)
    assert misfit < 1e-5  # Blender's deformed mesh is the rest mesh moved rigidly
    assert np.ptp(poses[:, :3, 3], axis=0).max() > 1.0  # and it moves

    driver = swept.bone_driver(prop)
    assert (driver.armature, driver.bone, driver.deformed) == (rig, "Hand", True)
    computed = swept.compute(prop, bpy.context, steps=4, caps=True)
    np.testing.assert_allclose(computed.poses, poses, rtol=0, atol=2e-5)

    # The closed region holds every vertex of Blender's deformed mesh at every frame.
    voxel = 0.03
    assert bpy.ops.screwbender.sweep(steps=4, caps=True, closed=True, voxel_size=voxel) == {"FINISHED"}
    (region,) = swept_objects()
    assert region["screwbender_swept_from"] == "Prop"
    tree = BVHTree.FromObject(region, bpy.context.evaluated_depsgraph_get())
    outside = -np.inf
    for f in frames:
        for p in deformed_world(prop, f):
            loc, normal, _, _ = tree.find_nearest(Vector(p))
            outside = max(outside, (Vector(p) - loc).dot(normal))

    # Every vertex of the open region (the same sweep before Closed Volume remeshes it) lies
    # on an instance of the body along the screws between the frames' poses (8 per span).
    dense = np.concatenate(
        [polyscrew.interpolate(a, b, np.linspace(0, 1, 8, endpoint=False)) for a, b in zip(poses, poses[1:])]
        + [poses[-1:]]
    )
    tris = [(0, 2, 3), (0, 3, 1), (4, 5, 7), (4, 7, 6), (0, 1, 5), (0, 5, 4), (2, 6, 7), (2, 7, 3), (0, 4, 6),
            (0, 6, 2), (1, 3, 7), (1, 7, 5)]
    points = [tuple(p) for pose in dense for p in rest @ pose[:3, :3].T + pose[:3, 3]]
    polys = [tuple(8 * k + i for i in t) for k in range(len(dense)) for t in tris]
    instances = BVHTree.FromPolygons(points, polys)
    off = max(instances.find_nearest(Vector(tuple(v)))[3] for v in computed.vertices)
    print(f"\nprop on a bone: pose fit {misfit:.1e}, instances outside the closed region by {outside:.4f} "
          f"(voxel {voxel}), open region vertices off the instances by at most {off:.1e}")
    assert outside <= voxel
    # 4 sweep steps per span fall on 4 of the 8 instances: the region's vertices are body
    # points at instance poses (a region swept along another motion would be far off)
    assert off < 1e-5


def test_partial_weights_on_one_bone_follow_it_fully():
    """Blender's Armature modifier divides by the sum of a vertex's weights: a vertex weighted
    0.4 to one bone alone follows it as fully as one weighted 1.0, and the prop sweeps the same."""
    swept = addon_module("blender.swept")
    rig, full = rig_with_prop()
    expected = swept.compute(full, bpy.context, steps=2, caps=True)
    world_full = deformed_world(full, 17)
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    rig, partial = rig_with_prop(weights=[{"Hand": 0.4 if i % 2 else 1.0} for i in range(8)])
    np.testing.assert_allclose(deformed_world(partial, 17), world_full, rtol=0, atol=1e-6)
    got = swept.compute(partial, bpy.context, steps=2, caps=True)
    np.testing.assert_allclose(got.poses, expected.poses, rtol=0, atol=1e-6)
    assert len(got.triangles) > 0


def test_a_prop_parented_to_a_bone_follows_the_smoothed_bone():
    scene = bpy.context.scene
    rig, prop = rig_with_prop(parent_bone=True)
    swept = addon_module("blender.swept")
    assert swept.bone_driver(prop).deformed is False
    h.select_only(rig)
    assert bpy.ops.screwbender.smooth(armature="BOTH", step=0.5) == {"FINISHED"}
    frames = swept.motion_frames(prop, scene, swept.bone_driver(prop))
    np.testing.assert_allclose(frames, np.arange(1.0, LAST + 0.25, 0.5))  # the smoothed bones' baked keys
    computed = swept.compute(prop, bpy.context, steps=2, caps=True)
    for i in (0, 7, 20, len(frames) - 1):
        h.evaluated_basis(prop, [frames[i]])  # sets the frame
        world = np.array(prop.matrix_world)
        np.testing.assert_allclose(computed.poses[i], world, rtol=0, atol=2e-5)


def snapshot():
    return (sorted(o.name for o in bpy.data.objects), sorted(m.name for m in bpy.data.meshes),
            sorted(c.name for c in bpy.data.collections))


def _two_bones(rig, prop):
    prop.vertex_groups["Arm"].add([3], 0.5, "REPLACE")


def _no_bone(rig, prop):
    prop.vertex_groups["Hand"].remove([2])


def _other_bone(rig, prop):
    prop.vertex_groups["Hand"].remove([4, 5, 6, 7])
    prop.vertex_groups["Arm"].add([4, 5, 6, 7], 1.0, "REPLACE")


def _shape_keys(rig, prop):
    prop.shape_key_add(name="Basis")
    prop.shape_key_add(name="Bulge").data[0].co = (9.0, 9.0, 9.0)


def _displace(rig, prop):
    prop.modifiers.new("Wobble", "DISPLACE")


def _mirror_after(rig, prop):
    prop.modifiers.new("Mirror", "MIRROR")  # after the Armature modifier: mirrors the moving mesh


def _envelopes(rig, prop):
    prop.modifiers["Armature"].use_bone_envelopes = True


def _mask(rig, prop):
    prop.modifiers["Armature"].vertex_group = "Paint"


def _bbone(rig, prop):
    rig.data.bones["Hand"].bbone_segments = 4


def _two_modifiers(rig, prop):
    prop.modifiers.new("Armature.001", "ARMATURE").object = rig


REFUSALS = {
    "two bones": (_two_bones, r"Prop: vertex 3 is weighted to 2 bones \('Arm' 0.5, 'Hand' 1\): it bends"),
    "no bone": (_no_bone, r"Prop: vertex 2 is weighted to no deforming bone of 'Rig' \(it stays behind"),
    "other bone": (_other_bone, r"Prop: its vertices follow different bones \('Hand', and 'Arm' from vertex 4\)"),
    "shape keys": (_shape_keys, r"Prop: has 1 shape key\(s\), which change its shape"),
    "displace": (_displace, r"Prop: its Displace modifier 'Wobble' may change its shape as it moves"),
    "mirror after": (_mirror_after, r"Prop: its Mirror modifier 'Mirror' may change its shape as it moves"),
    "envelopes": (_envelopes, r"Prop: its Armature modifier 'Armature' uses bone envelopes"),
    "mask": (_mask, r"Prop: its Armature modifier 'Armature' is masked by vertex group 'Paint'"),
    "b-bone": (_bbone, r"Prop: bone 'Hand' is a B-Bone with 4 segments, which bends the mesh"),
    "two modifiers": (_two_modifiers, r"Prop: deformed by 2 Armature modifiers"),
}


@pytest.mark.parametrize("case", sorted(REFUSALS))
def test_a_bending_prop_is_refused_naming_the_mesh_and_why(case):
    change, message = REFUSALS[case]
    rig, prop = rig_with_prop()
    change(rig, prop)
    h.select_only(prop)
    before = snapshot()
    with pytest.raises(RuntimeError, match=message) as error:
        bpy.ops.screwbender.sweep()
    print(f"\n{case}: {error.value}")
    assert snapshot() == before


def test_a_mirror_before_the_armature_modifier_is_allowed():
    rig, prop = rig_with_prop()
    mirror = prop.modifiers.new("Mirror", "MIRROR")
    while prop.modifiers[0] != mirror:
        bpy.ops.object.modifier_move_up(modifier="Mirror")
    assert bpy.ops.screwbender.sweep(steps=2, closed=False) == {"FINISHED"}
