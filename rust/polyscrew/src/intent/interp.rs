//! Piecewise-linear interpolation through points with non-decreasing abscissae, exactly as
//! numpy's `interp` computes it (the add-on's pipeline this module replaces used it).

/// The value at `x` of the broken line through `(xp[i], fp[i])`, `xp` non-decreasing and as
/// long as `fp` (at least one point): `fp[0]` left of `xp[0]`, the last `fp` right of the
/// last `xp`; between, the segment from the last point with `xp[j] <= x`, `fp[j]` where `x`
/// equals `xp[j]` (so a vertical step takes its right value), and numpy's NaN fallbacks for
/// infinite slopes. NaN stays NaN.
pub(crate) fn interp(x: f64, xp: &[f64], fp: &[f64]) -> f64 {
    debug_assert!(!xp.is_empty() && xp.len() == fp.len());
    let n = xp.len();
    if x.is_nan() {
        return x;
    }
    if x > xp[n - 1] {
        return fp[n - 1];
    }
    if x < xp[0] {
        return fp[0];
    }
    // The last j with xp[j] <= x (x >= xp[0], so there is one).
    let j = xp.partition_point(|&v| v <= x) - 1;
    if j == n - 1 || xp[j] == x {
        return fp[j];
    }
    let slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j]);
    let mut y = slope * (x - xp[j]) + fp[j];
    if y.is_nan() {
        y = slope * (x - xp[j + 1]) + fp[j + 1];
        if y.is_nan() && fp[j] == fp[j + 1] {
            y = fp[j];
        }
    }
    y
}

#[cfg(test)]
mod tests {
    use super::interp;

    #[test]
    fn ends_steps_and_segments() {
        let xp = [0.0, 1.0, 1.0, 3.0];
        let fp = [0.0, 2.0, 5.0, 9.0];
        assert_eq!(interp(-1.0, &xp, &fp), 0.0);
        assert_eq!(interp(4.0, &xp, &fp), 9.0);
        assert_eq!(interp(3.0, &xp, &fp), 9.0);
        assert_eq!(interp(0.5, &xp, &fp), 1.0);
        assert_eq!(
            interp(1.0, &xp, &fp),
            5.0,
            "a vertical step takes its right value"
        );
        assert_eq!(interp(2.0, &xp, &fp), 7.0);
        assert!(interp(f64::NAN, &xp, &fp).is_nan());
        assert_eq!(interp(7.0, &[2.0], &[4.0]), 4.0);
    }
}
