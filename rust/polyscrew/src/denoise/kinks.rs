//! Kinks: samples where the motion turns abruptly (a prop stopping against a wall, a foot
//! planting), which a smoothing spline would round off over its whole time scale.
//!
//! A kink shows in a pilot fit as a second divided difference far above the typical one. A
//! row `k` of second differences (centred on sample `k + 1`) is a kink when it is the
//! largest within [`KINK_WINDOW`] rows on either side and exceeds [`KINK_THRESHOLD`] times the
//! median of all rows. The penalty rows of order `m` around it are then released (weight 0):
//! the `m - 1` rows that have the sample strictly inside, and one more on the side of the
//! larger neighbour, so that a corner falling between two samples is let through too. Fewer
//! than `m + 1` consecutive rows are released, so no sample is ever cut loose from its
//! neighbours. Norms of rotation vectors and of world displacements are used, so the test is
//! coordinate-free.

use glam::DVec3;

use super::stencil::Stencils;

/// A kink's second difference exceeds this multiple of the median one (measured: no kink on
/// smooth clips from 3 up, the hard stop found from 3 to 10; the middle is taken).
pub(crate) const KINK_THRESHOLD: f64 = 6.0;

/// A kink is the largest second difference within this many rows on either side.
pub(crate) const KINK_WINDOW: usize = 3;

/// Second differences below this fraction of the path's extent (times the typical stencil
/// weight) are rounding, not kinks.
const ROUNDING_FLOOR: f64 = 1e-9;

/// Finds kinks in the pilot fit `x` (second-order stencils `st2`) and zeroes the weights `u`
/// of the order-`m` penalty rows around them. Returns the kinks' sample indices.
pub(crate) fn release(
    x: &[DVec3],
    st2: &Stencils,
    order: usize,
    u: &mut [f64],
    scratch: &mut Vec<f64>,
) -> Vec<usize> {
    debug_assert_eq!(st2.order, 2);
    let rows = st2.len();
    if rows == 0 {
        return Vec::new();
    }
    let mut r = Vec::with_capacity(rows);
    let mut weight = 0.0;
    for (k, row) in st2.rows.iter().enumerate() {
        let d = x[k] * row[0] + x[k + 1] * row[1] + x[k + 2] * row[2];
        r.push(d.length());
        weight += row[1].abs();
    }
    weight /= rows as f64;
    let first = x[0];
    let extent = x.iter().map(|p| (*p - first).length()).fold(0.0, f64::max);
    scratch.clear();
    scratch.extend_from_slice(&r);
    let mid = rows / 2;
    let median = *scratch.select_nth_unstable_by(mid, f64::total_cmp).1;
    let threshold = (KINK_THRESHOLD * median).max(ROUNDING_FLOOR * extent * weight);
    let mut kinks = Vec::new();
    for k in 0..rows {
        if r[k] <= threshold {
            continue;
        }
        let lo = k.saturating_sub(KINK_WINDOW);
        let hi = (k + KINK_WINDOW).min(rows - 1);
        // The largest in its window (ties go to the first).
        if (lo..=hi).any(|j| r[j] > r[k] || (r[j] == r[k] && j < k)) {
            continue;
        }
        let f = k + 1;
        kinks.push(f);
        let left = if k > 0 { r[k - 1] } else { 0.0 };
        let right = if k + 1 < rows { r[k + 1] } else { 0.0 };
        let extra = if right > left {
            f
        } else {
            f.wrapping_sub(order)
        };
        let inside = (f + 1).saturating_sub(order)..f;
        for row in inside.chain(std::iter::once(extra)) {
            if row < u.len() {
                u[row] = 0.0;
            }
        }
    }
    kinks
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_stop_is_found_and_released_and_a_smooth_path_is_not() {
        let times: Vec<f64> = (0..60).map(|i| i as f64).collect();
        let st2 = Stencils::new(&times, 2).unwrap();
        let mut scratch = Vec::new();
        let smooth: Vec<DVec3> = times
            .iter()
            .map(|t| DVec3::new((0.2 * t).sin(), 0.01 * t * t, 0.0))
            .collect();
        let mut u = vec![1.0; 57];
        assert!(release(&smooth, &st2, 3, &mut u, &mut scratch).is_empty());
        assert!(u.iter().all(|v| *v == 1.0));
        let stop: Vec<DVec3> = times
            .iter()
            .map(|t| DVec3::X * t.min(31.0) + DVec3::Y * 0.001 * (t * 1.3).sin())
            .collect();
        let kinks = release(&stop, &st2, 3, &mut u, &mut scratch);
        assert_eq!(kinks, vec![31]);
        let released: Vec<usize> = (0..u.len()).filter(|k| u[*k] == 0.0).collect();
        // Rows 29 and 30 have sample 31 inside; one more on one side.
        assert!(
            released.len() == 3 && released.contains(&29) && released.contains(&30),
            "{released:?}"
        );
    }
}
