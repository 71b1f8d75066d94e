"""Key fractions of `polyscrew.reduce_keys` (issue 26) on synthetic and captured-like motion.

Clips (30 frames per second, metres, built here with numpy and scipy):
- walk root: a character's hips walking 10 s (forward 1.4 m/s, bob, sway, yaw and roll);
- limb swing: a thigh swinging +-29 degrees at 1 Hz (body radius 0.45 m);
- tumble: a smooth random tumbling flight (rotation vector and path random cubic splines);
- captured: the walk root with 0.5 mm / 0.05 degree sensor noise per frame, the noise
  removed by `polyscrew.denoise` (Remove Noise) first, as a capture would be;
- rig: 20 bones in two chains of ten (the walk's hips, limbs swinging), world-space tolerance.
Tolerances: 0.5 mm / 0.05 degrees, 1 mm / 0.5 degrees, 5 mm / 1 degree, in Euler XYZ; the
dense motion between frames the screw (`between="screw"`, the default) and the cubic through
the frames around (`between="cubic"`).

For each: key frames as a fraction of the frames (the largest over the owners and the
total), the largest errors measured, and the time of the call (one thread).

Run: PYTHONPATH=<polyscrew> .venv/bin/python scripts/measure_reduce.py
"""

import time

import numpy as np
import polyscrew
from scipy.interpolate import CubicSpline
from scipy.spatial.transform import Rotation

FPS = 30.0
MM = 1e-3
DEG = np.pi / 180
TOLERANCES = [(0.5 * MM, 0.05 * DEG), (1 * MM, 0.5 * DEG), (5 * MM, 1 * DEG)]


def poses(rotvec, translation):
    out = np.zeros((len(rotvec), 4, 4))
    out[:, :3, :3] = Rotation.from_rotvec(rotvec).as_matrix()
    out[:, :3, 3] = translation
    out[:, 3, 3] = 1
    return out


def walk_root(n):
    t = np.arange(n) / FPS
    w = lambda f, p=0.0: np.sin(2 * np.pi * f * t + p)  # noqa: E731
    return poses(np.stack([0.05 * w(2), 0.03 * w(1), 0.09 * w(1, 0.3)], -1),
                 np.stack([0.02 * w(1), 1.4 * t, 1.0 + 0.03 * w(2)], -1))


def limb(n, phase=0.0, amplitude=0.5):
    t = np.arange(n) / FPS
    return poses(np.stack([amplitude * np.sin(2 * np.pi * t + phase), 0.05 * np.sin(4 * np.pi * t + phase),
                           np.zeros(n)], -1), np.zeros((n, 3)))


def tumble(n, seed=1):
    rng = np.random.default_rng(seed)
    u = np.linspace(0, 1, 8)
    s = np.linspace(0, 1, n)
    return poses(CubicSpline(u, rng.normal(0, 0.5, (8, 3)))(s), CubicSpline(u, rng.normal(0, 0.5, (8, 3)))(s))


def captured(n, seed=2):
    rng = np.random.default_rng(seed)
    clean = walk_root(n)
    noisy = clean.copy()
    noisy[:, :3, :3] = Rotation.from_rotvec(rng.normal(0, 0.05 * DEG, (n, 3))).as_matrix() @ clean[:, :3, :3]
    noisy[:, :3, 3] += rng.normal(0, 0.5 * MM, (n, 3))
    return polyscrew.denoise(noisy, np.arange(n, dtype=float)).poses


def rig(n):
    bones = []
    parents = []
    offsets = []
    for chain in range(2):
        for k in range(10):
            if k == 0:
                bones.append(walk_root(n) if chain == 0 else limb(n, 1.0, 0.3))
                parents.append(-1 if chain == 0 else 0)
            else:
                bones.append(limb(n, 0.3 * k + chain, 0.25))
                parents.append(len(bones) - 2)
            off = np.eye(4)
            off[1, 3] = 0.0 if (chain == 0 and k == 0) else 0.1
            offsets.append(off)
    return np.array(bones), np.array(parents), np.array(offsets)


def run(name, clip, radius, **kw):
    n = clip.shape[1]
    frames = np.arange(n, dtype=float)
    for (distance, angle), between in [(t, b) for t in TOLERANCES for b in ("screw", "cubic")]:
        start = time.perf_counter()
        r = polyscrew.reduce_keys(clip, frames, "XYZ", radius, distance, angle, threads=1, between=between, **kw)
        ms = 1e3 * (time.perf_counter() - start)
        ok = (r["distance_error"] <= distance).all() and (r["angle_error"] <= angle).all()
        print(f"| {name} | {distance / MM:g} mm / {angle / DEG:g} deg | {between} | {len(clip)} x {n} | "
              f"{r['keys'].max() / n:.1%} | {r['keys'].sum() / (len(clip) * n):.1%} | "
              f"{r['distance_error'].max() / MM:.3f} mm, {np.degrees(r['angle_error'].max()):.3f} deg "
              f"{'(within)' if ok else '(OVER)'} | {ms:.1f} ms |")


def main():
    n = 300
    print("| clip | tolerance | between frames | owners x frames | keys, worst owner | keys, all owners | largest error | time |")
    print("| --- | --- | --- | --- | --- | --- | --- | --- |")
    run("walk root", walk_root(n)[None], 0.3)
    run("limb swing", limb(n)[None], 0.45)
    run("tumble", tumble(n)[None], 0.3)
    run("captured (walk + noise, Remove Noise)", captured(n)[None], 0.3)
    bones, parents, offsets = rig(n)
    run("rig, 2 chains of 10", bones, 0.1, parents=parents, offsets=offsets)


if __name__ == "__main__":
    main()
