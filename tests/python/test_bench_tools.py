"""Keeps the benchmark and plotting tools honest, without timing anything: the growth
exponent fit of scripts/bench_report.py, its readers of criterion and callgrind output,
and the derivative and Euler helpers of scripts/plot_smoothness.py, against independent
references (analytic curves, scipy)."""

from __future__ import annotations

import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts"


def load(name: str):
    spec = importlib.util.spec_from_file_location(name, SCRIPTS / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


report = load("bench_report")
plot = load("plot_smoothness")


@pytest.mark.parametrize("p", [1.0, 1.5, 0.5])
def test_growth_exponent_recovers_power_law(p):
    sizes = [10 * 2**k for k in range(12)]
    times = [3e-8 * n**p for n in sizes]
    fitted, c = report.growth_exponent(sizes, times)
    assert fitted == pytest.approx(p, abs=1e-12)
    assert math.exp(c) == pytest.approx(3e-8, rel=1e-9)


def test_growth_exponent_with_noise_and_fixed_cost():
    rng = np.random.default_rng(3)
    sizes = np.array([10 * 2**k for k in range(16)])
    noisy = 5e-8 * sizes * np.exp(rng.normal(0, 0.05, len(sizes)))
    assert report.growth_exponent(sizes, noisy)[0] == pytest.approx(1.0, abs=0.02)
    # A fixed cost per call makes small sizes look cheap per element: p < 1 over all sizes,
    # back to 1 when only the large sizes are fitted (what BENCHMARKS.md reports).
    with_overhead = 5e-8 * sizes + 2e-5
    assert report.growth_exponent(sizes, with_overhead)[0] < 0.9
    large = sizes >= 10_000
    assert report.growth_exponent(sizes[large], with_overhead[large])[0] == pytest.approx(1.0, abs=0.05)


def test_growth_exponent_rejects_a_single_size():
    with pytest.raises(ValueError):
        report.growth_exponent([100, 100], [1.0, 2.0])


def test_read_criterion_and_callgrind(tmp_path):
    bench = tmp_path / "scaling" / "Jarek" / "10x3" / "new"
    bench.mkdir(parents=True)
    (bench / "benchmark.json").write_text(json.dumps({
        "group_id": "scaling", "function_id": "Jarek", "value_str": "10x3", "full_id": "scaling/Jarek/10x3",
        "throughput": {"Elements": 80}}))
    ci = {"confidence_level": 0.95, "lower_bound": 900.0, "upper_bound": 1100.0}
    (bench / "estimates.json").write_text(json.dumps({"median": {"point_estimate": 1000.0, "confidence_interval": ci}}))
    got = report.read_criterion(tmp_path)["scaling/Jarek/10x3"]
    assert (got["elements"], got["median_ns"], got["low_ns"]) == (80, 1000.0, 900.0)
    out = tmp_path / "callgrind.out"
    out.write_text("version: 1\ncmd: x\nevents: Ir\nfl=a\n0 5\nsummary: 123456\ntotals: 123456\n")
    assert report.callgrind_total(out) == 123456
    assert report.callgrind_total(tmp_path / "missing.out") is None


def test_derivatives_match_an_analytic_curve():
    dt = 1e-3
    t = np.arange(0, 3, dt)
    x = np.sin(2 * t) + t**3
    v, a = plot.derivatives(x, dt)
    ti = t[1:-1]
    # Central differences: errors dt^2/6 x''' and dt^2/12 x'''' (bounded by 8+6 and 16).
    assert np.abs(v - (2 * np.cos(2 * ti) + 3 * ti**2)).max() < 14 * dt**2 / 6 * 1.01
    assert np.abs(a - (-4 * np.sin(2 * ti) + 6 * ti)).max() < 16 * dt**2 / 12 * 1.01 + 1e-6
    # Exact on a quadratic (up to rounding).
    v, a = plot.derivatives(1 + 2 * t + 3 * t**2, dt)
    assert np.allclose(a, 6.0, atol=1e-5) and np.allclose(v, 2 + 6 * t[1:-1], atol=1e-9)


def test_derivatives_reject_too_few_samples():
    with pytest.raises(ValueError):
        plot.derivatives(np.array([1.0, 2.0]), 0.1)


@pytest.mark.parametrize("euler", [(0, 0, 0), (40, 10, 60), (90, -20, 150), (200, 10, 260), (-30, 80, 5)])
def test_euler_xyz_matrix_is_blenders_xyz_order(euler):
    # Blender's XYZ Euler applies X, then Y, then Z about the world axes: scipy's extrinsic "xyz".
    m = plot.euler_xyz_matrix((1.0, -2.0, 0.5), euler)
    assert np.allclose(m[:3, :3], Rotation.from_euler("xyz", euler, degrees=True).as_matrix(), atol=1e-14)
    assert np.allclose(m[:3, 3], (1.0, -2.0, 0.5)) and np.allclose(m[3], (0, 0, 0, 1))


def test_points_x_is_the_world_x_of_a_body_point():
    poses = np.array([plot.euler_xyz_matrix((k, 0.0, 1.0), (0, 0, 90 * k)) for k in range(4)])
    # Body point (2, 0, 0) turned by 90 degrees per pose about z: x = k + 2 cos(90 k).
    assert np.allclose(plot.points_x(poses, (2.0, 0.0, 0.0)), [2.0, 1.0, 0.0, 3.0], atol=1e-12)


def test_bake_ratios_are_read_from_the_best_of_lines(tmp_path):
    (tmp_path / "bake.txt").write_text(
        "Blender 5.0.1, bake over every frame, jarek 4 levels\n"
        "   1 object(s) x 100000 frames: ScrewBender   0.100 s, nla.bake  30.000 s, ratio  300.0x  (keys)\n"
        "  best of 3: ScrewBender 0.090 s, nla.bake 29.000 s, ratio 322.2x\n"
        " 100 object(s) x   1000 frames: ScrewBender   0.500 s, nla.bake   8.000 s, ratio   16.0x  (keys)\n"
        "  best of 3: ScrewBender 0.450 s, nla.bake 8.100 s, ratio 18.0x\n")
    rep = report.Report(tmp_path, {})
    rep.bake_section()
    name, measured, verdict = rep.targets[-1]
    assert name.startswith("bake") and measured == "322.2x, 18.0x" and verdict == "**missed**"
    assert any("keyframe_insert" in line for line in rep.lines)
