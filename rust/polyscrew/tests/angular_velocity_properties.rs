//! Property tests of `fit_angular_velocity` on random keys, constraint sets and targets:
//! it never panics, constrained keys hold exactly, orientations are unit, free keys are
//! free, and the result never has more variable frames than allowed.

use std::f64::consts::PI;

use glam::{DQuat, DVec3, DVec4};
use polyscrew::{fit_angular_velocity, AngularVelocityTarget, FitOptions};
use proptest::prelude::*;

#[path = "fixtures/poses.rs"]
mod poses;
use poses::unit;

fn rotation() -> impl Strategy<Value = DQuat> {
    (unit(), 0.0..PI).prop_map(|(axis, angle)| DQuat::from_axis_angle(axis, angle))
}

/// Angle of the rotation from `a` to `b`, accurate near zero.
fn angle(a: DQuat, b: DQuat) -> f64 {
    let d = DVec4::from(a.conjugate() * b);
    2.0 * d.truncate().length().atan2(d.w.abs())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn constrained_keys_hold_and_orientations_are_unit(
        keys in prop::collection::vec(rotation(), 2..7),
        gaps in prop::collection::vec(0.1..1.0f64, 6),
        mask in prop::collection::vec(any::<bool>(), 6),
        omega in prop::collection::vec((unit(), 0.0..8.0f64), 2..12),
        max_frames in 0usize..5,
    ) {
        let n = keys.len();
        let mut times = vec![0.0];
        for g in &gaps[..n - 1] {
            times.push(times.last().unwrap() + g);
        }
        let span = times[n - 1];
        let m = omega.len();
        let tt: Vec<f64> = (0..m).map(|j| span * j as f64 / (m - 1) as f64).collect();
        let w: Vec<DVec3> = omega.iter().map(|(d, s)| *d * *s).collect();
        let target = AngularVelocityTarget::new(&tt, &w).unwrap();
        let constrained = &mask[..n];
        let options = FitOptions { max_frames, ..FitOptions::default() };
        let fit = fit_angular_velocity(&keys, &times, constrained, &target, &options).unwrap();
        prop_assert!(fit.frame_times.len() <= max_frames);
        prop_assert!(fit.fit_error.is_finite() && fit.energy.is_finite());
        for i in 0..n {
            if constrained[i] {
                let a = angle(fit.keys[i], keys[i]);
                prop_assert!(a < 1e-9, "key {i} moved by {a}");
                let at = fit.sample(&[times[i]]).unwrap()[0];
                prop_assert!(angle(at, keys[i]) < 1e-9, "key {i} not met at its time");
            }
        }
        for j in 0..=50 {
            let q = fit.rotation(span * j as f64 / 50.0);
            prop_assert!((q.length() - 1.0).abs() < 1e-12);
        }
    }
}
