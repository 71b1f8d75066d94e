//! The pivot: the body point whose world path is smoothed as the translation.
//!
//! It is the point of least jitter: the point `c` (body coordinates) minimising the sum of
//! squared second divided differences of its world path `P_i c = R_i c + o_i`,
//!
//! ```text
//! minimise sum_k |D_k (R c + o)|^2  <=>  (sum_k A_k^T A_k) c = -sum_k A_k^T b_k,
//! A_k = sum_j a_kj R_{k+j},   b_k = sum_j a_kj o_{k+j}
//! ```
//!
//! It follows the data like a body point does: for poses `G P_i H` (rigid `G`, `H`) the
//! minimiser is `H^-1 c` (the world distances of second differences do not see `G`, and `H`
//! only renames body points), so smoothing the path of `c` is coordinate-free. On noisy
//! data the second differences are mostly noise, and `c` is where the capture's rotational
//! and positional noise separate best (the marker, the optical centre); on clean data it is
//! the point of least acceleration, which lies on the axis of a screw motion: its path is then
//! a straight line that the translation spline keeps exactly.
//!
//! A motion without rotation does not single out a point (every point has the same path, and
//! the result is the same for all), and a screw motion singles out its axis, not a point on
//! it: directions in which the 3x3 system is singular (eigenvalues below
//! [`PIVOT_RANK_TOLERANCE`] times the largest) are left out, so `c` is the admissible point
//! nearest the body origin.

use glam::{DMat3, DQuat, DVec3};

use super::smoother::Whittaker;
use super::stencil::Stencils;
use crate::numeric::eigen::symmetric_eigen;
use crate::Pose;

/// Eigenvalues of the pivot's normal equations below this fraction of the largest are
/// treated as zero.
pub(crate) const PIVOT_RANK_TOLERANCE: f64 = 1e-9;

/// The point of least jitter, from order-2 stencils `st`. Not finite on overflow.
pub(crate) fn pivot(poses: &[Pose], st: &Stencils) -> DVec3 {
    debug_assert_eq!(st.order, 2);
    let mut s = DMat3::ZERO;
    let mut g = DVec3::ZERO;
    for (k, row) in st.rows.iter().enumerate() {
        let mut a = DMat3::ZERO;
        let mut b = DVec3::ZERO;
        for (j, w) in row.iter().enumerate().take(3) {
            let p = &poses[k + j];
            a += DMat3::from_quat(p.rotation) * *w;
            b += p.translation * *w;
        }
        s += a.transpose() * a;
        g += a.transpose() * b;
    }
    solve_normal(&s, g)
}

/// The point `c` of least residual: minimises what the translation spline at `lambda`
/// removes from the path `Q_i c + o_i`,
///
/// ```text
/// J(c) = sum_i h_i (Q_i c + o_i) . z_i(Q c + o),   z = (H + lambda M)^-1 lambda M y
/// ```
///
/// a quadratic in `c` (the spline is linear): `S c = -g` with `S_ab = <Q e_a, z(Q e_b)>_h`,
/// `g_a = <Q e_a, z(o)>_h`. Where the raw second differences are all noise (the estimate of
/// [`pivot`] then wanders by about `(sigma_t / sigma_r) / sqrt(n)`), this one also weighs
/// what the spline would have to remove of the motion itself: a point off the axis of a
/// tumbling body circles, and smoothing its path would cut the circle. Rigid motions of the
/// world leave `J` unchanged (the spline keeps constants), a change of body frame renames the
/// points: the minimiser is covariant like [`pivot`]'s. `columns` is scratch (4 paths).
/// The smoother must be prepared with the translation's penalty (the data are ignored);
/// `index` is the grid strength.
pub(crate) fn refine<const W: usize>(
    quats: &[DQuat],
    poses: &[Pose],
    st: &Stencils,
    index: usize,
    smoother: &mut Whittaker<W>,
    paths: &mut [Vec<DVec3>; 4],
    zs: &mut [Vec<DVec3>; 4],
) -> DVec3 {
    // Every path relative to its first sample: the spline keeps constants, so `J` is the
    // same (`<1, H z(y)> = lambda <M 1, x> = 0`), but large common offsets would leave
    // rounding of the solve (relative to `lambda` times the offset) that a rigid motion of
    // the world or of the body frame changes; without them the equations change with the
    // frames exactly as the pivot does, to rounding of the paths' own variation.
    for (v, axis) in paths.iter_mut().zip([DVec3::X, DVec3::Y, DVec3::Z]) {
        let first = quats[0] * axis;
        v.clear();
        v.extend(quats.iter().map(|q| *q * axis - first));
    }
    let o0 = poses[0].translation;
    paths[3].clear();
    paths[3].extend(poses.iter().map(|p| p.translation - o0));
    let inputs = [&paths[0][..], &paths[1][..], &paths[2][..], &paths[3][..]];
    if !smoother.corrections(index, &inputs, zs) {
        return DVec3::NAN;
    }
    let dot = |a: &[DVec3], b: &[DVec3]| -> f64 {
        a.iter()
            .zip(b)
            .zip(&st.weights)
            .map(|((x, y), h)| h * x.dot(*y))
            .sum()
    };
    let mut s = DMat3::ZERO;
    let mut g = DVec3::ZERO;
    for a in 0..3 {
        for b in 0..3 {
            // Symmetrised: K is symmetric, rounding is not.
            s.col_mut(b)[a] = 0.5 * (dot(&paths[a], &zs[b]) + dot(&paths[b], &zs[a]));
        }
        g[a] = dot(&paths[a], &zs[3]);
    }
    solve_normal(&s, g)
}

/// `-S^+ g` for a symmetric positive semi-definite `S`, leaving out eigenvalues below
/// [`PIVOT_RANK_TOLERANCE`] times the largest. NaN when not finite.
fn solve_normal(s: &DMat3, g: DVec3) -> DVec3 {
    if !(s.is_finite() && g.is_finite()) {
        return DVec3::NAN;
    }
    let rows: [[f64; 3]; 3] = std::array::from_fn(|i| std::array::from_fn(|j| s.col(j)[i]));
    let (values, vectors) = symmetric_eigen(&rows);
    let mut c = DVec3::ZERO;
    for (value, vector) in values.iter().zip(vectors.iter()) {
        if *value > PIVOT_RANK_TOLERANCE * values[0] && *value > 0.0 {
            let v = DVec3::from_array(*vector);
            c -= v * (v.dot(g) / value);
        }
    }
    c
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;

    #[test]
    fn finds_the_axis_of_a_screw_and_follows_the_body_frame() {
        let times: Vec<f64> = (0..20).map(|i| i as f64).collect();
        let st = Stencils::new(&times, 2).unwrap();
        // A screw about the axis through (1, 2, 0) along z, seen from a body frame whose
        // origin is at (1, 2, 0) + (0.5, 0, 0.3) in the world at t = 0.
        let axis_point = DVec3::new(1.0, 2.0, 0.0);
        let poses: Vec<Pose> = times
            .iter()
            .map(|t| {
                let rot = DQuat::from_rotation_z(0.2 * t);
                let origin = axis_point + rot * DVec3::new(0.5, 0.0, 0.3) + DVec3::Z * 0.05 * t;
                Pose::from_rotation_translation(rot, origin)
            })
            .collect();
        let c = pivot(&poses, &st);
        // The body point on the axis: body coordinates (-0.5, 0, z) for any z.
        assert!((c.x + 0.5).abs() < 1e-9 && c.y.abs() < 1e-9, "{c}");
        // Under a change of body frame H the pivot maps to H^-1 c.
        let h = Pose::from_rotation_translation(
            DQuat::from_rotation_x(0.4),
            DVec3::new(0.2, -1.0, 0.7),
        );
        let moved: Vec<Pose> = poses.iter().map(|p| p.mul_pose(&h)).collect();
        let c2 = pivot(&moved, &st);
        let back = h.transform_point3(c2);
        assert!((back.x + 0.5).abs() < 1e-9 && back.y.abs() < 1e-9, "{back}");
    }
}
