"""The last rules that lived outside the core (issue 25 item 2): timing Keys chosen like Smooth
and Linear (`polyscrew.timed_frames`, `TIMINGS`, `PACED_TIMINGS`), the rotation-keeping maps of a
Frame Range's join (`same_rotation_map`), which rotation modes continue a previous value
(`CONTINUED_ROTATION_MODES`), whole turns towards a reference (`angles_near`), the angle
between sketch directions (`direction_steps`), and two error messages that state their facts
again (the key range's length, the span count).

References: the add-on's former numpy code, copied here as it was (the maps, the wrap, the
arccos step), scipy's rotations, and `keys_parameters` / `sample_channels` called as the add-on
called them before (bit for bit).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

import pure_layer
from test_intent import playback, reference_matrices

TAU = 2.0 * np.pi
sampling = pure_layer.module("sampling")
keyed = pure_layer.module("keyed")
smooth_options = pure_layer.module("smooth_options")
EULER = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")


# --- timing Keys, chosen like Smooth and Linear ----------------------------------------------


def test_the_timings_are_the_cores_and_the_add_on_offers_them():
    assert polyscrew.TIMINGS == ("smooth", "linear", "keys")
    assert polyscrew.PACED_TIMINGS == ("keys",)
    assert [name for name, *_ in smooth_options.TIMINGS] == list(polyscrew.TIMINGS)
    # a paced timing is not a map of time alone: the samplers refuse it with the reason
    with pytest.raises(polyscrew.InvalidArgument, match="sample: timing: timing keys follows a playback's pace"):
        polyscrew.sample(np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], [0.5], timing="keys")
    with pytest.raises(ValueError, match="timed_frames: size: timing keys needs the body's size"):
        polyscrew.timed_frames([0.0, 1.0], [0.5], "keys", poses=np.tile(np.eye(4), (2, 1, 1)))
    with pytest.raises(ValueError, match=r'timed_frames: timing: "cubic" is not one of "smooth", "linear", "keys"'):
        polyscrew.timed_frames([0.0, 1.0], [0.5], "cubic")


def scene(mode="XYZ"):
    """Four keys moving along X and turning about Z, Bezier with auto handles, as Blender
    plays them (a `Playback`), and the key poses."""
    frames = np.array([1.0, 7.0, 19.0, 31.0])
    x = np.array([0.0, 1.5, 6.0, 7.0])
    z = np.array([0.0, 0.6, 2.4, 2.9])
    curves = [
        [dict(co=(f, v), handle_left=(f - 2.0, v), handle_right=(f + 2.0, v)) for f, v in zip(frames, values)]
        for values in (x, z)
    ]
    pb = playback(curves, [("location", 0), ("rotation_euler", 2)], mode="XYZ")
    poses = np.tile(np.eye(4), (len(frames), 1, 1))
    poses[:, :3, :3] = Rotation.from_euler("z", z[:, None]).as_matrix()
    poses[:, 0, 3] = x
    return pb, frames, poses


def test_timed_frames_of_a_map_of_time_are_the_frames_themselves():
    pb, key_frames, poses = scene()
    frames = np.linspace(0.0, 32.0, 11)
    for timing in ("smooth", "linear"):
        got = polyscrew.timed_frames(key_frames, frames, timing, size=1.0, period=None, playback=pb, poses=poses, played=True)
        assert got[0] is key_frames and got[1] is frames and got[2] is None and got[3] == timing and got[4] is None


@pytest.mark.parametrize("closed", [False, True])
def test_timed_frames_of_timing_keys_are_keys_parameters_bit_for_bit(closed):
    """What `sampling` called before (keys_parameters, then the motion at those parameters, keys
    at 0..K-1, linear timing) and what it calls now give the same numbers to the bit."""
    pb, key_frames, poses = scene()
    frames = np.arange(-2.0, 44.0, 0.25)
    period = 36.0 if closed else None
    common = dict(size=1.7, closed=closed, period=period, playback=pb, scheme="jarek", levels=3)
    want, want_rows = polyscrew.keys_parameters(key_frames, frames, poses=poses, played=True, **common)
    key_times, at, got_period, timing, rows = polyscrew.timed_frames(key_frames, frames, "keys", poses=poses, played=True, **common)
    np.testing.assert_array_equal(key_times, np.arange(4.0))
    assert got_period == (4.0 if closed else None) and timing == "linear"
    assert at.tobytes() == want.tobytes() and rows.tobytes() == want_rows.tobytes()
    assert polyscrew.timed_frames(key_frames, frames, "keys", poses=poses, **common)[4] is None
    # the smoothed motion given by the caller (the feature-point method's way)
    spans = 4 if closed else 3
    smooth = polyscrew.sample(poses, np.arange(4.0), polyscrew.pace_parameters(spans), scheme="jarek", levels=3,
                              closed=closed, period=4.0 if closed else None, timing="linear")
    given = polyscrew.timed_frames(key_frames, frames, "keys", smooth=smooth, **common)
    assert given[1].tobytes() == polyscrew.keys_parameters(key_frames, frames, smooth=smooth, **common).tobytes()
    np.testing.assert_allclose(given[1], want, atol=1e-12)  # (the poses went through 4x4 matrices)
    print(f"closed={closed}: {len(frames)} frames, parameters from {at.min():.4f} to {at.max():.4f}, "
          f"{np.isfinite(rows[:, 0]).sum()} rows played")


def keyed_motion(pb, key_frames, poses, size=1.7):
    k = len(key_frames)
    source = SimpleNamespace(playback=pb)
    return keyed.KeyedMotion(
        frames=key_frames, poses=poses, scales=np.ones((k, 3)), scale_axes=np.zeros(3, bool), rotation_mode="XYZ",
        first_rotation=np.zeros(3), closed=False, period=None, cyclic=False, size=size, source=source,
    )


def test_sampling_timing_keys_is_what_it_was_to_the_bit():
    """`sampling.sample` with timing "keys" (now one `timed_frames` call) against the add-on's
    former path, called here as it called polyscrew: the channels and the played rows."""
    pb, key_frames, poses = scene()
    motion = keyed_motion(pb, key_frames, poses)
    frames = np.arange(1.0, 31.5, 0.5)
    options = SimpleNamespace(scheme="jarek", levels=4, timing="keys", method="SCREW")
    got = sampling.sample(motion, frames, options, channels=True, previous=np.zeros(3), played=True)
    at, rows = polyscrew.keys_parameters(key_frames, frames, size=1.7, closed=False, period=None, playback=pb,
                                         poses=poses, scheme="jarek", levels=4, played=True)
    loc, rot = polyscrew.sample_channels(poses, np.arange(4.0), at, "XYZ", np.zeros(3), scheme="jarek", levels=4,
                                         closed=False, period=None, timing="linear")
    assert got.location.tobytes() == loc.tobytes() and got.rotation.tobytes() == rot.tobytes()
    assert got.played.tobytes() == rows.tobytes()
    # and Smooth as before: the keys at their frames
    options.timing = "smooth"
    got = sampling.sample(motion, frames, options, channels=True, previous=np.zeros(3), played=True)
    loc, rot = polyscrew.sample_channels(poses, key_frames, frames, "XYZ", np.zeros(3), scheme="jarek", levels=4)
    assert got.location.tobytes() == loc.tobytes() and got.rotation.tobytes() == rot.tobytes() and got.played is None


# --- rotation rules ---------------------------------------------------------------------------


def former_equivalence(source, baked, mode):
    """`range_join.equivalence` as the add-on wrote it in numpy before (rotation channels)."""
    source, baked = np.asarray(source, dtype=np.float64), np.asarray(baked, dtype=np.float64)
    ones, zeros = np.ones_like(source), np.zeros_like(source)
    tol = 1e-5 * max(1.0, float(np.max(np.abs(baked))))
    candidates = []
    if mode == "QUATERNION":
        norm = float(source @ source)
        if norm > 0.0:
            candidates.append((ones * (float(baked @ source) / norm), zeros))
    elif mode == "AXIS_ANGLE":
        axis = float(source[1:] @ source[1:])
        for sign in (1.0, -1.0):
            if axis > 0.0:
                scale = float(baked[1:] @ source[1:]) / axis
                if scale * sign > 0.0:
                    a = np.array([sign, scale, scale, scale])
                    c = np.array([TAU * np.round((baked[0] - sign * source[0]) / TAU), 0.0, 0.0, 0.0])
                    candidates.append((a, c))
    else:
        candidates.append((ones, TAU * np.round((baked - source) / TAU)))
        _, middle, _ = ("XYZ".index(axis) for axis in mode)
        a = ones.copy()
        a[middle] = -1.0
        twin = np.full(3, np.pi)
        c = twin + TAU * np.round((baked - (a * source + twin)) / TAU)
        candidates.append((a, c))
    for a, c in candidates:
        if np.all(np.abs(a * source + c - baked) <= tol):
            return a, c
    return None


def scipy_matrix(values, mode):
    """Blender's rotation of channel values, by scipy (`test_intent.reference_matrices`)."""
    return reference_matrices(np.asarray(values, dtype=np.float64)[None], mode)[0]


@pytest.mark.parametrize("mode", ["QUATERNION", "AXIS_ANGLE", *EULER])
def test_same_rotation_map_is_the_former_join_map_and_keeps_every_rotation(mode, rng):
    """Against the former numpy maps (the same map, or both None) on the same rotation written
    otherwise and on other rotations; every map found keeps the rotation of other values
    (scipy's matrices)."""
    found = refused = 0
    worst = 0.0
    for _ in range(60):
        q = Rotation.random(random_state=rng)
        s = polyscrew.rotation_channels(q.as_matrix()[None], mode)[0]
        if mode == "QUATERNION":
            t = s * rng.choice([-2.0, -0.5, 0.7, 3.0])
        elif mode == "AXIS_ANGLE":
            sign = rng.choice([-1.0, 1.0])
            t = np.concatenate(([sign * s[0] + TAU * rng.integers(-2, 3)], sign * rng.uniform(0.3, 3.0) * s[1:]))
        else:
            t = polyscrew.rotation_channels_near(q.as_matrix()[None], mode, (s + TAU * rng.integers(-2, 3, 3))[None])[0]
            if rng.random() < 0.5:  # the twin triple
                middle = "XYZ".index(mode[1])
                t = np.where(np.arange(3) == middle, np.pi - s, s + np.pi) + TAU * rng.integers(-2, 3, 3)
        if rng.random() < 0.25:
            t = t + rng.normal(0.0, 0.05, len(t))  # another rotation
        got = polyscrew.same_rotation_map(s, t, mode)
        want = former_equivalence(s, t, mode)
        assert (got is None) == (want is None), (s, t, got, want)
        if got is None:
            refused += 1
            continue
        found += 1
        np.testing.assert_allclose(got[0], want[0], rtol=1e-15, atol=0.0)
        np.testing.assert_allclose(got[1], want[1], rtol=0.0, atol=1e-15)
        probe = polyscrew.rotation_channels(Rotation.random(random_state=rng).as_matrix()[None], mode)[0]
        mapped = got[0] * probe + got[1]
        worst = max(worst, float(np.abs(scipy_matrix(mapped, mode) - scipy_matrix(probe, mode)).max()))
    print(f"{mode}: {found} maps found, {refused} refused, largest matrix change of a mapped probe {worst:.1e}")
    assert found >= 30 and refused >= 5 and worst < 1e-12


def test_continued_rotation_modes_are_the_cores():
    assert polyscrew.CONTINUED_ROTATION_MODES == ("QUATERNION", *EULER)
    assert polyscrew.NORMALISED_CHANNELS == {"QUATERNION": (0, 4), "AXIS_ANGLE": (1, 4)}
    rng = np.random.default_rng(3)
    for mode, (start, stop) in polyscrew.NORMALISED_CHANNELS.items():  # scaling them keeps the rotation (scipy)
        values = polyscrew.rotation_channels(Rotation.random(random_state=rng).as_matrix()[None], mode)[0]
        scaled = values.copy()
        scaled[start:stop] *= 2.7
        np.testing.assert_allclose(scipy_matrix(scaled, mode), scipy_matrix(values, mode), atol=1e-14)
    previous = np.array([0.1, 0.2, 0.3])
    for mode in polyscrew.ROTATION_MODES:
        want = None if mode == "AXIS_ANGLE" else previous
        assert keyed.continued(mode, previous) is want


@pytest.mark.parametrize("mode", ["QUATERNION", "AXIS_ANGLE", "XYZ", "ZYX"])
def test_angles_near_is_the_former_per_key_euler_wrap(mode, rng):
    """Remove Noise wrote each Euler key within half a turn of its own value by numpy; the
    core's rule gives the same numbers, and leaves channels that are not angles alone."""
    target = rng.uniform(-30.0, 30.0, 500)
    co = rng.uniform(-30.0, 30.0, 500).astype(np.float32)
    for channel in range(polyscrew.ROTATION_MODES[mode][1]):
        got = polyscrew.angles_near(target, co, mode, channel)
        if mode in EULER or (mode == "AXIS_ANGLE" and channel == 0):
            want = target + TAU * np.round((co - target) / TAU)
            np.testing.assert_array_equal(got, want)
            assert np.all(np.abs(got - co) <= np.pi + 1e-12)
        else:
            np.testing.assert_array_equal(got, target)


def test_direction_steps_against_known_angles():
    """Consecutive directions at known angles (a unit vector turned about a perpendicular axis,
    lengths varied): exact to 1e-15 where the former arccos loses digits (near 0 and pi)."""
    angles = np.array([1e-9, 3e-8, 0.4, 1.5, 2.9, np.pi - 1e-8, np.pi - 1e-10])
    total = np.concatenate(([0.0], np.cumsum(angles)))
    directions = np.stack([np.cos(total), np.sin(total), np.zeros_like(total)], axis=1)
    directions *= np.linspace(0.5, 3.0, len(total))[:, None]
    got = polyscrew.direction_steps(directions)
    unit = directions / np.linalg.norm(directions, axis=1, keepdims=True)
    former = np.arccos(np.clip(np.sum(unit[1:] * unit[:-1], axis=1), -1.0, 1.0))
    err, err_former = np.abs(got - angles) / angles, np.abs(former - angles) / angles
    print("relative error of the step: core", np.array2string(err, precision=1), "former arccos",
          np.array2string(err_former, precision=1))
    assert err.max() < 1e-6 and err[2:5].max() < 1e-14 and err_former[0] > 1e-3
    assert polyscrew.direction_steps(np.zeros((1, 3))).shape == (0,)


# --- the facts the typed errors had lost ------------------------------------------------------


def test_fragment_duration_error_states_the_key_range_length():
    with pytest.raises(ValueError) as err:
        polyscrew.fit_angular_velocity([[1.0, 0, 0, 0]] * 2, [0.0, 250.0], [0.0, 250.0], np.zeros((2, 3)),
                                       fragment_duration=1e-7)
    message = str(err.value)
    print(message)
    assert message == (
        "fit_angular_velocity: fragment_duration: 1e-7 is not at least 0.00025 "
        "(at most 1000000 fragments of the key range, 250 long)"
    )


def test_analyse_spans_cap_states_the_span_count():
    """600 keys of a Z angle turning 1,000 radians per frame: 599 spans of 4,096 samples each,
    refused before any is taken, the message names the 599 spans and the samples they ask."""
    k = 600
    f = np.arange(k, dtype=float)
    pb = playback([[dict(co=(x, 1000.0 * x), interpolation="LINEAR") for x in f]], [("rotation_euler", 2)])
    with pytest.raises(ValueError) as err:
        polyscrew.analyse_spans(pb, f)
    message = str(err.value)
    print(message)
    assert message.startswith(
        f"analyse_spans: frames: the {k - 1} key spans would take {(k - 1) * polyscrew.MAX_SPAN_SAMPLES} samples of "
        f"the playback, over the limit of {polyscrew.MAX_ANALYSIS_SAMPLES} in one call: "
    )
