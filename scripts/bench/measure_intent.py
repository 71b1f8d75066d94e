"""What Smooth Motion keeps of what the animator meant (issue 17), measured with the default
settings against Blender's own playback of the keys: the closing table of issue 17.

Cases (each a fresh scene, one object, Smooth Motion with its default options):
  spins     Z Euler keys 0/360/720, 0/270, a wheel 0..800 in 5 keys, an axis-angle 540:
            the largest angle to Blender's playback at the keys and span middles, and the
            total turn (Blender's: 720, 270, 800, 540)
  holds     a CONSTANT hold (frames 10-19, pop at 20) and a hold of two equal keys: how far
            the held frames move, and the pop's size against Blender's
  easing    a two-key EASE_IN_OUT Bezier, EXPO ease in-out, custom handles: the largest
            difference of the fraction of the way travelled (percent of the span) and of the
            location (units), against Blender's playback
  keys      a random keyed motion (7 keys): the largest miss of the key poses (units, degrees)
  cycles    a walk with Repeat with Offset: distance to Blender's playback at frame 121 and
            the largest over three cycles after the keys

Run with the extension to measure (default: the newest dist/ zip):
    SCREWBENDER_EXTENSION_ZIP=dist/screwbender-...zip PYTHONPATH=.venv/bpy/5.0 \\
        .venv/bin/python scripts/bench/measure_intent.py [--json out.json]
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "demo"))
import demo_common  # noqa: E402

demo_common.blender_with_addon()
import bpy  # noqa: E402
from mathutils import Euler  # noqa: E402


def fresh() -> None:
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)


def new_object(name: str, mode: str) -> bpy.types.Object:
    obj = bpy.data.objects.new(name, None)
    bpy.context.scene.collection.objects.link(obj)
    obj.rotation_mode = mode
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    obj.select_set(True)
    bpy.context.view_layer.objects.active = obj
    return obj


def playback(obj, frames) -> np.ndarray:
    scene = bpy.context.scene
    out = []
    for f in frames:
        whole = math.floor(f)
        scene.frame_set(int(whole), subframe=float(f - whole))
        out.append(np.array(obj.matrix_basis))
    return np.array(out)


def angles(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    r = np.einsum("nji,njk->nik", a[:, :3, :3], b[:, :3, :3])
    return np.degrees(np.arccos(np.clip((np.trace(r, axis1=1, axis2=2) - 1) / 2, -1, 1)))


def total_turn_z(m: np.ndarray) -> float:
    z = np.degrees(np.unwrap(np.arctan2(m[:, 1, 0], m[:, 0, 0])))
    return float(z[-1] - z[0])


def smooth() -> None:
    assert bpy.ops.screwbender.smooth() == {"FINISHED"}


def spin_case(values, frames) -> dict:
    fresh()
    obj = new_object("Wheel", "XYZ")
    for f, v in zip(frames, values):
        obj.rotation_euler = (0.0, 0.0, math.radians(v))
        obj.location = (0.02 * f, 0.0, 0.0)
        obj.keyframe_insert("rotation_euler", frame=f)
        obj.keyframe_insert("location", frame=f)
    check = sorted(set(frames) | {0.5 * (a + b) for a, b in zip(frames, frames[1:])})
    every = np.arange(frames[0], frames[-1] + 1.0)
    blender, blender_every = playback(obj, check), playback(obj, every)
    smooth()
    return {"angle": float(angles(playback(obj, check), blender).max()),
            "turn": total_turn_z(playback(obj, every)), "blender_turn": total_turn_z(blender_every)}


def axis_angle_case() -> dict:
    fresh()
    obj = new_object("Spinner", "AXIS_ANGLE")
    axis = np.array([0.3, 0.2, 0.9]) / np.linalg.norm([0.3, 0.2, 0.9])
    for f, a in zip([1, 16, 31], [0.0, 270.0, 540.0]):
        obj.rotation_axis_angle = (math.radians(a), *axis)
        obj.keyframe_insert("rotation_axis_angle", frame=f)
    check = [1, 8.5, 16, 23.5, 31]
    blender = playback(obj, check)
    smooth()
    every = playback(obj, np.arange(1.0, 32.0))
    steps = np.einsum("nji,njk->nik", every[:-1, :3, :3], every[1:, :3, :3])
    from scipy.spatial.transform import Rotation  # measurement only (scipy is a test requirement)

    turned = float(np.degrees(np.sum(Rotation.from_matrix(steps).as_rotvec() @ axis)))
    return {"angle": float(angles(playback(obj, check), blender).max()), "turn": turned, "blender_turn": 540.0}


def hold_case(kind: str) -> dict:
    fresh()
    obj = new_object("Ball", "XYZ")
    if kind == "constant":
        keys = [(1, 0.0), (5, 2.0), (10, 4.0), (20, 8.0), (30, 9.0)]
        held, pop = np.arange(10.0, 20.0), 20
    else:
        keys = [(1, 0.0), (8, 2.0), (18, 2.0), (26, 4.0), (35, 5.0)]
        held, pop = np.arange(8.0, 19.0), None
    for f, x in keys:
        obj.location = (x, 0.5 * x, 0.0)
        obj.rotation_euler = (0.0, 0.1 * x, 0.0)
        obj.keyframe_insert("location", frame=f)
        obj.keyframe_insert("rotation_euler", frame=f)
    if kind == "constant":
        for fc in fcurves(obj):
            for kp in fc.keyframe_points:
                if kp.co[0] == 10:
                    kp.interpolation = "CONSTANT"
    blender_pop = playback(obj, [pop - 1, pop])[:, 0, 3] if pop else None
    smooth()
    m = playback(obj, held)
    out = {"drift": float(np.linalg.norm(m[:, :3, 3] - m[0, :3, 3], axis=1).max())}
    if pop:
        ours = playback(obj, [pop - 1, pop])[:, 0, 3]
        out["pop"], out["blender_pop"] = float(ours[1] - ours[0]), float(blender_pop[1] - blender_pop[0])
    return out


def fcurves(obj):
    adt = obj.animation_data
    action = adt.action
    if hasattr(action, "layers") and len(action.layers):
        for layer in action.layers:
            for strip in layer.strips:
                bag = strip.channelbag(adt.action_slot)
                if bag is not None:
                    return list(bag.fcurves)
    return list(action.fcurves)


def travelled(m: np.ndarray) -> np.ndarray:
    step = np.linalg.norm(np.diff(m[:, :3, 3], axis=0), axis=1) + np.linalg.norm(np.diff(m[:, :3, :3], axis=0), axis=(1, 2))
    done = np.concatenate(([0.0], np.cumsum(step)))
    return done / done[-1]


def ease_case(kind: str) -> dict:
    fresh()
    obj = new_object(f"Ease{kind}", "XYZ")
    for f, loc, rot in ((1, (0, 0, 0), (0, 0, 0)), (25, (6, 2, 1), (0.4, 0.3, 1.2))):
        obj.location, obj.rotation_euler = loc, rot
        obj.keyframe_insert("location", frame=f)
        obj.keyframe_insert("rotation_euler", frame=f)
    for fc in fcurves(obj):
        first, last = fc.keyframe_points
        if kind == "EXPO":
            first.interpolation, first.easing = "EXPO", "EASE_IN_OUT"
        elif kind == "HANDLES":
            first.handle_right_type = last.handle_left_type = "FREE"
            dv = last.co[1] - first.co[1]
            first.handle_right = (first.co[0] + 14.0, first.co[1] + 0.05 * dv)
            last.handle_left = (last.co[0] - 2.0, last.co[1] - 0.02 * dv)
        fc.update()
    frames = np.arange(1.0, 26.0)
    blender = playback(obj, frames)
    smooth()
    ours = playback(obj, frames)
    return {"fraction": float(100 * np.abs(travelled(ours) - travelled(blender)).max()),
            "location": float(np.linalg.norm(ours[:, :3, 3] - blender[:, :3, 3], axis=1).max()),
            "speed_first_frame": float(np.linalg.norm(ours[1, :3, 3] - ours[0, :3, 3])),
            "blender_speed_first_frame": float(np.linalg.norm(blender[1, :3, 3] - blender[0, :3, 3]))}


def keys_case() -> dict:
    fresh()
    rng = np.random.default_rng(7)
    obj = new_object("Random", "XYZ")
    frames = np.cumsum(rng.integers(3, 12, 7)).astype(float)
    previous = None
    for f in frames:
        obj.location = rng.uniform(-3, 3, 3)
        e = Euler(rng.normal(0, 1.0, 3), "XYZ")
        if previous is not None:
            e.make_compatible(previous)
        obj.rotation_euler, previous = e, e
        obj.keyframe_insert("location", frame=f)
        obj.keyframe_insert("rotation_euler", frame=f)
    keys = playback(obj, frames)
    smooth()
    hit = playback(obj, frames)
    return {"location": float(np.linalg.norm(hit[:, :3, 3] - keys[:, :3, 3], axis=1).max()),
            "angle": float(angles(hit, keys).max())}


def cycles_case() -> dict:
    fresh()
    obj = new_object("Walker", "XYZ")
    for f, x, z, turn in [(1, 0.0, 0.0, 0.0), (7, 0.6, 0.3, 0.2), (13, 1.0, 0.0, 0.0), (19, 1.5, 0.3, -0.2), (25, 2.0, 0.0, 0.0)]:
        obj.location = (x, 0.0, z)
        obj.rotation_euler = (0.0, 0.0, turn)
        obj.keyframe_insert("location", frame=f)
        obj.keyframe_insert("rotation_euler", frame=f)
    for fc in fcurves(obj):
        mod = fc.modifiers.new("CYCLES")
        mod.mode_before = mod.mode_after = "REPEAT_OFFSET"
    after = np.arange(25.0, 25.0 + 3 * 24 + 1)
    blender = playback(obj, after)
    at_121 = playback(obj, [121.0])
    smooth()
    ours = playback(obj, after)
    return {"at_121": float(np.linalg.norm(playback(obj, [121.0])[0, :3, 3] - at_121[0, :3, 3])),
            "after_keys": float(np.linalg.norm(ours[:, :3, 3] - blender[:, :3, 3], axis=1).max())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", type=Path)
    args = parser.parse_args()
    results = {
        "spin 0/360/720": spin_case([0, 360, 720], [1, 21, 41]),
        "spin 0/270": spin_case([0, 270], [1, 21]),
        "wheel 0..800, 5 keys": spin_case([0, 150, 400, 620, 800], [1, 8, 20, 31, 40]),
        "axis-angle 540": axis_angle_case(),
        "CONSTANT hold": hold_case("constant"),
        "equal-key hold": hold_case("equal"),
        "ease in/out (Bezier)": ease_case("EASE_IN_OUT"),
        "EXPO ease in/out": ease_case("EXPO"),
        "custom handles": ease_case("HANDLES"),
        "key poses (random motion)": keys_case(),
        "Repeat with Offset walk": cycles_case(),
    }
    print(f"Blender {bpy.app.version_string}, Smooth Motion with its default options ({demo_common.extension_zip().name})")
    for name, values in results.items():
        print(f"  {name}: " + ", ".join(f"{k} {v:.4g}" for k, v in values.items()))
    if args.json:
        args.json.write_text(json.dumps(results, indent=1))


if __name__ == "__main__":
    main()
