"""Huge input is refused before anything is reserved, and what is accepted stays within the
memory the module says it needs (issue 15's promise: bad or huge input is a clear error,
never an abort, a panic or a frozen Blender; issue 28: every byte an argument costs is in
the budget, estimates hold, time limits where memory does not bound the work).

- The issue-15 reproducers (huge levels, fragments, steps, times) are refused with a clear
  message; the budget is settable and restored.
- Arguments that are not float64 are costed before numpy converts them; numpy's own
  MemoryError comes out named; the F-curve evaluation counts its Bezier segments; sequences
  (`held`, `constrained`, `channels`, `extrapolation`, `cycles`) are refused when too long
  before anything is reserved for them (`range(2**62)`); a broadcast stiffness is expanded
  only after the budget's check.
- Calls whose work memory does not bound (`analyse_spans`, `rotation_channels`) have caps.
- The peak memory measured stays within the estimate the module checks.

Every huge request runs in its own child process under a 4 GB address-space cap
(`capped.run_capped`), which must exit normally. Where the peak is measured the child resets
it (`/proc/self/clear_refs`), reads its resident size, runs the call and reads the peak
(`VmHWM`). Each test prints the figures it measures. The per-function tests at the
documented limits are in `test_limits.py`, the fuzz suite in `fuzz.py`.
"""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import numpy as np
import polyscrew
import pytest

from capped import KEYS, NEED, run_capped
from fcurve_args import curve

EYE2 = "np.tile(np.eye(4), (2, 1, 1))"


# Child code: a UV sphere of `seg` segments x `rings` rings, and `n` poses along a tumbling helix.
UV_SPHERE_AND_HELIX = """
def uv_sphere(seg, rings):
    th = np.pi * np.arange(1, rings) / rings
    ph = 2 * np.pi * np.arange(seg) / seg
    v = [[0, 0, 1]] + [[np.sin(a) * np.cos(b), np.sin(a) * np.sin(b), np.cos(a)] for a in th for b in ph] + [[0, 0, -1]]
    v = np.array(v, float)
    idx = lambda r, s: 1 + r * seg + s % seg
    t = [[0, idx(0, s), idx(0, s + 1)] for s in range(seg)]
    for r in range(rings - 2):
        for s in range(seg):
            t += [[idx(r, s), idx(r + 1, s), idx(r + 1, s + 1)], [idx(r, s), idx(r + 1, s + 1), idx(r, s + 1)]]
    t += [[len(v) - 1, idx(rings - 2, s + 1), idx(rings - 2, s)] for s in range(seg)]
    return v, np.array(t)

def helix_poses(n):
    def pose(i):
        a = 0.05 * i
        c, s = np.cos(a), np.sin(a)
        return np.array([[c, -s, 0, 0.3 * i], [s, c, 0, np.sin(i)], [0, 0, 1, 0.1 * i], [0, 0, 0, 1.0]])
    return np.stack([pose(i) for i in range(n)])
"""

# A UV sphere of 40 segments x 20 rings: 1,520 triangles; 100 poses along a tumbling helix.
SPHERE_AND_MOTION = UV_SPHERE_AND_HELIX + """
v, t = uv_sphere(40, 20)
assert len(t) == 1520
poses = helix_poses(100)
"""


# (name, code run under the cap, expected exception type or None for a finite result,
#  regex the message must match)
REPRODUCERS = [
    (
        "fit, fragment_duration=1e-15 (asked for 32 PB)",
        "report(lambda: ps.fit_angular_velocity([[1.,0,0,0]]*2, [0.,1], [0.,1], np.zeros((2,3)), fragment_duration=1e-15))",
        "ValueError",
        r"fit_angular_velocity: fragment_duration: 1e-15 is not at least 1e-6 \(at most 1000000 fragments of the key range, 1 long\)",
    ),
    (
        "subdivide 100,000 keys x 12 levels (22.9 GB)",
        "report(lambda: ps.subdivide(np.tile(np.eye(4), (100000, 1, 1)), levels=12))",
        "ValueError",
        r"subdivide: the subdivided poses would need 86.8 GB, over the memory budget of 1.07 GB: use fewer levels or fewer keys",
    ),
    (
        "fit, fragment_duration=1e-300 (capacity overflow panic)",
        "report(lambda: ps.fit_angular_velocity([[1.,0,0,0]]*2, [0.,1], [0.,1], np.zeros((2,3)), fragment_duration=1e-300))",
        "ValueError",
        r"fragment_duration: 1e-300 is not at least 1e-6 \(at most 1000000 fragments",
    ),
    (
        "rotation_channels of 1e8 broadcast rotations",
        "report(lambda: ps.rotation_channels(np.broadcast_to(np.eye(3), (10**8, 3, 3)), 'XYZ'))",
        "ValueError",
        r"rotation_channels: the rotation channels would need 5.60 GB, over the memory budget .*convert fewer rotations",
    ),
    (
        "sample at 1e8 times",
        f"report(lambda: ps.sample({EYE2}, [0., 1], np.zeros(10**8)))",
        "ValueError",
        r"sample: the sampled poses would need 19.2 GB, over the memory budget .*sample fewer times",
    ),
    (
        "interpolate at 1e8 t",
        "report(lambda: ps.interpolate(np.eye(4), np.eye(4), np.broadcast_to(0.5, (10**8,))))",
        "ValueError",
        r"interpolate: the interpolated poses would need 19.2 GB, over the memory budget .*fewer t",
    ),
    (
        "sample_channels at 1e8 times",
        f"report(lambda: ps.sample_channels({EYE2}, [0., 1], np.broadcast_to(0.0, (10**8,)), 'XYZ'))",
        "ValueError",
        r"sample_channels: the sampled channels would need .* GB, over the memory budget",
    ),
    (
        "sample_vectors at 1e8 times",
        "report(lambda: ps.sample_vectors(np.eye(3)[:2], [0., 1], np.broadcast_to(0.0, (10**8,))))",
        "ValueError",
        r"sample_vectors: the sampled vectors would need .* GB, over the memory budget",
    ),
    (
        "sample_feature at 1e8 times",
        f"report(lambda: ps.sample_feature({EYE2}, [0., 1], np.broadcast_to(0.0, (10**8,)), levels=2))",
        "ValueError",
        r"sample_feature: the sampled feature-point motion would need .* GB, over the memory budget",
    ),
    (
        "sweep of a 1,520-triangle sphere over 100 poses, steps=4096",
        SPHERE_AND_MOTION + "report(lambda: ps.sweep(v, t, poses, steps=4096))",
        "ValueError",
        r"sweep: the swept mesh would need .* GB, over the memory budget .*fewer steps, fewer poses or a coarser mesh",
    ),
    (
        "sample of a closed motion at +-1e308 (index out of bounds panic)",
        f"report(lambda: ps.sample({EYE2}, [-1e308, -9e307], [1e308], closed=True))",
        "ValueError",
        r"sample: key time 0 \(-1e308\) is outside the working range \+-1e300",
    ),
    (
        "fit with times +-1e308 (index out of bounds panic)",
        "report(lambda: ps.fit_angular_velocity([[1.,0,0,0]]*2, [-1e308, 1e308], [-1e308, 1e308], np.zeros((2, 3))))",
        "ValueError",
        r"fit_angular_velocity: (target|key) time 0 \(-1e308\) is outside the working range \+-1e30",
    ),
    (
        "subdivide_vectors of +-1e308 (NaN)",
        "report(lambda: ps.subdivide_vectors([[1e308,0,0], [-1e308,0,0], [0,0,0]]))",
        "ValueError",
        r"subdivide_vectors: values: vector 0 \(1e308\) is outside the working range \+-1e150",
    ),
    (
        "subdivide with translations near 1e308 (NaN)",
        "k = np.tile(np.eye(4), (3, 1, 1)); k[:, 0, 3] = [1e308, -1e308, 5e307]\n"
        "report(lambda: ps.subdivide(k))",
        "ValueError",
        r"subdivide: poses: pose 0: translation 1e308 is outside the working range \+-1e150",
    ),
    (
        "sample with translations near 1e308 (NaN)",
        "k = np.tile(np.eye(4), (3, 1, 1)); k[:, 1, 3] = [0, 1.7e308, -1.7e308]\n"
        "report(lambda: ps.sample(k, [0., 1, 2], [0.5, 1.5]))",
        "ValueError",
        r"sample: poses: pose 1: translation 1.7e308 is outside the working range",
    ),
    (
        "fit with a target of 1e160 rad/s ('converged' with NaN energy)",
        "report(lambda: ps.fit_angular_velocity([[1.,0,0,0]]*2, [0.,1], [0.,1], np.full((2, 3), 1e160)))",
        "ValueError",
        r"fit_angular_velocity: target angular velocity 0 \(1e160\) is outside the working range \+-1e30",
    ),
    (
        "screw of a 1e155 translation (axis z, slide 0)",
        "report(lambda: ps.screw(np.eye(4), np.eye(4) + np.eye(4, k=3)*1e155))",
        "ValueError",
        r"screw: b: translation 1e155 is outside the working range \+-1e150",
    ),
    (
        "levels=2**63 (OverflowError)",
        f"report(lambda: ps.subdivide({EYE2}, levels=2**63))",
        "ValueError",
        r"subdivide: levels 9223372036854775808 out of range 0\.\.=12",
    ),
    (
        "steps=2**63 (OverflowError)",
        "report(lambda: ps.sweep(np.eye(3), [[0, 1, 2]], np.tile(np.eye(4), (2, 1, 1)), steps=2**63))",
        "ValueError",
        r"sweep: steps 9223372036854775808 out of range 1\.\.=4096",
    ),
    (
        "max_iterations=-1 (OverflowError)",
        "report(lambda: ps.fit_angular_velocity([[1.,0,0,0]]*2, [0.,1], [0.,1], np.zeros((2,3)), max_iterations=-1))",
        "ValueError",
        r"fit_angular_velocity: max_iterations -1 out of range 1\.\.=1000000",
    ),
    (
        "float triangle indices (2.7 truncated)",
        "report(lambda: ps.sweep(np.eye(3), [[0, 1, 2.7]], np.tile(np.eye(4), (2, 1, 1))))",
        "ValueError",
        r"sweep: triangles: entry \[0, 2\] is 2.7, not an integer",
    ),
    (
        "complex input (imaginary part discarded)",
        "report(lambda: ps.interpolate(np.eye(4) + 0j, np.eye(4), 0.5))",
        "TypeError",
        r"interpolate: a: expected real numbers, got complex128",
    ),
]


@pytest.mark.parametrize("name, code, error, message", REPRODUCERS, ids=[r[0] for r in REPRODUCERS])
def test_reproducer_is_refused_with_a_clear_message(name, code, error, message):
    (outcome,) = run_capped(code)
    assert outcome.get("error") == error, (name, outcome)
    assert re.search(message, outcome["message"]), (name, outcome["message"])


def test_memory_budget_is_settable_and_restored():
    assert polyscrew.memory_budget() == polyscrew.DEFAULT_MEMORY_BUDGET == 1 << 30
    keys = np.tile(np.eye(4), (3, 1, 1))
    old = polyscrew.set_memory_budget(10_000)
    try:
        assert old == polyscrew.DEFAULT_MEMORY_BUDGET
        assert polyscrew.memory_budget() == 10_000
        # 3 keys read (168 bytes), two buffers of 65 and 33 poses (5,488), the (65, 4, 4)
        # array (8,320).
        with pytest.raises(ValueError, match=r"subdivide: the subdivided poses would need 14.0 kB, over the memory budget of 10.0 kB: use fewer levels or fewer keys"):
            polyscrew.subdivide(keys, levels=5)
        assert polyscrew.subdivide(keys, levels=4).shape == (33, 4, 4)
    finally:
        polyscrew.set_memory_budget(old)
    assert polyscrew.subdivide(keys, levels=5).shape == (65, 4, 4)


CURVE = "\n" + inspect.getsource(curve)  # the same helper in the capped children


def test_fcurve_evaluation_counts_its_bezier_segments_against_the_budget():
    """The check once counted the keys (40 bytes each) and the values only: a budget of
    exactly that let the call allocate the prepared curves, Bezier segments, float32 times
    and copies beyond it."""
    k, t = 1000, 1000
    times = np.linspace(0.0, k - 1, t)
    keys_and_values = 40 * k + 8 * t
    old = polyscrew.set_memory_budget(keys_and_values)
    try:
        with pytest.raises(ValueError, match=r"evaluate_fcurves: the F-curve evaluation would need .*, over the memory budget of 48.0 kB"):
            polyscrew.evaluate_fcurves(times, **curve(k))
        with pytest.raises(ValueError, match=r"Playback: the F-curve evaluation would need .*, over the memory budget"):
            polyscrew.Playback(channels=[("location", 0)], unkeyed=np.zeros(9), mode="XYZ", **curve(k))
    finally:
        polyscrew.set_memory_budget(old)
    values = polyscrew.evaluate_fcurves(times, **curve(k))
    assert values.shape == (1, t) and np.isfinite(values).all()


HUGE = 2**40


EYE = "np.eye(4)"


# (name, code run under the cap, expected exception, regex its message must match)
CAPPED = [
    ("co of 2**31 broadcast keys", "report(lambda: ps.evaluate_fcurves([0.], **{**curve(), 'co': np.broadcast_to(0.0, (2**31, 2))}))",
     "ValueError", r"evaluate_fcurves: keys: 2147483648 keys exceed the limit of 67108864"),
    ("interpolation of 2**40 broadcast codes", f"report(lambda: ps.evaluate_fcurves([0.], **{{**curve(), 'interpolation': np.broadcast_to(np.int64(2), ({HUGE},))}}))",
     "ValueError", r"evaluate_fcurves: the F-curve evaluation would need .* over the memory budget"),
    ("interpolation of 2**40 broadcast whole floats", f"report(lambda: ps.evaluate_fcurves([0.], **{{**curve(), 'interpolation': np.broadcast_to(2.0, ({HUGE},))}}))",
     "ValueError", r"evaluate_fcurves: interpolation: the integer conversion would need .* over the memory budget"),
    ("offsets of 2**40 broadcast entries", f"report(lambda: ps.evaluate_fcurves([0.], **{{**curve(), 'offsets': np.broadcast_to(np.int64(0), ({HUGE},))}}))",
     "ValueError", r"evaluate_fcurves: times: 1099511627775 values \(curves x times\) exceed the limit of 134217728"),
    ("Playback offsets of 2**40 broadcast entries", f"report(lambda: ps.Playback(channels=[('location', 0)], unkeyed=np.zeros(9), mode='XYZ', **{{**curve(), 'offsets': np.broadcast_to(np.int64(0), ({HUGE},))}}))",
     "ValueError", r"Playback: the F-curve evaluation would need .* over the memory budget"),
    ("back of 2**40 broadcast values", f"report(lambda: ps.evaluate_fcurves([0.], **{{**curve(), 'back': np.broadcast_to(1.0, ({HUGE},))}}))",
     "ValueError", r"evaluate_fcurves: the F-curve evaluation would need .* over the memory budget"),
    ("Playback handle_left of 2**40 broadcast pairs", f"report(lambda: ps.Playback(channels=[('location', 0)], unkeyed=np.zeros(9), mode='XYZ', **{{**curve(), 'handle_left': np.broadcast_to(0.0, ({HUGE}, 2))}}))",
     "ValueError", r"Playback: the F-curve evaluation would need .* over the memory budget"),
    ("extrapolation=range(2**62)", "report(lambda: ps.evaluate_fcurves([0.], **curve(), extrapolation=range(2**62)))",
     "ValueError", r"evaluate_fcurves: extrapolation: expected 1 entries, got 4611686018427387904"),
    ("cycles=range(2**62)", "report(lambda: ps.evaluate_fcurves([0.], **curve(), cycles=range(2**62)))",
     "ValueError", r"evaluate_fcurves: cycles: expected 1 entries, got 4611686018427387904"),
    ("channels=range(2**62)", "report(lambda: ps.Playback(channels=range(2**62), unkeyed=np.zeros(9), mode='XYZ', **curve()))",
     "ValueError", r"Playback: channels: expected at most 9 entries, got 4611686018427387904"),
    ("held=range(2**62)", "report(lambda: ps.denoise(np.tile(np.eye(4), (8, 1, 1)), np.arange(8.), held=range(2**62)))",
     "ValueError", r"denoise: held: expected at most 8 entries, got 4611686018427387904"),
    ("held=[range(2**62)] * 8", "report(lambda: ps.denoise(np.tile(np.eye(4), (8, 1, 1)), np.arange(8.), held=[range(2**62)] * 8))",
     "(ValueError|MemoryError)", r"denoise: held"),
    ("held of 2**40 broadcast booleans", f"report(lambda: ps.denoise(np.tile(np.eye(4), (8, 1, 1)), np.arange(8.), held=np.broadcast_to(True, ({HUGE},))))",
     "ValueError", rf"denoise: held: expected at most 8 entries, got {HUGE}"),
    ("constrained=range(2**62)", "report(lambda: ps.fit_angular_velocity([[1.,0,0,0]]*2, [0.,1], [0.,1], np.zeros((2,3)), constrained=range(2**62)))",
     "ValueError", r"fit_angular_velocity: constrained: expected at most 64 entries, got 4611686018427387904"),
    ("stiffness 1.0 of 2**40 broadcast keys", f"report(lambda: ps.feature_motion(np.broadcast_to({EYE}, ({HUGE}, 4, 4)), stiffness=1.0))",
     "ValueError", r"feature_motion: the feature-point motion would need .* over the memory budget"),
    ("stiffness array(1.0) of 2**40 broadcast keys", f"report(lambda: ps.feature_motion(np.broadcast_to({EYE}, ({HUGE}, 4, 4)), levels=0, stiffness=np.array(1.0)))",
     "ValueError", r"feature_motion: the feature-point motion would need .* over the memory budget"),
    ("sample_feature stiffness 1.0 of 2**40 broadcast keys", f"report(lambda: ps.sample_feature(np.broadcast_to({EYE}, ({HUGE}, 4, 4)), [0., 1], [0.5], stiffness=1.0))",
     "ValueError", r"sample_feature: the sampled feature-point motion would need .* over the memory budget"),
]


@pytest.mark.parametrize("name, code, error, message", CAPPED, ids=[c[0] for c in CAPPED])
def test_huge_arguments_are_refused_before_anything_is_reserved(name, code, error, message):
    (outcome,) = run_capped(CURVE + code)
    assert re.fullmatch(error, outcome.get("error", "")), (name, outcome)
    assert re.search(message, outcome["message"]), (name, outcome["message"])


MB = 1 << 20


# Helpers run in the capped child: the peak growth of one call, and the estimate of a call
# (what it says it would need, refused with a budget of 0).
PEAK = NEED + r"""
import time
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
     f"keys_parameters: timing Keys would need 26.0 GB, over the memory budget of 1.07 GB: pass fewer frames or keys in one call {BUDGET}"),
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


# --- 6. caps where memory does not bound the work -----------------------------------------
# A refusal is shown to come before the work by the memory it did not take; the time the
# largest accepted call takes is measured in scripts/bench/memory_footprints.py.

# the playback whose every span takes MAX_SPAN_SAMPLES samples, shared with the benchmark
SPINS = f"""
sys.path.insert(0, {str(Path(__file__).resolve().parents[2] / "scripts" / "bench")!r})
from bench_shapes import spinning_playback as spins
"""


def test_analyse_spans_refuses_more_samples_than_its_cap_before_taking_any():
    """16,000 spans each turning 10,000 radians took 28 to 39 s; now refused up front, from
    the spans' sample counts alone (the message gives them), before any result is built (the
    refusals' peak grows by under 16 MB, the accepted call's by its inserted frames). The most
    the cap accepts (512 such spans, each a spin) is computed, finite."""
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
    hint = "analyse fewer key frames at once (a span takes one sample per few degrees its rotation channels turn)"
    assert many == {"error": "ValueError", "message": f"analyse_spans: frames: the 16000 key spans would take 65536000 samples of the playback, over the limit of 2097152 in one call: {hint}"}
    assert over == {"error": "ValueError", "message": f"analyse_spans: frames: the 513 key spans would take 2101248 samples of the playback, over the limit of 2097152 in one call: {hint}"}
    # the accepted call's ~5 million inserted frames take 40 MB; the refusals build nothing
    assert at_cap_peak["growth"] > 16 * MB
    assert many_peak["growth"] < 16 * MB and over_peak["growth"] < 16 * MB
    assert at_cap == {"finite": True}
    assert result["turn"] > 1000  # every span a spin (its samples alias: under 4096 pi)


def test_rotation_channels_has_a_cap_on_rotations():
    """At the largest size the default budget accepts (2**24 rotations, quaternion) the call
    is computed, finite; one more is refused before any is converted (its peak does not grow
    by the output's gigabyte), whatever the budget."""
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
    assert over == {"error": "ValueError", "message": "rotation_channels: rotations: 16777217 rotations exceed the limit of 16777216 in one call: convert fewer rotations at once"}
    assert at_cap_peak["growth"] > 2**30 - 16 * MB  # the output: 2**24 quaternions of 8 float64
    assert over_peak["growth"] < 16 * MB


# --- 4. estimates hold -------------------------------------------------------------------

ESTIMATE_SETUP = KEYS + r"""

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
        UV_SPHERE_AND_HELIX + """
v, t = uv_sphere(128, 81)
poses = helix_poses(65)
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
