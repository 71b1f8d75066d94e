//! Property tests of the laws in DESIGN.md: screw accuracy and continuity, frame invariance,
//! reproduction of single screws (line, circle, helix), 4-point interpolation, rigidity.

use std::f64::consts::PI;

use glam::DQuat;
use polyscrew::{s, subdivide, Pose, Scheme, Screw};
use proptest::prelude::*;

#[path = "fixtures/poses.rs"]
mod poses;
use poses::{exact, point, rigidity_error, unit};

const SCHEMES: [Scheme; 3] = [Scheme::FourPoint, Scheme::BSpline, Scheme::Jarek];

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 2000,
        ..ProptestConfig::default()
    }
}

fn pose() -> impl Strategy<Value = Pose> {
    poses::pose(PI, 2.0)
}

proptest! {
    #![proptest_config(config())]

    /// `s` matches the exact screw to 1e-12 for angles from 0 to 1e-13 .. 1e-3 and within
    /// 1e-9 of pi, with a unit-size translation.
    #[test]
    fn s_is_exact_at_tiny_and_half_turn_angles(
        a in pose(), axis in unit(), p in point(1.0), slide in -1.0..1.0f64,
        exponent in -13.0..-3.0f64, near_pi in 1e-9..1e-6f64, zero in proptest::bool::ANY,
        t in -0.5..1.5f64,
    ) {
        for angle in [if zero { 0.0 } else { 10f64.powf(exponent) }, PI - near_pi] {
            let b = exact(axis, p, angle, slide, 1.0, &a);
            let got = s(&a, t, &b);
            let want = exact(axis, p, angle, slide, t, &a);
            let err = got.max_abs_diff(&want);
            prop_assert!(err < 1e-12, "angle {angle:e} t {t}: error {err:e}");
        }
    }

    /// No jump in `s` across tiny changes of the angle near 0 and near pi.
    #[test]
    fn s_is_continuous_near_zero_and_pi(
        a in pose(), axis in unit(), p in point(1.0), slide in -1.0..1.0f64,
        base in prop_oneof![0.0..1e-7f64, (PI - 1e-7)..(PI - 1e-9)], t in -0.5..1.5f64,
    ) {
        let eps = 1e-11;
        let b0 = exact(axis, p, base, slide, 1.0, &a);
        let b1 = exact(axis, p, base + eps, slide, 1.0, &a);
        let jump = s(&a, t, &b0).max_abs_diff(&s(&a, t, &b1));
        prop_assert!(jump < 1e-9, "angle {base:e}: jump {jump:e}");
    }

    /// `s(A a B, t, A b B) = A s(a, t, b) B` and the endpoints are hit.
    #[test]
    fn s_is_frame_invariant(a in pose(), b in pose(), left in pose(), right in pose(), t in -0.5..1.5f64) {
        prop_assume!(Screw::between(&a, &b).angle() < PI - 1e-3);
        let moved = s(&left.mul_pose(&a).mul_pose(&right), t, &left.mul_pose(&b).mul_pose(&right));
        let want = left.mul_pose(&s(&a, t, &b)).mul_pose(&right);
        prop_assert!(moved.max_abs_diff(&want) < 1e-10, "{:e}", moved.max_abs_diff(&want));
        prop_assert!(s(&a, 0.0, &b).max_abs_diff(&a) < 1e-15);
        prop_assert!(s(&a, 1.0, &b).max_abs_diff(&b) < 1e-13);
    }

    /// Every scheme commutes with left and right rigid transforms, closed and open, and
    /// its output is rigid to 1e-12.
    #[test]
    fn schemes_are_frame_invariant_and_rigid(
        start in pose(), steps in proptest::collection::vec((unit(), 0.0..2.0f64, point(1.0)), 2..7),
        left in pose(), right in pose(), levels in 1u32..4, closed in proptest::bool::ANY,
    ) {
        // Keys whose consecutive rotations stay below 115 degrees, so every screw the rules
        // build is far from the half-turn ambiguity.
        let mut keys = vec![start];
        for (axis, angle, t) in &steps {
            let last = *keys.last().unwrap();
            keys.push(Pose::from_rotation_translation(DQuat::from_axis_angle(*axis, *angle) * last.rotation, last.translation + *t));
        }
        if closed {
            prop_assume!(Screw::between(keys.last().unwrap(), &keys[0]).angle() < 2.0);
        }
        let moved: Vec<Pose> = keys.iter().map(|k| left.mul_pose(k).mul_pose(&right)).collect();
        for scheme in SCHEMES {
            let a = subdivide(&keys, scheme, levels, closed).unwrap();
            let b = subdivide(&moved, scheme, levels, closed).unwrap();
            for (x, y) in a.iter().zip(&b) {
                let want = left.mul_pose(x).mul_pose(&right);
                let err = y.max_abs_diff(&want);
                prop_assert!(err < 1e-9, "{scheme:?} closed {closed}: error {err:e}");
                prop_assert!(rigidity_error(y) < 1e-12, "rigidity {:e}", rigidity_error(y));
            }
            if scheme == Scheme::FourPoint {
                for (i, k) in keys.iter().enumerate() {
                    let err = a[i << levels].max_abs_diff(k);
                    prop_assert!(err < 1e-13, "4-point moved key {i} by {err:e}");
                }
            }
            if !closed {
                prop_assert!(a[0].max_abs_diff(&keys[0]) == 0.0);
                prop_assert!(a.last().unwrap().max_abs_diff(keys.last().unwrap()) == 0.0);
            }
        }
    }

    /// Poses sampled evenly on one screw (a line, a circle, a helix) come back on it, at the
    /// same parameters, after any number of levels of any scheme, closed and open.
    #[test]
    fn single_screws_are_reproduced(
        start in pose(), axis in unit(), p in point(2.0), kind in 0usize..3,
        step_angle in 0.1..1.6f64, slide in 0.2..1.5f64, n in 3usize..8, levels in 1u32..5,
    ) {
        // kind 0: line (pure translation), 1: circle, 2: helix.
        let (angle, slide) = match kind { 0 => (0.0, slide), 1 => (step_angle, 0.0), _ => (step_angle, slide) };
        let keys: Vec<Pose> = (0..n).map(|i| exact(axis, p, angle, slide, i as f64, &start)).collect();
        for scheme in SCHEMES {
            let out = subdivide(&keys, scheme, levels, false).unwrap();
            for (j, q) in out.iter().enumerate() {
                let u = j as f64 / (1u64 << levels) as f64;
                let err = q.max_abs_diff(&exact(axis, p, angle, slide, u, &start));
                prop_assert!(err < 1e-10, "{scheme:?} kind {kind} open: pose {j} off by {err:e}");
            }
            if kind == 1 {
                // A closed circle: n poses a full turn apart.
                let step = 2.0 * PI / n as f64;
                let ring: Vec<Pose> = (0..n).map(|i| exact(axis, p, step, 0.0, i as f64, &start)).collect();
                let out = subdivide(&ring, scheme, levels, true).unwrap();
                for (j, q) in out.iter().enumerate() {
                    let u = j as f64 / (1u64 << levels) as f64;
                    let err = q.max_abs_diff(&exact(axis, p, step, 0.0, u, &start));
                    prop_assert!(err < 1e-10, "{scheme:?} closed circle: pose {j} off by {err:e}");
                }
            }
        }
    }

    /// Unevenly spaced poses on one helix stay on that helix (at other parameters).
    #[test]
    fn uneven_samples_stay_on_their_helix(
        start in pose(), axis in unit(), p in point(2.0), angle in 0.1..0.8f64, slide in 0.3..1.5f64,
        gaps in proptest::collection::vec(0.5..1.5f64, 3..7), levels in 1u32..4,
    ) {
        let mut u = 0.0;
        let mut keys = vec![start];
        for g in &gaps {
            u += g;
            keys.push(exact(axis, p, angle, slide, u, &start));
        }
        for scheme in SCHEMES {
            for q in subdivide(&keys, scheme, levels, false).unwrap() {
                // The slide coordinate gives the helix parameter of the pose's origin.
                let u = (q.translation - start.translation).dot(axis) / slide;
                let err = q.max_abs_diff(&exact(axis, p, angle, slide, u, &start));
                prop_assert!(err < 1e-9, "{scheme:?}: off the helix by {err:e}");
            }
        }
    }
}
