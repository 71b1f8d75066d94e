"""Every bad input is a clear error that names it: ValueError naming the offending index and
the reason; wrong types a TypeError naming the function and the argument; arrays read without
silent casts (codes, complex numbers); any exception raised while an argument is read comes
out named (issues 15 and 28). Huge input: `test_bad_input_memory.py`; extreme but legitimate
input: `test_bad_input_extremes.py`."""

import numpy as np
import polyscrew
import pytest

from fcurve_args import curve


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

# --- Every argument is read by name: wrong types, casts, and errors raised while reading -------
# (moved here from test_hardening.py, test_hardening_round2.py and test_argument_reading.py)


TYPE_ERRORS = [
    (lambda: polyscrew.subdivide(np.tile(np.eye(4), (2, 1, 1)), levels=2.5), TypeError, r"subdivide: levels: expected an int, got float"),
    (lambda: polyscrew.subdivide(np.tile(np.eye(4), (2, 1, 1)), scheme=5), TypeError, r"subdivide: scheme: expected a str, got int"),
    (lambda: polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0, 1], [0.5], closed="yes"), TypeError, r"sample: closed: expected a bool, got str"),
    (lambda: polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0, 1], [0.5], period="x"), TypeError, r"sample: period: expected a real number, got str"),
    (lambda: polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0, 1], [0.5], closed=True, period=2**2000), ValueError, r"sample: period: 1\d+ is too large for a float"),
    (lambda: polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), "ab", [0.5]), TypeError, r"sample: key_times: expected real numbers, got <U2"),
    (lambda: polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0, 1], [[0.5], [1, 2]]), ValueError, r"sample: times: .*inhomogeneous"),
    (lambda: polyscrew.sample_channels(np.tile(np.eye(4), (2, 1, 1)), [0, 1], [0.5], 3), TypeError, r"sample_channels: mode: expected a str, got int"),
    (lambda: polyscrew.interpolate(np.eye(4), np.eye(4), 1j), TypeError, r"interpolate: t: expected real numbers, got complex128"),
    (lambda: polyscrew.interpolate(np.eye(4), np.eye(4), 2**2000), ValueError, r"interpolate: t: 1\d+ is too large for a float"),
    (lambda: polyscrew.interpolate(np.eye(4), np.eye(3), 0.5), ValueError, r"interpolate: b: expected shape \(4, 4\) or \(N, 4, 4\)"),
    (lambda: polyscrew.interpolate(np.diag([2.0, 1, 1, 1]), np.eye(4), 0.5), ValueError, r"interpolate: a: not rigid: scale"),
    (lambda: polyscrew.screw([[None] * 4] * 4, np.eye(4)), TypeError, r"screw: a: expected real numbers, got object"),
    (lambda: polyscrew.sweep(np.eye(3), [[0, 1, 2]], np.tile(np.eye(4), (2, 1, 1)), steps=8.0), TypeError, r"sweep: steps: expected an int, got float"),
    (lambda: polyscrew.sweep(np.eye(3), [["a", "b", "c"]], np.tile(np.eye(4), (2, 1, 1))), TypeError, r"sweep: triangles: expected integers, got <U1"),
    (lambda: polyscrew.fit_angular_velocity([[1.0, 0, 0, 0]] * 2, [0.0, 1], [0.0, 1], np.zeros((2, 3)), alpha="x"), TypeError, r"fit_angular_velocity: alpha: expected a real number, got str"),
    (lambda: polyscrew.fit_angular_velocity([[1.0, 0, 0, 0]] * 2, [0.0, 1], [0.0, 1], np.zeros((2, 3)), max_frames=2**70), ValueError, r"fit_angular_velocity: max_frames 1180591620717411303424 out of range 0\.\.=1000000"),
    (lambda: polyscrew.feature_motion(np.tile(np.eye(4), (3, 1, 1)), stiffness="x"), TypeError, r"feature_motion: stiffness: expected real numbers, got <U1"),
    (lambda: polyscrew.feature_motion(np.tile(np.eye(4), (3, 1, 1)), parametrization=None), TypeError, r"feature_motion: parametrization: expected a str, got NoneType"),
    (lambda: polyscrew.register_points(np.eye(3) + 0j, np.eye(3)), TypeError, r"register_points: src: expected real numbers, got complex128"),
    (lambda: polyscrew.set_memory_budget(-1), ValueError, r"set_memory_budget: bytes -1 out of range"),
]


@pytest.mark.parametrize("call, error, message", TYPE_ERRORS, ids=[t[2][:48] for t in TYPE_ERRORS])
def test_errors_name_the_function_and_the_argument(call, error, message):
    with pytest.raises(error, match=message):
        call()


def test_whole_float_triangle_indices_are_accepted():
    v = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    t = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]]
    poses = np.tile(np.eye(4), (2, 1, 1))
    poses[1, 0, 3] = 1.0
    a = polyscrew.sweep(v, np.array(t, float), poses)
    b = polyscrew.sweep(v, t, poses)
    assert np.array_equal(a[0], b[0]) and np.array_equal(a[1], b[1])


class Raises:
    """An array-like whose conversion raises `error`."""

    def __init__(self, error: BaseException):
        self.error = error

    def __array__(self, *args, **kwargs):
        raise self.error


@pytest.mark.parametrize(
    "error, expected",
    [
        (RuntimeError("boom"), ValueError),
        (KeyError("k"), ValueError),
        (MemoryError("no room"), MemoryError),
        (TypeError("not here"), TypeError),
        (ValueError("bad"), ValueError),
    ],
)
def test_any_exception_while_reading_is_named(error, expected):
    with pytest.raises(expected) as info:
        polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], Raises(error))
    assert type(info.value) is expected
    assert str(info.value) == f"sample: times: {error}"
    assert info.value.__cause__ is not None


def test_ragged_and_complex_input_are_still_named():
    with pytest.raises(ValueError, match=r"^sample: times: setting an array element with a sequence"):
        polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], [0.0, [1.0, 2.0]])
    with pytest.raises(TypeError, match=r"^sample: times: expected real numbers, got complex128$"):
        polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], np.zeros(3, complex))


def test_keyboard_interrupt_passes_unchanged():
    with pytest.raises(KeyboardInterrupt):
        polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], Raises(KeyboardInterrupt()))


# --- the unnamed error ---------------------------------------------------------------------

def test_a_cycles_setting_that_is_not_a_str_is_named():
    co = np.c_[np.arange(3.0), np.arange(3.0)]
    curve = dict(offsets=[0, 3], co=co, handle_left=co - [0.3, 0], handle_right=co + [0.3, 0],
                 interpolation=np.full(3, 2), easing=np.zeros(3, dtype=np.int64))
    with pytest.raises(TypeError) as info:
        polyscrew.evaluate_fcurves([0.0], **curve, cycles=[{1: "x"}])
    assert str(info.value) == "evaluate_fcurves: cycles[0]: setting names must be str, got int"


@pytest.mark.parametrize(
    "change, error, message",
    [
        (dict(interpolation=[2.7, 2, 2]), ValueError, r"interpolation: entry \[0\] is 2.7, not an integer"),
        (dict(interpolation=[np.nan, 2, 2]), ValueError, r"interpolation: entry \[0\] is NaN, not an integer"),
        (dict(easing=[0, 0.5, 0]), ValueError, r"easing: entry \[1\] is 0.5, not an integer"),
        (dict(offsets=[0, 3.5]), ValueError, r"offsets: entry \[1\] is 3.5, not an integer"),
        (dict(offsets=["0", "3"]), TypeError, r"offsets: expected integers, got <U1"),
        (dict(co=np.c_[np.arange(3.0), np.zeros(3)] + 1j), TypeError, r"co: expected real numbers, got complex128"),
        (dict(handle_right=np.zeros((3, 2), complex)), TypeError, r"handle_right: expected real numbers, got complex128"),
        (dict(back=np.ones(3, complex)), TypeError, r"back: expected real numbers, got complex128"),
        (dict(period=["x", "y", "z"]), TypeError, r"period: expected real numbers"),
    ],
)
@pytest.mark.parametrize("function", ["evaluate_fcurves", "Playback"])
def test_curve_arrays_are_not_cast_silently(function, change, error, message):
    kw = {**curve(3), **change}
    if function == "evaluate_fcurves":
        call = lambda: polyscrew.evaluate_fcurves([0.5, 1.5], **kw)  # noqa: E731
    else:
        call = lambda: polyscrew.Playback(channels=[("location", 0)], unkeyed=np.zeros(9), mode="XYZ", **kw)  # noqa: E731
    with pytest.raises(error, match=f"{function}: {message}"):
        call()


def test_whole_float_codes_are_still_accepted():
    kw = {**curve(3), "interpolation": [2.0, 1.0, 0.0], "offsets": [0.0, 3.0]}
    want = polyscrew.evaluate_fcurves([0.5, 1.5], **{**curve(3), "interpolation": [2, 1, 0]})
    np.testing.assert_array_equal(polyscrew.evaluate_fcurves([0.5, 1.5], **kw), want)


def test_masks_and_indices_still_read_as_before():
    """Lists of bools, numpy masks, index lists and arrays, negative indices."""
    keys = [[1.0, 0, 0, 0], [0.0, 0, 0, 1.0], [1.0, 0, 0, 0]]
    args = (keys, [0.0, 1.0, 2.0], [0.0, 2.0], np.zeros((2, 3)))
    by_mask = polyscrew.fit_angular_velocity(*args, constrained=[True, False, True])
    for constrained in (np.array([True, False, True]), [0, 2], np.array([0, -1]), (2, 0)):
        fit = polyscrew.fit_angular_velocity(*args, constrained=constrained)
        np.testing.assert_array_equal(fit.quaternions, by_mask.quaternions)
    with pytest.raises(ValueError, match="constrained: index 3 out of range for 3 keys"):
        polyscrew.fit_angular_velocity(*args, constrained=[3])
    with pytest.raises(TypeError, match="constrained: expected integers"):
        polyscrew.fit_angular_velocity(*args, constrained=["a"])
    poses = np.tile(np.eye(4), (2, 6, 1, 1))
    poses[:, :, 0, 3] = np.arange(6.0) ** 2
    times = np.arange(6.0)
    held = [True, False, False, False, False, True]
    one = polyscrew.denoise(poses, times, held=held).poses
    two = polyscrew.denoise(poses, times, held=np.array([held, held])).poses
    np.testing.assert_array_equal(one, two)
    with pytest.raises(ValueError, match=r"held: expected a boolean mask of shape \(6,\) or \(2, 6\)"):
        polyscrew.denoise(poses, times, held=[1, 0, 0, 0, 0, 1])
    with pytest.raises(ValueError, match=r"held: expected a boolean mask"):
        polyscrew.denoise(poses, times, held=np.ones((3, 6), bool))
