//! Property tests of the feature-point motion design (Hofer-Pottmann-Ravani): registration
//! recovers rigid transforms, the designed motion is rigid, invariant under a change of world
//! frame, and interpolating designs keep their keys.

use std::f64::consts::PI;

use glam::DVec3;
use polyscrew::{
    feature_motion, register, CurveScheme, FeatureSpec, InertiaFrame, Parametrization, Pose,
    Stiffness,
};
use proptest::prelude::*;

#[path = "fixtures/poses.rs"]
mod poses;
use poses::{point, pose, rigidity_error};

fn config() -> ProptestConfig {
    ProptestConfig {
        cases: 300,
        ..ProptestConfig::default()
    }
}

/// Keys of a wandering body: each turns by at most 1.2 rad from the previous one (so no
/// scheme averages nearly opposite orientations into a degenerate frame).
fn keys(n: std::ops::Range<usize>) -> impl Strategy<Value = Vec<Pose>> {
    prop::collection::vec(pose(1.2, 2.0), n).prop_map(|steps| {
        let mut current = Pose::IDENTITY;
        steps
            .iter()
            .map(|s| {
                current = s.mul_pose(&current);
                current
            })
            .collect()
    })
}

fn spec() -> impl Strategy<Value = FeatureSpec> {
    (
        0..5usize,
        1..5u32,
        any::<bool>(),
        any::<bool>(),
        prop::collection::vec(0.05..50.0f64, 8),
    )
        .prop_map(|(kind, levels, closed, centripetal, lambda)| {
            let scheme = [
                CurveScheme::FourPoint,
                CurveScheme::BSpline,
                CurveScheme::Jarek,
                CurveScheme::Variational,
                CurveScheme::Variational,
            ][kind];
            let variational = scheme == CurveScheme::Variational;
            FeatureSpec {
                scheme,
                levels,
                closed,
                parametrization: if variational && centripetal {
                    Parametrization::Centripetal
                } else {
                    Parametrization::Uniform
                },
                stiffness: if kind == 4 {
                    Stiffness::keys(lambda)
                } else {
                    Stiffness::default()
                },
            }
        })
}

proptest! {
    #![proptest_config(config())]

    #[test]
    fn registration_recovers_rigid_transforms(
        truth in pose(PI, 10.0),
        cloud in prop::collection::vec(point(2.0), 3..30),
    ) {
        // Skip clouds that are (nearly) collinear: their rotation is barely determined.
        let frame = InertiaFrame::of(&cloud);
        prop_assume!(frame.is_ok_and(|f| f.extents[1] > 0.05 * f.extents[0]));
        let moved: Vec<DVec3> = cloud.iter().map(|p| truth.transform_point3(*p)).collect();
        let got = register(&cloud, &moved, None).unwrap();
        prop_assert!(got.max_abs_diff(&truth) < 1e-9, "{:?} vs {:?}", got, truth);
    }

    #[test]
    fn rigid_frame_invariant_and_interpolating(
        k in keys(4..9),
        spec in spec(),
        a in pose(PI, 20.0),
    ) {
        let n = k.len();
        let mut spec = spec;
        if let Some(l) = spec.stiffness.keys.as_mut() {
            l.truncate(n);
        }
        let base = feature_motion(&k, None, &spec).unwrap();
        for (j, p) in base.iter().enumerate() {
            prop_assert!(rigidity_error(p) < 1e-12, "pose {}", j);
        }
        let ak: Vec<Pose> = k.iter().map(|p| a.mul_pose(p)).collect();
        let moved = feature_motion(&ak, None, &spec).unwrap();
        for j in 0..base.len() {
            let e = moved[j].max_abs_diff(&a.mul_pose(&base[j]));
            prop_assert!(e < 1e-9, "{:?} pose {}: {:e}", spec, j, e);
        }
        if spec.interpolates_keys() {
            for (i, key) in k.iter().enumerate() {
                prop_assert_eq!(base[i << spec.levels], *key);
            }
        }
    }
}
