"""`polyscrew.rotation_channels_each` (issue 27: Insert Key converts every owner's new rotation
in one call per rotation mode): row i is, byte for byte, `rotation_channels(rotations[i:i + 1],
mode, previous=previous[i])`, on random rotations (matrices and poses, some of them turned
a whole or half turn away from the previous values) in all 8 modes; and what it refuses it
refuses naming the argument."""

from __future__ import annotations

import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

from test_intent import MODES, width


def previous_values(rng, rotations: np.ndarray, mode: str) -> np.ndarray:
    """Plausible current channel values: the rotations' own channels (quaternion sign or
    Euler/axis-angle turns shifted at random) plus noise, or random values far away."""
    n, w = len(rotations), width(mode)
    near = polyscrew.rotation_channels_near(rotations, mode, np.zeros((n, w)) + (1.0 if mode == "QUATERNION" else 0.0))
    turns = rng.integers(-3, 4, size=(n, w)) * 2 * np.pi
    if mode == "QUATERNION":
        near = near * rng.choice([-1.0, 1.0], size=(n, 1))
    elif mode == "AXIS_ANGLE":
        near[:, 0] += turns[:, 0]
    else:
        near += turns
    out = near + rng.normal(scale=0.3, size=(n, w))
    far = rng.random(n) < 0.3
    out[far] = rng.uniform(-20, 20, size=(int(far.sum()), w))
    return out


@pytest.mark.parametrize("mode", MODES)
def test_each_row_is_one_rotation_channels_call(rng, mode):
    assert len(MODES) == 8
    for n in (0, 1, 2, 37, 200):
        matrices = Rotation.random(n, random_state=rng).as_matrix() if n else np.zeros((0, 3, 3))
        poses = np.tile(np.eye(4), (n, 1, 1))
        poses[:, :3, :3] = matrices
        poses[:, :3, 3] = rng.normal(size=(n, 3))
        if n > 2:  # the identity, a half turn: no axis, or two equal representatives
            poses[0, :3, :3] = np.eye(3)
            poses[1, :3, :3] = np.diag([1.0, -1.0, -1.0])
        previous = previous_values(rng, poses, mode) if n else np.zeros((0, width(mode)))
        for rotations in (poses, poses[:, :3, :3].copy()):
            got = polyscrew.rotation_channels_each(rotations, mode, previous)
            assert got.shape == (n, width(mode)) and got.dtype == np.float64
            want = [polyscrew.rotation_channels(rotations[i : i + 1], mode, previous=previous[i])[0] for i in range(n)]
            assert got.tobytes() == np.array(want, dtype=np.float64).reshape(n, width(mode)).tobytes(), (mode, n)


def test_refusals_name_the_argument():
    poses = np.tile(np.eye(4), (3, 1, 1))
    with pytest.raises(ValueError, match=r"rotation_channels_each.*previous.*\(3, 3\)"):
        polyscrew.rotation_channels_each(poses, "XYZ", np.zeros((3, 4)))
    with pytest.raises(ValueError, match=r"rotation_channels_each.*previous"):
        polyscrew.rotation_channels_each(poses, "XYZ", np.full((3, 3), np.nan))
    with pytest.raises(ValueError, match=r"rotation_channels_each.*previous"):
        polyscrew.rotation_channels_each(poses, "QUATERNION", np.array([[1, 0, 0, 0], [1, 0, 0, 0], [1, 0, 0, np.inf]]))
    with pytest.raises(ValueError, match=r"rotation_channels_each.*previous"):
        polyscrew.rotation_channels_each(poses, "AXIS_ANGLE", np.array([[0, 0, 1, 0]] * 2 + [[2e9, 0, 1, 0]]))
    with pytest.raises(ValueError, match="rotation_channels_each"):
        polyscrew.rotation_channels_each(poses, "NOPE", np.zeros((3, 3)))
    with pytest.raises(ValueError, match=r"rotation_channels_each.*rotations"):
        polyscrew.rotation_channels_each(np.zeros((3, 2, 2)), "XYZ", np.zeros((3, 3)))
