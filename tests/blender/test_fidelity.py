"""Screw fidelity: keys on a circle or a helix bake into a motion that stays on it, where
Blender's own Bezier interpolation of the same keys leaves it."""

from __future__ import annotations

import bpy
import numpy as np
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h

#: Baked channels are float32; the screw is reproduced up to that.
ON_SCREW_TOLERANCE = 1e-6

TILT = Rotation.from_euler("xyz", [[0.4, -0.3, 0.2]]).as_matrix()[0]


@pytest.mark.parametrize(
    "name, mode, radius, pitch, thetas, frames",
    [
        # uneven angles at uneven frames; the Euler circle stays within (-pi, pi), where the
        # float32 storage of the key and baked angles costs at most ~2e-7
        ("circle", "XYZ", 2.0, 0.0, [-2.4, -1.9, -0.8, -0.2, 1.5, 2.6], [1, 5, 16, 20, 37, 45]),
        ("helix", "QUATERNION", 1.5, 0.25, [0.0, 0.9, 1.5, 3.0, 4.4, 6.0, 8.5], [1, 8, 12, 26, 35, 47, 60]),
    ],
)
@pytest.mark.parametrize("scheme", ["four_point", "bspline", "jarek"])
def test_keys_on_a_screw_stay_on_it(sb, name, mode, radius, pitch, thetas, frames, scheme):
    obj = h.new_object(name, "MESH", mode)
    keys = h.circle_poses(np.array(thetas), radius, pitch, TILT)
    h.key_poses(obj, frames, keys)
    assert h.screw_deviation(keys, radius, pitch, TILT).max() < 1e-12
    stored = sb.keys.read(obj).poses  # the keys as Blender stores them (float32)
    stored_error = h.screw_deviation(stored, radius, pitch, TILT).max()

    dense = np.arange(frames[0], frames[-1] + 0.25, 0.25)
    blender = h.screw_deviation(h.evaluated_basis(obj, dense), radius, pitch, TILT).max()

    assert bpy.ops.screwbender.smooth(scheme=scheme, levels=5, step=0.25) == {"FINISHED"}
    baked_frames, baked = h.baked_matrices(obj)
    np.testing.assert_allclose(baked_frames, dense)
    ours = h.screw_deviation(baked, radius, pitch, TILT).max()
    print(
        f"\n{bpy.app.version_string} {name} ({mode}, {scheme}): max distance from the {name} over "
        f"{len(dense)} frames: ScrewBender {ours:.1e}, Blender Bezier {blender:.1e} "
        f"(stored keys {stored_error:.1e})"
    )
    assert ours < ON_SCREW_TOLERANCE
    assert blender > 1e-3, "Blender's interpolation was expected to leave the screw"
    # the baked motion keeps moving along the screw (not parked on a key)
    relative = baked[:, :3, :3] @ TILT.T
    angle = np.unwrap(np.arctan2(relative[:, 1, 0], relative[:, 0, 0]))
    assert angle[0] == pytest.approx(thetas[0], abs=1e-6) and angle[-1] == pytest.approx(thetas[-1], abs=1e-5)
