//! Angular-velocity editing (Xie, Xu, Yu, Weng, *Sketch-based rotation editing*,
//! section 2): a Hermite quaternion spline through key orientations is refitted so that its
//! angular velocity `omega = 2 q' q^-1` follows a sketched target, with chosen keys held
//! exactly and variable frames inserted where the fit stays poor.
//!
//! [`quat_spline`] is the spline and its angular velocity; [`fit`] the energy, its
//! Levenberg-Marquardt minimisation and the variable-frame insertion. Everything of [`fit`]
//! is re-exported here.

pub mod fit;
pub mod quat_spline;

/// The paper's spinning top: a test fixture, not part of the library.
#[cfg(test)]
#[path = "../../tests/fixtures/spinning_top.rs"]
mod spinning_top;

pub use fit::*;
pub use quat_spline::{QuatJet, QuatSpline};
