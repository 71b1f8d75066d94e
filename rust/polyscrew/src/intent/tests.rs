//! Tests of the intent module against hand-computed cases: rotation conventions written out
//! element by element, holds and pops of known curves, spins of known turn, the pace of a
//! straight-line ease whose Bezier is a smoothstep. Agreement with the add-on's former numpy
//! pipeline and with Blender is in `tests/python/test_intent.py` and `tests/blender`.

use std::f64::consts::{FRAC_PI_2, PI};

use glam::{DMat3, DQuat, DVec3};

use super::*;
use crate::{
    At, Error, EulerOrder, Expected, Extrapolation, FCurve, Interpolation, Key, Pose, RotationMode,
    Scheme,
};

const XYZ: RotationMode = RotationMode::Euler(EulerOrder::Xyz);

/// A curve through `(frame, value)` keys, every key with `interpolation`.
pub(super) fn curve(points: &[(f32, f32)], interpolation: Interpolation) -> FCurve {
    let keys = points
        .iter()
        .map(|&(x, y)| Key::new(x, y).with_interpolation(interpolation))
        .collect();
    FCurve::new(keys, Extrapolation::Constant, None).unwrap()
}

/// A playback of location/rotation/scale curves, everything else at rest (unit scale).
pub(super) fn playback(curves: Vec<(Channel, FCurve)>, mode: RotationMode) -> Playback {
    let mut statics = vec![0.0; 6 + mode.width()];
    statics[3 + mode.width()..].fill(1.0);
    if mode == RotationMode::Quaternion {
        statics[3] = 1.0;
    }
    let (channels, curves): (Vec<_>, Vec<_>) = curves.into_iter().unzip();
    Playback::new(curves, &channels, statics, mode, true).unwrap()
}

fn max_diff(a: &DMat3, b: &DMat3) -> f64 {
    (*a - *b)
        .to_cols_array()
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs()))
}

/// The rotation by `a` about axis `i` (0: X, 1: Y, 2: Z), written out element by element.
fn about(i: usize, a: f64) -> DMat3 {
    let (s, c) = a.sin_cos();
    let rows = match i {
        0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
        1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
        _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
    };
    DMat3::from_cols_array_2d(&rows).transpose()
}

#[test]
fn euler_orders_apply_their_first_letter_first() {
    let e = [0.3, -1.1, 2.5];
    for (name, order) in [
        ("XYZ", [0, 1, 2]),
        ("XZY", [0, 2, 1]),
        ("YXZ", [1, 0, 2]),
        ("YZX", [1, 2, 0]),
        ("ZXY", [2, 0, 1]),
        ("ZYX", [2, 1, 0]),
    ] {
        let mode = RotationMode::from_name(name).unwrap();
        let want = about(order[2], e[order[2]])
            * about(order[1], e[order[1]])
            * about(order[0], e[order[0]]);
        let got = rotation_matrix(mode, &e);
        assert!(max_diff(&got, &want) < 1e-15, "{name}: {got} vs {want}");
    }
}

#[test]
fn quaternions_are_normalised_and_zero_is_the_identity() {
    let q = DQuat::from_axis_angle(DVec3::new(1.0, -2.0, 0.5).normalize(), 2.2);
    let scaled = [3.0 * q.w, 3.0 * q.x, 3.0 * q.y, 3.0 * q.z];
    let m = rotation_matrix(RotationMode::Quaternion, &scaled);
    for v in [DVec3::X, DVec3::Y, DVec3::new(0.3, 0.4, -2.0)] {
        assert!((m * v - q * v).length() < 1e-14, "{v}");
    }
    assert_eq!(
        rotation_matrix(RotationMode::Quaternion, &[0.0; 4]),
        DMat3::IDENTITY
    );
}

#[test]
fn axis_angle_turns_about_the_normalised_axis_and_zero_axis_is_the_identity() {
    let axis = DVec3::new(0.2, 3.0, -1.0);
    for angle in [0.0, 0.7, -2.9, 3.0 * PI + 0.1] {
        let m = rotation_matrix(RotationMode::AxisAngle, &[angle, axis.x, axis.y, axis.z]);
        let want = DMat3::from_axis_angle(axis.normalize(), angle);
        assert!(max_diff(&m, &want) < 1e-14, "angle {angle}");
    }
    assert_eq!(
        rotation_matrix(RotationMode::AxisAngle, &[1.0, 0.0, 0.0, 0.0]),
        DMat3::IDENTITY
    );
}

#[test]
fn rotation_matrices_check_rows_and_values() {
    let got = rotation_matrices(&[0.0, 0.0, FRAC_PI_2, 0.1, 0.2, 0.3], XYZ).unwrap();
    assert_eq!(got.len(), 2);
    assert!((got[0] * DVec3::X - DVec3::Y).length() < 1e-15);
    assert!(matches!(
        rotation_matrices(&[0.0; 4], XYZ),
        Err(Error::LengthMismatch { .. })
    ));
    assert_eq!(
        rotation_matrices(&[0.0, 0.0, 0.0, 0.0, f64::NAN, 0.0], XYZ),
        Err(Error::NotFinite {
            what: "rotation",
            index: 1
        })
    );
}

#[test]
fn channels_take_curves_statics_and_ignore_location_when_not_located() {
    let x = curve(&[(1.0, 0.0), (11.0, 5.0)], Interpolation::Linear);
    let statics = vec![7.0, 8.0, 9.0, 0.1, 0.2, 0.3, 1.0, -1.0, 2.0];
    let channels = [Channel::from_property("location", 1, XYZ).unwrap()];
    let p = Playback::new(vec![x.clone()], &channels, statics.clone(), XYZ, true).unwrap();
    let rows = p.channels(&[6.0, 11.0]).unwrap();
    assert_eq!(rows[..9], [7.0, 2.5, 9.0, 0.1, 0.2, 0.3, 1.0, -1.0, 2.0]);
    assert_eq!(rows[10], 5.0);
    let unlocated = Playback::new(vec![x.clone()], &channels, statics.clone(), XYZ, false).unwrap();
    assert_eq!(
        unlocated.channels(&[6.0]).unwrap()[..4],
        [0.0, 0.0, 0.0, 0.1]
    );
    // errors
    let twice = [channels[0], channels[0]];
    assert!(matches!(
        Playback::new(
            vec![x.clone(), x.clone()],
            &twice,
            statics.clone(),
            XYZ,
            true
        ),
        Err(Error::Conflict {
            what: "channels",
            ..
        })
    ));
    assert!(matches!(
        Playback::new(vec![x.clone()], &channels, vec![0.0; 10], XYZ, true),
        Err(Error::LengthMismatch { .. })
    ));
    assert!(matches!(
        Channel::from_property("rotation_quaternion", 0, XYZ),
        Err(Error::Choice { what: "property", expected, .. }) if expected.contains(&"rotation_euler")
    ));
    assert!(matches!(
        Channel::from_property("scale", 3, XYZ),
        Err(Error::Index {
            what: "scale",
            index: 3,
            len: 3,
            ..
        })
    ));
    assert_eq!(
        Channel::from_property("scale", 2, RotationMode::Quaternion)
            .unwrap()
            .column(RotationMode::Quaternion),
        9
    );
    assert!(matches!(
        p.channels(&[f64::INFINITY]),
        Err(Error::NotFinite {
            what: "time",
            index: 0
        })
    ));
}

#[test]
fn playback_refuses_channels_outside_their_property() {
    // Built directly (not by `Channel::from_property`): location[3] would read as the
    // rotation's x and rotation[usize::MAX] overflows its column.
    let x = curve(&[(1.0, 0.0), (2.0, 1.0)], Interpolation::Linear);
    for (mode, channel) in [
        (XYZ, Channel::Location(3)),
        (XYZ, Channel::Rotation(3)),
        (XYZ, Channel::Rotation(usize::MAX)),
        (XYZ, Channel::Scale(3)),
        (XYZ, Channel::Scale(usize::MAX)),
        (RotationMode::Quaternion, Channel::Rotation(4)),
        (RotationMode::AxisAngle, Channel::Location(usize::MAX)),
    ] {
        let statics = vec![0.0; 6 + mode.width()];
        let got = Playback::new(vec![x.clone()], &[channel], statics, mode, true);
        match got {
            Err(Error::In {
                at:
                    At {
                        item: "channel",
                        index: 0,
                    },
                source,
                ..
            }) => {
                assert!(
                    matches!(*source, Error::Index { index, len, .. } if index >= len as i64),
                    "{source:?}"
                )
            }
            other => panic!("{channel:?} in {mode:?}: {other:?}"),
        }
    }
    // The last index of each property is accepted.
    for (mode, channel) in [
        (XYZ, Channel::Location(2)),
        (XYZ, Channel::Rotation(2)),
        (RotationMode::Quaternion, Channel::Rotation(3)),
        (RotationMode::Quaternion, Channel::Scale(2)),
    ] {
        let statics = vec![1.0; 6 + mode.width()];
        let p = Playback::new(vec![x.clone()], &[channel], statics, mode, true);
        assert!(p.is_ok(), "{channel:?} in {mode:?}: {p:?}");
    }
}

#[test]
fn constant_hold_pops_and_equal_keys_hold_without_pop() {
    // x: 0 -> 4 (moving), 4 held CONSTANT to frame 20 where it pops to 8, then 8 -> 8 held.
    let mut keys = vec![
        Key::new(1.0, 0.0).with_interpolation(Interpolation::Linear),
        Key::new(10.0, 4.0).with_interpolation(Interpolation::Constant),
        Key::new(20.0, 8.0),
        Key::new(30.0, 8.0),
    ];
    keys[3].interpolation = Interpolation::Bezier;
    let x = FCurve::new(keys, Extrapolation::Constant, None).unwrap();
    let p = playback(vec![(Channel::Location(0), x)], XYZ);
    let spans = analyse_spans(&p, &[1.0, 10.0, 20.0, 30.0]).unwrap();
    assert_eq!(spans.held, [false, true, true]);
    assert_eq!(spans.pops, [false, true, false]);
    assert_eq!(spans.turn, [0.0, 0.0, 0.0]);
    assert!(spans.inserted.is_empty());
}

#[test]
fn a_700_degree_spin_turns_almost_twice_round_and_gets_equal_pieces() {
    let turn = 700f64.to_radians();
    let z = curve(&[(1.0, 0.0), (41.0, turn as f32)], Interpolation::Linear);
    let p = playback(vec![(Channel::Rotation(2), z)], XYZ);
    let spans = analyse_spans(&p, &[1.0, 41.0]).unwrap();
    assert!(
        (spans.turn[0] - turn).abs() < 1e-5,
        "turn {}",
        spans.turn[0]
    );
    // ceil(700 / 45) = 16 pieces: 15 frames, evenly spaced along a linear spin.
    assert_eq!(spans.inserted.len(), 15);
    for (j, f) in spans.inserted.iter().enumerate() {
        let want = 1.0 + 40.0 * (j + 1) as f64 / 16.0;
        assert!((f - want).abs() < 1e-4, "frame {j}: {f} vs {want}");
    }
    assert_eq!(spans.held, [false]);
}

#[test]
fn neighbours_of_a_spin_turning_more_than_a_step_are_cut_too() {
    // 350 degrees, then 1 rad (57 degrees > 45), then 0.3 rad (17 degrees).
    let spin = 350f64.to_radians();
    let z = curve(
        &[
            (1.0, 0.0),
            (21.0, spin as f32),
            (31.0, (spin + 1.0) as f32),
            (41.0, (spin + 1.3) as f32),
        ],
        Interpolation::Linear,
    );
    let p = playback(vec![(Channel::Rotation(2), z)], XYZ);
    let spans = analyse_spans(&p, &[1.0, 21.0, 31.0, 41.0]).unwrap();
    assert!((spans.turn[1] - 1.0).abs() < 1e-5 && (spans.turn[2] - 0.3).abs() < 1e-5);
    // 8 pieces in the spin (7 frames), 2 in its neighbour (one frame, half-way), none after.
    assert_eq!(spans.inserted.len(), 8);
    assert!(
        (spans.inserted[7] - 26.0).abs() < 1e-4,
        "{:?}",
        spans.inserted
    );
    assert!(spans.inserted[..7].iter().all(|&f| f > 1.0 && f < 21.0));
}

#[test]
fn axis_angle_spins_and_quaternions_keep_the_short_arc() {
    let turn = 530f64.to_radians();
    let angle = curve(&[(1.0, 0.0), (31.0, turn as f32)], Interpolation::Linear);
    // at rest, about z, unit scale
    let statics = vec![0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0];
    let aa = Playback::new(
        vec![angle],
        &[Channel::Rotation(0)],
        statics,
        RotationMode::AxisAngle,
        true,
    )
    .unwrap();
    let spans = analyse_spans(&aa, &[1.0, 31.0]).unwrap();
    assert!((spans.turn[0] - turn).abs() < 1e-5);
    assert_eq!(spans.inserted.len(), 11, "530 / 45: 12 pieces");
    // A quaternion turning by 170 degrees: counted, nothing added.
    let half = (170f64.to_radians() / 2.0).sin_cos();
    let w = curve(&[(1.0, 1.0), (11.0, half.1 as f32)], Interpolation::Linear);
    let zq = curve(&[(1.0, 0.0), (11.0, half.0 as f32)], Interpolation::Linear);
    let q = playback(
        vec![(Channel::Rotation(0), w), (Channel::Rotation(3), zq)],
        RotationMode::Quaternion,
    );
    let spans = analyse_spans(&q, &[1.0, 11.0]).unwrap();
    assert!(
        (spans.turn[0] - 170f64.to_radians()).abs() < 1e-5,
        "{}",
        spans.turn[0]
    );
    assert!(spans.inserted.is_empty());
}

#[test]
fn span_analysis_refuses_bad_frames() {
    let p = playback(vec![], XYZ);
    assert_eq!(
        analyse_spans(&p, &[1.0]),
        Err(Error::TooFew { got: 1, need: 2 })
    );
    assert_eq!(
        analyse_spans(&p, &[1.0, 1.0]),
        Err(Error::KeyTimes { index: 1 })
    );
    let spans = analyse_spans(&p, &[1.0, 2.0]).unwrap();
    assert_eq!((spans.held, spans.pops), (vec![true], vec![false]));
}

#[test]
fn travel_of_turns_and_slides() {
    let a = Pose::IDENTITY;
    let slide = Pose::from_translation(DVec3::new(3.0, 4.0, 0.0));
    assert!((travel(&a, &slide, 2.0) - 5.0).abs() < 1e-15);
    for angle in [0.1, 1.0, 3.0] {
        let turn = Pose::from_rotation_translation(DQuat::from_rotation_y(angle), DVec3::ZERO);
        let want = 2.0 * (8.0f64 / 3.0).sqrt() * (angle / 2.0).sin();
        assert!((travel(&a, &turn, 2.0) - want).abs() < 1e-14, "{angle}");
    }
}

/// Two keys on a straight line along x, 0 at frame 1 and 10 at frame 21, whose Bezier handles
/// sit at a third of the span, flat: `x(u) = 1 + 20 u`, `value(u) = 10 (3 u^2 - 2 u^3)`.
fn smoothstep_playback() -> Playback {
    let third = 20.0 / 3.0;
    let keys = vec![
        Key::new(1.0, 0.0).with_handles([1.0 - third, 0.0], [1.0 + third, 0.0]),
        Key::new(21.0, 10.0).with_handles([21.0 - third, 10.0], [21.0 + third, 10.0]),
    ];
    let x = FCurve::new(keys, Extrapolation::Constant, None).unwrap();
    playback(vec![(Channel::Location(0), x)], XYZ)
}

/// [`smoothstep_playback`] and the 4-point motion (4 levels) through its two key poses: what
/// Keys timing is measured on ([`ease_timing`]).
fn straight_ease() -> (Playback, Vec<Pose>) {
    let keys = [
        Pose::IDENTITY,
        Pose::from_translation(DVec3::new(10.0, 0.0, 0.0)),
    ];
    let smooth = screw_pace_poses(&keys, Scheme::FourPoint, 4, false).unwrap();
    (smoothstep_playback(), smooth)
}

/// Keys timing of the keys of [`straight_ease`] (frames 1 and 21), following `playback`.
fn ease_timing(playback: &Playback) -> KeysTiming<'_> {
    KeysTiming {
        key_frames: &[1.0, 21.0],
        period: None,
        size: 1.0,
        playback: Some(playback),
    }
}

#[test]
fn keys_timing_of_a_straight_ease_is_the_smoothstep() {
    let (p, smooth) = straight_ease();
    let timing = ease_timing(&p);
    let frames: Vec<f64> = (0..=40).map(|i| 1.0 + 0.5 * i as f64).collect();
    let u = keys_parameters(&timing, &frames, &smooth).unwrap();
    for (f, u) in frames.iter().zip(&u) {
        let tau = (f - 1.0) / 20.0;
        let want = 3.0 * tau * tau - 2.0 * tau * tau * tau;
        // float32 curve values: a few 1e-7 of the span
        assert!((u - want).abs() < 2e-6, "frame {f}: {u} vs {want}");
    }
    // Without playback, the fraction of time.
    let plain = KeysTiming {
        playback: None,
        ..timing
    };
    let u = keys_parameters(&plain, &frames, &smooth).unwrap();
    for (f, u) in frames.iter().zip(&u) {
        assert!((u - (f - 1.0) / 20.0).abs() < 1e-12, "frame {f}: {u}");
    }
    // Outside the keys: s + tau, extrapolated.
    let u = keys_parameters(&timing, &[-9.0, 41.0], &smooth).unwrap();
    assert_eq!(u, [-0.5, 2.0]);
}

#[test]
fn keys_timing_of_a_long_bake_interpolates_a_fine_grid() {
    // 20,000 frames in one span: the playback is measured on DENSE_PACE_SAMPLES steps, and
    // the frames between them still follow the smoothstep closely.
    let (p, smooth) = straight_ease();
    let timing = ease_timing(&p);
    let frames: Vec<f64> = (0..=20_000).map(|i| 1.0 + 0.001 * i as f64).collect();
    let u = keys_parameters(&timing, &frames, &smooth).unwrap();
    let worst = frames
        .iter()
        .zip(&u)
        .map(|(f, u)| {
            let tau = (f - 1.0) / 20.0;
            (u - (3.0 * tau * tau - 2.0 * tau * tau * tau)).abs()
        })
        .fold(0.0, f64::max);
    assert!(worst < 2e-5, "{worst}");
}

#[test]
fn keys_timing_follows_the_smoothed_motions_own_pace() {
    // The playback goes at constant speed; the smoothed motion, its keys unevenly spread
    // (4-point through 0, 1, 9, 10 at parameters 0..3), is slow in its first and last span:
    // the parameter at a frame is where it has travelled the fraction of time.
    let x = curve(
        &[(0.0, 0.0), (10.0, 1.0), (20.0, 9.0), (30.0, 10.0)],
        Interpolation::Linear,
    );
    let p = playback(vec![(Channel::Location(0), x)], XYZ);
    let keys: Vec<Pose> = [0.0, 1.0, 9.0, 10.0]
        .iter()
        .map(|&v| Pose::from_translation(DVec3::new(v, 0.0, 0.0)))
        .collect();
    let smooth = screw_pace_poses(&keys, Scheme::FourPoint, 5, false).unwrap();
    let timing = KeysTiming {
        key_frames: &[0.0, 10.0, 20.0, 30.0],
        period: None,
        size: 1.0,
        playback: Some(&p),
    };
    let frames: Vec<f64> = (0..=30).map(|i| i as f64).collect();
    let u = keys_parameters(&timing, &frames, &smooth).unwrap();
    let motion = crate::Motion::new(
        &keys,
        &[0.0, 1.0, 2.0, 3.0],
        &crate::MotionSpec {
            scheme: Scheme::FourPoint,
            levels: 5,
            closed: false,
            period: None,
            timing: crate::Timing::Linear,
        },
    )
    .unwrap();
    // The smoothed motion's travel from the span's start to u, over the span's, by dense
    // sampling (1,000 steps per span).
    let along = |s: usize, to: f64| -> f64 {
        let n = 1000;
        let us: Vec<f64> = (0..=n)
            .map(|i| s as f64 + (to - s as f64) * i as f64 / n as f64)
            .collect();
        let p = motion.sample(&us).unwrap();
        p.windows(2).map(|w| travel(&w[0], &w[1], 1.0)).sum()
    };
    for (i, (f, u)) in frames.iter().zip(&u).enumerate() {
        let s = (i / 10).min(2);
        let tau = (f - 10.0 * s as f64) / 10.0;
        let fraction = along(s, *u) / along(s, s as f64 + 1.0);
        assert!(
            (fraction - tau).abs() < 0.01,
            "frame {f}: u {u}, travel fraction {fraction}, time {tau}"
        );
    }
}

#[test]
fn keys_timing_checks_the_period_as_the_time_map_does() {
    let keys = [
        Pose::IDENTITY,
        Pose::from_translation(DVec3::new(4.0, 0.0, 0.0)),
    ];
    let smooth = screw_pace_poses(&keys, Scheme::FourPoint, 3, true).unwrap();
    // (key frames, period): the cycle's end beyond the time range; the end after the last
    // key but closer to it than MIN_KEY_SPACING; a period within the keys' span.
    for (key_frames, period) in [
        ([0.0, 1e300], 1.5e300),
        ([-1e-300, 0.0], 1.5e-300),
        ([1.0, 11.0], 10.0),
    ] {
        let timing = KeysTiming {
            key_frames: &key_frames,
            period: Some(period),
            size: 1.0,
            playback: None,
        };
        let got = keys_parameters(&timing, &[key_frames[0]], &smooth);
        assert!(
            matches!(got, Err(Error::Period { .. })),
            "{key_frames:?} period {period}: {got:?}"
        );
        let map = crate::TimeMap::new(&key_frames, true, Some(period), crate::Timing::Linear);
        assert!(
            matches!(map, Err(Error::Period { .. })),
            "{key_frames:?} period {period}: {map:?}"
        );
    }
    // Both accept the same period.
    let ok = KeysTiming {
        key_frames: &[1.0, 11.0],
        period: Some(20.0),
        size: 1.0,
        playback: None,
    };
    assert!(keys_parameters(&ok, &[1.0, 21.0], &smooth).is_ok());
    assert!(crate::TimeMap::new(&[1.0, 11.0], true, Some(20.0), crate::Timing::Linear).is_ok());
}

#[test]
fn keys_timing_of_a_cycle_and_its_errors() {
    let x = curve(
        &[(1.0, 0.0), (11.0, 4.0), (21.0, 0.0)],
        Interpolation::Linear,
    );
    let p = playback(vec![(Channel::Location(0), x)], XYZ);
    let keys = [
        Pose::IDENTITY,
        Pose::from_translation(DVec3::new(4.0, 0.0, 0.0)),
    ];
    let smooth = screw_pace_poses(&keys, Scheme::FourPoint, 3, true).unwrap();
    assert_eq!(smooth.len(), 2 * (PACE_SAMPLES + 1));
    let timing = KeysTiming {
        key_frames: &[1.0, 11.0],
        period: Some(20.0),
        size: 1.0,
        playback: Some(&p),
    };
    let u = keys_parameters(&timing, &[1.0, 6.0, 11.0, 16.0, 21.0], &smooth).unwrap();
    let want = [0.0, 0.5, 1.0, 1.5, 2.0];
    for (u, w) in u.iter().zip(want) {
        assert!((u - w).abs() < 1e-6, "{u} vs {w}");
    }
    let bad = |t: KeysTiming<'_>, frames: &[f64], smooth: &[Pose]| {
        keys_parameters(&t, frames, smooth).unwrap_err()
    };
    assert!(matches!(
        bad(
            KeysTiming {
                period: Some(5.0),
                ..timing
            },
            &[1.0],
            &smooth
        ),
        Error::Period { .. }
    ));
    assert!(matches!(
        bad(
            KeysTiming {
                size: 0.0,
                ..timing
            },
            &[1.0],
            &smooth
        ),
        Error::Value {
            what: "size",
            expected: Expected::PositiveUpTo(_),
            ..
        }
    ));
    assert!(matches!(
        bad(
            KeysTiming {
                key_frames: &[1.0],
                ..timing
            },
            &[1.0],
            &smooth
        ),
        Error::TooFew { .. }
    ));
    assert!(matches!(
        bad(
            KeysTiming {
                key_frames: &[3.0, 1.0],
                ..timing
            },
            &[1.0],
            &smooth
        ),
        Error::KeyTimes { .. }
    ));
    assert!(matches!(
        bad(timing, &[f64::NAN], &smooth),
        Error::NotFinite {
            what: "frame",
            index: 0
        }
    ));
    assert!(matches!(
        bad(timing, &[1.0], &smooth[1..]),
        Error::LengthMismatch { .. }
    ));
    assert_eq!(pace_parameters(1).unwrap()[PACE_SAMPLES], 1.0);
}

#[test]
fn sizes_are_checked_against_the_budget_before_allocating() {
    let p = playback(vec![], XYZ);
    let over = |e: Error| {
        matches!(
            e,
            Error::Memory {
                budget: Some(_),
                ..
            }
        )
    };
    assert!(over(pace_parameters(usize::MAX / 4).unwrap_err()));
    assert!(over(
        limits::check_footprint(usize::MAX, "x", "y").unwrap_err()
    ));
    assert!(limits::check_footprint(1024, "x", "y").is_ok());
    // a frame list as long as memory: refused before its channel rows are allocated
    let budget = crate::memory::memory_budget();
    let frames = vec![1.0; budget / (8 * p.width()) + 1];
    assert!(over(p.channels(&frames).unwrap_err()));
}

#[test]
fn span_analysis_refuses_more_samples_than_its_cap_before_taking_any() {
    // 513 spans of one frame each, the Z angle turning 1,000 radians per frame: 4,096 samples
    // each, 2,101,248 in all, over MAX_ANALYSIS_SAMPLES; 512 of them are exactly at it.
    let spin = |k: usize| {
        let points: Vec<(f32, f32)> = (0..k).map(|i| (i as f32, 1000.0 * i as f32)).collect();
        let p = playback(
            vec![(Channel::Rotation(2), curve(&points, Interpolation::Linear))],
            XYZ,
        );
        let frames: Vec<f64> = (0..k).map(|i| i as f64).collect();
        (p, frames)
    };
    let (p, frames) = spin(514);
    let err = analyse_spans(&p, &frames).unwrap_err();
    assert!(
        matches!(
            err,
            Error::LimitOver {
                parts: 513,
                count: 2101248,
                limit: 2097152,
                ..
            }
        ),
        "{err}"
    );
    assert!(
        err.to_string().starts_with(
            "frames: the 513 key spans would take 2101248 samples of the playback, over the \
             limit of 2097152 in one call: "
        ),
        "{err}"
    );
    let (p, frames) = spin(513);
    let spans = analyse_spans(&p, &frames).unwrap();
    assert_eq!(spans.turn.len(), 512);
    assert!(spans.held.iter().all(|h| !h), "{:?}", &spans.held[..4]);
}
