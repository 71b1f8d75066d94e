"""Flips are flips, spins are spins (issue 24, items 4 and 5): keys set from matrices, whose
Euler channels wrap, smooth into the short screw; the spins an animator typed keep turning
as Blender plays them; the option Turns (Auto / As Blender Plays / Shortest) decides; and the
report says where the result departs from what Blender played. References: Blender's own
playback (`frame_set` + `matrix_world` / `matrix_basis`) and the helix the keys were set from."""

from __future__ import annotations

import math

import bpy
import numpy as np
import pytest
from mathutils import Matrix
from scipy.spatial.transform import Rotation

import bake_helpers as h
import bone_helpers as bh

#: The helix: radius, pitch (units per radian), orientation of the body at theta = 0.
RADIUS, PITCH = 1.5, 0.25
TILT = Rotation.from_euler("xyz", [0.4, -0.3, 0.2]).as_matrix()
#: More than 90 degrees per key (109 on average), at uneven frames.
STEPS = np.radians([109.0, 96.0, 121.0, 109.0, 100.0, 117.0, 109.0, 112.0])
THETAS = np.concatenate([[0.3], 0.3 + np.cumsum(STEPS)])
FRAMES = [1, 6, 14, 19, 30, 35, 44, 52, 58]
#: Float32 key storage of values up to about 3 units.
ON_HELIX = 1e-5


def world_helix(parent_world: np.ndarray) -> np.ndarray:
    """The key poses: the helix about the parent's Z axis, in the world."""
    return parent_world @ h.circle_poses(THETAS, RADIUS, PITCH, TILT)


def off_helix(world: np.ndarray, parent_world: np.ndarray) -> np.ndarray:
    """Per frame: distance of a world pose from the helix (max abs matrix entry)."""
    return h.screw_deviation(np.linalg.inv(parent_world) @ world, RADIUS, PITCH, TILT)


def wrapped(values: np.ndarray) -> bool:
    """Whether some Euler channel jumps by more than half a turn between two keys, all keys
    inside -180..180 (what keys set from matrices look like)."""
    return bool(np.abs(values).max() <= math.pi + 1e-6 and np.abs(np.diff(values, axis=0)).max() > math.pi)


def keyed_object():
    """A mesh in ZXY mode under a rotated, moved parent, keyed by setting `matrix_world` to
    the helix poses (Blender computes the Euler values, inside -180..180)."""
    parent = h.new_object("Holder", "EMPTY")
    parent.location, parent.rotation_euler = (1.0, -2.0, 0.5), (0.3, -0.2, 0.9)
    obj = h.new_object("Helix", "MESH", "ZXY")
    obj.parent = parent
    bpy.context.view_layer.update()
    parent_world = np.array(parent.matrix_world)
    for frame, pose in zip(FRAMES, world_helix(parent_world)):
        obj.matrix_world = Matrix(pose.tolist())
        obj.keyframe_insert("location", frame=frame)
        obj.keyframe_insert("rotation_euler", frame=frame)
    h.select_only(obj)
    values = np.array([[fc.evaluate(f) for fc in sorted(
        (fc for fc in h.fcurves(obj) if fc.data_path == "rotation_euler"), key=lambda fc: fc.array_index)] for f in FRAMES])
    assert wrapped(values), np.degrees(values)

    def world(frames):
        scene = bpy.context.scene
        out = []
        for f in frames:
            scene.frame_set(int(f))
            out.append(np.array(obj.matrix_world))
        return np.array(out)

    return obj, parent_world, world


def keyed_bone():
    """The Hand bone (under Fore, in a rig under a rotated empty) in ZXY mode, keyed by
    setting `matrix_basis` to the helix poses; Pose Mode, Hand selected."""
    rig = bh.armature()
    pb = rig.pose.bones["Hand"]
    pb.rotation_mode = "ZXY"
    for frame, pose in zip(FRAMES, h.circle_poses(THETAS, RADIUS, PITCH, TILT)):
        pb.matrix_basis = Matrix(pose.tolist())
        pb.keyframe_insert("location", frame=frame)
        pb.keyframe_insert("rotation_euler", frame=frame)
    values = np.array([[fc.evaluate(f) for fc in sorted(
        (fc for fc in h.fcurves(rig) if fc.data_path == bh.bone_path("Hand", "rotation_euler")),
        key=lambda fc: fc.array_index)] for f in FRAMES])
    assert wrapped(values), np.degrees(values)
    h.select_only(rig)
    bpy.ops.object.mode_set(mode="POSE")
    bh.select_bones(rig, ["Hand"])
    # the bone's helix in the world: the rig and the parent bones stay put, so the world pose
    # is a constant rigid transform of matrix_basis, measured from Blender at frame 1
    scene = bpy.context.scene
    scene.frame_set(1)
    to_world = np.array(rig.matrix_world) @ np.array(pb.matrix) @ np.linalg.inv(np.array(pb.matrix_basis))

    def world(frames):
        out = []
        for f in frames:
            scene.frame_set(int(f))
            out.append(np.array(rig.matrix_world) @ np.array(pb.matrix))
        return np.array(out)

    return rig, to_world, world


@pytest.mark.parametrize("kind", ["object", "bone"])
def test_helix_keyed_from_matrices_stays_on_its_helix(sb, kind, capfd):
    """Every frame on the helix with the defaults; As Blender Plays (the behaviour before
    Turns) reproduces Blender's flips and leaves it."""
    owner, parent_world, world = keyed_object() if kind == "object" else keyed_bone()
    every = np.arange(FRAMES[0], FRAMES[-1] + 1.0)
    blender = off_helix(world(every), parent_world).max()
    capfd.readouterr()

    assert bpy.ops.screwbender.smooth(turns="BLENDER") == {"FINISHED"}
    before = off_helix(world(every), parent_world).max()
    report_before = capfd.readouterr().out
    if kind == "bone":  # Revert works on objects
        bpy.ops.object.mode_set(mode="OBJECT")
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    if kind == "bone":
        bpy.ops.object.mode_set(mode="POSE")
        bh.select_bones(owner, ["Hand"])

    assert bpy.ops.screwbender.smooth() == {"FINISHED"}  # the defaults: Turns Auto
    after = off_helix(world(every), parent_world)
    report = capfd.readouterr().out
    print(f"\n{bpy.app.version_string} helix keyed from matrices ({kind}, ZXY, under a parent, "
          f"{np.degrees(STEPS).mean():.0f} degrees per key): off the helix over {len(every)} frames: "
          f"Blender {blender:.3f}, As Blender Plays (before) {before:.3f}, Auto (defaults) {after.max():.1e}")
    print(report.strip())
    assert after.max() < ON_HELIX, np.flatnonzero(after >= ON_HELIX) + FRAMES[0]
    assert before > 0.3, "As Blender Plays was expected to reproduce the flips"
    assert "flip" not in report_before or "as Blender plays them" in report_before
    # the report counts the removed flips and names the owner, the frames and the departure
    name = "Helix" if kind == "object" else "Hand"
    removed = [line for line in report.splitlines() if "removed" in line and "flip(s)" in line]
    assert removed and name in removed[0] and "at frames" in removed[0], report
    departs = [line for line in report.splitlines() if "departs from what Blender played" in line]
    assert departs and name in departs[0] and "flips removed" in departs[0], report
    if kind == "bone":
        bpy.ops.object.mode_set(mode="OBJECT")


def flip_count(report: str) -> int:
    line = next(line for line in report.splitlines() if "flip(s)" in line)
    return int(line.split("removed ")[1].split(" flip(s)")[0])


def test_removed_flips_are_counted_where_blender_wraps(sb, capfd):
    """The count of removed flips is the number of key spans where an Euler channel of the
    stored keys jumps by more than half a turn (each helix span here wraps or not)."""
    obj, _, _ = keyed_object()
    values = np.array([[fc.evaluate(f) for fc in sorted(
        (fc for fc in h.fcurves(obj) if fc.data_path == "rotation_euler"), key=lambda fc: fc.array_index)] for f in FRAMES])
    jumps = int(np.sum(np.abs(np.diff(values, axis=0)).max(axis=1) > math.pi))
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    report = capfd.readouterr().out
    print(f"\nwraps in the stored keys: {jumps}; report: {report.strip()}")
    assert jumps >= 2 and flip_count(report) == jumps


def keyed_turns():
    """Z keyed as typed: 0 -> 270 (a typed spin), then as from matrices: 100 -> -150 (a wrap,
    110 degrees the short way), then -150 -> -20 (a plain move)."""
    obj = h.new_object("Turner", "MESH", "XYZ")
    for f, z in ((1, 0.0), (21, 270.0), (31, 100.0), (41, -150.0), (51, -20.0)):
        obj.rotation_euler = (0.0, 0.0, math.radians(z))
        obj.location = (0.05 * f, 0.0, 0.0)
        obj.keyframe_insert("rotation_euler", frame=f)
        obj.keyframe_insert("location", frame=f)
    h.select_only(obj)
    return obj


def z_turns(obj, spans) -> list[float]:
    """Degrees turned about Z over each (start, end) span, accumulated frame by frame from
    Blender's playback of the object's current action (quarter frames)."""
    out = []
    for a, b in spans:
        m = h.evaluated_basis(obj, np.arange(a, b + 0.01, 0.25))
        z = np.unwrap(np.arctan2(m[:, 1, 0], m[:, 0, 0]))
        out.append(float(np.degrees(z[-1] - z[0])))
    return out


SPANS = [(1, 21), (21, 31), (31, 41), (41, 51)]


@pytest.mark.parametrize(
    "turns, want",
    [
        # the typed spin turns 270; the wrap 100 -> -150 turns 110 the short way (Blender: -250)
        ("AUTO", [270.0, -170.0, 110.0, 130.0]),
        ("BLENDER", [270.0, -170.0, -250.0, 130.0]),
        # every span the short way: 270 becomes -90, 170 stays 170 the same way round
        ("SHORTEST", [-90.0, -170.0, 110.0, 130.0]),
    ],
)
def test_turns_option(sb, turns, want, capfd):
    obj = keyed_turns()
    blender = z_turns(obj, SPANS)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(turns=turns) == {"FINISHED"}
    report = capfd.readouterr().out
    ours = z_turns(obj, SPANS)
    print(f"\nTurns {turns}: turn per span {np.round(ours, 1).tolist()} (Blender {np.round(blender, 1).tolist()}); "
          f"report: {report.strip()}")
    np.testing.assert_allclose(blender, [270.0, -170.0, -250.0, 130.0], atol=0.5)
    np.testing.assert_allclose(ours, want, atol=2.0)
    # the key poses are hit whatever the option
    keys = h.evaluated_basis(obj, [f for f, _ in SPANS] + [51])
    obj_action = obj.animation_data.action
    source = obj_action["screwbender_source"]
    obj.animation_data.action = source
    keyed = h.evaluated_basis(obj, [f for f, _ in SPANS] + [51])
    obj.animation_data.action = obj_action
    assert np.abs(keys - keyed).max() < 1e-5
    if turns == "AUTO":
        assert "removed 1 flip(s) (Euler wrap(s) taken the short way) at frames 31-41" in report
    elif turns == "BLENDER":
        assert "1 flip(s) as Blender plays them" in report and "removed" not in report
    else:
        assert "removed 1 flip(s)" in report and "1 spin(s) taken the short way (Turns: Shortest) at frames 1-21" in report


def quaternion_keys(name: str, values) -> bpy.types.Object:
    obj = h.new_object(name, "MESH", "QUATERNION")
    for i, (f, q) in enumerate(zip((1, 11, 23, 31), values)):
        obj.rotation_quaternion = q
        obj.location = (0.1 * i, 0.0, 0.0)
        obj.keyframe_insert("rotation_quaternion", frame=f)
        obj.keyframe_insert("location", frame=f)
    h.select_only(obj)
    return obj


def departure_from_blender(obj, frames) -> tuple[float, float]:
    """Largest angle (degrees) and distance between the object's playback now and its
    source's playback at `frames` (Blender's own evaluation of both actions)."""
    angle, distance = per_frame_departure(obj, frames)
    return float(angle.max()), float(distance.max())


def per_frame_departure(obj, frames) -> tuple[np.ndarray, np.ndarray]:
    """Per frame: angle (degrees) and distance between the object's playback now and its
    source's (Blender's own evaluation of both actions)."""
    result = obj.animation_data.action
    ours = h.evaluated_basis(obj, frames)
    obj.animation_data.action = result["screwbender_source"]
    theirs = h.evaluated_basis(obj, frames)
    obj.animation_data.action = result
    r = np.einsum("nji,njk->nik", theirs[:, :3, :3], ours[:, :3, :3])
    angle = np.degrees(np.arccos(np.clip((np.trace(r, axis1=1, axis2=2) - 1) / 2, -1, 1)))
    return angle, np.linalg.norm(ours[:, :3, 3] - theirs[:, :3, 3], axis=1)


def check_frames(obj, line: str, frames: np.ndarray) -> None:
    """The frames the report names are those where Blender's playback of the result departs
    from the source's by more than 5 degrees or 5 % of the size (within float32 rounding), and
    the frame of the largest departure is among them."""
    named = set()
    for run in line.split(" at frames ")[1].split(" (")[0].split(", "):
        a, _, b = run.partition("-")
        named.update(np.arange(float(a), float(b or a) + 0.5))
    angle, distance = per_frame_departure(obj, frames)
    size = addon_size(obj)
    over = {float(f) for f, a, d in zip(frames, angle, distance) if a > 5.05 or d > 0.0505 * size}
    within = {float(f) for f, a, d in zip(frames, angle, distance) if a < 4.95 and d < 0.0495 * size}
    print(f"  named frames {sorted(named)}")
    assert over <= named and not (named & within), (sorted(over - named), sorted(named & within))
    assert float(frames[np.argmax(angle)]) in named


def reported_departure(report: str, name: str) -> tuple[float, float, str]:
    line = next(line for line in report.splitlines() if f"{name}: departs" in line)
    degrees = float(line.split("by up to ")[1].split(" degrees")[0])
    units = float(line.split(" degrees and ")[1].split(" units")[0])
    return degrees, units, line


def rotation_quaternion(axis, degrees) -> list[float]:
    axis = np.asarray(axis, dtype=float) / np.linalg.norm(axis)
    half = math.radians(degrees) / 2
    return [math.cos(half), *(math.sin(half) * axis)]


@pytest.mark.parametrize("kind", ["flipped", "non-normalised"])
def test_departure_report_on_quaternion_keys(sb, kind, capfd):
    axis = [0.2, 0.3, 0.9]
    unit = [rotation_quaternion(axis, a) for a in (0.0, 60.0, 130.0, 170.0)]
    if kind == "flipped":
        values = [unit[0], [-v for v in unit[1]], unit[2], [-v for v in unit[3]]]
    else:
        unit = [rotation_quaternion(axis, a) for a in (0.0, 80.0, 160.0, 240.0)]  # no sign flip
        values = [[s * v for v in q] for s, q in zip((1.0, 4.0, 0.25, 4.0), unit)]
    obj = quaternion_keys("Quat", values)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    report = capfd.readouterr().out
    frames = np.arange(1.0, 32.0)
    degrees, units = departure_from_blender(obj, frames)
    said_degrees, said_units, line = reported_departure(report, "Quat")
    print(f"\n{kind} quaternion keys: result against Blender's playback: {degrees:.1f} degrees, {units:.2e} units; "
          f"report: {line.strip()}")
    assert degrees > 5.0
    # the report's figure is Blender's (float32 keys: a hundredth of a degree)
    assert said_degrees == pytest.approx(degrees, abs=0.06)
    check_frames(obj, line, frames)
    if kind == "flipped":
        assert "quaternion sign flip(s)" in report and "flips removed" in line
    else:
        assert "non-normalised quaternion keys" in line


def test_no_departure_reported_where_the_result_plays_as_blender(sb, capfd):
    """Keys along a straight line with a small turn: the smoothed result stays within the
    thresholds of Blender's playback, and nothing is reported."""
    obj = h.new_object("Slider", "MESH", "XYZ")
    for f, x, z in ((1, 0.0, 0.0), (11, 1.0, 5.0), (21, 2.0, 10.0), (31, 3.0, 15.0)):
        obj.location = (x, 0.0, 0.0)
        obj.rotation_euler = (0.0, 0.0, math.radians(z))
        obj.keyframe_insert("location", frame=f)
        obj.keyframe_insert("rotation_euler", frame=f)
    h.select_only(obj)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    report = capfd.readouterr().out
    degrees, units = departure_from_blender(obj, np.arange(1.0, 32.0))
    size = addon_size(obj)
    print(f"\nstraight keys: {degrees:.2f} degrees, {units:.3f} units ({100 * units / size:.1f} % of {size:g}); "
          f"report: {report.strip()}")
    assert degrees < 5.0 and units < 0.05 * size
    assert "departs" not in report


def addon_size(obj) -> float:
    from conftest import addon_module

    return addon_module("blender.keys").body_size(addon_module("blender.owners").as_owner(obj))


def test_smooth_blend_script_takes_turns(sb, tmp_path):
    """scripts/smooth_blend.py --turns: the same choice for a pipeline."""
    import os
    import subprocess
    import sys

    from conftest import ROOT

    keyed_turns()
    source = tmp_path / "turns.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source))
    env = dict(os.environ)
    env.pop("BLENDER_USER_RESOURCES", None)  # a plain bpy session, as a farm would start it
    for turns, want in (("shortest", [-90.0, -170.0, 110.0, 130.0]), ("blender", [270.0, -170.0, -250.0, 130.0])):
        out = tmp_path / f"{turns}.blend"
        done = subprocess.run([sys.executable, str(ROOT / "scripts" / "smooth_blend.py"), str(source), "--turns", turns,
                               "--out", str(out)], env=env, capture_output=True, text=True, timeout=600)
        assert done.returncode == 0, done.stderr
        bpy.ops.wm.open_mainfile(filepath=str(out))
        got = z_turns(bpy.data.objects["Turner"], SPANS)
        print(f"\nsmooth_blend --turns {turns}: {np.round(got, 1).tolist()}")
        np.testing.assert_allclose(got, want, atol=2.0)


@pytest.mark.parametrize("turns", ["AUTO", "BLENDER", "SHORTEST"])
def test_panel_setting_preview_and_bake_agree(sb, turns):
    """The panel's Turns setting is the operator's (same items, default and tooltip, which
    states the rule); the live preview draws what Smooth Motion then bakes with it."""
    from conftest import addon_module

    pd = addon_module("ops.preview_draw")
    prop = bpy.ops.screwbender.smooth.get_rna_type().properties["turns"]
    setting = bpy.types.Scene.bl_rna.properties["screwbender"].fixed_type.properties["turns"]
    assert [i.identifier for i in prop.enum_items] == [i.identifier for i in setting.enum_items] == ["AUTO", "BLENDER", "SHORTEST"]
    assert prop.default == setting.default == "AUTO" and prop.description == setting.description
    assert "-180..180" in prop.description and "45 degrees" in prop.description
    obj = keyed_turns()
    scene = bpy.context.scene
    scene.screwbender.turns = turns
    # timing Smooth: the pace of timing Keys is measured along the frames sampled together
    # (the preview's instances and trajectory), which moves it by up to 1e-3
    scene.screwbender.timing = "smooth"
    assert sb.bake.options_from(scene.screwbender, scene).turns == turns
    scene.frame_set(1)
    scene.screwbender_preview.instances = 51
    obj.screwbender_preview = True
    try:
        pd.refresh(scene)
        previewed = pd.CACHE.entries[obj.session_uid].batches.instances
    finally:
        obj.screwbender_preview = False
        pd.sync()
    h.select_only(obj)
    assert bpy.ops.screwbender.smooth(turns=scene.screwbender.turns, timing="smooth") == {"FINISHED"}
    baked = h.evaluated_basis(obj, np.arange(1.0, 52.0))
    # (max abs matrix entry: Blender's matrix_basis is float32, the baked keys too)
    off = np.abs(previewed - baked).max()
    print(f"\nTurns {turns}: preview against the bake {off:.1e}")
    assert off < 1e-5


def test_departure_report_names_an_approximating_scheme(sb, capfd):
    """B-Spline cuts inside the keys: the report says where and by how much, and why."""
    rng = np.random.default_rng(3)
    obj = h.new_object("Blocky", "MESH", "XYZ")
    frames = [1, 9, 20, 26, 37, 45]
    rot = Rotation.from_rotvec(np.cumsum(rng.normal(0, 0.6, (6, 3)), axis=0)).as_matrix()
    h.key_poses(obj, frames, h.rigid(rng.uniform(-3, 3, (6, 3)), rot))
    h.select_only(obj)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(scheme="bspline") == {"FINISHED"}
    report = capfd.readouterr().out
    every = np.arange(1.0, 46.0)
    degrees, units = departure_from_blender(obj, every)
    said_degrees, said_units, line = reported_departure(report, "Blocky")
    print(f"\nB-Spline on random keys: {degrees:.1f} degrees, {units:.3f} units; report: {line.strip()}")
    assert "the B-Spline scheme cuts inside the keys" in line
    assert said_degrees == pytest.approx(degrees, abs=0.06) and said_units == pytest.approx(units, rel=1e-3, abs=1e-4)
    check_frames(obj, line, every)
