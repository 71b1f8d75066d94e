"""Feature-point motion design (Hofer-Pottmann-Ravani, issue 5) through the Python module:
registration against scipy, the variational scheme's linear systems and limits, rigidity,
frame invariance, smoothness, the paper's pose count, sampling and every bad input."""

import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

from conftest import random_pose, rigid

INF = float("inf")


def wandering_keys(rng, n, closed_loop=False):
    """Keys that turn by 0.3..1.3 rad and move ~2 units between each other."""
    pose = np.eye(4)
    out = []
    for _ in range(n):
        step = rigid(rng.normal(size=3), rng.uniform(0.3, 1.3), rng.uniform(-2, 2, 3))
        pose = step @ pose
        out.append(pose)
    return np.array(out)


def translation_keys(points):
    """Pure translations: the motion's origin path is then the curve scheme itself."""
    keys = np.stack([np.eye(4)] * len(points))
    keys[:, :3, 3] = points
    return keys


def polygon(n):
    i = np.arange(n, dtype=float)
    return np.c_[i * 1.5 + np.sin(i * 1.9), np.cos(i * 0.8) * 2.0, np.sin(i * 0.5)]


def rigidity_error(poses):
    r = poses[..., :3, :3]
    eye = np.broadcast_to(np.eye(3), r.shape)
    ortho = np.abs(np.swapaxes(r, -1, -2) @ r - eye).max()
    det = np.abs(np.linalg.det(r) - 1.0).max()
    bottom = np.abs(poses[..., 3, :] - [0, 0, 0, 1]).max()
    return max(ortho, det, bottom)


# --- registration ---------------------------------------------------------------------------


def scipy_registration(src, dst, weights=None):
    """Independent oracle: scipy's Rotation.align_vectors on the centred clouds."""
    w = np.ones(len(src)) if weights is None else np.asarray(weights, float)
    xbar = (w[:, None] * src).sum(0) / w.sum()
    ybar = (w[:, None] * dst).sum(0) / w.sum()
    rot, _ = Rotation.align_vectors(dst - ybar, src - xbar, weights=w)
    pose = np.eye(4)
    pose[:3, :3] = rot.as_matrix()
    pose[:3, 3] = ybar - rot.as_matrix() @ xbar
    return pose


@pytest.mark.parametrize("k", [3, 4, 7, 50, 400])
def test_registration_matches_scipy(rng, k):
    for _ in range(20):
        truth = random_pose(rng, scale=5.0)
        src = rng.uniform(-1, 1, (k, 3))
        dst = src @ truth[:3, :3].T + truth[:3, 3] + rng.normal(scale=0.05, size=(k, 3))
        weights = rng.uniform(0.1, 2.0, k)
        for w in (None, weights):
            got = polyscrew.register_points(src, dst, w)
            want = scipy_registration(src, dst, w)
            assert np.abs(got - want).max() < 1e-9, (k, w is None)


def test_registration_recovers_a_known_transform(rng):
    for _ in range(50):
        truth = random_pose(rng, scale=10.0)
        src = rng.uniform(-2, 2, (8, 3))
        dst = src @ truth[:3, :3].T + truth[:3, 3]
        assert np.abs(polyscrew.register_points(src, dst) - truth).max() < 1e-12
    # Noisy: the rotation error's mean square ~ sigma^2 tr((tr(J) I - J)^-1) (J the
    # centred second moment of src); the centroid's error ~ sigma / sqrt(K).
    sigma, k = 0.01, 300
    errors, predicted = [], []
    for _ in range(40):
        truth = random_pose(rng, scale=3.0)
        src = rng.uniform(-1, 1, (k, 3))
        dst = src @ truth[:3, :3].T + truth[:3, 3] + rng.normal(scale=sigma, size=(k, 3))
        got = polyscrew.register_points(src, dst)
        delta = Rotation.from_matrix(got[:3, :3] @ truth[:3, :3].T).magnitude()
        errors.append(delta**2)
        x = src - src.mean(0)
        j = x.T @ x
        predicted.append(sigma**2 * np.trace(np.linalg.inv(np.trace(j) * np.eye(3) - j)))
        c = src.mean(0)
        moved = got[:3, :3] @ c + got[:3, 3] - (truth[:3, :3] @ c + truth[:3, 3])
        assert np.abs(moved).max() < 5 * sigma / np.sqrt(k)
    assert 0.6 < np.sum(errors) / np.sum(predicted) < 1.5


def test_registration_errors():
    line = np.outer([0.0, 1.0, 2.0, 3.5], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match=r"register_points: registration: the best rotation is not unique"):
        polyscrew.register_points(line, line + 1.0)
    with pytest.raises(ValueError, match=r"register_points: target points: expected 4 entries, got 3"):
        polyscrew.register_points(line, line[:3])
    with pytest.raises(ValueError, match=r"points: 2 given, at least 3 needed"):
        polyscrew.register_points(line[:2], line[:2])
    bad = np.eye(3)
    bad[1, 2] = np.nan
    with pytest.raises(ValueError, match=r"target point 1 is NaN or infinite"):
        polyscrew.register_points(np.eye(3), bad)
    with pytest.raises(ValueError, match=r"weights: weight 2 is negative"):
        polyscrew.register_points(np.eye(3), np.eye(3), [1.0, 1.0, -1.0])
    with pytest.raises(ValueError, match=r"src: expected shape \(K, 3\)"):
        polyscrew.register_points(np.ones((4, 2)), np.ones((4, 2)))


def test_inertia_points_keep_barycentre_and_inertia(rng):
    cloud = rng.normal(size=(200, 3)) * [3.0, 1.0, 0.3] + [1.0, -2.0, 0.5]
    six = polyscrew.inertia_points(cloud)
    assert six.shape == (6, 3)
    assert np.abs(six.mean(0) - cloud.mean(0)).max() < 1e-12
    x, y = cloud - cloud.mean(0), six - six.mean(0)
    assert np.abs(x.T @ x - y.T @ y).max() < 1e-9
    # Registration to an affine image sees only barycentre and inertia (Proposition 2).
    a = np.array([[1.1, 0.2, -0.1], [0.1, 0.9, 0.3], [-0.2, 0.1, 1.2]])
    t = np.array([0.5, -1.0, 2.0])
    full = polyscrew.register_points(cloud, cloud @ a.T + t)
    short = polyscrew.register_points(six, six @ a.T + t)
    assert np.abs(full - short).max() < 1e-10


# --- the variational scheme's linear systems, through pure-translation keys ------------------


def paper_open_interpolating(n):
    """Eq. 23: A (N-1 x N-1), B (N-1 x N)."""
    a = np.diag(np.full(n - 1, 6.0)) + np.diag(np.ones(n - 2), 1) + np.diag(np.ones(n - 2), -1)
    a[0, 0] = a[-1, -1] = 5.0
    b = np.zeros((n - 1, n))
    for i in range(n - 1):
        b[i, i] = b[i, i + 1] = 4.0
    b[0, 0] = b[-1, -1] = 2.0
    return a, b


def test_variational_solves_the_paper_systems():
    for n in (3, 5, 8):
        f = polygon(n)
        # Open interpolating, eq. 23: A q = B f.
        w = polyscrew.feature_motion(translation_keys(f), levels=1)[:, :3, 3]
        a, b = paper_open_interpolating(n)
        q = w[1::2]
        assert np.abs(a @ q - b @ f).max() < 1e-10
        assert np.abs(w[::2] - f).max() == 0.0
        # Closed interpolating, eq. 24: cyclic (6, 1, 1) and (4, 4).
        w = polyscrew.feature_motion(translation_keys(f), levels=1, closed=True)[:, :3, 3]
        a = 6.0 * np.eye(n) + np.roll(np.eye(n), 1, 1) + np.roll(np.eye(n), -1, 1)
        b = 4.0 * np.eye(n) + 4.0 * np.roll(np.eye(n), 1, 1)
        assert np.abs(a @ w[1::2] - b @ f).max() < 1e-10
        # Open approximating, eqs. 26-27: [[A, -B], [-B^T, L]] (q, f^n) = (0, lambda f).
        lam = np.linspace(0.2, 3.0, n)
        lam[0] = 1e8
        w = polyscrew.feature_motion(translation_keys(f), levels=1, stiffness=lam)[:, :3, 3]
        a, b = paper_open_interpolating(n)
        l = np.diag(np.full(n, 6.0) + lam) + np.diag(np.ones(n - 1), 1) + np.diag(np.ones(n - 1), -1)
        l[0, 0], l[-1, -1] = 1.0 + lam[0], 1.0 + lam[-1]
        big = np.block([[a, -b], [-b.T, l]])
        x = np.vstack([w[1::2], w[::2]])
        rhs = np.vstack([np.zeros((n - 1, 3)), lam[:, None] * f])
        scaled = (big @ x - rhs) / np.abs(np.diag(big))[:, None]
        assert np.abs(scaled).max() < 1e-10


def test_variational_limits():
    f = polygon(6)
    keys = translation_keys(f)
    interp = polyscrew.feature_motion(keys, levels=4)
    # lambda -> inf: the interpolating result.
    previous = INF
    for big in (1e2, 1e4, 1e6, 1e8):
        d = np.abs(polyscrew.feature_motion(keys, levels=4, stiffness=big) - interp).max()
        assert d < previous
        previous = d
    assert previous < 1e-6
    assert np.array_equal(polyscrew.feature_motion(keys, levels=4, stiffness=INF), interp)
    # lambda -> 0 at interior keys, ends kept: the straight line through first and last.
    lam = np.full(6, 1e-9)
    lam[[0, -1]] = INF
    path = polyscrew.feature_motion(keys, levels=4, stiffness=lam)[:, :3, 3]
    d = (f[-1] - f[0]) / np.linalg.norm(f[-1] - f[0])
    rel = path - f[0]
    assert np.linalg.norm(rel - np.outer(rel @ d, d), axis=1).max() < 1e-6


def test_approximation_of_noisy_keys_is_smoother(rng):
    # Keys on a circle with positional jitter: the approximating design (stiffness 1) stays
    # closer to the design of the clean keys than the interpolating design of the noisy keys.
    n = 16
    angle = np.linspace(0, 2 * np.pi, n, endpoint=False)
    clean = np.c_[np.cos(angle), np.sin(angle), np.zeros(n)] * 5.0
    reference = polyscrew.feature_motion(
        np.stack([rigid([0, 0, 1], a, p) for a, p in zip(angle, clean)]), levels=4, closed=True
    )
    for _ in range(3):
        noisy = clean + rng.normal(scale=0.3, size=clean.shape)
        keys = np.stack([rigid([0, 0, 1], a, p) for a, p in zip(angle, noisy)])
        exact = polyscrew.feature_motion(keys, levels=4, closed=True)
        smooth = polyscrew.feature_motion(keys, levels=4, closed=True, stiffness=1.0)

        def error(m):
            return np.abs(m - reference).max(axis=(1, 2)).mean()

        assert error(smooth) < 0.8 * error(exact)


# --- motion properties ---------------------------------------------------------------------


def test_paper_count_rigidity_and_keys(rng):
    keys = wandering_keys(rng, 6)
    dense = polyscrew.feature_motion(keys, levels=7, closed=True)
    assert dense.shape == (768, 4, 4)  # Table 1: 6 closed keys, 7 levels
    assert rigidity_error(dense) < 1e-12
    assert np.abs(dense[::128] - keys).max() < 1e-14
    for options in (
        dict(scheme="jarek"),
        dict(scheme="bspline", closed=True),
        dict(scheme="four_point"),
        dict(parametrization="centripetal"),
        dict(stiffness=[INF, 0.5, 1.0, 0.1, 2.0, INF]),
        dict(stiffness=0.3, inserted_stiffness=5.0, closed=True),
    ):
        out = polyscrew.feature_motion(keys, levels=5, **options)
        assert rigidity_error(out) < 1e-12, options


@pytest.mark.parametrize(
    "options",
    [
        dict(),
        dict(closed=True),
        dict(parametrization="centripetal"),
        dict(stiffness=[1e3, 0.5, 1.0, 0.1, 2.0, 1e3]),
        dict(scheme="jarek", closed=True),
        dict(scheme="four_point"),
    ],
)
def test_world_frame_invariance(rng, options):
    keys = wandering_keys(rng, 6)
    a = random_pose(rng, scale=20.0)
    points = rng.normal(size=(12, 3))
    base = polyscrew.feature_motion(keys, levels=4, feature_points=points, **options)
    moved = polyscrew.feature_motion(a @ keys, levels=4, feature_points=points, **options)
    assert np.abs(moved - a @ base).max() < 1e-10


def test_default_points_ignore_how_local_axes_are_turned(rng):
    keys = wandering_keys(rng, 5)
    b = rigid(rng.normal(size=3), 1.1, [0, 0, 0])
    base = polyscrew.feature_motion(keys, levels=4)
    assert np.abs(polyscrew.feature_motion(keys @ b, levels=4) - base @ b).max() < 1e-12


def test_trajectories_converge_c2(rng):
    # Fig. 9 style: second differences of a body point's path times 4**level converge.
    keys = wandering_keys(rng, 5)
    point = np.array([0.7, -0.4, 1.2, 1.0])
    previous, changes = None, []
    for levels in range(3, 9):
        path = (polyscrew.feature_motion(keys, levels=levels) @ point)[:, :3]
        d2 = (path[:-2] - 2 * path[1:-1] + path[2:]) * 4.0**levels
        if previous is not None:
            changes.append(np.abs(previous - d2[1::2]).max())
        previous = d2
    assert all(b < 0.75 * a for a, b in zip(changes, changes[1:])), changes


def test_sample_feature(rng):
    keys = wandering_keys(rng, 5)
    key_times = np.array([1.0, 5.0, 12.0, 13.0, 30.0])
    got = polyscrew.sample_feature(keys, key_times, key_times, levels=4)
    assert got.shape == (5, 4, 4)
    assert np.abs(got - keys).max() < 1e-14
    # Evenly spaced keys, linear timing: the dense poses sit at multiples of 1 / 2**levels.
    even = np.arange(5.0)
    dense = polyscrew.feature_motion(keys, levels=4, closed=True, stiffness=0.5)
    times = np.arange(len(dense)) / 16.0
    at = polyscrew.sample_feature(
        keys, even, times, levels=4, closed=True, stiffness=0.5, period=5.0, timing="linear"
    )
    assert np.abs(at - dense).max() < 1e-12
    frames = np.linspace(0.0, 40.0, 400)
    assert rigidity_error(polyscrew.sample_feature(keys, key_times, frames, closed=True, period=35.0)) < 1e-12


# --- errors --------------------------------------------------------------------------------


def test_errors(rng):
    keys = wandering_keys(rng, 4)
    bad = keys.copy()
    bad[2, 0, 0] *= 1.01
    for function in (polyscrew.feature_motion, lambda k, **kw: polyscrew.sample_feature(k, np.arange(4.0), [0.5], **kw)):
        with pytest.raises(ValueError, match=r"pose 2: not rigid: scale"):
            function(bad)
        with pytest.raises(ValueError, match=r"stiffness: key 1 has stiffness -1"):
            function(keys, stiffness=[INF, -1.0, 1.0, INF])
        with pytest.raises(ValueError, match=r"stiffness: expected 4 entries, got 3"):
            function(keys, stiffness=[1.0, 1.0, 1.0])
        with pytest.raises(ValueError, match=r"stiffness: keys with a positive spring \(to pin the curve\): 1 given, at least 2 needed"):
            function(keys, stiffness=[0.0, 0.0, 0.0, 1.0])
        with pytest.raises(ValueError, match=r"scheme: \"spline\" is not one of"):
            function(keys, scheme="spline")
        with pytest.raises(ValueError, match=r"parametrization: \"chordal\" is not one of"):
            function(keys, parametrization="chordal")
        with pytest.raises(ValueError, match=r"stiffness: only the variational scheme"):
            function(keys, scheme="jarek", stiffness=1.0)
        with pytest.raises(ValueError, match=r"feature points: they are collinear"):
            function(keys, feature_points=np.outer(np.arange(4.0), [1.0, 0.0, 0.0]))
        with pytest.raises(ValueError, match=r"feature point 1 is NaN"):
            function(keys, feature_points=[[0, 0, 0], [np.nan, 0, 0], [0, 1, 0]])
        with pytest.raises(ValueError, match=r"levels 13 out of range"):
            function(keys, levels=13)
    with pytest.raises(ValueError, match=r"keys: key 1: coincides with the next key"):
        polyscrew.feature_motion(keys[[0, 1, 1, 2]], parametrization="centripetal")
    # Two keys half a turn apart, averaged by the closed B-spline: the distorted frame is
    # flat, so no unique rigid fit exists; the error names the sample.
    pair = np.stack([np.eye(4), rigid([0, 0, 1], np.pi, [0, 0, 0])])
    with pytest.raises(ValueError, match=r"feature_motion: key span \d: sample \d+: registration: the best rotation is not unique"):
        polyscrew.feature_motion(pair, scheme="bspline", levels=2, closed=True)
    with pytest.raises(ValueError, match=r"key_times: expected 4 entries, got 3|key times"):
        polyscrew.sample_feature(keys, [0.0, 1.0, 2.0], [0.5])
    with pytest.raises(ValueError, match=r"key time 2 is not finite or not greater"):
        polyscrew.sample_feature(keys, [0.0, 1.0, 1.0, 2.0], [0.5])
