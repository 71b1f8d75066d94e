//! Poses from channel values as Blender builds them, and the error of one pose against
//! another on a body of a given radius.
//!
//! A channel row here has [`STRIDE`] numbers: location `x, y, z` (columns 0..3), the rotation
//! channels of the owner's mode (columns 3..3 + w: quaternion `w, x, y, z`, axis-angle
//! `angle, x, y, z`, Euler `x, y, z`) and scale `x, y, z` (columns 7..10).

use glam::{DQuat, DVec3};

use crate::motion::channels::{EulerOrder, RotationMode};

/// Numbers per channel row: 3 location, up to 4 rotation, 3 scale.
pub const STRIDE: usize = 10;
/// First rotation column.
pub const ROT: usize = 3;
/// First scale column.
pub const SCALE: usize = 7;

/// The rotation Blender builds from rotation channels `r` (the mode's first
/// [`RotationMode::width`] numbers), as a unit quaternion:
///
/// - quaternion `(w, x, y, z)` normalised (all zero: the identity);
/// - axis-angle `(angle, x, y, z)`: `angle` about the normalised axis (zero axis: the
///   identity);
/// - Euler `(x, y, z)` in order `"XYZ"`: `Rz(z) Ry(y) Rx(x)`, X applied first (the other
///   orders alike).
#[inline]
pub fn rotation(mode: RotationMode, r: &[f64]) -> DQuat {
    match mode {
        RotationMode::Quaternion => {
            let q = DQuat::from_xyzw(r[1], r[2], r[3], r[0]);
            let len = q.length();
            if len > 0.0 && len.is_finite() {
                q / len
            } else {
                DQuat::IDENTITY
            }
        }
        RotationMode::AxisAngle => {
            let axis = DVec3::new(r[1], r[2], r[3]);
            match axis.try_normalize() {
                Some(a) => DQuat::from_axis_angle(a, r[0]),
                None => DQuat::IDENTITY,
            }
        }
        RotationMode::Euler(order) => {
            let x = DQuat::from_rotation_x(r[0]);
            let y = DQuat::from_rotation_y(r[1]);
            let z = DQuat::from_rotation_z(r[2]);
            match order {
                EulerOrder::Xyz => z * y * x,
                EulerOrder::Xzy => y * z * x,
                EulerOrder::Yxz => z * x * y,
                EulerOrder::Yzx => x * z * y,
                EulerOrder::Zxy => y * x * z,
                EulerOrder::Zyx => x * y * z,
            }
        }
    }
}

/// `sin(theta / 2)` and `theta` (in `[0, pi]`) of the rotation taking unit `a` to unit `b`:
/// with `q = a^-1 b`, `theta = 2 atan2(|q.xyz|, |q.w|)` (no cancellation at small angles).
#[inline]
pub fn relative_angle(a: DQuat, b: DQuat) -> (f64, f64) {
    let q = a.conjugate() * b;
    let s = q.xyz().length();
    let c = q.w.abs();
    let norm = (s * s + c * c).sqrt();
    let sin_half = if norm > 0.0 { s / norm } else { 0.0 };
    (sin_half, 2.0 * s.atan2(c))
}

/// What an owner keys: location, rotation, scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Keyed {
    /// Location channels are keyed.
    pub location: bool,
    /// Rotation channels are keyed.
    pub rotation: bool,
    /// Scale channels are keyed.
    pub scale: bool,
}

/// The distance and angle error of channel row `y` against the target pose
/// (`rotation`, `translation`) and scale on a body of radius `radius`:
///
/// `distance = |dt| + 2 r sin(theta / 2) + r |ds|`, `angle = theta`,
///
/// the largest distance any point within `r` of the body's origin can be from its place
/// (`|(R1 - R2) p| = 2 sin(theta / 2) |p|` for the rotation, `|dS p| <= |ds| |p|` for the
/// scale). Groups that are not keyed count as exact.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn row_error(
    mode: RotationMode,
    keyed: Keyed,
    radius: f64,
    y: &[f64; STRIDE],
    rotation_target: DQuat,
    translation_target: DVec3,
    scale_target: DVec3,
) -> (f64, f64, DQuat, DVec3) {
    let mut distance = 0.0;
    let mut angle = 0.0;
    let t = DVec3::new(y[0], y[1], y[2]);
    let (q, t) = {
        let q = if keyed.rotation {
            rotation(mode, &y[ROT..ROT + 4])
        } else {
            rotation_target
        };
        let t = if keyed.location {
            t
        } else {
            translation_target
        };
        (q, t)
    };
    if keyed.location {
        distance += (t - translation_target).length();
    }
    if keyed.rotation {
        let (sin_half, theta) = relative_angle(rotation_target, q);
        distance += 2.0 * radius * sin_half;
        angle = theta;
    }
    if keyed.scale {
        let s = DVec3::new(y[SCALE], y[SCALE + 1], y[SCALE + 2]);
        distance += radius * (s - scale_target).length();
    }
    (distance, angle, q, t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DMat3;

    #[test]
    fn euler_rotation_matches_the_channel_matrices() {
        let e = DVec3::new(0.3, -1.2, 2.2);
        for order in [
            EulerOrder::Xyz,
            EulerOrder::Xzy,
            EulerOrder::Yxz,
            EulerOrder::Yzx,
            EulerOrder::Zxy,
            EulerOrder::Zyx,
        ] {
            let q = rotation(RotationMode::Euler(order), &e.to_array());
            let m = order.to_mat3(e);
            let d = (DMat3::from_quat(q) - m)
                .to_cols_array()
                .iter()
                .fold(0.0f64, |a, v| a.max(v.abs()));
            assert!(d < 1e-14, "{order:?}: {d}");
        }
    }

    #[test]
    fn relative_angle_is_the_turn() {
        let a = DQuat::from_rotation_y(0.4);
        let b = a * DQuat::from_rotation_x(1e-7);
        let (s, t) = relative_angle(a, b);
        assert!((t - 1e-7).abs() < 1e-20, "{t}");
        assert!((s - (0.5e-7f64).sin()).abs() < 1e-20);
        let (_, t) = relative_angle(a, -b);
        assert!(
            (t - 1e-7).abs() < 1e-20,
            "sign of the quaternion does not matter"
        );
    }
}
