"""Every bad input raises ValueError naming the offending index and the reason."""

import numpy as np
import polyscrew
import pytest


def keys(n=4):
    out = np.stack([np.eye(4)] * n)
    out[:, 0, 3] = np.arange(n)
    return out


def corrupt(index, edit):
    k = keys()
    edit(k[index])
    return k


BAD_POSES = {
    "scale": (lambda m: m.__setitem__((0, 0), 1.0 + 2e-6), r"pose 2: not rigid: scale"),
    "shear": (lambda m: m.__setitem__((0, 1), 0.01), r"pose 2: not rigid: (shear|scale)"),
    "mirror": (lambda m: m.__setitem__((2, 2), -1.0), r"pose 2: not rigid: mirror"),
    "nan": (lambda m: m.__setitem__((1, 3), np.nan), r"pose 2: contains NaN or infinity"),
    "inf": (lambda m: m.__setitem__((0, 0), np.inf), r"pose 2: contains NaN or infinity"),
    "not affine": (lambda m: m.__setitem__((3, 0), 0.5), r"pose 2: bottom row"),
}


@pytest.mark.parametrize("name", BAD_POSES)
@pytest.mark.parametrize("function", ["subdivide", "sample", "sample_channels"])
def test_bad_pose_is_named(name, function):
    edit, message = BAD_POSES[name]
    bad = corrupt(2, edit)
    with pytest.raises(ValueError, match=message):
        if function == "subdivide":
            polyscrew.subdivide(bad)
        elif function == "sample_channels":
            polyscrew.sample_channels(bad, [0.0, 1.0, 2.0, 3.0], [0.5], "XYZ")
        else:
            polyscrew.sample(bad, [0.0, 1.0, 2.0, 3.0], [0.5])


def test_within_tolerance_is_accepted():
    k = keys()
    k[1, 0, 0] = 1.0 + 5e-7  # Blender's f32 matrices are this close to rigid
    assert polyscrew.subdivide(k, levels=1).shape == (7, 4, 4)


@pytest.mark.parametrize("shape", [(4, 3), (3, 4, 3), (2, 2, 4, 4), (16,)])
def test_wrong_shape(shape):
    with pytest.raises(ValueError, match="expected shape"):
        polyscrew.subdivide(np.zeros(shape))


def test_screw_and_interpolate_check_their_poses():
    bad = np.eye(4)
    bad[0, 0] = 2.0
    with pytest.raises(ValueError, match="screw: b: not rigid: scale"):
        polyscrew.screw(np.eye(4), bad)
    with pytest.raises(ValueError, match="expected shape"):
        polyscrew.screw(np.eye(3), np.eye(4))
    with pytest.raises(ValueError, match="t 1 is NaN"):
        polyscrew.interpolate(np.eye(4), np.eye(4), [0.0, np.nan])


@pytest.mark.parametrize("closed", [False, True])
def test_too_few_poses(closed):
    with pytest.raises(ValueError, match="1 poses given, at least 2 needed"):
        polyscrew.subdivide(keys(1), closed=closed)
    with pytest.raises(ValueError, match="at least 2 needed"):
        polyscrew.sample(keys(1), [0.0], [0.0], closed=closed)


@pytest.mark.parametrize("levels", [-1, 13, 100])
def test_levels_out_of_range(levels):
    with pytest.raises(ValueError, match=f"levels {levels} out of range 0..=12"):
        polyscrew.subdivide(keys(), levels=levels)


@pytest.mark.parametrize("times, index", [([0.0, 1.0, 1.0, 2.0], 2), ([0.0, 2.0, 1.0, 3.0], 2), ([0.0, np.nan, 2.0, 3.0], 1)])
def test_key_times_not_strictly_increasing(times, index):
    with pytest.raises(ValueError, match=f"key time {index} is not finite or not greater"):
        polyscrew.sample(keys(), times, [0.5])


def test_other_arguments():
    with pytest.raises(ValueError, match="expected 4 entries, got 3"):
        polyscrew.sample(keys(), [0.0, 1.0, 2.0], [0.5])
    with pytest.raises(ValueError, match="time 1 is NaN"):
        polyscrew.sample(keys(), [0.0, 1.0, 2.0, 3.0], [0.5, np.nan])
    with pytest.raises(ValueError, match="period 2 must"):
        polyscrew.sample(keys(), [0.0, 1.0, 2.0, 3.0], [0.5], closed=True, period=2.0)
    with pytest.raises(ValueError, match='scheme: "catmull" is not one of'):
        polyscrew.subdivide(keys(), scheme="catmull")
    with pytest.raises(ValueError, match='timing: "cubic" is not one of'):
        polyscrew.sample(keys(), [0.0, 1.0, 2.0, 3.0], [0.5], timing="cubic")
    with pytest.raises(ValueError, match="vector 1 is NaN"):
        polyscrew.subdivide_vectors([[0, 0, 0], [np.nan, 0, 0]])
    with pytest.raises(ValueError, match="rotation mode"):
        polyscrew.rotation_channels(np.eye(3)[None], "QUAT")
    with pytest.raises(ValueError, match="sample_channels: rotation mode"):
        polyscrew.sample_channels(keys(), [0.0, 1.0, 2.0, 3.0], [0.5], "QUAT")
    with pytest.raises(ValueError, match="sample_channels: previous: expected 3 entries, got 4"):
        polyscrew.sample_channels(keys(), [0.0, 1.0, 2.0, 3.0], [0.5], "XYZ", [1.0, 0.0, 0.0, 0.0])
