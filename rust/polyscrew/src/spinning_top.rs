//! The spinning top of Xie et al. 2011 (figure 3), as test and demo data for
//! [`fit_angular_velocity`](crate::fit_angular_velocity).
//!
//! The original animation is a top precessing steadily on the ground: world `z` up, its
//! symmetry axis tilted by `tilt` from `z`, turning about `z` at `precession` rad/s while it
//! spins about its own axis at `spin` rad/s:
//!
//! `R(t) = Rz(precession t) Rx(tilt) Rz(spin t)`,
//! `omega(t) = precession z + spin a(t)` with `a(t) = Rz(precession t) Rx(tilt) z`.
//!
//! The "sketch" adds the user's wobble pattern of figure 3a to the direction curve: small
//! loops of angular radius `wobble_amplitude` run `wobble_frequency` times per second
//! around the original direction, the magnitude is kept.

use glam::{DQuat, DVec3};

/// A steadily precessing top and a wobbly sketch of its angular velocity.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpinningTop {
    /// Spin about the top's own axis, rad/s.
    pub spin: f64,
    /// Precession of the axis about world `z`, rad/s.
    pub precession: f64,
    /// Angle between the top's axis and world `z`, rad.
    pub tilt: f64,
    /// Angular radius of the wobble loops drawn around the direction curve, rad.
    pub wobble_amplitude: f64,
    /// Wobble loops per second, counterclockwise about the direction when positive.
    pub wobble_frequency: f64,
}

impl Default for SpinningTop {
    /// One spin per second, one precession turn per four seconds, 20 degrees of tilt, loops
    /// of 12 degrees, two per second drawn against the spin (loops drawn with the spin at
    /// about the spin rate would resonate with it: no rotation through the keys follows
    /// them).
    fn default() -> Self {
        Self {
            spin: std::f64::consts::TAU,
            precession: std::f64::consts::TAU / 4.0,
            tilt: 20f64.to_radians(),
            wobble_amplitude: 12f64.to_radians(),
            wobble_frequency: -2.0,
        }
    }
}

impl SpinningTop {
    /// The original (keyed) orientation `Rz(precession t) Rx(tilt) Rz(spin t)`.
    pub fn rotation(&self, t: f64) -> DQuat {
        DQuat::from_rotation_z(self.precession * t)
            * DQuat::from_rotation_x(self.tilt)
            * DQuat::from_rotation_z(self.spin * t)
    }

    /// The original motion's world-frame angular velocity `precession z + spin a(t)`.
    pub fn angular_velocity(&self, t: f64) -> DVec3 {
        let axis = DQuat::from_rotation_z(self.precession * t)
            * DQuat::from_rotation_x(self.tilt)
            * DVec3::Z;
        self.precession * DVec3::Z + self.spin * axis
    }

    /// The sketched target: the original direction moved onto a loop of angular radius
    /// `wobble_amplitude` around it, phase `2 pi wobble_frequency t`, same magnitude.
    ///
    /// `d_w = cos(e) d + sin(e) (cos(phi) u + sin(phi) v)` with `u = unit(z x d)`, `v = d x u`.
    pub fn target(&self, t: f64) -> DVec3 {
        let w = self.angular_velocity(t);
        let speed = w.length();
        if speed == 0.0 {
            return w;
        }
        let d = w / speed;
        let u = DVec3::Z.cross(d).try_normalize().unwrap_or(DVec3::X);
        let v = d.cross(u);
        let phi = std::f64::consts::TAU * self.wobble_frequency * t;
        let e = self.wobble_amplitude;
        speed * (e.cos() * d + e.sin() * (phi.cos() * u + phi.sin() * v))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn angular_velocity_is_the_derivative_of_the_rotation() {
        let top = SpinningTop::default();
        for &t in &[0.0, 0.3, 1.7, 3.2] {
            let eps = 1e-6;
            let d = top.rotation(t + eps) * top.rotation(t - eps).inverse();
            let (axis, angle) = d.to_axis_angle();
            let fd = axis * angle / (2.0 * eps);
            let w = top.angular_velocity(t);
            assert!((fd - w).length() < 1e-6, "t {t}: {fd} vs {w}");
        }
    }

    #[test]
    fn target_keeps_magnitude_and_tilts_by_the_amplitude() {
        let top = SpinningTop::default();
        for &t in &[0.0, 0.5, 2.2] {
            let (w, s) = (top.angular_velocity(t), top.target(t));
            assert!((w.length() - s.length()).abs() < 1e-12);
            let angle = w.angle_between(s);
            assert!(
                (angle - top.wobble_amplitude).abs() < 1e-9,
                "t {t}: {angle}"
            );
        }
    }
}
