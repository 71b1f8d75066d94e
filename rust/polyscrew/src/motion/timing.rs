//! The map from time (frames) to the motion parameter `u` (key `i` at `u = i`).
//!
//! ScrewBender section 1: keys sit at arbitrary times; a C1 piecewise cubic `p` with
//! `p(t_i) = i` resynchronises the uniformly parameterised motion with them. We use the
//! monotone cubic Hermite interpolant with Fritsch-Butland slopes (the weighted harmonic mean
//! of the neighbouring secants, as in PCHIP): it is C1, strictly increasing whenever the key
//! times are, and exactly linear when the keys are evenly spaced.

use crate::error::{Error, Result};

/// How time maps to the motion parameter between keys.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Timing {
    /// The monotone C1 cubic: velocity stays continuous across unevenly spaced keys.
    #[default]
    Smooth,
    /// Each key span mapped linearly: speed jumps where key spacing changes.
    Linear,
}

impl Timing {
    /// Parses `"smooth"` or `"linear"`.
    ///
    /// # Errors
    /// [`Error::Invalid`] for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "smooth" => Ok(Self::Smooth),
            "linear" => Ok(Self::Linear),
            _ => Err(Error::Invalid {
                what: "timing",
                reason: format!("{name:?} is not one of \"smooth\", \"linear\""),
            }),
        }
    }
}

/// A monotone map from time to motion parameter, built from key times.
#[derive(Debug, Clone, PartialEq)]
pub struct TimeMap {
    /// Knot times: the key times, plus `t_0 + period` for a closed motion.
    knots: Vec<f64>,
    /// `du/dt` at each knot (all equal to the local secant for linear timing).
    slopes: Vec<f64>,
    timing: Timing,
    /// Cycle length for a closed motion.
    period: Option<f64>,
}

/// Checks that key times are finite and strictly increasing.
///
/// # Errors
/// [`Error::KeyTimes`] with the index of the first offending time.
pub fn check_key_times(times: &[f64]) -> Result<()> {
    for (i, t) in times.iter().enumerate() {
        if !t.is_finite() || (i > 0 && *t <= times[i - 1]) {
            return Err(Error::KeyTimes { index: i });
        }
    }
    Ok(())
}

impl TimeMap {
    /// Builds the map for keys at `key_times`.
    ///
    /// For a closed motion `period` is the cycle length (key `n` is key `0` again at
    /// `t_0 + period`); `None` closes the cycle after the mean key spacing.
    ///
    /// # Errors
    /// [`Error::TooFew`] for fewer than 2 keys, [`Error::KeyTimes`] for times that are not
    /// strictly increasing, [`Error::Period`] for a period not exceeding the keys' span.
    pub fn new(
        key_times: &[f64],
        closed: bool,
        period: Option<f64>,
        timing: Timing,
    ) -> Result<Self> {
        let n = key_times.len();
        if n < 2 {
            return Err(Error::TooFew { got: n, need: 2 });
        }
        check_key_times(key_times)?;
        let span = key_times[n - 1] - key_times[0];
        let mut knots = key_times.to_vec();
        let period = if closed {
            let period = period.unwrap_or(span * n as f64 / (n - 1) as f64);
            if !period.is_finite() || period <= span {
                return Err(Error::Period { period, span });
            }
            knots.push(key_times[0] + period);
            Some(period)
        } else {
            None
        };
        let m = knots.len();
        let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
        let secant = |k: usize| 1.0 / h[k];
        let harmonic = |k_prev: usize, k: usize| {
            // Fritsch-Butland: (w1 + w2) / (w1 / d_prev + w2 / d), w1 = 2 h + h_prev,
            // w2 = h + 2 h_prev; bounded by 3 min(d_prev, d), hence monotone.
            let (hp, hk) = (h[k_prev], h[k]);
            let (w1, w2) = (2.0 * hk + hp, hk + 2.0 * hp);
            (w1 + w2) / (w1 * hp + w2 * hk)
        };
        let slopes = match timing {
            Timing::Linear => vec![0.0; m],
            Timing::Smooth => (0..m)
                .map(|i| {
                    if closed {
                        // Knot m - 1 is knot 0 one period later: same slope.
                        let i = i % (m - 1);
                        harmonic((i + m - 2) % (m - 1), i)
                    } else if i == 0 {
                        secant(0)
                    } else if i == m - 1 {
                        secant(m - 2)
                    } else {
                        harmonic(i - 1, i)
                    }
                })
                .collect(),
        };
        Ok(Self {
            knots,
            slopes,
            timing,
            period,
        })
    }

    /// The number of key spans (`n - 1` open, `n` closed): `u` runs over `[0, spans]`.
    pub fn spans(&self) -> usize {
        self.knots.len() - 1
    }

    /// The motion parameter at time `t`. Open motions hold their end poses outside the keys'
    /// range (`u` clamped to `[0, n - 1]`); closed motions repeat with the period.
    pub fn parameter(&self, t: f64) -> f64 {
        let t0 = self.knots[0];
        let t = match self.period {
            Some(p) => t0 + (t - t0).rem_euclid(p),
            None => t,
        };
        let last = self.knots.len() - 1;
        if t <= t0 {
            return 0.0;
        }
        if t >= self.knots[last] {
            return last as f64;
        }
        // Knot interval k with knots[k] <= t < knots[k + 1].
        let k = self.knots.partition_point(|&x| x <= t) - 1;
        let h = self.knots[k + 1] - self.knots[k];
        let s = (t - self.knots[k]) / h;
        let u = match self.timing {
            Timing::Linear => s,
            Timing::Smooth => {
                // Cubic Hermite from 0 to 1 with end derivatives m h (in units of u per s).
                let (m0, m1) = (self.slopes[k] * h, self.slopes[k + 1] * h);
                let s2 = s * s;
                let s3 = s2 * s;
                (-2.0 * s3 + 3.0 * s2) + (s3 - 2.0 * s2 + s) * m0 + (s3 - s2) * m1
            }
        };
        k as f64 + u.clamp(0.0, 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_keys_map_linearly() {
        let map = TimeMap::new(&[0.0, 10.0, 20.0, 30.0], false, None, Timing::Smooth).unwrap();
        for t in [0.0, 3.0, 15.5, 29.0] {
            assert!((map.parameter(t) - t / 10.0).abs() < 1e-14, "t = {t}");
        }
        let closed = TimeMap::new(&[0.0, 10.0, 20.0], true, Some(30.0), Timing::Smooth).unwrap();
        assert!((closed.parameter(25.0) - 2.5).abs() < 1e-14);
        assert!((closed.parameter(35.0) - 0.5).abs() < 1e-14);
    }

    #[test]
    fn uneven_keys_monotone_and_c1() {
        let keys = [1.0, 2.0, 10.0, 11.0, 40.0];
        let map = TimeMap::new(&keys, false, None, Timing::Smooth).unwrap();
        for (i, t) in keys.iter().enumerate() {
            assert!((map.parameter(*t) - i as f64).abs() < 1e-14);
        }
        let dt = 1e-4;
        let mut prev = map.parameter(1.0);
        let mut t = 1.0 + dt;
        while t < 40.0 {
            let u = map.parameter(t);
            assert!(u > prev, "not increasing at {t}");
            prev = u;
            t += dt * 37.0;
        }
        // Derivative continuous at interior knots.
        for t in &keys[1..4] {
            let h = 1e-6;
            let left = (map.parameter(*t) - map.parameter(t - h)) / h;
            let right = (map.parameter(t + h) - map.parameter(*t)) / h;
            assert!(
                (left - right).abs() < 1e-4,
                "slope jump at {t}: {left} vs {right}"
            );
        }
    }

    #[test]
    fn errors() {
        assert!(matches!(
            TimeMap::new(&[0.0, 1.0, 1.0], false, None, Timing::Smooth),
            Err(Error::KeyTimes { index: 2 })
        ));
        assert!(matches!(
            TimeMap::new(&[0.0, 1.0], true, Some(0.5), Timing::Smooth),
            Err(Error::Period { .. })
        ));
        assert!(matches!(
            TimeMap::new(&[0.0, f64::NAN], false, None, Timing::Smooth),
            Err(Error::KeyTimes { index: 1 })
        ));
    }
}
