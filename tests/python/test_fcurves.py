"""polyscrew.evaluate_fcurves against independent references: numpy's ``interp`` for LINEAR
keys, step functions for CONSTANT, scipy's ``brentq`` on the Bezier cubic (with the handle
clamping Blender documents) for BEZIER, Penner's formulas for the easings, periodicity for
the Cycles modifier; shapes, names and errors. Agreement with Blender itself is
``tests/blender/test_curves.py``.
"""

from __future__ import annotations

import threading
import time

import numpy as np
import polyscrew
import pytest
from scipy.optimize import brentq

F32 = np.finfo(np.float32).eps
CODE = {name: i for i, name in enumerate(polyscrew.INTERPOLATIONS)}
EASE = {name: i for i, name in enumerate(polyscrew.EASINGS)}


def pack(curves, extrapolation="CONSTANT", cycles=None):
    """Keyword arguments for evaluate_fcurves from a list of curves, each a list of key dicts
    (co, optional handle_left / handle_right / interpolation / easing / back / amplitude / period)."""
    keys = [k for c in curves for k in c]
    get = lambda name, default: [k.get(name, default(k)) for k in keys]  # noqa: E731
    return dict(
        offsets=np.cumsum([0] + [len(c) for c in curves]),
        co=np.array([k["co"] for k in keys], float).reshape(-1, 2),
        handle_left=np.array(get("handle_left", lambda k: (k["co"][0] - 1, k["co"][1])), float).reshape(-1, 2),
        handle_right=np.array(get("handle_right", lambda k: (k["co"][0] + 1, k["co"][1])), float).reshape(-1, 2),
        interpolation=np.array([CODE[k.get("interpolation", "BEZIER")] for k in keys], dtype=np.int64),
        easing=np.array([EASE[k.get("easing", "AUTO")] for k in keys], dtype=np.int64),
        back=np.array(get("back", lambda k: 1.70158), float),
        amplitude=np.array(get("amplitude", lambda k: 0.8), float),
        period=np.array(get("period", lambda k: 4.1), float),
        extrapolation=extrapolation,
        cycles=cycles,
    )


def f32(t):
    """Times as Blender sees them: rounded to float32."""
    return np.asarray(t, np.float32).astype(np.float64)


def test_names_are_blenders_rna_identifiers():
    assert polyscrew.INTERPOLATIONS == (
        "CONSTANT", "LINEAR", "BEZIER", "SINE", "QUAD", "CUBIC", "QUART", "QUINT", "EXPO",
        "CIRC", "BACK", "BOUNCE", "ELASTIC",
    )
    assert polyscrew.EASINGS == ("AUTO", "EASE_IN", "EASE_OUT", "EASE_IN_OUT")
    assert polyscrew.EXTRAPOLATIONS == ("CONSTANT", "LINEAR")
    assert polyscrew.CYCLE_MODES == ("NONE", "REPEAT", "REPEAT_OFFSET", "MIRROR")
    assert polyscrew.MAX_FCURVE_VALUES == 2**27 and polyscrew.MAX_FCURVE_KEYS == 2**26


def test_linear_keys_are_numpys_interp(rng):
    curves, refs = [], []
    for _ in range(20):
        n = rng.integers(2, 9)
        x = np.cumsum(rng.uniform(0.5, 10, n)).astype(np.float32).astype(float)
        y = rng.normal(0, 5, n).astype(np.float32).astype(float)
        curves.append([{"co": (a, b), "interpolation": "LINEAR"} for a, b in zip(x, y)])
        refs.append((x, y))
    times = rng.uniform(-10, 90, 2000)
    out = polyscrew.evaluate_fcurves(times, **pack(curves))
    assert out.shape == (20, 2000) and out.dtype == np.float64
    for row, (x, y) in zip(out, refs):
        ref = np.interp(f32(times), x, y)  # CONSTANT extrapolation = interp's ends
        tol = 8 * F32 * (np.abs(y).max() + np.ptp(y))
        assert np.abs(row - ref).max() <= tol


def test_linear_extrapolation_continues_the_end_segments():
    c = [[{"co": (0, 1), "interpolation": "LINEAR"}, {"co": (4, 3), "interpolation": "LINEAR"},
          {"co": (10, -2), "interpolation": "LINEAR"}]]
    out = polyscrew.evaluate_fcurves([-4.0, 16.0], **pack(c, extrapolation="LINEAR"))
    np.testing.assert_allclose(out[0], [-1.0, -7.0], rtol=1e-6)


def test_constant_keys_are_steps(rng):
    x = np.array([1.0, 10.0, 20.0, 20.5])
    y = np.array([4.0, 7.75, -1.0, 2.0])
    c = [[{"co": (a, b), "interpolation": "CONSTANT"} for a, b in zip(x, y)]]
    times = np.sort(rng.uniform(-5, 30, 3000))
    times = times[np.min(np.abs(times[:, None] - x), axis=1) > 2e-4]  # away from Blender's 1e-4 snap
    out = polyscrew.evaluate_fcurves(times, **pack(c, extrapolation="LINEAR"))[0]
    ref = y[np.clip(np.searchsorted(x, times, side="right") - 1, 0, None)]
    np.testing.assert_array_equal(out, ref)


def bezier_reference(k0, h0, h1, k1, t):
    """Value of the Bezier segment at frame t: handles longer (in time) than the segment
    scaled back to its length about their key, then x(u) = t by brentq, then y(u)."""
    k0, h0, h1, k1 = (np.asarray(p, float) for p in (k0, h0, h1, k1))
    span = k1[0] - k0[0]
    for key, h in ((k0, h0), (k1, h1)):
        d = key - h
        if abs(d[0]) > span:
            h[:] = key - span / abs(d[0]) * d
    p = np.array([k0, h0, h1, k1])

    def point(u):
        w = np.array([(1 - u) ** 3, 3 * (1 - u) ** 2 * u, 3 * (1 - u) * u**2, u**3])
        return w @ p

    u = brentq(lambda u: point(u)[0] - t, 0.0, 1.0, xtol=1e-15)
    return point(u)[1]


def test_bezier_segments_against_brentq(rng):
    worst = {False: 0.0, True: 0.0}
    for _ in range(60):
        k0 = np.array([0.0, rng.normal(0, 3)])
        k1 = np.array([rng.uniform(1, 20), rng.normal(0, 3)])
        # Handles anywhere in value, and in time from inside the span to 3 spans beyond it.
        h0 = k0 + [rng.uniform(0, 3) * k1[0], rng.normal(0, 5)]
        h1 = k1 - [rng.uniform(0, 3) * k1[0], rng.normal(0, 5)]
        h0, h1, k0, k1 = (p.astype(np.float32).astype(float) for p in (h0, h1, k0, k1))
        c = [[{"co": k0, "handle_right": h0}, {"co": k1, "handle_left": h1}]]
        times = f32(np.linspace(k0[0], k1[0], 203)[1:-1])
        out = polyscrew.evaluate_fcurves(times, **pack(c))[0]
        ref = np.array([bezier_reference(k0, h0.copy(), h1.copy(), k1, t) for t in times])
        scale = np.abs([k0[1], k1[1], h0[1], h1[1]]).max() + 1
        both_clamped = h0[0] - k0[0] > k1[0] and k1[0] - h1[0] > k1[0]
        worst[both_clamped] = max(worst[both_clamped], np.abs(out - ref).max() / scale)
    print(f"\nBezier vs brentq in float64, of the values' scale: {worst[False]:.1e}; with both "
          f"handles clamped to the span {worst[True]:.1e}")
    assert worst[False] < 1e-5
    # Both handles clamped to the full span L make x(u) = x0 + L (3u - 6u^2 + 4u^3), with
    # x'(u) = 3 L (1 - 2u)^2 = 0 at u = 1/2: a double root there, and Blender's float32
    # solve loses about half its digits (up to 1.4e-3 measured). That is Blender's value,
    # which is what is mirrored (tests/blender/test_curves.py).
    assert 0 < worst[True] < 3e-3


PENNER = {
    ("QUAD", "EASE_IN"): lambda t: t * t,
    ("QUAD", "EASE_IN_OUT"): lambda t: np.where(t < 0.5, 2 * t * t, 1 - 2 * (1 - t) ** 2),
    ("CUBIC", "EASE_OUT"): lambda t: 1 + (t - 1) ** 3,
    ("QUART", "AUTO"): lambda t: t**4,
    ("QUINT", "EASE_OUT"): lambda t: 1 + (t - 1) ** 5,
    ("SINE", "EASE_IN"): lambda t: 1 - np.cos(t * np.pi / 2),
    ("SINE", "EASE_OUT"): lambda t: np.sin(t * np.pi / 2),
    ("CIRC", "EASE_OUT"): lambda t: np.sqrt(1 - (t - 1) ** 2),
    ("EXPO", "EASE_OUT"): lambda t: 1 - (2 ** (-10 * t) - 2**-10) / (1 - 2**-10),
    ("BACK", "EASE_IN"): lambda t: t * t * (2.70158 * t - 1.70158),
    ("BOUNCE", "AUTO"): lambda t: np.select(
        [t < 1 / 2.75, t < 2 / 2.75, t < 2.5 / 2.75],
        [7.5625 * t * t, 7.5625 * (t - 1.5 / 2.75) ** 2 + 0.75, 7.5625 * (t - 2.25 / 2.75) ** 2 + 0.9375],
        7.5625 * (t - 2.625 / 2.75) ** 2 + 0.984375,
    ),
}


@pytest.mark.parametrize("ipo, easing", sorted(PENNER))
def test_easings_are_penners(ipo, easing):
    begin, change, duration = 2.0, -3.0, 8.0
    c = [[{"co": (0, begin), "interpolation": ipo, "easing": easing}, {"co": (duration, begin + change)}]]
    times = np.linspace(0.01, duration - 0.01, 500)
    out = polyscrew.evaluate_fcurves(times, **pack(c))[0]
    ref = begin + change * PENNER[ipo, easing](f32(times) / duration)
    assert np.abs(out - ref).max() < 2e-5


def cycled(before, after, counts=(0, 0)):
    keys = [{"co": (1, 0), "handle_left": (-1, -1), "handle_right": (3, 1)},
            {"co": (7, 4), "handle_left": (5, 5), "handle_right": (9, 3)},
            {"co": (11, 2), "handle_left": (10, 2.5), "handle_right": (12, 1.5)}]
    cyc = {"mode_before": before, "mode_after": after, "cycles_before": counts[0], "cycles_after": counts[1]}
    return keys, cyc


def test_cycles_repeat_offset_and_mirror():
    keys, _ = cycled("NONE", "NONE")
    phase = 1 + np.arange(1, 80) / 8  # inside the keys, exact in float32
    base = polyscrew.evaluate_fcurves(phase, **pack([keys]))[0]
    shifts = np.array([-3, -1, 1, 2, 5])
    times = (phase[None, :] + 10 * shifts[:, None]).ravel()
    curves = [cycled(m, m)[0] for m in ("REPEAT", "REPEAT_OFFSET", "MIRROR")]
    cycles = [cycled(m, m)[1] for m in ("REPEAT", "REPEAT_OFFSET", "MIRROR")]
    rep, off, _ = polyscrew.evaluate_fcurves(times, **pack(curves, cycles=cycles)).reshape(3, 5, -1)
    np.testing.assert_allclose(rep, np.tile(base, (5, 1)), atol=1e-5)
    np.testing.assert_allclose(off, base[None, :] + 2.0 * shifts[:, None], atol=1e-5)
    mirrored = polyscrew.evaluate_fcurves(21 - (phase - 1), **pack([curves[2]], cycles=[cycles[2]]))[0]
    np.testing.assert_allclose(mirrored, base, atol=1e-5)


def test_cycle_counts_and_a_dict_with_defaults():
    keys, cyc = cycled("REPEAT_OFFSET", "REPEAT_OFFSET", counts=(1, 2))
    plain = polyscrew.evaluate_fcurves([31.5, 40.0, -9.5, 9.0, 3.0], **pack([keys], extrapolation="LINEAR"))[0]
    out = polyscrew.evaluate_fcurves([31.5, 40.0, -9.5, 29.0, -7.0], **pack([keys], "LINEAR", [cyc]))[0]
    np.testing.assert_array_equal(out[:3], plain[:3])  # past the counts: the curve's own line
    np.testing.assert_allclose(out[3:], plain[3:] + [4.0, -2.0], atol=1e-5)
    # An empty dict is a new modifier: REPEAT both sides, unlimited.
    rep = polyscrew.evaluate_fcurves([24.0, 4.0], **pack([keys], cycles=[{}]))[0]
    assert rep[0] == pytest.approx(rep[1], abs=1e-5)


def test_shapes_and_per_curve_extrapolation():
    c = [[{"co": (0, 0), "interpolation": "LINEAR"}, {"co": (1, 1), "interpolation": "LINEAR"}]] * 3
    out = polyscrew.evaluate_fcurves([-1.0, 2.0], **pack(c, extrapolation=["CONSTANT", "LINEAR", "LINEAR"]))
    np.testing.assert_array_equal(out, [[0, 1], [-1, 2], [-1, 2]])
    assert polyscrew.evaluate_fcurves(np.empty(0), **pack(c)).shape == (3, 0)
    empty = pack([])
    assert polyscrew.evaluate_fcurves([1.0, 2.0], **empty).shape == (0, 2)
    # Any integer and float array-likes are accepted (int32 codes, lists, float32 keys).
    kw = pack(c)
    kw["interpolation"] = kw["interpolation"].astype(np.int32)
    kw["co"] = kw["co"].astype(np.float32).tolist()
    np.testing.assert_array_equal(polyscrew.evaluate_fcurves([0.5], **kw), [[0.5]] * 3)


@pytest.mark.parametrize(
    "change, match",
    [
        (lambda kw: kw.update(co=kw["co"][:, :1]), r"co: expected shape \(K, 2\)"),
        (lambda kw: kw.update(offsets=[0, 3, 2]), r"offsets: offset 2 is less than the one before \(by 1\)"),
        (lambda kw: kw.update(offsets=[0, 1]), "extrapolation|co: expected 2"),
        (lambda kw: kw["interpolation"].__setitem__(1, 13), r"curve 0: key 1: interpolation: code 13 is outside 0\.\.13"),
        (lambda kw: kw["easing"].__setitem__(0, -1), r"curve 0: key 0: easing: code -1 is outside 0\.\.4"),
        (lambda kw: kw["co"].__setitem__((1, 0), -5.0), r"curve 0: key frames: key 1 is less than the one before \(by 5\)"),
        (lambda kw: kw["handle_left"].__setitem__((1, 1), np.nan), "curve 0: keys: key 1: handle_left is not finite in float32"),
        (lambda kw: kw["back"].__setitem__(0, 1e39), "key 0: back is not finite in float32"),
        (lambda kw: kw.update(extrapolation="Linear"), "extrapolation.*not one of CONSTANT, LINEAR"),
        (lambda kw: kw.update(extrapolation=["LINEAR"] * 2), "extrapolation: expected 1 entries, got 2"),
        (lambda kw: kw.update(cycles=[{"mode_after": "REPEAT_OFSET"}]), r"cycles\[0\]: mode_after"),
        (lambda kw: kw.update(cycles=[{"mode": "REPEAT"}]), r"cycles\[0\]: unknown setting 'mode'|\"mode\""),
        (lambda kw: kw.update(cycles=[{}, {}]), "cycles: expected 1 entries"),
        (lambda kw: kw.update(cycles=[{"use_influence": True, "influence": np.inf}]), "influence is not finite"),
        (lambda kw: kw.update(back=np.ones(5)), "back: expected 2 entries, got 5"),
    ],
)
def test_bad_input_raises_valueerror_naming_it(change, match):
    kw = pack([[{"co": (0, 1)}, {"co": (5, 2)}]])
    change(kw)
    with pytest.raises(ValueError, match=match):
        polyscrew.evaluate_fcurves([1.0, 2.0], **kw)


def test_bad_times_and_oversized_requests():
    kw = pack([[{"co": (0, 1)}, {"co": (5, 2)}]])
    with pytest.raises(ValueError, match="time 1 is NaN or infinite"):
        polyscrew.evaluate_fcurves([0.0, np.nan], **kw)
    with pytest.raises(ValueError, match="time 0 is NaN or infinite"):
        polyscrew.evaluate_fcurves([1e300], **kw)  # infinite in float32
    many = pack([[{"co": (0, 1)}]] * 2049)
    with pytest.raises(ValueError, match="exceed the limit"):
        polyscrew.evaluate_fcurves(np.zeros(2**16), **many)


def test_a_value_blender_would_make_infinite_raises():
    kw = pack([[{"co": (0, 0), "handle_left": (-1e-30, 1e30)}, {"co": (5, 1)}]], extrapolation="LINEAR")
    with pytest.raises(ValueError, match="curve 0 evaluates to"):
        polyscrew.evaluate_fcurves([-2.0], **kw)


def test_gil_is_released():
    """A second thread runs Python while one long evaluation is under way."""
    c = [[{"co": (i, np.sin(i))} for i in range(50)]] * 200
    kw = pack(c)
    times = np.linspace(-10, 60, 5000)
    ticks = []
    done = threading.Event()

    def count():
        while not done.is_set():
            ticks.append(time.perf_counter())
            time.sleep(0.001)

    start = time.perf_counter()
    polyscrew.evaluate_fcurves(times, **kw)
    alone = time.perf_counter() - start
    thread = threading.Thread(target=count)
    thread.start()
    start = time.perf_counter()
    polyscrew.evaluate_fcurves(times, **kw)
    end = time.perf_counter()
    done.set()
    thread.join()
    during = [t for t in ticks if start < t < end]
    assert alone > 0.01, "the evaluation must be long enough to observe"
    assert len(during) >= 3, f"the other thread ran {len(during)} times in {end - start:.3f} s"
