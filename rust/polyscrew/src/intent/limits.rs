//! The sizes this module may allocate, checked in one place ([`check_footprint`]) before
//! anything input-sized is allocated: the add-on runs inside the user's Blender session, and
//! a request too large for memory must be an error, not an abort. (When the crate gets one
//! memory budget, this function is where the module asks it.)

use crate::error::{Error, Result};

/// Most bytes one call of this module may hold for its samples, channel values and output:
/// 1 GiB. The largest legitimate use, timing "Keys" over a 100,000-frame bake, holds about
/// 10 MB; a spin analysed at [`MAX_SPAN_SAMPLES`](super::MAX_SPAN_SAMPLES) samples per span
/// holds about 400 kB per span.
pub const MAX_BYTES: usize = 1 << 30;

/// Checks that `bytes` (computed with saturating arithmetic) fit within [`MAX_BYTES`].
///
/// # Errors
/// [`Error::Invalid`] naming `what` would be allocated, its size and `hint` (how to ask for
/// less).
pub fn check_footprint(bytes: usize, what: &'static str, hint: &'static str) -> Result<()> {
    if bytes > MAX_BYTES {
        return Err(Error::Invalid {
            what,
            reason: format!(
                "would need {bytes} bytes, more than the limit of {MAX_BYTES} in one call: {hint}"
            ),
        });
    }
    Ok(())
}
