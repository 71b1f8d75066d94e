"""polyscrew's batch functions for Remove Noise and Reduce Keys (issue 27): `angles_near_many`,
`partial_moves_many`, `sample_many` and `channels_many` are, to the bit, the single-owner
function (`angles_near`, `partial_moves`, `sample`, `Playback.channels`) called on each part
in turn, on random parts of random sizes (empty parts too) in every rotation mode; and
what they refuse they refuse naming the argument and the part."""

from __future__ import annotations

import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

from test_intent import MODES, playback, random_curves, rotation_path, width


def random_poses(rng, n: int) -> np.ndarray:
    out = np.tile(np.eye(4), (n, 1, 1))
    out[:, :3, :3] = Rotation.random(n, random_state=rng).as_matrix()
    out[:, :3, 3] = rng.normal(size=(n, 3))
    return out


def test_angles_near_many_is_angles_near_per_part(rng):
    for _ in range(20):
        parts = int(rng.integers(1, 9))
        modes = [MODES[int(i)] for i in rng.integers(0, len(MODES), parts)]
        channels = np.array([int(rng.integers(0, width(m))) for m in modes])
        counts = rng.integers(0, 12, parts)
        n = int(counts.sum())
        values, reference = rng.uniform(-40, 40, n), rng.uniform(-7, 7, n)
        got = polyscrew.angles_near_many(values, reference, modes, channels, counts)
        bounds = np.cumsum([0, *counts])
        want = [polyscrew.angles_near(values[lo:hi], reference[lo:hi], m, int(c))
                for m, c, lo, hi in zip(modes, channels, bounds[:-1], bounds[1:])]
        assert np.array_equal(got, np.concatenate([np.zeros(0), *want])), (modes, channels, counts)
    with pytest.raises(ValueError, match="angles_near_many.*counts"):
        polyscrew.angles_near_many(np.zeros(3), np.zeros(3), ["XYZ"], [0], [2])
    with pytest.raises(ValueError, match="angles_near_many.*part 1"):
        polyscrew.angles_near_many(np.zeros(3), np.zeros(3), ["XYZ", "XYZ"], [0, 3], [1, 2])
    with pytest.raises(ValueError, match="angles_near_many: modes"):
        polyscrew.angles_near_many(np.zeros(3), np.zeros(3), ["XYZ", "TWIST"], [0, 0], [1, 2])
    with pytest.raises(ValueError, match="angles_near_many"):
        polyscrew.angles_near_many(np.zeros(3), np.zeros(2), ["XYZ"], [0], [3])


def test_partial_moves_many_is_partial_moves_per_part(rng):
    parts = 7
    counts = rng.integers(0, 10, parts)
    n = int(counts.sum())
    source, target = random_poses(rng, n), random_poses(rng, n)
    pivots = rng.normal(size=(parts, 3))
    angles = rng.uniform(0, 2, parts)
    distances = np.where(rng.random(parts) < 0.3, np.inf, rng.uniform(0, 2, parts))
    poses, cut = polyscrew.partial_moves_many(source, target, counts, pivots, angles, distances)
    bounds = np.cumsum([0, *counts])
    for i, (lo, hi) in enumerate(zip(bounds[:-1], bounds[1:])):
        want, want_cut = polyscrew.partial_moves(source[lo:hi], target[lo:hi], pivots[i], angles[i], distances[i])
        assert np.array_equal(poses[lo:hi], want) and np.array_equal(cut[lo:hi], want_cut), i
    assert cut.any() and not cut.all()
    with pytest.raises(ValueError, match="partial_moves_many.*part 2"):
        polyscrew.partial_moves_many(source[:3], target[:3], [1, 1, 1], np.zeros((3, 3)), [1, 1, -1], [1, 1, 1])
    with pytest.raises(ValueError, match="partial_moves_many: pivots"):
        polyscrew.partial_moves_many(source[:3], target[:3], [1, 2], np.zeros((3, 3)), [1, 1], [1, 1])


def test_sample_many_is_sample_per_owner(rng):
    key_times = np.cumsum(rng.uniform(0.5, 2.0, 9))
    times = np.sort(rng.uniform(key_times[0] - 1, key_times[-1] + 1, 40))
    keys = random_poses(rng, 5 * 9)
    for levels, timing in ((0, "linear"), (3, "smooth")):
        got = polyscrew.sample_many(keys, key_times, times, levels=levels, timing=timing)
        for i in range(5):
            want = polyscrew.sample(keys[9 * i:9 * (i + 1)], key_times, times, levels=levels, timing=timing)
            assert np.array_equal(got[40 * i:40 * (i + 1)], want), (i, levels, timing)
    with pytest.raises(ValueError, match="sample_many: poses"):
        polyscrew.sample_many(keys[:10], key_times, times)
    bad = keys.copy()
    bad[12, 0, 0] = np.nan
    with pytest.raises(ValueError, match="sample_many.*pose 12"):
        polyscrew.sample_many(bad, key_times, times)


def test_channels_many_is_channels_per_playback(rng):
    frames = np.array([1.0, 7.0, 12.5, 30.0])
    playbacks = []
    for mode in MODES:
        columns = [("location", 2), (rotation_path(mode), 1), ("scale", 0)]
        playbacks.append(playback(random_curves(rng, frames, 3), columns, mode, rng.normal(size=6 + width(mode))))
    t = np.linspace(-5, 40, 101)
    got = polyscrew.channels_many(playbacks, t)
    assert len(got) == len(playbacks)
    for pb, arrays in zip(playbacks, got):
        for a, b in zip(arrays, pb.channels(t)):
            assert a.shape == b.shape and np.array_equal(a, b)
    assert polyscrew.channels_many([], t) == []
    with pytest.raises(TypeError, match="channels_many: playbacks"):
        polyscrew.channels_many([playbacks[0], "not one"], t)
    with pytest.raises(ValueError, match="channels_many"):
        polyscrew.channels_many(playbacks, np.array([1.0, np.nan]))
