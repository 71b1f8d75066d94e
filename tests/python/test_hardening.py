"""Issue 15: the module never takes Blender down.

Every reproducer of the issue runs in its own process under a 4 GB address-space cap
(`capped.run_capped`) and must exit normally, with a clear error whose message is checked,
or with a correct finite result where the input is legitimately computable. Then: the
screw of a pure translation, the errors of every argument type, and the GIL released
during long calls. The per-function tests at the documented limits are in
`test_limits.py`, the fuzz suite in `fuzz.py`.
"""

from __future__ import annotations

import re
import threading
import time

import numpy as np
import polyscrew
import pytest

from capped import run_capped

EYE2 = "np.tile(np.eye(4), (2, 1, 1))"

# A UV sphere of 40 segments x 20 rings: 1,520 triangles; 100 poses along a tumbling helix.
SPHERE_AND_MOTION = """
seg, rings = 40, 20
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
t = np.array(t)
assert len(t) == 1520
def pose(i):
    a = 0.05 * i
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0, 0.3 * i], [s, c, 0, np.sin(i)], [0, 0, 1, 0.1 * i], [0, 0, 0, 1.0]])
poses = np.stack([pose(i) for i in range(100)])
"""

# (name, code run under the cap, expected exception type or None for a finite result,
#  regex the message must match)
REPRODUCERS = [
    (
        "fit, fragment_duration=1e-15 (asked for 32 PB)",
        "report(lambda: ps.fit_angular_velocity([[1.,0,0,0]]*2, [0.,1], [0.,1], np.zeros((2,3)), fragment_duration=1e-15))",
        "ValueError",
        r"fit_angular_velocity: fragment_duration: 1e-15 cuts the key range .* into 1e15 fragments, more than 1000000: use at least 1e-6",
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
        r"fragment_duration: 1e-300 cuts .* more than 1000000",
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


def test_sample_of_one_time_with_100000_keys_at_12_levels():
    """The issue's 22.9 GB of working memory for one output pose: the motion is subdivided in
    windows of key spans, so the call computes, in bounded memory, the same pose as a
    motion of only the keys around that time."""
    (outcome, check) = run_capped(
        """
rng = np.random.default_rng(3)
k = np.tile(np.eye(4), (100000, 1, 1)); k[:, :3, 3] = rng.normal(size=(100000, 3))
times = np.arange(1e5)
got = report(lambda: ps.sample(k, times, [0.0, 54321.37, 99999.0], levels=12))
# The keys around 54321 alone, sampled there: equal (the scheme is local).
local = ps.sample(k[54300:54344], times[54300:54344], [54321.37], levels=12, timing="linear")
window = ps.sample(k, times, [54321.37], levels=12, timing="linear")
print(json.dumps({"start": bool(np.array_equal(got[0], k[0])), "end": bool(np.array_equal(got[2], k[-1])),
                  "local": float(np.abs(local - window).max())}))
"""
    )
    assert outcome == {"finite": True}
    assert check["start"] and check["end"], check
    assert check["local"] < 1e-12, check


def test_tiny_key_spacing_is_computed_exactly():
    """Key times 1e-170 apart (the issue's silent NaN) are legitimately computable: the
    motion is the same as with the times scaled up to 1 apart."""
    values = np.eye(4)[:, :3]
    tiny = polyscrew.sample_vectors(values, np.arange(4) * 1e-170, [1.5e-170, 2.25e-170])
    unit = polyscrew.sample_vectors(values, np.arange(4.0), [1.5, 2.25])
    assert np.isfinite(tiny).all()
    assert np.abs(tiny - unit).max() < 1e-15, (tiny, unit)
    closed = polyscrew.sample_vectors(values, np.arange(4) * 1e-170, [3.5e-170], closed=True)
    assert np.abs(closed - polyscrew.sample_vectors(values, np.arange(4.0), [3.5], closed=True)).max() < 1e-15


@pytest.mark.parametrize("scheme", ["jarek", "four_point", "bspline"])
@pytest.mark.parametrize("closed", [False, True])
def test_translations_at_the_edge_of_the_range_stay_finite(scheme, closed):
    """Keys alternating between +-1e150 with half turns, at 12 levels: finite output, and no
    pose further out than a few times the keys (the factor the range was derived with)."""
    rng = np.random.default_rng(7)
    keys = np.tile(np.eye(4), (5, 1, 1))
    for i in range(5):
        a = np.pi * (i % 2)
        keys[i, :3, :3] = [[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]]
        keys[i, :3, 3] = (-1) ** i * polyscrew.MAX_COORDINATE * np.sign(rng.normal(size=3))
    dense = polyscrew.subdivide(keys, scheme, levels=12, closed=closed)
    assert np.isfinite(dense).all()
    assert np.abs(dense[:, :3, 3]).max() < 4 * polyscrew.MAX_COORDINATE
    times = polyscrew.sample(keys, np.arange(5.0), np.linspace(-1, 6, 1001), scheme, 12, closed)
    assert np.isfinite(times).all()
    sc = polyscrew.screw(np.eye(4), np.eye(4) + np.eye(4, k=3) * polyscrew.MAX_COORDINATE)
    assert sc.angle == 0 and sc.slide == polyscrew.MAX_COORDINATE
    assert np.array_equal(sc.axis, [1.0, 0.0, 0.0])  # np.eye(4, k=3) moves along x


def test_pure_translation_of_a_rotated_pose_is_a_translation():
    """The issue's example: a pose moved by (0, 3, 4) has slide 5 along (0, 0.6, 0.8), for
    every rotation of the pose (many of them leave a round-off relative rotation), at any
    distance from the origin; a true turn of 1e-13 rad on a small pose stays exact."""
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(15)
    move = np.array([0.0, 3.0, 4.0])
    for i in range(5000):
        a = np.eye(4)
        a[:3, :3] = Rotation.random(random_state=rng).as_matrix()
        a[:3, 3] = rng.uniform(-1, 1, 3) * 10.0 ** rng.integers(-3, 7)
        for b in (a.copy(), a.copy()):
            b[:3, 3] += move
            sc = polyscrew.screw(a, b)
            scale = 1 + np.abs(a[:3, 3]).max()
            assert sc.angle == 0.0, (i, sc)
            assert abs(sc.slide - 5.0) < 1e-14 * scale, (i, sc)
            assert np.abs(sc.axis - move / 5).max() < 1e-14 * scale, (i, sc)
    # A true turn of 1e-13 rad about x through the origin of a small pose, with the move.
    a = np.eye(4)
    a[:3, 3] = [0.2, 0.1, 0.3]
    b = np.eye(4)
    c, s = np.cos(1e-13), np.sin(1e-13)
    b[:3, :3] = [[1, 0, 0], [0, c, -s], [0, s, c]]
    b[:3, 3] = b[:3, :3] @ a[:3, 3] + move
    sc = polyscrew.screw(a, b)
    assert abs(sc.angle - 1e-13) < 1e-25
    mid = polyscrew.interpolate(a, b, 0.5)
    c, s = np.cos(5e-14), np.sin(5e-14)
    half = np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    assert np.abs(mid[:3, :3] - half).max() < 1e-15
    assert np.abs(mid[:3, 3] - (half @ a[:3, 3] + move / 2)).max() < 1e-12


TYPE_ERRORS = [
    (lambda: polyscrew.subdivide(np.tile(np.eye(4), (2, 1, 1)), levels=2.5), TypeError, r"subdivide: levels: expected an int, got float"),
    (lambda: polyscrew.subdivide(np.tile(np.eye(4), (2, 1, 1)), scheme=5), TypeError, r"subdivide: scheme: expected a str, got int"),
    (lambda: polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0, 1], [0.5], closed="yes"), TypeError, r"sample: closed: expected a bool, got str"),
    (lambda: polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0, 1], [0.5], period="x"), TypeError, r"sample: period: expected a real number, got str"),
    (lambda: polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0, 1], [0.5], closed=True, period=2**2000), ValueError, r"sample: period: 1\d+ is too large for a float"),
    (lambda: polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), "ab", [0.5]), TypeError, r"sample: key_times: expected real numbers, got <U2"),
    (lambda: polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0, 1], [[0.5], [1, 2]]), ValueError, r"sample: times: .*inhomogeneous"),
    (lambda: polyscrew.sample_channels(np.tile(np.eye(4), (2, 1, 1)), [0, 1], [0.5], 3), TypeError, r"sample_channels: mode: expected a str, got int"),
    (lambda: polyscrew.interpolate(np.eye(4), np.eye(4), 1j), TypeError, r"interpolate: t: expected real numbers, got complex128"),
    (lambda: polyscrew.interpolate(np.eye(4), np.eye(4), 2**2000), ValueError, r"interpolate: t: 1\d+ is too large for a float"),
    (lambda: polyscrew.interpolate(np.eye(4), np.eye(3), 0.5), ValueError, r"interpolate: b: expected shape \(4, 4\) or \(N, 4, 4\)"),
    (lambda: polyscrew.interpolate(np.diag([2.0, 1, 1, 1]), np.eye(4), 0.5), ValueError, r"interpolate: a: not rigid: scale"),
    (lambda: polyscrew.screw([[None] * 4] * 4, np.eye(4)), TypeError, r"screw: a: expected real numbers, got object"),
    (lambda: polyscrew.sweep(np.eye(3), [[0, 1, 2]], np.tile(np.eye(4), (2, 1, 1)), steps=8.0), TypeError, r"sweep: steps: expected an int, got float"),
    (lambda: polyscrew.sweep(np.eye(3), [["a", "b", "c"]], np.tile(np.eye(4), (2, 1, 1))), TypeError, r"sweep: triangles: expected integers, got <U1"),
    (lambda: polyscrew.fit_angular_velocity([[1.0, 0, 0, 0]] * 2, [0.0, 1], [0.0, 1], np.zeros((2, 3)), alpha="x"), TypeError, r"fit_angular_velocity: alpha: expected a real number, got str"),
    (lambda: polyscrew.fit_angular_velocity([[1.0, 0, 0, 0]] * 2, [0.0, 1], [0.0, 1], np.zeros((2, 3)), max_frames=2**70), ValueError, r"fit_angular_velocity: max_frames 1180591620717411303424 out of range 0\.\.=1000000"),
    (lambda: polyscrew.feature_motion(np.tile(np.eye(4), (3, 1, 1)), stiffness="x"), TypeError, r"feature_motion: stiffness: expected real numbers, got <U1"),
    (lambda: polyscrew.feature_motion(np.tile(np.eye(4), (3, 1, 1)), parametrization=None), TypeError, r"feature_motion: parametrization: expected a str, got NoneType"),
    (lambda: polyscrew.register_points(np.eye(3) + 0j, np.eye(3)), TypeError, r"register_points: src: expected real numbers, got complex128"),
    (lambda: polyscrew.set_memory_budget(-1), ValueError, r"set_memory_budget: bytes -1 out of range"),
]


@pytest.mark.parametrize("call, error, message", TYPE_ERRORS, ids=[t[2][:48] for t in TYPE_ERRORS])
def test_errors_name_the_function_and_the_argument(call, error, message):
    with pytest.raises(error, match=message):
        call()


def test_whole_float_triangle_indices_are_accepted():
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    t = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    poses = np.tile(np.eye(4), (2, 1, 1))
    poses[1, 0, 3] = 1.0
    a = polyscrew.sweep(v, np.array(t, float), poses)
    b = polyscrew.sweep(v, t, poses)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


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


# --- The GIL is released during long calls --------------------------------------------------


def _fit():
    t = np.linspace(0.0, 1.0, 5)
    q = np.array([[np.cos(0.3 * x), 0, 0, np.sin(0.3 * x)] for x in t])
    return polyscrew.fit_angular_velocity(q, t, [0.0, 1.0], [[0, 0, 0.6], [0, 0, 0.6]])


def _points(seed):
    return np.random.default_rng(seed).normal(size=(3_000_000, 3))


# name: (inputs, made before the call is timed; the call)
LONG_CALLS = {
    "inertia_points": (lambda: (_points(0),), polyscrew.inertia_points),
    "register_points": (lambda: (_points(0), _points(1)), polyscrew.register_points),
    "rotation_channels": (lambda: (np.tile(np.eye(3), (1_500_000, 1, 1)), "XYZ"), polyscrew.rotation_channels),
    "AngularVelocityFit.sample": (lambda: (_fit(), np.linspace(0, 1, 3_000_000)), lambda fit, t: fit.sample(t)),
    "AngularVelocityFit.angular_velocity": (
        lambda: (_fit(), np.linspace(0, 1, 3_000_000)),
        lambda fit, t: fit.angular_velocity(t),
    ),
    "sample": (lambda: (np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], np.linspace(0, 1, 1_500_000)), polyscrew.sample),
    "subdivide": (lambda: (np.tile(np.eye(4), (300, 1, 1)), "jarek", 12), polyscrew.subdivide),
}


@pytest.mark.parametrize("name", LONG_CALLS)
def test_other_threads_run_during_a_long_call(name):
    """A Python thread counting in a loop keeps counting while the call runs: the call
    released the GIL (with the GIL held it would stop for the whole call)."""
    inputs, call = LONG_CALLS[name]
    arguments = inputs()
    stop = threading.Event()
    count = [0]

    def counter():
        while not stop.is_set():
            count[0] += 1

    thread = threading.Thread(target=counter)
    thread.start()
    try:
        time.sleep(0.05)
        before, start = count[0], time.perf_counter()
        call(*arguments)
        during, elapsed = count[0] - before, time.perf_counter() - start
    finally:
        stop.set()
        thread.join()
    # Calibrate: how far the counter gets in the same time with the main thread asleep.
    stop.clear()
    count[0] = 0
    thread = threading.Thread(target=counter)
    thread.start()
    time.sleep(elapsed)
    stop.set()
    thread.join()
    alone = count[0]
    assert elapsed > 0.05, f"{name} took only {elapsed:.3f} s: too short to tell"
    assert during > 0.2 * alone, f"{name}: {during} counts during {elapsed:.3f} s, {alone} alone"
