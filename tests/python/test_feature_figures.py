"""The figures the README quotes for feature-point motion design (Hofer, Pottmann, Ravani, *From
curve design algorithms to the design of rigid body motions*), measured and bounded here: run
with `pytest -s` to print them (formerly the one-off scripts/feature_figures.py).

- Registration (section 2) on 500 random clouds of 3 to 49 points: noise-free, the true pose;
  noisy and weighted, scipy's `Rotation.align_vectors` on the centred clouds (independent).
- 6 closed keys at 7 levels (768 poses, the paper's Table 1 case): rigid, and independent of
  the world frame (A keys -> A motion).
- The paper's figure 9 check on a body point's path: its second differences times 4**level
  settle for the C2 variational scheme and keep growing for the C1 four-point scheme.
"""

from __future__ import annotations

import numpy as np
import polyscrew
from scipy.spatial.transform import Rotation

from test_feature import scipy_registration  # the independent oracle of the feature tests


def random_pose(rng: np.random.Generator, scale: float) -> np.ndarray:
    pose = np.eye(4)
    pose[:3, :3] = Rotation.from_rotvec(rng.normal(size=3)).as_matrix()
    pose[:3, 3] = rng.uniform(-scale, scale, 3)
    return pose


def test_readme_figures_of_feature_point_design():
    rng = np.random.default_rng(1)
    exact = against_scipy = 0.0
    for _ in range(500):
        truth = random_pose(rng, 5.0)
        k = int(rng.integers(3, 50))
        src = rng.uniform(-1, 1, (k, 3))
        dst = src @ truth[:3, :3].T + truth[:3, 3]
        exact = max(exact, np.abs(polyscrew.register_points(src, dst) - truth).max())
        noisy = dst + rng.normal(scale=0.05, size=dst.shape)
        w = rng.uniform(0.1, 2.0, k)
        got = polyscrew.register_points(src, noisy, w)
        against_scipy = max(against_scipy, np.abs(got - scipy_registration(src, noisy, w)).max())
    print("\nregistration, 500 random clouds of 3-49 points:")
    print(f"  noise-free, largest matrix error vs the true pose: {exact:.1e}")
    print(f"  noisy and weighted, largest difference from scipy align_vectors: {against_scipy:.1e}")

    keys = np.stack([random_pose(rng, 3.0) for _ in range(6)])
    dense = polyscrew.feature_motion(keys, levels=7, closed=True)
    r = dense[:, :3, :3]
    rigid = max(np.abs(np.swapaxes(r, 1, 2) @ r - np.eye(3)).max(), np.abs(np.linalg.det(r) - 1).max())
    a = random_pose(rng, 20.0)
    invariance = np.abs(polyscrew.feature_motion(a @ keys, levels=7, closed=True) - a @ dense).max()
    print(f"6 closed keys, 7 levels: {len(dense)} poses; rigid to {rigid:.1e}; "
          f"world-frame invariance (A keys -> A motion) to {invariance:.1e}")

    print("figure 9 check, a body point's path: max |second difference * 4**level| and its "
          "largest change from the previous level")
    pose = np.eye(4)
    walk = []
    for _ in range(5):
        pose = random_pose(rng, 2.0) @ pose
        walk.append(pose)
    walk = np.array(walk)
    point = np.array([0.7, -0.4, 1.2, 1.0])
    largest, changes = {}, {}
    for scheme in ("variational", "four_point"):
        previous, rows = None, []
        largest[scheme], changes[scheme] = [], []
        for levels in range(3, 10):
            path = (polyscrew.feature_motion(walk, scheme=scheme, levels=levels) @ point)[:, :3]
            d2 = (path[:-2] - 2 * path[1:-1] + path[2:]) * 4.0**levels
            largest[scheme].append(np.abs(d2).max())
            if previous is not None:
                changes[scheme].append(np.abs(previous - d2[1::2]).max())
            rows.append(f"L{levels} {largest[scheme][-1]:.2f} ({f'{changes[scheme][-1]:.3f}' if previous is not None else '-'})")
            previous = d2
        print(f"  {scheme:12s} " + ", ".join(rows))

    assert len(dense) == 768
    assert exact < 1e-13 and against_scipy < 1e-13, (exact, against_scipy)
    assert rigid < 1e-13 and invariance < 1e-12, (rigid, invariance)
    # C2: the scaled second differences converge (each change at most 3/4 of the one before).
    var = np.array(changes["variational"])
    assert (var[1:] < 0.75 * var[:-1]).all() and var[-1] < 0.25, var
    # C1 only: they keep growing, by about the same amount at every level.
    four = np.diff(largest["four_point"])
    assert (four > 3.0).all(), four
