//! The laws of `polyscrew::denoise` (issue 19): coordinate-free (`denoise(G P H) =
//! G denoise(P) H` for rigid `G`, `H`, automatic strengths included), a screw motion comes
//! back unchanged, held poses are kept exactly, the output is rigid, bad input is an error
//! (never a panic, never NaN), the noise goes down, and the rotation far from the ends does
//! not depend on how long the clip is.

use glam::{DQuat, DVec3};
use polyscrew::denoise::{MAX_DENOISE_BATCH, MAX_DENOISE_POSES};
use polyscrew::{
    denoise, denoise_batch, DenoiseOptions, Error, Expected, Pose, PoseDefect, Strength,
};
use proptest::prelude::*;

/// Deterministic pseudo-random numbers in [-1, 1) (xorshift).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }
    fn vec(&mut self) -> DVec3 {
        DVec3::new(self.next(), self.next(), self.next())
    }
}

/// A smooth tumbling flight (truth) at `times`.
fn flight(times: &[f64], phase: f64) -> Vec<Pose> {
    times
        .iter()
        .map(|t| {
            let t = t / 24.0;
            let rot = DQuat::from_axis_angle(
                DVec3::new((0.4 * t + phase).cos(), (0.3 * t).sin(), 1.0).normalize(),
                1.1 * t + phase,
            );
            let pos = DVec3::new(
                2.0 * (0.5 * t).cos(),
                1.5 * (0.3 * t + phase).sin(),
                0.3 * t,
            );
            Pose::from_rotation_translation(rot, pos)
        })
        .collect()
}

/// `truth` with noise of about `sigma_t` (position) and `sigma_r` radians per axis.
fn noisy(truth: &[Pose], sigma_t: f64, sigma_r: f64, seed: u64) -> Vec<Pose> {
    let mut rng = Rng(seed | 1);
    let s = 3f64.sqrt(); // uniform in [-1, 1) has deviation 1/sqrt(3)
    truth
        .iter()
        .map(|p| {
            let dr = rng.vec() * (s * sigma_r);
            let dt = rng.vec() * (s * sigma_t);
            Pose::from_rotation_translation(
                DQuat::from_scaled_axis(dr) * p.rotation,
                p.translation + dt,
            )
        })
        .collect()
}

fn frames(n: usize) -> Vec<f64> {
    (1..=n).map(|i| i as f64).collect()
}

/// Uneven times: frames with a jitter of up to `jitter`.
fn uneven(n: usize, seed: u64, jitter: f64) -> Vec<f64> {
    let mut rng = Rng(seed | 1);
    (0..n).map(|i| i as f64 + jitter * rng.next()).collect()
}

fn max_diff(a: &[Pose], b: &[Pose]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(p, q)| p.max_abs_diff(q))
        .fold(0.0, f64::max)
}

fn rms_error(a: &[Pose], truth: &[Pose]) -> (f64, f64) {
    let n = a.len() as f64;
    let loc = a
        .iter()
        .zip(truth)
        .map(|(p, q)| (p.translation - q.translation).length_squared())
        .sum::<f64>();
    let rot = a
        .iter()
        .zip(truth)
        .map(|(p, q)| {
            let d = (p.rotation * q.rotation.conjugate())
                .to_scaled_axis()
                .length();
            d * d
        })
        .sum::<f64>();
    ((loc / n).sqrt(), (rot / n).sqrt())
}

fn rigid(axis: [f64; 3], angle: f64, t: [f64; 3]) -> Pose {
    let axis = DVec3::from_array(axis).try_normalize().unwrap_or(DVec3::Z);
    Pose::from_rotation_translation(DQuat::from_axis_angle(axis, angle), DVec3::from_array(t))
}

fn options(strength: Strength, order: usize) -> DenoiseOptions {
    DenoiseOptions {
        strength,
        order,
        kinks: true,
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// denoise(G P H) = G denoise(P) H to 1e-9, with automatic and given strengths, both
    /// orders, even and uneven times, for any rigid G (world) and H (body frame).
    #[test]
    fn coordinate_free(
        ga in prop::array::uniform3(-1.0f64..1.0), gang in -3.1f64..3.1, gt in prop::array::uniform3(-10.0f64..10.0),
        ha in prop::array::uniform3(-1.0f64..1.0), hang in -3.1f64..3.1, ht in prop::array::uniform3(-2.0f64..2.0),
        seed in 1u64..1_000_000, order in 2usize..=3, auto in any::<bool>(), even in any::<bool>(),
    ) {
        let n = 150;
        let times = if even { frames(n) } else { uneven(n, seed, 0.3) };
        let poses = noisy(&flight(&times, seed as f64 * 1e-3), 0.02, 0.5f64.to_radians(), seed);
        let (g, h) = (rigid(ga, gang, gt), rigid(ha, hang, ht));
        let moved: Vec<Pose> = poses.iter().map(|p| g.mul_pose(&p.mul_pose(&h))).collect();
        let strength = if auto { Strength::Auto } else { Strength::Fixed { rotation: 4.0, translation: 6.0 } };
        let o = options(strength, order);
        let a = denoise(&poses, &times, None, &o).unwrap();
        let b = denoise(&moved, &times, None, &o).unwrap();
        let back: Vec<Pose> = a.poses.iter().map(|p| g.mul_pose(&p.mul_pose(&h))).collect();
        let diff = max_diff(&back, &b.poses);
        prop_assert!(diff < 1e-9, "max difference {diff:e}; strengths {} {} vs {} {}",
            a.rotation_strength, a.translation_strength, b.rotation_strength, b.translation_strength);
        prop_assert_eq!(a.rotation_strength, b.rotation_strength);
        prop_assert!((a.translation_strength - b.translation_strength).abs() <= 1e-12 * a.translation_strength);
        // The pivot is a body point: H^-1 c.
        let c = h.inverse().transform_point3(a.pivot);
        prop_assert!((c - b.pivot).length() < 1e-7, "pivot {} vs {}", c, b.pivot);
    }

    /// A screw motion (constant twist: rotation about a fixed axis with a slide along it,
    /// including pure rotations and translations) sampled at uneven times comes back
    /// unchanged to 1e-6, at automatic strength.
    #[test]
    fn a_screw_motion_is_unchanged(
        axis in prop::array::uniform3(-1.0f64..1.0), point in prop::array::uniform3(-3.0f64..3.0),
        rate in prop_oneof![Just(0.0), -0.4f64..0.4], slide in -0.2f64..0.2,
        start in prop::array::uniform3(-1.0f64..1.0), seed in 1u64..1000, order in 2usize..=3,
    ) {
        let n = 120;
        let times = uneven(n, seed, 0.3);
        let axis = DVec3::from_array(axis).try_normalize().unwrap_or(DVec3::X);
        let p = DVec3::from_array(point);
        let x0 = rigid(start, 0.7, [0.5, -0.3, 1.0]);
        let poses: Vec<Pose> = times
            .iter()
            .map(|t| {
                // M(t): rotation by rate t about the line through p along axis, plus a slide.
                let rot = DQuat::from_axis_angle(axis, rate * t);
                let m = Pose::from_rotation_translation(rot, p - rot * p + axis * (slide * t));
                m.mul_pose(&x0)
            })
            .collect();
        let d = denoise(&poses, &times, None, &options(Strength::Auto, order)).unwrap();
        let diff = max_diff(&d.poses, &poses);
        prop_assert!(diff < 1e-6, "max difference {diff:e}, strengths {} {}", d.rotation_strength, d.translation_strength);
    }
}

#[test]
fn held_poses_are_kept_exactly_and_the_output_is_rigid() {
    let times = frames(200);
    let truth = flight(&times, 0.3);
    let poses = noisy(&truth, 0.02, 0.01, 7);
    let held: Vec<bool> = (0..200)
        .map(|i| i % 17 == 3 || i == 0 || i == 199)
        .collect();
    for order in [2, 3] {
        for strength in [
            Strength::Auto,
            Strength::Fixed {
                rotation: 8.0,
                translation: 8.0,
            },
        ] {
            let d = denoise(&poses, &times, Some(&held), &options(strength, order)).unwrap();
            for (i, (p, q)) in d.poses.iter().zip(&poses).enumerate() {
                if held[i] {
                    assert_eq!(p, q, "held pose {i} moved");
                } else {
                    assert!(p.max_abs_diff(q) > 0.0, "pose {i} was not smoothed");
                }
                assert!(
                    (p.rotation.length() - 1.0).abs() < 1e-14,
                    "pose {i} not unit"
                );
                Pose::from_rows(&p.to_rows(), i).expect("rigid");
            }
            assert!(d.converged);
        }
    }
}

#[test]
fn the_noise_goes_down_and_is_estimated() {
    let times = frames(400);
    let truth = flight(&times, 1.0);
    let (st, sr) = (0.02, 0.5f64.to_radians());
    let poses = noisy(&truth, st, sr, 99);
    let (loc0, rot0) = rms_error(&poses, &truth);
    let d = denoise(&poses, &times, None, &DenoiseOptions::default()).unwrap();
    let (loc, rot) = rms_error(&d.poses, &truth);
    assert!(
        loc < 0.4 * loc0 && rot < 0.4 * rot0,
        "location {loc} vs {loc0}, rotation {rot} vs {rot0}"
    );
    // The estimated noise per axis is the one added (within 20 per cent; the pivot's
    // position noise also carries the rotation noise times its distance from the origin).
    assert!(
        (d.rotation_noise / sr - 1.0).abs() < 0.2,
        "rotation noise {} vs {sr}",
        d.rotation_noise
    );
    assert!(
        (d.translation_noise / st - 1.0).abs() < 0.2,
        "translation noise {} vs {st}",
        d.translation_noise
    );
    assert!(d.rotation_kinks.is_empty() && d.translation_kinks.is_empty());
}

#[test]
fn a_hard_stop_stays_sharp() {
    // Constant velocity and spin until sample 100, then at rest.
    let times = frames(200);
    let truth: Vec<Pose> = times
        .iter()
        .map(|t| {
            let s = t.min(100.0);
            Pose::from_rotation_translation(
                DQuat::from_rotation_y(0.05 * s),
                DVec3::new(0.1 * s, 0.0, 1.0),
            )
        })
        .collect();
    let poses = noisy(&truth, 0.01, 0.005, 5);
    let sharp = denoise(&poses, &times, None, &DenoiseOptions::default()).unwrap();
    let round = denoise(
        &poses,
        &times,
        None,
        &DenoiseOptions {
            kinks: false,
            ..Default::default()
        },
    )
    .unwrap();
    let at_stop =
        |d: &polyscrew::Denoised| (d.poses[99].translation - truth[99].translation).length();
    assert_eq!(sharp.translation_kinks, vec![99]);
    assert_eq!(sharp.rotation_kinks, vec![99]);
    assert!(
        at_stop(&sharp) < 0.5 * at_stop(&round),
        "{} vs {}",
        at_stop(&sharp),
        at_stop(&round)
    );
    let (loc_sharp, rot_sharp) = rms_error(&sharp.poses, &truth);
    let (loc_round, rot_round) = rms_error(&round.poses, &truth);
    assert!(
        loc_sharp < 0.6 * loc_round && rot_sharp < 0.6 * rot_round,
        "{loc_sharp} {rot_sharp} vs {loc_round} {rot_round}"
    );
}

#[test]
fn the_rotation_far_from_the_ends_does_not_depend_on_the_clip_length() {
    let times = frames(600);
    let poses = noisy(&flight(&times, 0.2), 0.02, 0.01, 3);
    let o = DenoiseOptions {
        strength: Strength::Fixed {
            rotation: 4.0,
            translation: 4.0,
        },
        kinks: false,
        ..Default::default()
    };
    let long = denoise(&poses, &times, None, &o).unwrap();
    let short = denoise(&poses[..400], &times[..400], None, &o).unwrap();
    for i in 100..300 {
        let d = (long.poses[i].rotation * short.poses[i].rotation.conjugate())
            .to_scaled_axis()
            .length();
        assert!(d < 1e-8, "frame {i}: {d:e}");
    }
}

#[test]
fn a_batch_equals_single_clips() {
    let times = frames(120);
    let clips: Vec<Vec<Pose>> = (0..5)
        .map(|b| noisy(&flight(&times, b as f64), 0.02, 0.01, b + 11))
        .collect();
    let flat: Vec<Pose> = clips.concat();
    for threads in [1, 3] {
        let batch =
            denoise_batch(&flat, 5, &times, None, &DenoiseOptions::default(), threads).unwrap();
        for (b, r) in batch.iter().enumerate() {
            let single = denoise(&clips[b], &times, None, &DenoiseOptions::default()).unwrap();
            assert_eq!(r.as_ref().unwrap(), &single, "body {b}, {threads} threads");
        }
    }
}

#[test]
fn bad_input_is_an_error() {
    let times = frames(50);
    let poses = noisy(&flight(&times, 0.0), 0.01, 0.01, 1);
    let o = DenoiseOptions::default();
    assert!(matches!(
        denoise(&poses[..3], &times[..3], None, &o),
        Err(Error::TooFew { got: 3, need: 4 })
    ));
    assert!(matches!(
        denoise(&poses, &times[..49], None, &o),
        Err(Error::LengthMismatch { what: "times", .. })
    ));
    let mut t = times.clone();
    t[20] = t[19];
    assert!(matches!(
        denoise(&poses, &t, None, &o),
        Err(Error::KeyTimes { index: 20 })
    ));
    t[20] = f64::NAN;
    assert!(matches!(
        denoise(&poses, &t, None, &o),
        Err(Error::KeyTimes { index: 20 })
    ));
    let mut p = poses.clone();
    p[7].translation.y = f64::INFINITY;
    assert!(matches!(
        denoise(&p, &times, None, &o),
        Err(Error::BadPose {
            index: 7,
            defect: PoseDefect::NotFinite
        })
    ));
    p = poses.clone();
    p[8].rotation = DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0);
    assert!(matches!(
        denoise(&p, &times, None, &o),
        Err(Error::BadPose { index: 8, .. })
    ));
    assert!(matches!(
        denoise(&poses, &times, Some(&[true; 3]), &o),
        Err(Error::LengthMismatch { what: "held", .. })
    ));
    for order in [0, 1, 4] {
        let bad = DenoiseOptions { order, ..o };
        assert!(matches!(
            denoise(&poses, &times, None, &bad),
            Err(Error::Value { what: "order", value, expected: Expected::OneOf(_), .. })
                if value == order as f64
        ));
    }
    for s in [-1.0, f64::NAN, f64::INFINITY] {
        let bad = DenoiseOptions {
            strength: Strength::Fixed {
                rotation: 1.0,
                translation: s,
            },
            ..o
        };
        assert!(matches!(
            denoise(&poses, &times, None, &bad),
            Err(Error::Value {
                what: "strength",
                expected: Expected::NonNegative(_),
                ..
            })
        ));
    }
    // Sizes are refused before anything is allocated for them.
    let long = vec![0.0; MAX_DENOISE_POSES + 1];
    assert!(matches!(
        denoise_batch(&[], 1, &long, None, &o, 1),
        Err(Error::Limit { count, limit: MAX_DENOISE_POSES, .. }) if count == MAX_DENOISE_POSES + 1
    ));
    assert!(matches!(
        denoise_batch(&[], usize::MAX / 2, &times, None, &o, 1),
        Err(Error::Limit {
            limit: MAX_DENOISE_BATCH,
            ..
        })
    ));
    assert!(matches!(
        denoise_batch(&[], MAX_DENOISE_BATCH / 50 + 1, &times, None, &o, 1),
        Err(Error::Limit {
            limit: MAX_DENOISE_BATCH,
            ..
        })
    ));
    assert!(matches!(
        denoise_batch(&poses, 2, &times, None, &o, 1),
        Err(Error::LengthMismatch { what: "poses", .. })
    ));
    // No bodies: the times and options are checked all the same, and the result is empty.
    let mut nan = times.clone();
    nan[3] = f64::NAN;
    assert!(matches!(
        denoise_batch(&[], 0, &nan, None, &o, 1),
        Err(Error::KeyTimes { index: 3 })
    ));
    assert!(matches!(
        denoise_batch(&[], 0, &times, None, &DenoiseOptions { order: 5, ..o }, 1),
        Err(Error::Value { what: "order", .. })
    ));
    assert!(denoise_batch(&[], 0, &times, None, &o, 1)
        .unwrap()
        .is_empty());
    // Values so large that the computation overflows: an error, not NaN.
    let huge: Vec<Pose> = poses
        .iter()
        .map(|p| Pose::from_rotation_translation(p.rotation, p.translation * 1e306))
        .collect();
    assert!(matches!(
        denoise(&huge, &times, None, &o),
        Err(Error::Overflow { what: "poses", .. })
    ));
    // Times in any unit (issue 28: these were refused, the work is now in a normalised
    // time): spaced 1e-120 apart, the result of times spaced 1 apart, strengths scaled.
    let tiny: Vec<f64> = (0..50).map(|i| i as f64 * 1e-120).collect();
    let unit: Vec<f64> = (0..50).map(|i| i as f64).collect();
    let (a, b) = (
        denoise(&poses, &tiny, None, &o).unwrap(),
        denoise(&poses, &unit, None, &o).unwrap(),
    );
    // (a time rounded to the last bit moves the poses by about 1e-7 here, noise 0.01)
    assert!(
        max_diff(&a.poses, &b.poses) < 1e-6,
        "{}",
        max_diff(&a.poses, &b.poses)
    );
    assert!((a.rotation_strength / 1e-120 / b.rotation_strength - 1.0).abs() < 1e-12);
    // Zero strength leaves the part as it is.
    let off = DenoiseOptions {
        strength: Strength::Fixed {
            rotation: 0.0,
            translation: 0.0,
        },
        ..o
    };
    let same = denoise(&poses, &times, None, &off).unwrap();
    assert!(max_diff(&same.poses, &poses) < 1e-14);
}
