"""Shared helpers for the polyscrew tests: random rigid poses and an independent screw."""

import sys
from pathlib import Path

import numpy as np
import pytest
from pytransform3d import rotations as pr
from pytransform3d import transformations as pt

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "fixtures"))  # helpers shared with tests/blender


def rigid(axis, angle, translation):
    """A (4, 4) rigid pose from an axis-angle rotation and a translation."""
    axis = np.asarray(axis, float)
    pose = np.eye(4)
    pose[:3, :3] = pr.matrix_from_axis_angle(np.r_[axis / np.linalg.norm(axis), angle])
    pose[:3, 3] = translation
    return pose


def random_pose(rng, max_angle=np.pi, scale=1.0):
    axis = rng.normal(size=3)
    return rigid(axis, rng.uniform(0.0, max_angle), rng.uniform(-scale, scale, 3))


def reference_s(a, t, b):
    """Independent s(a, t, b): pytransform3d's screw linear interpolation."""
    return pt.transform_sclerp(a, b, t)


@pytest.fixture
def rng():
    return np.random.default_rng(20261122)
