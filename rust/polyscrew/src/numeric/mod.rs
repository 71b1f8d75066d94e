//! Numeric kernels shared by the domains: no geometry of their own.
//!
//! [`fastmath`] holds `sin`/`cos` and the turn angle that `s(a, t, b)` needs (fdlibm's
//! polynomials by Estrin's scheme, generic over [`fastmath::Real`]); [`lanes`] runs them on
//! four `f64` lanes for batches (it depends on `fastmath`, not the other way round);
//! [`eigen`] is Jacobi's method for small symmetric matrices (registration, inertia points);
//! [`band`] is the one banded solver (`L D L^T` over scalar or 3x3-block entries, a fixed
//! half-bandwidth): the normal equations of the angular-velocity fit, the smoothing splines and
//! the rotation system of Remove Noise, and, with [`cyclic_band`]'s border of two unknowns on
//! top, the systems of variational subdivision (Hofer-Pottmann-Ravani, *From curve design algorithms to the design of rigid body motions*, eqs. 23-27).

pub(crate) mod band;
pub(crate) mod cyclic_band;
pub(crate) mod eigen;
pub(crate) mod fastmath;
pub(crate) mod lanes;
