//! Tests of flips and spins ([`super::turns`], [`super::analyse_turns`]) and of
//! [`super::departure`] on hand-made curves whose turns are known.

use std::f64::consts::{PI, TAU};

use glam::DVec3;

use super::tests::playback;
use super::*;
use crate::{EulerOrder, FCurve, Interpolation, RotationMode};

const XYZ: RotationMode = RotationMode::Euler(EulerOrder::Xyz);

/// A curve through `(frame, value)` keys, every key LINEAR.
fn curve(points: &[(f32, f32)]) -> FCurve {
    super::tests::curve(points, Interpolation::Linear)
}

fn deg(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x.to_radians(), y.to_radians(), z.to_radians())
}

#[test]
fn euler_wraps_are_told_from_typed_spins() {
    let z = |a: f64, b: f64| is_euler_wrap(EulerOrder::Xyz, deg(0.0, 0.0, a), deg(0.0, 0.0, b));
    assert!(
        z(111.5, -141.1),
        "the issue's wrap: 252.6 keyed, 107.4 equivalent"
    );
    assert!(z(-170.0, 170.0) && z(179.0, -179.0));
    assert!(z(180.0, -100.0), "pi itself is inside the range");
    assert!(!z(0.0, 270.0), "a value beyond the range is typed");
    assert!(!z(0.0, 150.0) && !z(-100.0, 100.0), "no closer equivalent");
    assert!(!z(360.0, 720.0) && !z(0.0, -200.0));
    // 157 degrees true change wraps (margin 46 > 45), 158 does not (44)
    assert!(z(80.0, -123.0) && !z(80.0, -122.0));
    // the twin triple: (x + 180, 180 - y, z + 180) in the order's axes (y: the middle one)
    let wrap = |v: f64| (v + PI).rem_euclid(TAU) - PI;
    for (order, middle) in [
        (EulerOrder::Xyz, 1),
        (EulerOrder::Zxy, 0),
        (EulerOrder::Yzx, 2),
        (EulerOrder::Zyx, 1),
    ] {
        let a = deg(10.0, 70.0, 20.0);
        let b = deg(14.0, 75.0, 26.0);
        let mut twin = b.to_array().map(|v| wrap(v + PI));
        twin[middle] = wrap(PI - b[middle]);
        let twin = DVec3::from_array(twin);
        let same = (order.to_mat3(twin) - order.to_mat3(b))
            .to_cols_array()
            .iter()
            .all(|v| v.abs() < 1e-12);
        assert!(same, "{order:?}: {twin:?} is not the twin of {b:?}");
        assert!(is_euler_wrap(order, a, twin), "{order:?}: {twin:?}");
        assert!(!is_euler_wrap(order, a, b), "{order:?}");
    }
}

#[test]
fn quaternion_sign_flips_are_flips_and_axis_angle_never() {
    assert!(is_sign_flip(&[1.0, 0.0, 0.0, 0.0], &[-0.9, 0.0, 0.0, -0.1]));
    assert!(!is_sign_flip(&[1.0, 0.0, 0.0, 0.0], &[0.1, 0.0, 0.0, 0.99]));
    assert!(!is_flip(
        RotationMode::AxisAngle,
        &[0.0, 0.0, 0.0, 1.0],
        &[-5.0, 0.0, 0.0, 1.0]
    ));
}

/// Z keyed 0, 111.5, -141.1 (a wrap), 120 (a wrap back), 400 (typed: beyond the range).
fn wrapped_z() -> Playback {
    let z = curve(&[
        (1.0, 0.0),
        (11.0, 111.5f32.to_radians()),
        (21.0, (-141.1f32).to_radians()),
        (31.0, 120f32.to_radians()),
        (41.0, 400f32.to_radians()),
    ]);
    playback(vec![(Channel::Rotation(2), z)], XYZ)
}

#[test]
fn auto_takes_wraps_the_short_way_and_keeps_typed_spins() {
    let p = wrapped_z();
    let frames = [1.0, 11.0, 21.0, 31.0, 41.0];
    let auto = analyse_turns(&p, &frames, Turns::Auto).unwrap();
    assert_eq!(auto.flips, [false, true, true, false]);
    assert!(
        (auto.turn[1] - 252.6f64.to_radians()).abs() < 1e-5,
        "{:?}",
        auto.turn
    );
    // the typed spin 120 -> 400 (280 degrees): 7 pieces; its neighbour 2-3 is a flip, not cut
    assert_eq!(auto.inserted.len(), 6, "{:?}", auto.inserted);
    assert!(auto.inserted.iter().all(|&f| f > 31.0 && f < 41.0));
    assert_eq!(analyse_spans(&p, &frames).unwrap(), auto);
    // as Blender plays: the wraps are followed too, and 0 -> 111.5 as their neighbour
    let played = analyse_turns(&p, &frames, Turns::AsPlayed).unwrap();
    assert_eq!(played.flips, auto.flips);
    let count = |lo: f64, hi: f64| {
        played
            .inserted
            .iter()
            .filter(|&&f| f > lo && f < hi)
            .count()
    };
    assert_eq!(
        (
            count(1.0, 11.0),
            count(11.0, 21.0),
            count(21.0, 31.0),
            count(31.0, 41.0)
        ),
        (2, 5, 5, 6)
    );
    let shortest = analyse_turns(&p, &frames, Turns::Shortest).unwrap();
    assert!(shortest.inserted.is_empty());
    assert_eq!((shortest.turn, shortest.held), (auto.turn, auto.held));
}

#[test]
fn a_sign_flipped_quaternion_is_followed_only_as_played() {
    // w: 1 -> -0.6, z: 0 -> -0.8: the short arc turns 106 degrees, Blender's lerp 254
    let w = curve(&[(1.0, 1.0), (11.0, -0.6)]);
    let z = curve(&[(1.0, 0.0), (11.0, -0.8)]);
    let q = playback(
        vec![(Channel::Rotation(0), w), (Channel::Rotation(3), z)],
        RotationMode::Quaternion,
    );
    let auto = analyse_turns(&q, &[1.0, 11.0], Turns::Auto).unwrap();
    assert_eq!(auto.flips, [true]);
    let long = 2.0 * (-0.6f64).acos();
    assert!(
        (auto.turn[0] - long).abs() < 1e-3,
        "{} vs {long}",
        auto.turn[0]
    );
    assert!(auto.inserted.is_empty());
    let played = analyse_turns(&q, &[1.0, 11.0], Turns::AsPlayed).unwrap();
    assert_eq!(
        played.inserted.len(),
        (long / WIND_STEP).ceil() as usize - 1
    );
}

#[test]
fn departure_is_zero_on_the_playback_and_measures_a_known_offset() {
    let p = wrapped_z();
    let frames: Vec<f64> = (0..=80).map(|i| 1.0 + 0.5 * i as f64).collect();
    let rows = p.channels(&frames).unwrap();
    let w = 3;
    let location: Vec<f64> = rows
        .chunks_exact(p.width())
        .flat_map(|r| r[..3].to_vec())
        .collect();
    let rotation: Vec<f64> = rows
        .chunks_exact(p.width())
        .flat_map(|r| r[3..3 + w].to_vec())
        .collect();
    let same = departure(&p, &frames, &location, &rotation).unwrap();
    assert!(same
        .distance
        .iter()
        .chain(&same.angle)
        .all(|&v| v.abs() < 1e-7));
    // 0.3 units along y and 20 degrees more about z; z plus a whole turn is the same rotation
    let moved: Vec<f64> = location
        .chunks(3)
        .flat_map(|l| [l[0], l[1] + 0.3, l[2]])
        .collect();
    let turned: Vec<f64> = rotation
        .chunks(3)
        .enumerate()
        .flat_map(|(i, r)| {
            [
                r[0],
                r[1],
                r[2] + 20f64.to_radians()
                    + if i % 2 == 0 {
                        std::f64::consts::TAU
                    } else {
                        0.0
                    },
            ]
        })
        .collect();
    let off = departure(&p, &frames, &moved, &turned).unwrap();
    assert!(off.distance.iter().all(|&d| (d - 0.3).abs() < 1e-12));
    assert!(
        off.angle
            .iter()
            .all(|&a| (a - 20f64.to_radians()).abs() < 1e-9),
        "{:?}",
        off.angle
    );
    assert!(matches!(
        departure(&p, &frames, &moved[3..], &turned),
        Err(crate::Error::LengthMismatch { .. })
    ));
    let mut bad = turned.clone();
    bad[5] = f64::NAN;
    assert!(matches!(
        departure(&p, &frames, &moved, &bad),
        Err(crate::Error::NotFinite { .. })
    ));
}

#[test]
fn departure_of_a_long_bake_on_several_threads_equals_the_serial_measure() {
    let p = wrapped_z();
    let t = 2 * super::departure::PARALLEL_FRAMES + 7;
    let frames: Vec<f64> = (0..t).map(|i| 40.0 * i as f64 / t as f64).collect();
    // a result off the playback: a wobble in location and rotation
    let location: Vec<f64> = (0..t)
        .flat_map(|i| [0.1 * (i as f64 * 1e-3).sin(), 0.0, 0.2])
        .collect();
    let rotation: Vec<f64> = (0..t)
        .flat_map(|i| [0.0, 0.05, 3.0 * (i as f64 * 3e-4).cos()])
        .collect();
    let whole = departure(&p, &frames, &location, &rotation).unwrap();
    let (mut distance, mut angle) = (vec![0.0; t], vec![0.0; t]);
    super::departure::measure(&p, &frames, &location, &rotation, &mut distance, &mut angle)
        .unwrap();
    assert_eq!(whole.distance, distance);
    assert_eq!(whole.angle, angle);
    assert!(
        angle.iter().any(|&a| a > 0.1),
        "the measure is not trivially zero"
    );
}
