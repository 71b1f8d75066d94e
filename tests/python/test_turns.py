"""polyscrew's flips and spins (`analyse_turns`, `analyse_spans(turns=...)`) and
`Playback.departure` (issue 24, items 4 and 5), against independent references: the wrap
rule written out with every equivalent Euler triple enumerated and checked with scipy, and
scipy's rotations for the departure."""

from __future__ import annotations

import itertools

import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

from test_intent import playback, reference_matrices

EULER = ("XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")


def linear(frames, values):
    return [dict(co=(f, v), interpolation="LINEAR") for f, v in zip(frames, values)]


def euler_playback(mode, keys, frames):
    """A playback whose Euler channels go linearly through `keys` (K, 3) at `frames`."""
    keys = np.asarray(keys, float)
    curves = [linear(frames, keys[:, i]) for i in range(3)]
    return playback(curves, [("rotation_euler", i) for i in range(3)], mode)


def equivalents(mode: str, b: np.ndarray) -> list[np.ndarray]:
    """Every triple of the same rotation as `b` near it: each angle plus -2 pi, 0 or 2 pi, and
    the same for the twin triple (the first and last angle plus pi, the middle one reflected:
    found by trying each axis as the middle one and keeping those scipy calls equal)."""
    m = reference_matrices(b[None], mode)[0]
    out = []
    for middle in range(3):
        twin = b + np.pi
        twin[middle] = np.pi - b[middle]
        if np.abs(reference_matrices(twin[None], mode)[0] - m).max() < 1e-9:
            out.append(twin)
    assert len(out) == 1, (mode, b)
    found = []
    for base in (b, out[0]):
        for k in itertools.product((-2, -1, 0, 1, 2), repeat=3):
            found.append(base + 2 * np.pi * np.array(k))
    return found


def reference_wrap(mode: str, a: np.ndarray, b: np.ndarray) -> bool:
    """The rule: both keys inside -pi..pi, and an equivalent triple of `b` at least WRAP_MARGIN
    closer to `a` (sum of absolute differences) than `b`."""
    limit = np.pi + polyscrew.RANGE_TOLERANCE
    if np.abs(a).max() > limit or np.abs(b).max() > limit:
        return False
    nearest = min(np.abs(e - a).sum() for e in equivalents(mode, b))
    return nearest <= np.abs(b - a).sum() - polyscrew.WRAP_MARGIN


@pytest.mark.parametrize("mode", EULER)
def test_euler_flips_follow_the_rule_on_random_keys(mode):
    rng = np.random.default_rng(len(mode) + EULER.index(mode))
    # keys as from matrices (inside -pi..pi), now and then one beyond the range (typed)
    rotations = Rotation.from_rotvec(np.cumsum(rng.normal(0, 1.6, (40, 3)), axis=0))
    # scipy's extrinsic lower-case order applies the first letter first, as Blender's mode;
    # its angles come in the order's letters, Blender stores x, y, z
    angles = rotations.as_euler(mode.lower())
    keys = np.stack([angles[:, mode.index(axis)] for axis in "XYZ"], axis=1)
    np.testing.assert_allclose(reference_matrices(keys, mode), rotations.as_matrix(), atol=1e-12)
    typed = rng.random(40) < 0.15
    keys[typed, 2] += 2 * np.pi
    keys = keys.astype(np.float32).astype(np.float64)  # as Blender stores them
    frames = np.arange(40.0) * 5 + 1
    _, _, _, _, flips = polyscrew.analyse_turns(euler_playback(mode, keys, frames), frames)
    want = [reference_wrap(mode, keys[i], keys[i + 1]) for i in range(39)]
    print(f"{mode}: {sum(want)} of 39 spans are wraps")
    assert flips.tolist() == want
    assert 3 <= sum(want) < 39


def test_three_ways_to_turn():
    z = np.radians([0.0, 111.5, -141.1, 120.0, 400.0])
    keys = np.stack([np.zeros(5), np.zeros(5), z], axis=1)
    frames = np.array([1.0, 11.0, 21.0, 31.0, 41.0])
    pb = euler_playback("XYZ", keys, frames)
    found = {t: polyscrew.analyse_turns(pb, frames, t) for t in ("AUTO", "BLENDER", "SHORTEST")}
    for turns, (held, pops, turn, inserted, flips) in found.items():
        assert flips.tolist() == [False, True, True, False], turns
        np.testing.assert_allclose(np.degrees(turn), [111.5, 252.6, 261.1, 280.0], atol=1e-3)
        # analyse_spans is analyse_turns without the flips
        spans = polyscrew.analyse_spans(pb, frames, turns)
        assert all(np.array_equal(x, y) for x, y in zip(spans, (held, pops, turn, inserted)))

    def per_span(inserted):
        return np.histogram(inserted, bins=frames)[0].tolist()

    # Auto: the typed spin 120 -> 400 (280 degrees) in 7 pieces, the wraps the short way
    assert per_span(found["AUTO"][3]) == [0, 0, 0, 6]
    assert per_span(found["BLENDER"][3]) == [2, 5, 5, 6]
    assert per_span(found["SHORTEST"][3]) == [0, 0, 0, 0]
    assert np.array_equal(polyscrew.analyse_spans(pb, frames)[3], found["AUTO"][3])  # default Auto
    with pytest.raises(ValueError, match="analyse_turns: turns: \"LONGEST\" is not one of AUTO, BLENDER, SHORTEST"):
        polyscrew.analyse_turns(pb, frames, "LONGEST")


def test_quaternion_sign_flips():
    q = np.array([[1.0, 0.0, 0.0, 0.0], [-0.6, 0.0, 0.0, -0.8], [-0.2, 0.0, 0.1, -0.95], [0.3, 0.0, 0.0, 0.9]])
    frames = np.array([1.0, 11.0, 21.0, 31.0])
    curves = [linear(frames, q[:, i]) for i in range(4)]
    pb = playback(curves, [("rotation_quaternion", i) for i in range(4)], "QUATERNION")
    _, _, turn, inserted, flips = polyscrew.analyse_turns(pb, frames)
    assert flips.tolist() == [True, False, True]
    assert len(inserted) == 0
    # Blender's lerp of the components turns the long way: 2 acos(q0 . q1 / |q0| |q1|)
    unit = q / np.linalg.norm(q, axis=1, keepdims=True)
    long = 2 * np.arccos(np.sum(unit[:-1] * unit[1:], axis=1))
    _, _, turn, inserted, _ = polyscrew.analyse_turns(pb, frames, "BLENDER")
    np.testing.assert_allclose(turn, long, atol=1e-5)
    # the two flips are spins now, the span between them (turning more than 45 degrees) their neighbour
    assert turn[0] > polyscrew.WIND_LIMIT and turn[2] > polyscrew.WIND_LIMIT and turn[1] > polyscrew.WIND_STEP
    assert len(inserted) == sum(int(np.ceil(t / polyscrew.WIND_STEP)) - 1 for t in turn)


@pytest.mark.parametrize("mode", ("QUATERNION", "AXIS_ANGLE", "ZXY"))
def test_departure_against_scipy(mode):
    rng = np.random.default_rng(7)
    frames = np.array([1.0, 9.0, 20.0, 31.0])
    w = 3 if mode == "ZXY" else 4
    columns = [("location", i) for i in range(3)] + [("rotation_euler" if w == 3 else f"rotation_{mode.lower()}", i) for i in range(w)]
    curves = [linear(frames, rng.normal(size=4) * 2) for _ in columns]
    pb = playback(curves, columns, mode)
    t = np.linspace(0.0, 35.0, 141)
    location, rotation, _ = pb.channels(t)
    ours_location = location + rng.normal(size=location.shape)
    ours_rotation = rng.normal(size=rotation.shape) * 2
    distance, angle = pb.departure(t, ours_location, ours_rotation)
    np.testing.assert_allclose(distance, np.linalg.norm(ours_location - location, axis=1), rtol=1e-12)
    relative = Rotation.from_matrix(reference_matrices(rotation, mode)).inv() * Rotation.from_matrix(
        reference_matrices(ours_rotation, mode))
    np.testing.assert_allclose(angle, relative.magnitude(), atol=1e-9)
    same_distance, same_angle = pb.departure(t, location, rotation)
    assert same_distance.max() == 0.0 and same_angle.max() < 1e-7
    with pytest.raises(ValueError, match=r"Playback.departure: rotation: expected shape"):
        pb.departure(t, location, rotation[:, :2])
    with pytest.raises(ValueError, match=r"Playback.departure: location: expected shape"):
        pb.departure(t[1:], location, rotation)
    bad = rotation.copy()
    bad[3, 1] = np.nan
    with pytest.raises(ValueError, match="Playback.departure"):
        pb.departure(t, location, bad)
