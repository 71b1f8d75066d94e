"""Where each writing operator's time goes against its floor (issue 27: the misses explained
with profiles; the figures of docs/performance.md).

For one scene of bench_floor.py (its scenes, floors and staging: every call starts from fresh
copies of the source actions, what it made is removed untimed), per operator:
  1. CPU time (`time.process_time`) of the operator through `bpy.ops` and of its floor,
     `--runs` interleaved repetitions, medians; on `--empty`, also two operators registered here
     that do nothing, with `bl_options` {REGISTER, UNDO} (the writing operators' and so the
     floor's) and {REGISTER}: what `bpy.ops` itself costs any operator;
  2. one more call of each under cProfile: the top entries by cumulative time (own and total
     time), and the own time grouped into `bpy.ops` (its C call: operator lookup, the undo push,
     the reports; its Python wrapper's view-layer updates before and after), `foreach_get` /
     `foreach_set`, other Blender methods cProfile sees, `polyscrew`, numpy, and the add-on's
     Python (which holds the RNA calls cProfile does not see: property reads, `fcurves.new`,
     `keyframe_points.add`, assignments); the floor's `foreach_*` calls are counted alike.
Without --case it runs the document's scenes (CASES: 1 owner x 50 frames, 500 objects x 50,
100 bones x 1,000, 20 objects for Build Swept Region; --quick the first two, seconds). Run after
scripts/build_extension.sh (scripts/bench.sh, part `measure`, runs it so):
    PYTHONPATH=.venv/bpy/5.0 .venv/bin/python scripts/bench/profile_floor.py [--quick] [--case objects:1:50:2 --empty]
"""

from __future__ import annotations

import argparse
import cProfile
import io
import os
import pstats
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_floor as bf  # noqa: E402  (installs the built extension into a temporary Blender)

# isort: split
import bpy  # noqa: E402

TOP = 14


class BENCH_OT_empty_undo(bpy.types.Operator):
    bl_idname, bl_label, bl_options = "bench.empty_undo", "Empty (undo)", {"REGISTER", "UNDO"}

    def execute(self, context):
        return {"FINISHED"}


#: What bench.floor runs (set before each call).
FLOOR = [lambda: None]


class BENCH_OT_floor(bpy.types.Operator):
    """The floor inside an operator with the writing operators' bl_options, called through
    bpy.ops: the floor with everything `bpy.ops` imposes."""

    bl_idname, bl_label, bl_options = "bench.floor", "Floor", {"REGISTER", "UNDO"}

    def execute(self, context):
        FLOOR[0]()
        return {"FINISHED"}


class BENCH_OT_empty(bpy.types.Operator):
    bl_idname, bl_label, bl_options = "bench.empty", "Empty", {"REGISTER"}

    def execute(self, context):
        return {"FINISHED"}


def group_of(key: tuple[str, int, str]) -> str:
    filename, _line, name = key
    if "_bpy.ops.call" in name or name == "<built-in method _bpy.ops.call>":
        return "bpy.ops C call (lookup, undo push, reports)"
    if filename.endswith(os.path.join("bpy", "ops.py")):
        return "bpy.ops wrapper (view-layer update x2)"
    if "polyscrew" in name:
        return "polyscrew"
    if "foreach_get" in name or "foreach_set" in name:
        return "Blender foreach_get/set"
    if "bpy_prop_collection" in name or "bpy_struct" in name or "bpy_func" in name:
        return "Blender, other methods cProfile sees"
    if "numpy" in filename or "numpy" in name:
        return "numpy"
    if "screwbender" in filename:
        return "add-on Python (+ RNA calls unseen)"
    if "bench_floor" in filename or "profile_floor" in filename:
        return "floor's Python (+ RNA calls unseen)"
    return "other Python (stdlib, builtins)"


def profiled(fn) -> pstats.Stats:
    profiler = cProfile.Profile(time.process_time)  # CPU time: under load, wall time charges preemption to whatever runs
    profiler.enable()
    fn()
    profiler.disable()
    return pstats.Stats(profiler)


def groups_of(stats: pstats.Stats) -> tuple[dict, dict]:
    """Own time per group, and the calls counted (foreach_get, foreach_set, polyscrew)."""
    groups: dict[str, float] = {}
    calls = {"foreach_get": 0, "foreach_set": 0, "polyscrew": 0}
    for key, (_cc, nc, tottime, _ct, _callers) in stats.stats.items():
        groups[group_of(key)] = groups.get(group_of(key), 0.0) + tottime
        for word in calls:
            if word in key[2]:
                calls[word] += nc
    return groups, calls


def addon_files(stats: pstats.Stats) -> dict[str, float]:
    """The add-on's own time per file (`blender/keys.py`, ...)."""
    out: dict[str, float] = {}
    for (filename, _line, _name), (_cc, _nc, tottime, _ct, _callers) in stats.stats.items():
        if "screwbender" in filename:
            name = "/".join(Path(filename).parts[-2:])
            out[name] = out.get(name, 0.0) + tottime
    return out


def report(title: str, profiles: list[pstats.Stats], top: bool) -> None:
    """Each group's median own time over the profiled calls; the top entries summed over them."""
    per_call = [groups_of(stats) for stats in profiles]
    names = {name for groups, _ in per_call for name in groups}
    median = {name: statistics.median(groups.get(name, 0.0) for groups, _ in per_call) for name in names}
    total = statistics.median(sum(groups.values()) for groups, _ in per_call)
    print(f"  {title}: {total * 1e3:.2f} ms own time under cProfile (median of {len(profiles)} calls); "
          f"calls per call {per_call[0][1]}")
    for group, seconds in sorted(median.items(), key=lambda item: -item[1]):
        print(f"    {group:42s} {seconds * 1e3:9.3f} ms {seconds / total:6.1%}")
    if top:
        by_file = [addon_files(stats) for stats in profiles]
        files = {name for one in by_file for name in one}
        print("    the add-on's own time by file (median):  " + ", ".join(
            f"{name} {statistics.median(one.get(name, 0.0) for one in by_file) * 1e3:.3f} ms"
            for name in sorted(files, key=lambda n: -statistics.median(one.get(n, 0.0) for one in by_file))[:9]))
        reports = [sum(v[3] for k, v in stats.stats.items() if "/ops/" in k[0] and k[2].startswith("report"))
                   for stats in profiles]
        print(f"    the operator's report (ops/*_ops.py report*, cumulative, median): {statistics.median(reports) * 1e3:.3f} ms")
        stats = profiles[0]
        for other in profiles[1:]:
            stats.add(other)
        for order, count in (("cumulative", TOP), ("tottime", TOP // 2)):
            text = io.StringIO()
            stats.stream = text
            stats.sort_stats(order).print_stats(count)
            lines = text.getvalue().splitlines()
            start = next(i for i, line in enumerate(lines) if line.strip().startswith("ncalls"))
            print(f"    by {order}, summed over {len(profiles)} calls:")
            for line in lines[start:start + count + 1]:
                print("    | " + line.replace(str(Path.home()), "~"))


def cpu(fn) -> float:
    start = time.process_time()
    fn()
    return time.process_time() - start


class Runner:
    """One operator and its floor, staged as bench_floor.one_repetition stages them; a call is
    timed (CPU) or profiled."""

    def __init__(self, stage: bf.Stage, frames: int, measure) -> None:
        self.stage, self.frames, self.measure = stage, frames, measure
        self.ops = bpy.ops.screwbender

    def floor(self, fn, through_ops: bool = True):
        """The floor, the view-layer update it leaves pending (timed apart), and the floor
        again on fresh copies inside bench.floor through `bpy.ops`."""
        alone, update = self.measure(fn), self.measure(bpy.context.view_layer.update)
        if not through_ops:
            return alone, update, None
        self.stage.clean()
        self.stage.fresh()
        FLOOR[0] = fn
        return alone, update, self.measure(bpy.ops.bench.floor)

    def smooth_and_revert(self):
        stage, objects = self.stage, self.stage.objects
        copies = stage.fresh()
        smooth = self.measure(self.ops.smooth)
        shape = bf.result_shape(objects)
        results = {o.name: o.animation_data.action for o in objects}
        revert_floor = self.floor(lambda: [bf.assign(o, copies[o.name]) for o in objects], through_ops=False)
        for o in objects:
            bf.assign(o, results[o.name])
        revert = self.measure(self.ops.revert)
        stage.clean()
        values = bf.result_values(shape, bf.WRITE_ATTRS["smooth"])
        stage.fresh()
        smooth_floor = self.floor(lambda: bf.floor_write(objects, shape, values))
        stage.clean()
        return {"smooth": (smooth, smooth_floor), "revert": (revert, revert_floor)}

    def insert_key(self):
        stage, objects = self.stage, self.stage.objects
        frame = self.frames // 2 + 1
        bpy.context.scene.frame_set(frame)
        stage.fresh()
        op = self.measure(self.ops.insert_key)
        stage.clean()
        stage.fresh()
        values = {o.name: [fc.evaluate(frame) for fc in bf.curves_of(o.animation_data.action)] for o in objects}
        floor = self.floor(lambda: bf.floor_insert(objects, frame, values))
        stage.clean()
        return {"insert_key": (op, floor)}

    def sweep(self):
        stage, objects = self.stage, self.stage.objects
        stage.fresh()
        op = self.measure(self.ops.sweep)
        made = bf.made_meshes(stage)
        stage.clean()
        stage.fresh()
        floor = self.floor(lambda: bf.floor_sweep(objects, made))
        stage.clean()
        return {"sweep": (op, floor)}

    def dense(self, name: str):
        stage, objects = self.stage, self.stage.objects
        stage.fresh()
        op = self.measure(getattr(self.ops, bf.IDNAMES[name]))
        shape = bf.result_shape(objects)
        values = bf.result_values(shape, bf.WRITE_ATTRS[name])
        stage.clean()
        stage.fresh()
        floor = self.floor(lambda: bf.floor_write(objects, shape, values))
        stage.clean()
        return {name: (op, floor)}


#: The doc's cases: (case, operators, CPU runs, profiled calls, the empty operators timed).
CASES = (
    ("objects:1:50:2", "smooth,insert_key,sweep", 9, 9, True),
    ("dense_objects:1:50", "denoise,reduce", 9, 9, True),
    ("objects:500:50:2", "smooth,insert_key", 3, 1, False),
    ("rig:100:1000:10", "smooth,insert_key", 3, 1, False),
    ("objects:20:50:2", "sweep", 3, 1, False),
    ("dense_objects:500:50", "denoise,reduce", 3, 1, False),
    ("dense_rig:100:1000", "denoise", 3, 1, False),
)
QUICK_CASES = (("objects:1:50:2", "smooth,insert_key,sweep", 2, 1, True), ("dense_objects:1:50", "denoise,reduce", 2, 1, True))


def run_case(case: str, only: set[str], runs: int, profile_calls: int, empty: bool) -> None:
    family, owners, frames, *rest = case.split(":")
    owners, frames, keys = int(owners), int(frames), int(rest[0]) if rest else 0
    objects = bf.build(family, owners, frames, keys)
    stage = bf.Stage(objects)
    print(f"Blender {bpy.app.version_string}, {owners} {family} x {frames} frames (keys {keys}); "
          f"load {os.getloadavg()[0]:.1f} {os.getloadavg()[1]:.1f} {os.getloadavg()[2]:.1f}", flush=True)

    def parts(runner: Runner) -> dict:
        out = {}
        for name, part in (("smooth", runner.smooth_and_revert), ("insert_key", runner.insert_key),
                           ("sweep", runner.sweep), ("denoise", lambda: runner.dense("denoise")),
                           ("reduce", lambda: runner.dense("reduce"))):
            if name in only:
                out.update(part())
        return out

    parts(Runner(stage, frames, lambda fn: fn()))  # warm-up: the first call of a session is slower
    times: dict[str, list] = {}
    empties: dict[str, list] = {"empty_undo": [], "empty": []}
    for _ in range(runs):
        for name, pair in parts(Runner(stage, frames, cpu)).items():
            times.setdefault(name, []).append(pair)
        if empty:
            empties["empty_undo"].append(cpu(bpy.ops.bench.empty_undo))
            empties["empty"].append(cpu(bpy.ops.bench.empty))
    print(f"CPU medians of {runs} interleaved runs (load now {os.getloadavg()[0]:.1f}):")
    for name, pairs in times.items():
        op, floor = statistics.median(p[0] for p in pairs), statistics.median(p[1][0] for p in pairs)
        update = statistics.median(p[1][1] for p in pairs)
        line = (f"  {name:12s} op {op * 1e3:10.2f} ms   floor {floor * 1e3:9.2f} ms   x{op / max(floor, 1e-9):.1f}"
                f"   view-layer update after the floor {update * 1e3:.3f} ms")
        if pairs[0][1][2] is not None:
            via = statistics.median(p[1][2] for p in pairs)
            line += f"   floor through bpy.ops {via * 1e3:.2f} ms (op x{op / max(via, 1e-9):.1f})"
        print(line)
    if empty:
        for name, values in empties.items():
            print(f"  bpy.ops.bench.{name:12s} {statistics.median(values) * 1e3:8.3f} ms")
    print(f"cProfile, {profile_calls} more call(s) of each:")
    profiles: dict[str, list] = {}
    for _ in range(profile_calls):
        for name, pair in parts(Runner(stage, frames, profiled)).items():
            profiles.setdefault(name, []).append(pair)
    for name, pairs in profiles.items():
        print(f"{name}:")
        report("operator", [p[0] for p in pairs], top=True)
        report("floor", [p[1][0] for p in pairs], top=False)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", metavar="FAMILY:OWNERS:FRAMES[:KEYS]", help="one scene (default: the doc's, CASES)")
    parser.add_argument("--only", help="with --case, comma-separated: smooth (with revert), insert_key, sweep, denoise, reduce")
    parser.add_argument("--runs", type=int, default=5, help="with --case: CPU runs")
    parser.add_argument("--profiles", type=int, default=1, help="with --case: calls of each under cProfile")
    parser.add_argument("--empty", action="store_true", help="with --case: also time the empty operators")
    parser.add_argument("--quick", action="store_true", help="the 1-owner cases, 2 runs (seconds)")
    args = parser.parse_args()
    for cls in (BENCH_OT_empty_undo, BENCH_OT_empty, BENCH_OT_floor):
        bpy.utils.register_class(cls)
    if args.case:
        only = args.only or ("denoise,reduce" if args.case.startswith("dense") else "smooth,insert_key,sweep")
        cases = [(args.case, only, args.runs, args.profiles, args.empty)]
    else:
        cases = QUICK_CASES if args.quick else CASES
    for case, only, runs, profile_calls, empty in cases:
        run_case(case, set(only.split(",")), runs, profile_calls, empty)


if __name__ == "__main__":
    main()
