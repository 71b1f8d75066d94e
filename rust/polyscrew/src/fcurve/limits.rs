//! The sizes an F-curve batch may reach, checked in one place ([`check_batch`]) before
//! anything is allocated: the add-on runs inside the user's Blender session, and a request
//! too large for memory must be an error, not an abort: after its own caps it asks the
//! crate's memory budget ([`crate::memory`]) for the keys and the values.

use crate::error::{Error, Result};
use crate::fcurve::Key;
use crate::memory::Footprint;

/// Most keys one batch may hold (all curves together): 2^26, about 67 million (each is
/// copied once into a 40-byte key).
pub const MAX_KEYS: usize = 1 << 26;

/// Most values one batch may produce (curves times times): 2^27, about 134 million
/// `float64`s (1 GiB).
pub const MAX_VALUES: usize = 1 << 27;

/// Checks a batch of `curves` curves holding `keys` keys in all, evaluated at `times` times,
/// against [`MAX_KEYS`] and [`MAX_VALUES`], then against the memory budget.
///
/// # Errors
/// [`Error::Invalid`] naming the size that is too large; [`Error::Memory`] over the budget.
pub fn check_batch(curves: usize, keys: usize, times: usize) -> Result<()> {
    if keys > MAX_KEYS {
        return Err(Error::Invalid {
            what: "keys",
            reason: format!("{keys} keys exceed the limit of {MAX_KEYS} in one call"),
        });
    }
    match curves.checked_mul(times) {
        Some(values) if values <= MAX_VALUES => Footprint::of::<Key>(keys)
            .and::<f64>(values)
            .check("the F-curve evaluation", "evaluate fewer curves or times in one call"),
        _ => Err(Error::Invalid {
            what: "times",
            reason: format!(
                "{curves} curves x {times} times exceed the limit of {MAX_VALUES} values in one call"
            ),
        }),
    }
}
