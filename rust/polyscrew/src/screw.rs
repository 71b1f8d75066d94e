//! The screw between two poses and `s(a, t, b)`, the motion along it.
//!
//! Rossignac-Kim (`003_*`, "Screw motions"): for poses `L0`, `L1` there is a unique
//! minimal-angle screw `M` with `L1 = M L0`: a rotation by `r` in `[0, pi]` about an axis of
//! unit direction `S` through a point `P`, plus a slide `d` along `S`. Then
//! `s(L0, t, L1) = M^t L0` for any real `t` (`t = 0` gives `L0`, `t = 1` gives `L1`, outside
//! `[0, 1]` the screw extrapolates).
//!
//! Instead of the paper's cross-product construction we take the logarithm of the relative
//! rotation as a unit quaternion `q = q1 q0^-1 = (cos h, sin h S)` with `h = r / 2`, `w >= 0`,
//! and write the translation of `M^t` without the axis point, so nothing divides by the
//! angle. With `tau = o1 - R o0` the translation of `M`:
//!
//! ```text
//! rho(t)  = sin(t h) / sin(h)          (= t sinc(t h) / sinc(h), exact at h = 0)
//! A(t)    = rho(t) cos((t - 1) h)
//! B(t)    = rho(t) sin((t - 1) h)
//! M^t     : x -> R^t x + A tau + (t - A) (tau . S) S + B (S x tau)
//! R^t     = (cos(t h), rho(t) sin(h) S)
//! ```
//!
//! `A(1) = 1`, `B(1) = 0`, and as `h -> 0`, `A -> t`, `B -> 0`: the screw degrades into the
//! straight translation continuously, and at `h = pi / 2` (`r = pi`) nothing is singular.
//! Derivation: `M^t x = R^t (x - P) + P + t d S` with `P = (tau_perp + cot(h) S x tau) / 2`,
//! expanded with half-angle identities.

use glam::{DQuat, DVec3};

use crate::fastmath;
use crate::pose::Pose;

/// Below this `|x|`, `sin(x) / x` is evaluated by its Taylor series (error below 1e-20).
const SINC_SERIES_BELOW: f64 = 1e-4;

/// `sin(x) / x` given `sin(x)`, exact to rounding for all `x` including 0.
#[inline]
fn sinc_from(x: f64, sin_x: f64) -> f64 {
    if x.abs() < SINC_SERIES_BELOW {
        1.0 - x * x / 6.0
    } else {
        sin_x / x
    }
}

/// The minimal screw carrying pose `a` to pose `b`, ready to be evaluated at any `t`.
///
/// Built once per pair by [`Screw::between`]; [`Screw::eval`] then costs one `sin_cos`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Screw {
    /// The start pose `a` (`eval(0)`).
    base: Pose,
    /// The relative rotation `q = q_b q_a^-1` with `w >= 0`.
    rotation: DQuat,
    /// Half the rotation angle, `h = atan2(|q.xyz|, q.w)`, in `[0, pi / 2]`.
    half_angle: f64,
    /// `sin(h) = |q.xyz|`, cached.
    sin_half: f64,
    /// `1 / sin(h)` (0 when `h = 0`), cached.
    inv_sin_half: f64,
    /// Unit axis direction `S` (the translation's direction for a pure translation, `+z` for
    /// the identity).
    axis: DVec3,
    /// The translation `tau = o_b - R o_a` of the world motion `M`.
    tau: DVec3,
}

impl Screw {
    /// The minimal screw from `a` to `b` (Rossignac-Kim, "Screw motions").
    ///
    /// When the relative rotation is exactly a half turn both axis directions are minimal;
    /// the one of the quaternion with `w >= 0` as computed is taken.
    #[inline]
    pub fn between(a: &Pose, b: &Pose) -> Self {
        // A product of unit quaternions is unit to rounding: no normalisation on this path
        // (every division and square root here is on the critical path of `s`).
        let mut q = b.rotation * a.rotation.conjugate();
        if q.w < 0.0 {
            q = -q;
        }
        let v = q.xyz();
        let sin_h = v.length();
        let half_angle = fastmath::atan2_first_quadrant(sin_h, q.w);
        let tau = b.translation - q * a.translation;
        let (inv_sin_half, axis) = if sin_h > 0.0 {
            let inv = 1.0 / sin_h;
            (inv, v * inv)
        } else {
            (0.0, tau.try_normalize().unwrap_or(DVec3::Z))
        };
        Self {
            base: *a,
            rotation: q,
            half_angle,
            sin_half: sin_h,
            inv_sin_half,
            axis,
            tau,
        }
    }

    /// The world motion `M^t` as a pose (the transform that carries `a` to `s(a, t, b)`).
    /// `t = 0` is the identity, `t = 1` is `M = b a^-1`.
    #[inline]
    pub fn motion(&self, t: f64) -> Pose {
        let h = self.half_angle;
        let th = t * h;
        let (sin_th, cos_th) = fastmath::sin_cos(th);
        let (sin_h, cos_h) = (self.sin_half, self.rotation.w);
        // rho = sin(t h) / sin(h); near h = 0 as t sinc(t h) / sinc(h), exact at h = 0.
        let rho = if h < SINC_SERIES_BELOW {
            t * sinc_from(th, sin_th) / (1.0 - h * h / 6.0)
        } else {
            sin_th * self.inv_sin_half
        };
        let v = self.rotation.xyz();
        let rotation = DQuat::from_xyzw(v.x * rho, v.y * rho, v.z * rho, cos_th);
        // cos((t-1)h), sin((t-1)h) from the angle-difference identities.
        let a = rho * (cos_th * cos_h + sin_th * sin_h);
        let b = rho * (sin_th * cos_h - cos_th * sin_h);
        let s = self.axis;
        let tau = self.tau;
        let translation = a * tau + ((t - a) * tau.dot(s)) * s + b * s.cross(tau);
        Pose {
            rotation,
            translation,
        }
    }

    /// `s(a, t, b) = M^t a`: `t = 0` gives `a`, `t = 1` gives `b` (to rounding), other `t`
    /// move along or past the screw (ScrewBender section 4, `s(L_a, t, L_b)`).
    #[inline]
    pub fn eval(&self, t: f64) -> Pose {
        let m = self.motion(t);
        Pose {
            rotation: m.rotation * self.base.rotation,
            translation: m.rotation * self.base.translation + m.translation,
        }
    }

    /// The start pose `a`.
    pub fn base(&self) -> Pose {
        self.base
    }

    /// Unit direction `S` of the screw axis. For a pure translation it is the translation's
    /// direction; when `a == b` it is `+z` (any direction would do).
    pub fn axis(&self) -> DVec3 {
        self.axis
    }

    /// Rotation angle `r` in `[0, pi]`, radians.
    pub fn angle(&self) -> f64 {
        2.0 * self.half_angle
    }

    /// Slide `d` along the axis: `M` translates by `d S` along its axis.
    pub fn slide(&self) -> f64 {
        self.tau.dot(self.axis)
    }

    /// The point of the screw axis nearest to the origin of `a`.
    ///
    /// `P = (tau_perp + cot(h) S x tau) / 2` (any point of the axis), then projected; for a
    /// pure translation, the origin of `a` itself. Far away (like `1 / r`) as `r -> 0`.
    pub fn point(&self) -> DVec3 {
        let o = self.base.translation;
        if self.half_angle == 0.0 {
            return o;
        }
        let s = self.axis;
        let perp = self.tau - self.tau.dot(s) * s;
        let cot = self.rotation.w / self.rotation.xyz().length();
        let p = 0.5 * (perp + cot * s.cross(self.tau));
        p - (p - o).dot(s) * s
    }

    /// The translation `tau` of the world motion `M = b a^-1` (`x -> R x + tau`).
    pub fn translation(&self) -> DVec3 {
        self.tau
    }

    /// The relative rotation `R = q_b q_a^-1` as a unit quaternion with `w >= 0`.
    pub fn rotation(&self) -> DQuat {
        self.rotation
    }
}

/// `s(a, 1/2, b)`, the pose halfway along the minimal screw, without trigonometry.
///
/// With `q = (w, v) = (cos h, sin h S)` the relative rotation (`w >= 0`) and `tau` its
/// translation, the half-angle identities give
/// `q^(1/2) = (c, v / (2 c))` with `c = cos(h / 2) = sqrt((1 + w) / 2)`, and the
/// translation of `M^(1/2)` is `tau / 2 - (v x tau) / (2 (1 + w))` (`A = 1/2`,
/// `B S = -tan(h / 2) S / 2 = -v / (2 (1 + w))` in [`Screw::motion`]). Exact at `h = 0`,
/// regular up to the half turn. The outer step of every Split&Tweak rule.
#[inline]
pub fn midpoint(a: &Pose, b: &Pose) -> Pose {
    let mut q = b.rotation * a.rotation.conjugate();
    if q.w < 0.0 {
        q = -q;
    }
    let q = q.normalize();
    let v = q.xyz();
    let tau = b.translation - q * a.translation;
    let c = (0.5 * (1.0 + q.w)).sqrt();
    let half_v = v * (0.5 / c);
    let rotation = DQuat::from_xyzw(half_v.x, half_v.y, half_v.z, c);
    let translation = 0.5 * tau - v.cross(tau) * (0.5 / (1.0 + q.w));
    Pose {
        rotation: (rotation * a.rotation).normalize(),
        translation: rotation * a.translation + translation,
    }
}

/// `s(a, t, b)`: the pose a fraction `t` along the minimal screw from `a` to `b`
/// (ScrewBender section 4; Rossignac-Kim). `t = 0` gives `a`, `t = 1` gives `b`; any real `t`.
#[inline]
pub fn s(a: &Pose, t: f64, b: &Pose) -> Pose {
    Screw::between(a, b).eval(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The exact screw by its parameters: rotation by `angle` about the line through `p`
    /// along unit `axis`, plus `slide` along it; evaluated directly at `t`.
    fn exact(axis: DVec3, p: DVec3, angle: f64, slide: f64, t: f64, x: &Pose) -> Pose {
        let r = DQuat::from_axis_angle(axis, t * angle);
        Pose {
            rotation: r * x.rotation,
            translation: r * (x.translation - p) + p + t * slide * axis,
        }
    }

    #[test]
    fn endpoints_and_parameters() {
        let a = Pose::from_rotation_translation(
            DQuat::from_axis_angle(DVec3::new(0.3, -0.2, 0.9).normalize(), 0.7),
            DVec3::new(1.0, 2.0, -0.5),
        );
        let axis = DVec3::new(1.0, 1.0, 0.0).normalize();
        let p = DVec3::new(0.0, 0.0, 3.0);
        let b = exact(axis, p, 2.0, 0.25, 1.0, &a);
        let sc = Screw::between(&a, &b);
        assert!(sc.eval(0.0).max_abs_diff(&a) < 1e-15);
        assert!(sc.eval(1.0).max_abs_diff(&b) < 1e-14);
        assert!((sc.angle() - 2.0).abs() < 1e-14);
        assert!((sc.slide() - 0.25).abs() < 1e-14);
        assert!(sc.axis().distance(axis) < 1e-14);
        // The reported point is on the true axis.
        let q = sc.point();
        let off = (q - p) - (q - p).dot(axis) * axis;
        assert!(off.length() < 1e-13, "point {q} off the axis by {off}");
        for t in [-0.5, 0.25, 0.5, 1.7] {
            let e = exact(axis, p, 2.0, 0.25, t, &a);
            assert!(sc.eval(t).max_abs_diff(&e) < 1e-14, "t = {t}");
        }
    }

    #[test]
    fn tiny_zero_and_half_turn_angles() {
        let a = Pose::from_rotation_translation(
            DQuat::from_axis_angle(DVec3::Y, 0.4),
            DVec3::new(0.2, 0.1, 0.3),
        );
        let axis = DVec3::new(0.0, 0.6, 0.8);
        let p = DVec3::new(0.5, -0.3, 0.1);
        for angle in [0.0, 1e-13, 1e-9, 1e-6, 1e-3, PI - 1e-9, PI - 1e-6] {
            let b = exact(axis, p, angle, 1.0, 1.0, &a);
            let sc = Screw::between(&a, &b);
            for t in [-0.5, 0.3, 0.5, 1.0, 1.5] {
                let e = exact(axis, p, angle, 1.0, t, &a);
                let err = sc.eval(t).max_abs_diff(&e);
                assert!(err < 1e-12, "angle {angle:e} t {t}: error {err:e}");
            }
        }
    }

    #[test]
    fn midpoint_equals_half_screw() {
        let a = Pose::from_rotation_translation(
            DQuat::from_axis_angle(DVec3::new(0.3, -0.2, 0.9).normalize(), 0.7),
            DVec3::new(1.0, 2.0, -0.5),
        );
        let axis = DVec3::new(0.0, 0.6, 0.8);
        let p = DVec3::new(0.5, -0.3, 0.1);
        for angle in [0.0, 1e-12, 1e-6, 0.5, 2.0, PI - 1e-6] {
            let b = exact(axis, p, angle, 0.7, 1.0, &a);
            let err = midpoint(&a, &b).max_abs_diff(&exact(axis, p, angle, 0.7, 0.5, &a));
            assert!(err < 1e-13, "angle {angle:e}: error {err:e}");
        }
    }

    #[test]
    fn pure_translation_axis() {
        let a = Pose::from_translation(DVec3::new(1.0, 1.0, 1.0));
        let b = Pose::from_translation(DVec3::new(1.0, 4.0, 5.0));
        let sc = Screw::between(&a, &b);
        assert_eq!(sc.angle(), 0.0);
        assert!(sc.axis().distance(DVec3::new(0.0, 0.6, 0.8)) < 1e-15);
        assert!((sc.slide() - 5.0).abs() < 1e-14);
        assert_eq!(sc.point(), a.translation);
    }
}
