"""scripts/bench/bench_report.py's refresh of some parts (BENCH_ONLY) and its floor section (issue
27), without timing anything: a refresh rewrites only the sections of the named parts and
keeps every other byte of BENCHMARKS.md and its target rows; the floor table's ratios, the
growth exponents and the goals' verdicts follow from the medians given."""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def load(name: str):
    spec = importlib.util.spec_from_file_location(name, ROOT / "scripts" / "bench" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


report = load("bench_report")


def op(median: float, floor: float | None = None, runs: int = 3) -> dict:
    out = {"op": [median] * runs, "op_median": median}
    if floor is not None:
        out |= {"floor": [floor] * runs, "floor_median": floor}
    return out


def floor_json(cases: list[dict], **kw) -> dict:
    return {"blender": "5.0.1", "quick": False, "repeat": 3, "date": "2026-12-02 05:00 UTC", "load_start": "1.00",
            "load_end": "1.00", "seconds": 600.0, "cases": cases} | kw


def case(family: str, owners: int, frames: int, ops: dict, keys: int = 2) -> dict:
    return {"family": family, "owners": owners, "frames": frames, "keys": keys, "curves": 9 * owners,
            "source_keys": 9 * owners * keys, "repeat": 3, "seconds": 1.0, "ops": ops}


def render_floor(tmp_path: Path, data: dict) -> report.Report:
    (tmp_path / "floor.json").write_text(json.dumps(data))
    rep = report.Report(tmp_path, {})
    rep.floor_section()
    return rep


def test_floor_cells_are_medians_over_the_floor_and_the_counterpart_over_ours(tmp_path):
    data = floor_json([case("objects", 500, 50, {"smooth": op(0.3, 0.1), "revert": op(0.05, 0.001),
                                                  "nla_bake": op(3.3)}),
                       case("dense_rig", 30, 1000, {"denoise": op(0.4, 0.25), "gaussian_smooth": op(0.1)}, 0)])
    rep = render_floor(tmp_path, data)
    text = "\n".join(rep.lines)
    assert "| 500 objects x 50 frames | 9,000 | 300.00 ms (3.0x floor) | 50.00 ms (50.0x floor) |" in text
    assert "3.300 s (11.0x ours) |" in text  # nla.bake / Smooth Motion
    assert "100.00 ms (0.25x ours)" in text  # gaussian / Remove Noise: ours 4x slower
    targets = {name: (measured, v) for name, measured, v in rep.targets}
    assert targets["Smooth Motion within 2x its floor at every scale"] == ("at most 3.0x (500 objects x 50 frames)",
                                                                           "**missed**")
    assert targets["Remove Noise within 2x its floor at every scale"][1] == "met"  # 1.6x
    assert targets["Smooth Motion >= 10x nla.bake, 500 objects x 50 frames"] == ("11.0x", "met")
    assert targets["Remove Noise <= 2x graph.gaussian_smooth, 30 bones x 1,000 frames"] == ("4.00x", "**missed**")
    assert targets["Remove Noise <= 2x graph.gaussian_smooth, 100 bones x 1,000 frames"] == ("not measured", "n/a")
    assert targets["Revert of 500 objects < 100 ms"] == ("50.00 ms", "met")


def test_a_failed_operator_is_shown_and_misses_its_goal(tmp_path):
    failed = {"op": [], "error": "RuntimeError: poll() failed | twice"}
    rep = render_floor(tmp_path, floor_json([case("objects", 20, 50, {"smooth": op(0.1, 0.08),
                                                                        "insert_key": failed})]))
    text = "\n".join(rep.lines)
    assert "failed: RuntimeError: poll() failed / twice" in text  # no "|" breaking the table
    targets = {name: (measured, v) for name, measured, v in rep.targets}
    assert targets["Insert Key on Motion within 2x its floor at every scale"] == (
        "; failed on 20 objects x 50 frames", "**missed**")
    assert targets["Smooth Motion within 2x its floor at every scale"][1] == "met"


@pytest.mark.parametrize("p, steep", [(1.0, False), (1.5, True)])
def test_growth_above_linear_is_flagged(tmp_path, p, steep):
    owners = (1, 20, 100, 500, 2000)
    # The single owner carries a large fixed cost: it is left out of the fit (owners from 20 up).
    cases = [case("objects", n, 50, {"smooth": op(1e-3 * n**p + (0.5 if n == 1 else 0.0), 1e-4 * n)}) for n in owners]
    cases += [case("objects", 100, f, {"smooth": op(1e-4 * f)}, keys=10) for f in (250, 1000)]
    assert report.growth_of(cases, "smooth", "objects", "owners")[:2] == (pytest.approx(p, abs=1e-9), 4)
    assert report.growth_of(cases, "smooth", "objects", "frames")[0] == pytest.approx(1.0, abs=1e-9)
    assert report.growth_of(cases, "revert", "objects", "owners") is None
    rep = render_floor(tmp_path, floor_json(cases))
    measured, v = next((m, v) for name, m, v in rep.targets if name == "no operator grows faster than linearly")
    assert (v == "**missed**") == steep
    assert ("Smooth Motion 1.50 (objects, owners)" in measured) == steep


def block(text: str, name: str) -> str:
    return text[text.index(report.begin(name)):text.index(report.end(name)) + len(report.end(name))]


def test_refresh_rewrites_only_the_named_parts(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    (run / "floor.json").write_text(json.dumps(floor_json([case("objects", 500, 50, {
        "smooth": op(0.3, 0.1), "nla_bake": op(3.3)})])))
    (run / "sweep.missing").write_text("gpytoolbox did not install")
    full = report.compose(report.Report(run, {}), None, None)
    assert full.count("<!-- floor:begin -->") == 1 and "11.0x ours" in full
    # An older full run's figures in the other sections (their text and their target rows).
    sweep_old = block(full, "sweep")
    sweep_new = sweep_old.replace("not available: gpytoolbox did not install", "| our sweep | 12 ms |")
    sweep_new = sweep_new.replace(report.end("sweep"), report.TARGETS_NOTE + json.dumps(
        [["sweep <= 10 ms", "12 ms", "**missed**"]]) + " -->\n" + report.end("sweep"))
    old = full.replace(sweep_old, sweep_new)
    (run / "floor.json").write_text(json.dumps(floor_json([case("objects", 500, 50, {
        "smooth": op(0.1, 0.1), "nla_bake": op(3.3)})])))
    (run / "sweep.missing").unlink()  # gone from the run folder: the section must come from the old file
    new = report.compose(report.Report(run, {}), {"floor"}, old, "_Refreshed alone._")
    assert block(new, "sweep") == sweep_new
    for name in ("machine", "s", "python", "subdivision", "bake", "criterion", "limits", "reduce", "papers"):
        assert block(new, name) == block(old, name), name
    assert "33.0x ours" in block(new, "floor") and "11.0x ours" not in new
    assert "_Refreshed alone._" in block(new, "floor")
    assert "| sweep <= 10 ms | 12 ms | **missed** |" in new  # a kept section's target row
    assert "| Smooth Motion >= 10x nla.bake, 500 objects x 50 frames | 33.0x | met |" in new
    assert "| Smooth Motion >= 10x nla.bake, 500 objects x 50 frames | 11.0x |" not in new


def test_a_section_of_two_parts_is_kept_when_the_other_part_is_missing(tmp_path, capsys):
    run = tmp_path / "run"
    run.mkdir()
    old = report.compose(report.Report(run, {}), None, None).replace(
        "not available: the criterion results of benches/core.rs are missing", "s: 68 ns")
    (run / "callgrind-n.txt").write_text("100000")
    new = report.compose(report.Report(run, {}), {"callgrind"}, old, "_Refreshed alone._")
    assert block(new, "s") == block(old, "s") and "s: 68 ns" in new
    assert "kept the s block" in capsys.readouterr().out


def test_a_file_without_markers_is_split_by_its_headings():
    legacy = "\n".join([
        "# Benchmarks", "", "Written by `scripts/bench.sh`.", "", "## Targets (issue 7)", "",
        "| target | measured | |", "| --- | --- | --- |", "| s >= 20 M/s on one core | 14.6 M/s | **missed** |",
        "| bake >= 20x nla.bake | 20.6x | met |", "| Reduce Keys within the tolerance | 100 % | met |", "",
        "## Machine and versions", "", "| date | x |", "", "## s(a, t, b): one screw interpolation", "", "68 ns", "",
        "## Bake in Blender", "", "bake table", "", "## Bake in Blender: bones", "", "bones table", "",
        "<!-- denoise:begin -->", "## Denoise (issue 19)", "", "denoise table", "<!-- denoise:end -->", ""])
    blocks, targets = report.split_blocks(legacy)
    assert set(blocks) == {"machine", "s", "bake", "denoise"}
    assert "bake table" in blocks["bake"] and "bones table" in blocks["bake"] and "68 ns" in blocks["s"]
    assert blocks["denoise"].startswith("<!-- denoise:begin -->") and "denoise table" in blocks["denoise"]
    assert targets == {"s": [("s >= 20 M/s on one core", "14.6 M/s", "**missed**")],
                       "bake": [("bake >= 20x nla.bake", "20.6x", "met")],
                       "reduce": [("Reduce Keys within the tolerance", "100 %", "met")]}


def test_bench_sh_refuses_an_unknown_part(tmp_path):
    env = dict(os.environ, BENCH_ONLY="floor,nope", CARGO_TARGET_DIR=str(tmp_path))
    done = subprocess.run(["bash", str(ROOT / "scripts" / "bench.sh")], env=env, capture_output=True, text=True,
                          timeout=60)
    assert done.returncode == 2 and "unknown part 'nope'" in done.stdout
    assert not (tmp_path / "bench").exists()  # refused before touching anything


def test_a_second_refresh_keeps_the_target_rows_of_a_file_without_markers(tmp_path):
    legacy = "\n".join([
        "# Benchmarks", "", "## Targets (issue 7)", "", "| target | measured | |", "| --- | --- | --- |",
        "| s >= 20 M/s on one core | 14.6 M/s | **missed** |", "| an old goal | 3 | met |", "",
        "## Machine and versions", "", "| date | x |", "", "## s(a, t, b): one screw interpolation", "", "68 ns", ""])
    run = tmp_path / "run"
    run.mkdir()
    (run / "floor.json").write_text(json.dumps(floor_json([case("objects", 500, 50, {"revert": op(0.05, 0.001)})])))
    once = report.compose(report.Report(run, {}), {"floor"}, legacy, "_Refreshed alone._")
    twice = report.compose(report.Report(run, {}), {"floor"}, once, "_Refreshed alone._")
    for text in (once, twice):
        rows = [line for line in text.splitlines() if line.startswith("| ") and line.endswith(" |")]
        assert "| s >= 20 M/s on one core | 14.6 M/s | **missed** |" in rows
        assert "| an old goal | 3 | met |" in rows
        assert "| Revert of 500 objects < 100 ms | 50.00 ms | met |" in rows
        assert "68 ns" in block(text, "s")
    assert twice == once
