# SPDX-License-Identifier: GPL-3.0-or-later
"""Swept regions and clearance: Blender data in and out of `polyscrew.sweep`.

The pipeline, per object (Rossignac-Kim, "Swept volumes"):

1. :func:`body_mesh` reads the evaluated mesh (modifiers applied) as triangles in the
   object's local frame, scaled by the object's (constant) world scale;
2. :func:`world_poses` samples the object's rigid world motion: at every key of the action
   made by Smooth Motion where there is one, otherwise at every frame of the scene's range;
   a mesh carried by a bone (:func:`bone_driver`: parented to it, or deformed rigidly by it
   through an Armature modifier) moves with the bone's world motion;
3. `polyscrew.sweep` builds the swept mesh (each pair of samples is one screw), each screw in
   the fewest steps that keep the swept surfaces within a tolerance of the exact ones (by
   default 0.2 % of the body's bounding radius);
   or, with Closed Volume (Build Swept Region's default), `polyscrew.sweep_closed` builds the
   region's boundary as a closed, consistently oriented, self-intersection-free mesh, every
   vertex within a tolerance (by default 0.5 % of the body's bounding-box diagonal; slower:
   seconds, many more triangles), its work told first (`polyscrew.sweep_closed_work`) and
   refused when it would run for minutes (:func:`sweep_report.closed_refusal`); a mesh that
   is not closed (decided from its triangles before any work, :func:`sweep_report.closed_choice`)
   refuses the run, or at Closed Volume's default gets the open sweep;
4. :func:`create_object` writes it into a new object of the "Swept Regions" collection.

Steps 1 to 3 run for every object before anything is created, so a refusal leaves the scene
as it was. :func:`clearance` measures a swept region against another object with
`mathutils.bvhtree.BVHTree`.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import bpy
import numpy as np
import polyscrew
from mathutils import Matrix, Vector
from mathutils.bvhtree import BVHTree

from ..pure import sweep_report
from . import bake, bulk, channels, curves, keys, owners, transaction

#: Name of the collection that receives swept regions.
COLLECTION = "Swept Regions"
#: A world scale that varies by more than this (relative) over the frame range is refused.
SCALE_TOLERANCE = 1e-5
#: A closed boundary's progress, in steps of its own (polyscrew reports fractions).
PROGRESS_STEPS = 1000
#: Custom property on a swept-region object: the name of the object it was swept from.
SOURCE_KEY = "screwbender_swept_from"


class SweepError(ValueError):
    """A refusal with a message for the user."""


@dataclass
class Swept:
    """One object's swept mesh, computed but not yet written into Blender."""

    obj: bpy.types.Object
    vertices: np.ndarray
    triangles: np.ndarray
    poses: np.ndarray
    seconds: float
    #: The tolerance asked for (world units) and the bound the sweep met (`polyscrew.sweep`'s
    #: `info`): every swept triangle within `error_bound` of the exact swept surface.
    tolerance: float = 0.0
    error_bound: float = 0.0
    #: The grid cell of a closed boundary (`polyscrew.sweep_closed`; 0 for the open sweep):
    #: every vertex and every edge's midpoint then within `error_bound` of the exact swept
    #: boundary; `attempts`: the grids it contoured (1 to 3, finer while the bound exceeded the
    #: tolerance); `vertex_bound`: the bound's part for the vertices alone.
    cell: float = 0.0
    attempts: int = 0
    vertex_bound: float = 0.0
    #: Why no finer grid was contoured though `error_bound` exceeds the tolerance (its memory),
    #: else None (`polyscrew.sweep_closed`'s ``finer_refused``; a bound over the tolerance
    #: without it: the finest grid missed it).
    finer_refused: str | None = None
    #: Closed Volume at its default on a mesh that is not closed: the open sweep instead
    #: (:func:`sweep_report.closed_choice`).
    fallback: bool = False


def body_mesh(obj: bpy.types.Object, depsgraph: bpy.types.Depsgraph) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) in the object's local frame and triangles (T, 3) of its evaluated mesh."""
    if obj.type != "MESH":
        raise SweepError(f"{obj.name}: not a mesh object")
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mesh.calc_loop_triangles()
        verts = np.empty(3 * len(mesh.vertices), dtype=np.float64)
        bulk.get(mesh.vertices, "co", verts)
        tris = np.empty(3 * len(mesh.loop_triangles), dtype=np.int64)
        bulk.get(mesh.loop_triangles, "vertices", tris)
    finally:
        evaluated.to_mesh_clear()
    return verts.reshape(-1, 3), tris.reshape(-1, 3)


# Meshes carried by a bone --------------------------------------------------------------

#: Modifiers that change a mesh's shape the same way wherever the mesh is (they use nothing
#: but the mesh itself): allowed anywhere in the stack of a mesh deformed by a bone.
SHAPE_ONLY_MODIFIERS = frozenset(
    {"SUBSURF", "MULTIRES", "BEVEL", "SOLIDIFY", "TRIANGULATE", "EDGE_SPLIT", "WEIGHTED_NORMAL", "WELD",
     "WIREFRAME", "DECIMATE", "UV_PROJECT", "UV_WARP"}
)
#: Blender's Armature modifier leaves a vertex whose weights sum to no more than this where it
#: is (`armature_deform.cc`: `contrib > 0.0001f`).
ARMATURE_WEIGHT_THRESHOLD = 1e-4


@dataclass
class BoneDriver:
    """The bone that carries a mesh: `armature.pose.bones[bone]`, through an Armature
    modifier (`deformed`) or as the mesh's parent bone."""

    armature: bpy.types.Object
    bone: str
    deformed: bool


def _before_armature_ok(mod: bpy.types.Modifier) -> bool:
    """Whether `mod`, before the Armature modifier, only builds the rest shape from the mesh
    itself (a mirror or array with no object)."""
    if mod.type == "MIRROR":
        return mod.mirror_object is None
    if mod.type == "ARRAY":
        return not mod.use_object_offset and mod.fit_type != "FIT_CURVE"
    return False


def bone_driver(obj: bpy.types.Object) -> BoneDriver | None:
    """The bone carrying the mesh `obj` rigidly, or None when no bone does (its own transform
    moves it); raises :class:`SweepError`, naming the mesh and why, for a bone deformation
    that is not rigid.

    Rigid: one Armature modifier (vertex groups, no envelopes, no mask group, not "multi")
    and every vertex weighted to one and the same deforming bone, which is not a curved
    B-Bone; no shape keys; other modifiers only those that shape the mesh by itself
    (:data:`SHAPE_ONLY_MODIFIERS`; before the Armature modifier also a mirror or array with
    no object). A vertex's weight need not be 1: Blender's Armature modifier divides by the
    sum of a vertex's weights, so a vertex weighted 0.5 to one bone alone follows it fully
    (only weights summing to no more than :data:`ARMATURE_WEIGHT_THRESHOLD` leave it behind).
    A mesh parented to a bone (no Armature modifier) is carried by it through its own world
    matrix.
    """
    name = obj.name
    if obj.parent is not None and obj.parent_type == "ARMATURE":
        raise SweepError(
            f"{name}: deformed through Armature Deform parenting; give it an Armature modifier instead "
            "(Object > Parent > Armature Deform adds one)"
        )
    modifiers = [m for m in obj.modifiers if m.show_viewport]
    armatures = [m for m in modifiers if m.type == "ARMATURE" and m.object is not None and m.object.type == "ARMATURE"]
    if not armatures:
        if obj.parent is not None and obj.parent_type == "BONE" and obj.parent.type == "ARMATURE" and obj.parent_bone:
            return BoneDriver(obj.parent, obj.parent_bone, False)
        return None
    if len(armatures) > 1:
        raise SweepError(
            f"{name}: deformed by {len(armatures)} Armature modifiers ({', '.join(m.name for m in armatures)}); "
            "a swept region needs a mesh carried rigidly by one bone"
        )
    mod = armatures[0]
    rig = mod.object
    why = ""
    if mod.use_bone_envelopes:
        why = f"its Armature modifier '{mod.name}' uses bone envelopes (they deform by distance to the bones)"
    elif not mod.use_vertex_groups:
        return None  # the modifier moves nothing
    elif mod.vertex_group:
        why = f"its Armature modifier '{mod.name}' is masked by vertex group '{mod.vertex_group}' (it blends with the rest shape)"
    elif mod.use_multi_modifier:
        why = f"its Armature modifier '{mod.name}' is a Multi Modifier (it blends with the modifiers before it)"
    if why:
        raise SweepError(f"{name}: {why}: not a rigid motion")
    index = modifiers.index(mod)
    for i, other in enumerate(modifiers):
        if other is mod or other.type in SHAPE_ONLY_MODIFIERS or (i < index and _before_armature_ok(other)):
            continue
        raise SweepError(
            f"{name}: its {other.type.replace('_', ' ').title()} modifier '{other.name}' may change its shape as it "
            "moves; a swept region needs a mesh carried rigidly by one bone (disable or apply it)"
        )
    keys_ = obj.data.shape_keys
    if keys_ is not None and len(keys_.key_blocks) > 1:
        raise SweepError(
            f"{name}: has {len(keys_.key_blocks) - 1} shape key(s), which change its shape; a swept region needs "
            "a mesh carried rigidly by one bone"
        )
    bone = _weighted_bone(obj, rig)
    data = rig.data.bones[bone]
    if data.bbone_segments > 1:
        raise SweepError(
            f"{name}: bone '{bone}' is a B-Bone with {data.bbone_segments} segments, which bends the mesh: "
            "not a rigid motion"
        )
    return BoneDriver(rig, bone, True)


def _weighted_bone(obj: bpy.types.Object, rig: bpy.types.Object) -> str:
    """The one deforming bone of `rig` every vertex of `obj` is weighted to; raises
    :class:`SweepError` naming the first vertex that is not."""
    name = obj.name
    deforming = {g.index: g.name for g in obj.vertex_groups if g.name in rig.data.bones and rig.data.bones[g.name].use_deform}
    # Blender has no bulk access to vertex weights (MeshVertex.groups has no foreach_get):
    # the weights are read vertex by vertex here, the one such loop of the add-on; nothing
    # is computed per vertex.
    weights = [
        sorted((deforming[g.group], g.weight) for g in v.groups if g.group in deforming and g.weight > 0.0)
        for v in obj.data.vertices
    ]
    found = None
    for i, entries in enumerate(weights):
        bones = sorted({b for b, _ in entries})
        total = sum(w for _, w in entries)
        if not bones or total <= ARMATURE_WEIGHT_THRESHOLD:
            raise SweepError(
                f"{name}: vertex {i} is weighted to no deforming bone of '{rig.name}' (it stays behind as the "
                "bones move): not a rigid motion"
            )
        if len(bones) > 1:
            listed = ", ".join(f"'{b}' {w:g}" for b, w in entries)
            raise SweepError(f"{name}: vertex {i} is weighted to {len(bones)} bones ({listed}): it bends, not a rigid motion")
        if found is None:
            found = bones[0]
        elif bones[0] != found:
            raise SweepError(
                f"{name}: its vertices follow different bones ('{found}', and '{bones[0]}' from vertex {i}): "
                "it bends, not a rigid motion"
            )
    if found is None:
        raise SweepError(f"{name}: has no vertices")
    return found


def carried_matrix(obj: bpy.types.Object, driver: BoneDriver | None) -> np.ndarray:
    """The world matrix the mesh's local coordinates go through at the current frame: its
    own `matrix_world`, or deformed by the bone through an Armature modifier
    `A B_pose B_rest^-1 A^-1 O` (A the armature's world matrix, B the bone's pose and rest
    matrices in armature space, O the mesh's world matrix: Blender's armature deform)."""
    world = np.array(obj.matrix_world, dtype=np.float64)
    if driver is None or not driver.deformed:
        return world
    rig = np.array(driver.armature.matrix_world, dtype=np.float64)
    pose_bone = driver.armature.pose.bones[driver.bone]
    deform = np.array(pose_bone.matrix, dtype=np.float64) @ np.linalg.inv(np.array(pose_bone.bone.matrix_local, dtype=np.float64))
    return rig @ deform @ np.linalg.inv(rig) @ world


def _carrier_frames(driver: BoneDriver, read: dict | None = None) -> list[float]:
    """The key frames of the smoothed action of the bone's armature that move the bone: its
    own transform curves, its parent bones' and the armature object's (`read`: see
    :func:`_key_frames`)."""
    rig = driver.armature
    chain, bone = {""}, rig.data.bones[driver.bone]
    while bone is not None:
        chain.add(bone.name)
        bone = bone.parent
    grouped = owners.curves_by_owner(channels.object_fcurves(rig))
    return _key_frames([fc for key in chain for fc in grouped.get(key, [])], read)


def _key_frames(fcurves: list, read: dict | None = None) -> list[float]:
    """The sorted distinct key frames (rounded to 1e-6) of `fcurves`: one foreach_get per curve.
    `read` (a dict the caller keeps over one run, by `fc.as_pointer()`) holds the frames of
    the curves read so far: meshes sharing an action or riding one rig read its curves once."""
    found = []
    for fc in fcurves:
        frames = None if read is None else read.get(fc.as_pointer())
        if frames is None:
            co = np.empty(2 * len(fc.keyframe_points), dtype=np.float32)
            bulk.get(fc.keyframe_points, "co", co)
            frames = co[0::2]
            if read is not None:
                read[fc.as_pointer()] = frames
        found.append(frames)
    if not found:
        return []
    return np.unique(np.round(np.concatenate(found).astype(np.float64), 6)).tolist()


def motion_frames(
    obj: bpy.types.Object, scene: bpy.types.Scene, driver: BoneDriver | None = None, read: dict | None = None
) -> np.ndarray:
    """The frames to sample: the keys of the smoothed action (Smooth Motion bakes one key per
    step, subframes included) where there is one (for a mesh carried by a bone, the keys of
    its armature's smoothed action moving that bone), else every frame of the scene's range.
    `read`: the key frames read so far in this run (:func:`_key_frames`)."""
    if driver is not None:
        if bake.source_of(driver.armature) is not None:
            frames = _carrier_frames(driver, read)
            if len(frames) >= 2:
                return np.asarray(frames, dtype=np.float64)
    elif bake.source_of(obj) is not None:
        frames = _key_frames(channels.object_fcurves(obj), read)
        if len(frames) >= 2:
            return np.asarray(frames, dtype=np.float64)
    return np.arange(scene.frame_start, scene.frame_end + 1, dtype=np.float64)


def _rigid_and_scale(name: str, matrices: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rigid poses (N, 4, 4) and the constant scale (3,) of world matrices (N, 4, 4), as
    `Matrix.decompose` splits them (column lengths, negated for a mirror; the rotation the
    nearest to the normalised columns); :class:`SweepError` when the scale changes."""
    linear = matrices[:, :3, :3]
    scales = np.linalg.norm(linear, axis=1)
    mirrored = np.linalg.det(linear) < 0.0
    scales[mirrored] *= -1.0
    u, _, vt = np.linalg.svd(linear / scales[:, None, :])
    poses = np.zeros_like(matrices)
    poses[:, :3, :3] = u @ vt
    poses[:, :3, 3] = matrices[:, :3, 3]
    poses[:, 3, 3] = 1.0
    _check_scale(name, scales)
    return poses, scales[0]


def _check_scale(name: str, scales: np.ndarray) -> None:
    spread = np.abs(scales - scales[0]).max()
    if spread > SCALE_TOLERANCE * max(1.0, np.abs(scales).max()):
        raise SweepError(f"{name}: its scale changes over the frame range (not a rigid motion)")


#: Properties whose curves also move an object (a pose bone: `rotation_mode`), which the
#: poses read from the curves leave out: an owner with one of them keyed is played by Blender.
_ALSO_MOVING = ("delta_location", "delta_rotation_euler", "delta_rotation_quaternion", "delta_scale", "rotation_mode")


class _Curves:
    """The transform curves, per owner, of the objects and bones whose world motion is read
    from the curves (:func:`world_poses_all`), with what Blender plays on top of them."""

    def __init__(self) -> None:
        self.per_owner: dict[tuple[int, str], dict] = {}  # (object, bone) -> {(prop, index): curve}
        self.steady: dict[tuple[int, str], bool] = {}

    def _action_alone(self, obj: bpy.types.Object) -> bool:
        """Whether Blender plays `obj`'s active action alone (no drivers, NLA, blending) and
        nothing else of the object data moves its bones."""
        key = (obj.as_pointer(), "*")
        if key not in self.steady:
            adt = obj.animation_data
            ok = adt is None or (
                not len(adt.drivers) and not keys.playing_strips(adt) and not getattr(adt, "use_tweak_mode", False)
                and not any(track.is_solo for track in adt.nla_tracks)
                and (adt.action is None or (adt.action_influence == 1.0 and adt.action_blend_type == "REPLACE"
                                            and adt.action_extrapolation == "HOLD"))
            )
            if ok and obj.type == "ARMATURE":
                data = obj.data.animation_data
                ok = (obj.data.pose_position == "POSE" and (data is None or (data.action is None and not len(data.drivers)))
                      and not any(len(pb.constraints) for pb in obj.pose.bones))
            if ok:
                listed = channels.object_fcurves(obj) if adt is not None and adt.action is not None else []
                paths = {fc.data_path for fc in listed}
                ok = not any(p.endswith(_ALSO_MOVING) for p in paths)
                grouped = owners.curves_by_owner(listed)
                for bone, found in grouped.items():
                    self.per_owner[obj.as_pointer(), bone] = found
            self.steady[key] = ok
        return self.steady[key]

    def owner_steady(self, obj: bpy.types.Object, bone: str = "") -> bool:
        """Whether the local matrix of the object (or its pose bone `bone`) follows from its
        own curves alone: nothing Blender's depsgraph must solve (constraints, drivers,
        physics, NLA, delta transforms, non-default bone inheritance)."""
        if not self._action_alone(obj):
            return False
        if bone:
            data = obj.data.bones[bone]
            return data.inherit_scale == "FULL" and data.use_inherit_rotation and data.use_local_location
        return (
            not len(obj.constraints) and obj.rigid_body is None and obj.rigid_body_constraint is None
            and not any(obj.delta_location) and tuple(obj.delta_rotation_euler) == (0.0, 0.0, 0.0)
            and tuple(obj.delta_rotation_quaternion) == (1.0, 0.0, 0.0, 0.0) and tuple(obj.delta_scale) == (1.0, 1.0, 1.0)
        )

    def played(self, obj: bpy.types.Object, bone: str = "") -> list:
        """The curves Blender plays on the owner's location, rotation (its mode) and scale
        (keyed, not muted)."""
        target = obj.pose.bones[bone] if bone else obj
        paths = keys.transform_paths(target.rotation_mode)
        found = []
        for fc in self.per_owner.get((obj.as_pointer(), bone), []):
            prop = fc.data_path.rsplit(".", 1)[-1] if bone else fc.data_path
            group_muted = fc.group is not None and fc.group.mute
            if prop in paths and len(fc.keyframe_points) and not fc.mute and not group_muted:
                found.append(fc)
        return found


def _chain(plays: _Curves, obj: bpy.types.Object, driver: BoneDriver | None) -> list[tuple] | None:
    """The owners ((object, bone)) whose curves make `obj`'s world matrix (and its driver
    bone's), or None when something else moves one of them (the depsgraph must play it)."""
    found: list[tuple] = []

    def bones_of(rig: bpy.types.Object, bone: str) -> bool:
        b = rig.data.bones.get(bone)
        while b is not None:
            if not plays.owner_steady(rig, b.name):
                return False
            found.append((rig, b.name))
            b = b.parent
        return True

    def objects_of(o: bpy.types.Object) -> bool:
        while o is not None:
            if not plays.owner_steady(o):
                return False
            found.append((o, ""))
            parent = o.parent
            if parent is None:
                return True
            if o.parent_type == "BONE" and parent.type == "ARMATURE":
                bone = parent.data.bones.get(o.parent_bone)
                if bone is None or bone.use_relative_parent or not bones_of(parent, o.parent_bone):
                    return False
            elif o.parent_type != "OBJECT" or parent.type == "CURVE":  # a curve parent may move it along its path
                return False
            o = parent
        return True

    if not objects_of(obj):
        return None
    if driver is not None and driver.deformed and not (objects_of(driver.armature) and bones_of(driver.armature, driver.bone)):
        return None
    return found


class _Evaluated:
    """Local matrices of objects and pose bones at `frames`, from their curves evaluated in
    one `polyscrew.evaluate_fcurves` call, composed into world matrices as Blender does."""

    def __init__(self, plays: _Curves, frames: np.ndarray, packed: curves.Packed | None, listed: list):
        self.frames = frames
        self.values = curves.evaluate_packed(packed, frames) if listed else np.zeros((0, len(frames)))
        self.row = {fc.as_pointer(): i for i, fc in enumerate(listed)}
        self.plays = plays
        self.memo: dict = {}
        #: `matrix_basis` per owner ((object pointer, bone)) made by :meth:`bases`.
        self.made: dict = {}

    def _channels(self, obj: bpy.types.Object, bone: str) -> tuple[str, dict]:
        """The owner's rotation mode and its channels (path -> (N, width)) at every frame: its
        curves' values, its static values where no curve plays (a connected bone's location 0)."""
        target = obj.pose.bones[bone] if bone else obj
        mode = target.rotation_mode
        n = len(self.frames)
        channels_ = {path: np.tile(np.array(getattr(target, path), dtype=np.float64), (n, 1)) for path in keys.transform_paths(mode)}
        for fc in self.plays.played(obj, bone):
            prop = fc.data_path.rsplit(".", 1)[-1] if bone else fc.data_path
            channels_[prop][:, fc.array_index] = self.values[self.row[fc.as_pointer()]]
        if bone and obj.data.bones[bone].use_connect:
            channels_["location"][:] = 0.0
        return mode, channels_

    def bases(self, owners: list[tuple]) -> None:
        """Makes :meth:`basis` of every owner ((object, bone)) of `owners`, their rotation
        matrices in one `polyscrew.rotation_matrices` call per rotation mode (row by row: the
        same matrices as one call per owner). A mode whose call refuses its values is left to
        :meth:`basis`, owner by owner, which names the owner's error as before."""
        by_mode: dict[str, list] = {}
        for obj, bone in owners:
            key = (obj.as_pointer(), bone)
            if key not in self.made:
                self.made[key] = None  # (once per owner)
                mode, channels_ = self._channels(obj, bone)
                by_mode.setdefault(mode, []).append((key, channels_, keys.transform_paths(mode)[1]))
        for mode, rows in by_mode.items():
            try:
                matrices = keys.rotation_matrices(np.concatenate([c[path] for _, c, path in rows]), mode)
            except ValueError:
                continue
            n = len(self.frames)
            for k, (key, c, _) in enumerate(rows):
                self.made[key] = keys.compose(c["location"], matrices[k * n : (k + 1) * n], c["scale"])

    def basis(self, obj: bpy.types.Object, bone: str = "") -> np.ndarray:
        """`matrix_basis` (N, 4, 4): `T R S` of the channels (Blender's BKE_object_to_mat4,
        BKE_pchan_to_mat4: a connected bone's location ignored); made by :meth:`bases` when
        it was."""
        made = self.made.get((obj.as_pointer(), bone))
        if made is not None:
            return made
        mode, channels_ = self._channels(obj, bone)
        return keys.compose(channels_["location"], keys.rotation_matrices(channels_[keys.transform_paths(mode)[1]], mode), channels_["scale"])

    def pose(self, rig: bpy.types.Object, bone: str) -> np.ndarray:
        """`pose_bone.matrix` (armature space): `P_parent R_parent^-1 R B` (R: rest
        `matrix_local`, B: basis), full inheritance."""
        key = ("bone", rig.as_pointer(), bone)
        if key not in self.memo:
            data = rig.data.bones[bone]
            rest = np.array(data.matrix_local, dtype=np.float64)
            local = rest @ self.basis(rig, bone)
            if data.parent is not None:
                offset = np.linalg.inv(np.array(data.parent.matrix_local, dtype=np.float64)) @ rest
                local = self.pose(rig, data.parent.name) @ offset @ self.basis(rig, bone)
            self.memo[key] = local
        return self.memo[key]

    def world(self, obj: bpy.types.Object) -> np.ndarray:
        """`matrix_world`: parent's world (at a parent bone's tail) `@ matrix_parent_inverse @ basis`."""
        key = ("object", obj.as_pointer())
        if key not in self.memo:
            world = self.basis(obj)
            parent = obj.parent
            if parent is not None:
                inverse = np.array(obj.matrix_parent_inverse, dtype=np.float64)
                above = self.world(parent)
                if obj.parent_type == "BONE":
                    bone = self.pose(parent, obj.parent_bone).copy()
                    bone[:, :3, 3] += bone[:, :3, 1] * parent.data.bones[obj.parent_bone].length  # to its tail
                    above = above @ bone
                world = above @ inverse @ world
            self.memo[key] = world
        return self.memo[key]

    def carried(self, obj: bpy.types.Object, driver: BoneDriver | None) -> np.ndarray:
        """:func:`carried_matrix` at every frame."""
        world = self.world(obj)
        if driver is None or not driver.deformed:
            return world
        rig = self.world(driver.armature)
        rest = np.array(driver.armature.data.bones[driver.bone].matrix_local, dtype=np.float64)
        deform = self.pose(driver.armature, driver.bone) @ np.linalg.inv(rest)
        return rig @ deform @ np.linalg.inv(rig) @ world


@dataclass
class _Plan:
    """Which objects' world poses are read from their curves (:func:`world_poses_all`)."""

    plays: _Curves
    #: Per object: the owners whose curves make its world matrix, None: played by Blender.
    chains: list
    #: The curves read, and their keys (None: none).
    listed: list
    packed: curves.Packed | None


def _plan(pairs: list[tuple[bpy.types.Object, BoneDriver | None]], scene: bpy.types.Scene, read: dict | None, fast: bool) -> _Plan:
    """Finds the objects ((object, driver) each) whose world matrix follows from curves alone
    and reads those curves, once (their key frames go into `read`, see :func:`_key_frames`)."""
    plays = _Curves()
    remapped = scene.render.frame_map_old != scene.render.frame_map_new
    chains = [None if remapped or not fast else _chain(plays, obj, driver) for obj, driver in pairs]
    listed, seen = [], set()
    for chain in chains:
        for obj, bone in chain or ():
            for fc in plays.played(obj, bone):
                if fc.as_pointer() not in seen:
                    seen.add(fc.as_pointer())
                    listed.append(fc)
    bad = {fc.as_pointer() for fc in listed if curves.problems(fc)}
    if bad:  # what polyscrew cannot play as Blender does: the depsgraph plays those owners
        chains = [None if c is None or any(fc.as_pointer() in bad for o, b in c for fc in plays.played(o, b)) else c
                  for c in chains]
        listed = [fc for fc in listed if fc.as_pointer() not in bad]
    packed = None
    if listed:
        try:
            packed = curves.read(listed)
        except curves.UnsupportedCurve:
            chains, listed = [None] * len(pairs), []
    if packed is not None and read is not None:
        bounds = packed.offsets.tolist()
        for i, fc in enumerate(listed):
            read.setdefault(fc.as_pointer(), packed.co[bounds[i] : bounds[i + 1], 0])
    return _Plan(plays, chains, listed, packed)


def world_poses_all(
    items: list[tuple[bpy.types.Object, np.ndarray, BoneDriver | None]], scene: bpy.types.Scene,
    read: dict | None = None, fast: bool = True, plan: _Plan | None = None,
) -> list[tuple[np.ndarray, np.ndarray]]:
    """:func:`world_poses` of several objects ((object, frames, driver) each) at once.

    Where an object's world matrix follows from transform curves alone (its own, its parents'
    and, for a mesh carried by a bone, the bones' and the armature's: no constraints, drivers,
    NLA, physics, delta transforms or non-default bone inheritance anywhere in the chain, no
    time remapping), every such curve is read once and evaluated at every frame in one
    `polyscrew.evaluate_fcurves` call (Blender's own values) and the matrices composed as
    Blender does. The others are played by Blender: one `frame_set` per frame for all of
    them together. `read`: the key frames read so far (:func:`_key_frames`), filled with the
    key frames of the curves read here. `fast=False` plays every object (the reference).
    `plan`: :func:`_plan` of the same objects, made already.
    """
    if plan is None:
        plan = _plan([(obj, driver) for obj, _, driver in items], scene, read, fast)
    out: list = [None] * len(items)
    evaluated = [i for i, chain in enumerate(plan.chains) if chain is not None]
    if evaluated:
        frames = np.unique(np.concatenate([items[i][1] for i in evaluated]))
        matrices = _Evaluated(plan.plays, frames, plan.packed, plan.listed)
        matrices.bases([owner for i in evaluated for owner in plan.chains[i]])
        for i in evaluated:
            obj, wanted, driver = items[i]
            out[i] = _rigid_and_scale(obj.name, matrices.carried(obj, driver)[np.searchsorted(frames, wanted)])
    played = [i for i, chain in enumerate(plan.chains) if chain is None]
    if played:
        for i, result in zip(played, _played_poses([items[i] for i in played], scene)):
            out[i] = result
    return out


def _played_poses(items: list, scene: bpy.types.Scene) -> list[tuple[np.ndarray, np.ndarray]]:
    """World poses of `items` as Blender plays them: one `frame_set` per frame of all their
    frames together, each object's carried matrix taken at its own frames."""
    frame, subframe = scene.frame_current, scene.frame_subframe
    frames = np.unique(np.concatenate([wanted for _, wanted, _ in items]))
    taken = [np.empty((len(wanted), 4, 4)) for _, wanted, _ in items]
    where = [np.searchsorted(frames, wanted) for _, wanted, _ in items]
    at = [{int(k): j for j, k in enumerate(w)} for w in where]
    try:
        for k, f in enumerate(frames):
            whole = math.floor(f)
            scene.frame_set(whole, subframe=float(f - whole))
            for (obj, _, driver), found, mine in zip(items, taken, at):
                j = mine.get(k)
                if j is not None:
                    found[j] = carried_matrix(obj, driver)
    finally:
        scene.frame_set(frame, subframe=subframe)
    out = []
    for (obj, _, _), found in zip(items, taken):
        poses, scales = [], []
        for matrix in found:
            loc, rot, scale = Matrix(matrix.tolist()).decompose()
            poses.append(np.array(Matrix.LocRotScale(loc, rot, None)))
            scales.append(np.array(scale))
        scales = np.array(scales)
        _check_scale(obj.name, scales)
        out.append((np.array(poses), scales[0]))
    return out


def world_poses(
    obj: bpy.types.Object, scene: bpy.types.Scene, frames: np.ndarray, driver: BoneDriver | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Rigid world poses (N, 4, 4) of `obj` (carried by `driver`, see :func:`carried_matrix`)
    at `frames` and its world scale (3,), which must stay constant (a swept region is for
    rigid motion): :func:`world_poses_all` of one object."""
    return world_poses_all([(obj, np.asarray(frames, dtype=np.float64), driver)], scene)[0]


def compute(
    obj: bpy.types.Object,
    context: bpy.types.Context,
    steps: int,
    caps: bool,
    tolerance: float | None = None,
    read: dict | None = None,
    closed: bool = False,
    cell: float | None = None,
    fallback: bool = False,
) -> Swept:
    """The swept mesh of `obj` along its world motion (nothing is created): each screw in the
    fewest steps (at least `steps`) within `tolerance` (world units; None: 0.2 % of the body's
    bounding radius; 0: exactly `steps`). `read`: a dict kept over one run of several objects
    (the key frames read so far: each curve is read once, :func:`_key_frames`). `closed`: the
    region's closed boundary instead (`polyscrew.sweep_closed`: every vertex within `tolerance`,
    None: 0.5 % of the body's extent, or a fixed grid `cell` in world units; `steps` and `caps`
    do not apply), refused before any is computed when one would sample more than
    :func:`sweep_report.closed_refusal` allows, or when the mesh is not closed (it has no
    inside) unless `fallback` (Closed Volume at its default): then the open sweep."""
    return compute_all([obj], context, steps, caps, tolerance, read, closed, cell, fallback)[0]


def _closed_progress(
    progress: Callable[[int, int], None] | None, done: int, total: int
) -> Callable[[float], None] | None:
    """`progress(done, total)` of a run as `polyscrew.sweep_closed`'s `progress(fraction)` of
    its closed boundary from `done` (None without `progress`)."""
    if progress is None:
        return None
    return lambda fraction: progress(done + int(PROGRESS_STEPS * fraction), total)


def compute_all(
    objects: list[bpy.types.Object],
    context: bpy.types.Context,
    steps: int,
    caps: bool,
    tolerance: float | None = None,
    read: dict | None = None,
    closed: bool = False,
    cell: float | None = None,
    fallback: bool = False,
    progress: Callable[[int, int], None] | None = None,
    decimate: bool = True,
) -> list[Swept]:
    """:func:`compute` of every object of `objects`, their world poses read together
    (:func:`world_poses_all`: the curves evaluated in one call where they alone move the
    objects, else one `frame_set` per frame for all). With `closed`, which objects get the
    closed boundary is decided from their meshes before any pose is read
    (:func:`sweep_report.closed_choice`): an open mesh refuses the run, or with `fallback` gets
    the open sweep (its :attr:`Swept.fallback` set). The open sweeps are computed before the
    closed boundaries, so a refusal comes before the long work; the results are in the
    objects' order. `progress(done, total)` follows the closed boundaries (seconds each), in
    thousandths of each. `decimate`: the closed boundaries with fewer triangles where flat."""
    scene = context.scene
    read = {} if read is None else read
    prepared = []
    for obj in objects:
        if obj.type != "MESH":
            raise SweepError(f"{obj.name}: not a mesh object")
        driver = bone_driver(obj)
        verts, tris = body_mesh(obj, context.evaluated_depsgraph_get())
        if driver is not None and driver.deformed:
            # The evaluated mesh is deformed by the bone's current pose: back into the frame the
            # bone carries, `C^-1 O v` (C: carried_matrix now, O: the mesh's world matrix).
            to_body = np.linalg.inv(carried_matrix(obj, driver)) @ np.array(obj.matrix_world, dtype=np.float64)
            verts = verts @ to_body[:3, :3].T + to_body[:3, 3]
        prepared.append((obj, driver, verts, tris))
    names = [obj.name for obj, _, _, _ in prepared]
    closed_meshes = [sweep_report.is_closed(tris) for _, _, _, tris in prepared] if closed else []
    kinds, refusal = sweep_report.closed_choice(names, closed_meshes, closed, fallback)
    if refusal is not None:
        raise SweepError(refusal)
    # The curves evaluated for the poses are read first: their key frames serve motion_frames.
    plan = _plan([(obj, driver) for obj, driver, _, _ in prepared], scene, read, True)
    items = []
    for obj, driver, _, _ in prepared:
        frames = motion_frames(obj, scene, driver, read)
        if len(frames) < 2:
            raise SweepError(f"{obj.name}: the frame range has a single frame; a motion needs two poses")
        items.append((obj, frames, driver))
    posed = world_poses_all(items, scene, read, plan=plan)
    # A closed boundary's grid: a cell given, else the tolerance's (None: the default).
    grid = {"cell": cell} if cell is not None else {"tolerance": tolerance}
    # Every closed boundary's work told before any object is computed.
    for (obj, _, verts, tris), (poses, scale), kind in zip(prepared, posed, kinds):
        if not kind:
            continue
        try:
            work = polyscrew.sweep_closed_work(verts * scale, tris, poses, **grid)
        except ValueError as err:
            raise SweepError(f"{obj.name}: {err}") from err
        refusal = sweep_report.closed_refusal(work, polyscrew.memory_budget())
        if refusal is not None:
            raise SweepError(f"{obj.name}: {refusal}")
    # The open sweeps (milliseconds) before the closed boundaries (seconds): an object the open
    # sweep refuses (a mesh without faces) stops the run before the long work, not after it.
    out: list = [None] * len(prepared)
    order = sorted(range(len(prepared)), key=lambda i: bool(kinds[i]))
    closed_total = PROGRESS_STEPS * sum(map(bool, kinds))
    closed_done = 0
    for i in order:
        (obj, _, verts, tris), (poses, scale) = prepared[i], posed[i]
        start = time.perf_counter()
        try:
            if kinds[i]:
                watch = _closed_progress(progress, closed_done, closed_total)
                v, t, info = polyscrew.sweep_closed(verts * scale, tris, poses, info=True, progress=watch,
                                                    decimate=decimate, **grid)
                closed_done += PROGRESS_STEPS
                out[i] = Swept(obj, v, t, poses, time.perf_counter() - start, info["tolerance"],
                               info["error_bound"], info["cell"], info["attempts"], info["vertex_bound"],
                               info["finer_refused"])
                continue
            v, t, info = polyscrew.sweep(verts * scale, tris, poses, steps=steps, caps=caps, tolerance=tolerance, info=True)
        except ValueError as err:
            raise SweepError(f"{obj.name}: {err}") from err
        out[i] = Swept(obj, v, t, poses, time.perf_counter() - start, info["tolerance"], info["error_bound"],
                       fallback=closed)
    return out


def collection(scene: bpy.types.Scene, t: transaction.Transaction | None = None) -> bpy.types.Collection:
    """The "Swept Regions" collection, created and linked to the scene when missing (the
    linking undone by `t` when it fails: a new collection goes anyway, an existing one that
    was not linked is unlinked again)."""
    coll = bpy.data.collections.get(COLLECTION)
    if coll is None:
        coll = bpy.data.collections.new(COLLECTION)
    if coll.name not in scene.collection.children:
        scene.collection.children.link(coll)
        if t is not None:

            def unlink() -> None:
                if coll.name in scene.collection.children:
                    scene.collection.children.unlink(coll)

            t.on_rollback(unlink)
    return coll


def mesh_from_arrays(name: str, vertices: np.ndarray, triangles: np.ndarray) -> bpy.types.Mesh:
    """A new triangle mesh from (V, 3) vertices and (T, 3) triangles (bulk foreach_set; the
    indices are trusted: `polyscrew.sweep` returns them in range and non-degenerate)."""
    mesh = bpy.data.meshes.new(name)
    n = len(triangles)
    co = np.ascontiguousarray(vertices, dtype=np.float32).ravel()
    corners = np.ascontiguousarray(triangles, dtype=np.int32).ravel()
    mesh.vertices.add(len(vertices))
    mesh.loops.add(3 * n)
    position = mesh.attributes.get("position")
    corner_vert = mesh.attributes.get(".corner_vert")
    if position is not None and corner_vert is not None:
        # The generic attributes take raw buffers (MeshLoop.vertex_index goes item by item).
        bulk.put(position.data, "vector", co)
        bulk.put(corner_vert.data, "value", corners)
    else:
        bulk.put(mesh.vertices, "co", co)
        bulk.put(mesh.loops, "vertex_index", corners)
    mesh.polygons.add(n)
    bulk.put(mesh.polygons, "loop_start", np.arange(0, 3 * n, 3, dtype=np.int32))
    mesh.update(calc_edges=True)
    return mesh


def create_object(swept: Swept, context: bpy.types.Context, t: transaction.Transaction | None = None) -> bpy.types.Object:
    """A new object in the "Swept Regions" collection holding the swept mesh (world frame:
    the open sweep or, computed with `closed`, the closed boundary). `t` undoes the linking
    of the collection when the operator fails."""
    name = f"{swept.obj.name} swept"
    mesh = mesh_from_arrays(name, swept.vertices, swept.triangles)
    obj = bpy.data.objects.new(name, mesh)
    collection(context.scene, t).objects.link(obj)
    obj[SOURCE_KEY] = swept.obj.name
    return obj


def triangle_count(mesh: bpy.types.Mesh) -> int:
    mesh.calc_loop_triangles()
    return len(mesh.loop_triangles)


def mesh_triangles(mesh: bpy.types.Mesh) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) and loop triangles (T, 3) of `mesh` (bulk foreach_get)."""
    mesh.calc_loop_triangles()
    verts = np.empty(3 * len(mesh.vertices), dtype=np.float64)
    bulk.get(mesh.vertices, "co", verts)
    tris = np.empty(3 * len(mesh.loop_triangles), dtype=np.int64)
    bulk.get(mesh.loop_triangles, "vertices", tris)
    return verts.reshape(-1, 3), tris.reshape(-1, 3)


def created_triangles(swept: Swept) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (V, 3) and triangles (T, 3) of the mesh made from `swept` by
    :func:`create_object`: what was written into it (float32, as the mesh holds it), not read
    back."""
    vertices = np.ascontiguousarray(swept.vertices, dtype=np.float32).astype(np.float64)
    return vertices, np.asarray(swept.triangles, dtype=np.int64)


# --- clearance ----------------------------------------------------------------------------


@dataclass
class Clearance:
    """The result of :func:`clearance`."""

    intersects: bool
    #: Smallest distance between the two surfaces (0 when they intersect).
    distance: float
    #: Polygon indices of each object that take part in an intersection.
    faces_a: list[int]
    faces_b: list[int]


def world_polygons(obj: bpy.types.Object, depsgraph: bpy.types.Depsgraph) -> tuple[list[Vector], list[tuple[int, ...]]]:
    """World-space vertices and polygons of the evaluated mesh (indices of `obj.data`'s
    polygons when there are no modifiers)."""
    evaluated = obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        mw = obj.matrix_world
        verts = [mw @ v.co for v in mesh.vertices]
        polys = [tuple(p.vertices) for p in mesh.polygons]
    finally:
        evaluated.to_mesh_clear()
    return verts, polys


def _nearest(tree: BVHTree, points: list[Vector]) -> float:
    best = math.inf
    for p in points:
        hit = tree.find_nearest(p)
        if hit[0] is not None and hit[3] < best:
            best = hit[3]
    return best


def is_closed(polys: list[tuple[int, ...]]) -> bool:
    """Whether every edge of the polygons is shared by exactly two of them (watertight)."""
    keys = [tuple(sorted((p[i], p[(i + 1) % len(p)]))) for p in polys for i in range(len(p))]
    if not keys:
        return False
    _, counts = np.unique(np.array(keys), axis=0, return_counts=True)
    return bool(np.all(counts == 2))


def inside(tree: BVHTree, point: Vector, scale: float) -> bool:
    """Whether `point` is inside the closed mesh of `tree`: odd number of crossings of a ray
    (in a direction unlikely to graze edges)."""
    direction = Vector((0.5773, 0.5774, 0.5773)).normalized()
    origin, crossings = point.copy(), 0
    for _ in range(10000):
        hit, _normal, _index, _dist = tree.ray_cast(origin, direction)
        if hit is None:
            break
        crossings += 1
        origin = hit + direction * (1e-7 * scale)
    return crossings % 2 == 1


def clearance(a: bpy.types.Object, b: bpy.types.Object, depsgraph: bpy.types.Depsgraph) -> Clearance:
    """Whether `a` and `b` intersect (BVH overlap of their polygons, or, for a closed mesh,
    one holding a vertex of the other inside) and their smallest distance (every vertex of
    each against the other's surface: exact for face-to-vertex and face-to-face closeness,
    within the edge length for edge-to-edge). The closed boundary made by Build Swept Region
    with Closed Volume has an inside (an object wholly within the region intersects it); the
    open superset made without it has none: only its surface counts."""
    va, pa = world_polygons(a, depsgraph)
    vb, pb = world_polygons(b, depsgraph)
    if not pa or not pb:
        raise SweepError(f"{a.name if not pa else b.name}: has no faces")
    ta = BVHTree.FromPolygons(va, pa, all_triangles=False)
    tb = BVHTree.FromPolygons(vb, pb, all_triangles=False)
    pairs = ta.overlap(tb)
    if pairs:
        return Clearance(True, 0.0, sorted({i for i, _ in pairs}), sorted({j for _, j in pairs}))
    scale = max((max(v) - min(v) for v in zip(*(va + vb))), default=1.0)
    for tree, polys, other in ((ta, pa, vb), (tb, pb, va)):
        if other and is_closed(polys) and inside(tree, other[0], scale):
            return Clearance(True, 0.0, [], [])
    distance = min(_nearest(ta, vb), _nearest(tb, va))
    return Clearance(False, distance, [], [])


def select_faces(obj: bpy.types.Object, faces: list[int]) -> None:
    """Selects exactly `faces` of `obj`'s mesh (Edit Mode shows them)."""
    mesh = obj.data
    mask = np.zeros(len(mesh.polygons), dtype=bool)
    mask[[f for f in faces if f < len(mask)]] = True
    bulk.put(mesh.polygons, "select", mask)
    mesh.update()
