"""Smooth Motion's "Feature Points" method (Hofer-Pottmann-Ravani): the baked channels are
`polyscrew.sample_feature` of the key poses with the mesh's inertia points; with Approximate
Keys the selected keys are approximated with the Stiffness option and the others hit."""

from __future__ import annotations

import bpy
import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

import bake_helpers as h

#: Baked values are stored by Blender as float32.
SAMPLE_TOLERANCE = 1e-6

FRAMES = [1.0, 6.0, 13.0, 19.0, 24.0, 31.0, 36.0, 44.0]


def keyed(seed: int, kind: str = "MESH", scales: bool = True):
    obj = h.new_object("Body", kind, "XYZ")
    rng = np.random.default_rng(seed)
    steps = Rotation.from_rotvec(rng.normal(0, 0.5, (len(FRAMES), 3)))
    rotations = [Rotation.identity()]
    for step in steps[1:]:
        rotations.append(step * rotations[-1])
    # Keys along a gentle arc with jitter: the noisy keys the method is for.
    t = np.linspace(0.0, 1.0, len(FRAMES))
    path = np.c_[6 * t, 3 * np.sin(np.pi * t), np.zeros_like(t)] + rng.normal(0, 0.3, (len(FRAMES), 3))
    poses = h.rigid(path, np.array([r.as_matrix() for r in rotations]))
    h.key_poses(obj, FRAMES, poses, rng.uniform(0.5, 2.0, (len(FRAMES), 3)) if scales else None)
    h.select_only(obj)
    return obj


def expected_points(obj, motion):
    if obj.type != "MESH":
        return None
    co = np.array([v.co for v in obj.data.vertices])
    return polyscrew.inertia_points(co * np.exp(np.log(motion.scales).mean(axis=0)))


def select_keys(obj, frames):
    """Selects exactly the keys at `frames` on every F-curve of `obj`."""
    for fcurve in h.fcurves(obj):
        for point in fcurve.keyframe_points:
            point.select_control_point = any(abs(point.co[0] - f) < 1e-3 for f in frames)


@pytest.mark.parametrize("parametrization", ["uniform", "centripetal"])
@pytest.mark.parametrize("kind", ["MESH", "EMPTY"])
def test_baked_channels_are_sample_feature(sb, parametrization, kind):
    obj = keyed(seed=3, kind=kind)
    motion = sb.keys.read(obj)
    assert bpy.ops.screwbender.smooth(method="FEATURE", parametrization=parametrization, levels=4, scheme="jarek", timing="smooth") == {"FINISHED"}
    frames, baked = h.baked_matrices(obj)
    expected = polyscrew.sample_feature(
        motion.poses, motion.frames, frames, levels=4, closed=motion.closed, period=motion.period,
        feature_points=expected_points(obj, motion), parametrization=parametrization,
    )
    assert np.abs(baked - expected).max() < SAMPLE_TOLERANCE
    # Every key is hit (interpolating variational design), the motion differs from the screw one.
    at_keys = np.searchsorted(frames, motion.frames)
    assert np.abs(baked[at_keys] - motion.poses).max() < 1e-5
    screw = polyscrew.sample(motion.poses, motion.frames, frames, levels=4)
    assert np.abs(baked - screw).max() > 1e-3


def test_selected_keys_approximated_others_hit(sb):
    obj = keyed(seed=8)
    motion = sb.keys.read(obj)
    # Freshly inserted keys are all selected: by default every inner key is approximated.
    assert all(p.select_control_point for fc in h.fcurves(obj) for p in fc.keyframe_points)
    select_keys(obj, [f for i, f in enumerate(FRAMES) if i != 3])
    assert bpy.ops.screwbender.smooth(method="FEATURE", approximate=True, stiffness=0.5, levels=4, scheme="jarek", timing="smooth") == {"FINISHED"}
    frames, baked = h.baked_matrices(obj)
    at_keys = np.searchsorted(frames, motion.frames)
    miss = np.abs(baked[at_keys] - motion.poses).max(axis=(1, 2))
    # The unselected key and the two ends of the open motion: hit; the selected inner keys:
    # approximated.
    hit = [0, 3, len(FRAMES) - 1]
    assert miss[hit].max() < 1e-5, miss
    assert np.delete(miss, hit).min() > 1e-3, miss
    lam = np.full(len(FRAMES), 0.5)
    lam[hit] = np.inf
    expected = polyscrew.sample_feature(
        motion.poses, motion.frames, frames, levels=4, feature_points=expected_points(obj, motion), stiffness=lam
    )
    assert np.abs(baked - expected).max() < SAMPLE_TOLERANCE
    # Smoother than hitting every key: the location's second differences are smaller.
    assert bpy.ops.screwbender.revert() == {"FINISHED"}
    assert bpy.ops.screwbender.smooth(method="FEATURE", levels=4, scheme="jarek", timing="smooth") == {"FINISHED"}
    exact = h.baked_matrices(obj)[1]

    def roughness(m):
        return np.abs(np.diff(m[:, :3, 3], 2, axis=0)).sum()

    assert roughness(baked) < 0.8 * roughness(exact)


def test_options_registered_with_tooltips(sb):
    assert bpy.context.scene.screwbender.method == "SCREW"
    rna = bpy.ops.screwbender.smooth.get_rna_type()
    for name in ("method", "parametrization", "approximate", "stiffness"):
        assert rna.properties[name].description, f"option {name} has no tooltip"
    assert "selected" in rna.properties["approximate"].description
    assert {item.identifier for item in rna.properties["method"].enum_items} == {"SCREW", "FEATURE"}


def test_default_method_unchanged(sb):
    obj = keyed(seed=5)
    motion = sb.keys.read(obj)
    assert bpy.ops.screwbender.smooth(levels=4, scheme="jarek", timing="smooth") == {"FINISHED"}
    frames, baked = h.baked_matrices(obj)
    expected = polyscrew.sample(motion.poses, motion.frames, frames, scheme="jarek", levels=4)
    assert np.abs(baked - expected).max() < SAMPLE_TOLERANCE


def test_smooth_blend_script_feature_method(tmp_path):
    """scripts/smooth_blend.py --method FEATURE gives the operator's F-curves."""
    from test_smooth_blend import SCENE, SCRIPT, curves_of, run

    done = run(SCENE, "--out-dir", tmp_path)
    assert done.returncode == 0, done.stderr
    source = tmp_path / "demo_source.blend"
    result = tmp_path / "smoothed.blend"
    args = ("--method", "FEATURE", "--parametrization", "centripetal", "--stiffness", "0.5", "--levels", "4")
    done = run(SCRIPT, source, "--objects", "Flyer", *args, "--out", result)
    assert done.returncode == 0, done.stderr
    bpy.ops.wm.open_mainfile(filepath=str(source))
    h.select_only(bpy.data.objects["Flyer"])
    assert bpy.ops.screwbender.smooth(
        method="FEATURE", parametrization="centripetal", approximate=True, stiffness=0.5, levels=4
    ) == {"FINISHED"}
    expected = curves_of(bpy.data.objects["Flyer"])
    bpy.ops.wm.open_mainfile(filepath=str(result))
    got = curves_of(bpy.data.objects["Flyer"])
    assert got.keys() == expected.keys()
    for path, (points, _) in expected.items():
        np.testing.assert_array_equal(got[path][0], points, err_msg=str(path))
    bad = run(SCRIPT, source, "--stiffness", "1", "--out", result)
    assert bad.returncode == 2 and "--stiffness needs --method FEATURE" in bad.stderr


def test_approximate_keys_refuses_stiffness_zero_and_no_selection(sb):
    obj = h.new_object("Noisy", "MESH", "XYZ")
    rng = np.random.default_rng(3)
    for f in range(1, 40, 4):
        obj.location = rng.normal(0, 1, 3)
        obj.keyframe_insert("location", frame=f)
    h.select_only(obj)
    before = h.snapshot_data()
    with pytest.raises(RuntimeError, match="Stiffness 0 would ignore the selected keys"):
        bpy.ops.screwbender.smooth(method="FEATURE", approximate=True, stiffness=0.0)
    for fc in h.fcurves(obj):
        for kp in fc.keyframe_points:
            kp.select_control_point = False
    with pytest.raises(RuntimeError, match="Approximate Keys: no key of its transform curves is selected"):
        bpy.ops.screwbender.smooth(method="FEATURE", approximate=True, stiffness=0.5)
    assert h.snapshot_data() == before
