"""scripts/smooth_blend.py: same F-curves as the operator, clear failures with a non-zero exit."""

from __future__ import annotations

import os
import subprocess
import sys

import bpy
import numpy as np
import pytest

import bake_helpers as h
import conftest

SCRIPT = conftest.ROOT / "scripts" / "smooth_blend.py"
SCENE = conftest.ROOT / "scripts" / "demo" / "10_scene.py"
OBJECTS = ["Flyer", "LCycle", "Pendulum"]


def run(*args, cwd=None):
    env = dict(os.environ)
    env.pop("BLENDER_USER_RESOURCES", None)  # a plain bpy session, as a farm would start it
    return subprocess.run([sys.executable, *map(str, args)], env=env, capture_output=True, text=True, timeout=600, cwd=cwd)


@pytest.fixture(scope="module")
def demo_source(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo")
    done = run(SCENE, "--out-dir", out)
    assert done.returncode == 0, done.stderr
    return out / "demo_source.blend"


def curves_of(obj) -> dict:
    out = {}
    for fc in h.fcurves(obj):
        out[(fc.data_path, fc.array_index)] = (h.curve_points(fc), [m.type for m in fc.modifiers])
    return out


def test_same_fcurves_as_the_operator(demo_source, tmp_path):
    result = tmp_path / "smoothed.blend"
    done = run(SCRIPT, demo_source, "--objects", *OBJECTS, "--scheme", "bspline", "--levels", "5", "--step", "0.5", "--out", result)
    assert done.returncode == 0, done.stderr
    assert "smoothed 3 object(s)" in done.stdout

    bpy.ops.wm.open_mainfile(filepath=str(demo_source))
    h.select_only(*(bpy.data.objects[name] for name in OBJECTS))
    assert bpy.ops.screwbender.smooth(scheme="bspline", levels=5, step=0.5) == {"FINISHED"}
    expected = {name: curves_of(bpy.data.objects[name]) for name in OBJECTS}
    actions = {name: bpy.data.objects[name].animation_data.action.name for name in OBJECTS}

    bpy.ops.wm.open_mainfile(filepath=str(result))
    for name in OBJECTS:
        obj = bpy.data.objects[name]
        assert obj.animation_data.action.name == actions[name]
        got = curves_of(obj)
        assert got.keys() == expected[name].keys()
        for path, (points, modifiers) in expected[name].items():
            np.testing.assert_array_equal(got[path][0], points, err_msg=f"{name} {path}")
            assert got[path][1] == modifiers
    # the object left out is untouched
    assert bpy.data.objects["SpinBlock"].animation_data.action.name == "SpinBlockAction"


def test_all_animated_objects_by_default(demo_source, tmp_path):
    result = tmp_path / "all.blend"
    done = run(SCRIPT, demo_source, "--levels", "3", "--out", result)
    assert done.returncode == 0, done.stderr
    bpy.ops.wm.open_mainfile(filepath=str(result))
    for name in ("Flyer", "LCycle", "Pendulum", "SpinBlock"):
        assert bpy.data.objects[name].animation_data.action.name.endswith(".smooth")


@pytest.mark.parametrize(
    "args, reason, status",
    [
        (["--objects", "Flyer", "Nobody"], "no object named Nobody", 1),
        (["--scheme", "catmull"], "argument --scheme: invalid choice: 'catmull'", 2),
        (["--levels", "99"], "argument --levels: invalid choice: 99", 2),
        (["--step", "0"], "--step must be positive", 2),
        ([], "one of the arguments --out --in-place is required", 2),
    ],
)
def test_failures_exit_non_zero_with_one_line(demo_source, tmp_path, args, reason, status):
    out = [] if not args or "--out" in args else ["--out", tmp_path / "never.blend"]
    done = run(SCRIPT, demo_source, *args, *out)
    print(f"\nexit {done.returncode}: {done.stderr.strip()}")
    assert done.returncode == status
    lines = [line for line in done.stderr.splitlines() if line.startswith("smooth_blend:")]
    assert len(lines) == 1 and reason in lines[0], done.stderr
    assert not (tmp_path / "never.blend").exists()


def test_named_object_that_cannot_be_smoothed_fails(tmp_path):
    h.new_object("Still", "EMPTY")
    source = tmp_path / "still.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(source))
    done = run(SCRIPT, source, "--objects", "Still", "--out", tmp_path / "never.blend")
    assert done.returncode == 1
    assert "smooth_blend: error: Still: no animation" in done.stderr
    assert not (tmp_path / "never.blend").exists()
    missing = run(SCRIPT, tmp_path / "nope.blend", "--out", tmp_path / "never.blend")
    assert missing.returncode == 1 and "no such file" in missing.stderr


def test_blender_command_line_form(demo_source, tmp_path):
    """`blender --background in.blend --python smooth_blend.py -- ...`: the file is already open
    and the script's arguments follow "--" (simulated: bpy opens the file, then the script runs
    with Blender's argv)."""
    result = tmp_path / "cli.blend"
    code = (
        "import bpy, runpy, sys\n"
        f"bpy.ops.wm.open_mainfile(filepath={str(demo_source)!r})\n"
        f"sys.argv = ['blender', '--background', {str(demo_source)!r}, '--python', {str(SCRIPT)!r},"
        f" '--', '--objects', 'LCycle', '--levels', '2', '--out', {str(result)!r}]\n"
        f"runpy.run_path({str(SCRIPT)!r}, run_name='__main__')\n"
    )
    done = run("-c", code)
    assert done.returncode == 0, done.stderr
    bpy.ops.wm.open_mainfile(filepath=str(result))
    assert bpy.data.objects["LCycle"].animation_data.action.name == "LCycleAction.smooth"
    assert bpy.data.objects["Flyer"].animation_data.action.name == "FlyerAction"
