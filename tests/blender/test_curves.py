"""`curves.evaluate` (one `polyscrew` call) against Blender's own `FCurve.evaluate(frame)`.

Random curves built in real Blender through `keyframe_insert` and the keyframe RNA: every
interpolation, every easing with every mode and random back / amplitude / period, every
handle type including FREE and ALIGNED handles pulled past the neighbouring key (Blender
must clamp them), subframe keys, keys closer than Blender's key search threshold, CONSTANT
and LINEAR extrapolation, the Cycles modifier in every mode before and after with cycle
counts, restricted range and influence. Each curve is evaluated at its keys, just beside
them, between them, before and after, and several cycles out. The reference is
`fcurve.evaluate(t)` in a Python loop; the promise is agreement to 1e-5 relative, the
measured error is printed per feature (``pytest -s``): it is exactly zero, because the core
mirrors Blender's float32 arithmetic.
"""

from __future__ import annotations

import time

import bpy
import numpy as np
import pytest

from conftest import addon_module

#: The agreement promised; the measured one is 0 (printed).
RELATIVE_TOLERANCE = 1e-5

INTERPOLATIONS = [i.identifier for i in bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items]
EASINGS = ["AUTO", "EASE_IN", "EASE_OUT", "EASE_IN_OUT"]
HANDLE_TYPES = ["FREE", "ALIGNED", "VECTOR", "AUTO", "AUTO_CLAMPED"]
CYCLE_MODES = ["NONE", "REPEAT", "REPEAT_OFFSET", "MIRROR"]
UNSUPPORTED = ["GENERATOR", "FNGENERATOR", "ENVELOPE", "NOISE", "LIMITS", "STEPPED"]


@pytest.fixture
def curves():
    return addon_module("blender.curves")


@pytest.fixture
def channels():
    return addon_module("blender.channels")


class Builder:
    """Curves on one empty, one custom float property each, keyed through `keyframe_insert`
    and found through the add-on's `channels.object_fcurves` (every Blender version)."""

    def __init__(self, channels, name="Curves"):
        self.channels = channels
        self.obj = bpy.data.objects.new(name, None)
        bpy.context.scene.collection.objects.link(self.obj)
        self.count = 0

    def curve(self, frames, values) -> bpy.types.FCurve:
        prop = f"p{self.count}"
        self.count += 1
        self.obj[prop] = 0.0
        path = f'["{prop}"]'
        for f, v in zip(frames, values):
            self.obj[prop] = float(v)
            self.obj.keyframe_insert(path, frame=float(f))
        return next(fc for fc in self.channels.object_fcurves(self.obj) if fc.data_path == path)


def random_frames(rng, n, spacing=(0.3, 12.0)):
    """n increasing subframe key frames."""
    return np.cumsum(rng.uniform(*spacing, n)) + rng.uniform(-20, 20)


def style_keys(fc, rng, interpolations=INTERPOLATIONS, pull=0.5):
    """Random interpolation, easing, parameters and handle types; with probability `pull`
    FREE / ALIGNED handles pulled up to three spans past the neighbouring key."""
    points = fc.keyframe_points
    span = max(points[-1].co[0] - points[0].co[0], 1.0)
    for kp in points:
        kp.interpolation = interpolations[rng.integers(len(interpolations))]
        kp.easing = EASINGS[rng.integers(4)]
        kp.back = rng.uniform(0.0, 4.0)
        kp.amplitude = rng.choice([0.0, rng.uniform(0.0, 8.0)])
        kp.period = rng.choice([0.0, rng.uniform(0.1, 8.0)])
        kp.handle_left_type = HANDLE_TYPES[rng.integers(5)]
        kp.handle_right_type = HANDLE_TYPES[rng.integers(5)]
        if rng.random() < pull:
            kind = rng.choice(["FREE", "ALIGNED"])
            kp.handle_left_type = kp.handle_right_type = kind
            x, y = kp.co
            kp.handle_left = (x - rng.uniform(0.0, 3.0) * span, y + rng.normal(0, 6))
            kp.handle_right = (x + rng.uniform(0.0, 3.0) * span, y + rng.normal(0, 6))
    fc.update()


def add_cycles(fc, rng, before=None, after=None, counts=None, range_influence=False):
    mod = fc.modifiers.new("CYCLES")
    mod.mode_before = before or CYCLE_MODES[rng.integers(4)]
    mod.mode_after = after or CYCLE_MODES[rng.integers(4)]
    mod.cycles_before, mod.cycles_after = counts if counts is not None else rng.integers(0, 4, 2).tolist()
    if range_influence:
        lo, hi = fc.keyframe_points[0].co[0], fc.keyframe_points[-1].co[0]
        span = hi - lo
        mod.use_restricted_range = True
        mod.frame_start = lo - rng.uniform(0, 3) * span
        mod.frame_end = hi + rng.uniform(0, 3) * span
        mod.blend_in = rng.uniform(0, span)
        mod.blend_out = rng.uniform(0, span)
        mod.use_influence = True
        mod.influence = rng.uniform(0.2, 1.0)
    fc.update()
    return mod


def probe_times(fc, rng, cycles_out=5):
    """Times at and beside every key (inside and at the edge of Blender's 1e-4 snap),
    between keys (dense), before and after, and up to `cycles_out` key ranges out, with whole
    key ranges out to the ulp."""
    keys = np.array([kp.co[0] for kp in fc.keyframe_points], dtype=np.float32)
    lo, hi = keys.min(), keys.max()
    span = max(float(hi - lo), 1.0)
    # Whole cycles out, computed in float32 as Blender's times are, and 3 ulps either side:
    # where float rounding decides which cycle a time falls in.
    whole = np.concatenate([hi + np.float32(hi - lo) * np.arange(1, cycles_out + 1, dtype=np.float32),
                            lo - np.float32(hi - lo) * np.arange(1, cycles_out + 1, dtype=np.float32)])
    ulps = [whole]
    for direction in (np.inf, -np.inf):
        step = whole
        for _ in range(3):
            step = np.nextafter(step, np.float32(direction))
            ulps.append(step)
    near = np.concatenate([keys + d for d in (-2e-4, -1.01e-4, -9.9e-5, -1e-6, 0.0, 1e-6, 9.9e-5, 1.01e-4, 2e-4, 0.5, -0.5)])
    return np.concatenate([
        near,
        np.linspace(lo, hi, 400),
        rng.uniform(lo - cycles_out * span, hi + cycles_out * span, 400),
        np.concatenate(ulps).astype(np.float64),
        np.round(rng.uniform(lo - 3 * span, hi + 3 * span, 100)),  # whole frames
    ])


def compare(curves, fcurves, times) -> tuple[float, float, float]:
    """Largest relative and absolute error of `curves.evaluate` against the loop of
    `fcurve.evaluate`, and the fraction of values that are bit-identical."""
    ours = curves.evaluate(fcurves, times)
    ref = np.array([[fc.evaluate(float(t)) for t in times] for fc in fcurves])
    assert ours.shape == (len(fcurves), len(times))
    diff = np.abs(ours - ref)
    rel = diff / np.maximum(1.0, np.abs(ref))
    return float(rel.max()), float(diff.max()), float((diff == 0).mean())


def build_features(channels, seed):
    """Curves grouped by the feature they exercise: name -> (fcurves, times)."""
    rng = np.random.default_rng(seed)
    b = Builder(channels)
    groups: dict[str, list] = {}

    def add(name, fc, times=None):
        groups.setdefault(name, []).append((fc, probe_times(fc, rng) if times is None else times))

    for ipo in INTERPOLATIONS:
        for easing in EASINGS if ipo not in ("CONSTANT", "LINEAR", "BEZIER") else ["AUTO"]:
            for _ in range(3):
                n = int(rng.integers(2, 6))
                fc = b.curve(random_frames(rng, n), rng.normal(0, 4, n))
                style_keys(fc, rng, interpolations=[ipo], pull=0.3)
                for kp in fc.keyframe_points:
                    kp.easing = easing
                fc.extrapolation = rng.choice(["CONSTANT", "LINEAR"])
                add(f"{ipo} {easing}" if ipo not in ("CONSTANT", "LINEAR", "BEZIER") else ipo, fc)
    for kind in HANDLE_TYPES:
        for _ in range(4):
            n = int(rng.integers(2, 7))
            fc = b.curve(random_frames(rng, n), rng.normal(0, 4, n))
            for kp in fc.keyframe_points:
                kp.interpolation = "BEZIER"
                kp.handle_left_type = kp.handle_right_type = kind
            if kind in ("FREE", "ALIGNED"):  # pulled past the neighbours: Blender must clamp
                span = fc.keyframe_points[-1].co[0] - fc.keyframe_points[0].co[0]
                for kp in fc.keyframe_points:
                    x, y = kp.co
                    kp.handle_left = (x - rng.uniform(1.0, 3.0) * span, y + rng.normal(0, 6))
                    kp.handle_right = (x + rng.uniform(1.0, 3.0) * span, y + rng.normal(0, 6))
            fc.extrapolation = "LINEAR"
            fc.update()
            add(f"handles {kind}", fc)
    for extrapolation in ("CONSTANT", "LINEAR"):
        for _ in range(8):
            n = int(rng.integers(1, 5))
            fc = b.curve(random_frames(rng, n), rng.normal(0, 4, n))
            style_keys(fc, rng)
            fc.extrapolation = extrapolation
            add(f"extrapolation {extrapolation}", fc)
    for _ in range(6):  # subframe keys less than a frame apart
        n = int(rng.integers(3, 8))
        fc = b.curve(random_frames(rng, n, spacing=(0.02, 0.9)), rng.normal(0, 4, n))
        style_keys(fc, rng)
        add("subframe keys", fc)
    for _ in range(4):  # keys closer than Blender's 1e-4 search threshold (set through co)
        fc = b.curve([0.0, 5.0, 10.0, 15.0], rng.normal(0, 4, 4))
        style_keys(fc, rng)
        gap = rng.uniform(1e-5, 3e-4)
        kp = fc.keyframe_points
        kp[2].co = (kp[1].co[0] + gap, kp[2].co[1])
        kp[3].co = (kp[2].co[0] + gap, kp[3].co[1])
        add("keys closer than 1e-4", fc)
    for before in CYCLE_MODES:
        for after in CYCLE_MODES:
            n = int(rng.integers(2, 6))
            fc = b.curve(random_frames(rng, n), rng.normal(0, 4, n))
            style_keys(fc, rng, pull=0.2)
            fc.extrapolation = rng.choice(["CONSTANT", "LINEAR"])
            add_cycles(fc, rng, before, after, counts=(0, 0))
            add(f"cycles {before} / {after}", fc)
    for _ in range(12):
        n = int(rng.integers(2, 6))
        fc = b.curve(random_frames(rng, n), rng.normal(0, 4, n))
        style_keys(fc, rng, pull=0.2)
        fc.extrapolation = rng.choice(["CONSTANT", "LINEAR"])
        add_cycles(fc, rng, counts=rng.integers(1, 4, 2).tolist())
        add("cycles with counts", fc)
    for _ in range(12):
        n = int(rng.integers(2, 6))
        fc = b.curve(random_frames(rng, n), rng.normal(0, 4, n))
        style_keys(fc, rng, pull=0.2)
        add_cycles(fc, rng, range_influence=True)
        add("cycles range + influence", fc)
    return groups


@pytest.mark.parametrize("seed", [1, 2])
def test_evaluate_equals_blenders_fcurve_evaluate(curves, channels, seed):
    groups = build_features(channels, seed)
    worst = 0.0
    lines = []
    total = exact_total = 0
    for name, items in groups.items():
        fcurves = [fc for fc, _ in items]
        # One call for the whole group: every curve at every time of the group.
        times = np.concatenate([t for _, t in items])
        rel, absolute, exact = compare(curves, fcurves, times)
        worst = max(worst, rel)
        total += len(fcurves) * len(times)
        exact_total += exact * len(fcurves) * len(times)
        lines.append(f"  {name:34s} {len(fcurves):3d} curves x {len(times):5d} times: "
                     f"max rel {rel:.1e}, max abs {absolute:.1e}, identical {exact:.4%}")
        assert rel <= RELATIVE_TOLERANCE, f"{name}: {rel}"
    print(f"\nBlender {bpy.app.version_string}, seed {seed}: {total} values, "
          f"{exact_total / total:.4%} bit-identical, largest relative error {worst:.1e}")
    print("\n".join(lines))


def test_transform_channels_and_playback(curves, channels):
    """Real transform curves: `curves.evaluate` equals `evaluate` and the scene's playback
    (`frame_set` with subframes) of `location` and `rotation_euler`."""
    rng = np.random.default_rng(5)
    obj = bpy.data.objects.new("Body", None)
    bpy.context.scene.collection.objects.link(obj)
    for f in (1.0, 7.5, 13.0, 30.25):
        obj.location = rng.normal(0, 3, 3)
        obj.rotation_euler = rng.normal(0, 3, 3)
        obj.keyframe_insert("location", frame=f)
        obj.keyframe_insert("rotation_euler", frame=f)
    fcurves = sorted(channels.object_fcurves(obj), key=lambda fc: (fc.data_path, fc.array_index))
    assert len(fcurves) == 6
    for fc in fcurves:
        style_keys(fc, rng, pull=0.3)
    add_cycles(fcurves[0], rng, "REPEAT_OFFSET", "MIRROR", counts=(0, 2))
    frames = np.linspace(-40, 80, 241) + 0.25
    rel, _, exact = compare(curves, fcurves, frames)
    assert rel <= RELATIVE_TOLERANCE and exact == 1.0
    ours = curves.evaluate(fcurves, frames)
    scene = bpy.context.scene
    played = []
    for f in frames[::10]:
        scene.frame_set(int(np.floor(f)), subframe=float(f - np.floor(f)))
        played.append([obj.location[i] for i in range(3)] + [obj.rotation_euler[i] for i in range(3)])
    order = [("location", i) for i in range(3)] + [("rotation_euler", i) for i in range(3)]
    index = {(fc.data_path, fc.array_index): c for c, fc in enumerate(fcurves)}
    expected = np.array([ours[index[o], ::10] for o in order]).T
    np.testing.assert_allclose(np.array(played), expected, rtol=1e-6, atol=1e-6)


@pytest.mark.parametrize("kind", UNSUPPORTED)
def test_other_modifiers_are_refused_by_name_and_ignored_when_muted(curves, channels, kind):
    rng = np.random.default_rng(len(kind))
    b = Builder(channels)
    ok = b.curve([1, 10, 20], [0, 5, 2])
    fc = b.curve([1, 10, 20], [0, 5, 2])
    add_cycles(fc, rng, "REPEAT_OFFSET", "REPEAT_OFFSET", counts=(0, 0))
    mod = fc.modifiers.new(kind)
    mod.name = f"My {kind}"
    assert curves.problems(ok) == []
    assert len(curves.problems(fc)) == 1
    with pytest.raises(curves.UnsupportedCurve) as info:
        curves.evaluate([ok, fc], np.arange(0.0, 30.0))
    message = str(info.value)
    assert f'{fc.data_path}[0]' in message and f"My {kind}" in message and ok.data_path not in message
    assert info.value.problems[0][0] == fc
    mod.mute = True  # Blender ignores a muted modifier, so may we
    rel, _, exact = compare(curves, [ok, fc], np.linspace(-30, 60, 181))
    assert rel <= RELATIVE_TOLERANCE and exact == 1.0


def test_muted_curves_groups_samples_and_empty_curves_are_refused(curves, channels):
    b = Builder(channels)
    muted = b.curve([1, 10], [0, 1])
    muted.mute = True
    sampled = b.curve([1, 10], [0, 1])
    sampled.convert_to_samples(1, 10)
    obj = b.obj
    obj.keyframe_insert("location", index=0, frame=1, group="Held")
    grouped = next(fc for fc in channels.object_fcurves(obj) if fc.data_path == "location")
    grouped.group.mute = True
    reasons = {curves.curve_name(fc): curves.problems(fc) for fc in (muted, sampled, grouped)}
    assert any("muted" in r for r in reasons[curves.curve_name(muted)])
    assert any("sample points" in r for r in reasons[curves.curve_name(sampled)])
    assert any("group 'Held' is muted" in r for r in reasons[curves.curve_name(grouped)])
    with pytest.raises(curves.UnsupportedCurve, match="is muted.*sample points.*group 'Held'"):
        curves.evaluate([muted, sampled, grouped], [1.0])


def test_speed_against_a_python_loop(curves, channels):
    """10 Bezier curves x 1,000 frames: one call against `fcurve.evaluate` in a loop, same
    session, runs interleaved, CPU time of this thread (the machine may be shared), medians
    of 7 runs; figures printed."""
    rng = np.random.default_rng(3)
    b = Builder(channels)
    fcurves = []
    for _ in range(10):
        fc = b.curve(random_frames(rng, 20, spacing=(20, 80)), rng.normal(0, 3, 20))
        style_keys(fc, rng, interpolations=["BEZIER"], pull=0.2)
        fcurves.append(fc)
    frames = np.linspace(fcurves[0].keyframe_points[0].co[0], fcurves[0].keyframe_points[-1].co[0], 1000)
    packed = curves.read(fcurves)
    runs = {"evaluate": [], "evaluate_packed": [], "loop": []}
    jobs = {
        "evaluate": lambda: curves.evaluate(fcurves, frames),
        "evaluate_packed": lambda: curves.evaluate_packed(packed, frames),
        "loop": lambda: [[fc.evaluate(f) for f in frames] for fc in fcurves],
    }
    for _ in range(7):
        for name, job in jobs.items():
            start = time.thread_time()
            job()
            runs[name].append(time.thread_time() - start)
    ours, evaluate_only, loop = (float(np.median(runs[n])) for n in ("evaluate", "evaluate_packed", "loop"))
    print(f"\nBlender {bpy.app.version_string}, 10 Bezier curves x 1,000 frames (thread CPU, median "
          f"of 7): curves.evaluate {ours * 1e3:.2f} ms (read {(ours - evaluate_only) * 1e3:.2f} ms + "
          f"evaluate {evaluate_only * 1e3:.2f} ms), fcurve.evaluate loop {loop * 1e3:.1f} ms: "
          f"{loop / ours:.1f}x")
    assert ours < loop
