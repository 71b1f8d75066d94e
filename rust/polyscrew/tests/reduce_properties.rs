//! The laws of `polyscrew::reduce_keys` (issue 26), checked from the outside: every result is
//! played by the crate's Blender evaluator (`FCurve::evaluate`, `float32` keys), composed by
//! `intent::rotation_matrix` (not the reduction's own composition) and compared with the
//! dense motion (the poses, `s(a, t, b)` between them) at every frame and the three
//! subframes: the tolerance holds, the reported errors are the measured ones, the first and
//! last frames are keys, a straight slide needs two keys, a left-multiplied motion (new world
//! frame) keeps its key count in quaternion mode, a rig holds in world space, bad input is an
//! error.

use glam::{DMat3, DQuat, DVec3};
use polyscrew::reduce::{ReduceInput, ReduceOptions, Reduced, Tolerance};
use polyscrew::{
    reduce_keys, rotation_matrix, s, At, Error, Expected, Extrapolation, FCurve, Group, Key, Pose,
    RotationMode,
};
use proptest::prelude::*;

const MODES: [&str; 8] = [
    "QUATERNION",
    "AXIS_ANGLE",
    "XYZ",
    "XZY",
    "YXZ",
    "YZX",
    "ZXY",
    "ZYX",
];

/// A smooth random motion: rotation vector and translation sums of random sinusoids.
fn motion(n: usize, seed: u64, turns: f64) -> Vec<Pose> {
    let mut x = seed | 1;
    let mut next = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    };
    let c: Vec<f64> = (0..24).map(|_| next()).collect();
    (0..n)
        .map(|i| {
            let t = i as f64 / n as f64 * 6.0;
            let w =
                |k: usize| c[k] * (t * (0.5 + c[k + 1].abs())).sin() + c[k + 2] * (0.7 * t).cos();
            let rv = DVec3::new(w(0), w(3), w(6)) * turns;
            let tr = DVec3::new(w(9), w(12), w(15));
            Pose::from_rotation_translation(DQuat::from_scaled_axis(rv), tr)
        })
        .collect()
}

fn frames(n: usize) -> Vec<f64> {
    (0..n).map(|i| i as f64).collect()
}

/// The sample times: every frame and 3 subframes between two.
fn samples(frames: &[f64]) -> Vec<f64> {
    let mut out = Vec::new();
    for w in frames.windows(2) {
        for k in 0..4 {
            out.push(w[0] + (w[1] - w[0]) * k as f64 / 4.0);
        }
    }
    out.push(*frames.last().unwrap());
    out
}

/// The played local poses of owner `o` at `times`, groups without curves from `dense`.
fn play(r: &Reduced, o: usize, mode: RotationMode, times: &[f64], dense: &[Pose]) -> Vec<Pose> {
    let w = mode.width();
    let mut loc: Vec<Option<Vec<f64>>> = vec![None; 3];
    let mut rot: Vec<Option<Vec<f64>>> = vec![None; w];
    for c in r.curves.iter().filter(|c| c.owner == o) {
        let keys: Vec<Key> = c.keys.iter().map(|k| k.key()).collect();
        let curve = FCurve::new(keys, Extrapolation::Constant, None).unwrap();
        let values: Vec<f64> = times.iter().map(|t| curve.evaluate(*t).unwrap()).collect();
        match c.group {
            Group::Location => loc[c.index] = Some(values),
            Group::Rotation => rot[c.index] = Some(values),
            _ => {}
        }
    }
    (0..times.len())
        .map(|j| {
            let rotation = if rot.iter().all(|r| r.is_some()) {
                let v: Vec<f64> = rot.iter().map(|r| r.as_ref().unwrap()[j]).collect();
                DQuat::from_mat3(&rotation_matrix(mode, &v)).normalize()
            } else {
                dense[j].rotation
            };
            let translation = if loc.iter().all(|l| l.is_some()) {
                DVec3::new(
                    loc[0].as_ref().unwrap()[j],
                    loc[1].as_ref().unwrap()[j],
                    loc[2].as_ref().unwrap()[j],
                )
            } else {
                dense[j].translation
            };
            Pose {
                rotation,
                translation,
            }
        })
        .collect()
}

/// The dense motion at the samples: the poses and `s` between them.
fn dense_samples(poses: &[Pose]) -> Vec<Pose> {
    let mut out = Vec::new();
    for w in poses.windows(2) {
        for k in 0..4 {
            out.push(s(&w[0], k as f64 / 4.0, &w[1]));
        }
    }
    out.push(*poses.last().unwrap());
    out
}

/// Distance bound and angle of `a` against `b` on a body of radius `r`.
fn error(a: &Pose, b: &Pose, r: f64) -> (f64, f64) {
    let m = DMat3::from_quat(b.rotation).transpose() * DMat3::from_quat(a.rotation);
    let cos = ((m.x_axis.x + m.y_axis.y + m.z_axis.z - 1.0) / 2.0).clamp(-1.0, 1.0);
    let skew = DVec3::new(
        m.y_axis.z - m.z_axis.y,
        m.z_axis.x - m.x_axis.z,
        m.x_axis.y - m.y_axis.x,
    );
    let theta = (skew.length() / 2.0).atan2(cos);
    (
        (a.translation - b.translation).length() + 2.0 * r * (theta / 2.0).sin(),
        theta,
    )
}

#[path = "fixtures/reduce.rs"]
mod fixtures;
use fixtures::{input, options};

/// Plays every owner, asserts the tolerance at every sample and the reported errors.
fn assert_within(
    r: &Reduced,
    poses: &[Pose],
    n: usize,
    modes: &[RotationMode],
    radius: &[f64],
    tol: Tolerance,
) {
    let f = frames(n);
    let times = samples(&f);
    for (o, mode) in modes.iter().enumerate() {
        let dense = dense_samples(&poses[o * n..(o + 1) * n]);
        let played = play(r, o, *mode, &times, &dense);
        let (mut dmax, mut amax) = (0.0f64, 0.0f64);
        for (p, d) in played.iter().zip(&dense) {
            let (e, a) = error(p, d, radius[o]);
            dmax = dmax.max(e);
            amax = amax.max(a);
        }
        assert!(
            dmax <= tol.distance && amax <= tol.angle,
            "owner {o} {mode:?}: {dmax:e} {amax:e}"
        );
        assert!(
            (dmax - r.distance_error[o]).abs() <= 1e-3 * dmax + 1e-9,
            "{dmax} vs {}",
            r.distance_error[o]
        );
        assert!(
            (amax - r.angle_error[o]).abs() <= 1e-3 * amax + 1e-9,
            "{amax} vs {}",
            r.angle_error[o]
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    #[test]
    fn tolerance_holds_in_every_mode(seed in 1u64.., m in 0usize..8, turns in 0.2f64..2.0, n in 20usize..160, distance in 1e-4f64..1e-2) {
        let mode = RotationMode::from_name(MODES[m]).unwrap();
        let poses = motion(n, seed, turns);
        let f = frames(n);
        let tol = Tolerance { distance, angle: distance * 10.0 };
        let r = reduce_keys(&input(&poses, &f, &[mode], &[0.5]), &options(tol.distance, tol.angle)).unwrap();
        assert_within(&r, &poses, n, &[mode], &[0.5], tol);
        for c in &r.curves {
            prop_assert_eq!(c.keys[0].co[0], 0.0);
            prop_assert_eq!(c.keys.last().unwrap().co[0], (n - 1) as f64);
            prop_assert_eq!(c.keys.len(), r.keys[0]);
        }
        // At most a key per frame on the frames; a span of one frame that no cubic can keep
        // within the tolerance of the screw between the frames (a fast turn: 32 degrees a frame
        // at 6 mm) gets keys at subframes too
        // (the proof covers the 1/4, 1/2, 3/4 subframes), so only whole-frame keys are bounded.
        let whole = r.curves[0].keys.iter().filter(|k| k.co[0].fract() == 0.0).count();
        prop_assert!(whole <= n, "{} keys on whole frames of {}", whole, n);
    }

    #[test]
    fn a_new_world_frame_keeps_the_key_count(seed in 1u64.., g in 1u64.., n in 30usize..150) {
        let mode = RotationMode::Quaternion;
        let poses = motion(n, seed, 1.0);
        let gp = motion(3, g, 3.0)[1];
        let moved: Vec<Pose> = poses.iter().map(|p| gp.mul_pose(p)).collect();
        let f = frames(n);
        let r0 = reduce_keys(&input(&poses, &f, &[mode], &[0.5]), &options(1e-3, 0.01)).unwrap();
        let r1 = reduce_keys(&input(&moved, &f, &[mode], &[0.5]), &options(1e-3, 0.01)).unwrap();
        prop_assert_eq!(&r0.keys, &r1.keys);
        assert_within(&r1, &moved, n, &[mode], &[0.5], Tolerance { distance: 1e-3, angle: 0.01 });
    }
}

#[test]
fn a_straight_slide_needs_two_keys() {
    let n = 100;
    let poses: Vec<Pose> = (0..n)
        .map(|i| {
            Pose::from_rotation_translation(
                DQuat::from_rotation_x(0.3),
                DVec3::new(0.03 * i as f64, 1.0, -2.0),
            )
        })
        .collect();
    let f = frames(n);
    for m in MODES {
        let mode = RotationMode::from_name(m).unwrap();
        let r = reduce_keys(&input(&poses, &f, &[mode], &[1.0]), &options(1e-4, 1e-4)).unwrap();
        assert_eq!(r.keys, vec![2], "{m}");
    }
}

#[test]
fn a_rig_holds_in_world_space() {
    let n = 120;
    let b = 4;
    let mut poses = Vec::new();
    for o in 0..b {
        let mut m = motion(n, 7 + o as u64, 0.5);
        for p in &mut m {
            p.translation *= 0.05;
        }
        poses.extend(m);
    }
    let offsets: Vec<Pose> = (0..b)
        .map(|o| Pose::from_translation(DVec3::new(0.0, if o == 0 { 0.0 } else { 0.7 }, 0.0)))
        .collect();
    let parents: Vec<Option<usize>> = (0..b).map(|o: usize| o.checked_sub(1)).collect();
    let f = frames(n);
    let modes = vec![RotationMode::Quaternion; b];
    let radius = vec![0.7; b];
    let mut inp = input(&poses, &f, &modes, &radius);
    inp.parents = Some(&parents);
    inp.offsets = Some(&offsets);
    let tol = Tolerance {
        distance: 1e-3,
        angle: 0.01,
    };
    let r = reduce_keys(&inp, &options(tol.distance, tol.angle)).unwrap();
    let worst = chain_errors(&r, &poses, n, &parents, &offsets, &modes, &radius);
    for (o, worst) in worst.iter().enumerate() {
        assert!(
            worst.0 <= tol.distance && worst.1 <= tol.angle,
            "bone {o}: {worst:?}"
        );
        assert!((worst.0 - r.distance_error[o]).abs() <= 1e-3 * worst.0 + 1e-9);
    }
}

/// Per owner of a chain (`parents`, `offsets`): the largest distance and angle between the
/// played reduced motion and the dense one in world space, over every frame and subframe.
fn chain_errors(
    r: &Reduced,
    poses: &[Pose],
    n: usize,
    parents: &[Option<usize>],
    offsets: &[Pose],
    modes: &[RotationMode],
    radius: &[f64],
) -> Vec<(f64, f64)> {
    let times = samples(&frames(n));
    let mut world_dense: Vec<Vec<Pose>> = Vec::new();
    let mut world_played: Vec<Vec<Pose>> = Vec::new();
    let mut out = Vec::new();
    for o in 0..modes.len() {
        let dense = dense_samples(&poses[o * n..(o + 1) * n]);
        let played = play(r, o, modes[o], &times, &dense);
        let world = |local: &[Pose], above: &[Vec<Pose>]| -> Vec<Pose> {
            (0..times.len())
                .map(|j| {
                    let base = parents[o].map_or(Pose::IDENTITY, |p| above[p][j]);
                    base.mul_pose(&offsets[o]).mul_pose(&local[j])
                })
                .collect()
        };
        let wd = world(&dense, &world_dense);
        let wp = world(&played, &world_played);
        out.push(
            wd.iter()
                .zip(&wp)
                .map(|(d, p)| error(p, d, radius[o]))
                .fold((0.0f64, 0.0f64), |a, e| (a.0.max(e.0), a.1.max(e.1))),
        );
        world_dense.push(wd);
        world_played.push(wp);
    }
    out
}

/// A chain of connected bones (the middle ones key rotation only; Blender ignores their
/// location) ending in a bone that keys its location too: the error reported for every bone
/// is the one measured in world space, the parent's error carried to the child's head included (before issue 26's last round the core counted the
/// unkeyed location as exact and reported less: 0.92 mm for the first child, 1.64 mm measured).
#[test]
fn a_connected_chain_reports_its_world_error() {
    let n = 120;
    let b = 4;
    let mut poses = Vec::new();
    for o in 0..b {
        let mut m = motion(n, 11 + o as u64, 0.5);
        for p in &mut m {
            p.translation = if o == 0 || o == b - 1 {
                p.translation * 0.05
            } else {
                DVec3::ZERO
            };
        }
        poses.extend(m);
    }
    let offsets: Vec<Pose> = (0..b)
        .map(|o| Pose::from_translation(DVec3::new(0.0, if o == 0 { 0.0 } else { 0.7 }, 0.0)))
        .collect();
    let parents: Vec<Option<usize>> = (0..b).map(|o: usize| o.checked_sub(1)).collect();
    let channels: Vec<[bool; 3]> = (0..b)
        .map(|o| [o == 0 || o == b - 1, true, false])
        .collect();
    let f = frames(n);
    let modes = vec![RotationMode::Euler(polyscrew::EulerOrder::Xyz); b];
    let radius = vec![0.7; b];
    let mut inp = input(&poses, &f, &modes, &radius);
    inp.parents = Some(&parents);
    inp.offsets = Some(&offsets);
    inp.channels = Some(&channels);
    let r = reduce_keys(&inp, &options(1e-3, 0.01)).unwrap();
    let worst = chain_errors(&r, &poses, n, &parents, &offsets, &modes, &radius);
    for (o, worst) in worst.iter().enumerate() {
        println!(
            "bone {o}: measured {:.4} mm, {:.4} deg; reported {:.4} mm, {:.4} deg",
            1e3 * worst.0,
            worst.1.to_degrees(),
            1e3 * r.distance_error[o],
            r.angle_error[o].to_degrees()
        );
        assert!(
            (worst.0 - r.distance_error[o]).abs() <= 1e-3 * worst.0 + 1e-9,
            "bone {o}: measured {worst:?}, reported {} {}",
            r.distance_error[o],
            r.angle_error[o]
        );
        assert!(
            (worst.1 - r.angle_error[o]).abs() <= 1e-3 * worst.1 + 1e-9,
            "bone {o}: measured {worst:?}, reported {}",
            r.angle_error[o]
        );
    }
    // the case is one where the parents' error reaches the children's heads
    assert!(worst[1..].iter().any(|w| w.0 > 1e-3));
}

#[test]
fn bad_input_is_an_error() {
    let n = 10;
    let poses = motion(n, 3, 1.0);
    let f = frames(n);
    let modes = [RotationMode::Quaternion];
    let base = input(&poses, &f, &modes, &[1.0]);
    let bad = |inp: ReduceInput<'_>, o: ReduceOptions| reduce_keys(&inp, &o).unwrap_err();
    assert!(matches!(
        bad(base, options(0.0, 1.0)),
        Error::Value {
            what: "distance",
            expected: Expected::Positive(_),
            ..
        }
    ));
    assert!(matches!(
        bad(base, options(1.0, f64::NAN)),
        Error::Value { what: "angle", .. }
    ));
    let back: Vec<f64> = f.iter().rev().copied().collect();
    assert!(matches!(
        bad(input(&poses, &back, &modes, &[1.0]), options(1.0, 1.0)),
        Error::Spacing {
            what: "frames",
            at: At { index: 1, .. },
            ..
        }
    ));
    assert!(matches!(
        bad(
            input(&poses[..1], &f[..1], &modes, &[1.0]),
            options(1.0, 1.0)
        ),
        Error::TooFew { .. }
    ));
    assert!(matches!(
        bad(input(&poses, &f, &modes, &[-1.0]), options(1.0, 1.0)),
        Error::Value {
            what: "radius",
            at: Some(At { index: 0, .. }),
            ..
        }
    ));
    let two: Vec<Pose> = poses.iter().chain(&poses).copied().collect();
    let modes2 = [RotationMode::Quaternion; 2];
    let mut cyc = input(&two, &f, &modes2, &[1.0, 1.0]);
    let parents = [Some(1), Some(0)];
    cyc.parents = Some(&parents);
    let e = bad(cyc, options(1.0, 1.0));
    assert!(
        matches!(
            e,
            Error::Degenerate {
                what: "parents",
                ..
            }
        ),
        "{e:?}"
    );
    assert!(e.to_string().contains("cycle"), "{e}");
}
