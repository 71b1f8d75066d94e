//! Progress of a long computation and a request to stop it, shared across threads: the
//! computation reports the fraction it has done and looks for the request between parts of
//! its work; its caller, on another thread, reads the one and makes the other.

use std::sync::atomic::{AtomicBool, AtomicU32, Ordering};

use crate::{Error, Result};

/// The fraction done is kept in these steps.
const STEPS: f64 = 1_000_000.0;

/// The fraction of a computation done (0 to 1) and whether it was asked to stop.
#[derive(Debug, Default)]
pub struct Progress {
    done: AtomicU32,
    stop: AtomicBool,
}

impl Progress {
    /// Nothing done, not asked to stop.
    pub fn new() -> Self {
        Self::default()
    }

    /// The fraction done, 0 to 1: it does not decrease but when the computation starts over
    /// ([`Progress::restart`]).
    pub fn fraction(&self) -> f64 {
        f64::from(self.done.load(Ordering::Relaxed)) / STEPS
    }

    /// Asks the computation to stop: it returns [`Error::Cancelled`] at its next look.
    pub fn cancel(&self) {
        self.stop.store(true, Ordering::Relaxed);
    }

    /// Whether [`Progress::cancel`] was called.
    pub fn is_cancelled(&self) -> bool {
        self.stop.load(Ordering::Relaxed)
    }

    /// [`Error::Cancelled`] once [`Progress::cancel`] was called.
    ///
    /// # Errors
    /// [`Error::Cancelled`].
    pub fn check(&self) -> Result<()> {
        if self.is_cancelled() {
            Err(Error::Cancelled)
        } else {
            Ok(())
        }
    }

    /// Raises the fraction done to `fraction` (clamped to 0..=1); a lower one changes nothing.
    pub fn advance(&self, fraction: f64) {
        let steps = (fraction.clamp(0.0, 1.0) * STEPS) as u32;
        self.done.fetch_max(steps, Ordering::Relaxed);
    }

    /// Back to nothing done (the computation starts over).
    pub fn restart(&self) {
        self.done.store(0, Ordering::Relaxed);
    }

    /// The stretch of this progress from `from` to `to` (fractions of the whole).
    pub fn span(&self, from: f64, to: f64) -> Span<'_> {
        Span {
            progress: self,
            from,
            to,
        }
    }
}

/// A stretch of a [`Progress`]: a part of the computation reports its own fraction done.
#[derive(Debug, Clone, Copy)]
pub struct Span<'a> {
    progress: &'a Progress,
    from: f64,
    to: f64,
}

impl Span<'_> {
    /// The whole's fraction at this stretch's `fraction`.
    fn at(&self, fraction: f64) -> f64 {
        self.from + (self.to - self.from) * fraction
    }

    /// Raises the whole's fraction to this part's `fraction` (0 to 1) of its stretch.
    pub fn advance(&self, fraction: f64) {
        self.progress.advance(self.at(fraction.clamp(0.0, 1.0)));
    }

    /// The stretch from `from` to `to` of this one (fractions of it).
    pub fn part(&self, from: f64, to: f64) -> Self {
        Self {
            progress: self.progress,
            from: self.at(from),
            to: self.at(to),
        }
    }

    /// Whether the computation was asked to stop.
    pub fn is_cancelled(&self) -> bool {
        self.progress.is_cancelled()
    }

    /// [`Error::Cancelled`] once the computation was asked to stop.
    ///
    /// # Errors
    /// [`Error::Cancelled`].
    pub fn check(&self) -> Result<()> {
        self.progress.check()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spans_map_into_the_whole_and_the_fraction_never_decreases() {
        let p = Progress::new();
        let refine = p.span(0.2, 0.6).part(0.5, 1.0);
        refine.advance(0.5);
        assert!((p.fraction() - 0.5).abs() < 1e-6);
        p.span(0.0, 0.2).advance(1.0);
        assert!(
            (p.fraction() - 0.5).abs() < 1e-6,
            "lowered to {}",
            p.fraction()
        );
        refine.advance(7.0);
        assert!((p.fraction() - 0.6).abs() < 1e-6);
        p.restart();
        assert_eq!(p.fraction(), 0.0);
        assert!(p.check().is_ok() && !refine.is_cancelled());
        p.cancel();
        assert!(matches!(refine.check(), Err(Error::Cancelled)));
    }
}
