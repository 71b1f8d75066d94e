"""Smooth Motion's departure measure for every owner in one call (issue 27):
`polyscrew.measure_departures` is, to the bit, `Playback.measure_departure` called on each
owner in turn (random owners in every rotation mode, located or not, with and without played
rows and key frames, spans measured at `most` frames or at every frame, empty owners), the
add-on's `intent.departures` is `intent.departure` per owner, and what the batch refuses it
refuses naming the owner (part), the add-on then measuring each owner alone."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import polyscrew
import pytest

from pure_layer import module
from test_intent import MODES, playback, random_curves, rotation_path, width

intent = module("intent")


def random_owner(rng, mode: str) -> dict:
    """A playback of random curves in `mode`, a result near it at sorted baked frames (some
    frames departing), the played rows at some of them (NaN elsewhere) and its key frames."""
    keys = np.sort(rng.choice(np.arange(0.0, 60.0), size=int(rng.integers(2, 6)), replace=False))
    columns = [("location", i) for i in range(3)] + [(rotation_path(mode), i) for i in range(width(mode))]
    located = bool(rng.random() < 0.8)
    pb = playback(random_curves(rng, keys, len(columns)), columns, mode, located=located)
    t = int(rng.choice([0, 1, 5, 40, 150]))
    step = rng.choice([0.25, 0.5, 1.0])
    frames = np.unique(np.concatenate([keys, keys[0] - 3.0 + step * np.arange(t)]))
    location, rotation, _ = pb.channels(frames)
    location = location + rng.normal(scale=rng.choice([1e-4, 0.05, 0.5]), size=location.shape)
    rotation = rotation + rng.normal(scale=rng.choice([1e-4, 0.05, 0.3]), size=rotation.shape)
    played = None
    if rng.random() < 0.5:
        played = np.hstack(pb.channels(frames)[:2])
        played[rng.random(len(frames)) < 0.4] = np.nan
    return dict(
        playback=pb, mode=mode, frames=frames, location=location, rotation=rotation, played=played,
        key_frames=keys if rng.random() < 0.7 else None, degrees=float(rng.uniform(0.5, 10.0)),
        distance=float(rng.uniform(0.01, 0.3)),
    )


def alone(owner: dict, most: int):
    return owner["playback"].measure_departure(
        owner["frames"], owner["location"], owner["rotation"], degrees=owner["degrees"], distance=owner["distance"],
        played=owner["played"], key_frames=owner["key_frames"], most=most,
    )


def batch(owners: list[dict], most: int, keyed: bool = True):
    """`measure_departures` of `owners`: their rows one after the other (rotation and played
    rows flat, row-major, each in its owner's width; NaN played rows for an owner without)."""
    counts = np.array([len(o["frames"]) for o in owners], dtype=np.int64)
    played = [np.full(len(o["frames"]) * (3 + width(o["mode"])), np.nan) if o["played"] is None else o["played"].ravel()
              for o in owners]
    given = [o["key_frames"] for o in owners if o["key_frames"] is not None]
    return polyscrew.measure_departures(
        [o["playback"] for o in owners], np.concatenate([o["frames"] for o in owners]), counts,
        np.concatenate([o["location"] for o in owners]), np.concatenate([o["rotation"].ravel() for o in owners]),
        degrees=np.array([o["degrees"] for o in owners]), distances=np.array([o["distance"] for o in owners]),
        played=np.concatenate(played) if any(o["played"] is not None for o in owners) else None,
        key_frames=np.concatenate(given or [np.zeros(0)]) if keyed else None,
        key_counts=np.array([-1 if o["key_frames"] is None else len(o["key_frames"]) for o in owners])
        if keyed else None,
        most=most,
    ), np.cumsum(counts), counts


def test_measure_departures_is_measure_departure_per_owner(rng):
    seen = set()
    for _ in range(40):
        owners = [random_owner(rng, MODES[int(i)]) for i in rng.integers(0, len(MODES), int(rng.integers(1, 9)))]
        most = int(rng.choice([2, 3, 8, 64]))
        keyed = bool(rng.random() < 0.8)
        if not keyed:
            for o in owners:
                o["key_frames"] = None
        (degrees, distances, over), ends, counts = batch(owners, most, keyed)
        assert degrees.shape == distances.shape == (len(owners),) and over.shape == (int(counts.sum()),)
        for o, d, x, end, c in zip(owners, degrees, distances, ends, counts):
            want_d, want_x, want_over = alone(o, most)
            assert np.float64(want_d).tobytes() == d.tobytes() and np.float64(want_x).tobytes() == x.tobytes()
            assert np.array_equal(over[end - c : end], want_over)
            seen.add((o["mode"], o["played"] is not None, o["key_frames"] is not None, bool(want_over.any())))
    # every mode with and without played rows and key frames, frames over and not
    assert {s[0] for s in seen} == set(MODES)
    assert {s[1:] for s in seen} == {(p, k, v) for p in (True, False) for k in (True, False) for v in (True, False)}


def test_the_add_ons_departures_are_departure_per_owner(rng):
    items = []
    for i, mode in enumerate(MODES * 3):
        o = random_owner(rng, mode)
        size = float(rng.uniform(0.2, 3.0))
        location = None if i % 4 == 1 else o["location"]
        items.append((SimpleNamespace(playback=o["playback"]), size, o["frames"], location, o["rotation"],
                      o["key_frames"], o["played"]))
    got = intent.departures(items)
    assert len(got) == len(items)
    for found, item in zip(got, items):
        want = intent.departure(*item)
        assert (found.degrees, found.distance) == (want.degrees, want.distance)
        assert type(found.degrees) is type(want.degrees) is float
        assert found.frames.tobytes() == want.frames.tobytes()
    assert any(len(f.frames) for f in got) and not all(len(f.frames) for f in got)
    assert intent.departures([]) == []


def test_refusals_name_the_owner_and_the_add_on_measures_it_alone(rng):
    owners = [random_owner(rng, mode) for mode in ("XYZ", "QUATERNION", "AXIS_ANGLE")]
    for o in owners:
        o["key_frames"] = o["key_frames"] if o["key_frames"] is not None else o["frames"][:1]
    owners[2]["frames"] = np.concatenate([owners[2]["frames"], [99.0]])
    owners[2]["location"] = np.vstack([owners[2]["location"], [np.nan, 0.0, 0.0]])
    owners[2]["rotation"] = np.vstack([owners[2]["rotation"], [1.0, 0.0, 0.0, 0.0]])  # (axis-angle)
    if owners[2]["played"] is not None:
        owners[2]["played"] = np.vstack([owners[2]["played"], np.full(7, np.nan)])
    with pytest.raises(ValueError, match=r"measure_departures: .*part 2"):
        batch(owners, 8)
    with pytest.raises(ValueError) as alone_error:
        alone(owners[2], 64)
    items = [(SimpleNamespace(playback=o["playback"]), 1.0, o["frames"], o["location"], o["rotation"],
              o["key_frames"], o["played"]) for o in owners]
    with pytest.raises(ValueError) as added:
        intent.departures(items)
    assert str(added.value) == str(alone_error.value)  # (today's message: the owner measured alone)
    ok, _, _ = owners
    frames, loc, rot = ok["frames"], ok["location"], ok["rotation"]
    pb = [ok["playback"]]
    flat = rot.ravel()  # (an Euler owner: 3 numbers a row)
    d = dict(degrees=[5.0], distances=[0.1])
    with pytest.raises(ValueError, match="counts"):
        polyscrew.measure_departures(pb, frames, [len(frames) + 1], loc, flat, **d)
    with pytest.raises(ValueError, match="key_frames and key_counts"):
        polyscrew.measure_departures(pb, frames, [len(frames)], loc, flat, key_frames=[1.0], **d)
    with pytest.raises(ValueError, match="key_counts"):
        polyscrew.measure_departures(pb, frames, [len(frames)], loc, flat, key_frames=[1.0], key_counts=[2], **d)
    with pytest.raises(ValueError, match="rotation"):
        polyscrew.measure_departures(pb, frames, [len(frames)], loc, rot, **d)
    with pytest.raises(ValueError, match="distances"):
        polyscrew.measure_departures(pb, frames, [len(frames)], loc, flat, degrees=[5.0], distances=[0.1, 0.2])
    with pytest.raises(TypeError, match="playbacks"):
        polyscrew.measure_departures([None], frames, [len(frames)], loc, flat, **d)
