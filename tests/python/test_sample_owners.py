"""Smooth Motion's sampling of many owners in one call (issue 27): `sampling.sample_many`
(one `polyscrew.sample_owners` call per rotation mode) gives, to the bit, what
`sampling.sample` gives owner by owner (its `timed_frames`, `sample_channels`,
`sample_vectors` and `rotation_channels` calls per piece and hold): every rotation mode, holds
and pops, closed motions, scale keyed on some axes, timings Smooth, Linear and Keys (with and
without Blender's playback), and the owners the core refuses (None, where `sample` raises).
"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

import pure_layer
from test_intent import playback

sampling = pure_layer.module("sampling")
keyed = pure_layer.module("keyed")
MODES = ("QUATERNION", "AXIS_ANGLE", "XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX")


def random_motion(rng, mode, closed=False, holds=False, scaled=False, played=True):
    """A keyed motion in `mode`: 2 to 7 keys turning up to 2.5 radians a span, some spans
    held (a hold popping at its end now and then), scale keyed on some axes; Blender's
    playback of its location keys (Bezier) when `played`."""
    k = int(rng.integers(3 if holds else 2, 8))
    frames = np.cumsum(rng.uniform(1.0, 9.0, k)) + rng.uniform(-5.0, 5.0)
    poses = np.tile(np.eye(4), (k, 1, 1))
    poses[:, :3, :3] = Rotation.from_rotvec(rng.normal(size=(k, 3)) * rng.uniform(0.2, 2.5)).as_matrix()
    poses[:, :3, 3] = rng.normal(size=(k, 3)) * 2.0
    held = pops = None
    if holds:
        held = rng.random(k - 1) < 0.4
        held[int(rng.integers(0, k - 1))] = True
        for i in np.flatnonzero(held):  # a held span keeps its first key's pose
            poses[i + 1] = poses[i]
        pops = held & (rng.random(k - 1) < 0.5)
        pops = np.append(pops, False)
    scale_axes = rng.random(3) < 0.6 if scaled else np.zeros(3, bool)
    scales = np.where(scale_axes, rng.uniform(0.5, 2.0, (k, 3)), rng.choice([1.0, -2.0, 0.0], 3))
    source = None
    if played:
        curves = [
            [dict(co=(f, v), handle_left=(f - 1.0, v), handle_right=(f + 1.0, v)) for f, v in zip(frames, poses[:, i, 3])]
            for i in range(3)
        ]
        source = SimpleNamespace(playback=playback(curves, [("location", i) for i in range(3)], mode=mode))
    period = float(frames[-1] - frames[0] + rng.uniform(1.0, 6.0)) if closed else None
    return keyed.KeyedMotion(
        frames=frames, poses=poses, scales=scales, scale_axes=scale_axes, rotation_mode=mode,
        first_rotation=polyscrew.rotation_channels(poses[:1], mode)[0], closed=closed, period=period, cyclic=closed,
        size=float(rng.uniform(0.3, 3.0)), source=source, held=held, pops=pops,
    )


def owners(rng, count):
    """`count` (motion, frames, previous) items: every mode, open and closed, with and without
    holds, scale and playback; frames before, between, on and after the keys."""
    items = []
    for i in range(count):
        mode = MODES[i % len(MODES)]
        closed = i % 5 == 3
        motion = random_motion(rng, mode, closed=closed, holds=not closed and i % 3 == 1, scaled=i % 4 != 0,
                               played=i % 7 != 6)
        lo, hi = motion.frames[0] - 3.0, motion.frames[-1] + 3.0
        frames = np.union1d(np.arange(lo, hi, rng.choice([0.5, 1.0, 0.3])), motion.frames)
        previous = keyed.continued(mode, motion.first_rotation)
        items.append((motion, frames, previous))
    return items


def same(a, b) -> bool:
    if a is None or b is None:
        return a is None and b is None
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


@pytest.mark.parametrize("timing", ["smooth", "linear", "keys"])
@pytest.mark.parametrize("scheme", ["four_point", "jarek"])
def test_sample_many_is_sample_owner_by_owner_to_the_bit(timing, scheme):
    rng = np.random.default_rng(27 + len(timing) + len(scheme))
    items = owners(rng, 48)
    options = SimpleNamespace(scheme=scheme, levels=3, timing=timing, method="SCREW")
    got = sampling.sample_many(items, options)
    refused = 0
    for (motion, frames, previous), batched in zip(items, got):
        try:
            want = sampling.sample(motion, frames, options, channels=True, previous=previous, played=True)
        except ValueError:
            assert batched is None, "the core refused this owner alone: the batch must tell it"
            refused += 1
            continue
        assert batched is not None, f"{motion.rotation_mode}: sampled alone, refused in the batch"
        for name in ("location", "rotation", "scales", "constant", "played"):
            assert same(getattr(batched, name), getattr(want, name)), (
                f"{name} differs: mode {motion.rotation_mode}, closed {motion.closed}, held {motion.held}"
            )
        assert batched.poses is None
    # (timing Keys samples the owners without a playback too: size and poses suffice, no rows
    # played; the refusals are test_sample_many_tells_the_owners_the_core_refuses)
    held = sum(m.held is not None and m.held.any() for m, _, _ in items)
    popped = sum(m.pops is not None and m.pops.any() for m, _, _ in items)
    assert held >= 5 and popped >= 2 and refused == 0
    print(f"timing {timing}, {scheme}: {len(items)} owners ({held} with holds, {popped} popping) bit for bit")


@pytest.mark.parametrize("timing", ["smooth", "linear", "keys"])
def test_sample_many_poses_are_sample_owner_by_owner_to_the_bit(timing):
    """With `poses` (Insert Key on Motion's sampling): the rigid poses and scales `sample`
    gives owner by owner (`polyscrew.sample` per piece, a hold its key's own matrix), every
    mode, holds, cycles, to the bit."""
    rng = np.random.default_rng(270 + len(timing))
    items = owners(rng, 48)
    options = SimpleNamespace(scheme="four_point", levels=3, timing=timing, method="SCREW")
    got = sampling.sample_many(items, options, poses=True)
    for (motion, frames, _), batched in zip(items, got):
        want = sampling.sample(motion, frames, options)
        assert batched is not None, f"{motion.rotation_mode}: sampled alone, refused in the batch"
        for name in ("poses", "scales", "constant"):
            assert same(getattr(batched, name), getattr(want, name)), (
                f"{name} differs: mode {motion.rotation_mode}, closed {motion.closed}, held {motion.held}"
            )
        assert batched.location is None and batched.rotation is None and batched.played is None
    assert sum(m.held is not None and m.held.any() for m, _, _ in items) >= 5


def test_sample_many_tells_the_owners_the_core_refuses():
    """A closed motion without a period (the core refuses it: `Error::Period`) and a motion
    sampled beyond the working range come back None, the others sampled as alone."""
    rng = np.random.default_rng(5)
    items = owners(rng, 6)
    bad = random_motion(rng, "XYZ", closed=True)
    bad.period = None
    far = random_motion(rng, "QUATERNION")
    items.insert(2, (bad, np.arange(0.0, 10.0), None))
    items.insert(4, (far, np.array([0.0, 1e301]), None))
    options = SimpleNamespace(scheme="jarek", levels=2, timing="keys", method="SCREW")
    got = sampling.sample_many(items, options)
    assert got[2] is None and got[4] is None
    for i in (2, 4):
        with pytest.raises(ValueError):
            motion, frames, previous = items[i]
            sampling.sample(motion, frames, options, channels=True, previous=previous, played=True)
    for (motion, frames, previous), batched in [(items[i], got[i]) for i in range(len(items)) if i not in (2, 4)]:
        want = sampling.sample(motion, frames, options, channels=True, previous=previous, played=True)
        assert same(batched.rotation, want.rotation) and same(batched.played, want.played)


def test_sample_many_makes_one_call_per_rotation_mode(monkeypatch):
    """The point of it: 40 owners in 2 rotation modes, 2 polyscrew calls (owner by owner:
    one `timed_frames` and one `sample_channels` per piece, `sample_vectors` for scale)."""
    rng = np.random.default_rng(40)
    items = []
    for i in range(40):
        motion = random_motion(rng, "XYZ" if i % 2 else "QUATERNION", holds=i % 3 == 0, scaled=True)
        items.append((motion, np.arange(motion.frames[0], motion.frames[-1] + 0.5), None))
    calls = []
    for name in ("sample_owners", "sample_channels", "sample_vectors", "timed_frames", "rotation_channels", "sample"):
        original = getattr(polyscrew, name)

        def counted(*args, _name=name, _original=original, **kwargs):
            calls.append(_name)
            return _original(*args, **kwargs)

        monkeypatch.setattr(sampling.polyscrew, name, counted)
    options = SimpleNamespace(scheme="jarek", levels=3, timing="keys", method="SCREW")
    got = sampling.sample_many(items, options)
    assert all(g is not None for g in got)
    assert calls == ["sample_owners", "sample_owners"], calls
    calls.clear()
    for motion, frames, previous in items:
        sampling.sample(motion, frames, options, channels=True, previous=previous, played=True)
    print(f"40 owners: 2 calls batched, {len(calls)} owner by owner")
    assert len(calls) >= 80


def test_sample_many_leaves_to_sample_what_it_cannot_batch():
    """Frames out of order (`sample` sorts them) and a batch over the memory budget come back
    None: the caller samples those owners alone, as before."""
    rng = np.random.default_rng(9)
    items = owners(rng, 4)
    motion, frames, previous = items[1]
    items[1] = (motion, frames[::-1].copy(), previous)
    options = SimpleNamespace(scheme="jarek", levels=2, timing="smooth", method="SCREW")
    got = sampling.sample_many(items, options)
    assert got[1] is None and all(g is not None for i, g in enumerate(got) if i != 1)
    budget = polyscrew.memory_budget()
    try:
        polyscrew.set_memory_budget(64)
        assert sampling.sample_many(items, options) == [None] * 4
    finally:
        polyscrew.set_memory_budget(budget)
    assert polyscrew.memory_budget() == budget


def test_sample_owners_refuses_tables_that_do_not_fit_with_a_value_error():
    """Counts and segments that do not fit the arrays are a ValueError naming the function,
    never a panic: counts whose sum wraps around (each one a valid int64), negative counts,
    segments past an owner's keys or frames, overlapping segments, a `previous` of the wrong
    shape, a `playbacks` list of the wrong length."""
    big = 2**63 - 1
    poses = np.tile(np.eye(4), (3, 1, 1))
    key_frames = np.array([1.0, 2.0, 3.0])
    frames = np.array([1.0, 2.0])
    one = np.array([[0, 2, 0, 2]])
    cases = {
        "counts wrapping": (np.array([[big, 1, 1], [big, 1, 0], [5, 0, 0]]), one, {}),
        "negative count": (np.array([[-1, 2, 1], [4, 0, 0]]), one, {}),
        "keys short": (np.array([[2, 2, 1]]), one, {}),
        "segment past the keys": (np.array([[3, 2, 1]]), np.array([[0, 3, 0, 2]]), {}),
        "segment past the frames": (np.array([[3, 2, 1]]), np.array([[0, 2, 0, 3]]), {}),
        "segments overlapping": (np.array([[3, 2, 2]]), np.array([[0, 2, 0, 1], [0, 2, 0, 1]]), {}),
        "previous shape": (np.array([[3, 2, 1]]), one, {"previous": np.zeros((2, 3))}),
        "playbacks length": (np.array([[3, 2, 1]]), one, {"playbacks": [None, None]}),
    }
    for name, (counts, segments, extra) in cases.items():
        try:
            got = polyscrew.sample_owners(poses, key_frames, frames, counts, segments, "XYZ", **extra)
        except ValueError as err:
            assert "sample_owners" in str(err), (name, err)
            continue
        # (a batch the core refuses owner by owner is told by the status, not raised)
        assert list(got[-1]) == [-1], (name, got[-1])
    fitting = polyscrew.sample_owners(poses, key_frames, frames, np.array([[3, 2, 1]]), one, "XYZ")
    assert list(fitting[-1]) == [0] and np.all(np.isfinite(fitting[1]))
