//! The map from time (frames) to the motion parameter `u` (key `i` at `u = i`).
//!
//! ScrewBender section 1: keys sit at arbitrary times; a C1 piecewise cubic `p` with
//! `p(t_i) = i` resynchronises the uniformly parameterised motion with them. We use the
//! monotone cubic Hermite interpolant with Fritsch-Butland slopes (the weighted harmonic mean
//! of the neighbouring secants, as in PCHIP): it is C1, strictly increasing whenever the key
//! times are, and exactly linear when the keys are evenly spaced.

#![allow(clippy::neg_cmp_op_on_partial_ord)] // `!(x > y)` also catches NaN

use crate::error::{At, Error, Result};

/// The working range of times (key times, sample times, the end of a closed motion's
/// period): `|t| <= MAX_TIME`.
///
/// Why `1e300`: the time map uses times only through differences (at most `4e300` with a
/// period), their ratios and the reciprocal of a sum of two key spacings; no time is
/// squared, so any range short of `f64::MAX / 4` keeps it finite.
pub const MAX_TIME: f64 = 1e300;

/// The smallest spacing of consecutive key times (and of the last key and the end of a
/// closed motion's period): the slopes of the time map are `3 / (h_prev + h)` at most, finite
/// for spacings down to about `2e-308`; `1e-300` leaves room.
pub const MIN_KEY_SPACING: f64 = 1e-300;

/// How time maps to the motion parameter between keys.
///
/// Adding a timing mode: its variant, its entry in [`Timing::ALL`], its [`name`](Self::name)
/// and [`paced`](Self::paced), and (a map of time alone) the slopes and the parameter of
/// [`TimeMap`], all in this file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Timing {
    /// The monotone C1 cubic: velocity stays continuous across unevenly spaced keys.
    #[default]
    Smooth,
    /// Each key span mapped linearly: speed jumps where key spacing changes.
    Linear,
    /// The pace of Blender's own playback of the keys: a frame gets the parameter at which
    /// the smoothed motion has travelled the same fraction of its span as the playback has
    /// ([`crate::intent::keys_parameters`]). Not a map of time alone: it needs the body's
    /// size and the playback ([`paced`](Self::paced)), so [`TimeMap`] refuses it and
    /// [`crate::intent::timed_frames`] turns it into parameters sampled with linear timing.
    Keys,
}

impl Timing {
    /// Every timing, in the order the add-on lists them.
    pub const ALL: [Self; 3] = [Self::Smooth, Self::Linear, Self::Keys];

    /// [`name`](Self::name) of every timing of [`ALL`](Self::ALL), in its order (the
    /// variants' order).
    pub const NAMES: [&'static str; 3] = ["smooth", "linear", "keys"];

    /// The timing's name: `"smooth"`, `"linear"`, `"keys"`.
    pub const fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// Whether the timing follows the pace of a playback (it needs the body's size and the
    /// playback, not only the key times): [`Timing::Keys`].
    pub const fn paced(self) -> bool {
        matches!(self, Self::Keys)
    }

    /// Parses a name of [`Timing::NAMES`].
    ///
    /// # Errors
    /// [`Error::Choice`] for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|timing| timing.name() == name)
            .ok_or_else(|| Error::Choice {
                what: "timing",
                got: name.to_owned(),
                expected: &Self::NAMES,
            })
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

/// Checks that key times are finite, strictly increasing, within [`MAX_TIME`] and at least
/// [`MIN_KEY_SPACING`] apart.
///
/// # Errors
/// [`Error::KeyTimes`] with the index of the first time that is not finite or not greater
/// than the one before, [`Error::OutOfRange`] for a time beyond [`MAX_TIME`],
/// [`Error::Spacing`] (`"key times"`) for two keys closer than [`MIN_KEY_SPACING`].
pub fn check_key_times(times: &[f64]) -> Result<()> {
    for (i, t) in times.iter().enumerate() {
        if !t.is_finite() || (i > 0 && *t <= times[i - 1]) {
            return Err(Error::KeyTimes { index: i });
        }
        if t.abs() > MAX_TIME {
            return Err(Error::OutOfRange {
                what: "key time",
                index: i,
                value: *t,
                limit: MAX_TIME,
            });
        }
        if i > 0 && *t - times[i - 1] < MIN_KEY_SPACING {
            return Err(Error::Spacing {
                what: "key times",
                at: At::new("key time", i),
                gap: *t - times[i - 1],
                min: MIN_KEY_SPACING,
            });
        }
    }
    Ok(())
}

/// Checks the period of a closed motion whose keys sit at `key_times` (at least two, checked
/// by [`check_key_times`]) and returns the cycle's end `t_0 + period`, a knot like the key
/// times: the period finite and longer than the keys' span `t_(n-1) - t_0`, the end within
/// [`MAX_TIME`] and at least [`MIN_KEY_SPACING`] after the last key.
///
/// # Errors
/// [`Error::Period`] for any other period (or fewer than two key times).
pub fn check_period(key_times: &[f64], period: f64) -> Result<f64> {
    let (first, last) = match key_times {
        [first, .., last] => (*first, *last),
        _ => return Err(Error::Period { period, span: 0.0 }),
    };
    let span = last - first;
    let end = first + period;
    if !period.is_finite()
        || period <= span
        || end.abs() > MAX_TIME
        || !(end - last >= MIN_KEY_SPACING)
    {
        return Err(Error::Period { period, span });
    }
    Ok(end)
}

/// Checks one sample time: finite and within [`MAX_TIME`].
///
/// # Errors
/// [`Error::NotFinite`] or [`Error::OutOfRange`] naming `what` and `index`.
#[inline]
pub fn check_time(what: &'static str, index: usize, t: f64) -> Result<()> {
    check_time_within(what, index, t, MAX_TIME)
}

/// Checks one time: finite and within `limit` (a domain's own bound, at most [`MAX_TIME`]).
///
/// # Errors
/// [`Error::NotFinite`] or [`Error::OutOfRange`] naming `what`, `index` and `limit`.
#[inline]
pub fn check_time_within(what: &'static str, index: usize, t: f64, limit: f64) -> Result<()> {
    if t.abs() <= limit {
        return Ok(());
    }
    if t.is_finite() {
        Err(Error::OutOfRange {
            what,
            index,
            value: t,
            limit,
        })
    } else {
        Err(Error::NotFinite { what, index })
    }
}

impl TimeMap {
    /// Builds the map for keys at `key_times`.
    ///
    /// For a closed motion `period` is the cycle length (key `n` is key `0` again at
    /// `t_0 + period`); `None` closes the cycle after the mean key spacing.
    ///
    /// # Errors
    /// [`Error::TooFew`] for fewer than 2 keys, [`Error::KeyTimes`] for times that are not
    /// strictly increasing, [`Error::Period`] for a period [`check_period`] refuses,
    /// [`Error::Conflict`] for a [`paced`](Timing::paced) timing (not a map of time alone).
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
        if timing.paced() {
            return Err(Error::Conflict {
                what: "timing",
                reason: format!(
                    "timing {} follows a playback's pace: it needs the body's size and the \
                     playback, not only the key times",
                    timing.name()
                ),
            });
        }
        let span = key_times[n - 1] - key_times[0];
        let mut knots = key_times.to_vec();
        let period = if closed {
            let period = period.unwrap_or(span * n as f64 / (n - 1) as f64);
            // The cycle's end, a knot like the others: in range and far enough from the last key.
            knots.push(check_period(key_times, period)?);
            Some(period)
        } else {
            None
        };
        let m = knots.len();
        let h: Vec<f64> = knots.windows(2).map(|w| w[1] - w[0]).collect();
        let secant = |k: usize| 1.0 / h[k];
        let harmonic = |k_prev: usize, k: usize| {
            // Fritsch-Butland: (w1 + w2) / (w1 / d_prev + w2 / d), w1 = 2 h + h_prev,
            // w2 = h + 2 h_prev; bounded by 3 min(d_prev, d), hence monotone. With
            // s = h_prev + h, a = h / s, b = h_prev / s (a + b = 1) it is 3 / (s (1 + 2 a b)):
            // no product of two spacings, so it stays finite for spacings near 1e-300 and
            // 1e300 alike.
            let (hp, hk) = (h[k_prev], h[k]);
            let sum = hp + hk;
            let (a, b) = (hk / sum, hp / sum);
            3.0 / (sum * (1.0 + 2.0 * a * b))
        };
        let slopes = match timing {
            Timing::Linear | Timing::Keys => vec![0.0; m],
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
    /// range (`u` clamped to `[0, n - 1]`); closed motions repeat with the period. A NaN
    /// time gives 0 (callers check times first, see [`check_time`]).
    pub fn parameter(&self, t: f64) -> f64 {
        let t0 = self.knots[0];
        let t = match self.period {
            Some(p) => t0 + (t - t0).rem_euclid(p),
            None => t,
        };
        let last = self.knots.len() - 1;
        if !(t > t0) {
            return 0.0;
        }
        if t >= self.knots[last] {
            return last as f64;
        }
        // Knot interval k with knots[k] <= t < knots[k + 1] (t0 < t < knots[last]).
        let k = (self.knots.partition_point(|&x| x <= t).max(1) - 1).min(last - 1);
        let h = self.knots[k + 1] - self.knots[k];
        let s = (t - self.knots[k]) / h;
        let u = match self.timing {
            Timing::Linear | Timing::Keys => s,
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
    fn every_timing_parses_its_own_name_and_only_keys_is_paced() {
        assert_eq!(Timing::NAMES, ["smooth", "linear", "keys"]);
        for (i, timing) in Timing::ALL.into_iter().enumerate() {
            assert_eq!(timing as usize, i);
            assert_eq!(Timing::from_name(timing.name()), Ok(timing));
            assert_eq!(timing.paced(), timing == Timing::Keys, "{timing:?}");
        }
        let err = Timing::from_name("cubic").unwrap_err();
        assert_eq!(
            err.to_string(),
            "timing: \"cubic\" is not one of \"smooth\", \"linear\", \"keys\""
        );
        assert!(matches!(
            TimeMap::new(&[0.0, 1.0], false, None, Timing::Keys),
            Err(Error::Conflict { what: "timing", .. })
        ));
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
