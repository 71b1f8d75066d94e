//! The sizes an F-curve batch may reach, checked in one place ([`check_batch`]) before
//! anything is allocated: the add-on runs inside the user's Blender session, and a request
//! too large for memory must be an error, not an abort: after its own caps it asks the
//! crate's memory budget ([`crate::memory`]) for everything the evaluation holds at its peak
//! ([`batch_footprint`]).

use crate::error::{Error, Result};
use crate::fcurve::bezier::BezierSegment;
use crate::fcurve::{Cycles, Extrapolation, FCurve, Key};
use crate::memory::Footprint;

/// Most keys one batch may hold (all curves together): 2^26, about 67 million (each is
/// copied once into a 40-byte key).
pub const MAX_KEYS: usize = 1 << 26;

/// Most values one batch may produce (curves times times): 2^27, about 134 million
/// `float64`s (1 GiB).
pub const MAX_VALUES: usize = 1 << 27;

/// What evaluating `curves` curves holding `keys` keys in all at `times` times holds at its
/// peak: the prepared curves (an [`FCurve`] each, with its keys and the Bezier segments
/// between them, fewer than one per key), the times rounded to `float32` and the
/// `curves x times` values. Saturates instead of overflowing.
pub fn batch_footprint(curves: usize, keys: usize, times: usize) -> Footprint {
    Footprint::of::<FCurve>(curves)
        .and::<Key>(keys)
        .and::<Option<BezierSegment>>(keys)
        .and::<f32>(times)
        .and::<f64>(curves.saturating_mul(times))
}

/// What a caller holds when it copies a batch into the arrays of
/// [`PackedCurves`](crate::fcurve::PackedCurves): `curves + 1` offsets, per key the three
/// pairs (`co` and the handles), the two codes and the three easing parameters, per curve
/// its extrapolation and Cycles modifier. Saturates instead of overflowing.
pub fn packed_footprint(curves: usize, keys: usize) -> Footprint {
    Footprint::of::<i64>(curves.saturating_add(1))
        .and::<f64>(keys.saturating_mul(2 * 3 + 3))
        .and::<i64>(keys.saturating_mul(2))
        .and::<Extrapolation>(curves)
        .and::<Option<Cycles>>(curves)
}

/// Checks a batch of `curves` curves holding `keys` keys in all, evaluated at `times` times,
/// against [`MAX_KEYS`] and [`MAX_VALUES`], then its [`batch_footprint`] against the memory
/// budget.
///
/// # Errors
/// [`Error::Limit`] naming the size that is too large; [`Error::Memory`] over the budget.
pub fn check_batch(curves: usize, keys: usize, times: usize) -> Result<()> {
    check_batch_with(curves, keys, times, Footprint::ZERO)
}

/// [`check_batch`], with `extra` (what the caller holds besides: its copies of the input,
/// for example [`packed_footprint`]) counted against the budget too.
///
/// # Errors
/// As [`check_batch`].
pub fn check_batch_with(curves: usize, keys: usize, times: usize, extra: Footprint) -> Result<()> {
    if keys > MAX_KEYS {
        return Err(Error::Limit {
            what: "keys",
            counted: "keys",
            count: keys,
            limit: MAX_KEYS,
            hint: "",
        });
    }
    match curves.checked_mul(times) {
        Some(values) if values <= MAX_VALUES => (batch_footprint(curves, keys, times) + extra)
            .check(
                "the F-curve evaluation",
                "evaluate fewer curves or times in one call",
            ),
        _ => Err(Error::Limit {
            what: "times",
            counted: "values (curves x times)",
            count: curves.saturating_mul(times),
            limit: MAX_VALUES,
            hint: "evaluate fewer curves or times in one call",
        }),
    }
}
