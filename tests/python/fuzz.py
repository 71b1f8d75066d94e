"""Fuzz suite of the polyscrew module (issue 15), run by `scripts/test.sh`.

Every public function and method is called with inputs Hypothesis draws: shapes right and
wrong, values from ordinary to the float limits (NaN, infinities, 1e308, 5e-324, 1e155,
1e-170), integers beyond 64 bits, wrong types (strings, complex numbers, None, lists).
Each call must return finite output or raise `ValueError`, `TypeError` or `MemoryError`:
any other exception fails the suite, `PanicException` (a `BaseException`) included, and so
does a signal or an abort (the child's exit status) or a hang (a timeout).

The cases run in child processes under a 4 GB address-space cap (`RLIMIT_AS`), many per
child: one child per group of functions, each with its own seed derived from `--seed`.

    .venv/bin/python tests/python/fuzz.py [--seed 20261201] [--examples 120]

prints the seed, the number of cases per function and the time.
"""

from __future__ import annotations

import argparse
import json
import math
import resource
import subprocess
import sys
import time

CAP = 4 << 30
DEFAULT_SEED = 20261201
DEFAULT_EXAMPLES = 300
TIMEOUT = 300

GROUPS = [
    ["screw", "interpolate", "subdivide", "subdivide_vectors", "rotation_channels", "memory_budget"],
    ["sample", "sample_vectors", "sample_channels", "evaluate_fcurves"],
    ["fit_angular_velocity", "AngularVelocityFit", "register_points", "inertia_points", "denoise"],
    ["feature_motion", "sample_feature", "sweep"],
    ["rotation_matrices", "Playback", "analyse_spans", "keys_parameters", "pace_parameters"],
]


def worker(group: int, seed: int, examples: int) -> None:
    resource.setrlimit(resource.RLIMIT_AS, (CAP, CAP))
    import numpy as np
    from hypothesis import HealthCheck, Phase, given, settings
    from hypothesis import seed as hypothesis_seed
    from hypothesis import strategies as st

    import polyscrew as ps

    counts: dict[str, int] = {}

    def finite(value) -> bool:
        if isinstance(value, (tuple, list)):
            return all(finite(v) for v in value)
        if isinstance(value, np.ndarray):
            return bool(np.isfinite(value).all()) if value.dtype.kind in "fc" else True
        if isinstance(value, float):
            return math.isfinite(value)
        if isinstance(value, ps.Screw):
            return finite((value.axis, value.point, value.angle, value.slide))
        if isinstance(value, ps.AngularVelocityFit):
            return finite(
                (value.quaternions, value.omega, value.key_quaternions, value.frame_times,
                 value.fit_error, value.fragment_errors, value.sample_times)
            )
        return True

    def check(name: str, call) -> None:
        """Runs one case: finite output, or one of the three allowed exceptions."""
        counts[name] = counts.get(name, 0) + 1
        try:
            out = call()
            counts["(computed)"] = counts.get("(computed)", 0) + 1
        except (ValueError, TypeError, MemoryError) as e:
            result = getattr(e, "result", None)
            if result is not None:
                assert isinstance(result, ps.AngularVelocityFit), (name, e)
            return
        except BaseException as e:  # noqa: BLE001 - a PanicException is a BaseException
            raise AssertionError(f"{name}: {type(e).__module__}.{type(e).__name__}: {e}") from None
        assert finite(out), f"{name}: non-finite output for finite-looking input: {out!r}"[:2000]

    # --- strategies ------------------------------------------------------------------------
    extreme = st.sampled_from(
        [0.0, -0.0, 1.0, -1.0, 1e-300, 5e-324, 1e-170, 1e150, -1e150, 1e155, 1e300, -1e308,
         1e308, float("nan"), float("inf"), -float("inf"), 3.4e38, 1e30, 1e160]
    )
    real = st.one_of(st.floats(-10, 10), st.floats(allow_nan=True, allow_infinity=True), extreme)
    big_int = st.sampled_from([2**63, -(2**63) - 1, 2**70, -1, 2**31, 0])
    junk = st.one_of(
        st.none(), st.text(max_size=3), st.complex_numbers(max_magnitude=10), st.just([1, [2]]),
        st.just(object()), st.just({"a": 1}),
    )

    @st.composite
    def rigid(draw, scale=None):
        q = np.array(draw(st.lists(st.floats(-1, 1), min_size=4, max_size=4)))
        n = np.linalg.norm(q)
        q = np.array([1.0, 0, 0, 0]) if n < 1e-3 else q / n
        w, x, y, z = q
        m = np.eye(4)
        m[:3, :3] = [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
        m[:3, 3] = [draw(real if scale is None else scale) for _ in range(3)]
        if draw(st.integers(0, 29)) == 0:  # a corrupted entry
            m[draw(st.integers(0, 3)), draw(st.integers(0, 3))] = draw(real)
        return m

    @st.composite
    def poses(draw, min_size=0, max_size=6):
        kind = draw(st.integers(0, 9))
        if kind == 0:
            return draw(junk)
        if kind == 1:
            shape = draw(st.lists(st.integers(0, 5), min_size=0, max_size=3))
            return np.full(shape, draw(real))
        n = draw(st.integers(min_size, max_size))
        scale = st.floats(-5, 5) if kind < 6 else real
        return np.array([draw(rigid(scale)) for _ in range(n)]).reshape(n, 4, 4)

    @st.composite
    def times(draw, n=None, increasing=True):
        kind = draw(st.integers(0, 11))
        if kind == 0:
            return draw(junk)
        size = n if n is not None and kind > 2 else draw(st.integers(0, 8))
        if increasing and kind > 4:
            start = draw(st.one_of(st.floats(-100, 100), extreme))
            step = draw(st.one_of(st.floats(1e-3, 10), extreme))
            return start + step * np.arange(size)
        return np.array(draw(st.lists(real, min_size=size, max_size=size)))

    def vectors(max_size=6, width=3):
        return st.one_of(
            st.lists(st.lists(real, min_size=width, max_size=width), min_size=0, max_size=max_size),
            st.lists(st.lists(st.floats(-5, 5), min_size=width, max_size=width), min_size=2, max_size=max_size),
            junk,
        )

    def mostly(good, *bad):
        '''`good` six times in seven, one of `bad` otherwise.'''
        return st.one_of(*([good] * 6), *bad)

    levels = mostly(st.integers(0, 12), st.integers(-2, 13), big_int, st.floats(0, 4), junk)
    small_levels = mostly(st.integers(0, 7), st.integers(-1, 13), big_int, junk)
    scheme = mostly(st.sampled_from(["jarek", "four_point", "bspline"]), st.just("catmull"), junk)
    timing = mostly(st.sampled_from(["smooth", "linear"]), st.just("cubic"), junk)
    closed = mostly(st.booleans(), junk)
    period = mostly(st.none(), real, junk)
    mode = mostly(st.sampled_from(["XYZ", "ZYX", "YZX", "QUATERNION", "AXIS_ANGLE"]), st.just("QUAT"), junk)

    opts = settings(
        max_examples=examples,
        deadline=None,
        database=None,
        suppress_health_check=list(HealthCheck),
        phases=[Phase.generate, Phase.shrink],
    )

    def fuzz(test):
        return hypothesis_seed(seed)(opts(test))

    # --- the functions ---------------------------------------------------------------------
    @fuzz
    @given(st.one_of(rigid(), poses()), st.one_of(rigid(), poses()))
    def screw(a, b):
        check("screw", lambda: ps.screw(a, b))

    @fuzz
    @given(rigid(), rigid(), st.one_of(real, st.lists(real, max_size=5), junk, big_int))
    def interpolate(a, b, t):
        check("interpolate", lambda: ps.interpolate(a, b, t))

    @fuzz
    @given(poses(), scheme, levels, closed)
    def subdivide(p, s, lv, c):
        check("subdivide", lambda: ps.subdivide(p, s, lv, c))

    @fuzz
    @given(vectors(), scheme, levels, closed)
    def subdivide_vectors(v, s, lv, c):
        check("subdivide_vectors", lambda: ps.subdivide_vectors(v, s, lv, c))

    @fuzz
    @given(st.one_of(poses(), st.lists(st.lists(st.lists(real, min_size=3, max_size=3), min_size=3, max_size=3), max_size=5)), mode, st.one_of(st.none(), st.lists(real, max_size=5), junk))
    def rotation_channels(r, m, prev):
        check("rotation_channels", lambda: ps.rotation_channels(r, m, prev))

    @fuzz
    @given(st.one_of(st.integers(-10, 10**12), big_int, junk), poses(min_size=2, max_size=4), st.integers(0, 12))
    def memory_budget(budget, p, lv):
        old = ps.memory_budget()
        try:
            check("set_memory_budget", lambda: ps.set_memory_budget(budget))
            check("memory_budget", ps.memory_budget)
            check("subdivide", lambda: ps.subdivide(p, levels=lv))
        finally:
            ps.set_memory_budget(old)

    @st.composite
    def sampled(draw, values):
        keys = draw(values)
        try:
            n = None if isinstance(keys, str) else len(keys)
        except TypeError:
            n = None
        return keys, draw(times(n)), draw(times(None, increasing=False))

    @fuzz
    @given(sampled(poses()), scheme, small_levels, closed, period, timing)
    def sample(kt, s, lv, c, pe, ti):
        k, key_times, t = kt
        check("sample", lambda: ps.sample(k, key_times, t, s, lv, c, pe, ti))

    @fuzz
    @given(sampled(vectors()), scheme, small_levels, closed, period, timing)
    def sample_vectors(kt, s, lv, c, pe, ti):
        k, key_times, t = kt
        check("sample_vectors", lambda: ps.sample_vectors(k, key_times, t, s, lv, c, pe, ti))

    @fuzz
    @given(sampled(poses()), mode, st.one_of(st.none(), st.lists(real, max_size=5)), scheme, small_levels, closed, period, timing)
    def sample_channels(kt, m, prev, s, lv, c, pe, ti):
        k, key_times, t = kt
        check("sample_channels", lambda: ps.sample_channels(k, key_times, t, m, prev, s, lv, c, pe, ti))

    quats = st.one_of(
        st.lists(st.lists(st.one_of(st.floats(-1, 1), real), min_size=4, max_size=4), min_size=0, max_size=5),
        junk,
    )

    @fuzz
    @given(
        quats, times(), times(), vectors(max_size=5),
        st.one_of(st.none(), st.lists(st.booleans(), max_size=5), st.lists(st.one_of(st.integers(-6, 6), big_int), max_size=3), junk),
        mostly(st.floats(0, 0.01), real, big_int, junk),
        mostly(st.floats(0.01, 1), real, junk),
        mostly(st.integers(1, 40), big_int, junk),
        mostly(st.integers(0, 5), big_int, junk),
        st.one_of(st.none(), times(increasing=False)),
        st.one_of(st.none(), st.lists(real, max_size=5)),
        st.one_of(st.none(), st.floats(1e-3, 1), real, junk),
    )
    def fit_angular_velocity(q, kt, tt, om, cons, alpha, delta, iters, frames, st_, speed, frag):
        check(
            "fit_angular_velocity",
            lambda: ps.fit_angular_velocity(
                q, kt, tt, om, cons, alpha, delta, iters, frames, st_,
                target_speed=speed, fragment_duration=frag,
            ),
        )

    fit = ps.fit_angular_velocity(
        [[1.0, 0, 0, 0], [np.cos(0.5), 0, 0, np.sin(0.5)], [0.0, 0, 0, 1.0]],
        [0.0, 1.0, 2.5], [0.0, 2.5], [[0, 0, 1.0], [0.3, 0, 1.0]],
    )

    @fuzz
    @given(st.one_of(times(increasing=False), st.floats(0, 2.5).map(lambda x: [x]), junk))
    def angular_velocity_fit(t):
        check("AngularVelocityFit.sample", lambda: fit.sample(t))
        check("AngularVelocityFit.angular_velocity", lambda: fit.angular_velocity(t))

    @fuzz
    @given(vectors(8), vectors(8), st.one_of(st.none(), st.lists(real, max_size=8), junk))
    def register_points(a, b, w):
        check("register_points", lambda: ps.register_points(a, b, w))

    @fuzz
    @given(vectors(8))
    def inertia_points(p):
        check("inertia_points", lambda: ps.inertia_points(p))

    feature_scheme = st.one_of(st.sampled_from(["variational", "four_point", "bspline", "jarek", "x"]), junk)
    parametrization = st.one_of(st.sampled_from(["uniform", "centripetal", "chordal"]), junk)
    stiffness = st.one_of(st.none(), real, st.lists(st.one_of(st.floats(0, 10), real), max_size=6), junk)

    @fuzz
    @given(poses(), feature_scheme, small_levels, closed, st.one_of(st.none(), vectors(8)), parametrization, stiffness, st.one_of(st.none(), real, junk))
    def feature_motion(p, s, lv, c, fp, par, sti, ins):
        check("feature_motion", lambda: ps.feature_motion(p, s, lv, c, fp, par, sti, ins))

    @fuzz
    @given(sampled(poses()), feature_scheme, small_levels, closed, st.one_of(st.none(), vectors(8)), parametrization, stiffness, period, timing)
    def sample_feature(kt, s, lv, c, fp, par, sti, pe, ti):
        k, key_times, t = kt
        check("sample_feature", lambda: ps.sample_feature(k, key_times, t, s, lv, c, fp, par, sti, None, pe, ti))

    triangles = st.one_of(
        st.lists(st.lists(st.integers(-1, 6), min_size=3, max_size=3), max_size=8),
        st.lists(st.lists(st.one_of(st.floats(-1, 6), big_int), min_size=3, max_size=3), max_size=4),
        st.just([[0, 1, 2], [0, 2, 3], [0, 3, 1], [1, 3, 2]]),
        junk,
    )

    @fuzz
    @given(vectors(6), triangles, poses(), mostly(st.integers(1, 64), st.integers(-1, 4097), big_int, junk), mostly(st.booleans(), junk))
    def sweep(v, t, p, steps, caps):
        check("sweep", lambda: ps.sweep(v, t, p, steps, caps))

    @st.composite
    def packed_curves(draw):
        counts = draw(st.lists(st.integers(0, 5), min_size=1, max_size=3))
        total = sum(counts)
        offsets = [0]
        for c in counts:
            offsets.append(offsets[-1] + c)
        if draw(st.booleans()):  # mostly well formed: increasing frames per curve
            frames = []
            for c in counts:
                start = draw(st.floats(-100, 100))
                steps = draw(st.lists(st.floats(0.01, 50), min_size=c, max_size=c))
                frames += list(start + np.cumsum(steps))
        else:
            frames = draw(st.lists(real, min_size=total, max_size=total))
        values = draw(st.lists(real, min_size=total, max_size=total))
        co = np.array([frames, values], dtype=np.float64).T.reshape(total, 2)
        shift = draw(st.lists(real, min_size=2, max_size=2))
        codes = st.integers(-1, len(ps.INTERPOLATIONS))
        mode = st.sampled_from(ps.CYCLE_MODES + ("NOPE",))
        cycles = st.one_of(
            st.none(),
            st.fixed_dictionaries({"mode_before": mode, "mode_after": mode,
                                   "cycles_before": st.integers(-2, 3), "cycles_after": st.integers(-2, 3)}),
            junk,
        )
        return dict(
            offsets=draw(mostly(
                st.just(np.array(offsets, dtype=np.int64)),
                st.lists(st.integers(-2, 9), max_size=4).map(lambda o: np.array(o, dtype=np.int64)),
            )),
            co=co,
            handle_left=co - np.array(shift) * 0.1 if total else co,
            handle_right=co + np.array(shift) * 0.1 if total else co,
            interpolation=np.array(draw(st.lists(codes, min_size=total, max_size=total)), dtype=np.int64),
            easing=np.array(draw(st.lists(st.integers(-1, len(ps.EASINGS)), min_size=total, max_size=total)), dtype=np.int64),
            extrapolation=draw(st.one_of(st.none(), st.lists(st.sampled_from(ps.EXTRAPOLATIONS + ("NOPE",)), min_size=len(counts), max_size=len(counts)), junk)),
            cycles=draw(st.one_of(st.none(), st.lists(cycles, min_size=len(counts), max_size=len(counts)), junk)),
        )

    @fuzz
    @given(packed_curves(), st.one_of(times(increasing=False), st.lists(real, max_size=6), junk))
    def evaluate_fcurves(curves, t):
        check("evaluate_fcurves", lambda: ps.evaluate_fcurves(t, **curves))

    def playback_of(curves, columns, unkeyed, m, located):
        return ps.Playback(channels=columns, unkeyed=unkeyed, mode=m, located=located, **curves)

    channel = st.tuples(
        st.sampled_from(["location", "scale", "rotation_euler", "rotation_quaternion", "rotation_axis_angle", "x"]),
        st.one_of(st.integers(-1, 4), big_int),
    )
    columns = st.one_of(st.lists(channel, min_size=0, max_size=3), junk)
    unkeyed = mostly(st.lists(st.floats(-5, 5), min_size=9, max_size=10), st.lists(real, min_size=9, max_size=10), junk)
    located_ = mostly(st.booleans(), junk)

    @fuzz
    @given(st.one_of(vectors(6, 3), vectors(6, 4), junk), mode)
    def rotation_matrices(v, m):
        check("rotation_matrices", lambda: ps.rotation_matrices(v, m))

    @fuzz
    @given(packed_curves(), st.one_of(st.none(), columns), unkeyed, mode, located_, st.one_of(times(increasing=False), junk))
    def playback(curves, cols, unk, m, loc, t):
        if cols is None:  # one location channel per curve, as many as there are offsets
            try:
                cols = [("location", i) for i in range(len(curves["offsets"]) - 1)]
            except TypeError:
                cols = []
        try:
            pb = playback_of(curves, cols, unk, m, loc)
        except (ValueError, TypeError, MemoryError):
            counts["Playback"] = counts.get("Playback", 0) + 1
            return
        check("Playback", lambda: pb)
        check("Playback.channels", lambda: pb.channels(t))

    # A playback that constructs: location x and a rotation angle, keyed where the frames are.
    @st.composite
    def good_playback(draw):
        m = draw(st.sampled_from(["XYZ", "ZYX", "QUATERNION", "AXIS_ANGLE"]))
        frames = np.cumsum(draw(st.lists(st.one_of(st.floats(0.01, 20), extreme.filter(lambda x: x > 0)), min_size=2, max_size=5)))
        values = draw(st.lists(st.one_of(st.floats(-50, 50), extreme), min_size=len(frames), max_size=len(frames)))
        co = np.c_[frames, values]
        curves = dict(offsets=np.array([0, len(frames), 2 * len(frames)]), co=np.r_[co, co],
                      handle_left=np.r_[co, co] - 0.3, handle_right=np.r_[co, co] + 0.3,
                      interpolation=np.array(draw(st.lists(st.integers(0, 12), min_size=2 * len(frames), max_size=2 * len(frames)))),
                      easing=np.zeros(2 * len(frames), dtype=np.int64))
        path = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}.get(m, "rotation_euler")
        width = 4 if m in ("QUATERNION", "AXIS_ANGLE") else 3
        unk = np.array(draw(st.lists(st.floats(-5, 5), min_size=6 + width, max_size=6 + width)))
        try:
            return playback_of(curves, [("location", 0), (path, 0)], unk, m, draw(st.booleans())), frames
        except (ValueError, TypeError, MemoryError):
            return None, frames

    @fuzz
    @given(good_playback(), st.one_of(times(), st.just(None)), st.one_of(times(increasing=False), junk))
    def analyse_spans(pf, t, anywhen):
        pb, frames = pf
        if pb is None:
            return
        check("analyse_spans", lambda: ps.analyse_spans(pb, frames if t is None else t))
        check("Playback.channels", lambda: pb.channels(anywhen))

    @fuzz
    @given(good_playback(), st.one_of(times(increasing=False), junk), mostly(st.floats(0.01, 5), real, junk), closed,
           period, poses(min_size=2, max_size=5), scheme, small_levels, st.booleans())
    def keys_parameters(pf, t, size, c, pe, p, s, lv, use_smooth):
        pb, frames = pf
        try:
            n = len(frames) if not c else len(frames) + 1
            smooth = ps.sample(p, np.arange(len(p), dtype=float), ps.pace_parameters(n - 1), timing="linear") if use_smooth else None
        except (ValueError, TypeError, MemoryError):
            smooth = None
        kwargs = dict(size=size, closed=c, period=pe, playback=pb, scheme=s, levels=lv)
        if smooth is not None:
            check("keys_parameters", lambda: ps.keys_parameters(frames, t, smooth=smooth, **kwargs))
        else:
            check("keys_parameters", lambda: ps.keys_parameters(frames, t, poses=p, **kwargs))

    @fuzz
    @given(st.one_of(st.integers(-3, 2000), big_int, junk))
    def pace_parameters(n):
        check("pace_parameters", lambda: ps.pace_parameters(n))
    @st.composite
    def clip(draw):
        """Poses and times of one clip: mostly a well-formed clip (rigid poses, increasing
        times of the same length, whose values the strategies still push to the extremes),
        sometimes anything."""
        n = draw(st.integers(0, 12).map(lambda k: 12 - k))  # mostly long enough
        if draw(st.integers(0, 3)) == 3:  # (Hypothesis favours 0: the well-formed case)
            return draw(poses(min_size=n, max_size=n)), draw(times(n=n))
        p = np.array([draw(rigid(st.floats(-5, 5))) for _ in range(n)]).reshape(n, 4, 4)
        start = draw(st.one_of(st.floats(-100, 100), extreme))
        step = draw(st.one_of(st.floats(1e-3, 10), extreme))
        return p, start + step * np.arange(n)

    @fuzz
    @given(
        clip(),
        st.one_of(st.sampled_from([None] * 5 + [0.0, 1.0, 4.0, (2.0, 8.0), -1.0, float("nan"), 1e300, "x"]), real),
        st.one_of(st.sampled_from([None] * 5 + ["x", 3]), st.lists(st.booleans(), min_size=0, max_size=12)),
        st.sampled_from([3] * 6 + [2] * 3 + [-1, 4, 2**63, "3", None]),
    )
    def denoise(pt, strength, held, order):
        p, t = pt
        if isinstance(held, list) and isinstance(p, np.ndarray) and p.ndim == 3 and len(held) != len(p):
            held = held[: len(p)] + [False] * max(0, len(p) - len(held))
        def run():
            result = ps.denoise(p, t, strength=strength, held=held, order=order)
            return [result.poses, result.rotation_strength, result.translation_strength]

        check("denoise", run)

    tests = {
        "rotation_matrices": [rotation_matrices], "Playback": [playback], "analyse_spans": [analyse_spans],
        "keys_parameters": [keys_parameters], "pace_parameters": [pace_parameters],
        "screw": [screw], "interpolate": [interpolate], "subdivide": [subdivide],
        "subdivide_vectors": [subdivide_vectors], "rotation_channels": [rotation_channels],
        "memory_budget": [memory_budget], "sample": [sample], "sample_vectors": [sample_vectors],
        "sample_channels": [sample_channels], "fit_angular_velocity": [fit_angular_velocity],
        "AngularVelocityFit": [angular_velocity_fit], "register_points": [register_points],
        "inertia_points": [inertia_points], "feature_motion": [feature_motion],
        "sample_feature": [sample_feature], "sweep": [sweep], "evaluate_fcurves": [evaluate_fcurves], "denoise": [denoise],
    }
    for name in GROUPS[group]:
        for test in tests[name]:
            test()
    print(json.dumps(counts), flush=True)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=DEFAULT_SEED)
    parser.add_argument("--examples", type=int, default=DEFAULT_EXAMPLES, help="examples per function")
    parser.add_argument("--worker", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.worker is not None:
        worker(args.worker, args.seed, args.examples)
        return 0
    start = time.perf_counter()
    total: dict[str, int] = {}
    failed = False
    for group in range(len(GROUPS)):
        child_seed = args.seed * 101 + group
        cmd = [sys.executable, __file__, "--worker", str(group), "--seed", str(child_seed), "--examples", str(args.examples)]
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=TIMEOUT)
        except subprocess.TimeoutExpired:
            print(f"fuzz: group {group} ({', '.join(GROUPS[group])}) hung: no answer in {TIMEOUT} s")
            failed = True
            continue
        if proc.returncode != 0:
            print(f"fuzz: group {group} ({', '.join(GROUPS[group])}), seed {child_seed}: exit status {proc.returncode}")
            print(proc.stdout[-4000:], proc.stderr[-6000:])
            failed = True
            continue
        for name, n in json.loads(proc.stdout.strip().splitlines()[-1]).items():
            total[name] = total.get(name, 0) + n
    elapsed = time.perf_counter() - start
    computed = total.pop("(computed)", 0)
    cases = sum(total.values())
    print(f"fuzz: seed {args.seed}, {args.examples} examples per test, {cases} cases in {elapsed:.0f} s, each group in a child under a 4 GB address-space cap")
    print("fuzz: " + ", ".join(f"{k} {v}" for k, v in sorted(total.items())))
    print(f"fuzz: {computed} cases computed a result, {cases - computed} were refused with an error")
    if failed:
        print("fuzz: FAILED")
        return 1
    print(f"{cases} passed, 0 failed")
    return 0


if __name__ == "__main__":
    sys.exit(main())
