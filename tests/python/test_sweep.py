"""polyscrew.sweep: the render-equivalence promise of Rossignac-Kim ("Swept volumes"),
measured against the union of 2,000 densely sampled instances of the body, plus errors.

For each body (box, cylinder, torus, a 10,000-triangle bumpy torus) and each motion (one
screw, a subdivided polyscrew), from 20 view directions: orthographic depth images of the
swept mesh and of the union of the instances (software z-buffer in ``raster.py``) must agree
within 0.5% of the scene size in at least 99% of the pixels both cover, and their covered
pixel sets may differ by at most 1%. The figures are printed (``pytest -s``).
"""

from __future__ import annotations

import time

import numpy as np
import polyscrew
import pytest

from conftest import rigid
from raster import View, depth_image, fibonacci_directions, instances_depth_images

INSTANCES = 2000
VIEWS = 20
RES = 200
DEPTH_TOL = 0.005  # of the scene size
MIN_DEPTH_AGREEMENT = 0.99
MAX_SILHOUETTE_DIFF = 0.01


# --- bodies (outward, closed) -------------------------------------------------------------


def box(sx=1.0, sy=0.6, sz=0.4):
    v = np.array([[(i & 1) * sx, ((i >> 1) & 1) * sy, ((i >> 2) & 1) * sz] for i in range(8)])
    v -= v.mean(axis=0)
    t = np.array(
        [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 1, 4], [1, 5, 4],
         [2, 6, 3], [3, 6, 7], [0, 4, 2], [2, 4, 6], [1, 3, 5], [3, 7, 5]]
    )
    return v, t


def cylinder(r=0.4, h=1.0, n=32):
    u = 2 * np.pi * np.arange(n) / n
    ring = np.stack([r * np.cos(u), r * np.sin(u)], axis=1)
    v = np.vstack([[0, 0, -h / 2], [0, 0, h / 2],
                   np.c_[ring, np.full(n, -h / 2)], np.c_[ring, np.full(n, h / 2)]])
    i = np.arange(n)
    j = (i + 1) % n
    lo, hi = 2 + i, 2 + n + i
    loj, hij = 2 + j, 2 + n + j
    t = np.vstack([
        np.c_[np.zeros(n, int), loj, lo],
        np.c_[np.ones(n, int), hi, hij],
        np.c_[lo, loj, hij],
        np.c_[lo, hij, hi],
    ])
    return v, t


def torus(big=0.6, small=0.22, n=32, m=16, bumps=0.0):
    u = 2 * np.pi * np.arange(n) / n
    w = 2 * np.pi * np.arange(m) / m
    uu, ww = np.meshgrid(u, w, indexing="ij")
    s = small * (1.0 + bumps * np.sin(5 * uu) * np.cos(3 * ww))
    r = big + s * np.cos(ww)
    v = np.stack([r * np.cos(uu), r * np.sin(uu), s * np.sin(ww)], axis=-1).reshape(-1, 3)
    i, j = np.meshgrid(np.arange(n), np.arange(m), indexing="ij")
    i, j = i.ravel(), j.ravel()
    a = i * m + j
    b = ((i + 1) % n) * m + j
    c = ((i + 1) % n) * m + (j + 1) % m
    d = i * m + (j + 1) % m
    t = np.vstack([np.c_[a, b, c], np.c_[a, c, d]])
    return v, t


BODIES = {
    "box": box(),
    "cylinder": cylinder(),
    "torus": torus(),
    "bumpy10k": torus(n=100, m=50, bumps=0.25),
}


# --- motions ------------------------------------------------------------------------------


def single_screw():
    a = rigid([0.2, 1.0, 0.3], 0.3, [0.0, 0.0, 0.0])
    b = rigid([1.0, -0.4, 0.8], 2.0, [1.4, 0.6, -0.5])
    keys = np.stack([a, b])
    inst = polyscrew.interpolate(a, b, np.linspace(0.0, 1.0, INSTANCES))
    return keys, inst, 24


def polyscrew_motion():
    keys = np.stack([
        rigid([0, 0, 1], 0.0, [0.0, 0.0, 0.0]),
        rigid([1, 0, 0], 1.2, [1.0, 0.5, 0.0]),
        rigid([0, 1, 1], 2.2, [1.5, -0.5, 0.8]),
        rigid([1, 1, 0], 1.0, [0.5, -1.2, 1.2]),
    ])
    dense = polyscrew.subdivide(keys, "jarek", 3)
    spans = len(dense) - 1
    per = -(-INSTANCES // spans)  # ceil: at least INSTANCES in all
    inst = [polyscrew.interpolate(dense[i], dense[i + 1], np.linspace(0, 1, per, endpoint=False))
            for i in range(spans)]
    inst.append(dense[-1:])
    return dense, np.concatenate(inst), 4


MOTIONS = {"screw": single_screw, "polyscrew": polyscrew_motion}


# --- comparison ---------------------------------------------------------------------------


def scene(vertices, poses):
    """Centre and diagonal of the bounding box of all instances."""
    lo = np.full(3, np.inf)
    hi = np.full(3, -np.inf)
    for chunk in np.array_split(poses, max(1, len(poses) // 200)):
        p = np.einsum("mij,vj->mvi", chunk[:, :3, :3], vertices) + chunk[:, None, :3, 3]
        lo = np.minimum(lo, p.reshape(-1, 3).min(axis=0))
        hi = np.maximum(hi, p.reshape(-1, 3).max(axis=0))
    return (lo + hi) / 2, float(np.linalg.norm(hi - lo))


def compare(a, b, tol):
    """(fraction of pixels covered by both whose depths differ by at most tol, fraction of
    the union of covered pixels covered by only one)."""
    ca, cb = np.isfinite(a), np.isfinite(b)
    both = ca & cb
    agree = np.abs(a[both] - b[both]) <= tol
    return agree.mean() if both.any() else 1.0, (ca ^ cb).sum() / max(1, (ca | cb).sum())


def render_all(views, mesh_v, mesh_t, body_v, body_t, inst):
    swept = [depth_image(view, mesh_v, mesh_t) for view in views]
    return list(zip(swept, instances_depth_images(views, body_v, body_t, inst)))


@pytest.mark.parametrize("motion", list(MOTIONS))
@pytest.mark.parametrize("body", list(BODIES))
def test_depth_images_match_the_union_of_instances(body, motion):
    v, t = BODIES[body]
    poses, inst, steps = MOTIONS[motion]()
    assert len(inst) >= INSTANCES
    t0 = time.perf_counter()
    sv, st = polyscrew.sweep(v, t, poses, steps=steps, caps=True)
    t_sweep = time.perf_counter() - t0
    center, size = scene(v, inst)
    views = [View(d, center, 1.05 * size, RES) for d in fibonacci_directions(VIEWS)]
    tol = DEPTH_TOL * size
    t0 = time.perf_counter()
    agree, sil = zip(*(compare(ds, di, tol) for ds, di in render_all(views, sv, st, v, t, inst)))
    t_render = time.perf_counter() - t0
    print(
        f"\n{body:9s} {motion:9s}: {len(t):6d} tris x {len(inst)} instances = "
        f"{len(t) * len(inst):9d} | swept {len(st):7d} tris ({t_sweep * 1e3:.1f} ms) | "
        f"depth agreement min {min(agree):.4f} mean {np.mean(agree):.4f} | "
        f"silhouette diff max {max(sil):.4f} mean {np.mean(sil):.4f} | render {t_render:.1f} s"
    )
    assert min(agree) >= MIN_DEPTH_AGREEMENT, (body, motion, agree)
    assert max(sil) <= MAX_SILHOUETTE_DIFF, (body, motion, sil)
    if len(t) >= 100:  # a 12-triangle box is cheap to instance anyway
        assert len(st) < len(t) * len(inst) / 10


def test_far_fewer_triangles_than_instances_at_equal_depth_error():
    """Stroboscopic instancing needs many instances to reach the sweep's depth error."""
    for body in ["torus", "bumpy10k"]:
        v, t = BODIES[body]
        poses, inst, steps = single_screw()
        sv, st = polyscrew.sweep(v, t, poses, steps=steps, caps=True)
        center, size = scene(v, inst)
        views = [View(d, center, 1.05 * size, RES) for d in fibonacci_directions(8)]
        tol = DEPTH_TOL * size
        refs = instances_depth_images(views, v, t, inst)

        def error(images):
            # Fraction of the union of covered pixels that differ from the reference by
            # more than tol or are covered by only one of the two images.
            bad = tot = 0
            for img, ref in zip(images, refs):
                cov = np.isfinite(img) | np.isfinite(ref)
                diff = np.abs(np.where(np.isfinite(img), img, 1e30) - np.where(np.isfinite(ref), ref, 1e30))
                bad += (cov & (diff > tol)).sum()
                tot += cov.sum()
            return bad / tot

        e_sweep = error([depth_image(view, sv, st) for view in views])
        found = None
        for m in [4, 8, 16, 32, 48, 64, 96, 128, 192, 256, 512, 1024]:
            strobe = polyscrew.interpolate(poses[0], poses[1], np.linspace(0, 1, m))
            e = error(instances_depth_images(views, v, t, strobe))
            if e <= e_sweep:
                found = (m, e)
                break
        m = found[0] if found else None
        print(
            f"\n{body}: sweep {len(st)} tris, depth error {e_sweep:.4f}; "
            + (f"{m} instances ({m * len(t)} tris) reach error {found[1]:.4f}"
               if found else "1024 instances do not reach it")
        )
        assert found is None or m * len(t) > 3 * len(st), (body, m, len(st))


# --- properties and errors ----------------------------------------------------------------


def test_output_is_a_clean_mesh():
    v, t = BODIES["torus"]
    poses, _, _ = polyscrew_motion()
    sv, st = polyscrew.sweep(v, t, poses, steps=3)
    assert sv.dtype == np.float64 and sv.shape[1] == 3
    assert st.dtype == np.int64 and st.shape[1] == 3
    assert st.min() >= 0 and st.max() < len(sv)
    a, b, c = sv[st[:, 0]], sv[st[:, 1]], sv[st[:, 2]]
    assert np.all(np.linalg.norm(np.cross(b - a, c - a), axis=1) > 0)
    # caps=False drops the end instances.
    _, st2 = polyscrew.sweep(v, t, poses, steps=3, caps=False)
    assert len(st2) == len(st) - 2 * len(t)


@pytest.mark.parametrize(
    "vertices, triangles, poses, match",
    [
        (np.zeros((0, 3)), np.zeros((0, 3), int), None, "no vertices"),
        (box()[0], np.zeros((0, 3), int), None, "no triangles"),
        (np.where(np.arange(24).reshape(8, 3) == 7, np.nan, box()[0]), box()[1], None, "vertex 2"),
        (box()[0], np.vstack([box()[1], [[0, 1, 1]]]), None, "triangle 12.*zero area"),
        (box()[0], np.vstack([box()[1], [[0, 1, 9]]]), None, "triangle 12.*vertex 9"),
        (box()[0], np.vstack([box()[1], [[0, -1, 2]]]), None, "triangle 12"),
        (box()[0], box()[1], np.eye(4)[None], "1 poses given, at least 2"),
        (box()[0], box()[1], np.eye(4), "1 poses given, at least 2"),
        (box()[0], box()[1], np.stack([np.eye(4), np.diag([2.0, 1, 1, 1])]), "pose 1"),
        (box()[0][:, :2], box()[1], None, "vertices.*shape"),
    ],
)
def test_bad_input_raises(vertices, triangles, poses, match):
    if poses is None:
        poses = np.stack([np.eye(4), rigid([0, 0, 1], 1.0, [1, 0, 0])])
    with pytest.raises(ValueError, match=match):
        polyscrew.sweep(vertices, triangles, poses)


def test_bad_steps():
    v, t = box()
    poses = np.stack([np.eye(4), rigid([0, 0, 1], 1.0, [1, 0, 0])])
    for steps in [0, -1, polyscrew.MAX_STEPS + 1]:
        with pytest.raises(ValueError, match="steps"):
            polyscrew.sweep(v, t, poses, steps=steps)
