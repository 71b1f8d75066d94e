"""Issue 15: every function at its documented limits (12 levels, 4096 steps, the largest
times array the memory budget accepts), each in a child process under a 4 GB address-space
cap: the largest accepted request is computed (finite), a slightly larger one is refused up
front with a ValueError naming the memory budget, and the child exits normally.

The largest accepted size is found from the module's own estimates: with the budget set to
0 bytes every call is refused before it allocates anything, and the refusal says how much
it would need; two sizes give the estimate's slope and intercept, and the size where it
meets the default budget.
"""

from __future__ import annotations

import pytest

from capped import KEYS, NEED, run_capped

HELPERS = NEED + KEYS + r"""

def limits(make, s1, s2):
    '''Sizes just under (98 %) and just over (103 %) the largest that the budget accepts.'''
    n1, n2 = need(make(s1)), need(make(s2))
    slope = (n2 - n1) / (s2 - s1)
    largest = (ps.memory_budget() - (n1 - slope * s1)) / slope
    print(json.dumps({"largest": largest}))
    return int(largest * 0.98), int(largest * 1.03) + 1

def at_limits(make, s1, s2):
    ok, over = limits(make, s1, s2)
    report(make(ok))
    report(make(over))
"""

# name: (code defining `make(size)`, two sizes for the estimate's slope)
CASES = {
    "subdivide, keys at 12 levels": (
        "make = lambda n: (lambda k=keys(n): ps.subdivide(k, 'jarek', levels=12))",
        (100, 200),
    ),
    "subdivide_vectors, keys at 12 levels": (
        "make = lambda n: (lambda v=keys(n)[:, :3, 3]: ps.subdivide_vectors(v, levels=12, closed=True))",
        (1000, 2000),
    ),
    "sample, times (50 keys at 12 levels)": (
        "k = keys(50)\nmake = lambda m: (lambda t=np.linspace(-1, 50, m): ps.sample(k, np.arange(50.0), t, levels=12))",
        (1_000_000, 2_000_000),
    ),
    "sample, times (1,000 keys at 12 levels, windowed)": (
        "k = keys(1000)\nmake = lambda m: (lambda t=np.linspace(-1, 1000, m): ps.sample(k, np.arange(1000.0), t, levels=12))",
        (1_000_000, 2_000_000),
    ),
    "sample_channels, times (100 keys at 12 levels)": (
        "k = keys(100)\nmake = lambda m: (lambda t=np.linspace(0, 99, m): ps.sample_channels(k, np.arange(100.0), t, 'ZXY', levels=12))",
        (1_000_000, 2_000_000),
    ),
    "sample_vectors, times (100 keys at 12 levels)": (
        "v = keys(100)[:, :3, 3]\nmake = lambda m: (lambda t=np.linspace(0, 99, m): ps.sample_vectors(v, np.arange(100.0), t, levels=12, closed=True))",
        (1_000_000, 2_000_000),
    ),
    "interpolate, t": (
        "a, b = keys(2)\nmake = lambda m: (lambda t=np.linspace(-2, 3, m): ps.interpolate(a, b, t))",
        (1_000_000, 2_000_000),
    ),
    "rotation_channels, rotations (broadcast, no input memory)": (
        "r = keys(1)[0, :3, :3]\nmake = lambda n: (lambda: ps.rotation_channels(np.broadcast_to(r, (n, 3, 3)), 'QUATERNION'))",
        (1_000_000, 2_000_000),
    ),
    "feature_motion, keys at 12 levels": (
        "make = lambda n: (lambda k=keys(n): ps.feature_motion(k, levels=12))",
        (20, 40),
    ),
    "sample_feature, times (20 keys at 12 levels, four_point)": (
        "k = keys(20)\nmake = lambda m: (lambda t=np.linspace(0, 19, m): ps.sample_feature(k, np.arange(20.0), t, 'four_point', levels=12))",
        (1_000_000, 2_000_000),
    ),
    "AngularVelocityFit.sample, times": (
        "fit = ps.fit_angular_velocity([[1.0, 0, 0, 0], [np.cos(0.5), 0, 0, np.sin(0.5)]], [0.0, 1.0], [0.0, 1.0], [[0, 0, 1.0]] * 2)\n"
        "make = lambda m: (lambda t=np.linspace(0, 1, m): fit.sample(t))",
        (1_000_000, 2_000_000),
    ),
    "AngularVelocityFit.angular_velocity, times": (
        "fit = ps.fit_angular_velocity([[1.0, 0, 0, 0], [np.cos(0.5), 0, 0, np.sin(0.5)]], [0.0, 1.0], [0.0, 1.0], [[0, 0, 1.0]] * 2)\n"
        "make = lambda m: (lambda t=np.linspace(0, 1, m): fit.angular_velocity(t))",
        (1_000_000, 2_000_000),
    ),
    "fit_angular_velocity, sample_times": (
        "q = [[1.0, 0, 0, 0], [np.cos(0.5), 0, 0, np.sin(0.5)]]\n"
        "make = lambda m: (lambda t=np.linspace(0, 1, m): ps.fit_angular_velocity(q, [0.0, 1.0], [0.0, 1.0], [[0, 0, 1.0]] * 2, sample_times=t))",
        (1_000_000, 2_000_000),
    ),
    "inertia_points, points": (
        "make = lambda n: (lambda p=np.random.default_rng(1).normal(size=(n, 3)): ps.inertia_points(p))",
        (1_000_000, 2_000_000),
    ),
}


@pytest.mark.parametrize("name", CASES)
def test_largest_accepted_is_computed_and_larger_is_refused(name):
    code, (s1, s2) = CASES[name]
    lines = run_capped(HELPERS + code + f"\nat_limits(make, {s1}, {s2})")
    largest, computed, refused = lines
    assert largest["largest"] > s2, (name, largest)
    assert computed == {"finite": True}, (name, computed)
    assert refused.get("error") == "ValueError", (name, refused)
    assert "over the memory budget" in refused["message"], (name, refused)


def test_sweep_at_4096_steps():
    """A body over a few screws at the largest step count is computed; the issue's sphere
    over 100 poses is refused before the span that would pass the budget."""
    lines = run_capped(
        """
v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
t = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
p = np.tile(np.eye(4), (12, 1, 1))
for i in range(12):
    c, s = np.cos(0.4 * i), np.sin(0.4 * i)
    p[i, :2, :2] = [[c, -s], [s, c]]
    p[i, :3, 3] = [0.5 * i, np.sin(i), 0.1 * i]
report(lambda: ps.sweep(v, t, p, steps=4096))
report(lambda: ps.sweep(v, t, p, steps=4097))
report(lambda: ps.sweep(np.tile(v, (1, 1)), t, np.tile(p, (800, 1, 1)), steps=4096))
"""
    )
    assert lines[0] == {"finite": True}
    assert lines[1]["error"] == "ValueError" and "steps 4097 out of range 1..=4096" in lines[1]["message"]
    assert lines[2].get("error") == "ValueError", lines[2]
    assert "sweep: the swept mesh would need" in lines[2]["message"], lines[2]


def test_fit_at_its_largest_fragment_count_and_frames():
    """The fit at a million fragments (the most accepted) is computed; 1 % more fragments is
    refused; a million variable frames allowed (8 kB each, with room) are refused up front
    by the budget, 100,000 are computed."""
    lines = run_capped(
        """
q = [[1.0, 0, 0, 0], [np.cos(0.5), 0, 0, np.sin(0.5)]]
args = ([0.0, 1.0], [0.0, 1.0], [[0, 0, 1.0], [0, 0, 1.0]])
def fit(**kw):
    try:
        return ps.fit_angular_velocity(q, *args, **kw)
    except ValueError as e:
        if hasattr(e, "result"):
            return e.result
        raise
report(lambda: fit(fragment_duration=1e-6, max_iterations=1_000_000))
report(lambda: fit(fragment_duration=0.99e-6))
report(lambda: fit(fragment_duration=1e-6, max_frames=1_000_000))
report(lambda: fit(fragment_duration=1e-6, max_frames=100_000))
"""
    )
    assert lines[0] == {"finite": True}, lines
    assert lines[1]["error"] == "ValueError" and "at most 1000000 fragments" in lines[1]["message"], lines
    assert lines[2]["error"] == "ValueError" and "fit would need 8.22 GB, over the memory budget" in lines[2]["message"], lines
    assert lines[3] == {"finite": True}, lines
