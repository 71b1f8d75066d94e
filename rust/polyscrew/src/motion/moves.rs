//! How far a body turns between two poses, and moves cut short: the rotation between two
//! orientations as a rotation vector, and a pose moved towards a target by at most an angle
//! and a distance.
//!
//! A turn from `Ra` to `Rb` is `log(Rb Ra^-1)`: a vector along the axis (world frame) whose
//! length is the angle in `[0, pi]`, computed from the relative unit quaternion by `atan2`
//! (exact near no turn and near a half turn, where `arccos` of a trace loses digits).

use glam::{DQuat, DVec3};

use crate::denoise::so3;
use crate::error::{Error, Expected, Result};
use crate::memory::{try_vec, Footprint};
use crate::motion::channels::{check_rotation_count, CHANNELS_HINT};
use crate::motion::pose::{Pose, MAX_COORDINATE};

/// The turn from orientation `a` to orientation `b`, world frame: `log(b a^-1)`, axis times
/// angle, the angle in `[0, pi]` (the quaternions' signs do not matter). Zero for `a = b`;
/// `|turn_vector(a, b)|` is the angle between the two orientations.
#[inline]
pub fn turn_vector(a: DQuat, b: DQuat) -> DVec3 {
    so3::log((b * a.conjugate()).normalize())
}

/// [`turn_vector`] of each pair `(a[i], b[i])`.
///
/// # Errors
/// [`Error::LengthMismatch`] when `b` is not as long as `a`, [`Error::Limit`] for more than
/// [`MAX_ROTATIONS`](crate::MAX_ROTATIONS) pairs, [`Error::Memory`] over the memory budget.
pub fn turn_vectors(a: &[DQuat], b: &[DQuat]) -> Result<Vec<DVec3>> {
    if a.len() != b.len() {
        return Err(Error::LengthMismatch {
            what: "rotations b",
            expected: a.len(),
            got: b.len(),
        });
    }
    check_rotation_count(a.len())?;
    Footprint::of::<DVec3>(a.len()).check("turn vectors", CHANNELS_HINT)?;
    let mut out = try_vec(a.len(), "turn vectors")?;
    out.extend(a.iter().zip(b).map(|(a, b)| turn_vector(*a, *b)));
    Ok(out)
}

/// The angle between each two consecutive directions (any nonzero lengths):
/// `atan2(|a x b|, a . b)` in `[0, pi]` for `a = directions[i]`, `b = directions[i + 1]`
/// (exact near 0 and near pi, where `arccos` of a dot product loses digits; 0 where either
/// is zero). `directions.len() - 1` angles, none for fewer than two directions.
///
/// # Errors
/// [`Error::Memory`] over the memory budget.
pub fn direction_steps(directions: &[DVec3]) -> Result<Vec<f64>> {
    let n = directions.len().saturating_sub(1);
    Footprint::of::<f64>(n).check("direction steps", CHANNELS_HINT)?;
    let mut out = try_vec(n, "direction steps")?;
    out.extend(
        directions
            .windows(2)
            .map(|w| w[0].cross(w[1]).length().atan2(w[0].dot(w[1]))),
    );
    Ok(out)
}

/// How far [`partial_move`] may move a pose: a turn angle (radians) and a distance of the
/// pivot point, each finite and at least 0 (or `inf`: no bound).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MoveBounds {
    /// The largest turn, radians.
    pub angle: f64,
    /// The largest distance the pivot point travels.
    pub distance: f64,
}

/// `target`, or, when the straight move from `source` to `target` turns by more than
/// `bounds.angle` or carries the point `pivot` (body coordinates) further than
/// `bounds.distance`, the pose the fraction `a` of the way there that brings both within
/// the bounds: `a = min(1, angle_bound / angle, distance_bound / distance)`, the rotation
/// `exp(a log(Rt Rs^-1)) Rs` (the same axis, `a` of the turn) and the pivot at
/// `ps + a (pt - ps)` (`a` of its straight move, not a screw's helix). At `a = 1` the
/// target itself; at `a = 0` the source. Returns the pose and whether it was cut short.
pub fn partial_move(
    source: &Pose,
    target: &Pose,
    pivot: DVec3,
    bounds: MoveBounds,
) -> (Pose, bool) {
    let turn = turn_vector(source.rotation, target.rotation);
    let (p0, p1) = (
        source.transform_point3(pivot),
        target.transform_point3(pivot),
    );
    let (angle, distance) = (turn.length(), (p1 - p0).length());
    let mut a: f64 = 1.0;
    if angle > bounds.angle {
        a = a.min(bounds.angle / angle);
    }
    if distance > bounds.distance {
        a = a.min(bounds.distance / distance);
    }
    if a >= 1.0 {
        return (*target, false);
    }
    let rotation = (so3::exp(turn * a) * source.rotation).normalize();
    let moved = p0 + a * (p1 - p0);
    (
        Pose::from_rotation_translation(rotation, moved - rotation * pivot),
        true,
    )
}

/// [`partial_move`] of each pair `(source[i], target[i])` with the same pivot and bounds:
/// the poses and which of them were cut short.
///
/// # Errors
/// [`Error::LengthMismatch`] when `target` is not as long as `source`, [`Error::NotFinite`]
/// or [`Error::OutOfRange`] for a pivot coordinate that is not finite or beyond
/// [`MAX_COORDINATE`], [`Error::Value`] for a bound that is negative or NaN, [`Error::Limit`] for more than
/// [`MAX_ROTATIONS`](crate::MAX_ROTATIONS) poses, [`Error::Memory`] over the memory budget.
pub fn partial_moves(
    source: &[Pose],
    target: &[Pose],
    pivot: DVec3,
    bounds: MoveBounds,
) -> Result<(Vec<Pose>, Vec<bool>)> {
    if source.len() != target.len() {
        return Err(Error::LengthMismatch {
            what: "target poses",
            expected: source.len(),
            got: target.len(),
        });
    }
    for (index, value) in pivot.to_array().into_iter().enumerate() {
        if !value.is_finite() {
            return Err(Error::NotFinite {
                what: "pivot",
                index,
            });
        }
        if value.abs() > MAX_COORDINATE {
            return Err(Error::OutOfRange {
                what: "pivot",
                index,
                value,
                limit: MAX_COORDINATE,
            });
        }
    }
    for (what, noun, bound) in [
        ("largest angle", "angle", bounds.angle),
        ("largest distance", "distance", bounds.distance),
    ] {
        if bound.is_nan() || bound < 0.0 {
            return Err(Error::Value {
                what,
                at: None,
                value: bound,
                expected: Expected::NonNegative(noun),
            });
        }
    }
    let n = source.len();
    check_rotation_count(n)?;
    (Footprint::of::<Pose>(n) + Footprint::of::<bool>(n)).check("partial moves", CHANNELS_HINT)?;
    let mut poses = try_vec(n, "partial moves")?;
    let mut cut = try_vec(n, "partial moves")?;
    for (s, t) in source.iter().zip(target) {
        let (pose, short) = partial_move(s, t, pivot, bounds);
        poses.push(pose);
        cut.push(short);
    }
    Ok((poses, cut))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    #[test]
    fn direction_steps_are_exact_near_no_turn_and_a_half_turn() {
        let x = DVec3::X;
        let tiny: f64 = 1e-9;
        let near = DVec3::new(tiny.cos(), tiny.sin(), 0.0) * 3.0;
        let back = DVec3::new(-(tiny.cos()), tiny.sin(), 0.0) * 0.25;
        let steps = direction_steps(&[x, near, DVec3::Y * 2.0, -DVec3::Y, back]).unwrap();
        assert_eq!(steps.len(), 4);
        // arccos of the dot product gives 0 for the first (cos(1e-9) rounds to 1)
        assert!((steps[0] - tiny).abs() < 1e-24, "{}", steps[0]);
        assert!((steps[1] - (PI / 2.0 - tiny)).abs() < 1e-15, "{}", steps[1]);
        assert_eq!(steps[2], PI);
        assert!((steps[3] - (PI / 2.0 + tiny)).abs() < 1e-15, "{}", steps[3]);
        assert_eq!(direction_steps(&[x]).unwrap(), Vec::<f64>::new());
        assert_eq!(direction_steps(&[x, DVec3::ZERO]).unwrap(), [0.0]);
    }

    #[test]
    fn turn_vector_is_axis_times_angle_in_the_world_frame() {
        let a = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, -0.5).normalize(), 0.8);
        for angle in [0.0, 1e-9, 0.3, 2.0, PI - 1e-9] {
            let axis = DVec3::new(-0.3, 0.4, 1.0).normalize();
            let b = DQuat::from_axis_angle(axis, angle) * a;
            for sign in [1.0, -1.0] {
                let v = turn_vector(a, b * sign);
                assert!(
                    (v - axis * angle).length() <= 1e-14 * (1.0 + angle),
                    "angle {angle}, sign {sign}: {v} vs {}",
                    axis * angle
                );
            }
        }
    }

    #[test]
    fn partial_move_keeps_what_is_within_the_bounds_and_cuts_the_rest() {
        let source =
            Pose::from_rotation_translation(DQuat::from_rotation_y(0.2), DVec3::new(1.0, 2.0, 3.0));
        let target = Pose::from_rotation_translation(
            DQuat::from_rotation_z(1.0) * source.rotation,
            DVec3::new(1.5, 2.0, 3.0),
        );
        let pivot = DVec3::new(0.1, 0.0, -0.2);
        let loose = MoveBounds {
            angle: 2.0,
            distance: 10.0,
        };
        assert_eq!(
            partial_move(&source, &target, pivot, loose),
            (target, false)
        );
        let tight = MoveBounds {
            angle: 0.25,
            distance: 10.0,
        };
        let (moved, cut) = partial_move(&source, &target, pivot, tight);
        assert!(cut);
        let angle = turn_vector(source.rotation, moved.rotation).length();
        assert!((angle - 0.25).abs() < 1e-14, "{angle}");
        let (p0, p1, pm) = (
            source.transform_point3(pivot),
            target.transform_point3(pivot),
            moved.transform_point3(pivot),
        );
        assert!((pm - (p0 + 0.25 * (p1 - p0))).length() < 1e-14, "{pm}");
        let err = partial_moves(
            &[source],
            &[target],
            pivot,
            MoveBounds {
                angle: f64::NAN,
                distance: 1.0,
            },
        )
        .unwrap_err();
        assert!(
            matches!(
                err,
                Error::Value {
                    what: "largest angle",
                    expected: Expected::NonNegative("angle"),
                    ..
                }
            ),
            "{err:?}"
        );
        assert_eq!(
            err.to_string(),
            "largest angle: NaN is not a finite angle >= 0"
        );
    }
}
