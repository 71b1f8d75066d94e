"""The add-on's pure layer (`addon/screwbender/pure`, issue 25 item 1): numpy and polyscrew
only, never bpy, and tested here without Blender.

- Every module of the folder imports in a fresh interpreter in which importing `bpy` (or
  `bmesh`, `mathutils`, `gpu`, ...) raises; the same check run on a copy of the folder with one
  module that reaches for Blender fails, so the check can fail.
- Its parts against independent references: Blender's rotation conventions (`keyed`) against
  scipy, `compose` against the product T R S, the pieces and holds of `sampling.segments`,
  `sampling.sample` reproducing a screw motion (scipy's matrix exponential of its twist),
  `feature_points.nearest_rows` against a brute-force search.
"""

from __future__ import annotations

import math
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import scipy.linalg
from scipy.spatial.transform import Rotation

import pure_layer
from screws import screw_matrix

BLOCKED = ("bpy", "bmesh", "mathutils", "gpu", "gpu_extras", "bpy_extras", "bl_ui", "addon_utils")

#: Run in a fresh interpreter: block Blender's modules, import every module of a pure folder.
CHECK = textwrap.dedent(
    """
    import importlib, importlib.abc, importlib.util, sys
    from pathlib import Path

    BLOCKED = {blocked!r}

    class Blocker(importlib.abc.MetaPathFinder):
        def find_spec(self, name, path=None, target=None):
            if name.split(".")[0] in BLOCKED:
                raise ImportError(f"the pure layer imported {{name}}")
            return None

    sys.meta_path.insert(0, Blocker())
    folder = Path({folder!r})
    spec = importlib.util.spec_from_file_location("pure_check", folder / "__init__.py",
                                                  submodule_search_locations=[str(folder)])
    package = importlib.util.module_from_spec(spec)
    sys.modules["pure_check"] = package
    spec.loader.exec_module(package)
    failed = []
    for path in sorted(folder.glob("*.py")):
        if path.stem == "__init__":
            continue
        try:
            importlib.import_module("pure_check." + path.stem)
            print("ok", path.stem)
        except Exception as err:
            failed.append(path.stem)
            print("FAILED", path.stem, type(err).__name__, err)
    loaded = sorted(m for m in sys.modules if m.split(".")[0] in BLOCKED)
    print("blender modules loaded:", loaded)
    sys.exit(1 if failed or loaded else 0)
    """
)


def check_folder(folder: Path) -> subprocess.CompletedProcess:
    script = CHECK.format(blocked=BLOCKED, folder=str(folder))
    return subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120)


def test_every_pure_module_imports_without_blender():
    names = pure_layer.names()
    # the folder holds the layer's modules (a rename or an empty folder would pass vacuously)
    assert {
        "intent", "sampling", "keyed", "packed", "feature_points", "denoise_data", "sweep_report", "grids", "reports",
        "smooth_options", "bezier", "preview_geometry", "reduce_plan",
    } <= set(names)
    done = check_folder(pure_layer.FOLDER)
    print(done.stdout)
    assert done.returncode == 0, done.stdout + done.stderr
    assert done.stdout.count("ok ") == len(names)


def test_the_check_fails_on_a_module_that_reaches_for_blender(tmp_path):
    copy = tmp_path / "pure"
    shutil.copytree(pure_layer.FOLDER, copy, ignore=shutil.ignore_patterns("__pycache__"))
    (copy / "reaches.py").write_text("from . import keyed\nimport mathutils\n")
    done = check_folder(copy)
    assert done.returncode != 0, done.stdout
    assert "FAILED reaches ImportError the pure layer imported mathutils" in done.stdout, done.stdout
    (copy / "reaches.py").write_text("from ..blender import keys\n")  # the Blender layer: not there
    done = check_folder(copy)
    assert done.returncode != 0 and "FAILED reaches" in done.stdout, done.stdout


keyed = pure_layer.module("keyed")
sampling = pure_layer.module("sampling")
feature_points = pure_layer.module("feature_points")
grids = pure_layer.module("grids")
reports = pure_layer.module("reports")
reduce_plan = pure_layer.module("reduce_plan")
preview_geometry = pure_layer.module("preview_geometry")
bezier = pure_layer.module("bezier")
smooth_options = pure_layer.module("smooth_options")


@pytest.mark.parametrize("order", ["XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"])
def test_euler_rotation_matrices_follow_blender_against_scipy(order, rng):
    angles = rng.uniform(-4.0, 4.0, (20, 3))  # beyond +-pi too
    got = keyed.rotation_matrices(angles, order)
    # Blender's "XYZ": X applied first about the fixed axes (R = Rz Ry Rx): scipy's extrinsic "xyz"
    # with the angles in the order's letters.
    index = ["XYZ".index(c) for c in order]
    want = Rotation.from_euler(order.lower(), angles[:, index]).as_matrix()
    np.testing.assert_allclose(got, want, atol=1e-12)


def test_quaternion_and_axis_angle_matrices_against_scipy(rng):
    q = rng.normal(size=(20, 4)) * rng.uniform(0.2, 3.0, (20, 1))  # not unit: Blender normalises
    got = keyed.rotation_matrices(q, "QUATERNION")
    want = Rotation.from_quat(q[:, [1, 2, 3, 0]]).as_matrix()
    np.testing.assert_allclose(got, want, atol=1e-12)
    axis_angle = np.column_stack([rng.uniform(-6, 6, 20), rng.normal(size=(20, 3))])
    got = keyed.rotation_matrices(axis_angle, "AXIS_ANGLE")
    axes = axis_angle[:, 1:] / np.linalg.norm(axis_angle[:, 1:], axis=1, keepdims=True)
    want = Rotation.from_rotvec(axes * axis_angle[:, :1]).as_matrix()
    np.testing.assert_allclose(got, want, atol=1e-12)
    with pytest.raises(keyed.SmoothError, match="unknown rotation mode"):
        keyed.rotation_matrices(q, "QUATERNIONS")


def test_compose_is_t_r_s(rng):
    loc, scale = rng.normal(size=(5, 3)), rng.uniform(0.5, 2.0, (5, 3))
    rot = Rotation.random(5, random_state=7).as_matrix()
    got = keyed.compose(loc, rot, scale)
    for i in range(5):
        t, r, s = np.eye(4), np.eye(4), np.diag([*scale[i], 1.0])
        t[:3, 3], r[:3, :3] = loc[i], rot[i]
        np.testing.assert_allclose(got[i], t @ r @ s, atol=1e-14)
    assert keyed.baked_channels("XYZ", True, np.array([False, True, False])) == [
        ("location", 0), ("location", 1), ("location", 2),
        ("rotation_euler", 0), ("rotation_euler", 1), ("rotation_euler", 2), ("scale", 1),
    ]
    assert [c for c, _ in keyed.baked_channels("QUATERNION", False, np.zeros(3, bool))] == ["rotation_quaternion"] * 4


def motion(frames, poses, held=None):
    k = len(frames)
    return keyed.KeyedMotion(
        frames=np.asarray(frames, float), poses=np.asarray(poses), scales=np.ones((k, 3)),
        scale_axes=np.zeros(3, bool), rotation_mode="XYZ", first_rotation=np.zeros(3), closed=False,
        period=None, cyclic=False, held=None if held is None else np.asarray(held, bool),
    )


def test_segments_cut_at_holds():
    m = motion([0, 10, 20, 30, 40], [np.eye(4)] * 5, held=[False, True, False, False])
    frames = np.arange(-2.0, 43.0)
    segments = sampling.segments(m, frames)
    assert [(s.lo, s.hi, s.held) for s in segments] == [(0, 1, False), (1, 1, True), (2, 4, False)]
    rows = np.concatenate([s.rows for s in segments])
    np.testing.assert_array_equal(rows, np.arange(len(frames)))  # every frame once, in order
    held = segments[1]
    # the held span 10..20 (from the key at 10 up to, not including, 20)
    np.testing.assert_array_equal(frames[held.rows], np.arange(10.0, 20.0))
    print("segments:", [(s.lo, s.hi, len(s.rows)) for s in segments])


@pytest.mark.parametrize("scheme", ["four_point", "bspline", "jarek"])
def test_sample_reproduces_a_screw_motion(scheme):
    """Key poses on one screw (a helix): the smoothed motion at any frame is that screw, as the
    matrix exponential of its twist (scipy) gives it, with every scheme and linear timing."""
    start = screw_matrix((0.2, 0.4, 1.0), (1.0, -0.5, 0.3), 0.0, 0.0) @ np.diag([1.0, 1.0, 1.0, 1.0])
    step = screw_matrix((0.2, 0.4, 1.0), (1.0, -0.5, 0.3), math.radians(35.0), 0.4)
    twist = scipy.linalg.logm(step).real
    frames = np.array([1.0, 11.0, 21.0, 31.0, 41.0])
    poses = [np.linalg.matrix_power(step, i) @ start for i in range(len(frames))]
    options = SimpleNamespace(scheme=scheme, levels=5, timing="linear", method="SCREW")
    at = np.linspace(1.0, 41.0, 97)
    got = sampling.sample(motion(frames, poses), at, options).poses
    want = np.array([scipy.linalg.expm(twist * (f - 1.0) / 10.0) @ start for f in at])
    err = np.abs(got - want).max()
    print(f"{scheme}: largest entry error against expm {err:.2e}")
    assert err < 1e-9


def test_nearest_rows_against_brute_force(rng):
    frames = np.sort(rng.choice(np.arange(0.0, 200.0, 0.5), 40, replace=False))
    at = np.concatenate([frames + rng.uniform(-5e-5, 5e-5, 40), rng.uniform(-10, 210, 60)])
    index, same = feature_points.nearest_rows(frames, at)
    brute = np.abs(frames[None, :] - at[:, None]).argmin(axis=1)
    np.testing.assert_allclose(np.abs(frames[index] - at), np.abs(frames[brute] - at))
    np.testing.assert_array_equal(same, np.abs(frames[brute] - at) < keyed.FRAME_TOLERANCE)
    assert same[:40].all()
    stiff = feature_points.key_stiffness(motion(frames[:4], [np.eye(4)] * 4), np.array([1, 1, 0, 1], bool), True, 0.5)
    np.testing.assert_array_equal(stiff, [np.inf, 0.5, np.inf, np.inf])  # ends of an open motion are hit
    assert feature_points.key_stiffness(motion(frames[:4], [np.eye(4)] * 4), np.ones(4, bool), False, 0.5) is None


def closed_keys(frames, poses, is_closed=True):
    """`keyed.key_motion` of key values alone (no playback), as `keys.read` calls it."""
    k = len(frames)
    poses = np.asarray(poses)
    rotation = np.zeros((k, 3))
    return keyed.key_motion(
        "Body", "XYZ", np.asarray(frames, float), poses, poses[:, :3, 3], rotation, np.ones((k, 3)),
        np.zeros(3, bool), None, {}, False, False, is_closed, [], None, True, "AUTO", True, None, 1.0, {}, frozenset(),
    )


def test_key_motion_turns_a_closing_key_into_the_period():
    turn = [screw_matrix((0, 0, 1), (0, 0, 0), a, 0.0) for a in (0.0, 2.0, 4.0)]
    m = closed_keys([0, 10, 20, 30], [*turn, turn[0]])  # the last key repeats the first pose
    assert m.closed and m.period == 30.0
    np.testing.assert_array_equal(m.frames, [0, 10, 20])
    assert m.frame_range == (0.0, 30.0) and m.is_key.tolist() == [True] * 3
    m = closed_keys([0, 10, 20], turn)  # no closing key: back to the first after the mean spacing
    assert m.closed and m.period == pytest.approx(30.0) and len(m.frames) == 3
    m = closed_keys([0, 10, 20], turn, is_closed=False)
    assert not m.closed and m.period is None and m.frame_range == (0.0, 20.0)
    with pytest.raises(keyed.SmoothError, match="Body: a cycle needs two distinct key poses"):
        closed_keys([0, 10], [turn[0], turn[0]])


@pytest.mark.parametrize(("start", "end", "step"), [(1.0, 30.0, 1.0), (1.5, 20.6, 1.0), (1.0, 30.0, 0.1), (0.0, 10.0, 0.3)])
def test_bake_frames_ends_exact_and_the_step_grid_between(start, end, step):
    frames = grids.bake_frames(start, end, step)
    assert frames[0] == start and frames[-1] == end
    inner = frames[1:-1]
    # every multiple of the step strictly inside (not within the tolerance of an end), exactly k / n for 1 / n steps
    k = np.arange(math.ceil(start / step) - 1, math.floor(end / step) + 2)
    want = k * step if abs(1 / step - round(1 / step)) > 1e-9 else k / round(1 / step)
    want = want[(want > start + keyed.FRAME_TOLERANCE) & (want < end - keyed.FRAME_TOLERANCE)]
    np.testing.assert_array_equal(inner, want)
    print(f"{start:g}..{end:g} step {step:g}: {len(frames)} frames")


def test_with_key_frames_adds_every_key_and_refuses_bad_ranges():
    grid = grids.bake_frames(1.0, 10.0, 1.0)
    keys_ = np.array([0.0, 2.5, 4.00002, 7.0, 12.0])  # outside, a subframe, a hair off a grid frame, on one
    frames = grids.with_key_frames(grid, keys_)
    np.testing.assert_array_equal(frames, [1, 2, 2.5, 3, 4.00002, 5, 6, 7, 8, 9, 10])
    assert grids.with_key_frames(grid, np.array([3.0, 5.0])) is grid  # every key on the grid: unchanged
    with pytest.raises(keyed.SmoothError, match="step must be positive"):
        grids.bake_frames(1.0, 10.0, 0.0)
    with pytest.raises(keyed.SmoothError, match="frame range 10 to 1 is empty"):
        grids.bake_frames(10.0, 1.0, 1.0)
    with pytest.raises(keyed.SmoothError, match="raise Step or shorten the Frame Range"):
        grids.bake_frames(0.0, 1e9, 1.0)
    assert reports.summary(["C", "A", "B", "D", "E"]) == "A, B, C and 2 more"


def test_reduce_measures_against_scipy(rng):
    """`reduce_plan`: the rigid part of a float32 matrix is scipy's polar factor; the body error
    between two poses is |dt| + 2 r sin(theta / 2) with theta scipy's rotation angle."""
    m = np.eye(4)
    m[:3, :3] = Rotation.random(random_state=3).as_matrix() @ (np.eye(3) + 1e-4 * rng.normal(size=(3, 3)))
    m[:3, 3] = rng.normal(size=3)
    rigid = reduce_plan._rigid(m.astype(np.float32))
    u, _ = scipy.linalg.polar(m[:3, :3].astype(np.float32).astype(np.float64))
    np.testing.assert_allclose(rigid[:3, :3], u, atol=1e-12)
    np.testing.assert_allclose(reduce_plan._mul(rigid, reduce_plan._rigid_inverse(rigid)), np.eye(4), atol=1e-12)
    a = np.array([screw_matrix(rng.normal(size=3), rng.normal(size=3), rng.uniform(0, 3), 0.3) for _ in range(6)])
    b = np.array([screw_matrix(rng.normal(size=3), rng.normal(size=3), rng.uniform(0, 3), -0.2) for _ in range(6)])
    bound, theta = reduce_plan._body_error(a, b, 0.7)
    want = Rotation.from_matrix(np.einsum("nji,njk->nik", a[:, :3, :3], b[:, :3, :3])).magnitude()
    np.testing.assert_allclose(theta, want, atol=1e-7)
    np.testing.assert_allclose(bound, np.linalg.norm(a[:, :3, 3] - b[:, :3, 3], axis=1) + 1.4 * np.sin(want / 2), atol=1e-7)
    frames = reduce_plan.dense_frames([np.array([1.5, 4.0]), np.array([2.0, 3.25, 5.00001])])
    np.testing.assert_array_equal(frames, [1.5, 2.0, 3.0, 3.25, 4.0, 5.0])
    assert reduce_plan._chain_order(np.array([2, -1, 1]), 3) == [1, 2, 0]  # parents first


def test_preview_space_from_probes_of_a_known_transform(rng):
    """`preview_geometry.space_from_probes` recovers `f(M) = [A M3 D | L t + l]` from the probes
    Blender's bone transform gives, and maps matrices as f does."""
    a = Rotation.random(random_state=5).as_matrix()
    d = np.array([1.0, 2.0, 0.5])
    big_l, small_l = rng.normal(size=(3, 3)), rng.normal(size=3)

    def f(m):
        out = np.eye(4)
        out[:3, :3] = a @ m[:3, :3] @ np.diag(d)
        out[:3, 3] = big_l @ m[:3, 3] + small_l
        return out

    moved = []
    for i in range(3):
        t = np.eye(4)
        t[i, 3] = 1.0
        moved.append(f(t))
    world = screw_matrix((1, 0, 0), (0, 1, 0), 0.4, 0.2)
    space = preview_geometry.space_from_probes(world, f(np.eye(4)), np.array(moved), f(preview_geometry.CYCLE))
    poses = np.array([screw_matrix(rng.normal(size=3), rng.normal(size=3), rng.uniform(0, 3), 0.1) for _ in range(4)])
    got = space.apply(poses)
    for g, p in zip(got, poses):
        w = world @ f(p)
        np.testing.assert_allclose(g, w, atol=1e-9)
    assert space.matrix is None  # location and rotation go through different matrices
    vertices = preview_geometry.instance_vertices(np.eye(3), poses)
    np.testing.assert_allclose(vertices[3:6], (poses[1][:3, :3] @ np.eye(3)).T + poses[1][:3, 3], atol=1e-5)


def cubic(p0, p1, p2, p3, t):
    s = 1.0 - t
    return s**3 * p0 + 3 * s * s * t * p1 + 3 * s * t * t * p2 + t**3 * p3


def test_split_bezier_cuts_the_segment_blender_plays():
    """The two halves of `bezier.split_bezier` trace the segment (handles within its time span,
    so Blender plays them uncorrected), and the cut point is at the frame asked for."""
    p = [np.array(v, float) for v in ((1.0, 0.0), (3.0, 2.0), (6.0, -1.0), (9.0, 1.0))]
    a1, a2, point, b1, b2 = bezier.split_bezier(*p, 4.0)
    assert point[0] == pytest.approx(4.0, abs=1e-12)
    ts = np.linspace(0.0, 1.0, 11)[:, None]
    whole = cubic(*p, np.linspace(0.0, 1.0, 2001)[:, None])
    for half in (cubic(p[0], a1, a2, point, ts), cubic(point, b1, b2, p[3], ts)):
        # every point of a half lies on the whole segment (nearest of a dense sampling)
        gap = np.min(np.linalg.norm(whole[None] - half[:, None], axis=2), axis=1)
        assert gap.max() < 5e-3, gap
    # handles longer than the segment in time are shortened as Blender does: the cut still lands on the frame
    long = [p[0], np.array([8.0, 3.0]), np.array([2.0, -2.0]), p[3]]
    assert bezier.split_bezier(*long, 7.5)[2][0] == pytest.approx(7.5, abs=1e-12)
    assert smooth_options.Options().scheme == "four_point" and smooth_options.Options().timing == "keys"
    assert [s[0] for s in smooth_options.SCHEMES] == ["four_point", "bspline", "jarek"]
