"""Extreme but legitimate input is computed, finite and exact (issues 15 and 28): one time
sampled from 100,000 keys at 12 levels in bounded memory, key times 1e-170 apart,
translations at the edge of the coordinate range, the pure translation of a rotated pose,
`previous` angles (beyond the range refused; within it, channels correct and continued), and
`denoise` of zero bodies. Extremes of `denoise` are in `test_denoise_extremes.py`.
"""

from __future__ import annotations

import numpy as np
import polyscrew
import pytest

from capped import run_capped


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
