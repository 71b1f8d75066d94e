//! Hermite quaternion splines and their angular velocity.
//!
//! Xie et al. 2011 (section 2), following Ramamoorthi-Barr 1997, represent a rotation as a
//! cubic Hermite spline in R^4 through control points `(t_i, q_i, q'_i)`: on the segment
//! `[t_i, t_{i+1}]`, with `h = t_{i+1} - t_i` and `s = (t - t_i) / h`,
//!
//! `q(t) = h00(s) q_i + h h10(s) q'_i + h01(s) q_{i+1} + h h11(s) q'_{i+1}`
//!
//! with `h00 = 2s^3 - 3s^2 + 1`, `h10 = s^3 - 2s^2 + s`, `h01 = -2s^3 + 3s^2`,
//! `h11 = s^3 - s^2`. The curve is C1 and passes through every `q_i` exactly.
//!
//! Between control points `q(t)` leaves the unit sphere slightly; the paper keeps it close
//! with the constraint `U = ∫ (1 - |q|^2)^2 dt = 0`. Here the rotation *is* the normalised
//! curve `r(t) = q(t) / |q(t)|`, so every orientation is exactly unit, and its angular
//! velocity (world frame, `v_world = r v_body r^-1`) is exactly the vector part of the
//! paper's `2 q' q^-1`:
//!
//! `omega(t) = vec(2 q'(t) q(t)^-1) = 2 vec(q' conj(q)) / |q|^2`
//!
//! (write `q = rho r` with `rho = |q|`: `q' q^-1 = rho'/rho + r' r^-1`, and `r' r^-1` is a pure
//! quaternion). The scalar part `2 (q . q') / |q|^2 = d/dt ln |q|^2` is the rate at which the
//! Hermite curve leaves the sphere; the fit penalises it as the paper does.
//!
//! Quaternions in R^4 arithmetic are [`DVec4`] in glam's `(x, y, z, w)` order; orientations
//! handed out are unit [`DQuat`].

use glam::{DQuat, DVec3, DVec4};

use crate::error::{At, Error, Expected, Result};
use crate::motion::timing::check_key_times;

/// Keys shorter than this (as 4-vectors) cannot be normalised and are rejected.
pub const MIN_QUATERNION_LENGTH: f64 = 1e-9;

/// The Hamilton product `a b` of two quaternions stored as `(x, y, z, w)`.
///
/// `w = a_w b_w - a_v . b_v`, `v = a_w b_v + b_w a_v + a_v x b_v`. Unlike `DQuat * DQuat` it
/// makes no assumption about unit length.
#[inline]
pub fn quat_mul(a: DVec4, b: DVec4) -> DVec4 {
    let av = a.truncate();
    let bv = b.truncate();
    let v = a.w * bv + b.w * av + av.cross(bv);
    v.extend(a.w * b.w - av.dot(bv))
}

/// The conjugate `(-x, -y, -z, w)` of a quaternion stored as `(x, y, z, w)`.
#[inline]
pub fn quat_conj(q: DVec4) -> DVec4 {
    DVec4::new(-q.x, -q.y, -q.z, q.w)
}

/// The unit quaternion `exp(v) = (sin|v| v/|v|, cos|v|)` of a pure quaternion `v`.
///
/// `exp(v) q` rotates `q` by the angle `2|v|` about `v` (left multiplication: world frame).
/// Its derivative at `v = 0` in direction `e` is the pure quaternion `e`.
#[inline]
pub fn quat_exp(v: DVec3) -> DVec4 {
    let angle = v.length();
    if angle < 1e-8 {
        // sin(a)/a = 1 - a^2/6 + ..., cos(a) = 1 - a^2/2 + ...: exact to rounding here.
        (v * (1.0 - angle * angle / 6.0)).extend(1.0 - angle * angle / 2.0)
    } else {
        (v * (angle.sin() / angle)).extend(angle.cos())
    }
}

/// Hermite basis weights of one segment at parameter `s` in `[0, 1]`, segment length `h`.
///
/// Row `k` holds the weights of `(q_i, q'_i, q_{i+1}, q'_{i+1})` in the `k`-th time
/// derivative of `q` (`k = 0, 1, 2`), with the chain-rule factors `1/h`, `1/h^2` folded in.
#[inline]
pub fn hermite_weights(s: f64, h: f64) -> [[f64; 4]; 3] {
    let s2 = s * s;
    let s3 = s2 * s;
    [
        [
            2.0 * s3 - 3.0 * s2 + 1.0,
            h * (s3 - 2.0 * s2 + s),
            -2.0 * s3 + 3.0 * s2,
            h * (s3 - s2),
        ],
        [
            (6.0 * s2 - 6.0 * s) / h,
            3.0 * s2 - 4.0 * s + 1.0,
            (-6.0 * s2 + 6.0 * s) / h,
            3.0 * s2 - 2.0 * s,
        ],
        [
            (12.0 * s - 6.0) / (h * h),
            (6.0 * s - 4.0) / h,
            (-12.0 * s + 6.0) / (h * h),
            (6.0 * s - 2.0) / h,
        ],
    ]
}

/// Value, first and second time derivative of the R^4 curve at one time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuatJet {
    /// `q(t)` (not unit between control points).
    pub value: DVec4,
    /// `q'(t)`.
    pub first: DVec4,
    /// `q''(t)`.
    pub second: DVec4,
}

impl QuatJet {
    /// The orientation `q / |q|`, a unit quaternion.
    pub fn rotation(&self) -> DQuat {
        DQuat::from_vec4(self.value / self.value.length())
    }

    /// The full quaternion `2 q' q^-1 = 2 q' conj(q) / |q|^2` of Xie et al. eq. (1).
    ///
    /// Its vector part is the world-frame angular velocity of `q / |q|`; its scalar part is
    /// `d/dt ln |q|^2`, zero on the unit sphere.
    pub fn velocity_quaternion(&self) -> DVec4 {
        2.0 * quat_mul(self.first, quat_conj(self.value)) / self.value.length_squared()
    }

    /// The world-frame angular velocity of `q / |q|`: `vec(2 q' q^-1)`.
    pub fn angular_velocity(&self) -> DVec3 {
        self.velocity_quaternion().truncate()
    }
}

/// A C1 cubic Hermite spline in R^4 whose normalisation is a rotation over time.
///
/// Between `times[0]` and the last time the orientation is `q(t) / |q(t)|`; at control
/// point `i` it is exactly `values[i]`. Times outside the range are clamped to it.
#[derive(Debug, Clone, PartialEq)]
pub struct QuatSpline {
    times: Vec<f64>,
    values: Vec<DVec4>,
    derivatives: Vec<DVec4>,
}

impl QuatSpline {
    /// A spline through unit quaternions `values` with time derivatives `derivatives`.
    ///
    /// `values` are normalised; derivatives are taken as given.
    ///
    /// # Errors
    /// [`Error::TooFew`] for fewer than 2 control points, [`Error::LengthMismatch`] when the
    /// three slices differ in length, [`Error::KeyTimes`] for times that are not strictly
    /// increasing, [`Error::NotFinite`] for a NaN or infinite entry and [`Error::Value`]
    /// for a value shorter than [`MIN_QUATERNION_LENGTH`].
    pub fn new(times: &[f64], values: &[DQuat], derivatives: &[DVec4]) -> Result<Self> {
        let values = check_keys(times, values)?;
        if derivatives.len() != times.len() {
            return Err(Error::LengthMismatch {
                what: "derivatives",
                expected: times.len(),
                got: derivatives.len(),
            });
        }
        if let Some(index) = derivatives.iter().position(|d| !d.is_finite()) {
            return Err(Error::NotFinite {
                what: "derivative",
                index,
            });
        }
        Ok(Self {
            times: times.to_vec(),
            values,
            derivatives: derivatives.to_vec(),
        })
    }

    /// The paper's `InitCurve`: a spline through `keys` at `times` with the derivatives
    /// `q'_i = (q_{i+1} - q_{i-1}) / (t_{i+1} - t_{i-1})` (one-sided at the ends).
    ///
    /// Keys are normalised and their signs made continuous (`q_i . q_{i-1} >= 0`, the first
    /// key's sign kept), so each segment takes the shorter way round.
    ///
    /// # Errors
    /// As [`QuatSpline::new`].
    pub fn through(times: &[f64], keys: &[DQuat]) -> Result<Self> {
        let values = check_keys(times, keys)?;
        let n = values.len();
        let derivatives = (0..n)
            .map(|i| {
                let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
                (values[b] - values[a]) / (times[b] - times[a])
            })
            .collect();
        Ok(Self {
            times: times.to_vec(),
            values,
            derivatives,
        })
    }

    /// Assembles a spline from parts already checked by the caller.
    pub(crate) fn from_parts(times: Vec<f64>, values: Vec<DVec4>, derivatives: Vec<DVec4>) -> Self {
        debug_assert!(times.len() == values.len() && times.len() == derivatives.len());
        Self {
            times,
            values,
            derivatives,
        }
    }

    /// Control-point times.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Control-point values, unit quaternions as `(x, y, z, w)`.
    pub fn values(&self) -> &[DVec4] {
        &self.values
    }

    /// Control-point time derivatives `q'_i`.
    pub fn derivatives(&self) -> &[DVec4] {
        &self.derivatives
    }

    /// The first and last control-point times.
    pub fn range(&self) -> (f64, f64) {
        (self.times[0], self.times[self.times.len() - 1])
    }

    /// The segment `i` with `times[i] <= t <= times[i + 1]` (clamped at the ends).
    pub fn segment(&self, t: f64) -> usize {
        let last = self.times.len() - 2;
        self.times
            .partition_point(|&x| x <= t)
            .saturating_sub(1)
            .min(last)
    }

    /// `q`, `q'` and `q''` at time `t` (clamped to the range).
    pub fn jet(&self, t: f64) -> QuatJet {
        let (t0, t1) = self.range();
        let t = t.clamp(t0, t1);
        let i = self.segment(t);
        let h = self.times[i + 1] - self.times[i];
        let w = hermite_weights((t - self.times[i]) / h, h);
        let c = [
            self.values[i],
            self.derivatives[i],
            self.values[i + 1],
            self.derivatives[i + 1],
        ];
        let comb = |r: &[f64; 4]| r[0] * c[0] + r[1] * c[1] + r[2] * c[2] + r[3] * c[3];
        QuatJet {
            value: comb(&w[0]),
            first: comb(&w[1]),
            second: comb(&w[2]),
        }
    }

    /// The orientation `q(t) / |q(t)|` at time `t`; exactly `values[i]` at `times[i]`.
    pub fn rotation(&self, t: f64) -> DQuat {
        self.jet(t).rotation()
    }

    /// The world-frame angular velocity `vec(2 q' q^-1)` of the orientation at time `t`.
    pub fn angular_velocity(&self, t: f64) -> DVec3 {
        self.jet(t).angular_velocity()
    }
}

/// Checks times and keys, normalises the keys and makes their signs continuous.
pub(crate) fn check_keys(times: &[f64], keys: &[DQuat]) -> Result<Vec<DVec4>> {
    if keys.len() < 2 {
        return Err(Error::TooFew {
            got: keys.len(),
            need: 2,
        });
    }
    if times.len() != keys.len() {
        return Err(Error::LengthMismatch {
            what: "key times",
            expected: keys.len(),
            got: times.len(),
        });
    }
    check_key_times(times)?;
    let mut out: Vec<DVec4> = Vec::with_capacity(keys.len());
    for (index, key) in keys.iter().enumerate() {
        let mut v = DVec4::from(*key);
        // Scale huge or tiny keys by a power of two first (exact), so |v|^2 stays finite.
        let big = v.abs().max_element();
        if big > 1e150 || (big > 0.0 && big < 1e-150) {
            v *= 2f64.powi(-(big.log2().floor() as i32).clamp(-1020, 1020));
        }
        if !v.is_finite() {
            return Err(Error::NotFinite {
                what: "key quaternion",
                index,
            });
        }
        let length = v.length();
        if length < MIN_QUATERNION_LENGTH {
            return Err(Error::Value {
                what: "key quaternion",
                at: Some(At::new("key", index)),
                value: length,
                expected: Expected::Normalisable(MIN_QUATERNION_LENGTH),
            });
        }
        let mut v = v / length;
        if let Some(prev) = out.last() {
            if v.dot(*prev) < 0.0 {
                v = -v;
            }
        }
        out.push(v);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spin(axis: DVec3, rate: f64, t: f64) -> DQuat {
        DQuat::from_axis_angle(axis, rate * t)
    }

    #[test]
    fn product_matches_glam_for_unit_quaternions() {
        let a = DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -1.2, 2.0);
        let b = DQuat::from_euler(glam::EulerRot::XYZ, -0.7, 0.4, 0.1);
        let ours = quat_mul(DVec4::from(a), DVec4::from(b));
        let theirs = DVec4::from(a * b);
        assert!((ours - theirs).length() < 1e-15, "{ours} vs {theirs}");
    }

    #[test]
    fn exp_rotates_by_twice_its_length() {
        let v = DVec3::new(0.1, -0.2, 0.3);
        let q = DQuat::from_vec4(quat_exp(v));
        let expected = DQuat::from_axis_angle(v.normalize(), 2.0 * v.length());
        assert!(q.dot(expected).abs() > 1.0 - 1e-15, "{q} vs {expected}");
        let small = quat_exp(DVec3::new(1e-10, 0.0, 0.0));
        assert!((small.length() - 1.0).abs() < 1e-15);
    }

    #[test]
    fn interpolates_controls_exactly() {
        let times = [0.0, 0.5, 1.3, 2.0];
        let keys: Vec<DQuat> = times
            .iter()
            .map(|&t| DQuat::from_euler(glam::EulerRot::ZYX, t, 0.5 * t * t, -t))
            .collect();
        let s = QuatSpline::through(&times, &keys).unwrap();
        for (t, k) in times.iter().zip(&keys) {
            let r = s.rotation(*t);
            assert!(r.dot(*k).abs() > 1.0 - 1e-15, "t {t}: {r} vs {k}");
        }
    }

    #[test]
    fn angular_velocity_matches_finite_differences_of_rotation() {
        let times = [0.0, 0.4, 1.0, 1.5];
        let keys: Vec<DQuat> = times
            .iter()
            .map(|&t| DQuat::from_euler(glam::EulerRot::ZYX, 2.0 * t, 0.5 * t, -t))
            .collect();
        let s = QuatSpline::through(&times, &keys).unwrap();
        for &t in &[0.1, 0.55, 0.9, 1.23] {
            let eps = 1e-6;
            let (a, b) = (s.rotation(t - eps), s.rotation(t + eps));
            // world-frame: b = exp(omega dt) a  =>  omega ~ axis-angle of b a^-1 / dt
            let d = b * a.inverse();
            let (axis, angle) = d.to_axis_angle();
            let fd = axis * angle / (2.0 * eps);
            let w = s.angular_velocity(t);
            assert!(
                (fd - w).length() < 1e-6 * (1.0 + w.length()),
                "t {t}: fd {fd} vs {w}"
            );
        }
    }

    #[test]
    fn keys_get_continuous_signs() {
        let times = [0.0, 1.0, 2.0];
        let keys = [
            spin(DVec3::Z, 1.0, 0.0),
            -spin(DVec3::Z, 1.0, 1.0),
            spin(DVec3::Z, 1.0, 2.0),
        ];
        let s = QuatSpline::through(&times, &keys).unwrap();
        assert!(s.values()[0].dot(s.values()[1]) > 0.0);
        assert!(s.values()[1].dot(s.values()[2]) > 0.0);
    }

    #[test]
    fn rejects_bad_keys() {
        let q = DQuat::IDENTITY;
        assert!(matches!(
            QuatSpline::through(&[0.0], &[q]),
            Err(Error::TooFew { got: 1, need: 2 })
        ));
        assert!(matches!(
            QuatSpline::through(&[0.0, 0.0], &[q, q]),
            Err(Error::KeyTimes { index: 1 })
        ));
        assert!(matches!(
            QuatSpline::through(&[0.0, 1.0], &[q, DQuat::from_xyzw(f64::NAN, 0.0, 0.0, 1.0)]),
            Err(Error::NotFinite { index: 1, .. })
        ));
        assert!(matches!(
            QuatSpline::through(&[0.0, 1.0], &[q, DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0)]),
            Err(Error::Value {
                expected: Expected::Normalisable(_),
                ..
            })
        ));
    }
}
