"""The live preview and Insert Key on Motion for bones (issue 18, item 4).

A previewed armature shows its keyed bones: each bone's batches are `polyscrew.sample` of its
keys (composed with scipy from the F-curves' key values) in the bone's own space, and they
are placed in the world through the armature object and the parent bones as Blender poses
them at the current frame: mapped at a key frame, a key pose lands on Blender's own
`matrix_world @ PoseBone.matrix` there, for every Inherit Rotation / Inherit Scale / Local
Location option. Insert Key on Motion keys bones in Pose Mode and an armature's bones in
Object Mode; with the raw polyscrew the motion moves only by float32 key rounding.
"""

from __future__ import annotations

import math
import re

import bpy
import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h
from bone_helpers import armature, bone_key_matrices, key_bone, random_poses, select_bones, world_pose
from conftest import addon_module

FRAMES = [1.0, 6.0, 14.0, 20.0, 33.0]
CHAIN = ("Upper", "Fore", "Hand")


@pytest.fixture
def pd():
    """The overlay module; the overlay is left disabled after each test."""
    module = addon_module("ops.preview_draw")
    yield module
    for obj in bpy.data.objects:
        obj.screwbender_preview = False
    module.sync()


def keyed_rig(mode: str = "XYZ", own_keys: bool = True, gentle: bool = False):
    """The three-bone chain (Fore connected to Upper, Hand not) under a rotated empty, every
    bone keyed at FRAMES (Hand with scale too), and the armature object's own keys."""
    rig = armature()
    for k, bone in enumerate(CHAIN):
        scales = np.random.default_rng(k).uniform(0.7, 1.4, (len(FRAMES), 3)) if bone == "Hand" else None
        key_bone(rig, bone, FRAMES, random_poses(len(FRAMES), 11 * k + 3, gentle=gentle), mode, scales)
    if own_keys:
        for i, frame in enumerate(FRAMES):
            rig.location = (0.3 * i, 0.0, -0.1 * i)
            rig.rotation_euler = (0.0, 0.1 * i, 0.2 * i)
            rig.keyframe_insert("location", frame=frame)
            rig.keyframe_insert("rotation_euler", frame=frame)
    scene = bpy.context.scene
    scene.frame_set(int(FRAMES[0]))
    return rig


def set_smooth(scene, scheme="jarek", levels=3, timing="smooth", armature="BOTH") -> None:
    s = scene.screwbender
    s.scheme, s.levels, s.timing, s.range_mode, s.armature = scheme, levels, timing, "KEYS", armature


def bone_entry(pd, rig, bone):
    pd.refresh(bpy.context.scene)
    entry = pd.CACHE.entries[(rig.session_uid, bone)]
    assert entry.error == "", entry.error
    return entry.batches


def owner(rig, bone=""):
    return addon_module("blender.owners").Owner(rig, bone)


def rest_offset(rig, bone) -> np.ndarray:
    """The bone's rest pose relative to its parent's (or armature space for a root bone):
    `parent.matrix_local^-1 @ bone.matrix_local` (Blender's default bone transform)."""
    data = rig.data.bones[bone]
    local = np.array(data.matrix_local, dtype=np.float64)
    if data.parent is None:
        return local
    return np.linalg.inv(np.array(data.parent.matrix_local, dtype=np.float64)) @ local


# Batches --------------------------------------------------------------------------------


def test_bone_batches_equal_polyscrew_sample_mapped_through_the_pose(pd):
    scene = bpy.context.scene
    set_smooth(scene, "jarek", 3, "smooth")
    scene.screwbender_preview.instances = 11
    scene.screwbender_preview.show_raw = True
    rig = keyed_rig()
    rig.screwbender_preview = True
    pd.refresh(scene)
    # the armature's own keys and its three keyed bones, each its own entry
    assert set(pd.CACHE.entries) == {rig.session_uid} | {(rig.session_uid, b) for b in CHAIN}
    assert all(pd.CACHE.recomputed[f"Rig: {b}"] == 1 for b in CHAIN) and pd.CACHE.recomputed["Rig"] == 1

    worst_world = worst_formula = 0.0
    for bone in CHAIN:
        b = bone_entry(pd, rig, bone)
        frames, key_matrices = bone_key_matrices(rig, bone, with_scale=bone == "Hand")
        np.testing.assert_array_equal(b.key_frames, frames)
        np.testing.assert_allclose(b.keys, key_matrices, rtol=0, atol=1e-9)
        times = np.linspace(FRAMES[0], FRAMES[-1], 11)
        np.testing.assert_allclose(b.instance_times, times, rtol=0, atol=1e-12)
        rigid = key_matrices.copy()
        scales = None
        if bone == "Hand":
            scales = np.linalg.norm(key_matrices[:, :3, :3], axis=1)
            rigid[:, :3, :3] /= scales[:, None, :]
        expected = polyscrew.sample(rigid, frames, times, scheme="jarek", levels=3, timing="smooth")
        if scales is not None:
            smooth_scale = np.exp(polyscrew.sample_vectors(np.log(scales), frames, times, scheme="jarek", levels=3))
            expected[:, :3, :3] *= smooth_scale[:, None, :]
        np.testing.assert_allclose(b.instances, expected, rtol=0, atol=1e-9)
        if bone == "Fore":  # connected: Blender ignores its location, the motion has none
            assert np.abs(b.instances[:, :3, 3]).max() == 0.0 and np.abs(b.trajectory).max() == 0.0
        raw = polyscrew.sample(rigid, frames, times, scheme="jarek", levels=0, timing="linear")
        np.testing.assert_allclose(b.raw_instances[:, :3, 3], raw[:, :3, 3], rtol=0, atol=1e-9)

        # In the world: at each key frame the key pose, mapped through the armature and the
        # parent bones as posed there, is Blender's own bone matrix.
        for i, frame in enumerate(frames):
            scene.frame_set(int(frame))
            space = pd.owner_space(owner(rig, bone))
            assert space.matrix is not None  # default bones: one matrix, drawn by the GPU
            world = space.apply(b.keys[i : i + 1])[0]
            worst_world = max(worst_world, np.abs(world - world_pose(rig, bone)).max())
        # Between keys: the instances mapped at the current frame are the armature's world
        # matrix times the parent bone's pose times the rest offset times the sampled motion.
        scene.frame_set(9)
        parent = rig.pose.bones[bone].parent
        chain = np.array(rig.matrix_world) @ (np.array(parent.matrix) if parent else np.eye(4)) @ rest_offset(rig, bone)
        mapped = pd.owner_space(owner(rig, bone)).apply(b.instances)
        worst_formula = max(worst_formula, np.abs(mapped - chain @ expected).max())
    # The draw code maps default bones together (two foreach_get for the whole armature, the
    # parent's pose times the rest offset): the same spaces as Blender's bone transform above.
    shown = [owner(rig, b) for b in CHAIN] + [owner(rig)]
    together = pd.owner_spaces(rig, shown)
    for space, one in zip(together, shown):
        alone = pd.owner_space(one)
        np.testing.assert_allclose(space.location, alone.location, rtol=0, atol=2e-6)
        np.testing.assert_allclose(space.rotation, alone.rotation, rtol=0, atol=2e-6)
        assert space.matrix is not None
    print(f"\nbone key poses mapped to the world vs Blender's pose: {worst_world:.1e}; "
          f"instances vs armature @ parent pose @ rest offset @ sample: {worst_formula:.1e}")
    assert worst_world < 2e-6  # Blender's pose matrices are float32 (3e-7 measured)
    assert worst_formula < 2e-6


@pytest.mark.parametrize(
    "option",
    ["use_inherit_rotation", "use_local_location", "NONE", "ALIGNED", "AVERAGE", "FIX_SHEAR", "NONE_LEGACY"],
)
def test_bone_space_is_blenders_bone_transform_for_every_inherit_option(pd, option):
    """A parent keyed with rotation and non-uniform scale; the child bone with one non-default
    option: mapped key poses land on Blender's own pose at every key frame."""
    rig = armature(bones=(("Root", None, False), ("Child", "Root", False)))
    child = rig.data.bones["Child"]
    if option in ("use_inherit_rotation", "use_local_location"):
        setattr(child, option, False)
    else:
        child.inherit_scale = option
    scales = np.array([[1.0, 1.0, 1.0], [1.5, 0.7, 1.2], [0.6, 1.3, 0.9], [1.2, 1.2, 0.5], [0.8, 1.0, 1.6]])
    key_bone(rig, "Root", FRAMES, random_poses(len(FRAMES), 5), "QUATERNION", scales)
    key_bone(rig, "Child", FRAMES, random_poses(len(FRAMES), 6), "XYZ", scales[::-1])
    set_smooth(bpy.context.scene, "four_point", 3)
    scene = bpy.context.scene
    scene.frame_set(0)  # the pose shows the animation (else the last keyed pose is a live key at frame 1)
    rig.screwbender_preview = True
    b = bone_entry(pd, rig, "Child")
    worst = 0.0
    single = []
    for i, frame in enumerate(FRAMES):
        scene.frame_set(int(frame))
        space = pd.owner_space(owner(rig, "Child"))
        together = pd.owner_spaces(rig, [owner(rig, "Root"), owner(rig, "Child")])[1]
        np.testing.assert_allclose(together.apply(b.keys), space.apply(b.keys), rtol=0, atol=1e-12)
        single.append(space.matrix is not None)
        worst = max(worst, np.abs(space.apply(b.keys[i : i + 1])[0] - world_pose(rig, "Child")).max())
    print(f"\n{option}: mapped key poses vs Blender's pose {worst:.1e}; one matrix: {all(single)}")
    assert worst < 2e-6  # float32 pose matrices (up to 2.2e-7 measured)
    if option in ("use_inherit_rotation", "use_local_location"):
        assert not any(single)  # location and rotation through different matrices: mapped on the CPU


def test_hidden_bones_and_the_armatures_option(pd):
    scene = bpy.context.scene
    rig = keyed_rig()
    rig.data.bones["Hand"].hide = True
    select_bones(rig, [])
    rig.screwbender_preview = True
    for mode, expected in (
        ("BOTH", {rig.session_uid, (rig.session_uid, "Upper"), (rig.session_uid, "Fore")}),
        ("BONES", {(rig.session_uid, "Upper"), (rig.session_uid, "Fore")}),
        ("OBJECT", {rig.session_uid}),
    ):
        set_smooth(scene, armature=mode)
        pd.refresh(scene)
        assert set(pd.CACHE.entries) == expected, mode
    set_smooth(scene, armature="BONES")
    select_bones(rig, ["Hand"])  # a hidden bone is previewed when selected
    pd.refresh(scene)
    assert (rig.session_uid, "Hand") in pd.CACHE.entries


def test_bone_geometry_is_an_octahedral_bone_of_the_bones_length():
    preview = addon_module("blender.preview")
    g = preview.bone_geometry(2.0)
    assert g.kind == "BONE" and g.points.shape == (6, 3) and g.edges.shape == (12, 2) and g.tris.shape == (8, 3)
    np.testing.assert_allclose(g.points[0], (0, 0, 0))
    np.testing.assert_allclose(g.points[1], (0, 2, 0))
    # every edge of the octahedron appears in exactly two triangles: a closed surface
    edges = {}
    for tri in g.tris:
        for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
            edges[tuple(sorted((int(a), int(b))))] = edges.get(tuple(sorted((int(a), int(b)))), 0) + 1
    assert set(edges) == {tuple(sorted(map(int, e))) for e in g.edges} and set(edges.values()) == {2}
    box = preview.bone_geometry(2.0, box=True)
    assert box.kind == "BOX"
    np.testing.assert_allclose(box.points.min(axis=0), (-0.2, 0.0, -0.2))
    np.testing.assert_allclose(box.points.max(axis=0), (0.2, 2.0, 0.2))


# Live update ----------------------------------------------------------------------------


def test_editing_a_bone_key_recomputes_that_bone_only_and_posing_a_parent_nothing(pd):
    scene = bpy.context.scene
    set_smooth(scene, "four_point", 3)
    rig = keyed_rig()
    rig.screwbender_preview = True
    bpy.context.view_layer.update()
    pd.refresh(scene)
    count = dict(pd.CACHE.recomputed)
    before = bone_entry(pd, rig, "Hand").instances.copy()
    curve = next(fc for fc in h.fcurves(rig) if fc.data_path == 'pose.bones["Hand"].location' and fc.array_index == 1)
    for attr in ("co", "handle_left", "handle_right"):
        getattr(curve.keyframe_points[2], attr)[1] += 0.5
    bpy.context.view_layer.update()
    assert pd.CACHE.recomputed["Rig: Hand"] == count["Rig: Hand"] + 1
    assert all(pd.CACHE.recomputed[name] == count[name] for name in ("Rig", "Rig: Upper", "Rig: Fore"))
    after = bone_entry(pd, rig, "Hand")
    assert np.abs(after.instances - before).max() > 0.05
    frames, key_matrices = bone_key_matrices(rig, "Hand", with_scale=True)
    np.testing.assert_allclose(after.keys, key_matrices, atol=1e-9)
    # playing the timeline (the parents move) recomputes nothing: only the space changes
    count = dict(pd.CACHE.recomputed)
    spaces = []
    for frame in (3, 9, 17, 25):
        scene.frame_set(frame)
        bpy.context.view_layer.update()
        pd.refresh(scene)
        spaces.append(pd.owner_space(owner(rig, "Hand")).location.copy())
    assert pd.CACHE.recomputed == count
    assert np.abs(spaces[0] - spaces[-1]).max() > 0.1


def test_rotating_a_bone_at_a_key_frame_previews_the_moved_key(pd):
    scene = bpy.context.scene
    set_smooth(scene, "four_point", 3)
    rig = keyed_rig(mode="QUATERNION", own_keys=False)
    rig.screwbender_preview = True
    scene.frame_set(14)  # the third key
    original = bone_entry(pd, rig, "Fore").instances.copy()
    pb = rig.pose.bones["Fore"]
    pb.rotation_quaternion = Rotation.from_euler("xyz", [0.4, -0.2, 0.9]).as_quat()[[3, 0, 1, 2]]
    bpy.context.view_layer.update()
    live = bone_entry(pd, rig, "Fore")
    frames, key_matrices = bone_key_matrices(rig, "Fore")
    key_matrices[2, :3, :3] = h.rotation_to_matrices(np.array([pb.rotation_quaternion]), "QUATERNION")[0]
    expected = polyscrew.sample(key_matrices, frames, live.instance_times, scheme="four_point", levels=3)
    np.testing.assert_allclose(live.instances, expected, atol=1e-9)
    assert np.abs(live.instances - original).max() > 0.1
    with pytest.raises(RuntimeError, match="Rig: Fore: moved at a key frame but not keyed"):
        bpy.ops.screwbender.preview_apply()


# Offscreen drawing ----------------------------------------------------------------------


def test_offscreen_drawing_of_bones(pd):
    from test_preview import ensure_gpu, ortho_view

    reason = ensure_gpu(pd)
    if reason:
        pytest.skip(f"no GPU drawing in this Blender: {reason}")
    scene = bpy.context.scene
    set_smooth(scene, "jarek", 3, armature="BONES")
    settings = scene.screwbender_preview
    settings.instance_color = (0.0, 0.0, 1.0, 1.0)
    settings.key_color = (1.0, 0.0, 0.0, 1.0)
    rig = armature(bones=(("Root", None, False), ("Child", "Root", False)), holder=False)
    rig.data.bones["Child"].use_inherit_rotation = False  # drawn through the CPU-mapped path
    key_bone(rig, "Root", FRAMES, random_poses(len(FRAMES), 1))
    key_bone(rig, "Child", FRAMES, random_poses(len(FRAMES), 2))
    scene.frame_set(9)
    rig.screwbender_preview = True
    pd.refresh(scene)
    heads = []
    for bone in ("Root", "Child"):
        space = pd.owner_space(owner(rig, bone))
        assert (space.matrix is None) == (bone == "Child")
        heads.append(space.apply(pd.CACHE.entries[(rig.session_uid, bone)].batches.keys)[:, :3, 3])
    heads = np.concatenate(heads)
    center = (heads.min(axis=0) + heads.max(axis=0)) / 2
    size = float(np.ptp(heads[:, :2], axis=0).max()) * 1.4 + 3.0
    view, projection = ortho_view(center, size)
    width = height = 200
    pixels, drawn = pd.render_offscreen(scene, bpy.context.view_layer, view, projection, width, height)
    assert drawn == 2
    rgb = pixels[..., :3]
    red = (rgb[..., 0] > 0.5) & (rgb[..., 1] < 0.5) & (rgb[..., 2] < 0.5)
    blue = (rgb[..., 2] > 0.5) & (rgb[..., 0] < 0.5) & (rgb[..., 1] < 0.5)
    assert red.sum() > 30 and blue.sum() > 30, (red.sum(), blue.sum())
    for p in heads:  # every key head lands (within 2 pixels) on a key-coloured pixel
        x = (p[0] - center[0]) / size * width + width / 2
        y = (p[1] - center[1]) / size * height + height / 2
        assert red[max(0, int(y) - 2) : int(y) + 3, max(0, int(x) - 2) : int(x) + 3].any(), (p, x, y)
    assert pd._last_draw_error == ""


# Apply ----------------------------------------------------------------------------------


def test_apply_preview_bakes_the_bones_shown(pd):
    scene = bpy.context.scene
    set_smooth(scene, "four_point", 4, armature="BONES")
    scene.screwbender.step = 1.0
    scene.screwbender_preview.instances = 9  # frames 1, 5, ..., 33: on the baked frames
    rig = keyed_rig()
    rig.screwbender_preview = True
    shown = {bone: bone_entry(pd, rig, bone).instances.copy() for bone in CHAIN}
    times = bone_entry(pd, rig, "Upper").instance_times
    own_before = [(fc.data_path, fc.array_index, len(fc.keyframe_points)) for fc in h.fcurves(rig) if "pose" not in fc.data_path]
    assert bpy.ops.screwbender.preview_apply() == {"FINISHED"}
    assert rig.animation_data.action.name.endswith(".smooth") and not rig.screwbender_preview
    for bone in CHAIN:
        frames, baked = bone_key_matrices(rig, bone, with_scale=bone == "Hand")
        rows = np.searchsorted(frames, times)
        np.testing.assert_array_equal(frames[rows], times)
        np.testing.assert_allclose(baked[rows], shown[bone], rtol=0, atol=2e-5 * (1 + np.abs(shown[bone]).max()))
    # Bones Only: the armature object's own keys are untouched
    assert [(fc.data_path, fc.array_index, len(fc.keyframe_points)) for fc in h.fcurves(rig) if "pose" not in fc.data_path] == own_before


# Insert Key on Motion -------------------------------------------------------------------


def bone_motion(rig, bone, times, scheme="jarek", levels=0, timing="linear"):
    frames, matrices = bone_key_matrices(rig, bone)
    return polyscrew.sample(matrices, frames, times, scheme=scheme, levels=levels, timing=timing)


def run_insert_key(capfd) -> list[tuple[str, float, float]]:
    capfd.readouterr()
    assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
    out = capfd.readouterr().out
    found = re.findall(r"(Rig[^:]*: \w+): key at frame \S+; the motion moved by at most (\S+) \(frame [^)]*\) and turned by at most (\S+) deg", out)
    assert found, out
    return [(name, float(move), math.radians(float(turn))) for name, move, turn in found]


@pytest.mark.parametrize("mode", ["XYZ", "QUATERNION", "AXIS_ANGLE"])
def test_insert_key_on_a_bone_with_the_raw_polyscrew_keeps_the_motion(pd, mode, capfd):
    scene = bpy.context.scene
    set_smooth(scene, "jarek", 0, "linear")
    rig = keyed_rig(mode=mode, gentle=True)  # no spins: the raw polyscrew is one screw per key span
    frame = 10.0  # 4/8 of the way from the key at 6 to the key at 14
    times = np.linspace(FRAMES[0], FRAMES[-1], 200)
    before = {bone: bone_motion(rig, bone, times) for bone in CHAIN}
    keys_before = {bone: bone_key_matrices(rig, bone) for bone in CHAIN}
    others_before = h.snapshot_action(rig.animation_data.action)
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    select_bones(rig, ["Hand", "Fore"])
    scene.frame_set(int(frame))
    reported = run_insert_key(capfd)
    bpy.ops.object.mode_set(mode="OBJECT")
    assert sorted(name for name, *_ in reported) == ["Rig: Fore", "Rig: Hand"]
    for bone in ("Fore", "Hand"):
        frames_before, matrices_before = keys_before[bone]
        frames_after, matrices_after = bone_key_matrices(rig, bone)
        np.testing.assert_array_equal(frames_after, np.insert(frames_before, 2, frame))
        np.testing.assert_array_equal(np.delete(matrices_after, 2, axis=0), matrices_before)  # old keys untouched
        exact = polyscrew.interpolate(matrices_before[1], matrices_before[2], 0.5)
        rounding = np.abs(matrices_after[2] - exact).max()  # F-curves store float32
        assert rounding < 1e-6
        after = bone_motion(rig, bone, times)
        moved = np.abs(after - before[bone]).max()
        assert moved <= 2.0 * rounding + 1e-12, (bone, moved, rounding)
        outside = (times <= FRAMES[1]) | (times >= FRAMES[2])
        assert np.abs(after[outside] - before[bone][outside]).max() < 1e-12
        with capfd.disabled():
            print(f"\n{mode} {bone}: float32 key rounding {rounding:.2e}, motion change at 200 frames {moved:.2e}")
    # the connected bone got no location key; Upper and the armature's own curves are unchanged
    paths = {fc.data_path for fc in h.fcurves(rig)}
    fore_location = [fc for fc in h.fcurves(rig) if fc.data_path == 'pose.bones["Fore"].location']
    assert all(len(fc.keyframe_points) == len(FRAMES) for fc in fore_location)
    assert 'pose.bones["Hand"].location' in paths
    new = {c["path"]: c for bag in h.snapshot_action(rig.animation_data.action)["bags"] for c in bag["curves"]}
    for bag in others_before["bags"]:
        for c in bag["curves"]:
            if 'pose.bones["Upper"]' in c["path"][0] or not c["path"][0].startswith("pose") or "Fore\"].location" in c["path"][0]:
                assert new[c["path"]] == c, c["path"]


def test_insert_key_in_object_mode_keys_the_armatures_bones(pd, capfd):
    scene = bpy.context.scene
    set_smooth(scene, "four_point", 4, armature="BONES")
    rig = keyed_rig()
    channels = addon_module("blender.channels")
    bag = channels.container(rig.animation_data.action, channels.assigned_slot(rig))
    for fc in [fc for fc in h.fcurves(rig) if fc.data_path == 'pose.bones["Upper"].location']:
        channels.remove_fcurve(bag, fc)  # Upper keyed on its rotation only
    h.select_only(rig)
    scene.frame_set(25)
    counts = {b: len(next(fc for fc in h.fcurves(rig) if fc.data_path == f'pose.bones["{b}"].rotation_euler').keyframe_points) for b in CHAIN}
    reported = run_insert_key(capfd)
    assert sorted(name for name, *_ in reported) == [f"Rig: {b}" for b in sorted(CHAIN)]
    for bone in CHAIN:
        frames, _ = h.channel(rig, f'pose.bones["{bone}"].rotation_euler', 3)
        assert len(frames) == counts[bone] + 1 and 25.0 in frames
    # Upper's location, unkeyed but not ignored (Upper is not connected), is keyed now, in the
    # F-curve group named after the bone, as Blender keys bones
    upper = [fc for fc in h.fcurves(rig) if fc.data_path == 'pose.bones["Upper"].location']
    assert sorted(fc.array_index for fc in upper) == [0, 1, 2]
    assert all(len(fc.keyframe_points) == 1 and fc.group is not None and fc.group.name == "Upper" for fc in upper)
    own = [fc for fc in h.fcurves(rig) if fc.data_path == "location"]
    assert all(len(fc.keyframe_points) == len(FRAMES) for fc in own)  # Bones Only
    # 4-point moves a little near the new key; the connected Fore has no translation to move
    moves = {name: (move, turn) for name, move, turn in reported}
    assert moves["Rig: Fore"][0] == 0.0 and 0.0 < moves["Rig: Fore"][1] < 0.5
    assert all(0.0 < moves[f"Rig: {b}"][0] < 1.0 for b in ("Upper", "Hand"))
