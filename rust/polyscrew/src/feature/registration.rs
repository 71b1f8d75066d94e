//! Registration with known correspondences: the rigid motion that brings one point cloud
//! closest to another in the least-squares sense (Hofer-Pottmann-Ravani, *From curve design algorithms to the design of rigid body motions*, section 2,
//! after Horn 1987, "Closed-form solution of absolute orientation using unit quaternions").
//!
//! Minimise `sum_k w_k |R x_k + t - y_k|^2` over rotations `R` and translations `t`:
//!
//! ```text
//! xbar, ybar   weighted barycentres                                   (eq. 3)
//! x'_k = x_k - xbar,  y'_k = y_k - ybar                               (eq. 4)
//! S = sum_k w_k x'_k y'_k^T,  S_ab = sum_k w_k x'_ka y'_kb            (eq. 6)
//!
//!     | Sxx+Syy+Szz  Syz-Szy      Szx-Sxz      Sxy-Syx     |
//! N = | Syz-Szy      Sxx-Syy-Szz  Sxy+Syx      Szx+Sxz     |          (eq. 5)
//!     | Szx-Sxz      Sxy+Syx     -Sxx+Syy-Szz  Syz+Szy     |
//!     | Sxy-Syx      Szx+Sxz      Syz+Szy     -Sxx-Syy+Szz |
//!
//! q = (a0, a1, a2, a3) the unit eigenvector of the largest eigenvalue of N,
//! R = rotation of the quaternion a0 + i a1 + j a2 + k a3              (eq. 7)
//! t = ybar - R xbar                                                   (eq. 8)
//! ```
//!
//! (The paper prints `Sxy - Syz` in the last row of eq. 5; Horn's matrix, used here, has
//! `Sxy - Syx`, which keeps `N` symmetric and traceless.)
//!
//! For a unit quaternion `q`, `q^T N q = sum_k w_k y'_k . (R(q) x'_k)`, so the largest
//! eigenvector maximises the correlation. When the largest eigenvalue is repeated the
//! minimiser is not unique (collinear points, or a distorted cloud on the "medial axis" of
//! the rigid motions, Hofer-Pottmann-Ravani, *From curve design algorithms to the design of rigid body motions*, section 3.3.2); then [`register`] returns an error rather than
//! an arbitrary rotation.

#![allow(clippy::neg_cmp_op_on_partial_ord)] // `!(gap > tol)` also rejects NaN

use glam::{DMat3, DQuat, DVec3};

use crate::error::{At, Error, Expected, Result};
use crate::motion::pose::{Pose, MAX_COORDINATE};
use crate::numeric::eigen::symmetric_eigen_from;

/// The largest eigenvalue of Horn's matrix counts as repeated when the gap to the second is
/// at most this fraction of the matrix's spectral radius. Jacobi resolves eigenvalues to
/// about `1e-16` of the radius, so a gap this small is rounding, and the rotation it would
/// pick is arbitrary (its error grows like `eps / gap`).
pub const REPEATED_EIGENVALUE_GAP: f64 = 1e-10;

/// The fewest points registration needs (three non-collinear ones fix a rotation).
pub const MIN_POINTS: usize = 3;

/// `2^-e` for the power of two `2^e` nearest above `big` (1 for `big` 0 or not finite):
/// multiplying by it is exact and brings `big` into `[0.5, 1)`.
fn power_of_two_scale(big: f64) -> f64 {
    if !(big > 0.0 && big.is_finite()) {
        return 1.0;
    }
    2f64.powi(-(big.log2().floor() as i32 + 1).clamp(-1020, 1020))
}

/// Weighted barycentre and cross-covariance `S = sum_k w_k x'_k y'_k^T` of two clouds
/// (Hofer-Pottmann-Ravani, *From curve design algorithms to the design of rigid body motions*, eqs. 3-6), up to a positive power-of-two factor. `S` is returned with
/// `S.col(b)[a] = S_ab`, so `S ~ sum w x' y'^T` as a glam matrix.
///
/// The weights are scaled by a power of two to at most 1 and the centred points to below 1
/// before the products, so `S` stays finite for any coordinates within
/// [`crate::motion::pose::MAX_COORDINATE`] and any finite weights; the scaling is exact,
/// so the rotation (Horn's eigenvector, scale-free) is the same to the bit.
///
/// # Errors
/// As [`register`].
pub fn cross_covariance(
    src: &[DVec3],
    dst: &[DVec3],
    weights: Option<&[f64]>,
) -> Result<(DVec3, DVec3, DMat3)> {
    check_clouds(src, dst, weights)?;
    let weight_scale = weights.map_or(1.0, |w| {
        power_of_two_scale(w.iter().copied().fold(0.0, f64::max))
    });
    let w = |k: usize| weights.map_or(1.0, |w| w[k] * weight_scale);
    let mut total = 0.0;
    let mut xbar = DVec3::ZERO;
    let mut ybar = DVec3::ZERO;
    for k in 0..src.len() {
        total += w(k);
        xbar += w(k) * src[k];
        ybar += w(k) * dst[k];
    }
    xbar /= total;
    ybar /= total;
    let big = src
        .iter()
        .map(|p| (*p - xbar).abs().max_element())
        .chain(dst.iter().map(|p| (*p - ybar).abs().max_element()))
        .fold(0.0, f64::max);
    let scale = power_of_two_scale(big);
    let mut s = DMat3::ZERO;
    for k in 0..src.len() {
        let x = w(k) * ((src[k] - xbar) * scale);
        let y = (dst[k] - ybar) * scale;
        // Column b of x y^T is x * y_b.
        s.x_axis += x * y.x;
        s.y_axis += x * y.y;
        s.z_axis += x * y.z;
    }
    Ok((xbar, ybar, s))
}

/// Horn's symmetric 4x4 matrix `N` (eq. 5) from the cross-covariance `S` of
/// [`cross_covariance`], with quaternion components ordered `(w, x, y, z)`.
pub fn horn_matrix(s: &DMat3) -> [[f64; 4]; 4] {
    let e = |a: usize, b: usize| s.col(b)[a];
    let (sxx, sxy, sxz) = (e(0, 0), e(0, 1), e(0, 2));
    let (syx, syy, syz) = (e(1, 0), e(1, 1), e(1, 2));
    let (szx, szy, szz) = (e(2, 0), e(2, 1), e(2, 2));
    [
        [sxx + syy + szz, syz - szy, szx - sxz, sxy - syx],
        [syz - szy, sxx - syy - szz, sxy + syx, szx + sxz],
        [szx - sxz, sxy + syx, -sxx + syy - szz, syz + szy],
        [sxy - syx, szx + sxz, syz + szy, -sxx - syy + szz],
    ]
}

/// The rotation of a cross-covariance `S` (Horn's eigenvector, eq. 5 and 7), with `w >= 0`.
///
/// # Errors
/// [`Error::NotUnique`] (`what = "registration"`) when the largest eigenvalue of `N` is
/// repeated within [`REPEATED_EIGENVALUE_GAP`] (the best rotation is not unique).
pub fn rotation_from_covariance(s: &DMat3) -> Result<DQuat> {
    let mut basis = IDENTITY4;
    rotation_from_covariance_warm(s, &mut basis)
}

/// The 4x4 identity, the cold start of [`rotation_from_covariance_warm`].
pub const IDENTITY4: [[f64; 4]; 4] = [
    [1.0, 0.0, 0.0, 0.0],
    [0.0, 1.0, 0.0, 0.0],
    [0.0, 0.0, 1.0, 0.0],
    [0.0, 0.0, 0.0, 1.0],
];

/// [`rotation_from_covariance`] with the eigen-solver started from `basis` (the
/// eigenvectors of the previous call, updated here): along a dense motion consecutive
/// Horn matrices are close, and Jacobi then needs one or two sweeps instead of five or six.
/// Start with [`IDENTITY4`]. The result is the same as the cold start's to rounding.
///
/// # Errors
/// As [`rotation_from_covariance`].
pub fn rotation_from_covariance_warm(s: &DMat3, basis: &mut [[f64; 4]; 4]) -> Result<DQuat> {
    let n = horn_matrix(s);
    let (values, vectors) = symmetric_eigen_from(&n, basis);
    let radius = values[0].abs().max(values[3].abs());
    if !(values[0] - values[1] > REPEATED_EIGENVALUE_GAP * radius) {
        *basis = IDENTITY4;
        return Err(Error::NotUnique {
            what: "registration",
            largest: values[0],
            next: values[1],
        });
    }
    *basis = vectors;
    let a = vectors[0];
    let q = DQuat::from_xyzw(a[1], a[2], a[3], a[0]).normalize();
    Ok(if q.w < 0.0 { -q } else { q })
}

/// The rigid pose `m` minimising `sum_k w_k |m(src_k) - dst_k|^2` (eq. 1), by Horn's
/// quaternion method (eqs. 3-8). Weights default to 1.
///
/// The result maps `src` onto `dst` exactly when `dst` is a rigid image of a non-collinear
/// `src`.
///
/// # Errors
/// [`Error::LengthMismatch`] when the clouds (or the weights) differ in length,
/// [`Error::Count`] for fewer than [`MIN_POINTS`] points, [`Error::Value`] for a negative
/// weight, [`Error::Degenerate`] for a zero total weight, [`Error::NotFinite`] for NaN or
/// infinite coordinates or weights, and [`Error::NotUnique`]
/// (`what = "registration"`) when the best rotation is not unique (see
/// [`rotation_from_covariance`]).
pub fn register(src: &[DVec3], dst: &[DVec3], weights: Option<&[f64]>) -> Result<Pose> {
    let (xbar, ybar, s) = cross_covariance(src, dst, weights)?;
    let rotation = rotation_from_covariance(&s)?;
    Ok(Pose {
        rotation,
        translation: ybar - rotation * xbar,
    })
}

fn check_clouds(src: &[DVec3], dst: &[DVec3], weights: Option<&[f64]>) -> Result<()> {
    if dst.len() != src.len() {
        return Err(Error::LengthMismatch {
            what: "target points",
            expected: src.len(),
            got: dst.len(),
        });
    }
    if src.len() < MIN_POINTS {
        return Err(Error::Count {
            what: "points",
            got: src.len(),
            need: MIN_POINTS,
        });
    }
    for (what, cloud) in [("source point", src), ("target point", dst)] {
        if let Some(index) = cloud.iter().position(|p| !p.is_finite()) {
            return Err(Error::NotFinite { what, index });
        }
        if let Some(index) = cloud
            .iter()
            .position(|p| p.abs().max_element() > MAX_COORDINATE)
        {
            return Err(Error::OutOfRange {
                what,
                index,
                value: cloud[index].abs().max_element(),
                limit: MAX_COORDINATE,
            });
        }
    }
    if let Some(w) = weights {
        if w.len() != src.len() {
            return Err(Error::LengthMismatch {
                what: "weights",
                expected: src.len(),
                got: w.len(),
            });
        }
        if let Some(index) = w.iter().position(|x| !x.is_finite()) {
            return Err(Error::NotFinite {
                what: "weight",
                index,
            });
        }
        if let Some(index) = w.iter().position(|&x| x < 0.0) {
            return Err(Error::Value {
                what: "weights",
                at: Some(At::new("weight", index)),
                value: w[index],
                expected: Expected::NonNegative("weight"),
            });
        }
        if w.iter().sum::<f64>() <= 0.0 {
            return Err(Error::Degenerate {
                what: "weights",
                at: None,
                reason: "they sum to zero",
            });
        }
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use nalgebra::{Matrix3, Vector3};

    /// A small deterministic generator (SplitMix64) for test data.
    pub(crate) struct Rng(u64);
    impl Rng {
        pub(crate) fn new(seed: u64) -> Self {
            Self(seed)
        }
        pub(crate) fn next_u64(&mut self) -> u64 {
            self.0 = self.0.wrapping_add(0x9e37_79b9_7f4a_7c15);
            let mut z = self.0;
            z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
            z ^ (z >> 31)
        }
        /// Uniform in [0, 1).
        pub(crate) fn uniform(&mut self) -> f64 {
            (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
        }
        /// Standard normal (Box-Muller).
        pub(crate) fn normal(&mut self) -> f64 {
            let u = self.uniform().max(1e-300);
            let v = self.uniform();
            (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
        }
        pub(crate) fn vec3(&mut self, scale: f64) -> DVec3 {
            DVec3::new(
                self.uniform() * 2.0 - 1.0,
                self.uniform() * 2.0 - 1.0,
                self.uniform() * 2.0 - 1.0,
            ) * scale
        }
        pub(crate) fn pose(&mut self, spread: f64) -> Pose {
            let axis = self.vec3(1.0).normalize();
            let angle = self.uniform() * std::f64::consts::PI;
            Pose::from_rotation_translation(DQuat::from_axis_angle(axis, angle), self.vec3(spread))
        }
    }

    /// Independent oracle: Kabsch's SVD solution (nalgebra), `R = V diag(1, 1, det) U^T`
    /// for `H = sum w x' y'^T = U S V^T`.
    fn kabsch(src: &[DVec3], dst: &[DVec3], w: &[f64]) -> (Matrix3<f64>, Vector3<f64>) {
        let total: f64 = w.iter().sum();
        let v = |p: DVec3| Vector3::new(p.x, p.y, p.z);
        let xbar = src
            .iter()
            .zip(w)
            .map(|(p, w)| v(*p) * *w)
            .sum::<Vector3<f64>>()
            / total;
        let ybar = dst
            .iter()
            .zip(w)
            .map(|(p, w)| v(*p) * *w)
            .sum::<Vector3<f64>>()
            / total;
        let mut h = Matrix3::zeros();
        for k in 0..src.len() {
            h += (v(src[k]) - xbar) * (v(dst[k]) - ybar).transpose() * w[k];
        }
        let svd = h.svd(true, true);
        let (u, vt) = (svd.u.unwrap(), svd.v_t.unwrap());
        let d = (vt.transpose() * u.transpose()).determinant().signum();
        let r = vt.transpose() * Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, d)) * u.transpose();
        let t = ybar - r * xbar;
        (r, t)
    }

    fn max_diff(pose: &Pose, r: &Matrix3<f64>, t: &Vector3<f64>) -> f64 {
        let rows = pose.to_rows();
        let mut worst: f64 = 0.0;
        for i in 0..3 {
            for j in 0..3 {
                worst = worst.max((rows[i][j] - r[(i, j)]).abs());
            }
            worst = worst.max((rows[i][3] - t[i]).abs());
        }
        worst
    }

    #[test]
    fn recovers_a_known_transform_exactly() {
        let mut rng = Rng::new(1);
        for case in 0..200 {
            let truth = rng.pose(5.0);
            let k = 3 + case % 20;
            let src: Vec<DVec3> = (0..k).map(|_| rng.vec3(2.0)).collect();
            let dst: Vec<DVec3> = src.iter().map(|p| truth.transform_point3(*p)).collect();
            let got = register(&src, &dst, None).unwrap();
            let err = got.max_abs_diff(&truth);
            assert!(err < 1e-12, "case {case} ({k} points): error {err:e}");
        }
        // Coplanar points still fix the rotation.
        let src = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
        let truth = rng.pose(1.0);
        let dst: Vec<DVec3> = src.iter().map(|p| truth.transform_point3(*p)).collect();
        assert!(register(&src, &dst, None).unwrap().max_abs_diff(&truth) < 1e-13);
    }

    #[test]
    fn noisy_correspondences_to_expected_accuracy() {
        // Isotropic noise sigma on K points uniform in [-1, 1]^3: the rotation estimate's
        // error vector has covariance ~ sigma^2 (tr(J) I - J)^-1 with J = sum x' x'^T, and
        // the translation's ~ sigma^2 / K.
        let mut rng = Rng::new(7);
        let sigma = 0.01;
        let k = 500;
        let mut sum_rot2 = 0.0;
        let mut sum_pred2 = 0.0;
        let trials = 40;
        for trial in 0..trials {
            let truth = rng.pose(3.0);
            let src: Vec<DVec3> = (0..k).map(|_| rng.vec3(1.0)).collect();
            let dst: Vec<DVec3> = src
                .iter()
                .map(|p| {
                    let n = DVec3::new(rng.normal(), rng.normal(), rng.normal());
                    truth.transform_point3(*p) + sigma * n
                })
                .collect();
            let got = register(&src, &dst, None).unwrap();
            // Same minimiser as the SVD oracle, to rounding.
            let (r, t) = kabsch(&src, &dst, &vec![1.0; k]);
            assert!(
                max_diff(&got, &r, &t) < 1e-12,
                "trial {trial}: Horn != Kabsch"
            );
            let d = got.rotation * truth.rotation.conjugate();
            let angle = 2.0 * d.xyz().length().atan2(d.w.abs());
            sum_rot2 += angle * angle;
            let c = src.iter().sum::<DVec3>() / k as f64;
            let mut j = DMat3::ZERO;
            for p in &src {
                let x = *p - c;
                j += DMat3::from_cols(x * x.x, x * x.y, x * x.z);
            }
            let tr = j.x_axis.x + j.y_axis.y + j.z_axis.z;
            let m = DMat3::from_diagonal(DVec3::splat(tr)) - j;
            let inv = m.inverse();
            sum_pred2 += sigma * sigma * (inv.x_axis.x + inv.y_axis.y + inv.z_axis.z);
            // Translation of the centroid within 5 sigma / sqrt(K) per axis.
            let moved = got.transform_point3(c) - truth.transform_point3(c);
            assert!(
                moved.abs().max_element() < 5.0 * sigma / (k as f64).sqrt(),
                "trial {trial}: centroid off by {moved}"
            );
        }
        let ratio = sum_rot2 / sum_pred2;
        assert!(
            (0.6..1.5).contains(&ratio),
            "mean squared rotation error {:.3e} vs predicted {:.3e}",
            sum_rot2 / trials as f64,
            sum_pred2 / trials as f64
        );
    }

    #[test]
    fn weights_match_the_oracle_and_zero_weights_drop_points() {
        let mut rng = Rng::new(3);
        let src: Vec<DVec3> = (0..12).map(|_| rng.vec3(1.0)).collect();
        let dst: Vec<DVec3> = src.iter().map(|p| *p * 1.3 + rng.vec3(0.2)).collect();
        let w: Vec<f64> = (0..12)
            .map(|i| if i < 4 { 0.0 } else { rng.uniform() + 0.1 })
            .collect();
        let got = register(&src, &dst, Some(&w)).unwrap();
        let (r, t) = kabsch(&src, &dst, &w);
        assert!(max_diff(&got, &r, &t) < 1e-12);
        let dropped = register(&src[4..], &dst[4..], Some(&w[4..])).unwrap();
        assert!(got.max_abs_diff(&dropped) < 1e-13);
    }

    #[test]
    fn warm_start_gives_the_cold_result() {
        // A slowly turning, distorted cloud: each warm-started solve matches the cold one.
        let mut rng = Rng::new(5);
        let src: Vec<DVec3> = (0..8).map(|_| rng.vec3(1.0)).collect();
        let mut basis = IDENTITY4;
        for step in 0..200 {
            let t = step as f64 * 0.05;
            let pose = Pose::from_rotation_translation(
                DQuat::from_axis_angle(DVec3::new(0.3, 1.0, -0.2).normalize(), t),
                DVec3::new(t, 0.0, 0.0),
            );
            let dst: Vec<DVec3> = src
                .iter()
                .map(|p| pose.transform_point3(*p * 1.1 + 0.2 * DVec3::new(p.y, p.z, p.x)))
                .collect();
            let (_, _, s) = cross_covariance(&src, &dst, None).unwrap();
            let cold = rotation_from_covariance(&s).unwrap();
            let warm = rotation_from_covariance_warm(&s, &mut basis).unwrap();
            let d = (cold - warm).length().min((cold + warm).length());
            assert!(d < 1e-13, "step {step}: {cold} vs {warm}");
        }
    }

    #[test]
    fn degenerate_and_bad_input() {
        let line = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X, 3.5 * DVec3::X];
        let moved: Vec<DVec3> = line.iter().map(|p| *p + DVec3::Y).collect();
        assert!(matches!(
            register(&line, &moved, None),
            Err(Error::NotUnique {
                what: "registration",
                ..
            })
        ));
        assert!(matches!(
            register(&line[..2], &moved[..2], None),
            Err(Error::Count {
                what: "points",
                got: 2,
                need: MIN_POINTS
            })
        ));
        assert!(matches!(
            register(&line, &moved[..3], None),
            Err(Error::LengthMismatch { .. })
        ));
        let mut bad = moved.clone();
        bad[2].y = f64::NAN;
        assert!(matches!(
            register(&line, &bad, None),
            Err(Error::NotFinite { index: 2, .. })
        ));
        let tri = [DVec3::ZERO, DVec3::X, DVec3::Y];
        assert!(matches!(
            register(&tri, &tri, Some(&[1.0, -1.0, 1.0])),
            Err(Error::Value {
                what: "weights",
                at: Some(At { index: 1, .. }),
                ..
            })
        ));
        // A point reflection of a planar triangle is a half-turn: unique and exact.
        let flipped: Vec<DVec3> = tri.iter().map(|p| -*p).collect();
        let got = register(&tri, &flipped, None).unwrap();
        for (p, q) in tri.iter().zip(&flipped) {
            assert!(got.transform_point3(*p).distance(*q) < 1e-14);
        }
    }
}
