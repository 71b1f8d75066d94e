"""polyscrew.denoise (Remove Noise, issue 19) against independent references.

The motions and the noise are built here with numpy, scipy's Rotation and scipy's matrix
exponential of twists (no polyscrew in the references); the laws checked are the issue's:
coordinate-free to 1e-9 (denoise(G P H) = G denoise(P) H, automatic strengths included),
a screw motion comes back unchanged to 1e-6, held keys exact, output rigid, bad input a
ValueError that names the argument.
"""

import numpy as np
import polyscrew
import pytest
from scipy.linalg import expm
from scipy.spatial.transform import Rotation

from conftest import random_pose


def flight(times, phase=0.0):
    """A tumbling flight along a curve (the truth), (N, 4, 4)."""
    t = np.asarray(times) / 24.0
    axes = np.stack([np.cos(0.4 * t + phase), np.sin(0.3 * t), np.ones_like(t)], -1)
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    poses = np.zeros((len(t), 4, 4))
    poses[:, :3, :3] = Rotation.from_rotvec(axes * (1.1 * t + phase)[:, None]).as_matrix()
    poses[:, :3, 3] = np.stack([2 * np.cos(0.5 * t), 1.5 * np.sin(0.3 * t + phase), 0.3 * t], -1)
    poses[:, 3, 3] = 1
    return poses


def add_noise(poses, sigma_t, sigma_r, rng):
    out = poses.copy()
    n = len(poses)
    out[:, :3, :3] = Rotation.from_rotvec(rng.normal(0, sigma_r, (n, 3))).as_matrix() @ poses[:, :3, :3]
    out[:, :3, 3] += rng.normal(0, sigma_t, (n, 3))
    return out


def errors(est, truth):
    loc = np.linalg.norm(est[:, :3, 3] - truth[:, :3, 3], axis=1)
    rel = np.einsum("nji,njk->nik", est[:, :3, :3], truth[:, :3, :3])
    ang = np.arccos(np.clip((np.trace(rel, axis1=1, axis2=2) - 1) / 2, -1, 1))
    return np.sqrt(np.mean(loc**2)), np.sqrt(np.mean(ang**2))


@pytest.mark.parametrize("order", [2, 3])
@pytest.mark.parametrize("even", [True, False])
def test_coordinate_free(rng, order, even):
    """denoise(G P H) == G denoise(P) H to 1e-9 at automatic strength, for random rigid G
    (the world) and H (the body frame), one clip and a batch."""
    n = 160
    times = np.arange(n, dtype=float) if even else np.arange(n) + rng.uniform(-0.3, 0.3, n)
    worst = 0.0
    for case in range(6):
        noisy = add_noise(flight(times, case), 0.02, np.radians(0.5), rng)
        g, h = random_pose(rng, scale=10.0), random_pose(rng, scale=2.0)
        a = polyscrew.denoise(noisy, times, order=order)
        b = polyscrew.denoise(g @ noisy @ h, times, order=order)
        diff = np.abs(g @ a.poses @ h - b.poses).max()
        worst = max(worst, diff)
        assert a.rotation_strength == pytest.approx(b.rotation_strength, rel=1e-12)
        assert a.translation_strength == pytest.approx(b.translation_strength, rel=1e-12)
        # The pivot is a body point: H^-1 c.
        c = np.linalg.solve(h, np.r_[a.pivot, 1.0])[:3]
        np.testing.assert_allclose(c, b.pivot, atol=1e-7)
    print(f"order {order}, {'even' if even else 'uneven'} times: largest difference {worst:.2e}")
    assert worst < 1e-9


def twist_motion(times, omega, v, start):
    """exp(t [omega, v]^) start: a screw motion, from scipy's matrix exponential."""
    xi = np.zeros((4, 4))
    xi[:3, :3] = [[0, -omega[2], omega[1]], [omega[2], 0, -omega[0]], [-omega[1], omega[0], 0]]
    xi[:3, 3] = v
    return np.stack([expm(t * xi) @ start for t in times])


@pytest.mark.parametrize("order", [2, 3])
def test_a_screw_motion_comes_back_unchanged(rng, order):
    """Screw motions (general, pure rotation, pure translation) sampled at uneven times come
    back unchanged to 1e-6 at automatic strength."""
    times = np.arange(120) + rng.uniform(-0.3, 0.3, 120)
    worst = 0.0
    for omega, v in [
        (rng.normal(size=3) * 0.1, rng.normal(size=3) * 0.2),
        (np.array([0.0, 0.0, 0.25]), np.array([1.0, -0.5, 0.0])),
        (np.zeros(3), rng.normal(size=3) * 0.3),
    ]:
        poses = twist_motion(times, omega, v, random_pose(rng, scale=3.0))
        d = polyscrew.denoise(poses, times, order=order)
        worst = max(worst, np.abs(d.poses - poses).max())
    print(f"order {order}: largest change of a screw motion {worst:.2e}")
    assert worst < 1e-6


def test_held_keys_are_exact_and_the_output_is_rigid(rng):
    times = np.arange(1, 201, dtype=float)
    noisy = add_noise(flight(times), 0.02, np.radians(0.5), rng)
    held = np.zeros(200, bool)
    held[[0, 37, 38, 120, 199]] = True
    for strength in (None, 5.0, (3.0, 8.0)):
        out = polyscrew.denoise(noisy, times, strength=strength, held=held).poses
        np.testing.assert_array_equal(out[held], noisy[held])
        assert np.all(np.abs(out[~held] - noisy[~held]).max(axis=(1, 2)) > 0)
        r = out[:, :3, :3]
        np.testing.assert_allclose(np.einsum("nji,njk->nik", r, r), np.broadcast_to(np.eye(3), r.shape), atol=1e-12)
        np.testing.assert_allclose(np.linalg.det(r), 1.0, atol=1e-12)
        np.testing.assert_array_equal(out[:, 3], np.broadcast_to([0.0, 0.0, 0.0, 1.0], (200, 4)))


def test_noise_goes_down_and_is_estimated(rng):
    """Against the truth: the error falls well below the noise; the noise reported is the
    noise added; the strengths are reported and a given strength is used as given."""
    times = np.arange(1, 401, dtype=float)
    truth = flight(times, 0.5)
    sigma_t, sigma_r = 0.02, np.radians(0.5)
    noisy = add_noise(truth, sigma_t, sigma_r, rng)
    loc0, rot0 = errors(noisy, truth)
    d = polyscrew.denoise(noisy, times)
    loc, rot = errors(d.poses, truth)
    assert loc < 0.4 * loc0 and rot < 0.4 * rot0, (loc, loc0, rot, rot0)
    assert d.rotation_noise == pytest.approx(sigma_r, rel=0.2)
    assert d.translation_noise == pytest.approx(sigma_t, rel=0.2)
    assert 1.0 < d.rotation_strength < 100 and 1.0 < d.translation_strength < 100
    assert d.converged and d.iterations >= 1
    assert len(d.rotation_kinks) == 0 and len(d.translation_kinks) == 0
    assert "rotation_strength" in repr(d)
    fixed = polyscrew.denoise(noisy, times, strength=(2.5, 7.0))
    assert (fixed.rotation_strength, fixed.translation_strength) == (2.5, 7.0)
    same = polyscrew.denoise(noisy, times, strength=0.0, kinks=False).poses
    np.testing.assert_allclose(same, noisy, atol=1e-14)


def test_a_batch_is_the_clips_one_by_one(rng):
    times = np.arange(100, dtype=float)
    clips = np.stack([add_noise(flight(times, b), 0.02, 0.01, rng) for b in range(4)])
    held = np.zeros((4, 100), bool)
    held[1, 50] = True
    batch = polyscrew.denoise(clips, times, held=held, threads=2)
    assert batch.poses.shape == clips.shape
    assert batch.pivot.shape == (4, 3) and batch.rotation_strength.shape == (4,)
    assert isinstance(batch.rotation_kinks, list) and len(batch.rotation_kinks) == 4
    for b in range(4):
        one = polyscrew.denoise(clips[b], times, held=held[b])
        np.testing.assert_array_equal(batch.poses[b], one.poses)
        assert batch.rotation_strength[b] == one.rotation_strength
    # One (N,) mask holds the same keys in every clip.
    shared = polyscrew.denoise(clips, times, held=held[1])
    np.testing.assert_array_equal(shared.poses[:, 50], clips[:, 50])


def test_a_hard_stop_stays_sharp(rng):
    times = np.arange(200, dtype=float)
    s = np.minimum(times, 100.0)
    truth = np.zeros((200, 4, 4))
    truth[:, :3, :3] = Rotation.from_rotvec(np.outer(0.05 * s, [0, 1, 0])).as_matrix()
    truth[:, :3, 3] = np.stack([0.1 * s, 0 * s, 1 + 0 * s], -1)
    truth[:, 3, 3] = 1
    noisy = add_noise(truth, 0.01, 0.005, rng)
    sharp = polyscrew.denoise(noisy, times)
    round_ = polyscrew.denoise(noisy, times, kinks=False)
    assert list(sharp.translation_kinks) == [100] and list(sharp.rotation_kinks) == [100]
    at_stop = lambda d: np.linalg.norm(d.poses[100, :3, 3] - truth[100, :3, 3])  # noqa: E731
    assert at_stop(sharp) < 0.5 * at_stop(round_)


POSE = np.eye(4)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(poses=np.zeros((10, 3, 3))), "poses: expected shape"),
        (dict(poses=np.broadcast_to(POSE, (3, 4, 4))), "at least 4 needed"),
        (dict(times=np.arange(9.0)), "times: expected 10 entries, got 9"),
        (dict(times=np.r_[0.0, 1, 2, 2, 4, 5, 6, 7, 8, 9]), "key time 3"),
        (dict(times=np.r_[0.0, 1, 2, np.nan, 4, 5, 6, 7, 8, 9]), "key time 3"),
        (dict(held=np.zeros(9, bool)), "held: expected a boolean mask"),
        (dict(strength=-1.0), "strength: -1 is not a finite time"),
        (dict(strength=(1.0, np.inf)), "strength: inf"),
        (dict(strength="auto"), "strength: expected None"),
        (dict(order=4), "order 4 out of range 2..=3"),
    ],
)
def test_bad_input_raises(kwargs, message):
    args = dict(poses=np.broadcast_to(POSE, (10, 4, 4)).copy(), times=np.arange(10.0))
    args.update(kwargs)
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        polyscrew.denoise(**args)


def test_bad_poses_are_named():
    times = np.arange(10.0)
    poses = np.broadcast_to(POSE, (10, 4, 4)).copy()
    poses[6, 0, 0] = 1.5
    with pytest.raises(ValueError, match="denoise: pose 6: not rigid: scale"):
        polyscrew.denoise(poses, times)
    poses[6, 0, 0] = np.nan
    with pytest.raises(ValueError, match="pose 6: contains NaN"):
        polyscrew.denoise(poses, times)
    batch = np.broadcast_to(POSE, (3, 10, 4, 4)).copy()
    batch[2, 4, 1, 1] = -1.0
    with pytest.raises(ValueError, match="body 2: pose 4"):
        polyscrew.denoise(batch, times)
    huge = np.broadcast_to(POSE, (10, 4, 4)).copy()
    huge[:, :3, 3] = np.arange(10)[:, None] ** 3 * 1e300
    with pytest.raises(ValueError, match="overflow|too large|outside the working range"):
        polyscrew.denoise(huge, times)


def test_huge_sizes_are_refused_before_allocating():
    """A view of one pose repeated beyond the limits (or the memory budget, which the default
    reaches first) is refused from its shape alone."""
    many = np.broadcast_to(POSE, (1_000_001, 4, 4))
    with pytest.raises(ValueError, match="exceed the limits|over the memory budget"):
        polyscrew.denoise(many, np.arange(1_000_001.0))
    rig = np.broadcast_to(POSE, (30, 1_000_000, 4, 4))
    with pytest.raises(ValueError, match="exceed the limits|over the memory budget"):
        polyscrew.denoise(rig, np.arange(1_000_000.0))
