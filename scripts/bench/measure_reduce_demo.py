"""Why Reduce Keys keeps most frames of the demo scene's Smooth Motion bake (issue 26, item 3).

The bench's demo clip is Smooth Motion's Every Step result on the demo scene: LINEAR keys on
every frame. Blender plays straight lines in channel space between them, and the bench checks
the reduced keys against that playback at every frame and three subframes between frames, as
Reduce Keys does (`between="linear"`). A Bezier curve spanning several frames must then pass
within the tolerance of the polyline's corners and of its chords' quarter points; where the
polyline turns by more than the tolerance allows (its second difference over 8, the gap at a
chord's middle between the polyline and any smooth curve through its corners), no key can be
left out there.

For each object of the clip, read through the add-on's own Reduce Keys reading
(`blender/reduce.py`: the dense poses and the body radius) and measured with numpy:
- its body radius, its speed (largest distance any point of the body moves in a frame) and turn
  (degrees a frame);
- the share of the frames where the polyline's corner gap `|d2|/8` (translation plus radius
  times the rotation's second difference, on the body) exceeds each tolerance's distance (a
  lower bound on the key frames against the LINEAR playback, from the corners alone);
- the key frames `polyscrew.reduce_keys` keeps per reference between frames: "linear" (the
  bake's playback: what the bench measures), "screw" (the screw between frames), "cubic" (the
  smooth curve through the baked poses: what Smooth Motion with Keys: Reduced measures).

Run after scripts/build_extension.sh:
    PYTHONPATH=.pylib:.venv/bpy/5.0 .venv/bin/python scripts/bench/measure_reduce_demo.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_reduce  # noqa: E402  (installs the add-on; the demo clip)

bpy = bench_reduce.bpy
TOLERANCES = bench_reduce.TOLERANCES


def addon(name: str):
    return sys.modules[next(m for m in sys.modules if m.endswith(f"screwbender.blender.{name}"))]


def main() -> None:
    red, owners, channels = addon("reduce"), addon("owners"), addon("channels")
    clip = bench_reduce.clip_demo()
    print(f"Blender {bpy.app.version_string}: the demo scene's Smooth Motion bake (Every Step, LINEAR keys)")
    for obj, _ in clip["owners"]:
        owner = owners.as_owner(obj)
        motion = red.read_motion(owner, channels.object_fcurves(obj))
        batch = red.batches([(owner, motion)], red.Options())[0]
        item, frames = batch.items[0], batch.frames
        poses = item.poses
        r = item.radius
        step = np.linalg.norm(np.diff(poses[:, :3, 3], axis=0), axis=1)
        rel = np.einsum("nji,njk->nik", poses[:-1, :3, :3], poses[1:, :3, :3])
        turn = np.degrees(np.arccos(np.clip((np.trace(rel, axis1=1, axis2=2) - 1) / 2, -1, 1)))
        # the corner gap on the body: points at the radius along the three axes, and the origin
        points = np.concatenate([np.zeros((1, 3)), r * np.eye(3), -r * np.eye(3)])
        world = np.einsum("nij,pj->npi", poses[:, :3, :3], points) + poses[:, None, :3, 3]
        gap = np.linalg.norm(world[:-2] - 2 * world[1:-1] + world[2:], axis=2).max(axis=1) / 8.0
        print(
            f"  {obj.name}: {len(frames)} frames, radius {r:.3f}, up to {1e3 * (step + np.radians(turn) * r).max():.1f} mm "
            f"and {turn.max():.2f} degrees a frame (median {1e3 * np.median(step + np.radians(turn) * r):.1f} mm, "
            f"{np.median(turn):.2f} degrees); corner gap median {1e3 * np.median(gap):.2f} mm, "
            f"max {1e3 * gap.max():.2f} mm; between={batch.between}"
        )
        for distance, angle in TOLERANCES:
            corners = float(np.mean(gap > distance))
            line = f"    {1e3 * distance:g} mm / {angle:g} deg: corner gap above the distance at {corners:.0%} of the frames;"
            for between in ("linear", "screw", "cubic"):
                options = red.Options(distance=distance, angle=np.radians(angle))
                result = red.solve(batch.items, frames, options, batch.cyclic, between)[0]
                line += f" {between} {result.keys} key frames ({result.keys / len(frames):.0%})"
            print(line, flush=True)


if __name__ == "__main__":
    main()
