"""Remove Noise batched over owners (issue 27): what the add-on's one-call-for-all relies on.

`blender/denoise.py` writes the rotation channels of every owner of one rotation mode with one
`polyscrew.rotation_channels_near` call on all their poses and references stacked, and smooths
owners keyed on the same frames with one `polyscrew.denoise` call. Both must give, bit for
bit, what one call per owner gives (the keys written are then those of a run per owner).
"""

from __future__ import annotations

import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

TAU = 2.0 * np.pi


def owners_poses(rng: np.random.Generator, sizes: list[int]) -> list[np.ndarray]:
    """Rigid (n, 4, 4) poses per owner: a slow turn and path with a little noise each."""
    out = []
    for n in sizes:
        t = np.arange(n, dtype=float)
        rotvec = np.stack([0.4 * np.sin(t / 25.0), 0.01 * t, 0.08 * t], axis=1) + rng.normal(0, 0.01, (n, 3))
        m = np.zeros((n, 4, 4))
        m[:, :3, :3] = Rotation.from_rotvec(rotvec).as_matrix()
        m[:, :3, 3] = np.stack([np.sin(t / 20.0), np.cos(t / 30.0), t / 100.0], axis=1) + rng.normal(0, 0.01, (n, 3))
        m[:, 3, 3] = 1.0
        out.append(m)
    return out


@pytest.mark.parametrize("mode", list(polyscrew.ROTATION_MODES))
def test_rotation_channels_near_of_owners_stacked_is_each_owners(mode):
    """One call on the stacked poses and references of five owners of different lengths equals
    the five calls, bit for bit (every row is written like its own reference only)."""
    rng = np.random.default_rng(27)
    poses = owners_poses(rng, [4, 60, 1, 250, 33])
    references = []
    for p in poses:  # the animator's keys: the rotation's channels with spins and sign flips
        own = polyscrew.rotation_channels(p, mode)
        if mode == "QUATERNION":
            own[::4] *= -1.0
        else:
            angles = slice(0, 1) if mode == "AXIS_ANGLE" else slice(0, 3)
            own[:, angles] += TAU * rng.integers(-2, 3, size=(len(own), angles.stop))
        references.append(own + 0.05 * rng.normal(size=own.shape))
    stacked = polyscrew.rotation_channels_near(np.concatenate(poses), mode, np.concatenate(references))
    bounds = np.cumsum([0] + [len(p) for p in poses])
    for k, (p, ref) in enumerate(zip(poses, references)):
        alone = polyscrew.rotation_channels_near(p, mode, ref)
        np.testing.assert_array_equal(stacked[bounds[k] : bounds[k + 1]], alone, err_msg=f"owner {k}, {mode}")
        # and the channels are the owner's rotations, near their references
        assert np.abs(polyscrew.rotation_matrices(alone, mode) - p[:, :3, :3]).max() < 1e-12
    print(f"rotation_channels_near {mode}: {len(stacked)} rows stacked = 5 calls, bit for bit")


def test_denoise_of_owners_batched_is_each_owners_with_held_keys():
    """Owners keyed on the same frames with the same held keys go into one `polyscrew.denoise`
    call: each body's poses, strengths, noise and pivot are its call's alone, bit for bit."""
    rng = np.random.default_rng(5)
    poses = owners_poses(rng, [120] * 4)
    times = np.arange(1.0, 121.0)
    held = np.zeros(120, dtype=bool)
    held[[0, 40, 41, 90]] = True
    batch = polyscrew.denoise(np.stack(poses), times, held=held)
    for b, p in enumerate(poses):
        alone = polyscrew.denoise(p, times, held=held)
        np.testing.assert_array_equal(batch.poses[b], alone.poses)
        np.testing.assert_array_equal(batch.poses[b][held], p[held])  # held keys exactly
        assert batch.rotation_strength[b] == alone.rotation_strength
        assert batch.translation_strength[b] == alone.translation_strength
        assert batch.rotation_noise[b] == alone.rotation_noise
        np.testing.assert_array_equal(batch.pivot[b], alone.pivot)
