"""polyscrew's intent functions (Playback, analyse_spans, keys_parameters, rotation_matrices)
against independent references: scipy's ``Rotation`` for every rotation mode, hand-computed
cases (a smoothstep ease on a straight line, a CONSTANT hold, equal keys, a 720-degree spin),
and a numpy implementation of the same rules (the add-on's former pipeline, with scipy for
the rotations) on random curves. What Smooth Motion then bakes is checked against Blender's
own playback in ``tests/blender/test_intent.py``.
"""

from __future__ import annotations

import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

CODE = {name: i for i, name in enumerate(polyscrew.INTERPOLATIONS)}
EASE = {name: i for i, name in enumerate(polyscrew.EASINGS)}
EULER = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")
MODES = ("QUATERNION", "AXIS_ANGLE") + EULER
ROTATION_PATH = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}


def rotation_path(mode: str) -> str:
    return ROTATION_PATH.get(mode, "rotation_euler")


def width(mode: str) -> int:
    return 4 if mode in ("QUATERNION", "AXIS_ANGLE") else 3


def pack(curves):
    """evaluate_fcurves' keyword arguments from curves, each a list of key dicts (co, and
    optional handle_left / handle_right / interpolation / easing)."""
    keys = [k for c in curves for k in c]
    return dict(
        offsets=np.cumsum([0] + [len(c) for c in curves]),
        co=np.array([k["co"] for k in keys], float).reshape(-1, 2),
        handle_left=np.array([k.get("handle_left", (k["co"][0] - 1, k["co"][1])) for k in keys], float).reshape(-1, 2),
        handle_right=np.array([k.get("handle_right", (k["co"][0] + 1, k["co"][1])) for k in keys], float).reshape(-1, 2),
        interpolation=np.array([CODE[k.get("interpolation", "BEZIER")] for k in keys], dtype=np.int64),
        easing=np.array([EASE[k.get("easing", "AUTO")] for k in keys], dtype=np.int64),
    )


def unkeyed_row(mode: str) -> np.ndarray:
    """An owner at rest: location 0, identity rotation, unit scale."""
    rotation = {"QUATERNION": [1, 0, 0, 0], "AXIS_ANGLE": [0, 0, 1, 0]}.get(mode, [0, 0, 0])
    return np.array([0, 0, 0, *rotation, 1, 1, 1], float)


def playback(curves, columns, mode="XYZ", unkeyed=None, located=True):
    unkeyed = unkeyed_row(mode) if unkeyed is None else unkeyed
    return polyscrew.Playback(channels=columns, unkeyed=unkeyed, mode=mode, located=located, **pack(curves))


# --- independent references --------------------------------------------------------------


def reference_matrices(values: np.ndarray, mode: str) -> np.ndarray:
    """(N, 3, 3) by scipy, with Blender's conventions for zero quaternions and axes."""
    values = np.asarray(values, float)
    if mode == "QUATERNION":
        norm = np.linalg.norm(values, axis=1)
        q = np.where(norm[:, None] > 0, values, [1, 0, 0, 0])
        return Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()
    if mode == "AXIS_ANGLE":
        norm = np.linalg.norm(values[:, 1:], axis=1)
        axis = np.where(norm[:, None] > 0, values[:, 1:] / np.where(norm > 0, norm, 1)[:, None], 0.0)
        return Rotation.from_rotvec(axis * values[:, :1]).as_matrix()
    # lowercase: extrinsic, Blender's order; scipy takes the angles in sequence order
    return Rotation.from_euler(mode.lower(), values[:, ["XYZ".index(a) for a in mode]]).as_matrix()


def reference_channels(curves, columns, mode, frames, unkeyed=None, located=True) -> np.ndarray:
    """(T, 6 + w) channel rows: evaluate_fcurves' values in their columns, the rest at rest."""
    unkeyed = unkeyed_row(mode) if unkeyed is None else unkeyed
    rows = np.tile(unkeyed, (len(frames), 1))
    values = polyscrew.evaluate_fcurves(np.asarray(frames, float), **pack(curves))
    start = {"location": 0, rotation_path(mode): 3, "scale": 3 + width(mode)}
    for row, (prop, index) in zip(values, columns):
        rows[:, start[prop] + index] = row
    if not located:
        rows[:, :3] = 0.0
    return rows


def angle_between(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return (Rotation.from_matrix(a).inv() * Rotation.from_matrix(b)).magnitude()


def reference_spans(rows_at, mode, frames):
    """The span analysis by its rules, in numpy and scipy: rows_at(frames) -> channel rows."""
    w = width(mode)
    spans = len(frames) - 1
    at_keys = rows_at(frames)
    rot = at_keys[:, 3 : 3 + w]
    if mode == "QUATERNION":
        counts = np.full(spans, polyscrew.SPAN_SAMPLES)
    else:
        change = np.abs(np.diff(rot[:, :1] if mode == "AXIS_ANGLE" else rot, axis=0)).sum(axis=1)
        counts = np.clip(np.ceil(np.degrees(change) / 10.0), polyscrew.SPAN_SAMPLES, polyscrew.MAX_SPAN_SAMPLES).astype(int)
    held, turn, steps_of, where_of = [], [], [], []
    for s in range(spans):
        t = frames[s] + (frames[s + 1] - frames[s]) * (np.arange(counts[s]) / counts[s])
        rows = rows_at(t)
        tol = polyscrew.HOLD_TOLERANCE * (np.abs(at_keys[s]) + 1.0)
        held.append(not np.any(np.abs(rows - at_keys[s]) > tol))
        m = reference_matrices(np.vstack([rows[:, 3 : 3 + w], rot[s + 1 : s + 2]]), mode)
        steps = angle_between(m[:-1], m[1:])
        turn.append(steps.sum())
        steps_of.append(steps)
        where_of.append(np.append(t, frames[s + 1]))
    held, turn = np.array(held), np.array(turn)
    moved = np.any(np.abs(np.diff(at_keys, axis=0)) > polyscrew.HOLD_TOLERANCE * (np.abs(at_keys[:-1]) + 1), axis=1)
    pops = held & moved
    inserted = []
    if mode != "QUATERNION":
        spinning = (turn > polyscrew.WIND_LIMIT) & ~held
        for s in np.flatnonzero(spinning):
            for step in (-1, 1):
                n = s + step
                while 0 <= n < spans and turn[n] > polyscrew.WIND_STEP and not held[n]:
                    spinning[n] = True
                    n += step
        for s in np.flatnonzero(spinning):
            pieces = int(np.ceil(turn[s] / polyscrew.WIND_STEP))
            cumulative = np.concatenate(([0.0], np.cumsum(steps_of[s])))
            inserted.append(np.interp(turn[s] * np.arange(1, pieces) / pieces, cumulative, where_of[s]))
    return held, pops, turn, np.concatenate(inserted) if inserted else np.zeros(0)


def travel(a: np.ndarray, b: np.ndarray, size: float) -> np.ndarray:
    """Travel between (N, 4, 4) poses: rms displacement of six points at +-size."""
    dt = b[:, :3, 3] - a[:, :3, 3]
    dr = b[:, :3, :3] - a[:, :3, :3]
    return np.sqrt(np.sum(dt * dt, axis=1) + size * size / 3.0 * np.sum(dr * dr, axis=(1, 2)))


def poses_of(rows: np.ndarray, mode: str) -> np.ndarray:
    out = np.zeros((len(rows), 4, 4))
    out[:, :3, :3] = reference_matrices(rows[:, 3 : 3 + width(mode)], mode)
    out[:, :3, 3] = rows[:, :3]
    out[:, 3, 3] = 1.0
    return out


def reference_keys_parameters(key_frames, frames, size, key_poses, scheme, levels, rows_at=None, mode="XYZ", period=None):
    """Timing Keys by its rule, span by span, in numpy (the smoothed motion by polyscrew.sample)."""
    p = polyscrew.PACE_SAMPLES
    ends = np.append(key_frames, key_frames[0] + period) if period is not None else np.asarray(key_frames, float)
    spans = len(ends) - 1
    k = len(key_frames)
    grid = np.arange(p + 1) / p
    u_grid = (np.arange(spans)[:, None] + grid).ravel()
    smooth = polyscrew.sample(key_poses, np.arange(k, dtype=float), u_grid, scheme=scheme, levels=levels,
                              closed=period is not None, period=float(k) if period is not None else None, timing="linear")
    smooth = smooth.reshape(spans, p + 1, 4, 4)
    frames = np.asarray(frames, float)
    span = np.clip(np.searchsorted(ends, frames, side="right") - 1, 0, spans - 1)
    tau = (frames - ends[span]) / (ends[span + 1] - ends[span])
    inside = (tau > 0.0) & (tau < 1.0)
    out = span + tau
    for s in range(spans):
        mine = inside & (span == s)
        # Blender's playback along the grid and every output frame inside the span
        fractions = np.sort(np.concatenate([grid, tau[mine]]))
        if rows_at is None:
            done = tau[mine]
        else:
            poses = poses_of(rows_at(ends[s] + fractions * (ends[s + 1] - ends[s])), mode)
            along = np.concatenate(([0.0], np.cumsum(travel(poses[:-1], poses[1:], size))))
            at = np.searchsorted(fractions, tau[mine])
            done = along[at] / along[-1] if along[-1] > 0 else tau[mine]
        # the smoothed motion's own travel, inverted
        steps = np.concatenate(([0.0], np.cumsum(travel(smooth[s, :-1], smooth[s, 1:], size))))
        x = steps / steps[-1] if steps[-1] > 0 else grid
        out[mine] = s + np.interp(done, x, grid)
    return out


# --- rotation matrices -------------------------------------------------------------------


@pytest.mark.parametrize("mode", MODES)
def test_rotation_matrices_match_scipy_for_every_mode(mode, rng):
    values = rng.normal(size=(200, width(mode))) * 3.0  # unnormalised quaternions and axes, angles past 2 pi
    got = polyscrew.rotation_matrices(values, mode)
    assert got.shape == (200, 3, 3)
    np.testing.assert_allclose(got, reference_matrices(values, mode), atol=1e-14, rtol=0)


def test_rotation_matrices_zero_quaternion_and_zero_axis_are_the_identity():
    assert np.array_equal(polyscrew.rotation_matrices([[0, 0, 0, 0]], "QUATERNION")[0], np.eye(3))
    assert np.array_equal(polyscrew.rotation_matrices([[2.0, 0, 0, 0]], "AXIS_ANGLE")[0], np.eye(3))


def test_rotation_matrices_errors_name_the_argument():
    with pytest.raises(ValueError, match=r"rotation_matrices: values: expected shape \(N, 4\)"):
        polyscrew.rotation_matrices(np.zeros((2, 3)), "QUATERNION")
    with pytest.raises(ValueError, match="rotation_matrices: rotation 1 is NaN"):
        polyscrew.rotation_matrices([[0, 0, 0], [0, np.nan, 0]], "XYZ")
    with pytest.raises(ValueError, match="rotation mode"):
        polyscrew.rotation_matrices(np.zeros((1, 3)), "XYX")


# --- playback ----------------------------------------------------------------------------


def random_curves(rng, frames, count):
    """`count` curves keyed at `frames` with random values, handles and interpolations."""
    kinds = ["BEZIER", "LINEAR", "CONSTANT", "SINE", "EXPO", "BACK", "ELASTIC", "CIRC", "QUAD"]
    curves = []
    for _ in range(count):
        values = rng.normal(size=len(frames)) * 2
        keys = []
        for f, v in zip(frames, values):
            d = rng.uniform(0.5, 4.0)
            keys.append(dict(co=(f, v), handle_left=(f - d, v + rng.normal()), handle_right=(f + d, v + rng.normal()),
                             interpolation=kinds[rng.integers(len(kinds))], easing=polyscrew.EASINGS[rng.integers(4)]))
        curves.append(keys)
    return curves


@pytest.mark.parametrize("mode", ["XYZ", "QUATERNION", "AXIS_ANGLE"])
def test_playback_channels_are_the_curves_in_their_columns(mode, rng):
    frames = np.array([1.0, 7.0, 12.5, 30.0])
    columns = [("location", 2), (rotation_path(mode), 1), ("scale", 0)]
    curves = random_curves(rng, frames, 3)
    unkeyed = rng.normal(size=6 + width(mode))
    for located in (True, False):
        pb = playback(curves, columns, mode, unkeyed, located)
        t = np.linspace(-5, 40, 301)
        location, rotation, scale = pb.channels(t)
        want = reference_channels(curves, columns, mode, t, unkeyed, located)
        assert np.array_equal(np.hstack([location, rotation, scale]), want)
    assert len(pb) == 3


def test_playback_errors_name_the_argument():
    curve = [[dict(co=(1, 0)), dict(co=(2, 1))]]
    with pytest.raises(ValueError, match=r"Playback: channels\[0\]: .*rotation_quaternion"):
        playback(curve, [("rotation_quaternion", 0)], "XYZ")
    with pytest.raises(ValueError, match=r"Playback: channels\[0\]: scale: index 3 is outside 0\.\.3"):
        playback(curve, [("scale", 3)])
    with pytest.raises(ValueError, match="Playback: channels: expected 1 entries"):
        playback(curve, [])
    with pytest.raises(ValueError, match="Playback: static values: expected 9 entries, got 10"):
        playback(curve, [("location", 0)], unkeyed=np.zeros(10))
    with pytest.raises(ValueError, match="Playback: co: expected shape"):
        polyscrew.Playback(channels=[("location", 0)], unkeyed=np.zeros(9), mode="XYZ", **{**pack(curve), "co": np.zeros(4)})
    with pytest.raises(ValueError, match="curves 0 and 1 drive the same channel"):
        playback(curve * 2, [("location", 0), ("location", 0)])


# --- span analysis -----------------------------------------------------------------------


def test_a_constant_hold_pops_and_equal_keys_hold_still():
    # x: 0 -> 4 moving; 4 held CONSTANT until frame 20, where it pops to 8; 8 -> 8 (equal keys,
    # flat handles) held without a pop; then moving again.
    x = [dict(co=(1, 0), interpolation="LINEAR"), dict(co=(10, 4), interpolation="CONSTANT"),
         dict(co=(20, 8)), dict(co=(30, 8)), dict(co=(40, 12))]
    pb = playback([x], [("location", 0)])
    held, pops, turn, inserted = polyscrew.analyse_spans(pb, [1.0, 10.0, 20.0, 30.0, 40.0])
    assert held.dtype == bool and held.tolist() == [False, True, True, False]
    assert pops.tolist() == [False, True, False, False]
    assert np.array_equal(turn, np.zeros(4)) and len(inserted) == 0


def test_a_720_degree_spin_turns_twice_round_in_equal_pieces():
    spin = np.radians(720.0)
    z = [dict(co=(1, 0), interpolation="LINEAR"), dict(co=(41, spin))]
    pb = playback([z], [("rotation_euler", 2)])
    held, pops, turn, inserted = polyscrew.analyse_spans(pb, [1.0, 41.0])
    assert not held[0] and not pops[0]
    assert turn[0] == pytest.approx(spin, abs=1e-5)
    # ceil(turn / 45 degrees) pieces (16, or 17 when float32 rounds 4 pi up), evenly spaced in time
    pieces = int(np.ceil(turn[0] / polyscrew.WIND_STEP))
    assert pieces in (16, 17) and len(inserted) == pieces - 1
    np.testing.assert_allclose(inserted, 1.0 + 40.0 * np.arange(1, pieces) / pieces, atol=1e-4)
    # quaternion keys keep the short arc: nothing added, whatever they turn
    half = np.radians(170.0) / 2
    q = [[dict(co=(1, 1.0), interpolation="LINEAR"), dict(co=(11, np.cos(half)))],
         [dict(co=(1, 0.0), interpolation="LINEAR"), dict(co=(11, np.sin(half)))]]
    _, _, turn, inserted = polyscrew.analyse_spans(
        playback(q, [("rotation_quaternion", 0), ("rotation_quaternion", 3)], "QUATERNION"), [1.0, 11.0])
    assert turn[0] == pytest.approx(np.radians(170.0), abs=1e-5) and len(inserted) == 0


@pytest.mark.parametrize("mode", MODES)
def test_span_analysis_follows_its_rules_on_random_curves(mode, rng):
    for _ in range(4):
        frames = np.cumsum(rng.uniform(2, 12, size=rng.integers(3, 7)))
        columns = [("location", 0), ("location", 2)] + [(rotation_path(mode), i) for i in range(width(mode))] + [("scale", 1)]
        curves = random_curves(rng, frames, len(columns))
        for i, (prop, _) in enumerate(columns):  # spins on the angles, now and then
            if prop == "rotation_euler" or (prop == "rotation_axis_angle" and i == 2):
                for key in curves[i]:
                    key["co"] = (key["co"][0], key["co"][1] * 4)
        pb = playback(curves, columns, mode)
        got = polyscrew.analyse_spans(pb, frames)
        want = reference_spans(lambda t: reference_channels(curves, columns, mode, t), mode, frames)
        assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
        np.testing.assert_allclose(got[2], want[2], atol=1e-9)
        assert got[3].shape == want[3].shape
        np.testing.assert_allclose(got[3], want[3], atol=1e-6)


def test_span_analysis_errors():
    pb = playback([[dict(co=(1, 0))]], [("location", 0)])
    with pytest.raises(ValueError, match="analyse_spans: 1 poses given, at least 2 needed"):
        polyscrew.analyse_spans(pb, [1.0])
    with pytest.raises(ValueError, match="analyse_spans: key time 1 is not finite or not greater"):
        polyscrew.analyse_spans(pb, [1.0, 1.0])
    with pytest.raises(TypeError):
        polyscrew.analyse_spans("not a playback", [1.0, 2.0])


# --- timing Keys -------------------------------------------------------------------------


def straight_line(distance: float = 10.0) -> np.ndarray:
    poses = np.tile(np.eye(4), (2, 1, 1))
    poses[1, 0, 3] = distance
    return poses


def test_keys_timing_of_a_straight_smoothstep_ease():
    """Two keys on a straight line, x from 0 at frame 1 to 10 at frame 21, handles flat at a
    third of the span: x(u) = 1 + 20 u, value = 10 (3 u^2 - 2 u^3). The motion (a straight
    screw, travelled at constant speed in its parameter) reaches the fraction 3 t^2 - 2 t^3
    of the way at the fraction t of the time."""
    third = 20.0 / 3.0
    x = [dict(co=(1, 0), handle_left=(1 - third, 0), handle_right=(1 + third, 0)),
         dict(co=(21, 10), handle_left=(21 - third, 10), handle_right=(21 + third, 10))]
    pb = playback([x], [("location", 0)])
    frames = np.arange(1.0, 21.01, 0.25)
    for scheme in ("four_point", "bspline", "jarek"):
        u = polyscrew.keys_parameters([1.0, 21.0], frames, size=1.0, playback=pb, poses=straight_line(), scheme=scheme, levels=4)
        tau = (frames - 1.0) / 20.0
        np.testing.assert_allclose(u, 3 * tau**2 - 2 * tau**3, atol=2e-6, err_msg=scheme)
    # without playback: the fraction of time; outside the keys: extrapolated
    u = polyscrew.keys_parameters([1.0, 21.0], [-9.0, 6.0, 41.0], size=1.0, poses=straight_line())
    np.testing.assert_allclose(u, [-0.5, 0.25, 2.0], atol=1e-12)


@pytest.mark.parametrize("kind", ["EXPO", "BACK", "SINE"])
def test_keys_timing_of_a_straight_easing_is_its_fraction_of_travel(kind):
    """A straight-line two-key motion eased by `kind` (EASE_IN_OUT): the fraction of travel at
    each frame is the distance covered by the curve's values (forward and back, for BACK's
    overshoot) over the total, measured here on a 20,000-step evaluation of the curve."""
    x = [dict(co=(1, 0), interpolation=kind, easing="EASE_IN_OUT"), dict(co=(21, 10))]
    pb = playback([x], [("location", 0)])
    frames = np.arange(1.0, 21.01, 0.5)
    u = polyscrew.keys_parameters([1.0, 21.0], frames, size=1.0, playback=pb, poses=straight_line())
    fine = np.linspace(1.0, 21.0, 20001)
    values = polyscrew.evaluate_fcurves(fine, **pack([x]))[0]
    along = np.concatenate(([0.0], np.cumsum(np.abs(np.diff(values)))))
    want = np.interp(frames, fine, along / along[-1])
    # 17 pace samples plus the frame itself: exact at the frame, linear between samples
    np.testing.assert_allclose(u, want, atol=2e-3)


@pytest.mark.parametrize("mode", ["XYZ", "ZXY", "QUATERNION", "AXIS_ANGLE"])
@pytest.mark.parametrize("scheme", ["four_point", "jarek"])
def test_keys_timing_follows_its_rule_on_random_curves(mode, scheme, rng):
    for closed in (False, True):
        key_frames = np.cumsum(rng.uniform(3, 12, size=rng.integers(3, 6)))
        period = float(key_frames[-1] - key_frames[0] + rng.uniform(3, 10)) if closed else None
        columns = [("location", i) for i in range(3)] + [(rotation_path(mode), i) for i in range(width(mode))]
        curves = random_curves(rng, key_frames, len(columns))
        rows_at = lambda t: reference_channels(curves, columns, mode, t)  # noqa: E731
        key_poses = poses_of(rows_at(key_frames), mode)
        end = key_frames[0] + period if closed else key_frames[-1]
        frames = np.sort(np.concatenate([np.arange(key_frames[0] - 2, end + 2, 0.37), key_frames]))
        pb = playback(curves, columns, mode)
        size = rng.uniform(0.3, 3.0)
        got = polyscrew.keys_parameters(key_frames, frames, size=size, closed=closed, period=period, playback=pb,
                                        poses=key_poses, scheme=scheme, levels=4)
        want = reference_keys_parameters(key_frames, frames, size, key_poses, scheme, 4, rows_at, mode, period)
        np.testing.assert_allclose(got, want, atol=1e-9, err_msg=f"closed {closed}")
        # the same from the smoothed motion's poses given by the caller (feature points)
        spans = len(key_frames) if closed else len(key_frames) - 1
        smooth = polyscrew.sample(key_poses, np.arange(len(key_frames), dtype=float), polyscrew.pace_parameters(spans),
                                  scheme=scheme, levels=4, closed=closed,
                                  period=float(len(key_frames)) if closed else None, timing="linear")
        again = polyscrew.keys_parameters(key_frames, frames, size=size, closed=closed, period=period, playback=pb, smooth=smooth)
        np.testing.assert_allclose(again, got, atol=1e-12)


def test_pace_parameters():
    p = polyscrew.PACE_SAMPLES
    got = polyscrew.pace_parameters(3)
    np.testing.assert_array_equal(got, (np.arange(3)[:, None] + np.arange(p + 1) / p).ravel())


def test_keys_timing_errors_name_the_argument():
    poses = straight_line()
    with pytest.raises(ValueError, match="keys_parameters: give either poses"):
        polyscrew.keys_parameters([1.0, 2.0], [1.5], size=1.0)
    with pytest.raises(ValueError, match="keys_parameters: give either poses"):
        polyscrew.keys_parameters([1.0, 2.0], [1.5], size=1.0, poses=poses, smooth=np.tile(np.eye(4), (17, 1, 1)))
    with pytest.raises(ValueError, match="keys_parameters: period: a closed motion needs its period"):
        polyscrew.keys_parameters([1.0, 2.0], [1.5], size=1.0, closed=True, poses=poses)
    with pytest.raises(ValueError, match="keys_parameters: period 0.5 must be finite and exceed"):
        polyscrew.keys_parameters([1.0, 2.0], [1.5], size=1.0, closed=True, period=0.5, poses=poses)
    with pytest.raises(ValueError, match=r"keys_parameters: size: -1 is not in the working range \(0, 1e150\]"):
        polyscrew.keys_parameters([1.0, 2.0], [1.5], size=-1.0, poses=poses)
    with pytest.raises(ValueError, match="keys_parameters: frame 1 is NaN"):
        polyscrew.keys_parameters([1.0, 2.0], [1.5, np.nan], size=1.0, poses=poses)
    with pytest.raises(ValueError, match="keys_parameters: smooth poses: expected 17 entries, got 3"):
        polyscrew.keys_parameters([1.0, 2.0], [1.5], size=1.0, smooth=np.tile(np.eye(4), (3, 1, 1)))
    with pytest.raises(ValueError, match="keys_parameters: poses: pose 1: not rigid"):
        bad = poses.copy()
        bad[1, 0, 0] = 2.0
        polyscrew.keys_parameters([1.0, 2.0], [1.5], size=1.0, poses=bad)


def test_constants():
    assert polyscrew.WIND_LIMIT == np.radians(150.0) and polyscrew.WIND_STEP == np.radians(45.0)
    assert (polyscrew.SPAN_SAMPLES, polyscrew.MAX_SPAN_SAMPLES, polyscrew.PACE_SAMPLES) == (8, 4096, 16)
    assert polyscrew.HOLD_TOLERANCE == 1e-6
