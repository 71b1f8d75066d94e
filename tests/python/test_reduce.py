"""polyscrew.reduce_keys (key reduction, issue 26) against independent references.

Every result is played back by ``polyscrew.evaluate_fcurves`` (Blender's F-curve evaluation,
bit-identical to ``FCurve.evaluate``, tested against Blender in tests/blender), the channels
composed into poses here with scipy's Rotation in each of Blender's rotation modes (not the
core's composition), and compared with the dense motion: the dense poses at the frames and
pytransform3d's screw interpolation (``conftest.reference_s``) between them, held across
CONSTANT spans. The error of a played pose on a body of radius r is measured as
``|dt| + 2 r sin(theta / 2)`` (the farthest any point within r can be from its place) and
``theta``; both must stay within the tolerance at every frame and at the three subframes the
contract names (1/4, 1/2, 3/4), and are reported at 1/8 steps too.
"""

import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

from conftest import reference_s

MODES = ["QUATERNION", "AXIS_ANGLE", "XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]
MM = 1e-3
DEG = np.pi / 180


# --- motions (numpy and scipy only) ------------------------------------------------------------


def smooth_motion(n, rng, turns=0.5, size=0.5, knots=8):
    """A smooth random rigid motion sampled at n frames: rotation vector and translation
    each a random cubic spline through `knots` random points, (n, 4, 4)."""
    from scipy.interpolate import CubicSpline

    u = np.linspace(0, 1, knots)
    t = np.linspace(0, 1, n)
    rv = CubicSpline(u, rng.normal(0, turns, (knots, 3)))(t)
    tr = CubicSpline(u, rng.normal(0, size, (knots, 3)))(t)
    poses = np.zeros((n, 4, 4))
    poses[:, :3, :3] = Rotation.from_rotvec(rv).as_matrix()
    poses[:, :3, 3] = tr
    poses[:, 3, 3] = 1
    return poses


def screw_motion(n, axis, angle, slide, point):
    """The screw about the line through `point` along `axis`: turn `angle` and slide `slide`
    over the n frames, (n, 4, 4)."""
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    s = np.linspace(0, 1, n)
    poses = np.zeros((n, 4, 4))
    r = Rotation.from_rotvec(axis[None] * (angle * s)[:, None]).as_matrix()
    poses[:, :3, :3] = r
    poses[:, :3, 3] = point - r @ point + axis[None] * (slide * s)[:, None]
    poses[:, 3, 3] = 1
    return poses


def random_rigid(rng, size=3.0):
    g = np.eye(4)
    g[:3, :3] = Rotation.random(random_state=rng.integers(1 << 31)).as_matrix()
    g[:3, 3] = rng.uniform(-size, size, 3)
    return g


# --- playback and the reference ---------------------------------------------------------------


def sample_times(frames, per=4):
    """Every frame and per - 1 evenly spaced subframes between two: ((n-1) per + 1,)."""
    frames = np.asarray(frames, float)
    k = np.arange(per) / per
    inner = (frames[:-1, None] + (frames[1:] - frames[:-1])[:, None] * k[None]).ravel()
    return np.r_[inner, frames[-1]]


def dense_reference(poses, frames, per=4, constant=None):
    """The dense motion at `sample_times(frames, per)`: the poses at frames, the independent
    screw (pytransform3d) between two, the first pose across a CONSTANT span."""
    out = []
    for i in range(len(frames) - 1):
        for k in range(per):
            if k == 0 or (constant is not None and constant[i]):
                out.append(poses[i])
            else:
                out.append(reference_s(poses[i], k / per, poses[i + 1]))
    out.append(poses[-1])
    return np.array(out)


def rotation_of(mode, values):
    """Blender's rotation of channel rows `values` (T, w) in `mode`, by scipy."""
    values = np.asarray(values, float)
    if mode == "QUATERNION":
        return Rotation.from_quat(values[:, [1, 2, 3, 0]]).as_matrix()
    if mode == "AXIS_ANGLE":
        axis = values[:, 1:] / np.linalg.norm(values[:, 1:], axis=1, keepdims=True)
        return Rotation.from_rotvec(axis * values[:, :1]).as_matrix()
    seq = mode.lower()  # extrinsic: "XYZ" applies X first, R = Rz Ry Rx, as Blender
    idx = ["xyz".index(c) for c in seq]
    return Rotation.from_euler(seq, values[:, idx]).as_matrix()


def evaluate(r, times):
    """The returned curves evaluated at `times` by Blender's evaluation: (C, T)."""
    return polyscrew.evaluate_fcurves(
        times,
        offsets=r["offsets"],
        co=r["co"],
        handle_left=r["handle_left"],
        handle_right=r["handle_right"],
        interpolation=r["interpolation"],
        easing=r["easing"],
    )


def channel_values(r, values, owner, path, width, default):
    """(T, width) values of an owner's property from evaluated curves (default where a
    curve is missing)."""
    t = values.shape[1]
    out = np.tile(np.asarray(default, float), (t, 1))
    for c in range(len(r["path"])):
        if r["owner"][c] == owner and r["path"][c] == path:
            out[:, r["index"][c]] = values[c]
    return out


def play(r, times, modes, dense=None, scales=False):
    """Local poses (B, T, 4, 4) Blender plays from the curves (missing groups taken from
    `dense`), and scales (B, T, 3) when `scales`."""
    values = evaluate(r, times)
    b = len(modes)
    poses = np.zeros((b, len(times), 4, 4))
    poses[:, :, 3, 3] = 1
    out_scales = np.ones((b, len(times), 3))
    for o, mode in enumerate(modes):
        prop = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}.get(
            mode, "rotation_euler"
        )
        has = lambda p: any(r["owner"][c] == o and r["path"][c] == p for c in range(len(r["path"])))  # noqa: E731
        width = 3 if prop == "rotation_euler" else 4
        if has(prop):
            rot = channel_values(r, values, o, prop, width, [1, 0, 0, 0] if width == 4 else [0, 0, 0])
            poses[o, :, :3, :3] = rotation_of(mode, rot)
        else:
            poses[o, :, :3, :3] = dense[o, :, :3, :3]
        if has("location"):
            poses[o, :, :3, 3] = channel_values(r, values, o, "location", 3, [0, 0, 0])
        else:
            poses[o, :, :3, 3] = dense[o, :, :3, 3]
        if scales:
            out_scales[o] = channel_values(r, values, o, "scale", 3, [1, 1, 1])
    return (poses, out_scales) if scales else poses


def pose_errors(played, dense, radius):
    """Distance bound |dt| + 2 r sin(theta / 2) and angle theta, elementwise over (..., 4, 4)."""
    dt = np.linalg.norm(played[..., :3, 3] - dense[..., :3, 3], axis=-1)
    rel = np.swapaxes(dense[..., :3, :3], -1, -2) @ played[..., :3, :3]
    theta = Rotation.from_matrix(rel.reshape(-1, 3, 3)).magnitude().reshape(dt.shape)
    return dt + 2 * np.asarray(radius)[..., None] * np.sin(theta / 2), theta


def check(poses, frames, modes, radius, distance, angle, label="", per_sub=4, **kw):
    """reduce_keys, then Blender's playback against the dense motion at every frame and the
    subframes: asserts the tolerance, returns (result, distance errors, angle errors)."""
    poses = np.asarray(poses, float)
    modes_list = [modes] * len(poses) if isinstance(modes, str) else list(modes)
    r = polyscrew.reduce_keys(poses, frames, modes, radius, distance, angle, **kw)
    times = sample_times(frames, per_sub)
    constant = kw.get("constant")
    dense = np.array(
        [dense_reference(p, frames, per_sub, None if constant is None else constant[o]) for o, p in enumerate(poses)]
    )
    played = play(r, times, modes_list, dense)
    d, a = pose_errors(played, dense, np.broadcast_to(radius, (len(poses),)))
    for o in range(len(poses)):
        assert d[o].max() <= distance, f"{label} owner {o}: distance {d[o].max():.3e} > {distance:.3e} at {times[d[o].argmax()]}"
        assert a[o].max() <= angle, f"{label} owner {o}: angle {a[o].max():.3e} > {angle:.3e} at {times[a[o].argmax()]}"
        # The core measures the same samples: its report agrees with ours.
        np.testing.assert_allclose(r["distance_error"][o], d[o].max(), rtol=1e-3, atol=1e-9)
        np.testing.assert_allclose(r["angle_error"][o], a[o].max(), rtol=1e-3, atol=1e-9)
    return r, d, a


def fraction(r, n):
    return float(np.max(r["keys"])) / n


# --- the tolerance holds ------------------------------------------------------------------


@pytest.mark.parametrize("mode", MODES)
def test_random_smooth_motions_every_mode(rng, mode):
    """Smooth random motions, 240 frames, 1 mm / 0.5 degrees on a body of radius 0.5: the
    tolerance holds at every frame and subframe; keys far fewer than frames."""
    n = 240
    frames = np.arange(n, dtype=float)
    poses = np.array([smooth_motion(n, rng) for _ in range(3)])
    r, d, a = check(poses, frames, mode, 0.5, 1 * MM, 0.5 * DEG, mode)
    print(f"\n{mode}: keys {r['keys'].tolist()} of {n} frames ({fraction(r, n):.1%}), "
          f"errors {r['distance_error'].max() / MM:.3f} mm, {np.degrees(r['angle_error'].max()):.3f} deg")
    assert fraction(r, n) < 0.5
    # The curves: three location and the mode's rotation channels, keys shared by them.
    assert set(r["path"]) == {"location", "rotation_quaternion" if mode == "QUATERNION" else
                              "rotation_axis_angle" if mode == "AXIS_ANGLE" else "rotation_euler"}
    for o in range(3):
        cs = np.flatnonzero(r["owner"] == o)
        frames_of = [tuple(r["co"][r["offsets"][c]:r["offsets"][c + 1], 0]) for c in cs]
        assert all(f == frames_of[0] for f in frames_of), "channels share key frames"
        assert len(frames_of[0]) == r["keys"][o]
        assert frames_of[0][0] == frames[0] and frames_of[0][-1] == frames[-1]


def test_between_the_checked_subframes(rng):
    """At 1/8 steps (half of them not checked by the core) the error stays near the
    tolerance: reported, and bounded by 1.25 x the tolerance."""
    n = 200
    frames = np.arange(n, dtype=float)
    poses = np.array([smooth_motion(n, rng) for _ in range(4)])
    r = polyscrew.reduce_keys(poses, frames, "XYZ", 0.5, 1 * MM, 0.5 * DEG)
    times = sample_times(frames, 8)
    dense = np.array([dense_reference(p, frames, 8) for p in poses])
    played = play(r, times, ["XYZ"] * 4, dense)
    d, a = pose_errors(played, dense, np.full(4, 0.5))
    print(f"\nat 1/8 frame: {d.max() / MM:.3f} mm, {np.degrees(a.max()):.3f} deg (tolerance 1 mm, 0.5 deg)")
    assert d.max() <= 1.25 * MM and a.max() <= 1.25 * 0.5 * DEG


@pytest.mark.parametrize("mode", ["QUATERNION", "XYZ", "AXIS_ANGLE"])
def test_screw_motions(mode):
    """Screw motions (helix, pure rotation about an offset axis, pure slide): within the
    tolerance, with a handful of keys."""
    n = 121
    frames = np.arange(n, dtype=float)
    poses = np.array([
        screw_motion(n, [0.2, 0.3, 1.0], np.radians(150), 2.0, np.array([1.0, -0.5, 0.2])),
        screw_motion(n, [1.0, 0.0, 0.3], np.radians(90), 0.0, np.array([0.0, 2.0, 0.0])),
        screw_motion(n, [0.0, 1.0, 0.0], 0.0, 3.0, np.zeros(3)),
    ])
    r, _, _ = check(poses, frames, mode, 0.3, 0.5 * MM, 0.05 * DEG, "screw")
    print(f"\nscrews {mode}: keys {r['keys'].tolist()} of {n}")
    assert r["keys"][2] == 2, "a straight slide needs its two end keys only"
    assert r["keys"].max() <= 12


@pytest.mark.parametrize("mode", ["XYZ", "ZXY", "AXIS_ANGLE", "QUATERNION"])
def test_spins_over_many_turns(mode):
    """A wheel spinning 10 turns about a tilted axis while rolling: within the tolerance, the
    Euler / axis-angle curves turning as the motion turns (no wraps: the channel reaches
    about 10 turns), few keys."""
    n = 241
    frames = np.arange(n, dtype=float)
    axis = np.array([0.0, 0.0, 1.0]) if mode != "QUATERNION" else np.array([0.3, 0.2, 1.0])
    poses = screw_motion(n, axis, 10 * 2 * np.pi, 0.0, np.zeros(3))[None]
    poses[0, :, 0, 3] = np.linspace(0, 5, n)
    r, _, _ = check(poses, frames, mode, 0.3, 1 * MM, 0.5 * DEG, "spin")
    values = evaluate(r, frames)
    rot = [c for c, p in enumerate(r["path"]) if p.startswith("rotation")]
    print(f"\nspin {mode}: keys {r['keys'].tolist()} of {n}")
    jumps = np.abs(np.diff(values[rot], axis=1)).max()
    assert jumps < 0.5, f"no wraps between frames: largest step {jumps}"
    if mode in ("XYZ", "ZXY"):
        z = values[rot[2]]
        assert abs(abs(z[-1] - z[0]) - 20 * np.pi) < 1e-3, "ten turns on Z"
    if mode == "AXIS_ANGLE":
        angle = values[rot[0]]
        assert abs(abs(angle[-1] - angle[0]) - 20 * np.pi) < 1e-3
    assert r["keys"][0] <= 25


def test_start_keeps_the_sources_values():
    """A spin from 360 to 720 degrees stays there when `start` gives the source's values."""
    n = 49
    frames = np.arange(n, dtype=float)
    poses = screw_motion(n, [0, 0, 1], 2 * np.pi, 0.0, np.zeros(3))[None]
    start = np.array([[0.0, 0.0, 2 * np.pi, 0.0]])
    r = polyscrew.reduce_keys(poses, frames, "XYZ", 1.0, MM, 0.1 * DEG, start=start)
    z = evaluate(r, frames)[[c for c, p in enumerate(r["path"]) if p == "rotation_euler"][2]]
    assert abs(z[0] - 2 * np.pi) < 1e-5 and abs(z[-1] - 4 * np.pi) < 1e-5, (z[0], z[-1])
    r = polyscrew.reduce_keys(poses, frames, "XYZ", 1.0, MM, 0.1 * DEG)
    z = evaluate(r, frames)[[c for c, p in enumerate(r["path"]) if p == "rotation_euler"][2]]
    assert abs(z[0]) < 1e-6 and abs(z[-1] - 2 * np.pi) < 1e-5


def test_holds_and_pops(rng):
    """A motion with a hold (a CONSTANT span of 10 frames) and a pop (a one-frame step): the
    spans stay CONSTANT keys, Blender plays the held pose until the pop, the rest within
    the tolerance."""
    n = 120
    frames = np.arange(n, dtype=float)
    poses = smooth_motion(n, rng, turns=0.25, size=0.25)
    poses[40:51] = poses[40]  # hold frames 40..50
    popped = poses[80:].copy()
    popped[:, :3, 3] += [0.5, 0.0, 0.0]  # pop at 80
    poses[80:] = popped
    constant = np.zeros((1, n - 1), bool)
    constant[0, 40:50] = True
    constant[0, 79] = True
    r, _, _ = check(poses[None], frames, "XYZ", 0.5, MM, 0.5 * DEG, "holds", constant=constant)
    interp = np.asarray(polyscrew.INTERPOLATIONS)[r["interpolation"]]
    for c in range(len(r["path"])):
        keys = slice(r["offsets"][c], r["offsets"][c + 1])
        at = dict(zip(r["co"][keys, 0], interp[keys]))
        for f in list(range(40, 50)) + [79]:
            assert at.get(float(f)) == "CONSTANT", (r["path"][c], f, at.get(float(f)))
    # Just before the pop Blender still plays frame 79's pose; at the pop the new one.
    played = play(r, np.array([79.0, 79.999, 80.0]), ["XYZ"], poses[None, [79, 79, 80]])
    np.testing.assert_allclose(played[0, 1, :3, 3], poses[79, :3, 3], atol=MM)
    np.testing.assert_allclose(played[0, 2, :3, 3], poses[80, :3, 3], atol=MM)
    print(f"\nholds and pops: keys {r['keys'].tolist()} of {n}")
    assert r["keys"][0] < 0.7 * n


def test_cycles(rng):
    """A cycle (first pose == last pose): keys at the first and last frame with equal
    values, the tolerance held, for every mode."""
    n = 97
    frames = np.arange(n, dtype=float)
    s = np.linspace(0, 2 * np.pi, n)
    poses = np.zeros((n, 4, 4))
    poses[:, :3, :3] = Rotation.from_rotvec(
        np.stack([0.4 * np.sin(s), 0.3 * np.sin(2 * s), 0.2 * np.cos(s) - 0.2], -1)).as_matrix()
    poses[:, :3, 3] = np.stack([np.sin(s), 0.5 * np.sin(2 * s), 0.1 * np.cos(s)], -1)
    poses[:, 3, 3] = 1
    poses[-1] = poses[0]
    for mode in MODES:
        r, _, _ = check(poses[None], frames, mode, 0.5, MM, 0.5 * DEG, mode, cyclic=True)
        ends = np.array([r["co"][[r["offsets"][c], r["offsets"][c + 1] - 1]] for c in range(len(r["path"]))])
        assert (ends[:, 0, 0] == frames[0]).all() and (ends[:, 1, 0] == frames[-1]).all()
        rot = [c for c, p in enumerate(r["path"]) if p.startswith("rotation")]
        first, last = ends[:, 0, 1], ends[:, 1, 1]
        if mode == "AXIS_ANGLE" and not np.array_equal(first[rot], last[rot]):
            # (angle, axis) and (-angle, -axis) are one rotation: the unwrapped channels may
            # come back to the other one; the rotation is then the same, to float32.
            np.testing.assert_allclose(rotation_of(mode, [first[rot]]), rotation_of(mode, [last[rot]]), atol=1e-6)
            first, last = first[:3], last[:3]
        assert np.array_equal(first, last), (mode, first, last)


def test_quaternion_keys_unit_and_continuous(rng):
    n = 300
    frames = np.arange(n, dtype=float)
    poses = np.array([smooth_motion(n, rng, turns=3.0) for _ in range(3)])
    r, _, _ = check(poses, frames, "QUATERNION", 0.5, MM, 0.5 * DEG, "quat")
    for o in range(3):
        cs = [c for c in range(len(r["path"])) if r["owner"][c] == o and r["path"][c] == "rotation_quaternion"]
        q = np.stack([r["co"][r["offsets"][c]:r["offsets"][c + 1], 1] for c in cs], -1)
        np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=1e-6)
        assert (np.sum(q[1:] * q[:-1], axis=1) > 0).all(), "signs continuous"


@pytest.mark.parametrize("mode", ["XYZ", "YZX", "ZYX", "AXIS_ANGLE"])
def test_euler_and_axis_angle_continuous(rng, mode):
    """The played channels follow the dense channels unwrapped along the frames (no 2 pi
    jumps anywhere): within 0.01 rad of them at every frame away from gimbal lock."""
    n = 200
    frames = np.arange(n, dtype=float)
    s = np.linspace(0, 1, n)
    # Several turns about Z and X, a moderate tilt about Y (no gimbal lock in any order).
    rv = np.stack([3 * np.pi * s, 0.3 * np.sin(5 * s), 4 * np.pi * s ** 2], -1)
    poses = np.zeros((1, n, 4, 4))
    poses[0, :, :3, :3] = Rotation.from_euler("xyz", rv).as_matrix()
    poses[0, :, 3, 3] = 1
    r, _, _ = check(poses, frames, mode, 0.5, MM, 0.5 * DEG, mode)
    values = evaluate(r, frames)
    rot = np.array([values[c] for c, p in enumerate(r["path"]) if p.startswith("rotation")]).T
    dense = polyscrew.rotation_channels(poses[0, :, :3, :3], mode)
    # The keys' channels are the dense channels unwrapped (to the tolerance): no 2 pi jump.
    gap = np.abs(rot - dense).max()
    print(f"\n{mode}: keys {r['keys'].tolist()} of {n}; channels within {gap:.2e} of the unwrapped dense ones; "
          f"range {np.ptp(dense, axis=0).round(2).tolist()}")
    assert gap < 0.05, gap
    if mode != "AXIS_ANGLE":
        assert np.ptp(rot, axis=0).max() > 2 * np.pi, "a channel runs over more than a turn, unwrapped"


def test_coordinate_free(rng):
    """Every pose left-multiplied by one rigid motion G (a new world frame): the same key
    count and the tolerance still held (quaternion and location channels: the fit commutes
    with G; Euler channels are not coordinate-free and are left out)."""
    n = 200
    frames = np.arange(n, dtype=float)
    poses = np.array([smooth_motion(n, rng) for _ in range(4)])
    r0, _, _ = check(poses, frames, "QUATERNION", 0.5, MM, 0.5 * DEG, "base")
    for case in range(4):
        g = random_rigid(rng)
        moved = g @ poses
        r1, _, _ = check(moved, frames, "QUATERNION", 0.5, MM, 0.5 * DEG, f"G{case}")
        assert r1["keys"].tolist() == r0["keys"].tolist(), (case, r0["keys"], r1["keys"])
    print(f"\ncoordinate-free: keys {r0['keys'].tolist()} in every frame")


def test_rig_world_space_tolerance(rng):
    """A chain of 5 bones (offsets along Y, each 0.6 long): the tolerance holds in world
    space at every bone, each child compensating its parents' errors."""
    n = 150
    frames = np.arange(n, dtype=float)
    b = 5
    local = np.array([smooth_motion(n, rng, turns=0.6, size=0.05) for _ in range(b)])
    local[0, :, :3, 3] *= 20  # the root travels
    offsets = np.tile(np.eye(4), (b, 1, 1))
    offsets[1:, 1, 3] = 0.6
    parents = np.array([-1, 0, 1, 2, 3])
    radius = np.full(b, 0.6)
    r = polyscrew.reduce_keys(local, frames, "QUATERNION", radius, MM, 0.5 * DEG,
                              parents=parents, offsets=offsets)
    times = sample_times(frames)
    dense_local = np.array([dense_reference(p, frames) for p in local])
    played_local = play(r, times, ["QUATERNION"] * b, dense_local)
    world_dense = np.zeros_like(dense_local)
    world_played = np.zeros_like(played_local)
    for i in range(b):
        pd = np.eye(4) if parents[i] < 0 else world_dense[parents[i]]
        pp = np.eye(4) if parents[i] < 0 else world_played[parents[i]]
        world_dense[i] = pd @ offsets[i] @ dense_local[i]
        world_played[i] = pp @ offsets[i] @ played_local[i]
    d, a = pose_errors(world_played, world_dense, radius)
    # The same chain reduced bone by bone (no parents): the world error accumulates.
    r_local = polyscrew.reduce_keys(local, frames, "QUATERNION", radius, MM, 0.5 * DEG)
    pl = play(r_local, times, ["QUATERNION"] * b, dense_local)
    wl = np.zeros_like(pl)
    for i in range(b):
        pp = np.eye(4) if parents[i] < 0 else wl[parents[i]]
        wl[i] = pp @ offsets[i] @ pl[i]
    dl, _ = pose_errors(wl, world_dense, radius)
    print(f"\nrig world errors per bone (mm): {np.round(d.max(axis=1) / MM, 3).tolist()}; "
          f"bone by bone: {np.round(dl.max(axis=1) / MM, 3).tolist()}; keys {r['keys'].tolist()}")
    for i in range(b):
        assert d[i].max() <= MM, (i, d[i].max())
        assert a[i].max() <= 0.5 * DEG, (i, a[i].max())
        np.testing.assert_allclose(r["distance_error"][i], d[i].max(), rtol=1e-3, atol=1e-9)


def test_scales_and_channels(rng):
    """Scale channels reduced too (their error |ds| r counted in the distance); an owner that
    keys only rotation gets only rotation curves."""
    n = 100
    frames = np.arange(n, dtype=float)
    poses = np.array([smooth_motion(n, rng) for _ in range(2)])
    scales = 1.0 + 0.3 * np.sin(np.linspace(0, 3, n))[None, :, None] * np.array([1.0, 0.5, -0.2])
    scales = np.repeat(scales, 2, axis=0)
    channels = np.array([[True, True, True], [False, True, False]])
    r = polyscrew.reduce_keys(poses, frames, "XYZ", 0.5, MM, 0.5 * DEG, scales=scales, channels=channels)
    assert [p for o, p in zip(r["owner"], r["path"]) if o == 1] == ["rotation_euler"] * 3
    nothing = polyscrew.reduce_keys(poses[:1], frames, "XYZ", 0.5, MM, DEG, channels=[[False, False, False]])
    assert nothing["path"] == [] and nothing["keys"].tolist() == [0]
    assert sorted(set(p for o, p in zip(r["owner"], r["path"]) if o == 0)) == ["location", "rotation_euler", "scale"]
    times = sample_times(frames)
    dense = np.array([dense_reference(p, frames) for p in poses])
    played, sc = play(r, times, ["XYZ"] * 2, dense, scales=True)
    d, a = pose_errors(played, dense, np.full(2, 0.5))
    ref_scale = np.array([np.r_[np.repeat(s[:-1], 4, 0) + np.repeat(np.diff(s, axis=0), 4, 0) * np.tile(np.arange(4) / 4, n - 1)[:, None], s[-1:]] for s in scales])
    d[0] += 0.5 * np.linalg.norm(sc[0] - ref_scale[0], axis=1)
    assert d.max() <= MM and a.max() <= 0.5 * DEG, (d.max(), a.max())


def test_per_channel(rng):
    """per_channel: each channel its own key frames, the whole still within the tolerance."""
    n = 150
    frames = np.arange(n, dtype=float)
    # Planar motions (turning about Z, moving in XY): Z never moves, at the subframes either
    # (every screw's axis is vertical), so its curve needs its two end keys only.
    s = np.linspace(0, 1, n)
    poses = np.zeros((2, n, 4, 4))
    for o in range(2):
        poses[o, :, :3, :3] = Rotation.from_rotvec(np.outer(2 * np.sin(3 * s + o), [0, 0, 1])).as_matrix()
        poses[o, :, :3, 3] = np.stack([np.sin(4 * s + o), np.cos(3 * s) * s, np.full(n, 0.25)], -1)
        poses[o, :, 3, 3] = 1
    r, _, _ = check(poses, frames, "XYZ", 0.5, MM, 0.5 * DEG, "per channel", per_channel=True)
    counts = np.diff(r["offsets"])
    z = [c for c in range(len(r["path"])) if r["path"][c] == "location" and r["index"][c] == 2]
    assert all(counts[c] == 2 for c in z), counts
    assert len(set(counts.tolist())) > 2, "channels keyed at different frames"
    shared = polyscrew.reduce_keys(poses, frames, "XYZ", 0.5, MM, 0.5 * DEG)
    print(f"\nper channel: keys per curve {counts.tolist()}; shared: {np.diff(shared['offsets']).tolist()}")


def test_uneven_frames_and_subframes(rng):
    """Frames unevenly spaced (subframes in the source) are handled like any others."""
    n = 150
    frames = np.cumsum(rng.uniform(0.25, 2.0, n))
    poses = smooth_motion(n, rng)[None]
    check(poses, frames, "ZXY", 0.5, MM, 0.5 * DEG, "uneven")


def test_fallback_when_a_frame_is_not_enough():
    """A body turning 120 degrees per frame: no span of a frame fits, keys go at subframes,
    and the tolerance still holds at every checked sample."""
    n = 6
    frames = np.arange(n, dtype=float)
    poses = screw_motion(n, [1.0, 1.0, 0.2], np.radians(600), 0.3, np.array([0.3, 0.0, 0.0]))[None]
    r, _, _ = check(poses, frames, "QUATERNION", 1.0, 0.1 * MM, 0.01 * DEG, "fast")
    assert r["keys"][0] >= n


def neville_reference(poses, frames, per=4):
    """The "cubic" dense motion at `sample_times(frames, per)`, independently: Aitken-Neville
    over the two poses each side of a span with pytransform3d's screw for straight lines."""
    n = len(frames)
    out = []
    for f in range(n - 1):
        lo, hi = max(f - 1, 0), min(f + 2, n - 1)
        for k in range(per):
            t = frames[f] + (frames[f + 1] - frames[f]) * k / per
            if k == 0:
                out.append(poses[f])
                continue
            p = [poses[i] for i in range(lo, hi + 1)]
            for level in range(1, len(p)):
                for i in range(len(p) - level):
                    ti, tj = frames[lo + i], frames[lo + i + level]
                    p[i] = reference_s(p[i], (t - ti) / (tj - ti), p[i + 1])
            out.append(p[0])
    out.append(poses[-1])
    return np.array(out)


def test_between_cubic(rng):
    """between="cubic": the tolerance holds against the cubic through the frames (built here
    with pytransform3d's screw), and a smooth clip needs fewer keys than against the screw's
    corners; a screw motion is still reproduced with two keys."""
    n = 300
    frames = np.arange(n, dtype=float)
    t = frames / 30.0
    limb = np.zeros((n, 4, 4))
    limb[:, :3, :3] = Rotation.from_rotvec(np.stack([0.5 * np.sin(2 * np.pi * t), 0.05 * np.sin(4 * np.pi * t),
                                                     np.zeros(n)], -1)).as_matrix()
    limb[:, 3, 3] = 1
    clips = np.array([limb, smooth_motion(n, rng), smooth_motion(n, rng)])
    radius = np.array([0.45, 0.3, 0.3])
    times = sample_times(frames)
    counts = {}
    for between in ("screw", "cubic"):
        r = polyscrew.reduce_keys(clips, frames, "XYZ", radius, MM, 0.5 * DEG, between=between)
        dense = np.array([(dense_reference if between == "screw" else neville_reference)(p, frames) for p in clips])
        played = play(r, times, ["XYZ"] * 3, dense)
        d, a = pose_errors(played, dense, radius)
        assert d.max() <= MM and a.max() <= 0.5 * DEG, (between, d.max(), a.max())
        np.testing.assert_allclose(r["distance_error"], d.max(axis=1), rtol=1e-3, atol=1e-9)
        counts[between] = r["keys"]
    print(f"\nkeys against the screw {counts['screw'].tolist()}, against the cubic {counts['cubic'].tolist()} "
          f"of {n} frames (limb swing, two tumbles)")
    assert (counts["cubic"] < counts["screw"]).all()
    helix = screw_motion(61, [0.2, 0.3, 1.0], np.radians(100), 1.0, np.array([0.5, 0.0, 0.0]))[None]
    r = polyscrew.reduce_keys(helix, np.arange(61.0), "QUATERNION", 0.3, MM, 0.5 * DEG, between="cubic")
    assert r["keys"][0] <= 4
    with pytest.raises(ValueError, match="reduce_keys: between"):
        polyscrew.reduce_keys(helix, np.arange(61.0), "XYZ", 0.3, MM, DEG, between="bezier")


def test_between_linear(rng):
    """between="linear": the tolerance holds against the channels interpolated linearly
    between frames (what LINEAR keys on every frame play), built here from scipy's Euler
    angles unwrapped by numpy and composed by scipy."""
    n = 200
    frames = np.arange(n, dtype=float)
    clips = np.array([smooth_motion(n, rng) for _ in range(2)])
    r = polyscrew.reduce_keys(clips, frames, "ZXY", 0.4, MM, 0.5 * DEG, between="linear")
    times = sample_times(frames)
    u = np.tile(np.arange(4) / 4, n - 1)
    dense = np.zeros((2, len(times), 4, 4))
    dense[:, :, 3, 3] = 1
    for o, p in enumerate(clips):
        e = np.unwrap(Rotation.from_matrix(p[:, :3, :3]).as_euler("zxy"), axis=0)[:, [1, 2, 0]]  # x, y, z
        lerp = lambda v: np.r_[v[:-1].repeat(4, 0) + np.diff(v, axis=0).repeat(4, 0) * u[:, None], v[-1:]]  # noqa: E731
        dense[o, :, :3, :3] = rotation_of("ZXY", lerp(e))
        dense[o, :, :3, 3] = lerp(p[:, :3, 3])
    played = play(r, times, ["ZXY"] * 2, dense)
    d, a = pose_errors(played, dense, np.full(2, 0.4))
    print(f"\nlinear: keys {r['keys'].tolist()} of {n}, errors {d.max() / MM:.3f} mm {np.degrees(a.max()):.3f} deg")
    assert d.max() <= MM and a.max() <= 0.5 * DEG, (d.max(), a.max())
    np.testing.assert_allclose(r["distance_error"], d.max(axis=1), rtol=1e-3, atol=1e-9)


# --- the result's form -------------------------------------------------------------------


def test_result_layout(rng):
    n = 60
    frames = np.arange(n, dtype=float)
    poses = np.array([smooth_motion(n, rng) for _ in range(2)])
    r = polyscrew.reduce_keys(poses, frames, ["QUATERNION", "YXZ"], [0.5, 1.0], MM, 0.5 * DEG)
    c = len(r["path"])
    k = r["offsets"][-1]
    assert c == 7 + 6 and r["offsets"].shape == (c + 1,) and r["offsets"][0] == 0
    assert r["owner"].dtype == np.int64 and r["index"].dtype == np.int64
    for name in ("co", "handle_left", "handle_right"):
        assert r[name].shape == (k, 2) and r[name].dtype == np.float64
    for name in ("interpolation", "easing", "handle_type"):
        assert r[name].shape == (k,) and r[name].dtype == np.int64
    assert r["keys"].shape == (2,) and r["distance_error"].shape == (2,)
    assert polyscrew.HANDLE_TYPES == ("FREE", "ALIGNED", "VECTOR", "AUTO", "AUTO_CLAMPED")
    assert set(np.asarray(polyscrew.HANDLE_TYPES)[r["handle_type"]]) <= {"FREE", "ALIGNED"}
    assert set(np.asarray(polyscrew.INTERPOLATIONS)[r["interpolation"]]) <= {"BEZIER", "CONSTANT"}
    assert r["path"][:7] == ["location"] * 3 + ["rotation_quaternion"] * 4
    assert r["index"][:7].tolist() == [0, 1, 2, 0, 1, 2, 3]
    # Handles sit at a third of each span, so each Bezier segment is a cubic in time.
    co, hl, hr = r["co"], r["handle_left"], r["handle_right"]
    for ci in range(c):
        s = slice(r["offsets"][ci], r["offsets"][ci + 1])
        f = co[s, 0]
        np.testing.assert_allclose(hr[s][:-1, 0], f[:-1] + np.diff(f) / 3)
        np.testing.assert_allclose(hl[s][1:, 0], f[1:] - np.diff(f) / 3)


# --- bad input -----------------------------------------------------------------------------


def test_bad_input_is_a_clear_error(rng):
    n = 20
    frames = np.arange(n, dtype=float)
    poses = smooth_motion(n, rng)[None]
    ok = dict(poses=poses, frames=frames, modes="XYZ", radius=1.0, distance=MM, angle=DEG)

    def call(**kw):
        args = {**ok, **kw}
        return polyscrew.reduce_keys(args.pop("poses"), args.pop("frames"), args.pop("modes"),
                                     args.pop("radius"), args.pop("distance"), args.pop("angle"), **args)

    def raises(exc, match, **kw):
        with pytest.raises(exc, match=match) as info:
            call(**kw)
        assert str(info.value).startswith("reduce_keys"), str(info.value)

    raises(ValueError, r"poses: expected shape \(B, N, 4, 4\)", poses=poses[0])
    bad = poses.copy()
    bad[0, 7, :3, :3] *= 1.1
    raises(ValueError, "owner 0.*pose 7.*scale", poses=bad)
    bad = poses.copy()
    bad[0, 3, 0, 0] = np.nan
    raises(ValueError, "owner 0.*NaN", poses=bad)
    raises(ValueError, "frames: frame 1", frames=frames[::-1].copy())
    raises(ValueError, "frames", frames=frames[:-1])
    raises(ValueError, "at least 2", poses=poses[:, :1], frames=frames[:1])
    raises(ValueError, "distance", distance=0.0)
    raises(ValueError, "angle", angle=-1.0)
    raises(ValueError, "distance", distance=np.inf)
    raises(ValueError, "modes.*XYZW", modes="XYZW")
    raises(ValueError, "modes: expected 1 entries, got 2", modes=["XYZ", "XYZ"])
    raises(TypeError, "modes", modes=3)
    raises(ValueError, "radius.*owner 0", radius=-1.0)
    raises(ValueError, "radius", radius=[1.0, 2.0])
    two = np.concatenate([poses, poses])
    raises(ValueError, "parents.*cycle", poses=two, parents=[1, 0])
    raises(ValueError, "parents.*own parent", poses=two, parents=[-1, 1])
    raises(ValueError, r"parents: owner 1: owner 5 is outside 0\.\.2", poses=two, parents=[-1, 5])
    raises(ValueError, "parents.*owner 1", poses=two, parents=[-1, -3])
    raises(ValueError, "offsets.*owner 1", poses=two, parents=[-1, 0], offsets=np.stack([np.eye(4), 2 * np.eye(4)]))
    raises(ValueError, "constant", constant=np.zeros((1, n), bool))
    raises(TypeError, "constant", constant=np.zeros((1, n - 1)))
    raises(ValueError, "channels.*scale", channels=[[True, True, True]])
    raises(ValueError, "scales.*owner 0", scales=np.zeros((1, n, 3)))
    raises(ValueError, "start", start=np.zeros((1, 3)))
    raises(TypeError, "cyclic", cyclic="yes")
    raises(ValueError, "threads", threads=-1)


def test_budget_is_checked_before_work():
    poses = np.broadcast_to(np.eye(4), (100, 100_000, 4, 4))
    old = polyscrew.set_memory_budget(1 << 20)
    try:
        with pytest.raises(ValueError, match="reduce_keys.*over the memory budget"):
            polyscrew.reduce_keys(poses, np.arange(100_000.0), "XYZ", 1.0, MM, DEG)
    finally:
        polyscrew.set_memory_budget(old)
    with pytest.raises(ValueError, match="exceed the limits"):
        polyscrew.reduce_keys(np.broadcast_to(np.eye(4), (30, 1_000_000, 4, 4)), np.arange(1e6), "XYZ", 1.0, MM, DEG)
