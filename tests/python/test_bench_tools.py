"""Keeps the benchmark and plotting tools honest, without timing anything: the growth
exponent fit of scripts/bench/bench_report.py, its readers of criterion and callgrind output,
and the derivative and Euler helpers of scripts/bench/plot_smoothness.py, against independent
references (analytic curves, scipy)."""

from __future__ import annotations

import importlib.util
import json
import math
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

SCRIPTS = Path(__file__).resolve().parents[2] / "scripts" / "bench"


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


# --- scripts/bench/bench_sweep_peers.py and the report's new sections (no gpytoolbox, no warp) -----

sweep = load("bench_sweep_peers")


def test_loading_the_sweep_bench_imports_neither_peer():
    import sys

    # CI does not install scripts/bench/requirements.txt: the helpers must not need it.
    assert "gpytoolbox" not in sys.modules and "warp" not in sys.modules


def test_hausdorff_against_brute_force():
    rng = np.random.default_rng(7)
    a, b = rng.normal(size=(300, 3)), rng.normal(size=(200, 3)) + 0.3
    d = np.linalg.norm(a[:, None] - b[None], axis=2)
    ab, ba = sweep.hausdorff(a, b)
    assert ab == pytest.approx(d.min(axis=1).max(), abs=1e-12)
    assert ba == pytest.approx(d.min(axis=0).max(), abs=1e-12)
    # A prebuilt tree on b gives the same, and a subset is 0 away one way only.
    from scipy.spatial import cKDTree

    assert sweep.hausdorff(a, b, cKDTree(b)) == (ab, ba)
    sub_ab, sub_ba = sweep.hausdorff(a[:10], a)
    assert sub_ab == 0.0 and sub_ba > 0.0


def test_hausdorff_of_a_translated_set_is_the_shift():
    a = np.random.default_rng(1).uniform(size=(50, 3))
    shift = np.array([0.0, 0.0, 1e-3])
    ab, ba = sweep.hausdorff(a, a + shift)
    assert ab <= 1e-3 + 1e-15 and ba <= 1e-3 + 1e-15 and max(ab, ba) > 0.0


def test_hausdorff_rejects_an_empty_set():
    with pytest.raises(ValueError):
        sweep.hausdorff(np.zeros((0, 3)), np.zeros((1, 3)))


@pytest.mark.parametrize("forward", [(0, 0, -1), (0.3, -0.2, -1.0), (1, 1, 1)])
def test_visible_points_lie_on_the_rendered_plane(forward):
    import sys

    sys.path.insert(0, str(SCRIPTS.parent / "tests" / "python"))
    import raster

    # A large tilted square: n . p = 0.2; every visible point must be on it.
    n = np.array([0.1, 0.2, 1.0])
    n /= np.linalg.norm(n)
    u = np.cross(n, [1.0, 0.0, 0.0])
    u /= np.linalg.norm(u)
    w = np.cross(n, u)
    corners = np.array([0.2 * n + 5 * (sx * u + sy * w) for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))])
    tris = np.array([[0, 1, 2], [0, 2, 3]])
    view = raster.View(forward, (0.1, -0.2, 0.3), 2.0, 64)
    depth = raster.depth_image(view, corners, tris, cull=False)
    pts = sweep.visible_points(view, depth)
    assert len(pts) == np.isfinite(depth).sum() > 1000
    assert np.abs(pts @ n - 0.2).max() < 1e-12
    # Back on screen, each point lands on a pixel centre.
    screen = pts @ view.matrix[:, :3].T + view.matrix[:, 3]
    assert np.allclose(screen[:, :2] % 1.0, 0.5, atol=1e-9)


def test_instance_arrays_place_the_body_at_every_pose():
    v, t = sweep.bumpy_torus(6, 4)
    assert len(t) == 48 and len(v) == 24
    poses = sweep.key_poses(3)
    iv, it = sweep.instance_arrays(v, t, poses)
    assert iv.shape == (4 * 24, 3) and it.shape == (4 * 48, 3)
    k = 2
    assert np.allclose(iv[k * 24:(k + 1) * 24], v @ poses[k, :3, :3].T + poses[k, :3, 3])
    assert np.array_equal(it[k * 48:(k + 1) * 48], t + k * 24)
    # The poses are rigid, and the torus is outward (positive signed volume).
    r = poses[:, :3, :3]
    assert np.allclose(np.einsum("kji,kjl->kil", r, r), np.eye(3), atol=1e-12)
    p = v[t]
    assert np.einsum("ij,ij->i", p[:, 0], np.cross(p[:, 1], p[:, 2])).sum() > 0


def test_first_match_is_at_equal_two_sided_error():
    rows = [{"per_screw": k, "h_to_ref": a, "h_from_ref": b}
            for k, a, b in ((8, 0.05, 0.02), (16, 0.011, 0.02), (32, 0.012, 0.009), (64, 0.005, 0.004))]
    assert sweep.first_match(rows, 0.012)["per_screw"] == 32
    assert sweep.first_match(rows, 0.05)["per_screw"] == 8
    assert sweep.first_match(rows, 0.001) is None


def test_extrapolation_follows_the_fitted_power_law_and_is_labelled():
    frames = [1000, 2000, 4000]
    seconds = [0.5 * (f / 1000) ** 2 for f in frames]
    value, p = report.extrapolate(frames, seconds, 100_000)
    assert p == pytest.approx(2.0, abs=1e-12) and value == pytest.approx(5000.0, rel=1e-9)
    assert report.fmt_seconds(value, extrapolated=True) == "~5000.000 s (extrapolated)"
    assert report.fmt_seconds(0.0125) == "12.50 ms"
    with pytest.raises(ValueError):
        report.extrapolate([1000], [0.5], 4000)


BAKE_JSON = {
    "blender": "5.0.1", "quick": False, "repeat": 3,
    "cases": [
        {"objects": 1, "frames": 100000, "ours": 0.2, "nla": 5.0, "loop": 6000.0, "loop_extrapolated": True},
        {"objects": 100, "frames": 1000, "ours": 0.3, "nla": 3.6, "loop": 60.0, "loop_extrapolated": False},
    ],
    "loop_series": [{"objects": 1, "frames": f, "seconds": 0.5 * (f / 1000) ** 2} for f in (1000, 2000, 4000)]
    + [{"objects": 100, "frames": 1000, "seconds": 60.0}],
}


def test_bake_section_from_json_marks_extrapolations(tmp_path):
    (tmp_path / "bake.json").write_text(json.dumps(BAKE_JSON))
    rep = report.Report(tmp_path, {})
    rep.bake_section()
    text = "\n".join(rep.lines)
    row_1 = next(line for line in rep.lines if line.startswith("| 1 object x 100,000 frames"))
    assert "~6000.000 s (extrapolated)" in row_1 and "~30000x (extrapolated)" in row_1 and "| 25.0x |" in row_1
    row_100 = next(line for line in rep.lines if line.startswith("| 100 objects x 1,000 frames"))
    assert "extrapolated" not in row_100 and "| 60.000 s |" in row_100 and "| 200x |" in row_100
    assert "frames^2.00" in text and "not measurements" in text and "between the two largest" in text
    assert "not available" not in text
    assert rep.targets[-1] == ("bake >= 20x nla.bake", "25.0x, 12.0x", "**missed**")


def test_bone_section_reports_medians_and_both_ratios(tmp_path):
    run = {"keys": 0.25, "keys_cpu": 0.11, "smooth": 0.2, "smooth_cpu": 0.1, "nla": 5.0, "nla_cpu": 2.4}
    bones = {"bones": 100, "frames": 1000, "timings": ["keys", "smooth"], "load": 6.5,
             "runs": [run, dict(run, keys=0.5), dict(run, keys=0.2)], "median": run}
    (tmp_path / "bake.json").write_text(json.dumps(dict(BAKE_JSON, bones=bones)))
    rep = report.Report(tmp_path, {})
    rep.bones_section()
    assert "| nla.bake POSE | 5.000 s | 2.400 s | | |" in rep.lines
    assert "| ScrewBender, timing Keys (default) | 250.00 ms | 110.00 ms | 20.0x | 21.8x |" in rep.lines
    assert "| ScrewBender, timing Smooth | 200.00 ms | 100.00 ms | 25.0x | 24.0x |" in rep.lines
    assert any(line.startswith("Per run (wall-clock, timing Keys): 20.0x, 10.0x, 25.0x; load average 6.5")
               for line in rep.lines)
    assert rep.targets[-1] == (
        "bake of a 100-bone rig >= 20x nla.bake POSE",
        "20.0x wall / 21.8x CPU (timing Keys), 25.0x wall / 24.0x CPU (timing Smooth)", "met")
    (tmp_path / "bake.json").write_text(json.dumps(BAKE_JSON))  # an older run without the bone case
    rep = report.Report(tmp_path, {})
    rep.bones_section()
    assert rep.targets[-1][1:] == ("not measured", "n/a") and "not available" in rep.lines[-2]


SWEEP_JSON = {
    "quick": False,
    "case": {"body": "bumpy torus, 48 x 24 quads", "triangles": 2304, "poses": 25, "screws": 24, "motion": "a helix"},
    "reference": {"stamps": 3001, "per_screw": 125, "views": 12, "res": 1024, "pixel": 0.006, "points": 10, "seconds": 1.0},
    "versions": {"gpytoolbox": "0.3.8", "warp-lang": "1.19.0"},
    "rows": [
        {"method": "ours (polyscrew.sweep)", "note": "8 steps per screw", "seconds": 0.01, "triangles": 94430,
         "h_to_ref": 0.008, "h_from_ref": 0.014, "ours": True},
        {"method": "gpytoolbox swept_volume", "note": "eps 0.05", "seconds": 20.0, "triangles": 54048,
         "h_to_ref": 0.07, "h_from_ref": 0.1, "grid": 0.05},
        {"method": "Warp swept_volume_mesh (CPU)", "note": "voxel 0.1, 601 poses", "seconds": 64.0, "triangles": 13000,
         "h_to_ref": 0.12, "h_from_ref": 0.11, "grid": 0.1, "poses": 601},
    ],
    "strobe": [
        {"method": "stroboscopic instancing", "note": "32 per screw", "seconds": 0.2, "triangles": 1771776,
         "h_to_ref": 0.026, "h_from_ref": 0.013, "per_screw": 32},
        {"method": "stroboscopic instancing", "note": "64 per screw", "seconds": 0.5, "triangles": 3541248,
         "h_to_ref": 0.0087, "h_from_ref": 0.009, "per_screw": 64},
    ],
    "strobe_match": 64,
    "warp_extrapolated": {"poses": 3001, "voxel": 0.1, "seconds": 320.0, "exponent": 1.0, "from": []},
    "notes": ["Warp: kernel compilation took 3 s, not counted"],
}


def test_sweep_section_states_the_method_and_the_match(tmp_path):
    (tmp_path / "sweep.json").write_text(json.dumps(SWEEP_JSON))
    rep = report.Report(tmp_path, {})
    rep.sweep_section()
    text = "\n".join(rep.lines)
    assert rep.lines[0] == "## Sweep against peers"
    assert "Hausdorff" in text and "cKDTree" in text and "3,001 stamps" in text and "depth images" in text
    assert "| ours (polyscrew.sweep) | 8 steps per screw | 10.00 ms | 94,430 | 0.0080 | 0.0140 |" in text
    assert "needs 64 copies per screw: 3,541,248 triangles (38x ours)" in text
    warp_all = next(line for line in rep.lines if "all 3,001 poses" in line)
    assert "(extrapolated)" in warp_all
    open_part = text.split("### Issue 29")[0]  # the three-case subsection (no JSON here) follows
    assert "gpytoolbox 0.3.8" in open_part and "not available" not in open_part


def test_sweep_section_says_why_it_is_missing(tmp_path):
    (tmp_path / "sweep.missing").write_text("polyscrew.sweep is not in this build\n")
    rep = report.Report(tmp_path, {})
    rep.sweep_section()
    assert "not available: polyscrew.sweep is not in this build" in rep.lines


def test_papers_section_marks_figures_from_other_machines():
    crit = {
        "hofer_table1/bunny 6/768 CUI": {"group": "hofer_table1", "function": "bunny 6/768 CUI", "value": None,
                                         "elements": None, "median_ns": 710e3, "low_ns": 0, "high_ns": 0},
        "fit_angular_velocity/top_20_keys": {"group": "fit_angular_velocity", "function": "top_20_keys", "value": None,
                                             "elements": None, "median_ns": 20e6, "low_ns": 0, "high_ns": 0},
    }
    rep = report.Report(Path("/nonexistent"), crit)
    rep.papers_section()
    text = "\n".join(rep.lines)
    assert "other machines" in rep.lines[0] and "not measured here" in rep.lines[0]
    bunny = next(line for line in rep.lines if "bunny" in line)
    assert "0.71 s" in bunny and "710.00 µs" in bunny and "| 1000x |" in bunny and "Matlab" in bunny
    teapot = next(line for line in rep.lines if "teapot" in line)
    assert "not measured in this run" in teapot
    xie = next(line for line in rep.lines if "Xie" in line)
    assert "about 2 s" in xie and "20.00 ms" in xie and "| 100x |" in xie
    assert "for scale" in text


def scaling_records(per_pose_ns, keys=(1_000, 10_000), levels=range(1, 9), schemes=("Jarek", "FourPoint", "BSpline")):
    """Synthetic criterion records of benches/scaling.rs: time = per_pose_ns(poses) * poses."""
    out = {}
    for scheme in schemes:
        for n in keys:
            for lv in levels:
                poses = n << lv
                out[f"scaling/{scheme}/{n}x{lv}"] = {
                    "group": "scaling", "function": scheme, "value": f"{n}x{lv}", "elements": poses,
                    "median_ns": per_pose_ns(poses) * poses, "low_ns": 0, "high_ns": 0}
    return out


def test_linearity_verdict_uses_the_memory_reused_rerun(tmp_path):
    # Default malloc: 90 ns per pose up to 320,000 poses, 180 ns beyond (fresh pages every call);
    # memory reused: 90 ns throughout.
    default = scaling_records(lambda poses: 90.0 if poses <= 320_000 else 180.0)
    reused = scaling_records(lambda poses: 90.0)
    rep = report.Report(tmp_path, default, reused)
    rep.subdivision_section()
    name, measured, verdict = rep.targets[-1]
    assert name == "subdivision linear in output size" and verdict == "met"
    reused_part, default_part = measured.split("; default malloc: ")
    assert reused_part == "Jarek p = 1.000, FourPoint p = 1.000, BSpline p = 1.000 (outputs >= 10,000, memory reused)"
    assert float(default_part.split("Jarek p = ")[1].split(",")[0]) > 1.05
    assert any("memory reused |" in line for line in rep.lines)
    # Without the rerun the verdict falls back on the default exponent, which is bent here.
    alone = report.Report(tmp_path, default)
    alone.subdivision_section()
    assert alone.targets[-1][2] == "**missed**" and "memory reused" not in alone.targets[-1][1]
