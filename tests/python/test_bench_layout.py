"""scripts/ split by role (issue 25): every script in scripts/bench/ is run by scripts/bench.sh
(or is a helper of one it runs), the measurement scripts' printouts reach BENCHMARKS.md through
the "measure" part of bench_report.py, and bench_report.py is BENCHMARKS.md's one writer."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from test_bench_tools import load, report

ROOT = Path(__file__).resolve().parents[2]
BENCH = ROOT / "scripts" / "bench"


def test_every_bench_script_is_run_by_bench_sh_or_a_helper_of_one():
    bench_sh = (ROOT / "scripts" / "bench.sh").read_text()
    scripts = sorted(p.stem for p in BENCH.glob("*.py"))
    run = {name for name in scripts if f"scripts/bench/{name}.py" in bench_sh or f"measure {name} " in bench_sh}
    assert "bench_report" in run and "measure_intent" in run and "plot_smoothness" in run, run
    helpers = set()
    for name in run:
        text = (BENCH / f"{name}.py").read_text()
        helpers |= {m for m in scripts if re.search(rf"^\s*(import|from) {m}\b", text, re.M)}
    assert set(scripts) == run | helpers, sorted(set(scripts) - run - helpers)
    # ... and the measurement scripts are all in the report's section, in bench.sh's order.
    measured = re.findall(r"^  measure (\w+) ", bench_sh, re.M)
    assert measured == [name for name, _ in report.Report.MEASUREMENTS]


def test_the_measure_section_shows_each_printout_or_why_it_is_missing(tmp_path):
    (tmp_path / "measure-measure_intent.txt").write_text("spin 0, 360, 720: total turn 720\n")
    (tmp_path / "measure-profile_bake.missing").write_text("scripts/bench/profile_bake.py failed: boom\n")
    rep = report.Report(tmp_path, {}, {})
    rep.lines = []
    rep.measure_section()
    text = "\n".join(rep.lines)
    assert "### `scripts/bench/measure_intent.py`" in text
    assert "```\nspin 0, 360, 720: total turn 720\n```" in text
    assert "not available: scripts/bench/profile_bake.py failed: boom" in text
    assert "not available: measure-memory_footprints.txt was not written" in text
    assert text.count("### ") == len(report.Report.MEASUREMENTS)
    assert "measure" in report.parts_at_hand(tmp_path, {})


def test_a_measure_refresh_keeps_the_other_blocks(tmp_path):
    (tmp_path / "measure-measure_reduce.txt").write_text("walk root: 4.1 % of frames\n")
    old = "\n".join([
        "# Benchmarks", "", "## Targets", "", "| target | measured | |", "| --- | --- | --- |", "",
        report.begin("machine"), "## Machine and versions", "", "old machine table", report.end("machine"), "",
        report.begin("measure"), "## Measurements the docs quote", "", "old printouts", report.end("measure"), "",
    ])
    rep = report.Report(tmp_path, {}, {})
    new = report.compose(rep, {"measure"}, old, stamp="_Refreshed alone (BENCH_ONLY=measure)._")
    blocks, _ = report.split_blocks(new)
    assert blocks["machine"] == report.begin("machine") + "\n## Machine and versions\n\nold machine table\n" + report.end("machine")
    assert "walk root: 4.1 % of frames" in blocks["measure"] and "old printouts" not in blocks["measure"]
    assert "_Refreshed alone (BENCH_ONLY=measure)._" in blocks["measure"]


def test_bench_denoise_writes_its_section_apart_never_benchmarks_md(tmp_path):
    denoise = load("bench_denoise")
    section = tmp_path / "run" / "denoise.md"
    denoise.write_section(f"{denoise.BEGIN}\n## Denoise\n{denoise.END}", section)
    assert section.read_text() == f"{denoise.BEGIN}\n## Denoise\n{denoise.END}\n"
    with pytest.raises(SystemExit, match="BENCHMARKS.md is written by scripts/bench/bench_report.py"):
        denoise.write_section("x", ROOT / "BENCHMARKS.md")
    # bench.sh gives it the run folder; bench_report.py puts the section into BENCHMARKS.md.
    assert '--section "$run/denoise.md"' in (ROOT / "scripts" / "bench.sh").read_text()
