"""Issue 28, hardening round 2: every byte an argument costs is in the budget, numpy's own
errors come out named, estimates hold, time limits where memory does not bound the work,
large `previous` angles, and the unnamed error.

Every reproducer runs in its own child process under a 4 GB address-space cap
(`capped.run_capped`), which must exit normally. The child measures the growth of its peak
resident memory over the call: it resets the peak (`/proc/self/clear_refs`), reads its
resident size, runs the call and reads the peak (`VmHWM`). Each test prints the figures it
measures.
"""

from __future__ import annotations

import json  # noqa: F401  (the helpers print JSON in the child)

import numpy as np
import polyscrew
import pytest

from capped import run_capped

MB = 1 << 20

# Helpers run in the capped child: the peak growth of one call, and the estimate of a call
# (what it says it would need, refused with a budget of 0).
PEAK = r"""
import re, time
UNITS = {"B": 1, "kB": 1e3, "MB": 1e6, "GB": 1e9, "TB": 1e12, "PB": 1e15, "EB": 1e18}
K2 = np.tile(np.eye(4), (2, 1, 1))

def _status(key):
    return int(re.search(key + r":\s+(\d+) kB", open("/proc/self/status").read()).group(1)) * 1024

def peak_of(call):
    '''Runs `call` through `report` and prints the growth of the peak resident memory and
    the CPU time it took.'''
    open("/proc/self/clear_refs", "w").write("5")
    before = _status("VmRSS")
    start = time.process_time()
    out = report(call)
    cpu = time.process_time() - start
    print(json.dumps({"growth": _status("VmHWM") - before, "cpu": cpu}), flush=True)
    return out

def need(call):
    '''The bytes `call` says it would need, from its refusal with a budget of 0.'''
    old = ps.set_memory_budget(0)
    try:
        call()
    except ValueError as e:
        m = re.search(r"would need ([0-9.]+) (B|kB|MB|GB|TB|PB|EB), over the memory budget", str(e))
        assert m, str(e)
        return float(m.group(1)) * UNITS[m.group(2)]
    finally:
        ps.set_memory_budget(old)
    raise AssertionError("not refused with a budget of 0")

def curve(k=3):
    co = np.c_[np.arange(k, dtype=float), np.arange(k) % 7]
    return dict(offsets=[0, k], co=co, handle_left=co - [0.3, 0], handle_right=co + [0.3, 0],
                interpolation=np.full(k, 2), easing=np.zeros(k, dtype=np.int64))

def playback():
    c = curve(10)
    return ps.Playback(channels=[("location", 0)], unkeyed=np.zeros(9), mode="XYZ", **c)
"""


def run_peak(code: str, timeout: float = 600) -> list[dict]:
    """Runs `code` after the helpers in a capped child; returns its report lines."""
    return run_capped(PEAK + code, timeout=timeout)


def f32(shape) -> str:
    """A broadcast float32 array of `shape`: it costs its caller nothing."""
    return f"np.broadcast_to(np.float32(0.5), {shape})"


BUDGET = "(or raise the budget with set_memory_budget)"

# --- 1. every byte an argument costs is in the budget ------------------------------------
# (name, the call, its exact message). Each argument is not float64 (float32, bool, int32)
# and broadcast: before, numpy converted it (+2.0 to +3.6 GB) before the budget's check.
CONVERSIONS = [
    ("sample, float32 times", f"ps.sample(K2, [0., 1.], {f32('(250_000_000,)')})",
     f"sample: the sampled poses would need 50.0 GB, over the memory budget of 1.07 GB: sample fewer times at once, or use fewer levels or fewer keys {BUDGET}"),
    ("interpolate, float32 t", f"ps.interpolate(np.eye(4), np.eye(4), {f32('(250_000_000,)')})",
     f"interpolate: the interpolated poses would need 50.0 GB, over the memory budget of 1.07 GB: pass fewer t at once {BUDGET}"),
    ("interpolate, bool t", "ps.interpolate(np.eye(4), np.eye(4), np.broadcast_to(True, (250_000_000,)))",
     f"interpolate: the interpolated poses would need 50.0 GB, over the memory budget of 1.07 GB: pass fewer t at once {BUDGET}"),
    ("rotation_channels, float32 rotations", "ps.rotation_channels(np.broadcast_to(np.eye(3, dtype=np.float32), (28_000_000, 3, 3)), 'XYZ')",
     f"rotation_channels: the rotation channels would need 3.58 GB, over the memory budget of 1.07 GB: convert fewer rotations at once {BUDGET}"),
    ("rotation_matrices, float32 values", f"ps.rotation_matrices({f32('(84_000_000, 3)')}, 'XYZ')",
     f"rotation_matrices: the rotation matrices would need 16.1 GB, over the memory budget of 1.07 GB: pass fewer frames or keys in one call {BUDGET}"),
    ("rotation_matrices, int32 values", "ps.rotation_matrices(np.broadcast_to(np.int32(1), (84_000_000, 3)), 'XYZ')",
     f"rotation_matrices: the rotation matrices would need 16.1 GB, over the memory budget of 1.07 GB: pass fewer frames or keys in one call {BUDGET}"),
    ("Playback.channels, float32 frames", f"playback().channels({f32('(250_000_000,)')})",
     f"Playback.channels: the channel values would need 40.0 GB, over the memory budget of 1.07 GB: pass fewer frames or keys in one call {BUDGET}"),
    ("keys_parameters, float32 frames", f"ps.keys_parameters([0., 1.], {f32('(250_000_000,)')}, size=1.0, poses=K2)",
     f"keys_parameters: timing Keys would need 24.0 GB, over the memory budget of 1.07 GB: pass fewer frames or keys in one call {BUDGET}"),
    ("fit_angular_velocity, float32 sample_times", f"ps.fit_angular_velocity([[1., 0, 0, 0]] * 2, [0., 1.], [0., 1.], np.zeros((2, 3)), sample_times={f32('(250_000_000,)')})",
     f"fit_angular_velocity: the fit would need 34.0 GB, over the memory budget of 1.07 GB: use fewer keys, fewer variable frames (max_frames) or a longer fragment_duration {BUDGET}"),
    ("evaluate_fcurves, int32 codes", "ps.evaluate_fcurves([0.], **{**curve(), 'interpolation': np.broadcast_to(np.int32(2), (2**28,))})",
     f"evaluate_fcurves: the F-curve evaluation would need 25.8 GB, over the memory budget of 1.07 GB: evaluate fewer curves or times in one call {BUDGET}"),
    ("evaluate_fcurves, float32 co", f"ps.evaluate_fcurves([0.], **{{**curve(), 'co': {f32('(2**26, 2)')}}})",
     f"evaluate_fcurves: the F-curve evaluation would need 15.6 GB, over the memory budget of 1.07 GB: evaluate fewer curves or times in one call {BUDGET}"),
    ("denoise, float32 poses", "ps.denoise(np.broadcast_to(np.eye(4, dtype=np.float32), (16_000_000, 4, 4)), np.broadcast_to(np.float32(1), (16_000_000,)))",
     f"denoise: the noise removal would need 30.8 GB, over the memory budget of 1.07 GB: denoise fewer frames or fewer bodies in one call {BUDGET}"),
    ("sweep, float32 vertices", f"ps.sweep({f32('(150_000_000, 3)')}, [[0, 1, 2]], K2)",
     f"sweep: the swept body would need 18.0 GB, over the memory budget of 1.07 GB: use fewer steps, fewer poses or a coarser mesh {BUDGET}"),
    ("sweep, int32 triangles", "ps.sweep(np.eye(3), np.broadcast_to(np.int32(0), (100_000_000, 3)), K2)",
     f"sweep: the swept body would need 34.4 GB, over the memory budget of 1.07 GB: use fewer steps, fewer poses or a coarser mesh {BUDGET}"),
    ("register_points, float32 src", f"ps.register_points({f32('(100_000_000, 3)')}, np.zeros((3, 3)))",
     f"register_points: the point copies would need 4.80 GB, over the memory budget of 1.07 GB: register fewer points {BUDGET}"),
]


@pytest.mark.parametrize("name, call, message", CONVERSIONS, ids=[c[0] for c in CONVERSIONS])
def test_conversions_are_costed_before_numpy_makes_them(name, call, message):
    refused, peak = run_peak(f"peak_of(lambda: {call})")
    print(f"\n{name}: peak growth {peak['growth'] / MB:.1f} MB, {peak['cpu']:.2f} s")
    assert refused == {"error": "ValueError", "message": message}, (name, refused)
    assert peak["growth"] < 16 * MB, (name, peak)


def test_an_accepted_conversion_is_computed_and_costed():
    """A float32 argument the budget accepts is converted and computed like its float64
    twin; its copy is in the estimate (8 bytes per entry more than the float64 call)."""
    lines = run_peak(
        """
t64 = np.linspace(0, 1, 1_000_000)
t32 = t64.astype(np.float32)
a = ps.sample(K2, [0., 1.], t32.astype(np.float64))
b = ps.sample(K2, [0., 1.], t32)
print(json.dumps({"same": bool(np.array_equal(a, b))}))
print(json.dumps({"n64": need(lambda: ps.sample(K2, [0., 1.], t64)), "n32": need(lambda: ps.sample(K2, [0., 1.], t32))}))
"""
    )
    assert lines[0] == {"same": True}
    print(f"\nestimate float64 {lines[1]['n64'] / 1e6:.1f} MB, float32 {lines[1]['n32'] / 1e6:.1f} MB")
    assert lines[1]["n32"] - lines[1]["n64"] == pytest.approx(8e6, rel=0.01)


# --- 2. numpy's own failures, named ------------------------------------------------------

def test_numpys_memory_error_is_a_named_memory_error():
    """With the budget raised, numpy itself cannot allocate the converted copy under the
    cap: a MemoryError naming the function and the argument (it was a TypeError from a
    broken re-raise of `_ArrayMemoryError`)."""
    lines = run_peak(
        f"""
ps.set_memory_budget(1 << 62)
peak_of(lambda: ps.sample(K2, [0., 1.], {f32('(1_000_000_000,)')}))
peak_of(lambda: ps.rotation_matrices({f32('(300_000_000, 3)')}, 'XYZ'))
"""
    )
    sample, sample_peak, matrices, matrices_peak = lines
    print(f"\npeak growth {sample_peak['growth'] / MB:.1f} MB, {matrices_peak['growth'] / MB:.1f} MB")
    assert sample == {
        "error": "MemoryError",
        "message": "sample: times: Unable to allocate 7.45 GiB for an array with shape (1000000000,) and data type float64",
    }
    assert matrices == {
        "error": "MemoryError",
        "message": "rotation_matrices: values: Unable to allocate 6.71 GiB for an array with shape (300000000, 3) and data type float64",
    }
    assert sample_peak["growth"] < 16 * MB and matrices_peak["growth"] < 16 * MB


class Raises:
    """An array-like whose conversion raises `error`."""

    def __init__(self, error: BaseException):
        self.error = error

    def __array__(self, *args, **kwargs):
        raise self.error


@pytest.mark.parametrize(
    "error, expected",
    [
        (RuntimeError("boom"), ValueError),
        (KeyError("k"), ValueError),
        (MemoryError("no room"), MemoryError),
        (TypeError("not here"), TypeError),
        (ValueError("bad"), ValueError),
    ],
)
def test_any_exception_while_reading_is_named(error, expected):
    with pytest.raises(expected) as info:
        polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], Raises(error))
    assert type(info.value) is expected
    assert str(info.value) == f"sample: times: {error}"
    assert info.value.__cause__ is not None


def test_ragged_and_complex_input_are_still_named():
    with pytest.raises(ValueError, match=r"^sample: times: setting an array element with a sequence"):
        polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], [0.0, [1.0, 2.0]])
    with pytest.raises(TypeError, match=r"^sample: times: expected real numbers, got complex128$"):
        polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], np.zeros(3, complex))


def test_keyboard_interrupt_passes_unchanged():
    with pytest.raises(KeyboardInterrupt):
        polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], Raises(KeyboardInterrupt()))


# --- the unnamed error ---------------------------------------------------------------------

def test_a_cycles_setting_that_is_not_a_str_is_named():
    co = np.c_[np.arange(3.0), np.arange(3.0)]
    curve = dict(offsets=[0, 3], co=co, handle_left=co - [0.3, 0], handle_right=co + [0.3, 0],
                 interpolation=np.full(3, 2), easing=np.zeros(3, dtype=np.int64))
    with pytest.raises(TypeError) as info:
        polyscrew.evaluate_fcurves([0.0], **curve, cycles=[{1: "x"}])
    assert str(info.value) == "evaluate_fcurves: cycles[0]: setting names must be str, got int"


# --- 6. time limits where memory does not bound the work ---------------------------------

SPINS = r"""
def spins(k):
    '''A playback of nine LINEAR curves over `k` keys one frame apart, the three Euler
    angles turning 10,000 radians per frame: every span takes MAX_SPAN_SAMPLES samples.'''
    f = np.arange(k, dtype=float)
    cols = [("location", i) for i in range(3)] + [("rotation_euler", i) for i in range(3)] + [("scale", i) for i in range(3)]
    co = np.concatenate([np.stack([f, {"location": 0.1 * f, "rotation_euler": 1e4 * f, "scale": 1 + 0 * f}[p]], 1) for p, _ in cols])
    n = len(co)
    pb = ps.Playback(channels=cols, unkeyed=np.array([0, 0, 0, 0, 0, 0, 1, 1, 1.0]), mode="XYZ",
                     offsets=np.arange(0, n + 1, k), co=co, handle_left=co - [1, 0], handle_right=co + [1, 0],
                     interpolation=np.full(n, ps.INTERPOLATIONS.index("LINEAR")), easing=np.zeros(n, int))
    return pb, f
"""


def test_analyse_spans_refuses_more_samples_than_its_cap_before_taking_any():
    """16,000 spans each turning 10,000 radians took 28 to 39 s; now refused up front. The
    most the cap accepts (512 such spans, each a spin) is computed within a few seconds."""
    assert polyscrew.MAX_ANALYSIS_SAMPLES == 512 * polyscrew.MAX_SPAN_SAMPLES == 2**21
    lines = run_peak(
        SPINS
        + """
pb, f = spins(16_001)
peak_of(lambda: ps.analyse_spans(pb, f))
pb, f = spins(514)
peak_of(lambda: ps.analyse_spans(pb, f))
pb, f = spins(513)
out = peak_of(lambda: ps.analyse_spans(pb, f))
print(json.dumps({"turn": float(out[2].min()), "inserted": len(out[3])}))
"""
    )
    many, many_peak, over, over_peak, at_cap, at_cap_peak, result = lines
    print(f"\n16,000 spans refused in {many_peak['cpu']:.3f} s; 513 in {over_peak['cpu']:.3f} s; "
          f"512 spans (2,097,152 samples) computed in {at_cap_peak['cpu']:.2f} s of CPU, "
          f"peak growth {at_cap_peak['growth'] / MB:.0f} MB, {result['inserted']} frames inserted")
    hint = "(a span whose rotation channels change by d degrees takes d / 10 of them, 8 to 4096): analyse fewer key frames at once"
    assert many == {"error": "ValueError", "message": f"analyse_spans: frames: the 16000 key spans would take 65536000 samples of the playback, more than 2097152 {hint}"}
    assert over == {"error": "ValueError", "message": f"analyse_spans: frames: the 513 key spans would take 2101248 samples of the playback, more than 2097152 {hint}"}
    assert many_peak["cpu"] < 1.0 and over_peak["cpu"] < 1.0
    assert at_cap == {"finite": True}
    assert result["turn"] > 1000  # every span a spin (its samples alias: under 4096 pi)
    assert at_cap_peak["cpu"] < 8.0


def test_rotation_channels_has_a_cap_on_rotations():
    """At the largest size the default budget accepts (2**24 rotations, quaternion) the call
    is computed within seconds; one more is refused before any is read, whatever the
    budget."""
    assert polyscrew.MAX_ROTATIONS == 2**24
    lines = run_peak(
        """
r = np.broadcast_to(np.eye(3), (2**24, 3, 3))
peak_of(lambda: ps.rotation_channels(r, 'QUATERNION'))
r = np.broadcast_to(np.eye(3), (2**24 + 1, 3, 3))
ps.set_memory_budget(1 << 40)
peak_of(lambda: ps.rotation_channels(r, 'XYZ'))
""",
    )
    at_cap, at_cap_peak, over, over_peak = lines
    print(f"\n2**24 rotations (QUATERNION) in {at_cap_peak['cpu']:.2f} s of CPU, peak growth "
          f"{at_cap_peak['growth'] / MB:.0f} MB; 2**24 + 1 refused in {over_peak['cpu']:.3f} s")
    assert at_cap == {"finite": True}
    assert at_cap_peak["growth"] <= 2**30 + 16 * MB
    assert over == {"error": "ValueError", "message": "rotation_channels: rotations: 16777217 rotations, more than 16777216 in one call: convert fewer rotations at once"}
    assert over_peak["cpu"] < 0.5 and over_peak["growth"] < 16 * MB
    assert at_cap_peak["cpu"] < 8.0


# --- 7. large previous angles --------------------------------------------------------------

RZ90 = np.array([[0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda: polyscrew.rotation_channels(RZ90[None], "XYZ", previous=[0, 0, 1e17]),
         "rotation_channels: previous value 2 (1e17) is outside the working range +-1e9"),
        (lambda: polyscrew.rotation_channels(RZ90[None], "ZYX", previous=[-1.5e9, 0, 0]),
         "rotation_channels: previous value 0 (-1.5e9) is outside the working range +-1e9"),
        (lambda: polyscrew.rotation_channels(RZ90[None], "AXIS_ANGLE", previous=[1e16, 0, 0, 1]),
         "rotation_channels: previous value 0 (1e16) is outside the working range +-1e9"),
        (lambda: polyscrew.sample_channels(np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], [0.5], "XYZ", previous=[0, 0, 1e17]),
         "sample_channels: previous value 2 (1e17) is outside the working range +-1e9"),
    ],
)
def test_previous_angles_beyond_the_range_are_refused(call, message):
    with pytest.raises(ValueError) as info:
        call()
    assert str(info.value) == message


EULER = ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]
PREVIOUS = [1e9, -1e9, 999_999_999.5, 123_456_789.123, -7.7e8, 1e6 + 0.25, 3e4, -2.5]


def euler_reference(values: np.ndarray, mode: str) -> np.ndarray:
    """Blender's Euler matrices by scipy (extrinsic axes in the order of the mode's name;
    numpy's sin and cos reduce large arguments exactly)."""
    from scipy.spatial.transform import Rotation

    order = mode.lower()
    return Rotation.from_euler(order, values[:, ["xyz".index(a) for a in order]]).as_matrix()


@pytest.mark.parametrize("mode", EULER)
def test_euler_channels_are_correct_and_continued_for_every_previous_in_range(mode, rng):
    rotations = [np.eye(3), RZ90]
    from scipy.spatial.transform import Rotation

    rotations += list(Rotation.random(6, random_state=rng).as_matrix())
    worst = 0.0
    for p in PREVIOUS:
        previous = np.array([p, -p / 3, p / 7])
        for r in rotations:
            got = polyscrew.rotation_channels(r[None], mode, previous=previous)
            assert np.all(np.abs(got[0] - previous) <= np.pi + 1e-6), (mode, p, got, previous)
            err = np.abs(euler_reference(got, mode)[0] - r).max()
            worst = max(worst, err)
    print(f"\n{mode}: worst matrix error {worst:.2e} for previous up to 1e9")
    assert worst < 1e-6


def test_axis_angle_and_sampled_channels_are_correct_for_every_previous_in_range(rng):
    from scipy.spatial.transform import Rotation

    worst = 0.0
    for p in PREVIOUS:
        for r in Rotation.random(6, random_state=rng).as_matrix():
            got = polyscrew.rotation_channels(r[None], "AXIS_ANGLE", previous=[p, 0, 0, 1])[0]
            assert abs(got[0] - p) <= np.pi + 1e-6, (p, got)
            err = np.abs(Rotation.from_rotvec(got[0] * got[1:]).as_matrix() - r).max()
            worst = max(worst, err)
        poses = np.tile(np.eye(4), (2, 1, 1))
        poses[1, :3, :3] = RZ90
        loc, rot = polyscrew.sample_channels(poses, [0.0, 1.0], [0.0, 0.5, 1.0], "XYZ", previous=[p, p, p])
        want = polyscrew.sample(poses, [0.0, 1.0], [0.0, 0.5, 1.0])[:, :3, :3]
        assert np.all(np.abs(rot - p) <= np.pi + 1e-6)
        worst = max(worst, np.abs(euler_reference(rot, "XYZ") - want).max())
    print(f"\nAXIS_ANGLE and sample_channels: worst matrix error {worst:.2e}")
    assert worst < 1e-6


# --- 4. estimates hold -------------------------------------------------------------------

ESTIMATE_SETUP = r"""
def keys(n, seed=0):
    rng = np.random.default_rng(seed)
    out = np.tile(np.eye(4), (n, 1, 1))
    a = rng.uniform(0, 2, n)
    out[:, 0, 0] = out[:, 1, 1] = np.cos(a)
    out[:, 0, 1], out[:, 1, 0] = -np.sin(a), np.sin(a)
    out[:, :3, 3] = rng.normal(size=(n, 3)) + np.arange(n)[:, None]
    return out

def noisy(n, seed=0):
    rng = np.random.default_rng(seed)
    t = np.arange(n, dtype=float)
    a = 0.01 * t
    p = np.tile(np.eye(4), (n, 1, 1))
    p[:, 0, 0] = p[:, 1, 1] = np.cos(a)
    p[:, 0, 1], p[:, 1, 0] = -np.sin(a), np.sin(a)
    p[:, :3, 3] = np.stack([np.sin(a), np.cos(a), 0.01 * t], 1) + rng.normal(0, 1e-3, (n, 3))
    return p, t

def estimate_and_peak(call):
    print(json.dumps({"estimate": need(call)}), flush=True)
    peak_of(call)
"""

FIT = "ps.fit_angular_velocity([[1.0, 0, 0, 0], [np.cos(0.5), 0, 0, np.sin(0.5)]], [0.0, 1.0], [0.0, 1.0], [[0, 0, 1.0]] * 2)"

# name: (setup, the call); each large enough that a constant overhead does not matter
ESTIMATES = {
    "sample": ("k, t = keys(50), np.linspace(0, 49, 1_000_000)", "ps.sample(k, np.arange(50.0), t, levels=8)"),
    "sample, float32 times": ("k, t = keys(50), np.linspace(0, 49, 1_000_000).astype(np.float32)", "ps.sample(k, np.arange(50.0), t, levels=8)"),
    "sample_channels": ("k, t = keys(50), np.linspace(0, 49, 1_000_000)", "ps.sample_channels(k, np.arange(50.0), t, 'XYZ', levels=8)"),
    "subdivide": ("k = keys(1000)", "ps.subdivide(k, levels=10)"),
    "subdivide_vectors": ("v = keys(1000)[:, :3, 3]", "ps.subdivide_vectors(v, levels=10)"),
    "sample_vectors": ("v, t = keys(50)[:, :3, 3], np.linspace(0, 49, 1_000_000)", "ps.sample_vectors(v, np.arange(50.0), t, levels=8)"),
    "interpolate": ("a, b = keys(2); t = np.linspace(-1, 2, 1_000_000)", "ps.interpolate(a, b, t)"),
    "rotation_channels": ("r = keys(2_000_000)[:, :3, :3].copy()", "ps.rotation_channels(r, 'XYZ')"),
    "rotation_channels, float32": ("r = keys(2_000_000)[:, :3, :3].astype(np.float32)", "ps.rotation_channels(r, 'QUATERNION')"),
    "rotation_matrices": ("v = np.random.default_rng(0).normal(size=(2_000_000, 3))", "ps.rotation_matrices(v, 'XYZ')"),
    "feature_motion": ("k = keys(100)", "ps.feature_motion(k, levels=10)"),
    "sample_feature": ("k, t = keys(20), np.linspace(0, 19, 1_000_000)", "ps.sample_feature(k, np.arange(20.0), t, 'four_point', levels=8)"),
    "register_points": ("p = np.random.default_rng(0).normal(size=(2_000_000, 3)); q = p + 1.0", "ps.register_points(p, q)"),
    "inertia_points": ("p = np.random.default_rng(0).normal(size=(2_000_000, 3))", "ps.inertia_points(p)"),
    "fit_angular_velocity": ("t = np.linspace(0, 1, 1_000_000)", "ps.fit_angular_velocity([[1.0, 0, 0, 0], [np.cos(0.5), 0, 0, np.sin(0.5)]], [0.0, 1.0], [0.0, 1.0], [[0, 0, 1.0]] * 2, sample_times=t)"),
    "AngularVelocityFit.sample": (f"fit = {FIT}; t = np.linspace(0, 1, 1_000_000)", "fit.sample(t)"),
    "AngularVelocityFit.angular_velocity": (f"fit = {FIT}; t = np.linspace(0, 1, 1_000_000)", "fit.angular_velocity(t)"),
    "evaluate_fcurves": ("c = curve(1000); t = np.linspace(-5, 1005, 4_000_000)", "ps.evaluate_fcurves(t, **c)"),
    "Playback.channels": ("pb = playback(); t = np.linspace(-5, 15, 2_000_000)", "pb.channels(t)"),
    "keys_parameters": ("k = keys(50); t = np.linspace(0, 49, 2_000_000)", "ps.keys_parameters(np.arange(50.0), t, size=1.0, poses=k)"),
    "analyse_spans": ("pb = playback(); f = np.linspace(0, 9, 250_000)", "ps.analyse_spans(pb, f)"),
    "denoise": ("p, t = noisy(400_000)", "ps.denoise(p, t)"),
    "denoise, float32 poses": ("p, t = noisy(300_000); p = p.astype(np.float32)", "ps.denoise(p, t)"),
    "denoise, a rig of 4 bodies": ("p, t = noisy(100_000); p = np.stack([p] * 4)", "ps.denoise(p, t)"),
}


@pytest.mark.parametrize("name", ESTIMATES)
def test_peak_memory_stays_within_the_estimate(name):
    """The call's peak resident growth is at most what it says it needs (its refusal with a
    budget of 0), plus 4 MB for what no estimate counts (the interpreter's own objects, a
    thread's stack, the allocator's granularity)."""
    setup, call = ESTIMATES[name]
    lines = run_peak(ESTIMATE_SETUP + setup + f"\nestimate_and_peak(lambda: {call})")
    estimate, result, peak = lines[0]["estimate"], lines[1], lines[2]
    print(f"\n{name}: estimate {estimate / 1e6:.1f} MB, peak growth {peak['growth'] / 1e6:.1f} MB "
          f"({peak['growth'] / estimate:.0%}), {peak['cpu']:.2f} s")
    assert result == {"finite": True}, (name, result)
    assert estimate > 20e6, (name, "not a large case", estimate)
    assert peak["growth"] <= estimate + 4 * MB, (name, estimate, peak)


def test_sweep_peak_memory_stays_within_its_stated_estimate():
    """The sweep checks its body up front (what a budget of 0 reports) and its output span by
    span: its stated estimate is the body's plus 48 bytes per output vertex and 36 per output
    triangle (the module documentation). A 20,480-triangle sphere over 64 screws."""
    lines = run_peak(
        """
seg, rings = 128, 81
th = np.pi * np.arange(1, rings) / rings
ph = 2 * np.pi * np.arange(seg) / seg
v = np.array([[0, 0, 1]] + [[np.sin(a) * np.cos(b), np.sin(a) * np.sin(b), np.cos(a)] for a in th for b in ph] + [[0, 0, -1]], float)
idx = lambda r, s: 1 + r * seg + s % seg
t = [[0, idx(0, s), idx(0, s + 1)] for s in range(seg)]
for r in range(rings - 2):
    for s in range(seg):
        t += [[idx(r, s), idx(r + 1, s), idx(r + 1, s + 1)], [idx(r, s), idx(r + 1, s + 1), idx(r, s + 1)]]
t += [[len(v) - 1, idx(rings - 2, s + 1), idx(rings - 2, s)] for s in range(seg)]
t = np.array(t)
def pose(i):
    a = 0.05 * i
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0, 0.3 * i], [s, c, 0, np.sin(i)], [0, 0, 1, 0.1 * i], [0, 0, 0, 1.0]])
poses = np.stack([pose(i) for i in range(65)])
print(json.dumps({"triangles": len(t), "estimate": need(lambda: ps.sweep(v, t, poses, steps=8))}))
out = peak_of(lambda: ps.sweep(v, t, poses, steps=8))
print(json.dumps({"vertices": len(out[0]), "triangles": len(out[1])}))
"""
    )
    body, result, peak, size = lines
    stated = body["estimate"] + 48 * size["vertices"] + 36 * size["triangles"]
    print(f"\nsweep of {body['triangles']} triangles: stated {stated / 1e6:.1f} MB (body {body['estimate'] / 1e6:.1f} MB), "
          f"peak growth {peak['growth'] / 1e6:.1f} MB ({peak['growth'] / stated:.0%}), {size['vertices']} vertices out")
    assert result == {"finite": True}
    assert stated > 20e6
    assert peak["growth"] <= stated + 4 * MB, (stated, peak)
