"""Review fixes of the module's argument reading (issue 15's promise: bad or huge input is
a clear error, never an abort, a panic or a silent cast).

- `evaluate_fcurves` and `Playback` read their arrays with the module's readers (no silent
  casts of codes or complex numbers), and the F-curve evaluation counts everything it holds
  (the prepared curves and their Bezier segments, the times, the copies) against the budget
  before copying anything;
- sequences (`held`, `constrained`, `channels`, `extrapolation`, `cycles`) are refused when
  too long before anything is reserved for them (`range(2**62)`);
- a broadcast stiffness is expanded only after the budget's check;
- `denoise` of zero bodies checks its times and gives an empty result that prints.

The huge requests run in children under a 4 GB address-space cap (`capped.run_capped`).
"""

from __future__ import annotations

import inspect
import re

import numpy as np
import polyscrew
import pytest

from capped import run_capped


# One BEZIER curve of K keys, as `evaluate_fcurves` and `Playback` take it.
def curve(k=3):
    co = np.c_[np.arange(k, dtype=float), np.arange(k) % 7]
    return dict(offsets=[0, k], co=co, handle_left=co - [0.3, 0], handle_right=co + [0.3, 0],
                interpolation=np.full(k, 2), easing=np.zeros(k, dtype=np.int64))


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


@pytest.mark.parametrize(
    "change, error, message",
    [
        (dict(interpolation=[2.7, 2, 2]), ValueError, r"interpolation: entry \[0\] is 2.7, not an integer"),
        (dict(interpolation=[np.nan, 2, 2]), ValueError, r"interpolation: entry \[0\] is NaN, not an integer"),
        (dict(easing=[0, 0.5, 0]), ValueError, r"easing: entry \[1\] is 0.5, not an integer"),
        (dict(offsets=[0, 3.5]), ValueError, r"offsets: entry \[1\] is 3.5, not an integer"),
        (dict(offsets=["0", "3"]), TypeError, r"offsets: expected integers, got <U1"),
        (dict(co=np.c_[np.arange(3.0), np.zeros(3)] + 1j), TypeError, r"co: expected real numbers, got complex128"),
        (dict(handle_right=np.zeros((3, 2), complex)), TypeError, r"handle_right: expected real numbers, got complex128"),
        (dict(back=np.ones(3, complex)), TypeError, r"back: expected real numbers, got complex128"),
        (dict(period=["x", "y", "z"]), TypeError, r"period: expected real numbers"),
    ],
)
@pytest.mark.parametrize("function", ["evaluate_fcurves", "Playback"])
def test_curve_arrays_are_not_cast_silently(function, change, error, message):
    kw = {**curve(3), **change}
    if function == "evaluate_fcurves":
        call = lambda: polyscrew.evaluate_fcurves([0.5, 1.5], **kw)  # noqa: E731
    else:
        call = lambda: polyscrew.Playback(channels=[("location", 0)], unkeyed=np.zeros(9), mode="XYZ", **kw)  # noqa: E731
    with pytest.raises(error, match=f"{function}: {message}"):
        call()


def test_whole_float_codes_are_still_accepted():
    kw = {**curve(3), "interpolation": [2.0, 1.0, 0.0], "offsets": [0.0, 3.0]}
    want = polyscrew.evaluate_fcurves([0.5, 1.5], **{**curve(3), "interpolation": [2, 1, 0]})
    np.testing.assert_array_equal(polyscrew.evaluate_fcurves([0.5, 1.5], **kw), want)


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
     "ValueError", r"evaluate_fcurves: times: 1099511627775 curves x 1 times exceed the limit of 134217728 values"),
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


def test_masks_and_indices_still_read_as_before():
    """Lists of bools, numpy masks, index lists and arrays, negative indices."""
    keys = [[1.0, 0, 0, 0], [0.0, 0, 0, 1.0], [1.0, 0, 0, 0]]
    args = (keys, [0.0, 1.0, 2.0], [0.0, 2.0], np.zeros((2, 3)))
    by_mask = polyscrew.fit_angular_velocity(*args, constrained=[True, False, True])
    for constrained in (np.array([True, False, True]), [0, 2], np.array([0, -1]), (2, 0)):
        fit = polyscrew.fit_angular_velocity(*args, constrained=constrained)
        np.testing.assert_array_equal(fit.quaternions, by_mask.quaternions)
    with pytest.raises(ValueError, match="constrained: index 3 out of range for 3 keys"):
        polyscrew.fit_angular_velocity(*args, constrained=[3])
    with pytest.raises(TypeError, match="constrained: expected integers"):
        polyscrew.fit_angular_velocity(*args, constrained=["a"])
    poses = np.tile(np.eye(4), (2, 6, 1, 1))
    poses[:, :, 0, 3] = np.arange(6.0) ** 2
    times = np.arange(6.0)
    held = [True, False, False, False, False, True]
    one = polyscrew.denoise(poses, times, held=held).poses
    two = polyscrew.denoise(poses, times, held=np.array([held, held])).poses
    np.testing.assert_array_equal(one, two)
    with pytest.raises(ValueError, match=r"held: expected a boolean mask of shape \(6,\) or \(2, 6\)"):
        polyscrew.denoise(poses, times, held=[1, 0, 0, 0, 0, 1])
    with pytest.raises(ValueError, match=r"held: expected a boolean mask"):
        polyscrew.denoise(poses, times, held=np.ones((3, 6), bool))


def test_denoise_of_zero_bodies_checks_its_times_and_prints():
    poses = np.zeros((0, 10, 4, 4))
    empty = polyscrew.denoise(poses, np.arange(10.0))
    assert repr(empty) == "Denoised(0 bodies x 10 poses)"
    assert empty.poses.shape == (0, 10, 4, 4)
    assert empty.rotation_strength.shape == (0,) and empty.pivot.shape == (0, 3)
    assert empty.rotation_kinks == [] and empty.converged
    times = np.arange(10.0)
    times[4] = np.nan
    with pytest.raises(ValueError, match=r"denoise: key time 4"):
        polyscrew.denoise(poses, times)
    with pytest.raises(ValueError, match=r"denoise: strength: -1 is not a finite time"):
        polyscrew.denoise(poses, np.arange(10.0), strength=-1.0)
