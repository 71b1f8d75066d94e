"""Growth against owners: Revert, Smooth Motion and Insert Key on Motion beside Blender-only
floors at the same sizes in the same run, each with its own growth exponent (issue 27, item 4:
no operator grows faster than linearly; what grows faster is shown to be Blender's or ours).

For one family of bench_floor.py's scenes (--family objects or rig) at several owner counts
(--sizes), each repetition (--runs, interleaved: every measurement of a size in turn, then the
next repetition) times, in CPU time (`time.process_time`) and wall clock:
  revert                      Revert through `bpy.ops` (after an untimed Smooth Motion);
  revert floor: assign        assigning every owner its previous action again (bench_floor's
                              floor for Revert), bare;
  view-layer update (assign)  the update Blender runs after that (`view_layer.update()`);
  batch_remove                removing the smoothed actions in one `bpy.data.batch_remove`;
  view-layer update (remove)  the update after it;
  revert floor via ops        the assignment and the batch removal inside an operator with
                              Revert's `bl_options` {REGISTER, UNDO} called through `bpy.ops`
                              (its undo push and view-layer update: any operator pays them);
  smooth                      Smooth Motion through `bpy.ops`;
  smooth floor via ops        bench_floor's floor_write (one read of each source curve, the
                              result's curves, one `foreach_set` per written attribute) through
                              `bpy.ops`;
  smooth floor grouped        the same, each curve made in its owner's F-curve group as
                              Blender's keying and the bake put it (a bone's curves in the group
                              named after it): `fcurves.new` in a large channelbag;
  insert_key, insert_key floor via ops   Insert Key on Motion and bench_floor's floor_insert.
Then the medians per size, the least-squares exponent over all sizes and the exponent between
neighbouring sizes. --profile adds one call of each under cProfile (timer: CPU time) per size
and lists, per measurement, the functions whose own time grows most above linear from the
smallest size to the largest (cProfile does not see RNA property reads: they count in their
Python caller).

Without --family it runs CASES (Revert on 20, 100, 500, 2,000 objects x 50 frames; the three
operators on rigs of 20, 100, 300 bones x 250 frames; --quick: small sizes, one run, seconds).
Run after scripts/build_extension.sh (scripts/bench.sh, part `measure`, runs it so;
SCREWBENDER_EXTENSION_ZIP picks another build, for an A/B of two trees run side by side):
    PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench/growth_floor.py [--quick]
    PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench/growth_floor.py --family rig \\
        --sizes 20,100,300 --frames 250 --keys 10 --ops revert,smooth,insert_key --profile
"""

from __future__ import annotations

import argparse
import cProfile
import math
import pstats
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_floor as bf  # noqa: E402  (installs the built extension into a temporary Blender)
import bench_report  # noqa: E402

# isort: split
import bpy  # noqa: E402

#: What bench.growth_floor runs (set before each call).
FLOOR = [lambda: None]


class BENCH_OT_growth_floor(bpy.types.Operator):
    """A floor inside an operator with the writing operators' bl_options, through bpy.ops."""

    bl_idname, bl_label, bl_options = "bench.growth_floor", "Floor", {"REGISTER", "UNDO"}

    def execute(self, context):
        FLOOR[0]()
        return {"FINISHED"}


def grouped_floor_write(objects, shape: dict, values: dict) -> None:
    """bench_floor.floor_write with each curve made in its owner's F-curve group (a bone's
    curves in the group named after it, an object's in "Object Transforms")."""
    bf.read_keys(objects)
    for obj in objects:
        action = bpy.data.actions.new(obj.name + "Floor")
        slot = None
        if bf.SLOTTED:
            slot = action.slots.new(id_type=obj.id_type, name=obj.name)
            bag = action.layers.new("Layer").strips.new(type="KEYFRAME").channelbag(slot, ensure=True)
        for path, index, n in shape[obj.name]:
            group = path.split('"')[1] if path.startswith("pose.bones") else "Object Transforms"
            if bf.SLOTTED:
                fcurve = bag.fcurves.new(path, index=index, group_name=group)
            else:
                fcurve = action.fcurves.new(path, index=index, action_group=group)
            points = fcurve.keyframe_points
            points.add(n)
            for attr, data in values[n].items():
                points.foreach_set(attr, data)
        bf.assign(obj, action, slot)


def cpu_wall(fn) -> tuple[float, float]:
    wall, cpu = time.perf_counter(), time.process_time()
    fn()
    return time.process_time() - cpu, time.perf_counter() - wall


def own_times(fn) -> dict[str, float]:
    """Own CPU time per function of one call of `fn` under cProfile."""
    profiler = cProfile.Profile(time.process_time)
    profiler.enable()
    fn()
    profiler.disable()
    stats = pstats.Stats(profiler).stats
    return {f"{Path(k[0]).name}:{k[1]}({k[2]})": v[2] for k, v in stats.items()}


def one_repetition(stage: bf.Stage, ops: list[str], frames: int, measure) -> None:
    """Every measurement of `ops` once: `measure(name, fn)` times (or profiles) `fn`."""
    objects, screw = stage.objects, bpy.ops.screwbender
    if "revert" in ops:
        copies = stage.fresh()
        screw.smooth()
        results = [o.animation_data.action for o in objects]
        measure("revert floor: assign", lambda: [bf.assign(o, copies[o.name]) for o in objects])
        measure("view-layer update (assign)", bpy.context.view_layer.update)
        measure("batch_remove", lambda: bpy.data.batch_remove(results))
        measure("view-layer update (remove)", bpy.context.view_layer.update)
        stage.clean()
        copies = stage.fresh()
        screw.smooth()
        results = [o.animation_data.action for o in objects]

        def assign_and_remove() -> None:
            for o in objects:
                bf.assign(o, copies[o.name])
            bpy.data.batch_remove(results)

        FLOOR[0] = assign_and_remove
        measure("revert floor via ops", bpy.ops.bench.growth_floor)
        stage.clean()
        stage.fresh()
        screw.smooth()
        measure("revert", screw.revert)
        stage.clean()
    if "smooth" in ops:
        stage.fresh()
        measure("smooth", screw.smooth)
        shape = bf.result_shape(objects)
        values = bf.result_values(shape, bf.WRITE_ATTRS["smooth"])
        stage.clean()
        for name, write in (("smooth floor via ops", bf.floor_write), ("smooth floor grouped", grouped_floor_write)):
            stage.fresh()
            FLOOR[0] = lambda write=write: write(objects, shape, values)
            measure(name, bpy.ops.bench.growth_floor)
            stage.clean()
    if "insert_key" in ops:
        frame = frames // 2 + 1
        bpy.context.scene.frame_set(frame)
        stage.fresh()
        measure("insert_key", screw.insert_key)
        stage.clean()
        stage.fresh()
        values = {o.name: [fc.evaluate(frame) for fc in bf.curves_of(o.animation_data.action)] for o in objects}
        FLOOR[0] = lambda: bf.floor_insert(objects, frame, values)
        measure("insert_key floor via ops", bpy.ops.bench.growth_floor)
        stage.clean()


#: The default cases: (family, sizes, frames, keys, operators).
CASES = (
    ("objects", (20, 100, 500, 2000), 50, 2, ("revert",)),
    ("rig", (20, 100, 300), 250, 10, ("revert", "smooth", "insert_key")),
)
QUICK_CASES = (("objects", (2, 6), 20, 2, ("revert",)), ("rig", (2, 6), 30, 3, ("revert", "smooth", "insert_key")))


def run_case(family: str, sizes: list[int], frames: int, keys: int, ops: list[str], runs: int, profile: bool,
             top: int) -> None:
    medians: dict[int, dict[str, tuple[float, float]]] = {}
    profiles: dict[int, dict[str, dict[str, float]]] = {}
    for n in sizes:
        stage = bf.Stage(bf.build(family, n, frames, keys))
        times: dict[str, list[tuple[float, float]]] = {}
        one_repetition(stage, ops, frames, lambda name, fn: fn())  # warm-up
        for _ in range(runs):
            one_repetition(stage, ops, frames, lambda name, fn: times.setdefault(name, []).append(cpu_wall(fn)))
        medians[n] = {k: (statistics.median(c for c, _ in v), statistics.median(w for _, w in v)) for k, v in times.items()}
        if profile:
            profiles[n] = {}
            one_repetition(stage, ops, frames, lambda name, fn, n=n: profiles[n].__setitem__(name, own_times(fn)))
    print(f"Blender {bpy.app.version_string}, {family} x {frames} frames: CPU medians of {runs} interleaved run(s) (ms) "
          f"at {', '.join(map(str, sizes))} owners; exponent p fitted over all sizes (CPU, wall) and between "
          "neighbouring sizes (CPU); one size: CPU and wall:")
    for name in medians[sizes[0]]:
        cpu = [medians[n][name][0] for n in sizes]
        wall = [medians[n][name][1] for n in sizes]
        if len(sizes) < 2:  # one size: its times (CPU, wall), no exponent
            print(f"  {name:28s} {1e3 * cpu[0]:9.2f} CPU, {1e3 * wall[0]:9.2f} wall", flush=True)
            continue
        p_cpu = bench_report.growth_exponent(sizes, [max(t, 1e-9) for t in cpu])[0]
        p_wall = bench_report.growth_exponent(sizes, [max(t, 1e-9) for t in wall])[0]
        pairs = [math.log(max(b, 1e-9) / max(a, 1e-9)) / math.log(m / n)
                 for (n, a), (m, b) in zip(zip(sizes, cpu), zip(sizes[1:], cpu[1:]))]
        print(f"  {name:28s} {' '.join(f'{1e3 * t:9.2f}' for t in cpu)}   p {p_cpu:.2f} CPU, {p_wall:.2f} wall;"
              f" pairs {' '.join(f'{p:.2f}' for p in pairs)}", flush=True)
    if profile:
        first, last = sizes[0], sizes[-1]
        for name in profiles[first]:
            a, b = profiles[first][name], profiles[last].get(name, {})
            excess = sorted(((b.get(f, 0.0) - last / first * a.get(f, 0.0), f) for f in set(a) | set(b)), reverse=True)
            print(f"{name}: own time above linear from {first} to {last} (ms: excess, at {first}, at {last}):")
            for extra, f in excess[:top]:
                print(f"  {1e3 * extra:8.2f} {1e3 * a.get(f, 0.0):8.2f} {1e3 * b.get(f, 0.0):8.2f}  {f}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--family", choices=("objects", "rig"), help="one case (default: CASES)")
    parser.add_argument("--sizes", default="20,100,500", help="with --family: owner counts, comma-separated")
    parser.add_argument("--frames", type=int, default=50)
    parser.add_argument("--keys", type=int, default=2)
    parser.add_argument("--runs", type=int, default=3, help="interleaved repetitions per size (medians)")
    parser.add_argument("--ops", default="revert,smooth,insert_key", help="with --family")
    parser.add_argument("--profile", action="store_true", help="also one cProfile'd call of each per size")
    parser.add_argument("--top", type=int, default=8, help="with --profile: functions listed per measurement")
    parser.add_argument("--quick", action="store_true", help="QUICK_CASES, one run (seconds)")
    args = parser.parse_args()
    bpy.utils.register_class(BENCH_OT_growth_floor)
    if args.family:
        cases = [(args.family, [int(s) for s in args.sizes.split(",")], args.frames, args.keys, args.ops.split(","))]
    else:
        cases = QUICK_CASES if args.quick else CASES
    for family, sizes, frames, keys, ops in cases:
        run_case(family, list(sizes), frames, keys, list(ops), 1 if args.quick else args.runs, args.profile, args.top)

if __name__ == "__main__":
    main()
