"""The polyscrew module against independent references: pytransform3d's screw interpolation,
the paper's subdivision formulas, the linear masks, and the smoothness of figure 3."""

import numpy as np
import polyscrew
import pytest

from conftest import random_pose, reference_s, rigid

SCHEMES = ("four_point", "bspline", "jarek")


def test_s_agrees_with_pytransform3d_on_10000_pairs(rng):
    worst = 0.0
    for _ in range(10_000):
        a = random_pose(rng, scale=2.0)
        b = random_pose(rng, max_angle=np.radians(179.0), scale=1.0) @ a
        t = rng.uniform(-0.5, 1.5)
        worst = max(worst, np.abs(polyscrew.interpolate(a, b, t) - reference_s(a, t, b)).max())
    print(f"largest difference to pytransform3d over 10,000 pairs: {worst:.2e}")
    assert worst < 1e-9


@pytest.mark.parametrize("angle", [0.0, 1e-13, 1e-9, 1e-6, 0.5, np.pi - 1e-6, np.pi - 1e-9])
def test_s_is_exact_for_tiny_and_half_turn_angles(angle):
    # The exact screw by construction: rotation about the line through p along axis, plus a
    # unit slide; evaluated directly at each t.
    axis = np.array([0.0, 0.6, 0.8])
    p = np.array([0.5, -0.3, 0.1])
    a = rigid([1.0, 2.0, 0.5], 0.4, [0.2, 0.1, 0.3])

    def exact(t):
        m = rigid(axis, t * angle, [0.0, 0.0, 0.0])
        m[:3, 3] = p - m[:3, :3] @ p + t * 1.0 * axis
        return m @ a

    b = exact(1.0)
    ts = np.linspace(-0.5, 1.5, 41)
    got = polyscrew.interpolate(a, b, ts)
    want = np.stack([exact(t) for t in ts])
    assert np.abs(got - want).max() < 1e-12


def test_screw_parameters():
    axis = np.array([1.0, 1.0, 0.0]) / np.sqrt(2.0)
    p = np.array([0.0, 0.0, 3.0])
    a = rigid([0.3, -0.2, 0.9], 0.7, [1.0, 2.0, -0.5])
    m = rigid(axis, 2.0, [0.0, 0.0, 0.0])
    m[:3, 3] = p - m[:3, :3] @ p + 0.25 * axis
    sc = polyscrew.screw(a, m @ a)
    assert sc.angle == pytest.approx(2.0, abs=1e-14)
    assert sc.slide == pytest.approx(0.25, abs=1e-14)
    np.testing.assert_allclose(sc.axis, axis, atol=1e-14)
    off = (sc.point - p) - np.dot(sc.point - p, axis) * axis
    assert np.linalg.norm(off) < 1e-13
    # The reported point is the axis point nearest to a's origin.
    assert abs(np.dot(sc.point - a[:3, 3], axis)) < 1e-13

    t = polyscrew.screw(np.eye(4), rigid([0, 0, 1], 0.0, [0.0, 3.0, 4.0]))
    assert t.angle == 0.0 and t.slide == pytest.approx(5.0)
    np.testing.assert_allclose(t.axis, [0.0, 0.6, 0.8], atol=1e-15)


def test_interpolate_shapes_and_endpoints(rng):
    a, b = random_pose(rng), random_pose(rng)
    assert polyscrew.interpolate(a, b, 0.3).shape == (4, 4)
    out = polyscrew.interpolate(a, b, [0.0, 1.0])
    assert out.shape == (2, 4, 4)
    np.testing.assert_allclose(out[0], a, atol=1e-15)
    np.testing.assert_allclose(out[1], b, atol=1e-14)


def paper_level(keys, scheme):
    """One closed level of ScrewBender section 4 (formulation A), written from the paper
    with the independent s."""
    n = len(keys)
    s = reference_s
    out = []
    for i in range(n):
        a, b, c, d = keys[i - 1], keys[i], keys[(i + 1) % n], keys[(i + 2) % n]
        if scheme == "bspline":
            old = s(s(b, 0.25, a), 0.5, s(b, 0.25, c))
            new = s(b, 0.5, c)
        elif scheme == "four_point":
            old = b
            new = s(s(a, 9 / 8, b), 0.5, s(d, 9 / 8, c))
        else:
            old = s(s(a, 7 / 8, b), 0.5, s(c, 7 / 8, b))
            new = s(s(a, 17 / 16, b), 0.5, s(d, 17 / 16, c))
        out += [old, new]
    return np.stack(out)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_one_closed_level_equals_the_paper_formulas(rng, scheme):
    for _ in range(20):
        keys = [random_pose(rng, scale=2.0)]
        for _ in range(5):
            keys.append(random_pose(rng, max_angle=np.radians(100.0)) @ keys[-1])
        keys = np.stack(keys)
        got = polyscrew.subdivide(keys, scheme, 1, closed=True)
        want = paper_level(keys, scheme)
        assert np.abs(got - want).max() < 1e-9


@pytest.mark.parametrize("scheme", SCHEMES)
def test_vectors_follow_the_linear_masks(rng, scheme):
    p = rng.normal(size=(7, 3))
    q = polyscrew.subdivide_vectors(p, scheme, 1, closed=True)
    a, b, c, d = (np.roll(p, -k, axis=0) for k in (-1, 0, 1, 2))
    old, new = {
        "bspline": ((2 * a + 12 * b + 2 * c) / 16, (b + c) / 2),
        "four_point": (b, (-a + 9 * b + 9 * c - d) / 16),
        "jarek": ((2 * a + 28 * b + 2 * c) / 32, (-a + 17 * b + 17 * c - d) / 32),
    }[scheme]
    np.testing.assert_allclose(q[0::2], old, atol=1e-14)
    np.testing.assert_allclose(q[1::2], new, atol=1e-14)
    # A translation-only polyscrew is the polygon subdivision of its origins.
    poses = np.stack([rigid([0, 0, 1], 0.0, x) for x in p])
    np.testing.assert_allclose(polyscrew.subdivide(poses, scheme, 3, True)[:, :3, 3],
                               polyscrew.subdivide_vectors(p, scheme, 3, True), atol=1e-13)


def jumps(points, levels):
    """Largest jump of the first and second divided differences of a closed trajectory
    sampled at spacing 2**-levels (ScrewBender figure 3, per unit parameter)."""
    h = 2.0 ** -levels
    d1 = (np.roll(points, -1, axis=0) - points) / h
    d2 = (np.roll(d1, -1, axis=0) - d1) / h
    jump = lambda d: np.linalg.norm(np.roll(d, -1, axis=0) - d, axis=1).max()  # noqa: E731
    return jump(d1), jump(d2)


@pytest.mark.parametrize("scheme", SCHEMES)
def test_smoothness_grows_level_over_level(rng, scheme):
    # A random closed sequence of 8 poses; the trajectories of the body points (0, 0, 0) and
    # (2, 0, 0) as in the paper's figure 10.
    keys = [random_pose(rng, scale=2.0)]
    for _ in range(7):
        keys.append(random_pose(rng, max_angle=np.radians(90.0)) @ keys[-1])
    keys = np.stack(keys)
    for body_point in ([0.0, 0.0, 0.0, 1.0], [2.0, 0.0, 0.0, 1.0]):
        rows = []
        for levels in range(3, 9):
            dense = polyscrew.subdivide(keys, scheme, levels, closed=True)
            trajectory = (dense @ np.array(body_point))[:, :3]
            rows.append((levels, *jumps(trajectory, levels)))
        print(scheme, body_point[:3], [f"L{l}: {a:.3g} / {b:.3g}" for l, a, b in rows])
        tangent = [r[1] for r in rows]
        second = [r[2] for r in rows]
        assert all(b < a for a, b in zip(tangent, tangent[1:])), tangent
        assert tangent[-1] < 0.1 * tangent[0]
        if scheme != "four_point":
            assert all(b < a for a, b in zip(second, second[1:])), second
            assert second[-1] < 0.3 * second[0]


def test_sample_hits_keys_and_respects_timing(rng):
    keys = [random_pose(rng)]
    for _ in range(4):
        keys.append(random_pose(rng, max_angle=1.5) @ keys[-1])
    keys = np.stack(keys)
    key_times = np.array([1.0, 4.0, 13.0, 15.0, 30.0])
    got = polyscrew.sample(keys, key_times, key_times, scheme="four_point", levels=5)
    np.testing.assert_allclose(got, keys, atol=1e-13)
    # Evenly spaced keys: smooth and linear timing are the same map, and the samples at the
    # dense parameters are the subdivided poses.
    even = np.arange(5) * 8.0
    dense = polyscrew.subdivide(keys, "jarek", 3)
    frames = np.arange(len(dense)) * 1.0
    for timing in ("smooth", "linear"):
        np.testing.assert_allclose(polyscrew.sample(keys, even, frames, levels=3, timing=timing), dense, atol=1e-13)
    # Closed: one period later, the same pose.
    a = polyscrew.sample(keys, key_times, [2.5, 20.0], closed=True, period=40.0)
    b = polyscrew.sample(keys, key_times, [42.5, 60.0], closed=True, period=40.0)
    np.testing.assert_allclose(a, b, atol=1e-12)
    # Open motions hold the end poses outside the key range.
    ends = polyscrew.sample(keys, key_times, [-100.0, 100.0])
    np.testing.assert_allclose(ends, keys[[0, -1]], atol=1e-15)


def test_smooth_timing_keeps_velocity_continuous_at_uneven_keys():
    # A straight line keyed at uneven frames: linear timing jumps in speed at the keys,
    # smooth timing does not.
    x = np.array([[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0], [3.0, 0.0, 0.0]])
    key_times = np.array([0.0, 2.0, 10.0, 12.0])
    h = 1e-4
    t = np.array([2.0 - h, 2.0, 2.0 + h])
    for timing, continuous in (("smooth", True), ("linear", False)):
        v = polyscrew.sample_vectors(x, key_times, t, scheme="four_point", levels=6, timing=timing)[:, 0]
        left, right = (v[1] - v[0]) / h, (v[2] - v[1]) / h
        assert (abs(left - right) < 1e-2) == continuous, (timing, left, right)


def test_rotation_channels_match_scipy_for_every_order(rng):
    from scipy.spatial.transform import Rotation

    rots = Rotation.random(200, random_state=7)
    mats = rots.as_matrix()
    q = polyscrew.rotation_channels(mats, "QUATERNION")
    np.testing.assert_allclose(np.abs(np.einsum("ij,ij->i", q, rots.as_quat(scalar_first=True))), 1.0, atol=1e-12)
    for order in ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"):
        e = polyscrew.rotation_channels(mats, order)
        # Blender's "XYZ" applies X first: scipy's extrinsic "xyz" with angles in that order.
        idx = ["XYZ".index(c) for c in order]
        back = Rotation.from_euler(order.lower(), e[:, idx]).as_matrix()
        assert np.abs(back - mats).max() < 1e-12, order
    aa = polyscrew.rotation_channels(mats, "AXIS_ANGLE")
    back = Rotation.from_rotvec(aa[:, 1:] * aa[:, :1]).as_matrix()
    assert np.abs(back - mats).max() < 1e-12


@pytest.mark.parametrize("mode", ["QUATERNION", "AXIS_ANGLE", "XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"])
@pytest.mark.parametrize("closed", [False, True])
def test_sample_channels_is_rotation_channels_of_sample(mode, closed):
    from scipy.spatial.transform import Rotation

    # A tumbling motion over several turns, keyed at uneven times, sampled past its ends.
    n = 9
    keys = np.tile(np.eye(4), (n, 1, 1))
    keys[:, :3, :3] = Rotation.from_rotvec(np.outer(np.arange(n), [1.1, 0.4, 1.9])).as_matrix()
    keys[:, :3, 3] = np.column_stack([np.cos(np.arange(n)), np.sin(np.arange(n)), 0.3 * np.arange(n)])
    key_times = np.cumsum([1.0, 3.0, 7.0, 2.0, 5.0, 4.0, 9.0, 3.0, 6.0])
    times = np.linspace(key_times[0] - 2.0, key_times[-1] + 5.0, 997)
    spec = dict(scheme="bspline", levels=5, closed=closed, timing="smooth")
    previous = None if mode == "AXIS_ANGLE" else polyscrew.rotation_channels(keys[:1], mode)[0] + 2 * np.pi
    location, rotation = polyscrew.sample_channels(keys, key_times, times, mode, previous, **spec)
    poses = polyscrew.sample(keys, key_times, times, **spec)
    np.testing.assert_array_equal(location, poses[:, :3, 3])
    # The same quaternions reach the channels, less the round trip through the matrices.
    want = polyscrew.rotation_channels(poses, mode, previous)
    assert rotation.shape == want.shape
    assert np.abs(rotation - want).max() < 1e-13, np.abs(rotation - want).max()
