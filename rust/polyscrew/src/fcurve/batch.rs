//! Many curves at many times in one call, from packed arrays (what the binding and the
//! add-on's `keyframe_points.foreach_get` produce): the keys of all curves one after the
//! other, each curve a range of them.

use super::curve::{Extrapolation, FCurve};
use super::cycles::Cycles;
use super::key::{Easing, Interpolation, Key};
use super::limits::check_batch;
use crate::error::{At, Error, Expected, Result};
use crate::memory::try_vec;

/// The keys of `C` curves packed one curve after the other (`K` keys in all), as numbers and
/// codes: the layout of `polyscrew.evaluate_fcurves`.
///
/// Codes are indices into the name tables: [`Interpolation::NAMES`], [`Easing::NAMES`].
/// Numbers are rounded to `float32` (Blender's storage).
#[derive(Debug, Clone, Copy)]
pub struct PackedCurves<'a> {
    /// `C + 1` non-decreasing offsets from 0 to `K`: curve `c` owns keys
    /// `offsets[c]..offsets[c + 1]`.
    pub offsets: &'a [i64],
    /// `2 K` numbers: `(frame, value)` per key.
    pub co: &'a [f64],
    /// `2 K` numbers: the left handles.
    pub handle_left: &'a [f64],
    /// `2 K` numbers: the right handles.
    pub handle_right: &'a [f64],
    /// `K` interpolation codes.
    pub interpolation: &'a [i64],
    /// `K` easing codes.
    pub easing: &'a [i64],
    /// `K` BACK overshoots.
    pub back: &'a [f64],
    /// `K` ELASTIC amplitudes.
    pub amplitude: &'a [f64],
    /// `K` ELASTIC periods.
    pub period: &'a [f64],
    /// `C` extrapolations.
    pub extrapolation: &'a [Extrapolation],
    /// `C` Cycles modifiers (`None`: no modifier), or empty when no curve has one.
    pub cycles: &'a [Option<Cycles>],
}

impl PackedCurves<'_> {
    /// The number of curves `C`.
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Whether there are no curves.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Checks every length against `C` and `K` (the last offset).
    pub(crate) fn check_lengths(&self) -> Result<usize> {
        if self.offsets.is_empty() {
            return Err(Error::Count {
                what: "offsets (one per curve, plus one)",
                got: 0,
                need: 1,
            });
        }
        let c = self.len();
        if self.offsets[0] != 0 {
            return Err(Error::Value {
                what: "first offset",
                at: None,
                value: self.offsets[0] as f64,
                expected: Expected::OneOf(&[0.0]),
            });
        }
        for i in 1..self.offsets.len() {
            if self.offsets[i] < self.offsets[i - 1] {
                return Err(Error::Spacing {
                    what: "offsets",
                    at: At::new("offset", i),
                    gap: (self.offsets[i] - self.offsets[i - 1]) as f64,
                    min: 0.0,
                });
            }
        }
        let k = usize::try_from(self.offsets[c]).map_err(|_| Error::Value {
            what: "last offset",
            at: None,
            value: self.offsets[c] as f64,
            expected: Expected::NonNegative("offset"),
        })?;
        let lengths: [(&'static str, usize, usize); 10] = [
            ("co", self.co.len(), k.saturating_mul(2)),
            ("handle_left", self.handle_left.len(), k.saturating_mul(2)),
            ("handle_right", self.handle_right.len(), k.saturating_mul(2)),
            ("interpolation", self.interpolation.len(), k),
            ("easing", self.easing.len(), k),
            ("back", self.back.len(), k),
            ("amplitude", self.amplitude.len(), k),
            ("period", self.period.len(), k),
            ("extrapolation", self.extrapolation.len(), c),
            (
                "cycles",
                self.cycles.len(),
                if self.cycles.is_empty() { 0 } else { c },
            ),
        ];
        for (what, got, expected) in lengths {
            if got != expected {
                return Err(Error::LengthMismatch {
                    what,
                    expected,
                    got,
                });
            }
        }
        Ok(k)
    }

    /// The curves, validated (see [`FCurve::new`]; errors name the curve and the key).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] for an array of the wrong length; [`Error::Count`],
    /// [`Error::Value`] or [`Error::Spacing`] for bad offsets; [`Error::Limit`] for a batch
    /// over the size limits ([`check_batch`]); inside [`Error::In`] naming the curve and the
    /// key, [`Error::Index`] for an unknown code and the errors of [`FCurve::new`];
    /// [`Error::Memory`] when the curves exceed the memory budget or the allocator refuses.
    pub fn to_curves(&self) -> Result<Vec<FCurve>> {
        let k = self.check_lengths()?;
        check_batch(self.len(), k, 0)?;
        let f = |v: f64| v as f32;
        let mut curves = try_vec(self.len(), "F-curves")?;
        for c in 0..self.len() {
            // Offsets are checked: non-negative, non-decreasing, ending at k.
            let (lo, hi) = (self.offsets[c] as usize, self.offsets[c + 1] as usize);
            let mut keys = try_vec(hi - lo, "F-curve keys")?;
            for i in lo..hi {
                let code_err = |e: Error| e.within("key", i - lo).within("curve", c);
                keys.push(Key {
                    co: [f(self.co[2 * i]), f(self.co[2 * i + 1])],
                    handle_left: [f(self.handle_left[2 * i]), f(self.handle_left[2 * i + 1])],
                    handle_right: [f(self.handle_right[2 * i]), f(self.handle_right[2 * i + 1])],
                    interpolation: Interpolation::from_code(self.interpolation[i])
                        .map_err(code_err)?,
                    easing: Easing::from_code(self.easing[i]).map_err(code_err)?,
                    back: f(self.back[i]),
                    amplitude: f(self.amplitude[i]),
                    period: f(self.period[i]),
                });
            }
            let cycles = self.cycles.get(c).copied().flatten();
            curves.push(FCurve::labelled(
                keys,
                self.extrapolation[c],
                cycles,
                Some(c),
            )?);
        }
        Ok(curves)
    }
}

/// Every curve at every time: `out[c * times.len() + i]` is curve `c` at `times[i]`
/// (row-major `(C, T)`), each exactly Blender's `FCurve.evaluate(times[i])` (see
/// [`FCurve::evaluate`]). Times may be in any order; each is rounded to `float32` once.
/// `O(K + C T log K)`.
///
/// # Errors
/// [`Error::Limit`] for a batch over the size limits ([`check_batch`]), [`Error::Evaluates`]
/// for a value that is not finite (naming the curve and the time), [`Error::NotFinite`] for a time that is not
/// finite in `float32`, [`Error::Memory`] when the evaluation exceeds the memory budget
/// ([`check_batch`]: the curves, the times and the values) or the allocator refuses.
pub fn evaluate_fcurves(curves: &[FCurve], times: &[f64]) -> Result<Vec<f64>> {
    let keys = curves.iter().map(|c| c.keys().len()).sum();
    check_batch(curves.len(), keys, times.len())?;
    let mut t32 = try_vec(times.len(), "F-curve times")?;
    for (index, &t) in times.iter().enumerate() {
        let t = t as f32;
        if !t.is_finite() {
            return Err(Error::NotFinite {
                what: "time",
                index,
            });
        }
        t32.push(t);
    }
    let mut out = try_vec(curves.len() * times.len(), "F-curve values")?;
    for (c, curve) in curves.iter().enumerate() {
        for (i, &t) in t32.iter().enumerate() {
            let v = curve.evaluate_f32(t);
            if !v.is_finite() {
                return Err(Error::Evaluates {
                    curve: Some(c),
                    value: v.into(),
                    time: Some(i),
                    frame: t.into(),
                });
            }
            out.push(v as f64);
        }
    }
    Ok(out)
}

/// [`PackedCurves::to_curves`] and [`evaluate_fcurves`] in one call: `(C, T)` row-major.
///
/// # Errors
/// As both.
pub fn evaluate_packed(curves: &PackedCurves<'_>, times: &[f64]) -> Result<Vec<f64>> {
    let k = curves.check_lengths()?;
    check_batch(curves.len(), k, times.len())?;
    evaluate_fcurves(&curves.to_curves()?, times)
}
