//! Poses from channel values as Blender builds them, and the error of one pose against
//! another on a body of a given radius.
//!
//! A channel row here has [`STRIDE`] numbers: location `x, y, z` (columns 0..3), the rotation
//! channels of the owner's mode (columns 3..3 + w: quaternion `w, x, y, z`, axis-angle
//! `angle, x, y, z`, Euler `x, y, z`) and scale `x, y, z` (columns 7..10).

use glam::{DQuat, DVec3};

use crate::motion::channels::{EulerOrder, RotationMode};
use crate::numeric::fastmath;

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
            // `from_rotation_x(a)` is `(sin(a / 2), 0, 0, cos(a / 2))`; the sines and cosines
            // by the crate's one-reduction kernel (std's `sin_cos` is two library calls).
            // `z * y * x` for "XYZ" (the last axis applied on the left), each product with a
            // one-axis quaternion written out without its zero terms: the same values as
            // glam's products (every component has at most two terms that are not zero).
            let [a1, a2, a3] = euler_axes(order);
            let (s1, c1) = fastmath::sin_cos(0.5 * r[a1]);
            let (s2, c2) = fastmath::sin_cos(0.5 * r[a2]);
            let (s3, c3) = fastmath::sin_cos(0.5 * r[a3]);
            let mut q = [0.0; 3];
            q[a3] = s3;
            let q = DQuat::from_xyzw(q[0], q[1], q[2], c3);
            times_axis(times_axis(q, a2, s2, c2), a1, s1, c1)
        }
    }
}

/// `p * (c + s e_a)`, the product with the one-axis quaternion of axis `a` (0: x, 1: y,
/// 2: z), sine `s` and cosine `c`: glam's product without the terms that are zero.
#[inline(always)]
fn times_axis(p: DQuat, a: usize, s: f64, c: f64) -> DQuat {
    let DQuat { x, y, z, w } = p;
    match a {
        0 => DQuat::from_xyzw(w * s + x * c, y * c + z * s, z * c - y * s, w * c - x * s),
        1 => DQuat::from_xyzw(x * c - z * s, w * s + y * c, x * s + z * c, w * c - y * s),
        _ => DQuat::from_xyzw(x * c + y * s, y * c - x * s, w * s + z * c, w * c - z * s),
    }
}

/// The turn between two rotations, kept as `(|q.xyz|, |q.w|)` of `q = a^-1 b`: its angle
/// `theta = 2 atan2(|q.xyz|, |q.w|)` is only computed when asked ([`Turn::angle`]), so a
/// check over many samples takes one `atan2` (of the largest turn) instead of one each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Turn {
    /// `|q.xyz|`.
    pub s: f64,
    /// `|q.w|`.
    pub c: f64,
}

impl Default for Turn {
    /// No turn (`q` the identity).
    fn default() -> Self {
        Self { s: 0.0, c: 1.0 }
    }
}

impl Turn {
    /// The turn taking unit `a` to unit `b`.
    #[inline]
    pub fn between(a: DQuat, b: DQuat) -> Self {
        let q = a.conjugate() * b;
        Self {
            s: q.xyz().length(),
            c: q.w.abs(),
        }
    }

    /// `sin(theta / 2) = s / sqrt(s^2 + c^2)` (0 for a zero quaternion).
    #[inline]
    pub fn sin_half(self) -> f64 {
        let norm = (self.s * self.s + self.c * self.c).sqrt();
        if norm > 0.0 {
            self.s / norm
        } else {
            0.0
        }
    }

    /// `theta = 2 atan2(s, c)` in `[0, pi]` (no cancellation at small angles).
    #[inline]
    pub fn angle(self) -> f64 {
        2.0 * self.s.atan2(self.c)
    }

    /// Whether this turn is larger than `other` (`s / c` larger, without dividing: the angle
    /// grows with it).
    #[inline]
    pub fn exceeds(self, other: Self) -> bool {
        self.s * other.c > other.s * self.c
    }
}

/// `sin(theta / 2)` and `theta` (in `[0, pi]`) of the rotation taking unit `a` to unit `b`:
/// with `q = a^-1 b`, `theta = 2 atan2(|q.xyz|, |q.w|)` (no cancellation at small angles).
#[inline]
pub fn relative_angle(a: DQuat, b: DQuat) -> (f64, f64) {
    let turn = Turn::between(a, b);
    (turn.sin_half(), turn.angle())
}

/// The rotation channels' Jacobian at channel values `r` whose rotation is the unit `q`:
/// `J` (3 x 4, by rows; unused columns zero) with `omega = J dr` the rotation vector of
/// `R(r)^-1 R(r + dr)` to first order (its angle `|omega|`), for the search's `f64` model:
///
/// - quaternion `(w, v)`: `omega = 2 Im(q^* dq) = 2 (w dv - dw v - v x dv)`;
/// - Euler, axes applied `a1, a2, a3`: `omega = R3 R2 u1 de1 + R3 u2 de2 + u3 de3` (world
///   frame; its length is the angle in any frame);
/// - axis-angle: `None` (the model composes it exactly).
#[inline]
pub fn jacobian(mode: RotationMode, r: &[f64], q: DQuat) -> Option<[[f64; 4]; 3]> {
    match mode {
        RotationMode::Quaternion => {
            let (w, v) = (q.w, q.xyz());
            // Signs of the stored channels may be the opposite of q's.
            let s = if q.dot(DQuat::from_xyzw(r[1], r[2], r[3], r[0])) < 0.0 {
                -2.0
            } else {
                2.0
            };
            // d(Im) / d(dw) = -v; d(Im) / d(dv) = w I - [v]x.
            Some([
                [-s * v.x, s * w, s * v.z, -s * v.y],
                [-s * v.y, -s * v.z, s * w, s * v.x],
                [-s * v.z, s * v.y, -s * v.x, s * w],
            ])
        }
        RotationMode::AxisAngle => None,
        RotationMode::Euler(order) => {
            let [a1, a2, a3] = euler_axes(order);
            let unit = |a: usize| match a {
                0 => DVec3::X,
                1 => DVec3::Y,
                _ => DVec3::Z,
            };
            let c3 = unit(a3);
            // R3 R2 u1 = R u1 (R1 keeps u1); R3 u2 is perpendicular to both: c3 x c1 =
            // cos(e2) R3 u2 for an even order, -cos(e2) R3 u2 for an odd one.
            let c1 = matrix_column(q, a1);
            let cross = c3.cross(c1);
            let len = cross.length();
            let c2 = if len > GIMBAL_JACOBIAN {
                // The sign of cos(e2) from e2 itself: even half-turn count -> positive.
                let even_order = (a2 + 3 - a1) % 3 == 1;
                let positive = even_half_turns(r[a2]) == even_order;
                if positive {
                    cross / len
                } else {
                    -cross / len
                }
            } else {
                DQuat::from_axis_angle(c3, r[a3]) * unit(a2)
            };
            let mut j = [[0.0; 4]; 3];
            for (axis, col) in [(a1, c1), (a2, c2), (a3, c3)] {
                j[0][axis] = col.x;
                j[1][axis] = col.y;
                j[2][axis] = col.z;
            }
            Some(j)
        }
    }
}

/// Column `a` (0: x, 1: y, 2: z) of the rotation matrix of unit `q`, `q * e_a`, by the
/// entries of glam's `DMat3::from_quat` (a third of the work of rotating the vector).
#[inline(always)]
fn matrix_column(q: DQuat, a: usize) -> DVec3 {
    let (x2, y2, z2) = (q.x + q.x, q.y + q.y, q.z + q.z);
    match a {
        0 => DVec3::new(
            1.0 - (q.y * y2 + q.z * z2),
            q.x * y2 + q.w * z2,
            q.x * z2 - q.w * y2,
        ),
        1 => DVec3::new(
            q.x * y2 - q.w * z2,
            1.0 - (q.x * x2 + q.z * z2),
            q.y * z2 + q.w * x2,
        ),
        _ => DVec3::new(
            q.x * z2 + q.w * y2,
            q.y * z2 - q.w * x2,
            1.0 - (q.x * x2 + q.y * y2),
        ),
    }
}

/// Whether `floor(angle / pi + 1/2)`, the number of half turns nearest `angle`, is even
/// (`cos(angle) >= 0` away from the ties, where `cos(angle) = 0`), without the library
/// calls of `floor` and `rem_euclid`: rounding by the `1.5 * 2^52` shift (half to even,
/// which differs from `floor(x + 1/2)` only at those ties); std beyond `2^51` half turns.
#[inline(always)]
fn even_half_turns(angle: f64) -> bool {
    let x = angle / std::f64::consts::PI;
    if x.is_nan() || x.abs() >= 2_251_799_813_685_248.0 {
        return (x + 0.5).floor().rem_euclid(2.0) == 0.0;
    }
    let n = (x + fastmath::ROUNDING_SHIFT) - fastmath::ROUNDING_SHIFT;
    (n as i64) & 1 == 0
}

/// Below this `|cos(e2)|` the Euler Jacobian's middle column is built with trigonometry.
const GIMBAL_JACOBIAN: f64 = 1e-3;

/// The axes of an Euler order in the order they are applied (`"XYZ"`: X first).
fn euler_axes(order: EulerOrder) -> [usize; 3] {
    match order {
        EulerOrder::Xyz => [0, 1, 2],
        EulerOrder::Xzy => [0, 2, 1],
        EulerOrder::Yxz => [1, 0, 2],
        EulerOrder::Yzx => [1, 2, 0],
        EulerOrder::Zxy => [2, 0, 1],
        EulerOrder::Zyx => [2, 1, 0],
    }
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
/// scale). Groups that are not keyed count as exact. The angle comes as a [`Turn`]
/// ([`Turn::angle`] gives it), so that a check over many samples computes it once, for the
/// largest; the played rotation and translation come with it.
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
) -> (f64, Turn, DQuat, DVec3) {
    let mut distance = 0.0;
    let mut turn = Turn::default();
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
        turn = Turn::between(rotation_target, q);
        distance += 2.0 * radius * turn.sin_half();
    }
    if keyed.scale {
        let s = DVec3::new(y[SCALE], y[SCALE + 1], y[SCALE + 2]);
        distance += radius * (s - scale_target).length();
    }
    (distance, turn, q, t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::channels::tests::{max_abs_diff, ORDERS};
    use glam::DMat3;

    #[test]
    fn euler_rotation_matches_the_channel_matrices() {
        let e = DVec3::new(0.3, -1.2, 2.2);
        for order in ORDERS {
            let q = rotation(RotationMode::Euler(order), &e.to_array());
            let m = order.to_mat3(e);
            let d = max_abs_diff(DMat3::from_quat(q), m);
            assert!(d < 1e-14, "{order:?}: {d}");
        }
    }

    #[test]
    fn jacobian_gives_the_small_turns() {
        let mut cases = vec![];
        for order in ORDERS {
            for r in [
                [0.4, -0.9, 2.1],
                [3.0, 2.5, -7.0],
                [-1.0, 7.5, 0.3],
                [0.2, std::f64::consts::FRAC_PI_2 - 1e-4, 0.1], // near gimbal lock
            ] {
                cases.push((RotationMode::Euler(order), vec![r[0], r[1], r[2], 0.0]));
            }
        }
        let q = DQuat::from_scaled_axis(DVec3::new(0.3, -1.0, 0.7));
        cases.push((RotationMode::Quaternion, vec![-q.w, -q.x, -q.y, -q.z]));
        for (mode, r) in cases {
            let q = rotation(mode, &r);
            let j = jacobian(mode, &r, q).unwrap();
            for k in 0..mode.width() {
                let mut d = r.clone();
                d[k] += 1e-6;
                let (_, angle) = relative_angle(q, rotation(mode, &d));
                let col = DVec3::new(j[0][k], j[1][k], j[2][k]);
                let want = col.length() * 1e-6;
                assert!(
                    (angle - want).abs() < 1e-11,
                    "{mode:?} {k}: {angle} vs {want}"
                );
            }
        }
    }

    #[test]
    fn euler_rotation_equals_glams_products() {
        for i in 0..300 {
            let f = i as f64;
            let r = [
                (1.7 * f).sin() * 4.0,
                (0.3 * f).cos() * 2.0,
                f * 0.11 - 15.0,
                0.0,
            ];
            let (sx, cx) = fastmath::sin_cos(0.5 * r[0]);
            let (sy, cy) = fastmath::sin_cos(0.5 * r[1]);
            let (sz, cz) = fastmath::sin_cos(0.5 * r[2]);
            let x = DQuat::from_xyzw(sx, 0.0, 0.0, cx);
            let y = DQuat::from_xyzw(0.0, sy, 0.0, cy);
            let z = DQuat::from_xyzw(0.0, 0.0, sz, cz);
            for (order, want) in [
                (EulerOrder::Xyz, z * y * x),
                (EulerOrder::Xzy, y * z * x),
                (EulerOrder::Yxz, z * x * y),
                (EulerOrder::Yzx, x * z * y),
                (EulerOrder::Zxy, y * x * z),
                (EulerOrder::Zyx, x * y * z),
            ] {
                let got = rotation(RotationMode::Euler(order), &r);
                assert!(
                    got.to_array() == want.to_array(),
                    "{order:?} {r:?}: {got} vs {want}"
                );
            }
        }
    }

    #[test]
    fn matrix_columns_and_half_turns_agree_with_their_definitions() {
        for i in 0..500 {
            let f = i as f64;
            let q = DQuat::from_scaled_axis(DVec3::new(
                (1.3 * f).sin() * 3.0,
                (0.7 * f).cos() * 2.0,
                (0.31 * f).sin(),
            ));
            for (a, unit) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
                let d = (matrix_column(q, a) - q * unit).abs().max_element();
                assert!(d < 1e-15, "{q} column {a}: {d}");
            }
            let angle = (f - 250.0) * 0.0731;
            let want = (angle / std::f64::consts::PI + 0.5).floor().rem_euclid(2.0) == 0.0;
            assert_eq!(even_half_turns(angle), want, "{angle}");
            assert_eq!(even_half_turns(angle), angle.cos() >= 0.0, "{angle}");
        }
        assert!(even_half_turns(0.0) && even_half_turns(-0.0) && !even_half_turns(3.0));
        assert!(
            even_half_turns(1e300)
                == ((1e300 / std::f64::consts::PI + 0.5).floor().rem_euclid(2.0) == 0.0)
        );
    }

    #[test]
    fn the_largest_turn_is_the_largest_angle() {
        let turns: Vec<Turn> = [0.0, 1e-9, 0.3, 0.2, 2.9, 3.1, 1.0]
            .iter()
            .map(|a| Turn::between(DQuat::IDENTITY, DQuat::from_rotation_z(*a)))
            .collect();
        let mut max = Turn::default();
        assert_eq!(max.angle(), 0.0);
        for t in &turns {
            if t.exceeds(max) {
                max = *t;
            }
        }
        assert!((max.angle() - 3.1).abs() < 1e-12, "{}", max.angle());
        let zero = Turn::between(DQuat::IDENTITY, DQuat::IDENTITY);
        assert!(!zero.exceeds(Turn::default()) && !Turn::default().exceeds(zero));
        assert!(turns[1].exceeds(Turn::default()), "any turn exceeds none");
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
