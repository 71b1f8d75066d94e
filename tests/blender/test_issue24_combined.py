"""Issue 24's parts together, as an animator uses them: a Frame Range with Turns, F-curve
modifiers, unkeyed channels, re-runs of edited results, linked duplicates, bones, subframe
keys, the departure report, and the all-or-nothing journal.

References are Blender's own playback: `FCurve.evaluate` (modifiers included) of the source
action's curves and of the result's, `matrix_basis` / `matrix_world` after `frame_set`. Every
figure is printed (pytest -s).
"""

from __future__ import annotations

import math

import bpy
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h
from conftest import addon_module
from test_all_or_nothing import check_unchanged, fail_on_call
from test_modifiers_and_reruns import keys_only, move_key, properties, reports
from test_range_and_grid import curves_of, difference, keyed, played
from test_turns import FRAMES as HELIX_FRAMES
from test_turns import flip_count, keyed_bone, keyed_object, reported_departure

#: float32 keys: values of a few units agree to this (m, rad).
F32 = 2e-6


def fine(lo: float, hi: float, per_frame: int = 4) -> np.ndarray:
    return np.arange(lo * per_frame, hi * per_frame + 1) / per_frame


def evaluate(curves: dict, frames) -> dict:
    """(path, index) -> Blender's playback (modifiers included) of each curve at `frames`."""
    return {key: np.array([fc.evaluate(float(f)) for f in frames]) for key, fc in curves.items()}


def source_action(obj):
    return obj.animation_data.action


def euler_wraps(obj, path: str, frames) -> np.ndarray:
    """Per span of `frames`: whether an Euler channel's stored keys jump by more than half a turn."""
    fcs = sorted((fc for fc in h.fcurves(obj) if fc.data_path == path), key=lambda fc: fc.array_index)
    values = np.array([[fc.evaluate(f) for fc in fcs] for f in frames])
    return np.abs(np.diff(values, axis=0)).max(axis=1) > math.pi


def largest_step(obj, at: float, world) -> tuple[float, float]:
    """The largest change of location (mm) and rotation (degrees) over 0.01 frame across `at`
    as Blender plays it (`world(frames)` gives the poses; subframes through frame_set)."""
    frames = np.linspace(at - 0.05, at + 0.05, 11)
    poses = world(frames)
    loc = np.linalg.norm(np.diff(poses[:, :3, 3], axis=0), axis=1).max() * 1000
    _, ang = max((difference(poses[i : i + 1], poses[i + 1 : i + 2]) for i in range(len(poses) - 1)), key=lambda d: d[1])
    return float(loc), float(ang)


def named_frames(line: str) -> list[float]:
    """The frames a departure line names ("at frames 11-15, 19-23 (...)"): each run's ends."""
    runs = line.split(" at frames ")[1].split(" (")[0].replace(" and", ",").split(", ")
    return [float(x) for run in runs if "more" not in run for x in run.split("-")]


def subframe_world(obj, bone=None):
    scene = bpy.context.scene

    def world(frames):
        out = []
        for f in frames:
            scene.frame_set(int(math.floor(f)), subframe=float(f - math.floor(f)))
            m = np.array(obj.matrix_world)
            if bone is not None:
                m = m @ np.array(obj.pose.bones[bone].matrix)
            out.append(m)
        return np.array(out)

    return world


# --- a range with an Euler wrap, Turns Auto ------------------------------------------------


def limit_rotation(obj) -> None:
    """Limits the source's keys never reach (they stay inside -180..180 degrees)."""
    for fc in h.fcurves(obj):
        if fc.data_path == "rotation_euler":
            mod = fc.modifiers.new("LIMITS")
            mod.use_min_y, mod.min_y, mod.use_max_y, mod.max_y = True, -math.pi - 0.01, True, math.pi + 0.01


def test_range_ending_a_turn_away_refuses_limits_on_rotation(sb):
    """The keys after the range would be written a turn (or the twin triple) away: a Limits
    modifier on them would then clamp what it never clamped (measured before the fix: 177.7
    degrees off the source after the range). The owner is refused with the reason."""
    obj, _, _ = keyed_object()
    limit_rotation(obj)
    check_unchanged(
        lambda: bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=14, frame_end=44),
        match=r"Helix: rotation_euler\[\d\]: the smoothed motion ends the Frame Range a turn .* Limits modifier",
    )
    # As Blender Plays keeps the source's winding: nothing to map, the Limits play as before
    world = subframe_world(obj)
    frames = fine(HELIX_FRAMES[0] - 2, HELIX_FRAMES[-1] + 2)
    before = world(frames)
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=14, frame_end=44, turns="BLENDER") == {"FINISHED"}
    after = world(frames)
    outside = (frames < 14) | (frames > 44)
    loc, ang = difference(after[outside], before[outside])
    print(f"\n[range 14..44, Limits on rotation, As Blender Plays] outside {loc:.4f} mm {ang:.5f} deg off the source")
    assert loc < 0.01 and ang < 1e-3


@pytest.mark.parametrize("start, end", [(14.0, 44.0), (10.0, 40.0)])
def test_range_over_an_euler_wrap_keeps_the_rest_and_reports_the_flips_inside(sb, capfd, start, end):
    obj, _, _ = keyed_object()
    world = subframe_world(obj)
    frames = fine(HELIX_FRAMES[0] - 2, HELIX_FRAMES[-1] + 2)
    before = world(frames)
    wraps = euler_wraps(obj, "rotation_euler", HELIX_FRAMES)
    spans = np.array(list(zip(HELIX_FRAMES[:-1], HELIX_FRAMES[1:])))
    inside = (spans[:, 1] > start) & (spans[:, 0] < end)  # spans the range smooths (some of)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=start, frame_end=end) == {"FINISHED"}
    report = capfd.readouterr().out
    after = world(frames)
    outside = (frames < start) | (frames > end)
    loc, ang = difference(after[outside], before[outside])
    ends = np.array([start, end])
    end_loc, end_ang = difference(world(ends), before[np.searchsorted(frames, ends)])
    steps = [largest_step(obj, at, world) for at in ends]
    speed = np.linalg.norm(np.diff(after[:, :3, 3], axis=0), axis=1).max() * 1000
    turn = np.degrees(max(difference(after[i : i + 1], after[i + 1 : i + 2])[1] for i in range(len(after) - 1)))
    print(
        f"\n[range {start:g}..{end:g} over Euler wraps, Turns Auto] outside {loc:.4f} mm {ang:.5f} deg off the source; "
        f"at the ends {end_loc:.4f} mm {end_ang:.5f} deg; largest 0.01-frame step across the ends {steps}; "
        f"wraps in spans touched by the range {int(wraps[inside].sum())} of {int(wraps.sum())}; report: {report.strip()}"
    )
    assert loc < 0.01 and ang < 1e-3, (loc, ang)
    assert end_loc < 0.01 and end_ang < 1e-3, (end_loc, end_ang)
    # no jump at either end: 0.01 frame moves a small part of a quarter frame's motion
    for step_loc, step_ang in steps:
        assert step_loc < 0.1 * speed and step_ang < 5.0, (steps, speed, turn)
    # the flips reported are those the range smoothed, not the ones kept outside it
    assert wraps[inside].sum() >= 1 and wraps[~inside].sum() >= 1
    assert flip_count(report) == int(wraps[inside].sum()), report


def test_range_over_a_flip_on_a_bone_in_pose_mode(sb, capfd):
    rig, _, _ = keyed_bone()
    world = subframe_world(rig, "Hand")
    start, end = 14.0, 44.0
    frames = fine(HELIX_FRAMES[0] - 2, HELIX_FRAMES[-1] + 2)
    before = world(frames)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=start, frame_end=end) == {"FINISHED"}
    report = capfd.readouterr().out
    after = world(frames)
    outside = (frames < start) | (frames > end)
    loc, ang = difference(after[outside], before[outside])
    steps = [largest_step(rig, at, world) for at in (start, end)]
    moved = difference(after[~outside], before[~outside])
    per = [difference(after[i : i + 1], before[i : i + 1]) for i in np.flatnonzero(outside)]
    worst = np.flatnonzero(outside)[int(np.argmax([a for _, a in per]))]
    # (the matrices' own float32 rounding: the largest entry difference, in radians)
    entries = float(np.abs(after[outside][:, :3, :3] - before[outside][:, :3, :3]).max())
    print(f"\n[bone range {start:g}..{end:g} over a flip] outside {loc:.4f} mm {ang:.5f} deg (rotation matrix "
          f"entries {entries:.2g}, worst at frame {frames[worst]:g}); steps {steps}; inside moved {moved}; {report.strip()}")
    # (arccos of a float32 matrix's trace reads 1e-6 of rounding as 0.03 degrees: the entries are the measure)
    assert loc < 0.01 and entries < 1e-5
    assert all(a < 5.0 for _, a in steps), steps
    assert moved[1] > 10.0  # the flip inside is gone: the inside is not the source
    assert flip_count(report) >= 1 and "Hand" in report


# --- a range on curves with modifiers -------------------------------------------------------


def noise(fc, i):
    mod = fc.modifiers.new("NOISE")
    mod.scale, mod.strength, mod.phase, mod.depth = 1.5, 0.4, 1.0 + 2 * i, 1


def stepped(fc, i):
    mod = fc.modifiers.new("STEPPED")
    mod.frame_step = 3.0


def limits(fc, i):
    mod = fc.modifiers.new("LIMITS")
    mod.use_max_y, mod.max_y = True, 0.5


MODIFIERS = {"noise": noise, "stepped": stepped, "limits": limits}


@pytest.mark.parametrize("kind", list(MODIFIERS))
def test_range_on_curves_with_a_modifier(sb, capfd, kind):
    obj, _ = keyed(name="Shaky")
    for i in range(3):
        MODIFIERS[kind](curves_of(obj)["location", i], i)
    start, end = 10.0, 30.0
    frames = fine(-2, 44)
    src = curves_of(obj)
    was = evaluate(src, frames)
    originals = {key: [properties(m) for m in fc.modifiers] for key, fc in src.items()}
    source = source_action(obj)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=start, frame_end=end) == {"FINISHED"}
    out = reports(capfd)
    new = curves_of(obj)
    now = evaluate(new, frames)
    outside = (frames < start) | (frames > end)
    gap_out = max(float(np.abs(now[k][outside] - was[k][outside]).max()) for k in src)
    # inside: the result's own keys, then the same modifier
    inside_gap = 0.0
    for key, fc in new.items():
        if key[0] != "location":
            continue
        result_keys = keys_only(fc, frames)
        with_mods = now[key]
        # the modifier acts on the smoothed keys as it acted on the source's keys: compare the
        # result with a copy of the modifier applied by Blender to a plain curve of those keys
        inside_gap = max(inside_gap, float(np.abs(with_mods - result_keys).max()))
    kept = {key: [properties(m) for m in fc.modifiers] for key, fc in new.items()}
    # inside: Blender plays the result's own keys, then the same modifier on them
    ref_gap = 0.0
    for i in range(3):
        fc, was_fc = new["location", i], src["location", i]
        result_keys = keys_only(fc, frames)
        if kind == "noise":  # the same noise, frame by frame, on top of the smoothed keys
            want = result_keys + (was["location", i] - keys_only(was_fc, frames))
        elif kind == "limits":
            want = np.minimum(result_keys, 0.5)
        else:  # stepped every 3 frames from frame 0: the keys held from each step
            want = keys_only(fc, np.floor(frames / 3.0) * 3.0)
        ref_gap = max(ref_gap, float(np.abs(now["location", i] - want).max()))
    moved_inside = max(float(np.abs(now[k][~outside] - was[k][~outside]).max()) for k in src)
    print(f"\n[range {start:g}..{end:g} + {kind}] outside {gap_out:.2g} off the source (modifier included); inside "
          f"the result moved {moved_inside:.3f} from the source, the modifier changes its keys by up to {inside_gap:.3f}; result vs its keys + the modifier {ref_gap:.2g}; {out}")
    assert gap_out < F32 * 4, gap_out
    assert ref_gap < 1e-5, ref_gap
    assert kept == originals  # once each, every property: not dropped, not doubled
    assert moved_inside > 1e-3
    assert any(f"kept the {kind.capitalize()}" in line and "modifier on location" in line for line in out), out
    # the source action keeps its own stack untouched
    assert {k: [properties(m) for m in fc.modifiers] for k, fc in curves_of(obj, source).items()} == originals


def test_subframe_keys_range_and_modifiers(sb, capfd):
    obj = h.new_object("Half", "MESH", "XYZ")
    frames = np.arange(1.0, 21.0, 0.5)
    rng = np.random.default_rng(11)
    rot = Rotation.from_rotvec(np.cumsum(rng.normal(0, 0.08, (len(frames), 3)), axis=0)).as_matrix()
    loc = np.cumsum(rng.normal(0, 0.2, (len(frames), 3)), axis=0)
    h.key_poses(obj, frames, h.rigid(loc, rot))
    for i in range(3):
        noise(curves_of(obj)["location", i], i)
    start, end = 6.25, 14.75
    times = fine(0, 22, 8)
    src = curves_of(obj)
    was = evaluate(src, times)
    source_keys = {k: sorted(float(p.co[0]) for p in fc.keyframe_points) for k, fc in src.items()}
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=start, frame_end=end) == {"FINISHED"}
    new = curves_of(obj)
    now = evaluate(new, times)
    outside = (times < start) | (times > end)
    gap = max(float(np.abs(now[k][outside] - was[k][outside]).max()) for k in src)
    counts = {k: len(fc.modifiers) for k, fc in new.items()}
    # every source key inside the range is a baked frame
    baked = {k: np.array([p.co[0] for p in fc.keyframe_points]) for k, fc in new.items()}
    missing = [f for k, fs in source_keys.items() for f in fs if start < f < end and np.abs(baked[k] - f).min() > 1e-4]
    print(f"\n[half-frame keys, range {start:g}..{end:g}, Noise] outside {gap:.2g} off; modifiers per curve {set(counts.values())}; "
          f"source keys inside missing from the bake {missing}")
    assert gap < 1e-5
    assert all(counts[("location", i)] == 1 for i in range(3)) and all(counts[k] == 0 for k in counts if k[0] != "location")
    assert not missing


# --- a range and unkeyed channels -----------------------------------------------------------


def test_range_with_only_location_keyed(sb, capfd):
    obj = h.new_object("Slide", "MESH", "XYZ")
    obj.rotation_euler = (0.3, -0.2, 0.7)
    obj.scale = (1.5, 1.0, 0.5)
    rng = np.random.default_rng(5)
    key_frames = [1, 7, 13, 19, 25, 31, 37, 40]
    for f, p in zip(key_frames, np.cumsum(rng.normal(0, 1.0, (len(key_frames), 3)), axis=0)):
        obj.location = p
        obj.keyframe_insert("location", frame=f)
    frames = fine(-2, 44)
    before = played(obj, frames)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30) == {"FINISHED"}
    report = capfd.readouterr().out
    after = played(obj, frames)
    outside = (frames < 10) | (frames > 30)
    loc, ang = difference(after[outside], before[outside])
    inside = difference(after[~outside], before[~outside])
    paths = sorted({fc.data_path for fc in h.fcurves(obj)})
    print(f"\n[range 10..30, location keyed only] outside {loc:.4f} mm {ang:.5f} deg; inside moved {inside}; curves {paths}; "
          f"{report.strip()}")
    assert paths == ["location"]
    assert loc < 0.01 and ang < 1e-6
    assert inside[0] > 1.0 and inside[1] < 1e-4  # the rotation stays the owner's own
    # the departure report: measured where the result differs (inside), the unkeyed rotation not at all
    deg, units, line = reported_departure(report, "Slide")
    assert deg == 0.0 and abs(units - inside[0] / 1000) < 0.002, (line, inside)
    assert all(10 <= f <= 30 for f in named_frames(line)), line


# --- re-runs of a range result ---------------------------------------------------------------


def test_edit_then_rerun_on_a_range_result_with_modifiers(sb, capfd):
    obj, _ = keyed(name="Edited")
    for i in range(3):
        noise(curves_of(obj)["location", i], i)
    original = source_action(obj)
    originals = {key: [properties(m) for m in fc.modifiers] for key, fc in curves_of(obj).items()}
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30) == {"FINISHED"}
    first = source_action(obj)
    slot = sb.channels.slot_identifier(obj)
    assert not sb.bake.was_edited(first, slot)
    # an unedited range result is re-smoothed from the original: the same result again
    frames = fine(-2, 44)
    first_played = evaluate(curves_of(obj), frames)
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30) == {"FINISHED"}
    again = source_action(obj)
    assert again["screwbender_source"] == original
    again_gap = max(float(np.abs(v - first_played[k]).max()) for k, v in evaluate(curves_of(obj), frames).items())
    assert again_gap < F32
    # the animator moves a key outside the range (a source key kept by the join) and re-runs
    moved = move_key(curves_of(obj)["location", 0], 37.0, 1.0)
    assert sb.bake.was_edited(again, slot)
    edited = source_action(obj)
    edited_played = evaluate(curves_of(obj), frames)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30, turns="SHORTEST") == {"FINISHED"}
    out = reports(capfd)
    second = source_action(obj)
    now = evaluate(curves_of(obj), frames)
    outside = (frames < 10) | (frames > 30)
    gap = max(float(np.abs(now[k][outside] - edited_played[k][outside]).max()) for k in now)
    counts = {key: [properties(m) for m in fc.modifiers] for key, fc in curves_of(obj).items()}
    at37 = float(keys_only(curves_of(obj)["location", 0], [37.0])[0])
    print(f"\n[edit a kept key of a range result, re-run with Turns Shortest] outside {gap:.2g} off the edited result; "
          f"the moved key {abs(at37 - moved):.2g} off; modifiers per curve {[len(v) for v in counts.values()]}; {out}")
    assert any("was edited after Smooth Motion made it" in line for line in out), out
    assert second["screwbender_source"] == edited
    assert gap < F32 * 4 and abs(at37 - moved) < 1e-5
    assert counts == originals  # the copied stack is not copied again on top of itself
    # Revert: the edited result, then the original
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert source_action(obj) == edited
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert source_action(obj) == original
    assert {key: [properties(m) for m in fc.modifiers] for key, fc in curves_of(obj).items()} == originals


def test_rerun_of_an_edited_result_with_modifiers_does_not_double_them(sb):
    obj, _ = keyed(name="Twice")
    for i in range(3):
        noise(curves_of(obj)["location", i], i)
        stepped(curves_of(obj)["location", i], i)
    originals = {key: [properties(m) for m in fc.modifiers] for key, fc in curves_of(obj).items()}
    for run in range(3):
        assert bpy.ops.screwbender.smooth(turns=("AUTO", "SHORTEST", "BLENDER")[run]) == {"FINISHED"}
        move_key(curves_of(obj)["location", 1], 13.0, 0.25)
        now = {key: [properties(m) for m in fc.modifiers] for key, fc in curves_of(obj).items()}
        print(f"\nrun {run + 1}: modifiers per curve {[len(v) for v in now.values()]}")
        assert now == originals
    for _run in range(2):  # Smooth Result on, with a range: the result itself, twice
        assert bpy.ops.screwbender.smooth(smooth_result=True, range_mode="CUSTOM", frame_start=8, frame_end=25) == {"FINISHED"}
        now = {key: [properties(m) for m in fc.modifiers] for key, fc in curves_of(obj).items()}
        assert now == originals


# --- linked duplicates, the departure report ---------------------------------------------------


def test_linked_duplicates_with_a_range_are_both_named(sb, capfd):
    obj, _ = keyed(name="Rotor")
    dup = obj.copy()
    dup.name = "Rotor.001"
    bpy.context.scene.collection.objects.link(dup)
    frames = fine(-2, 44)
    before = played(dup, frames)
    h.select_only(obj)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30) == {"FINISHED"}
    out = reports(capfd)
    after = played(dup, frames)
    outside = (frames < 10) | (frames > 30)
    print(f"\n[linked duplicates, range] dup outside {difference(after[outside], before[outside])}; {out}")
    assert dup.animation_data.action == obj.animation_data.action
    assert difference(after[outside], before[outside])[0] < 0.01
    assert any("Rotor, Rotor.001" in line and line.startswith("Info: Smoothed 2 object(s)") for line in out), out
    assert any("smoothed frames 10 to 30 of Rotor, Rotor.001" in line for line in out), out


def test_departure_report_with_a_range_is_measured_inside_it(sb, capfd):
    """Quaternion keys of the other sign inside and outside the range: Blender plays the long
    way there; the report's departure is measured where the result differs (inside)."""
    obj = h.new_object("Quat", "MESH", "QUATERNION")
    axis = np.array([0.2, 0.3, 0.9]) / np.linalg.norm([0.2, 0.3, 0.9])
    key_frames = [1, 9, 17, 25, 33, 41]
    angles = [0, 40, 80, 120, 160, 200]
    signs = [1, 1, -1, 1, -1, 1]
    for f, a, s in zip(key_frames, angles, signs):
        half = math.radians(a) / 2
        obj.rotation_quaternion = [s * math.cos(half), *(s * math.sin(half) * axis)]
        obj.location = (0.01 * f, 0, 0)
        obj.keyframe_insert("rotation_quaternion", frame=f)
        obj.keyframe_insert("location", frame=f)
    frames = np.arange(1.0, 42.0)
    source = source_action(obj)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=9, frame_end=25) == {"FINISHED"}
    report = capfd.readouterr().out
    deg, units, line = reported_departure(report, "Quat")
    now = played(obj, frames)
    was = played(obj, frames, source)
    per_frame = np.array([difference(now[i : i + 1], was[i : i + 1])[1] for i in range(len(frames))])
    inside = (frames >= 9) & (frames <= 25)
    print(f"\n[departure with a range 9..25] reported {deg} degrees {units} units; measured inside {per_frame[inside].max():.2f}, "
          f"outside {per_frame[~inside].max():.4f}; {line}")
    assert per_frame[~inside].max() < 1e-3
    assert abs(deg - per_frame[inside].max()) < 0.5
    assert all(9 <= f <= 25 for f in named_frames(line)), line


# --- all or nothing ----------------------------------------------------------------------------


def test_range_modifiers_rerun_failing_midway_changes_nothing(sb):
    obj, _ = keyed(name="A")
    for i in range(3):
        noise(curves_of(obj)["location", i], i)
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30) == {"FINISHED"}
    move_key(curves_of(obj)["location", 1], 37.0, 1.0)
    mod = addon_module("blender.modifiers")
    assert mod is not None
    with fail_on_call("blender.modifiers", "copy_onto", 2) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30))
    assert calls["n"] == 2
    with fail_on_call("blender.range_join", "write", 5) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30))
    assert calls["n"] == 5
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30) == {"FINISHED"}
    assert all(len(fc.modifiers) == 1 for key, fc in curves_of(obj).items() if key[0] == "location")


def test_range_on_quaternion_keys_with_noise_and_limits_on_rotation(sb, capfd):
    """Quaternion keys (a sign flip inside the range) under Noise and Limits on the rotation:
    not refused (the join's map is the identity), the source plays outside the range."""
    obj, _ = keyed(name="Spun", mode="QUATERNION")
    fcs = curves_of(obj)
    for i in range(4):
        noise(fcs["rotation_quaternion", i], i)
        mod = fcs["rotation_quaternion", i].modifiers.new("LIMITS")
        mod.use_min_y, mod.min_y = True, -0.9
    frames = fine(-2, 44)
    before = played(obj, frames)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=10, frame_end=30) == {"FINISHED"}
    out = reports(capfd)
    after = played(obj, frames)
    outside = (frames < 10) | (frames > 30)
    loc, ang = difference(after[outside], before[outside])
    print(f"\n[quaternion range 10..30, Noise + Limits on rotation] outside {loc:.4f} mm {ang:.5f} deg; {out}")
    assert loc < 0.01 and ang < 1e-3
    assert all(len(fc.modifiers) == 2 for key, fc in curves_of(obj).items() if key[0] == "rotation_quaternion")


def test_range_ending_a_turn_away_keeps_noise_on_rotation(sb, capfd):
    """A Noise on the rotation only adds: keys after the range written a whole turn away play
    the same poses under it (or, for the twin Euler triple, the owner is refused with the reason)."""
    obj, _, _ = keyed_object()
    for i, fc in enumerate(fc for fc in h.fcurves(obj) if fc.data_path == "rotation_euler"):
        noise(fc, i)
    source = obj.animation_data.action
    world = subframe_world(obj)
    frames = fine(HELIX_FRAMES[0] - 2, HELIX_FRAMES[-1] + 2)
    before = world(frames)
    try:
        result = bpy.ops.screwbender.smooth(range_mode="CUSTOM", frame_start=14, frame_end=44)
    except RuntimeError as err:  # the twin triple: refused, with the Noise named
        print(f"\n[range 14..44, Noise on rotation] refused: {err}")
        assert "Noise modifier" in str(err) and "twin" in str(err)
        return
    assert result == {"FINISHED"}
    after = world(frames)
    outside = (frames < 14) | (frames > 44)
    entries = float(np.abs(after[outside][:, :3, :] - before[outside][:, :3, :]).max())
    last = {key: fc.keyframe_points[-1].co[1] for key, fc in curves_of(obj).items()}
    was = {key: fc.keyframe_points[-1].co[1] for key, fc in curves_of(obj, source).items()}
    shift = [round(float(last[k] - was[k]) / (2 * math.pi), 4) for k in sorted(last) if k[0] == "rotation_euler"]
    print(f"\n[range 14..44, Noise on rotation] outside: matrix entries {entries:.2g} off the source; the last "
          f"key of each rotation channel moved by {shift} turns")
    assert any(abs(t) > 0.5 for t in shift)  # the keys after the range are written a turn away
    assert entries < 1e-4
