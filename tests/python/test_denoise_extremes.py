"""polyscrew.denoise at the extremes of issue 28 (items 3 and 5), each in a capped child
(`capped.run_capped`) where it computes, and the concurrent writer in-process.

- Every strength the operator's property allows (0 up, no hard maximum) gives a finite,
  rigid result; a strength above 100 median spacings acts as 100 spacings and the result
  reports the strength used. Before: 0.0005, 0.001, 316, 500 and 1000 frames on a plain
  250-frame clip, and four keys 0.001 frames apart at 2 or 20, raised "poses: values too
  large: the computation overflowed".
- The unit of time: times multiplied by 1e50, 1e-100 or 0.1 give the same poses (to the
  rounding of the times) and the strengths in the new unit. Before: 1e-100 was refused
  ("times 0 to 3 are too close together or too far apart for f64"; the issue saw
  "overflowed", and at 1e50 poses moved by 0.0059 on its clip; on this clip 1e50 and 0.1
  already agreed to 1.5e-11).
- Held poses are read once: a thread writing NaN (or a scale) into the held rows of the
  input while `denoise` works cannot reach the result. Before: every held output pose NaN
  (3 of 3 runs).
"""

from __future__ import annotations

import threading
import time

import numpy as np
import polyscrew

from capped import run_capped

#: A plain noisy clip of `n` frames (a tumbling flight), built in the child.
CLIP = """
from scipy.spatial.transform import Rotation
def clip(n, seed=1):
    t = np.arange(n) / 24.0
    rng = np.random.default_rng(seed)
    p = np.zeros((n, 4, 4)); p[:, 3, 3] = 1
    axes = np.stack([np.cos(0.4 * t), np.sin(0.3 * t), np.ones_like(t)], -1)
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    rv = axes * (1.1 * t)[:, None] + rng.normal(0, 0.01, (n, 3))
    p[:, :3, :3] = Rotation.from_rotvec(rv).as_matrix()
    p[:, :3, 3] = np.stack([2 * np.cos(0.5 * t), 1.5 * np.sin(0.3 * t), 0.3 * t], -1) + rng.normal(0, 0.02, (n, 3))
    return p
def rigid_error(p):
    r = p[..., :3, :3]
    return float(np.abs(np.swapaxes(r, -1, -2) @ r - np.eye(3)).max()) + float(np.abs(np.linalg.det(r) - 1).max())
"""


def test_every_strength_the_property_allows_is_served():
    out = run_capped(
        CLIP
        + """
p, t = clip(250), np.arange(250.0)
for s in [0.0, 1e-300, 0.0005, 0.001, 0.25, 2.0, 20.0, 316.0, 500.0, 1000.0, 1e6, 1e300]:
    d = report(lambda: ps.denoise(p, t, strength=s))
    if d is not None:
        print(json.dumps({"s": s, "used": d.rotation_strength, "used_t": d.translation_strength,
                          "rigid": rigid_error(d.poses), "moved": float(np.abs(d.poses - p).max())}))
at100 = ps.denoise(p, t, strength=100.0).poses
print(json.dumps({"same_as_100": float(np.abs(ps.denoise(p, t, strength=1000.0).poses - at100).max())}))
# Four keys 0.001 frames apart (as close as Blender's float32 frames keep them near 1..100).
close = clip(4, seed=2)
for s in [2.0, 20.0, None]:
    d = report(lambda: ps.denoise(close, 1 + 0.001 * np.arange(4), strength=s))
    if d is not None:
        print(json.dumps({"close": s, "used": d.rotation_strength, "rigid": rigid_error(d.poses)}))
"""
    )
    results = [o for o in out if "s" in o]
    for o in out:
        assert o.get("finite", True), out
    print("strength asked -> used (frames), rigidity, largest change:")
    for o in results:
        print(f"  {o['s']:g} -> {o['used']:.6g} / {o['used_t']:.6g}, {o['rigid']:.1e}, {o['moved']:.3g}")
    assert len(results) == 12  # every one computed (before: 0.0005, 0.001, 316, 500, 1000 refused)
    for o in results:
        want = min(o["s"], 100.0)
        assert abs(o["used"] - want) <= 1e-12 * want and abs(o["used_t"] - want) <= 1e-12 * want, o
        assert o["rigid"] < 1e-12, o
    # A tiny strength leaves the clip as it is (to rounding).
    assert [o for o in results if o["s"] == 0.0005][0]["moved"] < 1e-9
    same = [o for o in out if "same_as_100" in o][0]["same_as_100"]
    assert same == 0.0  # 1000 frames acts as 100 (100 spacings)
    close = [o for o in out if "close" in o]
    print("four keys 0.001 apart:", close)
    assert len(close) == 3
    for o in close:
        if o["close"] is not None:
            assert abs(o["used"] - min(o["close"], 0.1)) <= 1e-12, o  # 100 spacings of 0.001
        assert o["rigid"] < 1e-12


def test_the_unit_of_time_does_not_matter():
    out = run_capped(
        CLIP
        + """
p, t = clip(250), np.arange(250.0)
base = ps.denoise(p, t)
for k in [1e50, 1e-100, 0.1, 1e-298]:  # (keys closer than 1e-300 are refused by design)
    d = report(lambda: ps.denoise(p, t * k))
    if d is not None:
        print(json.dumps({"k": k, "poses": float(np.abs(d.poses - base.poses).max()),
                          "rotation": d.rotation_strength / k / base.rotation_strength - 1,
                          "translation": d.translation_strength / k / base.translation_strength - 1}))
"""
    )
    rows = [o for o in out if "k" in o]
    print("time unit x k: largest pose change, strength changes (relative):")
    for o in rows:
        print(f"  {o['k']:g}: {o['poses']:.2e}, {o['rotation']:.1e}, {o['translation']:.1e}")
    assert len(rows) == 4 and all(o.get("finite", True) for o in out), out
    for o in rows:
        # The times rounded to their last bit move the poses by about 1e-7 (noise 0.01 rad, 2 cm).
        assert o["poses"] < 1e-6 and abs(o["rotation"]) < 1e-9 and abs(o["translation"]) < 1e-9, o


def _flight(n: int, bodies: int) -> np.ndarray:
    t = np.arange(n) / 24.0
    p = np.zeros((bodies, n, 4, 4))
    for b in range(bodies):
        a = 0.3 * t + b
        p[b, :, 0, 0], p[b, :, 0, 1], p[b, :, 1, 0], p[b, :, 1, 1] = np.cos(a), -np.sin(a), np.sin(a), np.cos(a)
        p[b, :, 2, 2] = 1.0
        p[b, :, :3, 3] = np.stack([np.cos(0.5 * t), np.sin(0.2 * t) + b, 0.1 * t], -1)
        p[b, :, :3, 3] += np.random.default_rng(b).normal(0, 0.01, (n, 3))
    p[..., 3, 3] = 1.0
    return p


def _with_writer(value: str) -> dict:
    """One denoise call on 60 bodies x 2,000 frames, half held, while another thread writes
    `value` (NaN, or a scale) into every held row of the input; what came back."""
    poses = _flight(2000, 60)
    original = poses.copy()
    held = np.zeros(2000, dtype=bool)
    held[::2] = True
    start, done = threading.Event(), threading.Event()
    first = {}

    def writer():
        start.wait()
        time.sleep(0.05)  # inside the call's work, after its reading
        while not done.is_set():
            if value == "nan":
                poses[:, held, 0, 0] = np.nan
            else:
                poses[:, held, :3, :3] *= 2.0
            first.setdefault("at", time.perf_counter())
            time.sleep(0.001)

    thread = threading.Thread(target=writer)
    thread.start()
    try:
        start.set()
        result = polyscrew.denoise(poses, np.arange(2000.0), held=held, threads=1)
        returned = time.perf_counter()
    finally:
        done.set()
        thread.join()
    out = result.poses
    r = out[..., :3, :3]
    return {
        "wrote_during_call": "at" in first and first["at"] < returned,
        "held_nan": int(np.isnan(out[:, held]).any(axis=(2, 3)).sum()),
        "held_exact": bool(np.array_equal(out[:, held], original[:, held])),
        "finite": bool(np.isfinite(out).all()),
        "rigid": float(np.abs(np.swapaxes(r, -1, -2) @ r - np.eye(3)).max()),
        "held": int(held.sum()) * poses.shape[0],
    }


def test_held_poses_are_read_once_whatever_another_thread_writes():
    for value in ["nan", "nan", "nan", "scale"]:
        got = _with_writer(value)
        print(f"writer of {value}: {got}")
        assert got["wrote_during_call"], got  # the writer did write while the work ran
        assert got["held_nan"] == 0 and got["held_exact"] and got["finite"], got
        assert got["rigid"] < 1e-12, got
