"""Many owners' keys read in one call (issue 27): `polyscrew.read_owners` gives, to the bit,
what `keys.read` computes owner by owner from its packed curves: `Playback(...)`, the union of
the curves' key frames (`keyed._union`), `Playback.channels` there (or the key values of a
capture, `key_values`), `keyed.compose(location, keyed.rotation_matrices(rotation, mode))`,
`analyse_turns` under every Turns choice and `Playback.channels` at the frames it inserts.
Random owners in all 8 rotation modes: holds
and pops (CONSTANT keys), spins over half a turn, Euler wraps, quaternion sign flips and
non-normalised quaternions, scale keyed on some axes, connected bones (no location), owners
sharing curves with other values, and owners the core refuses (a NaN key, keys out of time
order, one key frame, a keyed scale of 0): refused in the batch exactly when the calls alone
raise, without disturbing the others.
"""

from __future__ import annotations

import numpy as np
import polyscrew
import pytest

import pure_layer
from test_intent import CODE, MODES, rotation_path, width

keyed = pure_layer.module("keyed")
TURNS = ("AUTO", "BLENDER", "SHORTEST")


def f32(values) -> np.ndarray:
    """Values Blender stores (float32), widened."""
    return np.asarray(values, dtype=np.float32).astype(np.float64)


def random_owner(rng, o: int) -> dict:
    """An owner's curves (list of (column, keys as (K, 2) co and interpolation codes)) and
    options; `o` picks the mode and the kind of trouble."""
    mode = MODES[o % len(MODES)]
    w = width(mode)
    k = int(rng.integers(2, 7))
    frames = f32(np.cumsum(rng.uniform(1.0, 8.0, k)) + rng.uniform(-4.0, 4.0))
    capture = o % 6 == 5  # every curve keyed on every key frame
    located = o % 9 != 4  # a connected bone's location is not read
    columns = [("location", i) for i in range(3) if located and rng.random() < 0.7]
    columns += [(rotation_path(mode), i) for i in range(w) if rng.random() < 0.85 or i == 0]
    columns += [("scale", i) for i in range(3) if rng.random() < 0.4]
    rng.shuffle(columns)
    curves = []
    for prop, index in columns:
        mine = frames if capture or rng.random() < 0.6 else np.sort(rng.choice(frames, int(rng.integers(1, k + 1)), replace=False))
        if prop == "location":
            values = rng.normal(size=len(mine)) * 2.0
        elif prop == "scale":
            values = rng.uniform(0.4, 2.0, len(mine))
        elif mode == "QUATERNION":
            values = rng.normal(size=len(mine)) * (1.0 if index == 0 else 0.6)
            if rng.random() < 0.4:
                values[1::2] *= -1.0  # sign flips
        elif mode == "AXIS_ANGLE" and index > 0:
            values = rng.normal(size=len(mine))
        else:  # Euler angles (and the axis-angle angle): wraps, spins, holds
            step = rng.choice([0.5, 2.5, 4.0, 7.0])
            values = np.cumsum(rng.uniform(-step, step, len(mine)))
            if rng.random() < 0.3:
                values = (values + np.pi) % (2 * np.pi) - np.pi
        interpolation = rng.choice([CODE["BEZIER"], CODE["LINEAR"], CODE["CONSTANT"]], len(mine), p=[0.6, 0.25, 0.15])
        if o % 7 == 0:  # held spans: every channel CONSTANT (a pop at each key)
            interpolation[:] = CODE["CONSTANT"]
        if rng.random() < 0.3 and len(mine) > 2:  # a held span: equal keys, flat handles
            values[1] = values[0]
        curves.append(((prop, index), f32(mine), f32(values), interpolation))
    statics = rng.normal(size=3 + w + 3)
    statics[3 + w :] = rng.uniform(0.5, 1.5, 3)
    trouble = o % 17
    if trouble == 3:
        curves[0][2][-1] = np.nan  # a NaN key
    elif trouble == 7 and len(curves[0][1]) > 1:
        curves[0][1][[0, -1]] = curves[0][1][[-1, 0]]  # keys out of time order
    elif trouble == 11:
        curves = [(c, fr[:1], v[:1], i[:1]) for c, fr, v, i in curves]
        curves = [c for c in curves if len(c[1]) and c[1][0] == curves[0][1][0]]  # one key frame
    elif trouble == 13:
        scaled = [c for c in curves if c[0][0] == "scale"]
        if scaled:
            scaled[0][2][0] = 0.0  # a keyed scale of 0
    return dict(
        mode=mode, curves=curves, statics=f32(statics), located=located, key_values=capture or o % 4 == 1,
        turns=None if o % 5 == 2 else TURNS[o % 3],
    )


def packed_of(curves) -> dict:
    """evaluate_fcurves' arguments of (column, frames, values, interpolation) curves."""
    co = np.concatenate([np.stack([fr, v], axis=1) for _, fr, v, _ in curves]).reshape(-1, 2)
    return dict(
        offsets=np.cumsum([0] + [len(fr) for _, fr, _, _ in curves]).astype(np.int64),
        co=co,
        handle_left=co - [1.0, 0.0],
        handle_right=co + [1.0, 0.0],
        interpolation=np.concatenate([i for *_, i in curves]).astype(np.int64),
        easing=np.zeros(len(co), dtype=np.int64),
    )


def alone(owner: dict):
    """What keys.read computes from the owner's curves, call after call; None where one
    raises (or keys.read refuses the values)."""
    mode, curves = owner["mode"], owner["curves"]
    w = width(mode)
    columns = [c for c, *_ in curves]
    try:
        playback = polyscrew.Playback(
            channels=columns, unkeyed=owner["statics"], mode=mode, located=owner["located"], **packed_of(curves)
        )
    except ValueError:
        return None
    frames = keyed._union([fr for _, fr, _, _ in curves])
    if len(frames) < 2:
        return None
    if owner["key_values"] and all(np.array_equal(fr, frames) for _, fr, _, _ in curves):
        rows = np.tile(owner["statics"], (len(frames), 1))
        start = {"location": 0, rotation_path(mode): 3, "scale": 3 + w}
        for (prop, index), _, values, _ in curves:
            rows[:, start[prop] + index] = values
        if not owner["located"]:
            rows[:, :3] = 0.0
        location, rotation, scale = rows[:, :3], rows[:, 3 : 3 + w], rows[:, 3 + w :]
    else:
        try:
            location, rotation, scale = playback.channels(frames)
        except ValueError:
            return None
    axes = np.array([("scale", i) in columns for i in range(3)])
    if not all(np.isfinite(a).all() for a in (location, rotation, scale)) or ((scale <= 0.0) & axes).any():
        return None
    poses = keyed.compose(location, keyed.rotation_matrices(rotation, mode))
    spans = None
    if owner["turns"] is not None:
        try:
            spans = polyscrew.analyse_turns(playback, frames, owner["turns"])
            if len(spans[3]):  # (keys.read plays the frames added to spins)
                spans += (playback.channels(spans[3]),)
        except ValueError:
            return None
    return playback, frames, location, rotation, scale, poses, spans


def same(a, b) -> bool:
    a, b = np.ascontiguousarray(a), np.ascontiguousarray(b)
    return a.shape == b.shape and a.dtype == b.dtype and a.tobytes() == b.tobytes()


def batch(owners: list[dict], shared: dict | None = None):
    """`read_owners` of `owners`, their curves packed one owner after the other (`shared`:
    owner -> the owner whose curves it plays, packed once)."""
    shared = shared or {}
    packed_owners = [o for o in range(len(owners)) if o not in shared]
    starts, at = {}, 0
    for o in packed_owners:
        starts[o] = at
        at += len(owners[o]["curves"])
    curves = [c for o in packed_owners for c in owners[o]["curves"]]
    ranges = [(starts[shared.get(o, o)], len(owners[o]["curves"])) for o in range(len(owners))]
    unkeyed = np.zeros((len(owners), 10))
    for o, owner in enumerate(owners):
        w = width(owner["mode"])
        unkeyed[o, : 3 + w] = owner["statics"][: 3 + w]
        unkeyed[o, 7:] = owner["statics"][3 + w :]
    return polyscrew.read_owners(
        np.array(ranges, dtype=np.int64), [c for c, *_ in curves], unkeyed, [o["mode"] for o in owners],
        located=np.array([o["located"] for o in owners], dtype=np.int64),
        key_values=np.array([o["key_values"] for o in owners], dtype=np.int64),
        turns=[o["turns"] for o in owners], **packed_of(curves),
    )


def test_read_owners_is_each_owner_read_alone_to_the_bit():
    rng = np.random.default_rng(2727)
    owners = [random_owner(rng, o) for o in range(160)]
    # linked duplicates: owners playing another owner's curves with their own values
    shared = {}
    for o in range(160, 176):
        twin = dict(owners[(o * 7) % 160], statics=f32(rng.normal(size=3 + width(owners[(o * 7) % 160]["mode"]) + 3)))
        twin["statics"][3 + width(twin["mode"]) :] = f32(rng.uniform(0.5, 1.5, 3))
        shared[o] = (o * 7) % 160
        owners.append(twin)
    playbacks, frames, counts, location, rotation, scale, poses, spans, status = batch(owners, shared)
    held, pops, turn, flips, inserted, inserted_counts, at_location, at_rotation, at_scale = spans
    key_at = np.concatenate(([0], np.cumsum(counts)))
    span_at = np.concatenate(([0], np.cumsum(np.where(status == 1, np.maximum(counts - 1, 0), 0))))
    inserted_at = np.concatenate(([0], np.cumsum(inserted_counts)))
    seen = dict(refused=0, spins=0, flips=0, holds=0, pops=0, captures=0, unnormalised=0)
    for o, owner in enumerate(owners):
        want = alone(owner)
        if want is None:
            assert status[o] == -1 and playbacks[o] is None and counts[o] == 0, f"owner {o}: refused alone, not in the batch"
            seen["refused"] += 1
            continue
        assert status[o] == (owner["turns"] is not None), f"owner {o}: read alone, status {status[o]} in the batch"
        playback, want_frames, want_location, want_rotation, want_scale, want_poses, want_spans = want
        k0, k1 = key_at[o], key_at[o + 1]
        w = width(owner["mode"])
        got = (frames[k0:k1], location[k0:k1], rotation[k0:k1, :w], scale[k0:k1], poses[k0:k1])
        for name, a, b in zip(("frames", "location", "rotation", "scale", "poses"), got,
                              (want_frames, want_location, want_rotation, want_scale, want_poses)):
            assert same(a, b), f"owner {o} ({owner['mode']}): {name} differs"
        assert np.isnan(rotation[k0:k1, w:]).all()
        assert same(playbacks[o].channels(want_frames)[1], playback.channels(want_frames)[1])
        if want_spans is not None:
            s0, s1 = span_at[o], span_at[o + 1]
            i0, i1 = inserted_at[o], inserted_at[o + 1]
            mine = (held[s0:s1], pops[s0:s1], turn[s0:s1], inserted[i0:i1], flips[s0:s1])
            for name, a, b in zip(("held", "pops", "turn", "inserted", "flips"), mine, want_spans):
                assert same(a, b), f"owner {o} ({owner['mode']}, {owner['turns']}): {name} differs"
            played = (at_location[i0:i1], at_rotation[i0:i1, :w], at_scale[i0:i1])
            if len(want_spans[3]):
                for name, a, b in zip(("location", "rotation", "scale"), played, want_spans[5]):
                    assert same(a, b), f"owner {o}: the playback's {name} at the inserted frames differs"
            assert all(len(p) == len(want_spans[3]) for p in played)
            seen["spins"] += int(len(want_spans[3]) > 0)
            seen["flips"] += int(want_spans[4].any())
            seen["holds"] += int(want_spans[0].any())
            seen["pops"] += int(want_spans[1].any())
        seen["captures"] += int(owner["key_values"] and all(np.array_equal(fr, want_frames) for _, fr, _, _ in owner["curves"]))
        if owner["mode"] == "QUATERNION":
            seen["unnormalised"] += int(np.abs(np.linalg.norm(want_rotation, axis=1) - 1.0).max() > 1e-3)
    print(seen)
    assert seen["refused"] >= 8 and seen["spins"] >= 5 and seen["flips"] >= 5 and seen["holds"] >= 5
    assert seen["pops"] >= 2 and seen["captures"] >= 5 and seen["unnormalised"] >= 5


def test_read_owners_plays_each_owner_as_often_as_reading_it_alone():
    """A capture read from its key values plays nothing; otherwise the key frames once and
    what `analyse_turns` plays (the same counts as the calls alone)."""
    rng = np.random.default_rng(99)
    owners = [random_owner(rng, o) for o in range(48)]
    playbacks, *_ , status = batch(owners)
    for o, owner in enumerate(owners):
        want = alone(owner)
        if want is not None:
            assert playbacks[o].rows_evaluated == want[0].rows_evaluated, f"owner {o}"


def test_read_owners_refuses_arrays_that_do_not_fit():
    rng = np.random.default_rng(5)
    owners = [random_owner(rng, o) for o in (0, 1)]
    good = batch(owners)
    assert list(good[-1]) == [1, 1]
    curves = owners[0]["curves"] + owners[1]["curves"]
    args = dict(located=None, key_values=None, turns=None, **packed_of(curves))
    columns = [c for c, *_ in curves]
    with pytest.raises(ValueError, match="curves"):
        polyscrew.read_owners(np.array([[0, len(curves) + 1]]), columns, np.zeros((1, 10)), ["QUATERNION"], **args)
    with pytest.raises(ValueError, match="unkeyed"):
        polyscrew.read_owners(np.array([[0, 1]]), columns, np.zeros((1, 9)), ["XYZ"], **args)
    with pytest.raises(ValueError, match="channels"):
        polyscrew.read_owners(np.array([[0, 1]]), columns[:-1], np.zeros((1, 10)), ["XYZ"], **args)
    with pytest.raises(ValueError, match="negative"):
        polyscrew.read_owners(np.array([[-1, 1]]), columns, np.zeros((1, 10)), ["XYZ"], **args)
    with pytest.raises(ValueError):
        polyscrew.read_owners(np.array([[0, 1]]), columns, np.zeros((1, 10)), ["XYZ"], turns=["SIDEWAYS"],
                              **packed_of(curves))
