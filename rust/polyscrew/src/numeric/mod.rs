//! Numeric kernels shared by the domains: no geometry of their own.
//!
//! [`fastmath`] holds `sin`/`cos` and the turn angle that `s(a, t, b)` needs (fdlibm's
//! polynomials by Estrin's scheme, generic over [`fastmath::Real`]); [`lanes`] runs them on
//! four `f64` lanes for batches (it depends on `fastmath`, not the other way round);
//! [`eigen`] is Jacobi's method for small symmetric matrices (registration, inertia points);
//! [`banded`] and [`cyclic_band`] solve the banded systems of spline fits and of variational
//! subdivision (Hofer-Pottmann-Ravani, *From curve design algorithms to the design of rigid body motions*, eqs. 23-27).

pub(crate) mod band;
pub(crate) mod banded;
pub(crate) mod cyclic_band;
pub(crate) mod eigen;
pub(crate) mod fastmath;
pub(crate) mod lanes;
