//! The sizes this module allocates, checked in one place ([`check_footprint`]) before
//! anything input-sized is allocated: the add-on runs inside the user's Blender session, and
//! a request too large for memory must be an error, not an abort. The check asks the crate's
//! memory budget ([`crate::memory`]); the buffers are then allocated fallibly.

use crate::memory::try_vec;
use crate::{Footprint, Result};

/// Checks that `bytes` (computed with saturating arithmetic) fit within the memory budget.
///
/// # Errors
/// [`Error::Memory`](crate::Error::Memory) naming `what` would be allocated, its size and
/// `hint` (how to ask for less).
pub fn check_footprint(bytes: usize, what: &'static str, hint: &'static str) -> Result<()> {
    Footprint::bytes(bytes).check(what, hint)
}

/// `n` copies of `value`, allocated fallibly.
pub(crate) fn filled<T: Clone>(n: usize, value: T, what: &'static str) -> Result<Vec<T>> {
    let mut v = try_vec(n, what)?;
    v.resize(n, value);
    Ok(v)
}

/// The items of `items` (at most `n` of them expected), allocated fallibly.
pub(crate) fn collected<T>(
    n: usize,
    items: impl IntoIterator<Item = T>,
    what: &'static str,
) -> Result<Vec<T>> {
    let mut v = try_vec(n, what)?;
    v.extend(items);
    Ok(v)
}
