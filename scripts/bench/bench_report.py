"""Writes BENCHMARKS.md from one run of scripts/bench.sh.

Reads criterion's JSON (target/criterion/**/new/{benchmark,estimates}.json: the median per
iteration), the callgrind outputs, the JSON of scripts/bench/bench_python.py and the text of
scripts/bench/bench_bake.py from the run directory (target/bench), and writes every median and
every ratio, each ratio taken between figures of the same run. Also importable: the growth
exponent fit (`growth_exponent`) is tested in tests/python/test_bench_tools.py.

    python scripts/bench/bench_report.py --run target/bench --criterion target/criterion --out BENCHMARKS.md
"""

from __future__ import annotations

import argparse
import json
import math
import re
from pathlib import Path

# Figures published for other implementations on other machines (never measured here).
#: Hofer, Pottmann, Ravani, Table 1 (m = 7 subdivision steps; Matlab 6.5 on a 1.8 GHz PC,
#: Windows 2000): case, N/F, scheme, T_c (curve design, s), T_r (registration, s). Our
#: counterparts are the criterion group `hofer_table1` of benches/feature.rs, whose function
#: names start with the case's name.
HOFER_TABLE1 = [
    ("bunny", "6/768", "CUI", 0.16, 0.55),
    ("teapot", "5/513", "ONI", 0.20, 0.34),
    ("gripper", "6/641", "OUA", 0.38, 0.43),
    ("window", "4/385", "OUI", 0.06, 0.29),
]
HOFER_MACHINE = "Matlab 6.5, 1.8 GHz PC, Windows 2000 (2004)"
#: Xie, Xu, Yu, Weng: about 2 s to fit 20 keyframes, 3 GHz quad core (2011).
XIE_SECONDS_PER_20_KEYS = 2.0
XIE_MACHINE = "3 GHz quad core (2011)"
#: ScrewBender paper, section 5: more than 110,000 s(a, t, b) per second.
SCREWBENDER_S_PER_SECOND = 110_000
SCREWBENDER_MACHINE = "1.5 GHz Apple PowerBook G4"

# The issue's targets.
TARGET_S_PER_SECOND = 20e6
TARGET_S_VS_NALGEBRA = 1.5
TARGET_BATCH_VS_PT3D = 100.0
TARGET_JAREK_1000x6_MS = 30.0
TARGET_BAKE_VS_NLA = 20.0
TARGET_REDUCE_RIG_MS = 100.0  # issue 26: 100 bones x 1,000 frames reduced, Rust, one thread
TARGET_EXPONENT_TOLERANCE = 0.1  # "linear": fitted exponent within 1 +- this, on large outputs
LARGE_OUTPUT = 10_000  # outputs from this size up are used for the linearity verdict


def growth_exponent(sizes, times) -> tuple[float, float]:
    """Least-squares fit of ``log t = p log n + c``: returns ``(p, c)``.

    ``p`` is the growth exponent of time against size (1 for linear). Needs at least two
    distinct positive sizes and positive times.
    """
    xs = [math.log(float(n)) for n in sizes]
    ys = [math.log(float(t)) for t in times]
    if len(xs) != len(ys) or len(set(xs)) < 2:
        raise ValueError("growth_exponent: at least two distinct sizes with a time each are needed")
    mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
    sxx = sum((x - mx) ** 2 for x in xs)
    sxy = sum((x - mx) * (y - my) for x, y in zip(xs, ys))
    p = sxy / sxx
    return p, my - p * mx


def extrapolate(sizes, times, size) -> tuple[float, float]:
    """The time at `size` predicted by the power law fitted to ``(sizes, times)``
    (:func:`growth_exponent`): returns ``(time, exponent)``. An extrapolation, never a
    measurement: whoever prints it says so (:func:`fmt_seconds` with ``extrapolated=True``)."""
    p, c = growth_exponent(sizes, times)
    return math.exp(c + p * math.log(float(size))), p


def fmt_seconds(seconds: float, extrapolated: bool = False) -> str:
    """Seconds for a table cell; an extrapolated figure is prefixed "~" and labelled."""
    text = fmt_ns(seconds * 1e9)
    return f"~{text} (extrapolated)" if extrapolated else text


def read_criterion(root: Path) -> dict[str, dict]:
    """``{full_id: {group, function, value, elements, median_ns, low_ns, high_ns}}``."""
    out = {}
    for bench in sorted(root.glob("**/new/benchmark.json")):
        meta = json.loads(bench.read_text())
        est = json.loads((bench.parent / "estimates.json").read_text())
        thr = meta.get("throughput") or {}
        elements = thr.get("Elements") if isinstance(thr, dict) else None
        median = est["median"]
        out[meta["full_id"]] = {
            "group": meta["group_id"], "function": meta.get("function_id"), "value": meta.get("value_str"),
            "elements": elements, "median_ns": median["point_estimate"],
            "low_ns": median["confidence_interval"]["lower_bound"],
            "high_ns": median["confidence_interval"]["upper_bound"],
        }
    return out


def callgrind_total(path: Path) -> int | None:
    """The instruction count (Ir) of a callgrind output file."""
    if not path.exists():
        return None
    for line in path.read_text().splitlines():
        if line.startswith(("totals:", "summary:")):
            return int(line.split()[1])
    return None


def callgrind_events(path: Path) -> dict[str, int] | None:
    """All event totals of a callgrind output file (Ir, and Bc, Bcm, ... with --branch-sim)."""
    if not path.exists():
        return None
    names, totals = None, None
    for line in path.read_text().splitlines():
        if line.startswith("events:"):
            names = line.split()[1:]
        elif line.startswith(("totals:", "summary:")):
            totals = [int(v) for v in line.split()[1:]]
    return dict(zip(names, totals)) if names and totals else None


def fmt_ns(ns: float) -> str:
    if ns < 1e3:
        return f"{ns:.1f} ns"
    if ns < 1e6:
        return f"{ns / 1e3:.2f} µs"
    if ns < 1e9:
        return f"{ns / 1e6:.2f} ms"
    return f"{ns / 1e9:.3f} s"


def fmt_rate(per_second: float) -> str:
    if per_second >= 1e6:
        return f"{per_second / 1e6:.1f} M/s"
    if per_second >= 1e3:
        return f"{per_second / 1e3:.1f} k/s"
    return f"{per_second:.0f} /s"


def fmt_ratio(r: float) -> str:
    """A ratio for a table cell: two decimals below 1 (0.07x), one above (12.4x)."""
    return f"{r:.2f}x" if r < 1 else f"{r:.1f}x"


def verdict(ok: bool | None) -> str:
    return "n/a" if ok is None else ("met" if ok else "**missed**")


class Report:
    def __init__(self, run: Path, crit: dict[str, dict], crit_reuse: dict[str, dict] | None = None) -> None:
        self.run, self.crit = run, crit
        #: The scaling rows rerun with freed memory kept for reuse (bench.sh, glibc tunables).
        self.crit_reuse = crit_reuse or {}
        self.lines: list[str] = []
        self.targets: list[tuple[str, str, str]] = []

    def w(self, *lines: str) -> None:
        self.lines.extend(lines)

    def find(self, group: str, function: str, value: str | None = None) -> dict | None:
        for rec in self.crit.values():
            if rec["group"] == group and rec["function"] == function and (value is None or rec["value"] == value):
                return rec
        return None

    def machine(self) -> None:
        env = json.loads((self.run / "machine.json").read_text()) if (self.run / "machine.json").exists() else {}
        self.w("## Machine and versions", "", "| | |", "| --- | --- |")
        for key, label in [("date", "date (UTC)"), ("cpu", "CPU model (/proc/cpuinfo)"), ("nproc", "nproc"),
                           ("load_start", "load average at start"), ("load_end", "load average at end"),
                           ("kernel", "kernel"), ("rustc", "rustc"), ("python", "python"), ("numpy", "numpy"),
                           ("bpy", "bpy (Blender)"), ("pytransform3d", "pytransform3d"), ("valgrind", "valgrind")]:
            if key in env:
                self.w(f"| {label} | {env[key]} |")
        self.w("", "The machine is shared (several builds at once on two cores): wall-clock times count the "
               "time spent waiting for a core. The Rust benches therefore measure the benchmark thread's CPU "
               "time (criterion with a `CLOCK_THREAD_CPUTIME_ID` measurement), the Python benches report both "
               "wall-clock and thread CPU time (`time.thread_time`), and callgrind instruction counts give a "
               "figure independent of the load. Ratios are always between figures of the same run.", "")

    def s_section(self) -> None:
        self.w("## s(a, t, b): one screw interpolation", "")
        ours = self.find("s", "polyscrew s(a, t, b)")
        reuse = self.find("s", "polyscrew Screw::eval (screw reused)")
        batch = self.find("s", "polyscrew s_many (batch of 1024)")
        na = self.find("s", "nalgebra UnitDualQuaternion::sclerp")
        if not (ours and na):
            self.w("not available: the criterion results of benches/core.rs are missing", "")
            return
        per = lambda r: r["median_ns"] / r["elements"]  # noqa: E731
        self.w("Criterion (`cargo bench --bench core`), 1,024 random pose pairs per iteration, median per "
               "evaluation:", "", "| | CPU time per s | rate (one core) | wall-clock per s |", "| --- | --- | --- | --- |")
        for label, rec in [("polyscrew `s(a, t, b)`", ours), ("polyscrew `s_many` (batch of 1,024)", batch),
                           ("polyscrew `Screw::eval` (screw reused)", reuse),
                           ("nalgebra `UnitDualQuaternion::try_sclerp`", na)]:
            if rec is None:
                continue
            wall = self.find("s wall-clock", rec["function"])
            wall_s = fmt_ns(wall["median_ns"] / wall["elements"]) if wall else "-"
            self.w(f"| {label} | {fmt_ns(per(rec))} | {fmt_rate(1e9 / per(rec))} | {wall_s} |")
        ratio = per(na) / per(ours)
        rate = 1e9 / per(ours)
        wall_o, wall_n = self.find("s wall-clock", ours["function"]), self.find("s wall-clock", na["function"])
        self.w("", f"Ratio nalgebra / ours (CPU time, same run): **{ratio:.2f}x**"
               + (f"; wall-clock: {wall_n['median_ns'] / wall_o['median_ns']:.2f}x." if wall_o and wall_n else "."))
        ratio_many = per(na) / per(batch) if batch else None
        if batch:
            wall_m = self.find("s wall-clock", batch["function"])
            self.w("", f"Ratio nalgebra / `s_many` (CPU time, same run): **{ratio_many:.2f}x**"
                   + (f"; wall-clock: {wall_n['median_ns'] / wall_m['median_ns']:.2f}x." if wall_m and wall_n else ".")
                   + " `s_many` computes four pairs at a time side by side (packed SSE2, baseline x86-64: two "
                   "lanes per instruction), with selects instead of branches.")
        cg = {}
        for which in ("ours", "many", "nalgebra"):
            zero, many = callgrind_total(self.run / f"callgrind-{which}-0.out"), callgrind_total(self.run / f"callgrind-{which}-N.out")
            n = int((self.run / "callgrind-n.txt").read_text()) if (self.run / "callgrind-n.txt").exists() else None
            if zero is not None and many is not None and n:
                cg[which] = (many - zero) / n
        if "ours" in cg and "nalgebra" in cg:
            self.w("", "Callgrind (`examples/count_s.rs`, instructions of N evaluations minus those of 0, over N):", "",
                   "| | instructions per s |", "| --- | --- |",
                   f"| polyscrew `s(a, t, b)` | {cg['ours']:.0f} |",
                   *([f"| polyscrew `s_many` (batches of 1,024) | {cg['many']:.0f} |"] if "many" in cg else []),
                   f"| nalgebra `try_sclerp` | {cg['nalgebra']:.0f} |", "",
                   f"Ratio nalgebra / ours in instructions: **{cg['nalgebra'] / cg['ours']:.2f}x**"
                   + (f" (`s_many`: {cg['nalgebra'] / cg['many']:.2f}x)." if "many" in cg else "."))
        else:
            self.w("", "Callgrind counts: not available (valgrind missing or the example failed).")
        self.w("")
        self.targets.append(("s >= 20 M/s on one core", fmt_rate(rate) + " (CPU time)", verdict(rate >= TARGET_S_PER_SECOND)))
        self.targets.append(("s >= 1.5x nalgebra, same run", f"{ratio:.2f}x (CPU time)"
                             + (f", {cg['nalgebra'] / cg['ours']:.2f}x (instructions)" if "ours" in cg and "nalgebra" in cg else ""),
                             verdict(ratio >= TARGET_S_VS_NALGEBRA)))
        if batch:
            rate_many = 1e9 / per(batch)
            self.targets.append(("s >= 20 M/s on one core, batch (`s_many`)", fmt_rate(rate_many) + " (CPU time)",
                                 verdict(rate_many >= TARGET_S_PER_SECOND)))
            self.targets.append(("s >= 1.5x nalgebra, same run, batch (`s_many`)", f"{ratio_many:.2f}x (CPU time)"
                                 + (f", {cg['nalgebra'] / cg['many']:.2f}x (instructions)" if "many" in cg and "nalgebra" in cg else ""),
                                 verdict(ratio_many >= TARGET_S_VS_NALGEBRA)))

    def python_section(self) -> None:
        self.w("## Through Python: batch against per-call loops", "")
        for fname, title in [("python.json", "Plain Python (project venv)"), ("blender.json", "Inside Blender (bpy module)")]:
            path = self.run / fname
            if not path.exists():
                self.w(f"{title}: not available: {fname} was not written (see the bench.sh log).", "")
                continue
            data = json.loads(path.read_text())
            env = data["env"]
            recs = {r["name"]: r for r in data["records"]}
            self.w(f"### {title}: Python {env['python']}, numpy {env['numpy']}"
                   + (f", Blender {env['bpy']}" if "bpy" in env else ""), "",
                   "| | calls per run | wall per call | CPU per call | note |", "| --- | --- | --- | --- | --- |")
            for r in data["records"]:
                note = ", ".join(f"{k} {v}" for k, v in r.items()
                                 if k not in ("name", "calls", "repeat", "wall_per_call", "cpu_per_call"))
                self.w(f"| {r['name']} | {r['calls']:,} | {fmt_ns(r['wall_per_call'] * 1e9)} | "
                       f"{fmt_ns(r['cpu_per_call'] * 1e9)} | {note} |")
            self.w("", f"Medians of {data['records'][0]['repeat']} runs." if data["records"] else "")
            batch = recs.get("polyscrew.interpolate batch")
            loop = recs.get("polyscrew.interpolate per call (Python loop)")
            ratios = []
            for other, label in [("pytransform3d transform_sclerp (Python loop)", "pytransform3d loop / our batch"),
                                 ("mathutils.Matrix.lerp (Python loop)", "Blender Matrix.lerp loop / our batch"),
                                 ("polyscrew.interpolate per call (Python loop)", "our per-call loop / our batch")]:
                if batch and other in recs:
                    r = recs[other]
                    ratios.append((label, r["cpu_per_call"] / batch["cpu_per_call"], r["wall_per_call"] / batch["wall_per_call"]))
            for other, label in [("pytransform3d transform_sclerp (Python loop)", "pytransform3d per call / ours per call"),
                                 ("mathutils.Matrix.lerp (Python loop)", "Blender Matrix.lerp per call / ours per call")]:
                if loop and other in recs:
                    r = recs[other]
                    ratios.append((label, r["cpu_per_call"] / loop["cpu_per_call"], r["wall_per_call"] / loop["wall_per_call"]))
            if ratios:
                self.w("", "| ratio (same run) | CPU time | wall-clock |", "| --- | --- | --- |")
                for label, c, w in ratios:
                    self.w(f"| {label} | {c:.1f}x | {w:.1f}x |")
            pt = recs.get("pytransform3d transform_sclerp (Python loop)")
            if batch and pt:
                ratio = pt["cpu_per_call"] / batch["cpu_per_call"]
                self.targets.append(("batch through Python >= 100x a pytransform3d loop", f"{ratio:.0f}x (CPU time)",
                                     verdict(ratio >= TARGET_BATCH_VS_PT3D)))
            for note in data.get("notes", []):
                self.w("", f"- {note}")
            self.w("")
        self.w("`Matrix.lerp` interpolates the matrix decoupled (Shoemake-Duff polar decomposition: the translation "
               "on a straight line, the rotation separately): it is what an animator gets from Blender today; "
               "`polyscrew.interpolate` is the screw, whose per-call cost in a Python loop is dominated by the "
               "call and the array conversion, hence the batch form.", "")

    def subdivision_section(self) -> None:
        self.w("## Subdivision", "")
        rows = [(f"{s} closed, 6 levels", "100") for s in ("Jarek", "FourPoint", "BSpline")] + [("Jarek closed, 6 levels", "1000")]
        found = [(f, v, self.find("subdivide", f, v)) for f, v in rows]
        if any(r for _, _, r in found):
            self.w("Criterion (`benches/core.rs`), CPU time, median:", "", "| case | output poses | time | poses per second |",
                   "| --- | --- | --- | --- |")
            for f, v, r in found:
                if r:
                    self.w(f"| {v} keys, {f} | {r['elements']:,} | {fmt_ns(r['median_ns'])} | "
                           f"{fmt_rate(r['elements'] / r['median_ns'] * 1e9)} |")
            j = found[-1][2]
            if j:
                ms = j["median_ns"] / 1e6
                self.targets.append(("1,000 keys x 6 levels Jarek < 30 ms", f"{ms:.2f} ms (CPU time)", verdict(ms < TARGET_JAREK_1000x6_MS)))
        cg_zero = callgrind_total(self.run / "callgrind-subdivide-0.out")
        cg_one = callgrind_total(self.run / "callgrind-subdivide-1.out")
        if cg_zero is not None and cg_one is not None:
            self.w("", f"Callgrind (`examples/count_subdivide.rs`, one subdivision of 1,000 keys x 6 levels Jarek "
                   f"minus the set-up): {cg_one - cg_zero:,} instructions, "
                   f"{(cg_one - cg_zero) / 64000:.0f} per output pose.")
        scaling = [r for r in self.crit.values() if r["group"] == "scaling"]
        if not scaling:
            self.w("", "Scaling: not available (benches/scaling.rs did not run).", "")
            return
        self.w("", "Scaling (`benches/scaling.rs`, closed, CPU time): poses per second by keys (rows) and levels "
               "(columns); the output has keys x 2^levels poses.", "")
        lin_ok = True
        exps = []
        for scheme in ("Jarek", "FourPoint", "BSpline"):
            recs = [r for r in scaling if r["function"] == scheme]
            if not recs:
                continue
            grid = {}
            for r in recs:
                n, lv = (int(x) for x in r["value"].split("x"))
                grid[(n, lv)] = r
            levels = sorted({lv for _, lv in grid})
            self.w(f"**{scheme}**", "", "| keys | " + " | ".join(f"{lv}" for lv in levels) + " |",
                   "| --- |" + " --- |" * len(levels))
            for n in sorted({n for n, _ in grid}):
                cells = []
                for lv in levels:
                    r = grid.get((n, lv))
                    cells.append(fmt_rate(r["elements"] / r["median_ns"] * 1e9) if r else "skipped")
                self.w(f"| {n:,} | " + " | ".join(cells) + " |")
            p_all, _ = growth_exponent([r["elements"] for r in recs], [r["median_ns"] for r in recs])
            large = [r for r in recs if r["elements"] >= LARGE_OUTPUT]
            p_large = growth_exponent([r["elements"] for r in large], [r["median_ns"] for r in large])[0] if len(large) >= 2 else float("nan")
            reuse = [r for r in self.crit_reuse.values()
                     if r["group"] == "scaling" and r["function"] == scheme and r["elements"] >= LARGE_OUTPUT]
            p_reuse = growth_exponent([r["elements"] for r in reuse], [r["median_ns"] for r in reuse])[0] \
                if len(reuse) >= 2 else None
            exps.append((scheme, p_all, p_large, len(recs), len(large), p_reuse, len(reuse)))
            lin_ok &= abs((p_reuse if p_reuse is not None else p_large) - 1) <= TARGET_EXPONENT_TOLERANCE
            self.w("")
        reused = any(pr is not None for *_, pr, _ in exps)
        self.w("Growth exponent p of time against output size (least squares on log t = p log n + c):", "",
               "| scheme | p, all sizes | p, outputs >= 10,000 poses |"
               + (" p, outputs >= 10,000, memory reused |" if reused else ""),
               "| --- | --- | --- |" + (" --- |" if reused else ""))
        for scheme, pa, pl, na, nl, pr, nr in exps:
            self.w(f"| {scheme} | {pa:.3f} ({na} points) | {pl:.3f} ({nl} points) |"
                   + ((f" {pr:.3f} ({nr} points) |" if pr is not None else " - |") if reused else ""))
        if reused:
            self.w("", "*Memory reused*: the rows of 1,000 and 10,000 keys run again with glibc told to keep freed "
                   "memory for the next call (`GLIBC_TUNABLES=glibc.malloc.mmap_max=0:glibc.malloc.trim_threshold="
                   "4294967295`). By default glibc maps every block above 32 MB afresh on each call and the kernel "
                   "faults and zeroes its pages again (see \"What limits the targets\"), while smaller outputs reuse "
                   "warm memory: that, not the subdivision, bends the default column. The linearity verdict uses the "
                   "memory-reused exponent and the default one is shown beside it.")
        self.w("", "Small outputs carry a fixed cost (allocation, validation), which pulls p below 1 over all sizes.",
               "No combination exceeded the 3,000,000-pose bound (the largest, 10,000 keys x 8 levels, is 2,560,000 "
               "poses), so none was skipped.", "")
        self.targets.append(("subdivision linear in output size",
                             ", ".join(f"{s} p = {pr:.3f}" for s, *_, pr, _ in exps if pr is not None)
                             + (" (outputs >= 10,000, memory reused); default malloc: " if reused else "")
                             + ", ".join(f"{s} p = {pl:.3f}" for s, _, pl, *_ in exps)
                             + " (outputs >= 10,000)", verdict(lin_ok)))

    def bake_section(self) -> None:
        self.w("## Bake in Blender", "")
        js = self.run / "bake.json"
        if js.exists():
            self.bake_table(json.loads(js.read_text()))
            return
        path = self.run / "bake.txt"
        if not path.exists():
            why = (self.run / "bake.missing").read_text().strip() if (self.run / "bake.missing").exists() else "not run"
            self.w(f"not available: {why}", "")
            self.targets.append(("bake >= 20x nla.bake", "not measured", "n/a"))
            return
        text = path.read_text().strip()
        self.w("`scripts/bench/bench_bake.py` (ScrewBender's bake against `bpy.ops.nla.bake`, same objects and frames):", "",
               "```", text, "```", "")
        # The "best of N" line of each case when present, else every "ratio X x".
        ratios = [float(x) for x in re.findall(r"best of \d+:.*ratio\s+([\d.]+)x", text)] or \
            [float(x) for x in re.findall(r"ratio\s+([\d.]+)x", text)]
        if ratios:
            self.targets.append(("bake >= 20x nla.bake", ", ".join(f"{r:.1f}x" for r in ratios),
                                 verdict(min(ratios) >= TARGET_BAKE_VS_NLA)))
        if "keyframe_insert" not in text:
            self.w("not available: the comparison against a `keyframe_insert` loop on the same objects and frames "
                   "is not in scripts/bench/bench_bake.py yet.", "")

    def bake_table(self, data: dict) -> None:
        """The bake comparison from scripts/bench/bench_bake.py's JSON."""
        self.w(f"`scripts/bench/bench_bake.py`, Blender {data['blender']}: every baker writes the same ten dense F-curves "
               "per object (location, XYZ Euler rotation, scale; one key per frame) for the same objects and frames. "
               "ScrewBender: the Smooth Motion operator's whole work (read keys, sample, write the action); "
               "`nla.bake`: the operator call; both best of "
               f"{data['repeat']} runs. The `keyframe_insert` loop: per frame `scene.frame_set`, set each object's "
               "location, rotation and scale from the smoothed motion (values computed before timing) and "
               "`keyframe_insert` the three; one run.", "",
               "| case | ScrewBender | nla.bake | keyframe_insert loop | nla.bake / ours | loop / ours |",
               "| --- | --- | --- | --- | --- | --- |")
        ratios = []
        for c in data["cases"]:
            ext = c.get("loop_extrapolated", False)
            loop = fmt_seconds(c["loop"], ext) if "loop" in c else "not measured"
            loop_ratio = (("~" if ext else "") + f"{c['loop'] / c['ours']:.0f}x" + (" (extrapolated)" if ext else "")) \
                if "loop" in c else "-"
            ratios.append(c["nla"] / c["ours"])
            self.w(f"| {c['objects']} object{'s' if c['objects'] > 1 else ''} x {c['frames']:,} frames | "
                   f"{fmt_seconds(c['ours'])} | {fmt_seconds(c['nla'])} | {loop} | {c['nla'] / c['ours']:.1f}x | "
                   f"{loop_ratio} |")
        series = data.get("loop_series", [])
        if series:
            self.w("", "The `keyframe_insert` loop, measured:", "", "| objects x frames | loop time | per key |",
                   "| --- | --- | --- |")
            for r in series:
                self.w(f"| {r['objects']} x {r['frames']:,} | {fmt_seconds(r['seconds'])} | "
                       f"{fmt_ns(r['seconds'] / (9 * r['objects'] * r['frames']) * 1e9)} |")
            one = [r for r in series if r["objects"] == 1]
            if len({r["frames"] for r in one}) >= 2:
                p, _ = growth_exponent([r["frames"] for r in one], [r["seconds"] for r in one])
                top = sorted(one, key=lambda r: r["frames"])[-2:]
                q, _ = growth_exponent([r["frames"] for r in top], [r["seconds"] for r in top])
                self.w("", f"Its time grows as frames^{p:.2f} on one object (least squares over the sizes above; "
                       f"frames^{q:.2f} between the two largest): each insertion keeps the F-curve sorted and "
                       "recomputes its handles. Figures marked \"extrapolated\" are the fit over all sizes carried to "
                       "the case's frame count, not measurements (a loop that long was not run); where the exponent "
                       "still rises with size they are too low.")
        self.w("")
        self.targets.append(("bake >= 20x nla.bake", ", ".join(f"{r:.1f}x" for r in ratios),
                             verdict(min(ratios) >= TARGET_BAKE_VS_NLA) if ratios else "n/a"))

    def bones_section(self) -> None:
        """The 100-bone rig against nla.bake POSE, from scripts/bench/bench_bake.py's JSON ("bones")."""
        self.w("## Bake in Blender: bones", "")
        js = self.run / "bake.json"
        data = json.loads(js.read_text()).get("bones") if js.exists() else None
        if not data:
            self.w("not available: no bone case in this run's scripts/bench/bench_bake.py results", "")
            self.targets.append(("bake of a 100-bone rig >= 20x nla.bake POSE", "not measured", "n/a"))
            return
        self.bones_table(data, json.loads(js.read_text()).get("blender", "?"))

    def bones_table(self, data: dict, blender: str) -> None:
        """The bone case: medians of wall-clock and CPU time, ours (per timing) and nla.bake,
        and their ratios."""
        runs, m = data["runs"], data["median"]
        self.w(f"`scripts/bench/bench_bake.py`, Blender {blender}: a rig of {data['bones']} bones (ten chains of ten, not "
               "connected), every bone keyed on location, XYZ Euler rotation and scale at ten uneven frames. "
               "ScrewBender: Smooth Motion of all its bones (Object Mode, the armature selected, Armatures: Bones "
               "Only: the selection, reading, sampling and the new action), Jarek 4 levels; nla.bake: "
               "`bpy.ops.nla.bake(bake_types={'POSE'})` of the same bones (Pose Mode, all selected; location, "
               f"rotation, scale) over the same {data['frames']:,} frames. Each writes "
               f"{9 * data['bones'] * data['frames']:,} keys. In each of {len(runs)} runs, on fresh rigs, ours with "
               "each timing then nla.bake, back to back in one process, after one untimed warm-up; medians of the "
               "runs. CPU time is the process's (every thread: nla.bake's depsgraph evaluation may run on "
               "several).", "",
               "| median of the runs | wall-clock | CPU time | nla.bake / ours, wall | nla.bake / ours, CPU |",
               "| --- | --- | --- | --- | --- |",
               f"| nla.bake POSE | {fmt_seconds(m['nla'])} | {fmt_seconds(m['nla_cpu'])} | | |")
        ratios = []
        for t in data["timings"]:
            wall, cpu = m["nla"] / m[t], m["nla_cpu"] / m[f"{t}_cpu"]
            ratios.append((t, wall, cpu))
            self.w(f"| ScrewBender, timing {t.title()}{' (default)' if t == 'keys' else ''} | {fmt_seconds(m[t])} | "
                   f"{fmt_seconds(m[f'{t}_cpu'])} | {wall:.1f}x | {cpu:.1f}x |")
        self.w("", "Per run (wall-clock, timing Keys): " + ", ".join(f"{r['nla'] / r['keys']:.1f}x" for r in runs)
               + (f"; load average {data['load']:.1f} at the end." if data.get("load") is not None else "."), "")
        t, wall, cpu = ratios[0]
        measured = ", ".join(f"{w:.1f}x wall / {c:.1f}x CPU (timing {name.title()})" for name, w, c in ratios)
        self.targets.append(("bake of a 100-bone rig >= 20x nla.bake POSE", measured,
                             verdict(min(wall, cpu) >= TARGET_BAKE_VS_NLA)))

    def other_criterion(self) -> None:
        known = {"s", "s wall-clock", "subdivide", "scaling"}
        rest = [(k, r) for k, r in sorted(self.crit.items()) if r["group"] not in known]
        self.w("## Other criterion benches (wall-clock, as the benches define them)", "")
        if not rest:
            self.w("none in this checkout", "")
            return
        self.w("| benchmark | median | 95% interval |", "| --- | --- | --- |")
        for k, r in rest:
            self.w(f"| {k} | {fmt_ns(r['median_ns'])} | {fmt_ns(r['low_ns'])} .. {fmt_ns(r['high_ns'])} |")
        self.w("")
        rig = self.find("reduce_rig", "100x1000_one_thread")
        if rig is not None:
            ms = rig["median_ns"] / 1e6
            self.targets.append(("key reduction, 100 bones x 1,000 frames < 100 ms (Rust, one thread)",
                                 f"{ms:.1f} ms (CPU time)", verdict(ms < TARGET_REDUCE_RIG_MS)))
        if "fit_angular_velocity/top_20_keys" in self.crit or any(r["group"] == "hofer_table1" for _, r in rest):
            self.w("The paper figures these compare with are in \"Figures from other machines\" below.", "")

    def limits_section(self) -> None:
        """Measurements that say what limits the missed targets (profile, not wall time)."""
        self.w("## What limits the targets (profiles of this run)", "")
        n = int((self.run / "callgrind-n.txt").read_text()) if (self.run / "callgrind-n.txt").exists() else None
        rows = []
        for which, label, fn in (("ours", "polyscrew s(a, t, b)", "polyscrew s(a, t, b)"),
                                 ("nalgebra", "nalgebra try_sclerp", "nalgebra UnitDualQuaternion::sclerp")):
            a, b = callgrind_events(self.run / f"branches-{which}-0.out"), callgrind_events(self.run / f"branches-{which}-N.out")
            rec = self.find("s", fn)
            if a and b and n and "Bcm" in a:
                per = {k: (b[k] - a[k]) / n for k in a}
                ipns = per["Ir"] / (rec["median_ns"] / rec["elements"]) if rec else float("nan")
                rows.append(f"| {label} | {per['Ir']:.0f} | {per['Bc']:.1f} | {per['Bcm']:.2f} | {ipns:.2f} |")
        if rows:
            self.w("Per s, from callgrind with `--branch-sim=yes` (instructions, conditional branches, simulated "
                   "mispredictions) and, last column, instructions per nanosecond of CPU time in the criterion run:", "",
                   "| | instructions | cond. branches | mispredicted | instructions per ns |", "| --- | --- | --- | --- | --- |",
                   *rows, "",
                   "Both mispredict about one branch per call or less, so branches do not explain the gap. Ours runs "
                   "at fewer instructions per nanosecond; the likely reason (hardware counters are not available in "
                   "this VM to confirm it) is that its work is one dependency chain (quaternion product, square root, "
                   "the angle (square root, division, polynomial), sin/cos polynomials, then the products), while "
                   "nalgebra's more numerous instructions overlap. Removing a fifth of our instructions without "
                   "shortening that chain left the time unchanged; the batch `s_many` overlaps four chains.", "")
            reuse = self.find("s", "polyscrew Screw::eval (screw reused)")
            if reuse:
                rate = reuse["elements"] / reuse["median_ns"] * 1e9
                self.w(f"`Screw::eval` with the screw built once (what sampling and baking do: one screw, many t) runs "
                       f"at {fmt_rate(rate)} in the same run.", "")
        per_pose = []
        for kl in ("100x6", "10000x6"):
            a = callgrind_total(self.run / f"callgrind-subdivide-{kl}-0.out")
            b = callgrind_total(self.run / f"callgrind-subdivide-{kl}-1.out")
            if a is not None and b is not None:
                keys, levels = (int(v) for v in kl.split("x"))
                per_pose.append(f"{keys:,} keys x {levels} levels: {(b - a) / (keys << levels):.0f}")
        if per_pose:
            self.w("Jarek subdivision, callgrind instructions per output pose: " + "; ".join(per_pose)
                   + ". The work per pose does not grow with the size: the subdivision is linear in instructions.", "")
        t = self.run / "time-10000x8.txt"
        if t.exists():
            user, sys_, faults, rss = t.read_text().split()[:4]
            user, sys_ = float(user), float(sys_)
            self.w(f"The largest case, 10,000 keys x 8 levels Jarek (2,560,000 poses, `/usr/bin/time`): {user:.2f} s user, "
                   f"{sys_:.2f} s system ({100 * sys_ / max(user + sys_, 1e-9):.0f} % of the CPU time), {int(faults):,} minor "
                   f"page faults, {int(rss) / 1024:.0f} MB peak memory. The system time is the kernel mapping and "
                   "zeroing freshly allocated memory (two pose buffers, of the last two levels' sizes): glibc maps "
                   "blocks above 32 MB afresh on every call, so from about 640,000 poses on every call pays these "
                   "faults, which smaller outputs, reusing warm memory, do not. That lifts the default exponent above "
                   "1 for large outputs; with memory reused it is the \"memory reused\" column of the scaling table.",
                   "")

    def reduce_section(self) -> None:
        """Reduce Keys against graph.decimate, from scripts/bench/bench_reduce.py's JSON (issue 26)."""
        self.w("## Reduce Keys against graph.decimate", "")
        js = self.run / "reduce.json"
        if not js.exists():
            path = self.run / "reduce.missing"
            self.w("not available: " + (path.read_text().strip() if path.exists() else "not run"), "")
            self.targets.append(("Reduce Keys <= 0.6x the keys of the best graph.decimate margin", "not measured", "n/a"))
            return
        d = json.loads(js.read_text())
        self.w(f"`scripts/bench/bench_reduce.py`, Blender {d['blender']}. Ours: the Reduce Keys operator (all of it: read, "
               "one `polyscrew.reduce_keys` call, write). Theirs: `graph.decimate` in ERROR mode, every other option at "
               f"its default, its margin searched (regula falsi on the logarithms, to the resolution of {d['steps']} bisection steps in log scale) for the largest value whose result "
               "meets the same world-space tolerance; its time is one decimate call at that margin. Both results "
               "checked by Blender's own playback (`frame_set` at every frame and 3 subframes between frames, every "
               "owner's world matrix) against the dense clip's playback: the largest distance of a point of the body "
               "(bounding box corners, a bone's head and tail) and the largest rotation angle. Keys: keyframe points "
               "over the transform curves; % of frames: distinct key frames per owner over the frames of its key range. "
               f"Within: the share of (owner, sample) pairs within the tolerance (+{d['slack']:g} for float32 "
               "world matrices).", "",
               "Ours twice: an owner's channels keyed on shared frames (the default) and Per Channel. Ratios: "
               "key frames, ours (shared) / decimate; keys (keyframe points), ours (per channel) / decimate.", "",
               "| clip | tolerance | ours: key frames (% of frames) | keys | per channel: keys | decimate: margin | "
               "key frames (% of frames) | keys | key frames ours / decimate | keys per channel / decimate | "
               "error ours, per channel, decimate (mm / deg) | within ours, per channel, decimate | "
               "time ours, per channel, decimate | time ours / decimate |",
               "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        key_ratios, point_ratios, time_ratios, within, captured_share, frames_note = [], [], [], [], [], []
        for clip in d["clips"]:
            for c in clip["cases"]:
                o, t, pc = c["ours"], c["decimate"], c.get("ours_per_channel", c["ours"])
                within += [o["within"], pc["within"]]
                if clip["captured"] and c["distance"] == 0.001:
                    captured_share.append((clip["name"], o["fraction"]))
                tol = f"{1000 * c['distance']:g} mm / {c['angle']:g} deg"
                err = lambda r: f"{1000 * r['distance']:.3g} / {r['angle']:.3g}"  # noqa: E731
                if t is None:
                    self.w(f"| {clip['label']} | {tol} | {o['keyframes']:,} ({100 * o['fraction']:.1f} %) | "
                           f"{o['points']:,} | {pc['points']:,} | no margin meets it | - | - | - | - | "
                           f"{err(o)}, {err(pc)}, - | {100 * o['within']:.2f} %, {100 * pc['within']:.2f} %, - | "
                           f"{fmt_seconds(o['time'])}, {fmt_seconds(pc['time'])}, - | - |")
                    continue
                kr, pr, tr = o["keyframes"] / t["keyframes"], pc["points"] / t["points"], o["time"] / t["time"]
                if "within_frames" in o and o["within"] < 1.0:
                    frames_note.append(f"{clip['label']}, {tol}: ours {100 * o['within_frames']:.2f} % within at whole "
                                       f"frames (largest {1000 * o['distance_frames']:.3g} mm / {o['angle_frames']:.3g} "
                                       "deg there)")
                key_ratios.append((clip["name"], kr))
                point_ratios.append((clip["name"], pr))
                time_ratios.append((clip["name"], max(tr, pc["time"] / t["time"])))
                self.w(f"| {clip['label']} | {tol} | {o['keyframes']:,} ({100 * o['fraction']:.1f} %) | {o['points']:,} | "
                       f"{pc['points']:,} | {t['margin']:.3g} | {t['keyframes']:,} ({100 * t['fraction']:.1f} %) | "
                       f"{t['points']:,} | {kr:.2f} | {pr:.2f} | {err(o)}, {err(pc)}, {err(t)} | "
                       f"{100 * o['within']:.2f} %, {100 * pc['within']:.2f} %, {100 * t['within']:.2f} % | "
                       f"{fmt_seconds(o['time'])}, {fmt_seconds(pc['time'])}, {fmt_seconds(t['time'])} | {tr:.2f} |")
        self.w("")
        if frames_note:
            self.w("Where ours misses the tolerance, at the whole frames alone: " + "; ".join(frames_note) + ".", "")
        windowed = [c for c in d["clips"] if c.get("searched_on", "the clip") != "the clip"]
        for c in windowed:
            self.w(f"{c['label']}: one decimate call on the whole clip takes a minute or more here, so its margin was "
                   f"searched on the clip's {c['searched_on']} (the same motion) and then run once on the whole clip "
                   "(x0.7 smaller, up to twice, where the whole clip missed the tolerance).")
        if windowed:
            self.w("")
        smooth = d.get("smooth", [])
        if smooth:
            self.w("Smooth Motion with Keys: Reduced (default tolerance, 1 mm / 0.5 deg) against Every Step, the whole "
                   "operator, median of runs:", "", "| case | Every Step | keys | Reduced | keys | Reduced / Every Step |",
                   "| --- | --- | --- | --- | --- | --- |")
            for s_ in smooth:
                self.w(f"| {s_['case']} | {fmt_seconds(s_['every_step'])} | {s_['every_keys']:,} | "
                       f"{fmt_seconds(s_['reduced'])} | {s_['reduced_keys']:,} | {s_['reduced'] / s_['every_step']:.2f} |")
            self.w("")
        self.w(f"The whole benchmark ran in {d['seconds']:.0f} s.", "")
        if key_ratios:
            worst = max(key_ratios, key=lambda r: r[1])
            self.targets.append(("Reduce Keys <= 0.6x the key frames of the best graph.decimate margin (every clip, "
                                 "every tolerance)", f"at most {worst[1]:.2f}x ({worst[0]})", verdict(worst[1] <= 0.6)))
        if point_ratios:
            worst = max(point_ratios, key=lambda r: r[1])
            self.targets.append(("Reduce Keys (Per Channel) <= 0.6x the keyframe points of the best graph.decimate "
                                 "margin", f"at most {worst[1]:.2f}x ({worst[0]})", verdict(worst[1] <= 0.6)))
        if captured_share:
            self.targets.append(("<= 10 % of frames on captured motion at 1 mm / 0.5 deg",
                                 ", ".join(f"{n} {100 * f:.1f} %" for n, f in captured_share),
                                 verdict(max(f for _, f in captured_share) <= 0.10)))
        if within:
            self.targets.append(("Reduce Keys within the tolerance at 100 % of checked samples",
                                 f"at least {100 * min(within):.2f} %", verdict(min(within) >= 1.0)))
        if time_ratios:
            worst = max(time_ratios, key=lambda r: r[1])
            self.targets.append(("Reduce Keys <= 2x graph.decimate's time", f"at most {worst[1]:.2f}x ({worst[0]})",
                                 verdict(worst[1] <= 2.0)))
        if smooth:
            worst = max(s_["reduced"] / s_["every_step"] for s_ in smooth)
            self.targets.append(("Smooth Motion with Reduced no slower than Every Step", f"at most {worst:.2f}x",
                                 verdict(worst <= 1.0)))

    def sweep_section(self) -> None:
        self.w("## Sweep against peers", "")
        js = self.run / "sweep.json"
        if not js.exists():
            path = self.run / "sweep.missing"
            self.w("not available: " + (path.read_text().strip() if path.exists() else "not run"), "")
        else:
            self.sweep_open_peers(json.loads(js.read_text()))
        self.sweep_cases()

    @staticmethod
    def body_note(c: dict) -> str:
        """What body the case's reference sweeps, when it is not simply the mesh's closed form."""
        if not c.get("body_error"):
            return ""
        within = f"{100 * c['body_error'] / c['size']:.3f} %"
        if c.get("exact_body"):
            return (f"; the reference sweeps the mesh itself (its exact distance), its surface found first on the "
                    f"smooth torus (within {within} of the mesh; what sweep3d sweeps), then taken onto the mesh's union")
        return f"; the body mesh lies within {within} of the smooth torus the reference and sweep3d sweep"

    def sweep_open_peers(self, d: dict) -> None:
        case, ref = d["case"], d["reference"]
        self.w(f"`scripts/bench/bench_sweep_peers.py`{' (quick: a smoke run)' if d.get('quick') else ''}. Case: a "
               f"{case['body']} ({case['triangles']:,} triangles) along a polyscrew of {case['poses']} poses "
               f"({case['screws']} screws; {case.get('motion', '')}).", "",
               f"Method. Reference: the union of {ref['stamps']:,} stamps, the body at poses sampled along the "
               f"screws ({ref['per_screw']} per screw). Each result and the reference are compared by what can be "
               f"seen of them from outside: orthographic depth images (software z-buffer, `tests/python/raster.py`) "
               f"from {ref['views']} directions spread over the sphere, {ref['res']} x {ref['res']} pixels "
               f"(pixel {ref['pixel']:.4f}; the body is about 1.75 across), every covered pixel taken back to its 3D "
               "point; then the directed Hausdorff distances between the two point sets (scipy `cKDTree`, both "
               "ways): *result -> ref*, how far what is seen of the result lies from the reference surface at worst "
               "(bulges, dents, a surface seen through a gap), and *ref -> result*, how far the reference surface "
               "lies from what is seen of the result (a part missed or flattened); the larger is the two-sided "
               "Hausdorff distance, the depth error compared below. Surfaces hidden inside (our sweep's excess lies inside the region) do not "
               "count, as in a render. The floor of the measure is about one pixel. Times are wall-clock, median "
               "of several runs for ours and instancing, one run for the others.", "",
               "| method | setting | time | triangles | Hausdorff result -> ref | ref -> result |",
               "| --- | --- | --- | --- | --- | --- |")
        ours = next((r for r in d["rows"] if r.get("ours")), None)
        for r in ([ours] if ours else []) + d.get("strobe", []) + [r for r in d["rows"] if not r.get("ours")]:
            self.w(f"| {r['method']} | {r['note']} | {fmt_seconds(r['seconds'])} | {r['triangles']:,} | "
                   f"{r['h_to_ref']:.4f} | {r['h_from_ref']:.4f} |")
        wx = d.get("warp_extrapolated")
        if wx:
            self.w(f"| Warp swept_volume_mesh (CPU) | voxel {wx['voxel']:g}, all {wx['poses']:,} poses | "
                   f"{fmt_seconds(wx['seconds'], True)} | - | - | - |")
        self.w("")
        if ours:
            h = max(ours["h_to_ref"], ours["h_from_ref"])
            match = next((r for r in d.get("strobe", []) if r.get("per_screw") == d.get("strobe_match")), None)
            if match:
                self.w(f"At equal depth error (two-sided Hausdorff, the larger direction, no more than ours: {h:.4f}), "
                       f"stroboscopic instancing needs {match['per_screw']} copies per screw: "
                       f"{match['triangles']:,} triangles ({match['triangles'] / ours['triangles']:.0f}x ours) and "
                       f"{fmt_seconds(match['seconds'])} to build them with numpy "
                       f"({match['seconds'] / ours['seconds']:.0f}x our sweep's time).")
            elif d.get("strobe"):
                last = d["strobe"][-1]
                self.w(f"Stroboscopic instancing did not reach our error ({h:.4f}) up to {last['per_screw']} copies "
                       f"per screw ({last['triangles']:,} triangles).")
            for name in ("gpytoolbox swept_volume", "Warp swept_volume_mesh (CPU)"):
                rows = [r for r in d["rows"] if r["method"] == name]
                if rows:
                    best = min(rows, key=lambda r: max(r["h_to_ref"], r["h_from_ref"]))
                    self.w(f"{name}, its closest here ({best['note']}): error "
                           f"{max(best['h_to_ref'], best['h_from_ref']) / h:.1f}x ours in "
                           f"{best['seconds'] / ours['seconds']:.0f}x our time.")
        self.w("", "gpytoolbox `swept_volume` (Sellán, Aigerman, Jacobson 2021: spacetime numerical continuation, grid "
               "size `eps`) is given the reference's dense poses as its transformations (it interpolates between "
               "them). Warp's `warp.geometry.swept_volume_mesh` (marching cubes of the minimum over the given poses "
               "of the body's signed distance, winding-number sign, threshold 0) runs on the CPU device; its field is "
               "a brute-force loop over poses at every grid node, so it is given every 25th and every 5th of the "
               "dense poses and its time for all of them is extrapolated from those two"
               + (f" (fitted: time ~ poses^{wx['exponent']:.2f})." if wx else "."))
        vers = ", ".join(f"{k} {v}" for k, v in d.get("versions", {}).items())
        self.w("", f"Versions: {vers}.")
        for note in d.get("notes", []):
            self.w(f"- {note}")
        self.w("")

    #: sweep3d on the issue's cases, as the issue reports them (its run, not this one).
    SWEEP3D_ISSUE = ("126 s per case, Hausdorff 0.039 (cube) and 0.027 (prism), volume within 0.3 %, 32 to 86 "
                     "self-intersecting faces and collapsed faces as returned")

    def sweep_cases(self) -> None:
        """Issue 29's three cases from scripts/bench/bench_sweep_cases.py (sweep.cases.json)."""
        self.w("### Issue 29's three cases: the closed boundary against gpytoolbox and sweep3d", "")
        js = self.run / "sweep.cases.json"
        if not js.exists():
            path = self.run / "sweep.cases.missing"
            self.w("not available: " + (path.read_text().strip() if path.exists() else "not run"), "")
            return
        d = json.loads(js.read_text())
        self.w(f"`scripts/bench/bench_sweep_cases.py`{' (quick: a smoke run)' if d.get('quick') else ''}. Every tool "
               f"gets the same {d['poses']} screws' worth of dense poses along each motion (ours screws between them, "
               "gpytoolbox interpolates them, sweep3d gets the space-time function of the body's exact signed "
               "distance along the screws between them, with its gradient in closed form). Reference: the union of "
               "the body over far denser poses (no body point moving more than half a reference cell between two), "
               f"marching cubes (scikit-image) of the minimum over them of the body's exact signed distance on a grid "
               f"of {100 * d['ref_cell']:g} % of the body's size evaluated only near the boundary, its vertices then "
               "taken onto the boundary by Newton steps: the reference points. Per result: CPU (`process_time`) and "
               "wall time of one run (ours open: median of 5), triangles, closed (every edge in two faces, once each "
               "way), self-intersecting faces (an edge of one passing strictly through another, faces sharing a "
               "vertex skipped, candidates on a uniform grid: `scripts/bench/sweep_measures.py`), degenerate faces, "
               "volume against the reference's, and the two-sided Hausdorff distance to the boundary: result -> "
               "boundary is the exact distance (the region's signed distance over the reference poses) at "
               f"20,000 of the result's surface samples (exact outside the region, a lower bound inside it), "
               f"boundary -> result the distance from every reference point to the result's samples "
               f"(spacing {100 * d['spacing']:g} % of the size, scipy `cKDTree`). Sizes and distances in % of the "
               "body's size (its bounding-box diagonal).", "")
        self.w("| case | method | setting | CPU | wall | triangles | closed | self-int. faces | degenerate | "
               "volume | Hausdorff |", "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |")
        goals = {"closed": [], "hausdorff": [], "volume": [], "speed": [], "fewer": []}
        for c in d["cases"]:
            ours = next((r for r in c["rows"] if r.get("ours")), None)
            for r in c["rows"]:
                if r.get("skipped"):
                    self.w(f"| {c['name']} | {r['method']} | {r['note']} | {r['skipped']} | | | | | | | |")
                    continue
                if "hausdorff" not in r:
                    self.w(f"| {c['name']} | {r['method']} | {r['note']} | {fmt_seconds(r['cpu'])} | "
                           f"{fmt_seconds(r['wall'])} | 0 | | | | | |")
                    continue
                self.w(f"| {c['name']} | {r['method']} | {r['note']} | {fmt_seconds(r['cpu'])} | "
                       f"{fmt_seconds(r['wall'])} | {r['triangles']:,} | {'yes' if r['closed'] else 'no'} | "
                       f"{r['self_intersecting']:,} | {r['degenerate']:,} | {100 * r['volume_error']:+.2f} % | "
                       f"{100 * r['hausdorff']:.3f} % |")
            if not ours or "hausdorff" not in ours:
                continue
            goals["closed"].append((c["name"], ours["closed"] and ours["self_intersecting"] == 0))
            goals["hausdorff"].append((c["name"], ours["hausdorff"]))
            goals["volume"].append((c["name"], abs(ours["volume_error"])))
            for r in c["rows"]:
                if r.get("ours") or "hausdorff" not in r or r["method"].startswith("ours"):
                    continue
                if r["hausdorff"] >= ours["hausdorff"]:  # at equal or better accuracy: ours no worse
                    goals["speed"].append((f"{c['name']}, {r['method']} {r['note']}", r["cpu"] / ours["cpu"]))
                if r["method"].startswith("gpytoolbox") and r["note"] == "eps 0.02":
                    goals["fewer"].append((c["name"], ours["triangles"] / r["triangles"]))
        self.w("")
        for c in d["cases"]:
            ref = c["reference"]
            self.w(f"- {c['name']} ({c['triangles']:,} triangles, size {c['size']:.3f}, {c['key_poses']} key poses, "
                   f"{c['poses']} dense poses): reference of {ref['poses']:,} poses (largest move "
                   f"{ref['largest_move']:.4f}), cell {ref['cell']:.4f}, {ref['points']:,} points, volume "
                   f"{ref['volume']:.4f}, {fmt_seconds(ref['cpu'])} CPU; its points within "
                   f"{100 * ref['max_error'] / c['size']:.4f} % of the size of the boundary (the flat marching-cubes "
                   f"faces between them: {100 * ref['mc_max_error'] / c['size']:.3f} %)"
                   + self.body_note(c) + ".")
        big = d.get("big")
        if big and big.get("unfinished"):
            self.w("- `sweep_closed` on the 100,000-triangle bumpy torus over 64 screws did not finish within the "
                   "bench's time limit (bench.sh stops the script after 60 minutes).")
            big = None
        if big:
            self.w(f"- `sweep_closed` on the bumpy torus of {big['triangles']:,} triangles over {big['screws']} screws "
                   f"(benches/sweep.rs's case), default cell {big['cell']:.4f}: {fmt_seconds(big['cpu'])} CPU, "
                   f"{fmt_seconds(big['wall'])} wall, {big['out_triangles']:,} triangles.")
        if not any(r["method"].startswith("sweep3d") and "hausdorff" in r for c in d["cases"] for r in c["rows"]):
            self.w(f"- sweep3d was not run here; the issue's figures for it (its run, not measured here): "
                   f"{self.SWEEP3D_ISSUE}.")
        vers = ", ".join(f"{k} {v}" for k, v in d.get("versions", {}).items())
        self.w("", f"Versions: {vers}. The whole script ran in {d['seconds']:.0f} s (wall).")
        for note in d.get("notes", []):
            self.w(f"- {note}")
        self.w("")
        if goals["closed"]:
            self.targets.append(("sweep_closed at its default cell: closed manifold, 0 self-intersecting faces (issue "
                                 "29's cases)", ", ".join(f"{n}: {'yes' if ok else 'no'}" for n, ok in goals["closed"]),
                                 verdict(all(ok for _, ok in goals["closed"]))))
            self.targets.append(("sweep_closed Hausdorff <= 0.5 % of the body's size",
                                 ", ".join(f"{n} {100 * x:.2f} %" for n, x in goals["hausdorff"]),
                                 verdict(max(x for _, x in goals["hausdorff"]) <= 0.005)))
            self.targets.append(("sweep_closed volume within 0.5 %",
                                 ", ".join(f"{n} {100 * x:.2f} %" for n, x in goals["volume"]),
                                 verdict(max(x for _, x in goals["volume"]) <= 0.005)))
        if goals["speed"]:
            worst = min(goals["speed"], key=lambda g: g[1])
            self.targets.append((">= 1,000x faster (CPU) than gpytoolbox and sweep3d at equal or better accuracy",
                                 f"at least {worst[1]:.1f}x ({worst[0]})", verdict(worst[1] >= 1000)))
        elif goals["closed"]:
            self.targets.append((">= 1,000x faster (CPU) than gpytoolbox and sweep3d at equal or better accuracy",
                                 "no peer result as accurate as ours to compare with", "n/a"))
        if goals["fewer"]:
            self.targets.append(("sweep_closed fewer triangles than gpytoolbox at eps 0.02",
                                 ", ".join(f"{n} {x:.2f}x" for n, x in goals["fewer"]),
                                 verdict(max(x for _, x in goals["fewer"]) < 1)))
        if big:
            self.targets.append(("sweep_closed: 100,000 triangles over 64 screws in under a second",
                                 f"{fmt_seconds(big['cpu'])} CPU", verdict(big["cpu"] < 1.0)))

    def papers_section(self) -> None:
        self.w("## Figures from other machines (papers, not measured here)", "",
               "Each paper's figure was measured by its authors on their machine, in their language, years ago; "
               "ours beside it is from this run. The speed-up (their time over ours, or our rate over theirs) is for scale "
               "only, not a like-for-like comparison.", "",
               "| paper, case | their figure | their machine | ours, this run | ours faster by |",
               "| --- | --- | --- | --- | --- |")
        s_rec = self.find("s", "polyscrew s(a, t, b)")
        if s_rec:
            rate = s_rec["elements"] / s_rec["median_ns"] * 1e9
            self.w(f"| ScrewBender (Powell, Rossignac), section 5: s(a, t, b) | more than 110,000 per second | "
                   f"{SCREWBENDER_MACHINE} | {fmt_rate(rate)} | {rate / SCREWBENDER_S_PER_SECOND:.0f}x |")
        else:
            self.w(f"| ScrewBender (Powell, Rossignac), section 5: s(a, t, b) | more than 110,000 per second | "
                   f"{SCREWBENDER_MACHINE} | not measured in this run | - |")
        for name, nf, scheme, tc, tr in HOFER_TABLE1:
            rec = next((r for r in self.crit.values()
                        if r["group"] == "hofer_table1" and (r["function"] or "").startswith(name)), None)
            ours = fmt_ns(rec["median_ns"]) if rec else "not measured in this run"
            ratio = f"{(tc + tr) * 1e9 / rec['median_ns']:.0f}x" if rec else "-"
            self.w(f"| Hofer, Pottmann, Ravani, Table 1: {name} {nf} {scheme}, m = 7 | {tc + tr:.2f} s "
                   f"(T_c {tc:.2f} + T_r {tr:.2f}) | {HOFER_MACHINE} | {ours} | {ratio} |")
        fit = self.crit.get("fit_angular_velocity/top_20_keys")
        ours = fmt_ns(fit["median_ns"]) if fit else "not measured in this run"
        ratio = f"{XIE_SECONDS_PER_20_KEYS * 1e9 / fit['median_ns']:.0f}x" if fit else "-"
        self.w(f"| Xie, Xu, Yu, Weng: angular-velocity fitting, 20 keys | about {XIE_SECONDS_PER_20_KEYS:g} s | "
               f"{XIE_MACHINE} | {ours} | {ratio} |")
        self.w("", "Ours: criterion medians (wall-clock) of `benches/feature.rs` (group `hofer_table1`: the paper's key "
               "counts, levels, open/closed, parametrisation and springs, on keys of our own since the paper's poses "
               "are not published; whole design, curves and registration, against their T_c + T_r) and "
               "`benches/angular_velocity.rs` (`top_20_keys`: the spinning top, 20 keys).", "")

    def denoise_section(self) -> None:
        """The section scripts/bench/bench_denoise.py wrote into the run folder (denoise.md)."""
        path = self.run / "denoise.md"
        text = path.read_text() if path.exists() else ""
        if begin("denoise") in text and end("denoise") in text:
            text = text[text.index(begin("denoise")) + len(begin("denoise")):text.index(end("denoise"))]
            self.w(text.strip(), "")
        else:
            self.w("## Denoise (issue 19)", "", "not available: scripts/bench/bench_denoise.py did not write its section "
                   "(see the bench.sh log)", "")

    #: The measurement scripts of the "measure" part, in the order of their sections: (script,
    #: what it measures).
    MEASUREMENTS = (
        ("measure_intent", "what Smooth Motion keeps of the animator's intent, against Blender's playback (issue 17)"),
        ("measure_schemes", "how far each subdivision scheme strays from the key poses (the Scheme tooltips)"),
        ("profile_bake", "where Smooth Motion's time goes on many objects, and Blender's own read and write calls"),
        ("profile_floor", "each writing operator against its floor, profiled (issue 27; docs/performance.md)"),
        ("growth_floor", "Revert, Smooth Motion and Insert Key against owners beside Blender-only floors (issue 27, item 4)"),
        ("bench_preview", "the live preview's recompute (issue 8: 50 keys, 5 levels, 64 instances)"),
        ("bench_sweep_blender", "Build Swept Region on a 100,000-triangle mesh against stroboscopic instancing"),
        ("bench_sweep_closed", "the closed boundary of the swept region against the open sweep on issue 29's cases"),
        ("measure_reduce", "key fractions of reduce_keys on synthetic and captured-like motion (issue 26)"),
        ("memory_footprints", "the module's memory estimates beside the peaks measured, and the CPU"),
        ("plot_smoothness", "the ScrewBender paper's smoothness figures (docs/smoothness_fig10.png, docs/circle_fig11.png)"),
    )

    def measure_section(self) -> None:
        """The printouts of the measurement scripts (target/bench/measure-<name>.txt), each as
        it printed them: the figures README.md and docs/ quote."""
        self.w("## Measurements the docs quote", "",
               "Each script in `scripts/bench/`, run by `scripts/bench.sh` (part `measure`), as it printed its figures.", "")
        if (self.run / "measure.missing").exists():
            self.w(f"not available: {(self.run / 'measure.missing').read_text().strip()}", "")
            return
        for name, what in self.MEASUREMENTS:
            self.w(f"### `scripts/bench/{name}.py`: {what}", "")
            text, missing = self.run / f"measure-{name}.txt", self.run / f"measure-{name}.missing"
            if text.exists() and not missing.exists():
                self.w("```", text.read_text().rstrip(), "```", "")
            elif missing.exists():
                self.w(f"not available: {missing.read_text().strip()}", "")
            else:
                self.w(f"not available: measure-{name}.txt was not written (see the bench.sh log).", "")

    def floor_section(self) -> None:
        """Every writing operator against its floor and Blender's counterpart, and how each grows,
        from scripts/bench/bench_floor.py's JSON (issue 27)."""
        self.w("## Operators against their floor", "")
        js = self.run / "floor.json"
        if not js.exists():
            path = self.run / "floor.missing"
            self.w("not available: " + (path.read_text().strip() if path.exists() else "not run"), "")
            self.targets.append(("every writing operator within 2x its floor", "not measured", "n/a"))
            return
        d = json.loads(js.read_text())
        end_ = d.get("date_end", "")
        when = (f"{d['date']} to {end_[11:] if end_[:10] == d['date'][:10] else end_}" if end_
                else f"ended {d['date']}")
        self.w(f"`scripts/bench/bench_floor.py`{' (quick: a smoke run)' if d.get('quick') else ''}, Blender {d['blender']}, "
               f"{when}, load average {d['load_start']} at its start, {d['seconds']:.0f} s in all. Each operator "
               "through `bpy.ops` with its defaults, against its *floor*: only the Blender calls no implementation "
               "through Blender's Python API can avoid (one `foreach_get` of `co` and of `interpolation` per source "
               "F-curve; the result action with its slot and channelbag where the version has them, its curves, one "
               "`foreach_set` per written attribute, the assignment; Insert Key: one `keyframe_points.insert` per "
               "keyed curve; Revert: assigning the previous action; Build Swept Region: the evaluated mesh read and "
               "a new mesh object of the result's size), the result's shape being the one the operator wrote in the "
               "same repetition. Blender's counterparts on the same keys and frames: `nla.bake` (OBJECT; POSE for "
               "rigs), `graph.gaussian_smooth` and `graph.decimate` at their defaults. Cells: median wall-clock of "
               f"{d['repeat']} run(s), A/B interleaved in one process; (x floor) is the operator over its floor, "
               "(x ours) the counterpart over the operator: above 1 ours is faster.", "")
        cases = d["cases"]
        med = lambda e, k="op": e.get(f"{k}_median")  # noqa: E731

        def cell(case, name, counterpart_of=None):
            e = case["ops"].get(name)
            if e is None:
                return "-"
            if med(e) is None:
                return "failed: " + e.get("error", "?").replace("|", "/")
            text = fmt_seconds(med(e)) + (", 1 run" if len(e.get("op", [])) == 1 < case.get("repeat", 1) else "")
            if counterpart_of:
                ours = case["ops"].get(counterpart_of, {})
                return text + (f" ({fmt_ratio(med(e) / med(ours))} ours)" if med(ours) else "")
            return text + (f" ({fmt_ratio(med(e) / med(e, 'floor'))} floor)" if med(e, "floor") else "")

        what = {"objects": "objects", "rig": "bones", "dense_objects": "objects", "dense_rig": "bones"}
        size = lambda c: (f"{c['owners']:,} {what[c['family']][:-1] if c['owners'] == 1 else what[c['family']]} "  # noqa: E731
                          f"x {c['frames']:,} frames" + (" (one run)" if c.get("repeat", d["repeat"]) < d["repeat"] else ""))
        sparse = [c for c in cases if not c["family"].startswith("dense")]
        dense = [c for c in cases if c["family"].startswith("dense")]
        if sparse:
            self.w("Key poses (objects: a tetrahedron each; rigs: chains of ten bones; location, XYZ Euler and a "
                   "constant scale keyed at a few uneven frames):", "",
                   "| scene | keys | Smooth Motion | Revert | Insert Key on Motion | Build Swept Region | nla.bake |",
                   "| --- | --- | --- | --- | --- | --- | --- |")
            for c in sparse:
                self.w(f"| {size(c)} | {c['source_keys']:,} | {cell(c, 'smooth')} | {cell(c, 'revert')} | "
                       f"{cell(c, 'insert_key')} | {cell(c, 'sweep')} | {cell(c, 'nla_bake', 'smooth')} |")
            self.w("")
        if dense:
            self.w("Captured motion (XYZ Euler keyed on every frame, and location on objects and a rig's root, a "
                   "slow motion with a little noise; Reduce Keys and graph.decimate only on scenes of up to "
                   f"{d.get('reduce_max_keys', 200_000):,} keys):", "",
                   "| scene | keys | Remove Noise | graph.gaussian_smooth | Reduce Keys | graph.decimate |",
                   "| --- | --- | --- | --- | --- | --- |")
            for c in dense:
                self.w(f"| {size(c)} | {c['source_keys']:,} | {cell(c, 'denoise')} | "
                       f"{cell(c, 'gaussian_smooth', 'denoise')} | {cell(c, 'reduce')} | "
                       f"{cell(c, 'decimate', 'reduce')} |")
            self.w("")
        # Growth against owners (frames fixed) and against frames (owners fixed).
        rows, steep = [], []
        ops = [n for n in ("smooth", "revert", "insert_key", "sweep", "denoise", "reduce", "nla_bake",
                           "gaussian_smooth", "decimate") if any(n in c["ops"] for c in cases)]
        for name in ops:
            cells = []
            for axis in ("owners", "frames"):
                for family in ("objects", "rig", "dense_objects", "dense_rig"):
                    fit = growth_of(cases, name, family, axis)
                    if fit is None:
                        continue
                    p, n, lo, hi = fit
                    flag = p > 1 + TARGET_EXPONENT_TOLERANCE
                    if flag and name in FLOOR_OPERATORS:
                        steep.append(f"{FLOOR_LABELS[name]} {p:.2f} ({what[family]}, {axis})")
                    cells.append(f"{what[family]}{' (dense)' if family.startswith('dense') else ''} "
                                 f"{axis} {lo:,}..{hi:,}: {'**' if flag else ''}{p:.2f}{'**' if flag else ''}")
            if cells:
                rows.append(f"| {FLOOR_LABELS[name]} | " + "; ".join(cells) + " |")
        if rows:
            self.w("Growth exponent p of the median time (least squares on log t = p log n + c; owners from 20 up, "
                   "frames fixed; frames at fixed owners and keys); **bold** above linear (p > "
                   f"{1 + TARGET_EXPONENT_TOLERANCE:g}):", "", "| | p |", "| --- | --- |", *rows, "")
        # The goals of issue 27.
        for name in FLOOR_OPERATORS:
            ratios = [(med(c["ops"][name]) / med(c["ops"][name], "floor"), size(c)) for c in cases
                      if name in c["ops"] and med(c["ops"][name]) and med(c["ops"][name], "floor")]
            failed = [size(c) for c in cases if name in c["ops"] and med(c["ops"][name]) is None]
            if ratios or failed:
                worst = max(ratios) if ratios else None
                self.targets.append((f"{FLOOR_LABELS[name]} within 2x its floor at every scale",
                                     (f"at most {worst[0]:.1f}x ({worst[1]})" if worst else "")
                                     + (f"; failed on {', '.join(failed)}" if failed else ""),
                                     verdict(bool(worst) and worst[0] <= 2.0 and not failed)))
        for family, owners, frames, goal, label in FLOOR_GOALS:
            c = next((c for c in cases if (c["family"], c["owners"], c["frames"]) == (family, owners, frames)), None)
            e = c and c["ops"]
            if family.startswith("dense"):
                ratio = med(e["denoise"]) / med(e["gaussian_smooth"]) if e and med(e.get("denoise", {})) \
                    and med(e.get("gaussian_smooth", {})) else None
                self.targets.append((label, f"{ratio:.2f}x" if ratio else "not measured", verdict(ratio <= goal)
                                     if ratio else "n/a"))
            else:
                ratio = med(e["nla_bake"]) / med(e["smooth"]) if e and med(e.get("smooth", {})) \
                    and med(e.get("nla_bake", {})) else None
                self.targets.append((label, f"{ratio:.1f}x" if ratio else "not measured", verdict(ratio >= goal)
                                     if ratio else "n/a"))
        c = next((c for c in cases if (c["family"], c["owners"], c["frames"]) == ("objects", 500, 50)), None)
        revert = med(c["ops"].get("revert", {})) if c else None
        self.targets.append(("Revert of 500 objects < 100 ms", fmt_seconds(revert) if revert else "not measured",
                             verdict(revert < TARGET_REVERT_500_S) if revert else "n/a"))
        self.targets.append(("no operator grows faster than linearly", "; ".join(steep) if steep else
                             ("all p <= " + f"{1 + TARGET_EXPONENT_TOLERANCE:g}" if rows else "not measured"),
                             verdict(not steep) if rows else "n/a"))


#: The writing operators measured against their floor (scripts/bench/bench_floor.py), and labels.
FLOOR_OPERATORS = ("smooth", "revert", "denoise", "reduce", "insert_key", "sweep")
FLOOR_LABELS = {
    "smooth": "Smooth Motion", "revert": "Revert", "denoise": "Remove Noise", "reduce": "Reduce Keys",
    "insert_key": "Insert Key on Motion", "sweep": "Build Swept Region", "nla_bake": "nla.bake",
    "gaussian_smooth": "graph.gaussian_smooth", "decimate": "graph.decimate",
}
#: Issue 27's goals against Blender: (family, owners, frames, ratio, label).
FLOOR_GOALS = (
    ("objects", 500, 50, 10.0, "Smooth Motion >= 10x nla.bake, 500 objects x 50 frames"),
    ("objects", 300, 250, 10.0, "Smooth Motion >= 10x nla.bake, 300 objects x 250 frames"),
    ("rig", 100, 1000, 20.0, "Smooth Motion >= 20x nla.bake POSE, 100-bone rig x 1,000 frames"),
    ("dense_rig", 30, 1000, 2.0, "Remove Noise <= 2x graph.gaussian_smooth, 30 bones x 1,000 frames"),
    ("dense_rig", 100, 1000, 2.0, "Remove Noise <= 2x graph.gaussian_smooth, 100 bones x 1,000 frames"),
)
TARGET_REVERT_500_S = 0.1
#: Growth against owners is fitted from this many owners up (a single owner is mostly fixed cost).
GROWTH_MIN_OWNERS = 20


def growth_of(cases: list[dict], name: str, family: str, axis: str):
    """The growth exponent of operator `name`'s median time in `family` against `axis`
    ("owners" at the frame count with the most owner counts, or "frames" at the owner count
    with the most frame counts; same keys per owner): ``(p, points, smallest, largest)``,
    None when fewer than two sizes were measured."""
    fixed = "frames" if axis == "owners" else "owners"
    groups: dict[tuple, list[tuple[int, float]]] = {}
    for c in cases:
        e = c["ops"].get(name)
        if c["family"] != family or not e or e.get("op_median") is None:
            continue
        if axis == "owners" and c["owners"] < GROWTH_MIN_OWNERS:
            continue
        groups.setdefault((c[fixed], c["keys"]), []).append((c[axis], e["op_median"]))
    best = max(groups.values(), key=lambda g: len({n for n, _ in g}), default=[])
    if len({n for n, _ in best}) < 2:
        return None
    p, _ = growth_exponent([n for n, _ in best], [t for _, t in best])
    return p, len(best), min(n for n, _ in best), max(n for n, _ in best)


#: The parts of scripts/bench.sh (BENCH_ONLY=<part>[,<part>]).
PARTS = ("criterion", "callgrind", "python", "bake", "reduce", "floor", "denoise", "sweep", "measure")
#: The blocks of BENCHMARKS.md in order: (name, the parts whose results it shows, its methods).
#: Each is written between ``<!-- name:begin -->`` and ``<!-- name:end -->``; a refresh of some
#: parts rewrites the blocks that show them and keeps the others as they are.
BLOCKS = (
    ("machine", (), ("machine",)),
    ("s", ("criterion", "callgrind"), ("s_section",)),
    ("python", ("python",), ("python_section",)),
    ("subdivision", ("criterion", "callgrind"), ("subdivision_section",)),
    ("bake", ("bake",), ("bake_section", "bones_section")),
    ("floor", ("floor",), ("floor_section",)),
    ("criterion", ("criterion",), ("other_criterion",)),
    ("limits", ("criterion", "callgrind"), ("limits_section",)),
    ("sweep", ("sweep",), ("sweep_section",)),
    ("reduce", ("reduce",), ("reduce_section",)),
    ("papers", ("criterion",), ("papers_section",)),
    ("denoise", ("denoise",), ("denoise_section",)),
    ("measure", ("measure",), ("measure_section",)),
)
#: A file written before the blocks had markers: the block of each "## " heading (prefix).
LEGACY_HEADINGS = (
    ("## Machine and versions", "machine"), ("## s(a, t, b)", "s"), ("## Through Python", "python"),
    ("## Subdivision", "subdivision"), ("## Bake in Blender", "bake"), ("## Operators against their floor", "floor"),
    ("## Other criterion benches", "criterion"), ("## What limits the targets", "limits"),
    ("## Sweep against peers", "sweep"), ("## Reduce Keys against", "reduce"),
    ("## Figures from other machines", "papers"), ("## Denoise", "denoise"),
)
#: ... and the block of each row of its targets table (label prefix).
LEGACY_TARGETS = (
    ("s >=", "s"), ("batch through Python", "python"), ("1,000 keys x 6 levels", "subdivision"),
    ("subdivision linear", "subdivision"), ("bake", "bake"), ("key reduction", "criterion"),
    ("Reduce Keys", "reduce"), ("<= 10 % of frames", "reduce"), ("Smooth Motion with Reduced", "reduce"),
)
TARGETS_NOTE = "<!-- targets: "


def begin(name: str) -> str:
    return f"<!-- {name}:begin -->"


def end(name: str) -> str:
    return f"<!-- {name}:end -->"


def split_blocks(text: str) -> tuple[dict[str, str], dict[str, list[tuple[str, str, str]]]]:
    """The blocks of an existing BENCHMARKS.md: ``{name: text between its markers (markers
    included)}`` and ``{name: its target rows}``. A file without markers (written before
    them) is split at its "## " headings and its targets table by label."""
    blocks: dict[str, str] = {}
    targets: dict[str, list[tuple[str, str, str]]] = {}
    names = [name for name, _, _ in BLOCKS]
    if any(begin(n) in text for n in names if n != "denoise"):
        for name in names:
            if begin(name) in text and end(name) in text:
                i, j = text.index(begin(name)), text.index(end(name)) + len(end(name))
                blocks[name] = text[i:j]
                for line in blocks[name].splitlines():
                    if line.startswith(TARGETS_NOTE):
                        targets[name] = [tuple(r) for r in json.loads(line[len(TARGETS_NOTE):-len(" -->")])]
        return blocks, targets
    # Legacy: the denoise block has markers of its own; the rest goes by headings.
    if begin("denoise") in text and end("denoise") in text:
        i, j = text.index(begin("denoise")), text.index(end("denoise")) + len(end("denoise"))
        blocks["denoise"] = text[i:j]
        text = text[:i] + text[j:]
    current, chunk = None, []
    pieces: dict[str, list[str]] = {}
    in_targets = False
    for line in text.splitlines():
        if line.startswith("## "):
            in_targets = line.startswith("## Targets")
            current = next((b for h, b in LEGACY_HEADINGS if line.startswith(h)), None)
            chunk = pieces.setdefault(current, []) if current else []
        if in_targets:
            cells = [c.strip() for c in line.strip().strip("|").split("|")]
            if line.startswith("| ") and len(cells) == 3 and cells[0] not in ("target", "---"):
                block = next((b for prefix, b in LEGACY_TARGETS if cells[0].startswith(prefix)), "unknown")
                targets.setdefault(block, []).append(tuple(cells))
            continue
        if current:
            chunk.append(line)
    for name, lines in pieces.items():
        blocks[name] = "\n".join([begin(name)] + lines).rstrip() + "\n" + end(name)
    return blocks, targets


def parts_at_hand(run: Path, crit: dict) -> set[str]:
    """The parts whose results are in the run folder (this run's or an earlier one's)."""
    have = set()
    if crit:
        have.add("criterion")
    if (run / "callgrind-n.txt").exists():
        have.add("callgrind")
    files = {"python": ("python.json", "blender.json"), "bake": ("bake.json", "bake.txt", "bake.missing"),
             "sweep": ("sweep.json", "sweep.missing"), "reduce": ("reduce.json", "reduce.missing"),
             "floor": ("floor.json", "floor.missing"), "denoise": ("denoise.md",)}
    for part, names in files.items():
        if any((run / n).exists() for n in names):
            have.add(part)
    if (run / "measure.missing").exists() or any(run.glob("measure-*.txt")) or any(run.glob("measure-*.missing")):
        have.add("measure")
    return have


def compose(rep: Report, only: set[str] | None, old_text: str | None, stamp: str | None = None) -> str:
    """BENCHMARKS.md from the run in `rep`: every block (`only` None), or only the blocks that
    show a part of `only`, the others kept from `old_text` as they are. A block that shows a
    refreshed part and another part whose results are not at hand is kept too (and said)."""
    old_blocks, old_targets = split_blocks(old_text) if old_text else ({}, {})
    at_hand = parts_at_hand(rep.run, rep.crit)
    texts: list[str] = []
    targets: list[tuple[str, str, str]] = []
    for name, parts, methods in BLOCKS:
        fresh = only is None or bool(set(parts) & only)
        if fresh and only is not None and not set(parts) - only <= at_hand:
            missing = ", ".join(sorted(set(parts) - only - at_hand))
            print(f"bench_report: kept the {name} block as it was: it also shows {missing}, whose results are not "
                  f"in {rep.run} (refresh {missing} with it)")
            fresh = False
        if not fresh and name in old_blocks:
            kept = old_targets.get(name, []) + (old_targets.get("unknown", []) if name == "machine" else [])
            text = old_blocks[name]
            if kept and TARGETS_NOTE not in text:  # a block from a file without markers: its rows go with it
                text = text[:-len(end(name))] + TARGETS_NOTE + json.dumps([list(t) for t in kept]) + " -->\n" + end(name)
            texts.append(text)
            targets += kept
            continue
        if not fresh:
            continue
        rep.lines, rep.targets = [], []
        for method in methods:
            getattr(rep, method)()
        body = "\n".join(rep.lines).rstrip()
        if not body:
            continue
        lines = [begin(name), body]
        if stamp and only is not None:
            lines += ["", stamp]
        if rep.targets:
            lines.append(TARGETS_NOTE + json.dumps([list(t) for t in rep.targets]) + " -->")
        texts.append("\n".join(lines + [end(name)]))
        targets += rep.targets
    head = ["# Benchmarks", "", "Written by `scripts/bench.sh` (rerun it to reproduce; about 18 minutes on 2 cores for "
            "everything; `BENCH_ONLY=<part>[,<part>] scripts/bench.sh` refreshes only those parts' sections and "
            "keeps the others). Every figure below was measured in one run unless marked as a figure from another "
            "machine or as refreshed alone.", ""]
    summary = ["## Targets", "", "| target | measured | |", "| --- | --- | --- |"]
    summary += [f"| {a} | {b} | {c} |" for a, b, c in targets] + [""]
    return "\n".join(head + summary + ["\n\n".join(texts)]).rstrip() + "\n"


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--run", type=Path, required=True)
    parser.add_argument("--criterion", type=Path, required=True)
    parser.add_argument("--criterion-reuse", type=Path, help="criterion results of the scaling rerun with memory reused")
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--only", help="comma-separated parts (" + ", ".join(PARTS) + "): rewrite only the "
                        "sections that show them, keep the rest of --out as it is")
    args = parser.parse_args()
    only = None
    if args.only:
        only = {p.strip() for p in args.only.split(",") if p.strip()}
        unknown = only - set(PARTS)
        if unknown:
            parser.error(f"unknown part(s) {', '.join(sorted(unknown))}; the parts: {', '.join(PARTS)}")
    reuse = read_criterion(args.criterion_reuse) if args.criterion_reuse and args.criterion_reuse.exists() else {}
    crit = read_criterion(args.criterion) if args.criterion.exists() else {}
    rep = Report(args.run, crit, reuse)
    old = args.out.read_text() if only is not None and args.out.exists() else None
    stamp = None
    if only is not None:
        env = json.loads((args.run / "machine.json").read_text()) if (args.run / "machine.json").exists() else {}
        date, _, quick = env.get("date", "an unknown date").partition(" (")
        stamp = (f"_Refreshed alone (BENCH_ONLY={','.join(sorted(only))}): measured from "
                 f"{date} UTC{' (' + quick if quick else ''}, load average {env.get('load_start', '?')} at its start; "
                 "the other sections and the machine table are the last full run's._")
    args.out.write_text(compose(rep, only, old, stamp))
    print(f"bench_report: wrote {args.out}" + (f" (refreshed: {', '.join(sorted(only))})" if only else ""))


if __name__ == "__main__":
    main()
