//! Tests of the departure measured from the rows timing "Keys" has played
//! ([`super::keys_parameters_played`], [`super::measure_departure`]): the same figures as the
//! separate [`super::departure`], bit for bit, with each frame played once.

use glam::{DQuat, DVec3};

use super::tests::playback;
use super::*;
use crate::{EulerOrder, Extrapolation, FCurve, Key, Pose, RotationMode, Scheme};

const XYZ: RotationMode = RotationMode::Euler(EulerOrder::Xyz);

/// A Bezier curve through `(frame, value)` keys with flat handles a third of the way to the
/// neighbouring keys (an ease in and out on every span).
fn eased(points: &[(f32, f32)]) -> FCurve {
    let keys = points
        .iter()
        .enumerate()
        .map(|(i, &(x, y))| {
            let before = if i > 0 { points[i - 1].0 } else { x - 3.0 };
            let after = points.get(i + 1).map_or(x + 3.0, |p| p.0);
            Key::new(x, y).with_handles([x - (x - before) / 3.0, y], [x + (after - x) / 3.0, y])
        })
        .collect();
    FCurve::new(keys, Extrapolation::Constant, None).unwrap()
}

const KEY_FRAMES: [f64; 4] = [1.0, 7.0, 20.5, 31.0];

/// Location and XYZ Euler keyed at [`KEY_FRAMES`] (one subframe), eased; and its key poses.
fn keyed() -> (Playback, Vec<Pose>) {
    let values: [[f32; 6]; 4] = [
        [0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        [2.0, 1.0, -0.5, 0.4, -0.2, 1.2],
        [3.5, -1.0, 0.5, 0.9, 0.3, 2.6],
        [6.0, 0.5, 1.0, 1.5, 0.1, 3.9],
    ];
    let channel = |c: usize| {
        if c < 3 {
            Channel::Location(c)
        } else {
            Channel::Rotation(c - 3)
        }
    };
    let curves = (0..6)
        .map(|c| {
            let points: Vec<(f32, f32)> = KEY_FRAMES
                .iter()
                .zip(&values)
                .map(|(&f, v)| (f as f32, v[c]))
                .collect();
            (channel(c), eased(&points))
        })
        .collect();
    let poses = values
        .iter()
        .map(|v| {
            let r = EulerOrder::Xyz.to_mat3(DVec3::new(v[3] as f64, v[4] as f64, v[5] as f64));
            Pose::from_rotation_translation(
                DQuat::from_mat3(&r),
                DVec3::new(v[0] as f64, v[1] as f64, v[2] as f64),
            )
        })
        .collect();
    (playback(curves, XYZ), poses)
}

fn timing(p: &Playback) -> KeysTiming<'_> {
    KeysTiming {
        key_frames: &KEY_FRAMES,
        period: None,
        size: 1.5,
        playback: Some(p),
    }
}

/// The output frames: every quarter frame from before the first key to after the last.
fn frames() -> Vec<f64> {
    (0..=136).map(|i| -1.0 + 0.25 * i as f64).collect()
}

#[test]
fn played_rows_are_the_playback_rows_bit_for_bit() {
    let (p, poses) = keyed();
    let smooth = screw_pace_poses(&poses, Scheme::FourPoint, 4, false).unwrap();
    let frames = frames();
    let (u, rows) = keys_parameters_played(&timing(&p), &frames, &smooth).unwrap();
    // the parameters are those of keys_parameters
    assert_eq!(u, keys_parameters(&timing(&p), &frames, &smooth).unwrap());
    let width = 3 + XYZ.width();
    assert_eq!(rows.len(), frames.len() * width);
    let want = p.channels(&frames).unwrap();
    let mut kept = 0;
    for (i, &f) in frames.iter().enumerate() {
        let row = &rows[i * width..(i + 1) * width];
        let inside = (KEY_FRAMES[0]..=KEY_FRAMES[3]).contains(&f);
        if row[0].is_nan() {
            assert!(!inside, "frame {f} inside the keys was played but not kept");
            continue;
        }
        assert!(
            inside,
            "frame {f} outside the keys is not played by the pace"
        );
        // bit for bit the row the playback gives at that frame
        assert_eq!(
            row,
            &want[i * p.width()..i * p.width() + width],
            "frame {f}"
        );
        kept += 1;
    }
    // every frame from the first key to the last, the keys (one a subframe) included
    assert_eq!(kept, 121);
}

#[test]
fn a_long_span_keeps_no_rows_inside_it() {
    // more output frames in a span than DENSE_PACE_SAMPLES: the pace plays its own grid
    let (p, poses) = keyed();
    let smooth = screw_pace_poses(&poses, Scheme::FourPoint, 4, false).unwrap();
    let frames: Vec<f64> = (0..=3000).map(|i| 1.0 + 0.01 * i as f64).collect();
    let (_, rows) = keys_parameters_played(&timing(&p), &frames, &smooth).unwrap();
    let width = 3 + XYZ.width();
    let kept: Vec<f64> = frames
        .iter()
        .enumerate()
        .filter(|&(i, _)| !rows[i * width].is_nan())
        .map(|(_, &f)| f)
        .collect();
    // the keys; the span 20.5..31 (1,050 frames) and 7..20.5 (1,350) kept nothing inside
    assert!(
        kept.contains(&1.0) && kept.contains(&7.0) && kept.contains(&20.5) && kept.contains(&31.0)
    );
    assert!(
        kept.iter().all(|&f| f <= 7.0 || KEY_FRAMES.contains(&f)),
        "{kept:?}"
    );
}

/// A result off the playback: the played channels, turned and moved a little more with time.
fn result_channels(p: &Playback, frames: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let rows = p.channels(frames).unwrap();
    let (mut location, mut rotation) = (Vec::new(), Vec::new());
    for (i, row) in rows.chunks_exact(p.width()).enumerate() {
        let s = (0.37 * i as f64).sin();
        location.extend([row[0] + 0.04 * s, row[1], row[2] - 0.02 * s]);
        rotation.extend([row[3], row[4] + 0.09 * s, row[5]]);
    }
    (location, rotation)
}

const LIMITS: DepartureLimits = DepartureLimits {
    degrees: 5.0,
    distance: 0.03,
};

#[test]
fn the_combined_measure_equals_the_separate_departure_bit_for_bit() {
    let (p, poses) = keyed();
    let smooth = screw_pace_poses(&poses, Scheme::FourPoint, 4, false).unwrap();
    for frames in [
        frames(),
        (0..=3000).map(|i| 1.0 + 0.01 * i as f64).collect(),
    ] {
        let (location, rotation) = result_channels(&p, &frames);
        let (_, rows) = keys_parameters_played(&timing(&p), &frames, &smooth).unwrap();
        for spans in [None, Some((&KEY_FRAMES[..], 64))] {
            let before = p.rows_evaluated();
            let combined = measure_departure(
                &p,
                &frames,
                &location,
                &rotation,
                Some(&rows),
                spans,
                LIMITS,
            )
            .unwrap();
            let played_again = p.rows_evaluated() - before;
            let alone =
                measure_departure(&p, &frames, &location, &rotation, None, spans, LIMITS).unwrap();
            assert_eq!(combined, alone);
            // against the per-frame departure at the measured frames
            let measured = spans
                .map(|(k, most)| measured_frames(&frames, k, most).unwrap())
                .unwrap_or(None)
                .unwrap_or_else(|| (0..frames.len()).collect());
            let pick = |values: &[f64], per: usize| -> Vec<f64> {
                measured
                    .iter()
                    .flat_map(|&i| values[per * i..per * (i + 1)].to_vec())
                    .collect()
            };
            let every = departure(
                &p,
                &pick(&frames, 1),
                &pick(&location, 3),
                &pick(&rotation, 3),
            )
            .unwrap();
            let degrees = every
                .angle
                .iter()
                .map(|a| a.to_degrees())
                .fold(0.0, f64::max);
            let distance = every.distance.iter().copied().fold(0.0, f64::max);
            assert_eq!((combined.degrees, combined.distance), (degrees, distance));
            let over: Vec<bool> = every
                .angle
                .iter()
                .zip(&every.distance)
                .map(|(a, d)| a.to_degrees() > LIMITS.degrees || *d > LIMITS.distance)
                .collect();
            for (k, &i) in measured.iter().enumerate() {
                assert_eq!(combined.over[i], over[k], "frame {}", frames[i]);
            }
            assert!(
                over.iter().any(|&o| o) && !over.iter().all(|&o| o),
                "the case is not trivial"
            );
            // each frame is played once: the rows the pace kept are not played again
            let missing = measured.iter().filter(|&&i| rows[i * 6].is_nan()).count() as u64;
            assert_eq!(
                played_again,
                missing,
                "{} frames, spans {spans:?}",
                frames.len()
            );
            println!(
                "{} frames, {} measured: {played_again} played again (separately: {})",
                frames.len(),
                measured.len(),
                measured.len()
            );
        }
    }
}

#[test]
fn measured_frames_are_every_frame_of_short_spans_and_evenly_spaced_in_long_ones() {
    let frames: Vec<f64> = (0..=200).map(|i| i as f64).collect();
    assert_eq!(
        measured_frames(&frames, &[0.0, 100.0, 200.0], 101).unwrap(),
        None
    );
    let m = measured_frames(&frames, &[0.0, 100.0, 200.0], 11)
        .unwrap()
        .unwrap();
    let want: Vec<usize> = (0..=100)
        .step_by(10)
        .chain((100..=190).step_by(10))
        .chain([199, 200])
        .collect();
    // span 0..100 has 100 frames (0..=99): 11 of them, the first and last (99) included
    assert_eq!(m[..11], [0, 10, 20, 30, 40, 50, 59, 69, 79, 89, 99]);
    assert_eq!(m.len(), 11 + 11 + 1, "{m:?} vs {want:?}");
    assert!(matches!(
        measured_frames(&frames, &[0.0], 1),
        Err(crate::Error::Count {
            got: 1,
            need: 2,
            ..
        })
    ));
}

#[test]
fn the_playback_counts_the_rows_it_plays() {
    let (p, _) = keyed();
    assert_eq!(p.rows_evaluated(), 0);
    p.channels(&[1.0, 2.0, 3.0]).unwrap();
    let _ = departure(&p, &[1.0], &[0.0; 3], &[0.0; 3]).unwrap();
    assert_eq!(p.rows_evaluated(), 4);
    assert_eq!(p.clone().rows_evaluated(), 0);
    assert_eq!(p.clone(), p, "equal whatever each has played");
}

#[test]
fn curves_keyed_together_share_their_roots_and_give_each_curves_own_value() {
    // six curves keyed at the same frames (one cubic solved per time for all), and a seventh
    // keyed at other frames with steeper handles (its own): each value bit for bit the curve's
    // own evaluation, at keys, subframes and beyond the keys
    let (p, _) = keyed();
    let mut curves: Vec<(Channel, FCurve)> = p
        .curves()
        .iter()
        .enumerate()
        .map(|(c, curve)| {
            let channel = if c < 3 {
                Channel::Location(c)
            } else {
                Channel::Rotation(c - 3)
            };
            (channel, curve.clone())
        })
        .collect();
    let other = FCurve::new(
        vec![
            Key::new(2.0, 1.0).with_handles([1.0, 0.0], [2.5, 3.0]),
            Key::new(9.5, -1.0).with_handles([8.0, -4.0], [12.0, 2.0]),
            Key::new(30.0, 0.5),
        ],
        Extrapolation::Linear,
        None,
    )
    .unwrap();
    curves.insert(2, (Channel::Scale(1), other));
    let all = playback(curves.clone(), XYZ);
    let times: Vec<f64> = (0..=400).map(|i| -2.0 + 0.0875 * i as f64).collect();
    let rows = all.channels(&times).unwrap();
    for (i, &t) in times.iter().enumerate() {
        for (channel, curve) in &curves {
            let got = rows[i * all.width() + channel.column(XYZ)];
            assert_eq!(
                got.to_bits(),
                curve.evaluate(t).unwrap().to_bits(),
                "{channel:?} at {t}"
            );
        }
    }
}
