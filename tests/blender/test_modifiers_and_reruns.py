"""Nothing the animator made is lost (issue 24, items 2, 6 and 9): F-curve modifiers on
transform curves are kept on the result and still act on it; a result edited after Smooth
Motion made it is smoothed as it is (never thrown away); reports name every object whose
motion changed and the real reason for NLA refusals; muted NLA tracks do not block.

References are Blender's own: `FCurve.evaluate` (with the modifiers, and with them muted),
`Object.matrix_basis` after `frame_set`; the same keys without modifiers smoothed on a twin
object give the keys' own smoothed motion. Every figure is printed (`pytest -s`).
"""

from __future__ import annotations

import bpy
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h
import bone_helpers as bh
from test_all_or_nothing import check_unchanged, fail_on_call

FRAMES = [1, 9, 17, 30]
LOCATIONS = np.array([[0, 0, 0], [1, 2, 0], [3, 1, 1], [4, 0, 0]], dtype=float)
EULERS = [[0, 0, 0], [0.4, 0.1, 1.0], [0.2, 0.7, 2.0], [0.1, 0.1, 2.8]]


def keyed(name: str, mode: str = "XYZ", closed: bool = False):
    """An object keyed on location and rotation at 4 frames (a fifth repeating the first
    pose at frame 40 with `closed`)."""
    obj = h.new_object(name, "MESH", mode)
    frames, locations, eulers = list(FRAMES), LOCATIONS, list(EULERS)
    if closed:
        frames, locations, eulers = frames + [40], np.vstack([LOCATIONS, LOCATIONS[:1]]), eulers + [EULERS[0]]
    h.key_poses(obj, frames, h.rigid(locations, Rotation.from_euler("xyz", eulers).as_matrix()))
    return obj


def curve(obj, path: str, index: int):
    found = [fc for fc in h.fcurves(obj) if fc.data_path == path and fc.array_index == index]
    assert len(found) == 1, f"{obj.name}: {len(found)} curves {path}[{index}]"
    return found[0]


def played(fc, frames) -> np.ndarray:
    """Blender's own playback of `fc` (keys, then modifiers) at `frames`."""
    return np.array([fc.evaluate(float(f)) for f in frames])


def keys_only(fc, frames) -> np.ndarray:
    """Blender's playback of `fc` with its modifiers muted (but a first Cycles): what the keys make."""
    mods = [m for i, m in enumerate(fc.modifiers) if not (i == 0 and m.type == "CYCLES")]
    was = [m.mute for m in mods]
    for m in mods:
        m.mute = True
    try:
        return played(fc, frames)
    finally:
        for m, mute in zip(mods, was):
            m.mute = mute


def properties(mod) -> dict:
    """Every RNA property of a modifier (collections as lists of their items' properties)."""
    out = {}
    for prop in mod.bl_rna.properties:
        name = prop.identifier
        if name in ("rna_type", "active") or prop.type == "POINTER":
            continue
        value = getattr(mod, name)
        if prop.type == "COLLECTION":
            value = [
                {p.identifier: getattr(item, p.identifier) for p in item.bl_rna.properties if p.identifier != "rna_type"}
                for item in value
            ]
        elif getattr(prop, "is_array", False) or (prop.type == "FLOAT" and getattr(prop, "array_length", 0)):
            value = list(value)
        out[name] = value
    return out


def reports(capfd) -> list[str]:
    return [line for line in capfd.readouterr().out.splitlines() if line.split(":")[0] in ("Info", "Warning", "Error")]


def rms_second_difference(values: np.ndarray) -> float:
    """RMS over frames of the second difference of a (frames, 3) path (units/frame^2)."""
    d2 = values[2:] - 2 * values[1:-1] + values[:-2]
    return float(np.sqrt(np.mean(np.sum(d2**2, axis=1))))


# 2. Modifiers survive -------------------------------------------------------------------


def test_noise_keeps_shaking_the_smoothed_motion_and_stays_out_of_the_key_poses(sb, capfd):
    shaky, clean = keyed("Shaky"), keyed("Clean")
    for i in range(3):
        mod = curve(shaky, "location", i).modifiers.new("NOISE")
        mod.scale, mod.strength, mod.phase, mod.depth = 1.5, 0.6, 1.0 + 2 * i, 1
    frames = np.arange(1.0, 30.5, 1.0)
    source = np.stack([played(curve(shaky, "location", i), frames) for i in range(3)], axis=1)
    source_keys = np.stack([keys_only(curve(shaky, "location", i), frames) for i in range(3)], axis=1)
    originals = [properties(m) for i in range(3) for m in curve(shaky, "location", i).modifiers]
    h.select_only(shaky, clean)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    out = reports(capfd)
    fcs = [curve(shaky, "location", i) for i in range(3)]
    result = np.stack([played(fc, frames) for fc in fcs], axis=1)
    result_keys = np.stack([keys_only(fc, frames) for fc in fcs], axis=1)
    twin = np.stack([played(curve(clean, "location", i), frames) for i in range(3)], axis=1)
    # the smoothing saw the keys alone: without its modifiers the result is the twin's result
    keys_gap = np.abs(result_keys - twin).max()
    # the noise on top is the source's noise, frame by frame
    noise_gap = np.abs((result - result_keys) - (source - source_keys)).max()
    # no noise baked into the key poses: at the key frames the result's keys are the key values
    at_keys = np.isin(frames, FRAMES)
    key_poses = np.abs(result_keys[at_keys] - LOCATIONS).max()
    rms_source, rms_result = rms_second_difference(source), rms_second_difference(result)
    print(
        f"\nNoise: RMS second difference source {1000 * rms_source:.1f} mm/frame^2, result "
        f"{1000 * rms_result:.1f} ({100 * (rms_result / rms_source - 1):+.2f} %); key poses off the keyed "
        f"values by {1000 * key_poses:.3g} mm; keys-only vs twin {keys_gap:.2g}; noise vs source's {noise_gap:.2g}; {out}"
    )
    assert "Info: Shaky: kept the Noise modifier on location" in out, out
    assert [properties(m) for fc in fcs for m in fc.modifiers] == originals  # every property, in order
    assert keys_gap < 1e-5 and noise_gap < 1e-5 and key_poses < 1e-5
    assert abs(rms_result / rms_source - 1) < 0.05


def stepped(fc):
    mod = fc.modifiers.new("STEPPED")
    mod.frame_step, mod.frame_offset = 3.0, 1.0


def test_stepped_stays_stepped(sb, capfd):
    obj, clean = keyed("Blocky"), keyed("Clean")
    paths = [("location", i) for i in range(3)] + [("rotation_euler", i) for i in range(3)]
    for path, i in paths:
        stepped(curve(obj, path, i))
    frames = np.arange(1.0, 30.01, 0.25)
    source = np.stack([played(curve(obj, p, i), frames) for p, i in paths], axis=1)
    h.select_only(obj, clean)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    out = reports(capfd)
    result = np.stack([played(curve(obj, p, i), frames) for p, i in paths], axis=1)
    # Blender's Stepped: the keys read at the start of each 3-frame block after the offset
    snapped = np.floor((frames - 1.0) / 3.0) * 3.0 + 1.0
    twin = np.stack([played(curve(clean, p, i), snapped) for p, i in paths], axis=1)
    gap = np.abs(result - twin).max()
    blocks = len(np.unique(snapped))
    distinct = len(np.unique(np.round(result, 6), axis=0))
    change = np.abs(result - source)
    print(
        f"\nStepped: result vs smoothed motion read at the steps {gap:.2g}; {distinct} distinct poses over "
        f"{blocks} blocks ({len(frames)} frames); result vs source playback: {1000 * change[:, :3].max():.0f} mm, "
        f"{np.degrees(change[:, 3:].max()):.1f} deg (the smoothing)"
    )
    assert (
        "Info: Blocky: kept the Stepped Interpolation modifier on location; the Stepped Interpolation modifier "
        "on rotation" in out
    ), out
    assert gap < 1e-5 and distinct == blocks


def test_limits_hold(sb, capfd):
    obj, clean = keyed("Held"), keyed("Clean")
    mod = curve(obj, "location", 1).modifiers.new("LIMITS")
    mod.use_max_y, mod.max_y = True, 1.5
    mod = curve(obj, "rotation_euler", 2).modifiers.new("LIMITS")
    mod.use_min_y, mod.min_y, mod.use_max_y, mod.max_y = True, 0.2, True, 2.5
    frames = np.arange(1.0, 30.01, 0.5)
    h.select_only(obj, clean)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    y = played(curve(obj, "location", 1), frames)
    z = played(curve(obj, "rotation_euler", 2), frames)
    free_y = played(curve(clean, "location", 1), frames)
    free_z = played(curve(clean, "rotation_euler", 2), frames)
    print(
        f"\nLimits: location Y max {y.max():.4f} (limit 1.5; without the modifier {free_y.max():.4f}); rotation Z "
        f"{z.min():.4f}..{z.max():.4f} (limits 0.2..2.5; without {free_z.min():.4f}..{free_z.max():.4f}); result "
        f"vs the smoothed keys clamped: {1000 * np.abs(y - np.minimum(free_y, 1.5)).max():.3g} mm, "
        f"{np.degrees(np.abs(z - np.clip(free_z, 0.2, 2.5)).max()):.3g} deg"
    )
    assert free_y.max() > 1.6 and free_z.max() > 2.6  # the limits bite
    assert y.max() <= 1.5 + 1e-6 and z.min() >= 0.2 - 1e-6 and z.max() <= 2.5 + 1e-6
    np.testing.assert_allclose(y, np.minimum(free_y, 1.5), atol=1e-5)
    np.testing.assert_allclose(z, np.clip(free_z, 0.2, 2.5), atol=1e-5)
    # and Blender's own playback of the object holds them too
    basis = h.evaluated_basis(obj, frames[::4])
    assert basis[:, 1, 3].max() <= 1.5 + 1e-6


def generator(fc):
    mod = fc.modifiers.new("GENERATOR")
    mod.use_additive, mod.poly_order = True, 2
    mod.coefficients = (0.1, 0.02, -0.001)


def envelope(fc):
    mod = fc.modifiers.new("ENVELOPE")
    mod.reference_value, mod.default_min, mod.default_max = 0.5, -1.0, 1.0
    for frame in (5.0, 25.0):
        mod.control_points.add(frame)
    # (a point's min/max set one by one runs a modifier update on the point: unsafe in Blender)
    mod.control_points.foreach_set("min", (-0.5, -2.0))
    mod.control_points.foreach_set("max", (0.5, 3.0))


def function(fc):
    mod = fc.modifiers.new("FNGENERATOR")
    mod.function_type, mod.use_additive = "SIN", True
    mod.amplitude, mod.phase_multiplier, mod.phase_offset, mod.value_offset = 0.3, 0.5, 0.2, 0.05


def ranged_noise(fc):
    mod = fc.modifiers.new("NOISE")
    mod.strength, mod.scale = 0.5, 2.0
    mod.use_restricted_range, mod.frame_start, mod.frame_end, mod.blend_in, mod.blend_out = True, 6.0, 22.0, 2.0, 3.0
    mod.use_influence, mod.influence = True, 0.7


def muted_stepped(fc):
    stepped(fc)
    fc.modifiers[-1].mute = True


def stack(fc):
    generator(fc)
    ranged_noise(fc)
    limits = fc.modifiers.new("LIMITS")
    limits.use_min_y, limits.min_y = True, -0.2


def cycles(mode):
    def add(fc):
        mod = fc.modifiers.new("CYCLES")
        mod.mode_before = mod.mode_after = mode

    return add


CASES = {
    "generator": (None, generator, False),
    "envelope": (None, envelope, False),
    "function": (None, function, False),
    "noise_ranged": (None, ranged_noise, False),
    "stepped_muted": (None, muted_stepped, False),
    "stack": (None, stack, False),
    "cycles_repeat_noise": (cycles("REPEAT"), ranged_noise, True),
    "cycles_offset_generator": (cycles("REPEAT_OFFSET"), generator, False),
    "cycles_mirror_envelope": (cycles("MIRROR"), envelope, False),
    "cycles_none_before_limits": (cycles("NONE"), stack, False),
}


@pytest.mark.parametrize("case", CASES)
def test_other_modifiers_are_copied_and_act_on_the_result(sb, case):
    """The result with its modifiers, played by Blender, equals the twin's smoothed motion
    (the same keys without those modifiers) with the same modifiers put on it by hand."""
    base, extra, closed = CASES[case]
    obj, clean = keyed("Modified", closed=closed), keyed("Clean", closed=closed)
    paths = [("location", 0), ("location", 2), ("rotation_euler", 1)]
    for o in (obj, clean):
        for p, i in paths:
            if base is not None:
                base(curve(o, p, i))
    for p, i in paths:
        extra(curve(obj, p, i))
    originals = [[properties(m) for m in curve(obj, p, i).modifiers] for p, i in paths]
    h.select_only(obj, clean)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    frames = np.arange(-12.0, 55.0, 0.5)
    gaps = []
    for (p, i), before in zip(paths, originals):
        fc = curve(obj, p, i)
        copied = [properties(m) for m in fc.modifiers]
        first_cycles = copied and copied[0]["type"] == "CYCLES"
        # the bake writes the first Cycles modifier itself (one period); the rest are copies
        assert copied[1:] == before[1:] if first_cycles else copied == before, (p, i)
        reference = curve(clean, p, i)
        extra(reference)
        gaps.append(np.abs(played(fc, frames) - played(reference, frames)).max())
    print(f"\n{case}: result vs smoothed twin with the modifiers by hand, max over 3 curves {max(gaps):.2g}")
    assert max(gaps) < 1e-5


@pytest.mark.parametrize("case", ["GENERATOR", "FNGENERATOR"])
def test_modifiers_that_make_smoothing_meaningless_refuse_the_owner(sb, case):
    """A Generator or Built-in Function that replaces the keys over their whole range.
    (A Cycles modifier below another one is refused too, but Blender's Python API cannot
    build that stack: `modifiers.new("CYCLES")` on a curve with modifiers gives None.)"""
    obj = keyed("Odd")
    fc = curve(obj, "location", 0)
    fc.modifiers.new(case).use_additive = False
    kind = {"GENERATOR": "Generator", "FNGENERATOR": "Built-In Function"}[case]
    name = fc.modifiers[0].name
    expected = f"Error: Odd: location[0]: its {kind} modifier '{name}' replaces the keys (not Additive)"
    action = obj.animation_data.action
    before = h.snapshot_data()
    with pytest.raises(RuntimeError) as error:
        bpy.ops.screwbender.smooth()
    print(f"\n{case}: {error.value}")
    assert str(error.value).startswith(expected), error.value
    assert obj.animation_data.action == action and h.snapshot_data() == before
    # restricted to a part of the keys: it is kept
    mod = fc.modifiers[0]
    mod.use_restricted_range, mod.frame_start, mod.frame_end = True, 10.0, 20.0
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert [m.type for m in curve(obj, "location", 0).modifiers] == [case]


def test_modifier_copies_are_all_or_nothing(sb):
    a, b = keyed("A"), keyed("B")
    for obj in (a, b):
        for i in range(3):
            curve(obj, "location", i).modifiers.new("NOISE")
    h.select_only(a, b)
    with fail_on_call("blender.modifiers", "copy_onto", 5) as calls:  # B's second curve
        check_unchanged(lambda: bpy.ops.screwbender.smooth())
    assert calls["n"] == 5
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}


# 6. Re-runs keep edits ------------------------------------------------------------------


def move_key(fc, frame: float, by: float) -> float:
    """Moves the key of `fc` at `frame` by `by` (as dragging it in the Graph Editor); its new value."""
    point = next(p for p in fc.keyframe_points if abs(p.co[0] - frame) < 1e-6)
    point.co = (point.co[0], point.co[1] + by)
    point.handle_left = (point.handle_left[0], point.handle_left[1] + by)
    point.handle_right = (point.handle_right[0], point.handle_right[1] + by)
    fc.update()
    return float(point.co[1])


def test_a_rerun_smooths_the_edited_result_and_keeps_it(sb, capfd):
    obj = keyed("Edited")
    original = obj.animation_data.action
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    first = obj.animation_data.action
    first_name = first.name
    fc = curve(obj, "location", 0)
    unedited = float(played(fc, [10.0])[0])
    moved = move_key(fc, 10.0, 1.0)  # the animator moves a key of the result 1 m
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}  # default options: not Smooth Result
    out = reports(capfd)
    second = obj.animation_data.action
    # the original, the edited result and the new one (a name alone could be reused)
    others = sorted(a.name for a in bpy.data.actions if a != second and a != original)
    now = float(played(curve(obj, "location", 0), [10.0])[0])
    basis = h.evaluated_basis(obj, [10.0])[0]
    print(
        f"\nEdit then re-run: the moved key (frame 10, +1 m) is in the new result to {abs(now - moved):.2g} "
        f"(the unedited result had {unedited:.4f}, {1000 * abs(now - unedited):.0f} mm away); Blender plays "
        f"{basis[0, 3]:.6f}; the edited action is {'kept' if others else 'deleted'}; {out}"
    )
    assert any("'EditedAction.smooth' was edited after Smooth Motion made it" in line for line in out), out
    assert others == [first_name] and second != first  # the edit is kept
    assert second["screwbender_source"] == first and sb.bake.was_edited(first, sb.channels.slot_identifier(obj))
    assert abs(now - moved) < 1e-5 and abs(basis[0, 3] - moved) < 1e-5
    # Revert returns to the edited result, a second Revert to the original; nothing is deleted
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == first and abs(played(curve(obj, "location", 0), [10.0])[0] - moved) < 1e-6
    capfd.readouterr()
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert obj.animation_data.action == original
    assert "Info: kept the edited result EditedAction.smooth (fake user): it was edited after it was made" in reports(capfd)
    assert first_name in bpy.data.actions and bpy.data.actions[first_name].use_fake_user


def test_an_unedited_result_is_still_replaced(sb):
    obj = keyed("Plain")
    original = obj.animation_data.action
    assert bpy.ops.screwbender.smooth(scheme="bspline") == {"FINISHED"}
    first = obj.animation_data.action
    assert not sb.bake.was_edited(first, sb.channels.slot_identifier(obj))
    bpy.context.scene.frame_set(12)  # playing it is no edit
    assert not sb.bake.was_edited(first, sb.channels.slot_identifier(obj))
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert sorted(a.name for a in bpy.data.actions) == sorted([original.name, f"{original.name}.smooth"])


@pytest.mark.parametrize("edit", ["added", "deleted", "interpolation", "new curve"])
def test_every_kind_of_key_edit_is_seen(sb, edit):
    obj = keyed("Edited")
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    action, slot = obj.animation_data.action, sb.channels.slot_identifier(obj)
    fc = curve(obj, "location", 2)
    if edit == "added":
        fc.keyframe_points.insert(10.5, 3.0)
    elif edit == "deleted":
        fc.keyframe_points.remove(fc.keyframe_points[5])
    elif edit == "interpolation":
        fc.keyframe_points[5].interpolation = "BEZIER"
    else:
        obj.keyframe_insert("scale", frame=3)
    assert sb.bake.was_edited(action, slot)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert obj.animation_data.action["screwbender_source"] == action and action.name in bpy.data.actions


def test_keys_added_to_an_armature_object_after_smoothing_are_smoothed(sb, capfd):
    rig = bh.armature(holder=False)
    poses = bh.random_poses(4, seed=3, gentle=True)
    bh.key_bone(rig, "Upper", FRAMES, poses)
    h.select_only(rig)
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    for frame, x in ((1, 0.0), (12, 2.0), (24, 1.0)):
        rig.location = (x, 0.5 * x, 0.0)
        rig.keyframe_insert("location", frame=frame)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    out = reports(capfd)
    print(f"\nArmature keys added after smoothing, re-run: {out}")
    assert not any("no keyed transform channels" in line for line in out), out
    assert any(line.startswith("Info: Smoothed 2 bone(s) and object(s)") and "Rig" in line for line in out), out
    frames, location = h.channel(rig, "location", 3)
    assert len(frames) == 24  # baked every frame from 1 to 24
    at = {f: location[list(frames).index(f)] for f in (1.0, 12.0, 24.0)}
    assert abs(at[12.0][0] - 2.0) < 1e-6 and abs(at[24.0][0] - 1.0) < 1e-6


def test_an_edited_rerun_is_all_or_nothing(sb):
    obj = keyed("A")
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    move_key(curve(obj, "location", 1), 12.0, 1.0)
    with fail_on_call("blender.channels", "new_fcurve", 4) as calls:
        check_unchanged(lambda: bpy.ops.screwbender.smooth())
    assert calls["n"] == 4
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    with fail_on_call("blender.channels", "assign", 1) as calls:  # the second Revert keeps the edit: fake user
        check_unchanged(lambda: bpy.ops.screwbender.revert())


def test_a_solo_nla_track_is_refused_with_the_reason(sb):
    """With a Solo track Blender plays that track alone, not the action (measured: the
    action's keys and Blender's playback then differ by units): the reason is said."""
    obj = keyed("Soloed")
    solo = obj.animation_data.nla_tracks.new()
    solo.name = "Listen"
    solo.is_solo = True
    h.select_only(obj)
    gap = np.linalg.norm(h.evaluated_basis(obj, [9.0])[0, :3, 3] - LOCATIONS[1])
    with pytest.raises(RuntimeError) as error:
        bpy.ops.screwbender.smooth()
    print(f"\nSolo NLA track: Blender plays {gap:.3f} away from the action's key at frame 9; {error.value}")
    assert gap > 0.5
    assert str(error.value).startswith("Error: Soloed: NLA track 'Listen' is Solo, so Blender plays that track alone")


def test_nla_tweak_mode_is_refused_with_the_reason(sb):
    obj = keyed("Tweaked")
    adt = obj.animation_data
    track = adt.nla_tracks.new()
    strip = track.strips.new("Walk", 1, adt.action)
    adt.action = None
    track.select = strip.select = True
    adt.use_tweak_mode = True
    assert adt.use_tweak_mode and adt.action is not None
    h.select_only(obj)
    with pytest.raises(RuntimeError) as error:
        bpy.ops.screwbender.smooth()
    print(f"\nNLA tweak mode: {error.value}")
    assert str(error.value).startswith("Error: Tweaked: is in NLA tweak mode")
    adt.use_tweak_mode = False


def test_modifiers_on_bones_are_kept(sb, capfd):
    rig = bh.armature(holder=False)
    poses = bh.random_poses(4, seed=5, gentle=True)
    bh.key_bone(rig, "Upper", FRAMES, poses)
    bh.key_bone(rig, "Hand", FRAMES, poses)
    path = 'pose.bones["Upper"].location'
    for i in range(3):
        mod = curve(rig, path, i).modifiers.new("NOISE")
        mod.strength, mod.phase = 0.3, 1.0 + i
    frames = np.arange(1.0, 30.5, 0.5)
    shake = [played(curve(rig, path, i), frames) - keys_only(curve(rig, path, i), frames) for i in range(3)]
    h.select_only(rig)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    out = reports(capfd)
    assert "Info: Rig: Upper: kept the Noise modifier on location" in out, out
    gap = max(
        np.abs(played(curve(rig, path, i), frames) - keys_only(curve(rig, path, i), frames) - shake[i]).max()
        for i in range(3)
    )
    hand = [len(curve(rig, 'pose.bones["Hand"].location', i).modifiers) for i in range(3)]
    print(f"\nBone Noise: the result's shake vs the source's {gap:.2g}; {out}")
    assert gap < 1e-5 and hand == [0, 0, 0]


# 9. Reports tell the truth ----------------------------------------------------------------


def test_linked_duplicates_whose_motion_changed_are_named(sb, capfd):
    obj = keyed("Rotor")
    dup = obj.copy()  # shares the mesh and the action, as Alt+D does
    dup.name = "Rotor.001"
    bpy.context.scene.collection.objects.link(dup)
    frames = np.arange(1.0, 30.5, 0.5)
    before = h.evaluated_basis(dup, frames)
    h.select_only(obj)
    capfd.readouterr()
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    out = reports(capfd)
    after = h.evaluated_basis(dup, frames)
    print(f"\nLinked duplicate not selected: its motion changed by {1000 * np.abs(after - before)[:, :3, 3].max():.0f} mm; {out}")
    assert np.abs(after - before)[:, :3, 3].max() > 0.01  # it did change
    assert "Info: Smoothed 2 object(s): Rotor, Rotor.001 (1 new action)" in out, out
    assert any(line.startswith("Info: Rotor.001 shares the smoothed action") for line in out), out


def nla_only(name: str = "Pushed"):
    obj = keyed(name)
    adt = obj.animation_data
    action = adt.action
    track = adt.nla_tracks.new()
    track.name = "Walk track"
    track.strips.new("Walk", 1, action)
    adt.action = None  # as Push Down leaves it
    return obj


def test_motion_only_in_nla_strips_is_refused_with_the_reason(sb, capfd):
    obj = nla_only()
    with pytest.raises(RuntimeError) as error:
        bpy.ops.screwbender.smooth()
    message = str(error.value)
    print(f"\nNLA only (before: 'Pushed: no animation (no active action): skipped'): {message}")
    assert message.startswith(
        "Error: Pushed: its motion is in NLA strips ('Walk' on track 'Walk track'), not in an active action"
    ), message
    assert "make the strip's action the active one" in message and "no animation" not in message
    result = sb.bake.smooth([obj], sb.bake.Options())
    assert result.skipped[0].startswith("Pushed: its motion is in NLA strips")


@pytest.mark.parametrize("muted", ["track", "strip", "nla off"])
def test_muted_nla_below_the_action_does_not_block(sb, capfd, muted):
    obj = keyed("Layered")
    other = keyed("Other")
    other_action = other.animation_data.action
    track = obj.animation_data.nla_tracks.new()
    strip = track.strips.new("Idle", 1, other_action)
    h.select_only(obj)
    with pytest.raises(RuntimeError, match=r"Layered: has 1 NLA strip\(s\) that play"):
        bpy.ops.screwbender.smooth()  # a playing strip still blocks
    if muted == "track":
        track.mute = True
    elif muted == "strip":
        strip.mute = True
    else:
        obj.animation_data.use_nla = False
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}
    assert obj.animation_data.action.get("screwbender_source") is not None
    assert len(track.strips) == 1  # the NLA is left alone
    # Blender plays the smoothed action alone (the muted NLA adds nothing)
    frames, baked = h.baked_matrices(obj)
    played_basis = h.evaluated_basis(obj, frames[::5])
    gap = np.abs(played_basis - baked[::5]).max()
    print(f"\nMuted NLA {muted}: smoothed; Blender's playback vs baked keys {gap:.2g}")
    assert gap < 1e-5
