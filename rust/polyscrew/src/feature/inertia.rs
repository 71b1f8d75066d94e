//! The six inertia points of a point cloud and the four-point affine shortcut
//! (Hofer-Pottmann-Ravani, *From curve design algorithms to the design of rigid body motions*, sections 2.1 and 4.3).
//!
//! Registration of a cloud `X` to an affine image `A X + a` depends only on the barycentre
//! `xbar` and the inertia tensor `J = sum_k x'_k x'_k^T` of `X` (Proposition 2), and the six
//! points
//!
//! ```text
//! xbar +- sqrt(lambda_j / 2) e_j,   j = 1, 2, 3                          (eq. 10)
//! ```
//!
//! (`lambda_j`, `e_j` the eigenvalues and unit eigenvectors of `J`) have the same barycentre
//! and inertia tensor. A linear curve scheme maps affine copies to affine copies (eqs.
//! 11-12), so it suffices to run it on four affinely independent points, the control points
//! `xbar` and `xbar + s e_j` (here `s` is the cloud's RMS radius), and to carry the six
//! inertia points along by their fixed barycentric coordinates:
//!
//! ```text
//! image of xbar +- a_j e_j  =  C_0 +- (a_j / s) (C_j - C_0)
//! ```
//!
//! where `C_0..C_3` are the control points' images.

#![allow(clippy::neg_cmp_op_on_partial_ord)] // `!(x > tol)` also rejects NaN

use glam::{DMat3, DVec3};

use crate::error::{Error, Result};
use crate::motion::pose::MAX_COORDINATE;
use crate::numeric::eigen::symmetric_eigen;

/// A cloud counts as collinear (its rotation about the line undetermined) when the second
/// largest eigenvalue of its inertia tensor is at most this fraction of the largest.
pub const COLLINEAR_TOLERANCE: f64 = 1e-12;

/// Barycentre, principal axes and inertia extents of a point cloud.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InertiaFrame {
    /// The barycentre `xbar` (eq. 3).
    pub centroid: DVec3,
    /// Unit principal axes `e_1, e_2, e_3`, by decreasing eigenvalue, right-handed.
    pub axes: [DVec3; 3],
    /// `a_j = sqrt(lambda_j / 2)`: the inertia points sit at `xbar +- a_j e_j` (eq. 10).
    pub extents: [f64; 3],
    /// RMS distance of the points from the barycentre: the length `s` of the control
    /// frame's legs (positive for any non-degenerate cloud).
    pub radius: f64,
}

impl InertiaFrame {
    /// The inertia frame of `points` (the paper's unit point masses).
    ///
    /// # Errors
    /// [`Error::NotFinite`] for a NaN or infinite point, [`Error::Count`] or [`Error::Degenerate`]
    /// (`what = "feature points"`) for fewer than 3 points or collinear points (within
    /// [`COLLINEAR_TOLERANCE`]): they do not fix a rigid motion.
    pub fn of(points: &[DVec3]) -> Result<Self> {
        if let Some(index) = points.iter().position(|p| !p.is_finite()) {
            return Err(Error::NotFinite {
                what: "feature point",
                index,
            });
        }
        if points.len() < 3 {
            return Err(Error::Count {
                what: "feature points",
                got: points.len(),
                need: 3,
            });
        }
        if let Some(index) = points
            .iter()
            .position(|p| p.abs().max_element() > MAX_COORDINATE)
        {
            return Err(Error::OutOfRange {
                what: "feature point",
                index,
                value: points[index].abs().max_element(),
                limit: MAX_COORDINATE,
            });
        }
        let centroid = points.iter().sum::<DVec3>() / points.len() as f64;
        // The tensor of the centred points scaled by a power of two to below 1 (exact), so
        // its entries and Jacobi's sums of their squares stay finite; scaled back below.
        let big = points
            .iter()
            .map(|p| (*p - centroid).abs().max_element())
            .fold(0.0, f64::max);
        let scale = if big > 0.0 {
            2f64.powi(-(big.log2().floor() as i32 + 1).clamp(-1020, 1020))
        } else {
            1.0
        };
        let mut j = [[0.0; 3]; 3];
        for p in points {
            let x = ((*p - centroid) * scale).to_array();
            for a in 0..3 {
                for b in 0..3 {
                    j[a][b] += x[a] * x[b];
                }
            }
        }
        let (values, vectors) = symmetric_eigen(&j);
        if !(values[1] > COLLINEAR_TOLERANCE * values[0]) {
            return Err(Error::Degenerate {
                what: "feature points",
                at: None,
                reason: "they are collinear (or coincide): the rotation about their line is \
                         undetermined",
            });
        }
        let e0 = DVec3::from_array(vectors[0]);
        let e1 = DVec3::from_array(vectors[1]);
        let e2 = e0.cross(e1).normalize();
        let extents = values.map(|l| (l.max(0.0) / 2.0).sqrt() / scale);
        let radius = ((j[0][0] + j[1][1] + j[2][2]) / points.len() as f64).sqrt() / scale;
        Ok(Self {
            centroid,
            axes: [e0, e1, e2],
            extents,
            radius,
        })
    }

    /// The inertia tensor `J = sum_k x'_k x'_k^T` (eq. 9, about the barycentre).
    pub fn inertia_tensor(&self) -> DMat3 {
        let mut j = DMat3::ZERO;
        for (e, a) in self.axes.iter().zip(self.extents) {
            let l = 2.0 * a * a;
            j += DMat3::from_cols(*e * (l * e.x), *e * (l * e.y), *e * (l * e.z));
        }
        j
    }

    /// The six inertia points `xbar +- a_j e_j`, ordered `+e_1, -e_1, +e_2, -e_2, +e_3, -e_3`
    /// (eq. 10).
    pub fn inertia_points(&self) -> [DVec3; 6] {
        std::array::from_fn(|i| {
            let j = i / 2;
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            self.centroid + sign * self.extents[j] * self.axes[j]
        })
    }

    /// The four affinely independent control points `xbar, xbar + s e_1, xbar + s e_2,
    /// xbar + s e_3` (`s` = [`InertiaFrame::radius`]) that a linear scheme is run on.
    pub fn control_points(&self) -> [DVec3; 4] {
        let c = self.centroid;
        let s = self.radius;
        [
            c,
            c + s * self.axes[0],
            c + s * self.axes[1],
            c + s * self.axes[2],
        ]
    }

    /// The affine shortcut (section 4.3): the images of the six inertia points under the
    /// affine map that takes the control points to `images`,
    /// `C_0 +- (a_j / s) (C_j - C_0)`, in the order of [`InertiaFrame::inertia_points`].
    #[inline]
    pub fn affine_images(&self, images: &[DVec3; 4]) -> [DVec3; 6] {
        let c0 = images[0];
        std::array::from_fn(|i| {
            let j = i / 2;
            let sign = if i % 2 == 0 { 1.0 } else { -1.0 };
            c0 + (sign * self.extents[j] / self.radius) * (images[j + 1] - c0)
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::feature::registration::register;
    use glam::{DAffine3, DQuat};

    fn cloud() -> Vec<DVec3> {
        (0..17)
            .map(|i| {
                let x = i as f64;
                DVec3::new(
                    (x * 0.7).sin() * 2.0,
                    (x * 1.3).cos(),
                    x * 0.1 - 0.5 + (x * 2.1).sin(),
                )
            })
            .collect()
    }

    #[test]
    fn six_points_keep_barycentre_and_inertia() {
        let pts = cloud();
        let f = InertiaFrame::of(&pts).unwrap();
        let six = f.inertia_points();
        let c6 = six.iter().sum::<DVec3>() / 6.0;
        assert!(c6.distance(f.centroid) < 1e-14);
        let mut j = [[0.0; 3]; 3];
        let mut j6 = [[0.0; 3]; 3];
        for (cloud_pts, out, c) in [(&pts[..], &mut j, f.centroid), (&six[..], &mut j6, c6)] {
            for p in cloud_pts {
                let x = (*p - c).to_array();
                for a in 0..3 {
                    for b in 0..3 {
                        out[a][b] += x[a] * x[b];
                    }
                }
            }
        }
        for a in 0..3 {
            for b in 0..3 {
                assert!(
                    (j[a][b] - j6[a][b]).abs() < 1e-12,
                    "J[{a}][{b}]: {j:?} vs {j6:?}"
                );
            }
        }
        assert!(f.axes[0].cross(f.axes[1]).dot(f.axes[2]) > 0.999_999);
    }

    #[test]
    fn registration_to_an_affine_image_only_sees_the_six_points() {
        // Proposition 2: registering the whole cloud or its six inertia points to the same
        // affine image gives the same pose; the affine shortcut reproduces the images.
        let pts = cloud();
        let f = InertiaFrame::of(&pts).unwrap();
        let a = DAffine3::from_cols_array(&[
            1.1, 0.2, -0.1, 0.1, 0.9, 0.3, -0.2, 0.1, 1.2, 0.5, -1.0, 2.0,
        ]) * DAffine3::from_quat(DQuat::from_rotation_y(0.8));
        let images: Vec<DVec3> = pts.iter().map(|p| a.transform_point3(*p)).collect();
        let six = f.inertia_points();
        let six_images = f.affine_images(&f.control_points().map(|p| a.transform_point3(p)));
        for (p, q) in six.iter().zip(&six_images) {
            assert!(a.transform_point3(*p).distance(*q) < 1e-13);
        }
        let full = register(&pts, &images, None).unwrap();
        let short = register(&six, &six_images, None).unwrap();
        assert!(full.max_abs_diff(&short) < 1e-12, "{full:?} vs {short:?}");
    }

    #[test]
    fn collinear_and_planar_clouds() {
        let line: Vec<DVec3> = (0..5)
            .map(|i| DVec3::new(1.0, 2.0, 3.0) * i as f64)
            .collect();
        assert!(matches!(
            InertiaFrame::of(&line),
            Err(Error::Degenerate {
                what: "feature points",
                ..
            })
        ));
        let plate = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
        let f = InertiaFrame::of(&plate).unwrap();
        assert!(f.extents[2] < 1e-12 && f.radius > 0.5);
    }
}
