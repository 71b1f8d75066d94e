"""Motion capture (issue 18, item 7): a BVH clip written here, imported with Blender's own
importer (`bpy.ops.import_anim.bvh`), smoothed on all its bones by ONE Smooth Motion call
(Object Mode, the armature selected), and every bone's baked channels checked against
`polyscrew.sample` of its keys.

The reference is independent of the add-on's reading: each bone's key poses are composed with
scipy from the imported F-curves' key values (float32, read as float64), sampled in float64
with `polyscrew.sample` at the baked frames. The baked channels are stored as float32, so a
stored value v32 can differ from the float64 reference v by half a float32 unit in the last
place: |v32 - v| <= 2^-24 |v|, which for the values of this clip (locations below 2, Euler
angles below 4 rad) is below 2.4e-7; a rotation matrix composed from three such angles moves
by at most the sum of their errors, below 7.2e-7. Hence the 1e-6 bound on both locations and
rotation matrices, and locations are also checked to be the float32 rounding of the reference
to one unit in the last place.
"""

from __future__ import annotations

import re

import bpy
import numpy as np
import polyscrew

import bake_helpers as h
from conftest import addon_module

#: (name, parent, offset, channels): a small skeleton: hips (root, translated), spine, head,
#: an arm of two bones, a leg of two bones.
JOINTS = (
    ("Hips", None, (0.0, 0.0, 0.0), ("Xposition", "Yposition", "Zposition", "Zrotation", "Xrotation", "Yrotation")),
    ("Spine", "Hips", (0.0, 0.35, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
    ("Head", "Spine", (0.0, 0.4, 0.02), ("Zrotation", "Xrotation", "Yrotation")),
    ("LeftArm", "Spine", (0.2, 0.3, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
    ("LeftForeArm", "LeftArm", (0.3, 0.0, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
    # (at the root's head: Blender's importer then connects its only child to it)
    ("RightUpLeg", "Hips", (0.0, 0.0, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
    ("RightLeg", "RightUpLeg", (-0.1, -0.45, 0.0), ("Zrotation", "Xrotation", "Yrotation")),
)
#: Frames in the file (the importer keeps all but the first, the rest pose by convention).
FRAMES = 41
#: Largest difference allowed between a stored channel (float32) and the float64 reference;
#: see the module docstring for why it holds.
TOLERANCE = 1e-6


def motion(frames: int) -> np.ndarray:
    """(frames, channels) BVH values: smooth swings with a little capture jitter, in degrees
    (positions in scene units, below 1.5)."""
    rng = np.random.default_rng(18)
    t = np.arange(frames) / 24.0
    columns = []
    for j, (_, _, _, channels) in enumerate(JOINTS):
        for c, name in enumerate(channels):
            phase = 0.7 * j + 1.3 * c
            if name.endswith("position"):
                column = 0.5 * np.sin(2.0 * t + phase) + (0.9 if name == "Yposition" else 0.0) + 0.3 * t
            else:
                column = 35.0 * np.sin(3.0 * t + phase) + 10.0 * np.sin(7.0 * t + 2 * phase)
            columns.append(column + rng.normal(0.0, 0.4 if name.endswith("rotation") else 0.004, frames))
    return np.stack(columns, axis=1)


def write_bvh(path, frames: int = FRAMES) -> None:
    children = {name: [j for j in JOINTS if j[1] == name] for name, *_ in JOINTS}

    def joint(entry, depth: int) -> list[str]:
        name, parent, offset, channels = entry
        pad = "  " * depth
        head = f"{pad}{'ROOT' if parent is None else 'JOINT'} {name}"
        lines = [head, f"{pad}{{", f"{pad}  OFFSET {offset[0]:.6f} {offset[1]:.6f} {offset[2]:.6f}",
                 f"{pad}  CHANNELS {len(channels)} {' '.join(channels)}"]
        if children[name]:
            for child in children[name]:
                lines += joint(child, depth + 1)
        else:
            lines += [f"{pad}  End Site", f"{pad}  {{", f"{pad}    OFFSET 0.000000 0.200000 0.000000", f"{pad}  }}"]
        lines.append(f"{pad}}}")
        return lines

    lines = ["HIERARCHY"] + joint(JOINTS[0], 0)
    data = motion(frames)
    lines += ["MOTION", f"Frames: {frames}", "Frame Time: 0.041667"]
    lines += [" ".join(f"{v:.6f}" for v in row) for row in data]
    path.write_text("\n".join(lines) + "\n")


def import_bvh(path) -> bpy.types.Object:
    if not hasattr(bpy.ops.import_anim, "bvh"):
        bpy.ops.preferences.addon_enable(module="io_anim_bvh")
    assert bpy.ops.import_anim.bvh(filepath=str(path), global_scale=1.0, frame_start=1, rotate_mode="NATIVE") == {"FINISHED"}
    rig = bpy.context.view_layer.objects.active
    assert rig is not None and rig.type == "ARMATURE"
    return rig


def bone_curves(action, slot: str, bone: str, prop: str, size: int) -> np.ndarray:
    """(frames, values (N, size)) of a bone's curves in `action`."""
    channels = addon_module("blender.channels")
    path = f'pose.bones["{bone}"].{prop}'
    curves = {fc.array_index: fc for fc in channels.action_fcurves(action, slot) if fc.data_path == path}
    assert sorted(curves) == list(range(size)), (bone, prop, sorted(curves))
    points = [h.curve_points(curves[i]) for i in range(size)]
    for p in points[1:]:
        np.testing.assert_array_equal(p[:, 0], points[0][:, 0])
    return points[0][:, 0], np.stack([p[:, 1] for p in points], axis=1)


def test_a_bvh_clip_is_smoothed_on_all_its_bones_in_one_call(tmp_path, capfd):
    path = tmp_path / "walk.bvh"
    write_bvh(path)
    rig = import_bvh(path)
    bones = [b.name for b in rig.pose.bones]
    assert sorted(bones) == sorted(name for name, *_ in JOINTS)
    connected = {b.name for b in rig.data.bones if b.use_connect}
    assert connected == {"RightLeg"}
    source = rig.animation_data.action
    slot = addon_module("blender.channels").slot_identifier(rig)
    before = h.snapshot_action(source)

    h.select_only(rig)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(armature="BOTH", scheme="jarek", levels=3, timing="smooth", step=0.5) == {"FINISHED"}
    report = capfd.readouterr().out
    assert re.search(rf"Smoothed {len(bones)} bone\(s\)", report), report
    smoothed = rig.animation_data.action
    assert smoothed is not source and h.snapshot_action(source) == before

    worst = {"location": 0.0, "rotation": 0.0}
    moved = 0.0
    largest = {"location": 0.0, "angle": 0.0}
    for bone in bones:
        mode = rig.pose.bones[bone].rotation_mode
        assert mode in h.EULER_ORDERS  # the importer's NATIVE mode: the BVH channel order
        key_frames, key_angles = bone_curves(source, slot, bone, "rotation_euler", 3)
        has_location = any(fc.data_path == f'pose.bones["{bone}"].location' for fc in addon_module("blender.channels").action_fcurves(source, slot))
        # A connected bone's location is ignored by Blender: not read, not baked. Any other
        # bone's location is baked where it is keyed; where only its rotation is keyed, the
        # location stays constant (a screw through poses sharing their origin turns about an axis
        # through it) and stays unkeyed (issue 24, item 7).
        located = bone not in connected and has_location
        key_location = bone_curves(source, slot, bone, "location", 3)[1] if has_location else np.zeros((len(key_frames), 3))
        key_poses = h.compose(key_location, h.rotation_to_matrices(key_angles, mode))
        frames, angles = bone_curves(smoothed, slot, bone, "rotation_euler", 3)
        np.testing.assert_allclose(frames, np.arange(key_frames[0], key_frames[-1] + 0.25, 0.5))
        reference = polyscrew.sample(key_poses, key_frames, frames, scheme="jarek", levels=3, timing="smooth")
        rotation_error = np.abs(h.rotation_to_matrices(angles, mode) - reference[:, :3, :3]).max()
        at_keys = np.searchsorted(frames, key_frames)
        moved = max(moved, np.abs(h.rotation_to_matrices(angles[at_keys], mode) - key_poses[:, :3, :3]).max())
        worst["rotation"] = max(worst["rotation"], rotation_error)
        largest["angle"] = max(largest["angle"], np.abs(angles).max())
        if located:
            loc_frames, location = bone_curves(smoothed, slot, bone, "location", 3)
            np.testing.assert_array_equal(loc_frames, frames)
            expected = reference[:, :3, 3]
            worst["location"] = max(worst["location"], np.abs(location - expected).max())
            largest["location"] = max(largest["location"], np.abs(expected).max())
            # the stored float32 is the float32 rounding of the reference, to one unit in the last place
            ulps = np.abs(location.astype(np.float32).view(np.int32).astype(np.int64)
                          - expected.astype(np.float32).view(np.int32).astype(np.int64))
            assert ulps.max() <= 1, (bone, ulps.max())
        elif bone not in connected:  # location not keyed: constant, so left unkeyed
            assert np.abs(reference[:, :3, 3]).max() < 1e-9
            assert not any(
                fc.data_path == f'pose.bones["{bone}"].location' for fc in addon_module("blender.channels").action_fcurves(smoothed, slot)
            )
        else:  # no location was baked for a connected bone
            assert not any(
                fc.data_path == f'pose.bones["{bone}"].location' and len(fc.keyframe_points) > len(key_frames)
                for fc in addon_module("blender.channels").action_fcurves(smoothed, slot)
            )
    print(f"\nBVH clip, {len(bones)} bones ({len(connected)} connected), {FRAMES - 1} frames, one Smooth Motion call: "
          f"baked locations vs float64 polyscrew.sample {worst['location']:.1e} (largest {largest['location']:.2f}), "
          f"rotation matrices {worst['rotation']:.1e} (largest angle {largest['angle']:.2f} rad); off the keys at key frames by up to {moved:.3f}")
    assert largest["location"] < 2.0 and largest["angle"] < 4.0  # where the docstring's bound holds
    assert worst["location"] <= TOLERANCE and worst["rotation"] <= TOLERANCE
    # and the smoothing did something: Jarek approximates the jittery keys (it passes near,
    # not through them), so at the key frames the baked motion leaves the keys
    assert moved > 1e-3, moved
