//! Issue 15 in Rust: finite in, finite out at the edges of the working ranges (property
//! tests), and the memory rule (a budget refusal before allocation, with its message).
//!
//! The budget is process-wide: the one test that changes it restores it and is the only
//! one in this binary that depends on it.

use glam::{DQuat, DVec3};
use proptest::prelude::*;

use polyscrew::motion::pose::MAX_COORDINATE;
use polyscrew::{
    fit_angular_velocity, sample, subdivide, AngularVelocityTarget, Error, FitOptions, MotionSpec,
    Pose, Scheme, Screw, Timing,
};

fn pose(axis: [f64; 3], angle: f64, t: [f64; 3]) -> Pose {
    let axis = DVec3::from(axis);
    let axis = axis.try_normalize().unwrap_or(DVec3::Z);
    Pose::from_rotation_translation(DQuat::from_axis_angle(axis, angle), DVec3::from(t))
}

fn finite(p: &Pose) -> bool {
    p.rotation.is_finite() && p.translation.is_finite()
}

fn coordinate() -> impl Strategy<Value = f64> {
    prop_oneof![
        -MAX_COORDINATE..MAX_COORDINATE,
        Just(MAX_COORDINATE),
        Just(-MAX_COORDINATE),
        -1.0..1.0f64,
    ]
}

fn key() -> impl Strategy<Value = Pose> {
    (
        prop::array::uniform3(-1.0..1.0f64),
        0.0..std::f64::consts::PI,
        prop::array::uniform3(coordinate()),
    )
        .prop_map(|(a, r, t)| pose(a, r, t))
}

fn scheme() -> impl Strategy<Value = Scheme> {
    prop_oneof![
        Just(Scheme::Jarek),
        Just(Scheme::FourPoint),
        Just(Scheme::BSpline)
    ]
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Keys anywhere in the coordinate range, any turns: every subdivided and sampled pose
    /// is finite, and none is further out than 4 times the range (the factor its derivation
    /// allows).
    #[test]
    fn subdivision_and_sampling_stay_finite(
        keys in prop::collection::vec(key(), 2..6),
        scheme in scheme(),
        levels in 0u32..7,
        closed: bool,
        times in prop::collection::vec(-10.0..20.0f64, 1..20),
    ) {
        let dense = subdivide(&keys, scheme, levels, closed).unwrap();
        for p in &dense {
            prop_assert!(finite(p), "{p:?}");
            prop_assert!(p.translation.abs().max_element() <= 4.0 * MAX_COORDINATE, "{p:?}");
        }
        let key_times: Vec<f64> = (0..keys.len()).map(|i| i as f64 * 3.0).collect();
        let spec = MotionSpec { scheme, levels, closed, period: None, timing: Timing::Smooth };
        for p in sample(&keys, &key_times, &times, &spec).unwrap() {
            prop_assert!(finite(&p), "{p:?}");
        }
    }

    /// The screw between two poses in range, evaluated anywhere in `|t| <= 1e12`: finite.
    #[test]
    fn screws_stay_finite(a in key(), b in key(), t in prop_oneof![-1e12..1e12f64, -3.0..3.0f64]) {
        let sc = Screw::between(&a, &b);
        prop_assert!(sc.axis().is_finite() && sc.point().is_finite(), "{sc:?}");
        prop_assert!(sc.slide().is_finite() && sc.angle().is_finite(), "{sc:?}");
        prop_assert!(finite(&sc.eval(t)), "{a:?} {b:?} {t}");
    }

    /// Key times anywhere in +-1e300 with spacings down to 1e-300: the time map is finite
    /// and monotone.
    #[test]
    fn timing_stays_finite(
        start in prop_oneof![-1e299..1e299f64, -1.0..1.0f64],
        steps in prop::collection::vec(prop_oneof![1e-300..1e-290f64, 1e-3..1e3f64, 1e290..1e297f64], 1..5),
        closed: bool,
    ) {
        let mut key_times = vec![start];
        for s in &steps {
            let next = key_times.last().unwrap() + s;
            prop_assume!(next > *key_times.last().unwrap() && next.abs() <= 1e300);
            key_times.push(next);
        }
        let keys: Vec<DVec3> = (0..key_times.len()).map(|i| DVec3::splat(i as f64)).collect();
        let spec = MotionSpec { scheme: Scheme::Jarek, levels: 3, closed, period: None, timing: Timing::Smooth };
        let span = key_times.last().unwrap() - key_times[0];
        let times: Vec<f64> = (0..=40).map(|i| key_times[0] + span * (i as f64 / 40.0)).collect();
        match sample(&keys, &key_times, &times, &spec) {
            Ok(out) => {
                for v in &out {
                    prop_assert!(v.is_finite(), "{key_times:?}: {v}");
                }
            }
            // A default period past the range's end is refused, not computed.
            Err(e) => prop_assert!(closed && matches!(e, Error::Period { .. }), "{e}"),
        }
    }

    /// The fit at the edges of its ranges (times 1e30, spacings 1e-30, angular velocities
    /// 1e30, alpha up to 1e30): a finite result or an error, never NaN reported as converged.
    #[test]
    fn fits_stay_finite(
        scale in prop_oneof![Just(1e-30), Just(1.0), Just(1e25)],
        omega in prop_oneof![Just(0.0), Just(1.0), Just(1e30), -1e30..1e30f64],
        alpha in prop_oneof![Just(0.0), Just(0.002), Just(1e30)],
        angle in 0.0..3.0f64,
    ) {
        let keys = [DQuat::IDENTITY, DQuat::from_rotation_z(angle), DQuat::from_rotation_x(angle)];
        let times = [0.0, scale, 2.0 * scale];
        let target = AngularVelocityTarget::new(&[0.0, 2.0 * scale], &[DVec3::new(0.0, 0.0, omega); 2]).unwrap();
        let options = FitOptions { alpha, max_iterations: 30, ..FitOptions::default() };
        if let Ok(fit) = fit_angular_velocity(&keys, &times, &[true, false, true], &target, &options) {
            prop_assert!(fit.fit_error.is_finite() && fit.fragment_errors.iter().all(|e| e.is_finite()));
            prop_assert!(!fit.converged() || fit.energy.is_finite(), "{fit:?}");
            for t in [0.0, 0.3 * scale, scale, 1.7 * scale] {
                prop_assert!(fit.rotation(t).is_finite() && fit.angular_velocity(t).is_finite());
            }
        }
    }
}

/// A call over the budget is refused before it allocates, saying how much it needed; the
/// same call fits once the budget is raised.
#[test]
fn the_budget_refuses_before_allocating() {
    let keys = vec![Pose::IDENTITY; 1000];
    let old = polyscrew::set_memory_budget(1 << 20);
    let refused = subdivide(&keys, Scheme::Jarek, 6, true);
    let spec = MotionSpec {
        levels: 12,
        ..MotionSpec::default()
    };
    let key_times: Vec<f64> = (0..1000).map(f64::from).collect();
    // 1,000 keys at 12 levels would be 4 million dense poses: sampled in windows, one time
    // needs a window's worth only (about 29 MB), still over this 1 MiB budget.
    let windowed = sample(&keys, &key_times, &[3.5], &spec);
    polyscrew::set_memory_budget(old);
    let err = refused.unwrap_err();
    assert!(
        matches!(
            err,
            Error::Memory {
                bytes: 5_376_000,
                budget: Some(1_048_576),
                ..
            }
        ),
        "{err:?}"
    );
    assert_eq!(
        err.to_string(),
        "subdivided poses would need 5.38 MB, over the memory budget of 1.05 MB: use fewer \
         levels or fewer keys (or raise the budget with set_memory_budget)"
    );
    assert!(
        matches!(
            windowed,
            Err(Error::Memory {
                budget: Some(_),
                ..
            })
        ),
        "{windowed:?}"
    );
    assert_eq!(
        subdivide(&keys, Scheme::Jarek, 6, true).unwrap().len(),
        64_000
    );
    assert_eq!(sample(&keys, &key_times, &[3.5], &spec).unwrap().len(), 1);
}
