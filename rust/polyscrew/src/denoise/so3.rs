//! The rotation group's logarithm, exponential and the inverse of its right Jacobian, on unit
//! quaternions, as the smoother needs them (Sola, Deray, Atchuthan, "A micro Lie theory for
//! state estimation in robotics", 2018, equations (143) to (146)).
//!
//! A rotation vector `phi` (axis times angle, radians) stands for `exp(phi)`; `log` returns the
//! vector of angle in `[0, pi]`. With `theta = |phi|` and `K = [phi]x`:
//!
//! ```text
//! Jr^-1(phi) = I + K / 2 + beta K^2,   beta = 1 / theta^2 - cot(theta / 2) / (2 theta)
//! Jl^-1(phi) = Jr^-1(-phi) = Jr^-1(phi)^T
//! log(exp(phi) exp(d)) = phi + Jr^-1(phi) d + O(d^2)
//! log(exp(d) exp(phi)) = phi + Jl^-1(phi) d + O(d^2)
//! ```

use glam::{DMat3, DQuat, DVec3};

use crate::numeric::fastmath;

/// Below this half angle the series of `beta` and of `sin(h) / h` take over from the closed
/// forms (whose cancellation would lose digits): their next terms are below `1e-16` there.
const SERIES_BELOW: f64 = 1e-4;

/// `log(q)` as a rotation vector (angle in `[0, pi]`), for a unit quaternion of either sign.
#[inline]
pub(crate) fn log(q: DQuat) -> DVec3 {
    let (w, v) = if q.w < 0.0 {
        (-q.w, -q.xyz())
    } else {
        (q.w, q.xyz())
    };
    let s = v.length();
    if s > 0.0 {
        // h = atan2(s, w) in [0, pi / 2]; log = 2 h v / s.
        let h = fastmath::turn_angle(w.min(1.0), s.min(1.0));
        v * (2.0 * h / s)
    } else {
        DVec3::ZERO
    }
}

/// `exp(phi)` as a unit quaternion.
#[inline]
pub(crate) fn exp(phi: DVec3) -> DQuat {
    let theta = phi.length();
    let h = 0.5 * theta;
    let (s, c) = fastmath::sin_cos(h);
    // sin(h) / theta, with its series near 0.
    let k = if h < SERIES_BELOW {
        0.5 * (1.0 - h * h / 6.0)
    } else {
        s / theta
    };
    DQuat::from_xyzw(phi.x * k, phi.y * k, phi.z * k, c).normalize()
}

/// Below this angle `beta` is taken from its series (to `theta^8`, whose next term is below
/// `1e-17` there).
const BETA_SERIES_BELOW: f64 = 0.1;

/// `beta(theta)` of `Jr^-1` (see the module documentation), from `phi`.
#[inline]
pub(crate) fn jr_beta(phi: DVec3) -> f64 {
    let theta2 = phi.length_squared();
    if theta2 < BETA_SERIES_BELOW * BETA_SERIES_BELOW {
        // 1/12 + t^2/720 + t^4/30240 + t^6/1209600 + t^8/47900160
        1.0 / 12.0
            + theta2
                * (1.0 / 720.0
                    + theta2
                        * (1.0 / 30240.0 + theta2 * (1.0 / 1_209_600.0 + theta2 / 47_900_160.0)))
    } else {
        let theta = theta2.sqrt();
        let h = 0.5 * theta;
        let (s, c) = fastmath::sin_cos(h);
        (1.0 - h * c / s) / theta2
    }
}

/// `Jr^-1(phi)` as a matrix, given `beta = jr_beta(phi)`.
#[inline]
pub(crate) fn jr_inv_with(phi: DVec3, beta: f64) -> DMat3 {
    let k = skew(phi);
    DMat3::IDENTITY + k * 0.5 + (k * k) * beta
}

/// `Jr^-1(phi) v` given `beta = jr_beta(phi)`, without the matrix.
#[inline]
pub(crate) fn jr_inv_mul(phi: DVec3, beta: f64, v: DVec3) -> DVec3 {
    let a = phi.cross(v);
    v + a * 0.5 + phi.cross(a) * beta
}

/// `Jr^-1(phi)^T v = Jl^-1(phi) v` given `beta = jr_beta(phi)`.
#[inline]
pub(crate) fn jr_inv_t_mul(phi: DVec3, beta: f64, v: DVec3) -> DVec3 {
    let a = phi.cross(v);
    v - a * 0.5 + phi.cross(a) * beta
}

/// `Jr^-1(phi)` (see the module documentation).
#[cfg(test)]
pub(crate) fn jr_inv(phi: DVec3) -> DMat3 {
    jr_inv_with(phi, jr_beta(phi))
}

/// The cross-product matrix `[v]x` (`[v]x w = v x w`).
#[inline]
pub(crate) fn skew(v: DVec3) -> DMat3 {
    DMat3::from_cols(
        DVec3::new(0.0, v.z, -v.y),
        DVec3::new(-v.z, 0.0, v.x),
        DVec3::new(v.y, -v.x, 0.0),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rand_vec(i: usize, scale: f64) -> DVec3 {
        let f = |k: f64| ((i as f64 + 1.0) * k).sin();
        DVec3::new(f(12.9898), f(78.233), f(37.719)) * scale
    }

    #[test]
    fn log_inverts_exp() {
        for i in 0..2000 {
            let scale = [1e-9, 1e-5, 0.1, 1.0, 1.7][i % 5];
            let phi = rand_vec(i, scale);
            let back = log(exp(phi));
            assert!(
                (back - phi).length() <= 1e-14 * phi.length().max(1e-300) + 1e-300,
                "{phi} -> {back}"
            );
            // Against glam's axis-angle.
            let q = DQuat::from_scaled_axis(phi);
            assert!((exp(phi).dot(q)).abs() > 1.0 - 1e-15);
        }
    }

    #[test]
    fn beta_series_meets_the_closed_form() {
        for theta in [0.0999999, 0.1, 0.1000001, 0.05] {
            let phi = DVec3::new(0.6, -0.8, 0.0) * theta;
            let h = 0.5 * theta;
            let closed = (1.0 - h / h.tan()) / (theta * theta);
            assert!(
                (jr_beta(phi) - closed).abs() < 1e-12,
                "{theta}: {} vs {closed}",
                jr_beta(phi)
            );
            let v = DVec3::new(0.3, 0.1, -2.0);
            assert!((jr_inv_mul(phi, jr_beta(phi), v) - jr_inv(phi) * v).length() < 1e-15);
            assert!(
                (jr_inv_t_mul(phi, jr_beta(phi), v) - jr_inv(phi).transpose() * v).length() < 1e-15
            );
        }
    }

    #[test]
    fn jacobian_matches_finite_differences() {
        for i in 0..50 {
            let phi = rand_vec(i, 0.5 + 0.4 * (i % 3) as f64);
            let jr = jr_inv(phi);
            let eps = 1e-6;
            for a in 0..3 {
                let mut d = DVec3::ZERO;
                d[a] = eps;
                // log(exp(phi) exp(d)) - log(exp(phi) exp(-d)) ~ 2 Jr^-1 d
                let num = (log(exp(phi) * exp(d)) - log(exp(phi) * exp(-d))) / (2.0 * eps);
                let col = jr.col(a);
                assert!(
                    (num - col).length() < 1e-8,
                    "{phi} column {a}: {num} vs {col}"
                );
                let numl = (log(exp(d) * exp(phi)) - log(exp(-d) * exp(phi))) / (2.0 * eps);
                assert!((numl - jr.transpose().col(a)).length() < 1e-8);
            }
        }
    }
}
