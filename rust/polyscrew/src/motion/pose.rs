//! Rigid poses: a rotation and a translation, local -> world (Rossignac-Kim's
//! `L = [O, I, J, K]`, with `O` the translation and `I, J, K` the rotated basis).

use glam::{DAffine3, DMat3, DMat4, DQuat, DVec3, DVec4};

use crate::error::{Error, PoseDefect, Result};

/// Largest deviation from orthonormality (column lengths, column dot products) and from
/// the affine bottom row that a matrix may show and still be read as a rigid pose.
/// Blender stores matrices in f32 (about 1e-7 relative), well inside this bound.
pub const RIGID_TOLERANCE: f64 = 1e-6;

/// The working range of coordinates: translations, vectors and points must satisfy
/// `|x| <= MAX_COORDINATE` (every value Blender can store, float32 below `3.4e38`, is inside).
///
/// Why `1e150`: the screw formulas are bilinear in a unit quaternion and a coordinate, and
/// the only squares of coordinates they take are lengths (`|tau|^2` to normalise the axis of
/// a translation). Subdivision moves no pose further than about 4 times the keys' largest
/// coordinate (`1.125^12` for the widest mask, phantom ends `2 p0 - p1`), and the translation
/// between two poses is at most twice that, so every square stays below
/// `3 (2 * 4 * 3e150)^2 ~ 2e303`, short of `f64::MAX ~ 1.8e308`. Where a formula squares
/// coordinates of many points (registration, inertia) it scales them by a power of two first.
pub const MAX_COORDINATE: f64 = 1e150;

/// A rigid transform `x -> R x + o` with `R` a unit quaternion.
///
/// The rotation is kept normalised by every constructor, so a pose converted back to a
/// matrix is orthonormal to rounding (about 1e-16).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pose {
    /// The rotation (unit quaternion; the sign is not significant).
    pub rotation: DQuat,
    /// The translation: where the local origin lands in the world.
    pub translation: DVec3,
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    /// The identity pose.
    pub const IDENTITY: Self = Self {
        rotation: DQuat::IDENTITY,
        translation: DVec3::ZERO,
    };

    /// A pose from a rotation (normalised here) and a translation.
    #[inline]
    pub fn from_rotation_translation(rotation: DQuat, translation: DVec3) -> Self {
        Self {
            rotation: rotation.normalize(),
            translation,
        }
    }

    /// A pure translation.
    #[inline]
    pub fn from_translation(translation: DVec3) -> Self {
        Self {
            rotation: DQuat::IDENTITY,
            translation,
        }
    }

    /// Reads a 4x4 matrix given row by row (Blender's layout: translation in the last
    /// column), checking that it is rigid within [`RIGID_TOLERANCE`].
    ///
    /// # Errors
    /// [`Error::BadPose`] with `index` and the defect: NaN or infinity, a bottom row other
    /// than `(0, 0, 0, 1)`, scale, shear or mirror.
    pub fn from_rows(rows: &[[f64; 4]; 4], index: usize) -> Result<Self> {
        let bad = |defect| Error::BadPose { index, defect };
        if rows.iter().flatten().any(|v| !v.is_finite()) {
            return Err(bad(PoseDefect::NotFinite));
        }
        if let Some(value) = (0..3)
            .map(|r| rows[r][3])
            .find(|v| v.abs() > MAX_COORDINATE)
        {
            return Err(bad(PoseDefect::OutOfRange {
                value,
                limit: MAX_COORDINATE,
            }));
        }
        let bottom = rows[3];
        if bottom[0].abs() > RIGID_TOLERANCE
            || bottom[1].abs() > RIGID_TOLERANCE
            || bottom[2].abs() > RIGID_TOLERANCE
            || (bottom[3] - 1.0).abs() > RIGID_TOLERANCE
        {
            return Err(bad(PoseDefect::NotAffine));
        }
        let col = |j: usize| DVec3::new(rows[0][j], rows[1][j], rows[2][j]);
        let cols = [col(0), col(1), col(2)];
        for (column, c) in cols.iter().enumerate() {
            let length = c.length();
            if (length - 1.0).abs() > RIGID_TOLERANCE {
                return Err(bad(PoseDefect::Scale { column, length }));
            }
        }
        for (a, b) in [(0, 1), (1, 2), (2, 0)] {
            let dot = cols[a].dot(cols[b]);
            if dot.abs() > RIGID_TOLERANCE {
                return Err(bad(PoseDefect::Shear {
                    a: a.min(b),
                    b: a.max(b),
                    dot,
                }));
            }
        }
        let basis = DMat3::from_cols(cols[0], cols[1], cols[2]);
        if basis.determinant() < 0.0 {
            return Err(bad(PoseDefect::Mirror));
        }
        Ok(Self::from_rotation_translation(
            DQuat::from_mat3(&basis),
            col(3),
        ))
    }

    /// The 4x4 matrix row by row (Blender's layout), exactly orthonormal up to rounding.
    pub fn to_rows(&self) -> [[f64; 4]; 4] {
        let m = DMat3::from_quat(self.rotation);
        let t = self.translation;
        [
            [m.x_axis.x, m.y_axis.x, m.z_axis.x, t.x],
            [m.x_axis.y, m.y_axis.y, m.z_axis.y, t.y],
            [m.x_axis.z, m.y_axis.z, m.z_axis.z, t.z],
            [0.0, 0.0, 0.0, 1.0],
        ]
    }

    /// The pose as a glam column-major 4x4 matrix.
    pub fn to_mat4(&self) -> DMat4 {
        DMat4::from_rotation_translation(self.rotation, self.translation)
    }

    /// The pose as a glam affine transform.
    pub fn to_affine(&self) -> DAffine3 {
        DAffine3::from_rotation_translation(self.rotation, self.translation)
    }

    /// A pose from a glam affine transform, validated like [`Pose::from_rows`].
    ///
    /// # Errors
    /// As [`Pose::from_rows`].
    pub fn from_affine(a: &DAffine3, index: usize) -> Result<Self> {
        let m = DMat4::from(*a);
        let row = |i: usize| -> [f64; 4] {
            let r: DVec4 = m.row(i);
            r.to_array()
        };
        Self::from_rows(&[row(0), row(1), row(2), row(3)], index)
    }

    /// Composition `self * other`: first `other`, then `self`.
    #[inline]
    pub fn mul_pose(&self, other: &Self) -> Self {
        Self {
            rotation: (self.rotation * other.rotation).normalize(),
            translation: self.rotation * other.translation + self.translation,
        }
    }

    /// The inverse transform.
    #[inline]
    pub fn inverse(&self) -> Self {
        let r = self.rotation.conjugate();
        Self {
            rotation: r,
            translation: -(r * self.translation),
        }
    }

    /// Maps a point of the body (local) frame into the world.
    #[inline]
    pub fn transform_point3(&self, p: DVec3) -> DVec3 {
        self.rotation * p + self.translation
    }

    /// Maps a direction of the body frame into the world (rotation only).
    #[inline]
    pub fn transform_vector3(&self, v: DVec3) -> DVec3 {
        self.rotation * v
    }

    /// Whether the pose is usable by the crate's formulas: a finite rotation and a translation
    /// within [`MAX_COORDINATE`].
    ///
    /// # Errors
    /// [`Error::BadPose`] with `index` (`NotFinite` or `OutOfRange`).
    pub fn check_range(&self, index: usize) -> Result<()> {
        let bad = |defect| Err(Error::BadPose { index, defect });
        if !self.rotation.is_finite() || !self.translation.is_finite() {
            return bad(PoseDefect::NotFinite);
        }
        let value = self.translation.abs().max_element();
        if value > MAX_COORDINATE {
            return bad(PoseDefect::OutOfRange {
                value,
                limit: MAX_COORDINATE,
            });
        }
        Ok(())
    }

    /// Largest absolute difference between the matrices of two poses (an honest distance for
    /// tests and reports: it sees rotation and translation in the same units as the matrix).
    pub fn max_abs_diff(&self, other: &Self) -> f64 {
        let a = self.to_rows();
        let b = other.to_rows();
        a.iter()
            .flatten()
            .zip(b.iter().flatten())
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max)
    }
}

/// Reads a sequence of row-major 4x4 matrices, validating each (see [`Pose::from_rows`]).
///
/// # Errors
/// The first bad pose, by index.
pub fn poses_from_rows(rows: &[[[f64; 4]; 4]]) -> Result<Vec<Pose>> {
    rows.iter()
        .enumerate()
        .map(|(i, m)| Pose::from_rows(m, i))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trip_rows() {
        let p = Pose::from_rotation_translation(
            DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 2.5),
            DVec3::new(0.5, -1.0, 4.0),
        );
        let q = Pose::from_rows(&p.to_rows(), 0).unwrap();
        assert!(p.max_abs_diff(&q) < 1e-15, "{p:?} vs {q:?}");
    }

    #[test]
    fn rejects_scale_shear_mirror_nan() {
        let mut m = Pose::IDENTITY.to_rows();
        m[0][0] = 1.1;
        assert!(matches!(
            Pose::from_rows(&m, 3),
            Err(Error::BadPose {
                index: 3,
                defect: PoseDefect::Scale { column: 0, .. }
            })
        ));
        let mut m = Pose::IDENTITY.to_rows();
        m[0][1] = 0.01;
        m[1][1] = (1.0f64 - 1e-4).sqrt();
        assert!(matches!(
            Pose::from_rows(&m, 0),
            Err(Error::BadPose {
                defect: PoseDefect::Shear { .. },
                ..
            })
        ));
        let mut m = Pose::IDENTITY.to_rows();
        m[2][2] = -1.0;
        assert!(matches!(
            Pose::from_rows(&m, 0),
            Err(Error::BadPose {
                defect: PoseDefect::Mirror,
                ..
            })
        ));
        let mut m = Pose::IDENTITY.to_rows();
        m[1][3] = f64::NAN;
        assert!(matches!(
            Pose::from_rows(&m, 0),
            Err(Error::BadPose {
                defect: PoseDefect::NotFinite,
                ..
            })
        ));
        let mut m = Pose::IDENTITY.to_rows();
        m[3][0] = 0.5;
        assert!(matches!(
            Pose::from_rows(&m, 0),
            Err(Error::BadPose {
                defect: PoseDefect::NotAffine,
                ..
            })
        ));
    }
}
