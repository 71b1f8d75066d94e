"""The polyscrew module inside Blender's own Python: same process as bpy, Blender's numpy."""

import bpy
import numpy as np
import polyscrew


def test_polyscrew_runs_next_to_bpy_with_blenders_numpy():
    # bpy wheels ship numpy 1.26; the module is built against the stable ABI and must work
    # with it as it does with numpy 2 in tests/python.
    assert bpy.app.version >= (4, 2, 0)
    keys = np.stack([np.eye(4)] * 3)
    keys[1, :3, 3] = (1.0, 0.0, 0.0)
    keys[2, :3, 3] = (1.0, 1.0, 0.0)
    out = polyscrew.sample(keys, [1.0, 10.0, 20.0], np.arange(1.0, 21.0), scheme="four_point")
    assert out.shape == (20, 4, 4)
    np.testing.assert_allclose(out[0], keys[0], atol=1e-15)
    np.testing.assert_allclose(out[-1], keys[2], atol=1e-15)
    print(f"bpy {bpy.app.version_string} numpy {np.__version__}")
