"""Key fractions of `polyscrew.reduce_keys` (issue 26) on synthetic and captured-like motion.

Clips (30 frames per second, metres, built here with numpy and scipy):
- walk root: a character's hips walking 10 s (forward 1.4 m/s, bob, sway, yaw and roll);
- limb swing: a thigh swinging +-29 degrees at 1 Hz (body radius 0.45 m);
- tumble: a smooth random tumbling flight (rotation vector and path random cubic splines);
- captured: the walk root with 0.5 mm / 0.05 degree sensor noise per frame, the noise
  removed by `polyscrew.denoise` (Remove Noise) first, as a capture would be;
- rig: 20 bones in two chains of ten (the walk's hips, limbs swinging), world-space tolerance;
- bench walk: `scripts/bench/bench_reduce.py`'s 13-bone walk (its formulas, rest pose and bone
  lengths as radii, built here without Blender), at its 24 frames per second and sampled
  at 120 (the same motion, five times the frames): the key fraction of a clip is a density
  per frame, so it depends on the frame rate.
Tolerances: 0.5 mm / 0.05 degrees, 1 mm / 0.5 degrees, 5 mm / 1 degree, in Euler XYZ; the
dense motion between frames the screw (`between="screw"`, the default) and the cubic through
the frames around (`between="cubic"`).

For each: key frames as a fraction of the frames (the largest over the owners and the
total), the largest errors measured, and the time of the call (one thread). Then the bench
walk's hip bob alone: its keys at 1 mm, and the error of the best cubic over a span of 0.28 s
and of 10 frames at 24 fps (why 10 % of that clip's frames is out of reach at 1 mm).

Run: PYTHONPATH=<polyscrew> .venv/bin/python scripts/bench/measure_reduce.py
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


def bone_rest(head, tail):
    """A bone's rest matrix in armature space (roll 0): the shortest turn taking +Y to the
    bone's direction (Blender's `vec_roll_to_mat3` away from -Y), at its head."""
    nor = np.subtract(tail, head) / np.linalg.norm(np.subtract(tail, head))
    k = np.cross([0.0, 1.0, 0.0], nor)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    s2 = k @ k
    out = np.eye(4)
    out[:3, :3] = np.eye(3) + kx + (kx @ kx) * ((1 - nor[1]) / s2 if s2 > 0 else 0.0)
    out[:3, 3] = head
    return out


def bench_walk(n, fps):
    """`scripts/bench/bench_reduce.py`'s walk at `fps` over the same time as its `n` frames at 24:
    each bone's `matrix_basis` (B, N, 4, 4), parents, offsets (parent rest^-1 @ rest), lengths."""
    bones = [("Hips", None, (0, 0, 1.0), (0, 0, 1.1)), ("Spine", "Hips", (0, 0, 1.1), (0, 0, 1.45)),
             ("Head", "Spine", (0, 0, 1.45), (0, 0, 1.75))]
    for side, x in (("L", 0.1), ("R", -0.1)):
        bones += [(f"Thigh.{side}", "Hips", (x, 0, 1.0), (x, 0, 0.55)),
                  (f"Shin.{side}", f"Thigh.{side}", (x, 0, 0.55), (x, 0, 0.1)),
                  (f"Foot.{side}", f"Shin.{side}", (x, 0, 0.1), (x, -0.15, 0.0)),
                  (f"Arm.{side}", "Spine", (2 * x, 0, 1.4), (2.2 * x, 0, 1.12)),
                  (f"Fore.{side}", f"Arm.{side}", (2.2 * x, 0, 1.12), (2.3 * x, -0.05, 0.86))]
    names = [b[0] for b in bones]
    t = np.arange(round(n * fps / 24)) / fps
    w = 2 * np.pi / 1.1
    z = 0 * t
    rot = {"Hips": [0.05 * np.sin(2 * w * t), 0.04 * np.sin(w * t), 0.08 * np.sin(w * t)],
           "Spine": [0.05 + 0.03 * np.sin(2 * w * t), z, -0.1 * np.sin(w * t)],
           "Head": [-0.03 * np.sin(2 * w * t), z, 0.06 * np.sin(w * t)]}
    for side, phase in (("L", 0.0), ("R", np.pi)):
        swing = np.sin(w * t + phase)
        rot[f"Thigh.{side}"] = [0.45 * swing, z, 0.02 * swing]
        rot[f"Shin.{side}"] = [-0.6 * np.clip(np.sin(w * t + phase - 1.2), 0, None) - 0.05, z, z]
        rot[f"Foot.{side}"] = [0.25 * np.sin(w * t + phase + 0.6), z, z]
        rot[f"Arm.{side}"] = [-0.35 * swing, z, 0.05 + z]
        rot[f"Fore.{side}"] = [-0.3 - 0.2 * np.clip(-swing, 0, None), z, z]
    location = np.stack([0.02 * np.sin(w * t), 1.3 * t, 0.03 * np.cos(2 * w * t)], axis=1)
    basis = np.zeros((len(bones), len(t), 4, 4))
    for b, name in enumerate(names):
        # Blender's XYZ Euler: Rz Ry Rx (scipy's extrinsic "xyz")
        basis[b, :, :3, :3] = Rotation.from_euler("xyz", np.stack(rot[name], axis=1)).as_matrix()
        basis[b, :, :3, 3] = location if name == "Hips" else 0.0
        basis[b, :, 3, 3] = 1
    rest = {name: bone_rest(head, tail) for name, _, head, tail in bones}
    parents = np.array([names.index(p) if p else -1 for _, p, _, _ in bones])
    offsets = np.array([np.linalg.inv(rest[p]) @ rest[name] if p else rest[name] for name, p, _, _ in bones])
    lengths = np.array([np.linalg.norm(np.subtract(tail, head)) for _, _, head, tail in bones])
    return basis, parents, offsets, lengths


def cubic_floor(amplitude, omega, h):
    """The max error of the best cubic in time (near-minimax: Lawson's weighted least squares,
    keys not even fixed) to `amplitude cos(omega t)` over a span of `h` seconds: (worst, best)
    over the span's placements in the period. No Bezier segment of that length does better."""
    errors = []
    for t0 in np.linspace(0, 2 * np.pi / omega, 60, endpoint=False):
        t = np.linspace(t0, t0 + h, 2001)
        f = amplitude * np.cos(omega * t)
        basis = np.vander((t - t0) / h, 4)
        w = np.full(len(t), 1.0 / len(t))
        for _ in range(60):
            c = np.linalg.lstsq(basis * np.sqrt(w)[:, None], f * np.sqrt(w), rcond=None)[0]
            e = np.abs(basis @ c - f)
            w = w * e / (w * e).sum()
        errors.append(np.abs(basis @ c - f).max())
    return max(errors), min(errors)


def walk_bob():
    """The bench walk's hip bob alone (location z = 3 cm cos(2 w t), a stride every 1.1 s): its
    keys at 1 mm at 24 and 120 fps, and the best cubic's error over spans of 0.28 s and 10 frames
    at 24 fps (0.42 s)."""
    omega = 2 * 2 * np.pi / 1.1
    for fps in (24, 120):
        t = np.arange(8 * fps) / fps
        p = np.tile(np.eye(4), (len(t), 1, 1))
        p[:, 2, 3] = 0.03 * np.cos(omega * t)
        r = polyscrew.reduce_keys(p[None], np.arange(len(t), dtype=float), "XYZ", 0.0, MM, 0.5 * DEG, threads=1)
        k = int(r["keys"][0])
        print(f"walk's hip bob alone, {fps} fps, 1 mm: {k} keys ({k / len(t):.1%} of frames, a key every "
              f"{8 / (k - 1):.3f} s)")
    for h in (0.28, 10 / 24):
        worst, best = cubic_floor(0.03, omega, h)
        print(f"best cubic to the bob over {h:.3f} s: {worst / MM:.2f} mm at the worst placement, {best / MM:.2f} mm "
              f"at the best")


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
    for fps in (24, 120):
        basis, parents, offsets, lengths = bench_walk(192, fps)
        run(f"bench walk, 13 bones, {fps} fps", basis, lengths, parents=parents, offsets=offsets)
    walk_bob()


if __name__ == "__main__":
    main()
