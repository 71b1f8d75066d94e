//! Motion design from feature points (Hofer-Pottmann-Ravani, *From curve design algorithms
//! to the design of rigid body motions*): run a curve scheme on the homologous
//! positions of a body's feature points (section 3), then register the rigid body to the
//! distorted points at every sample (Horn's quaternion method, section 2).
//!
//! [`motion`] is the method itself; [`registration`] the least-squares rigid fit (section 2);
//! [`inertia`] the six inertia points and the four-point affine shortcut (sections 2.1 and
//! 4.3); [`variational`] Kobbelt's variational subdivision, interpolating and approximating,
//! uniform and non-uniform (sections 4.1-4.2).

pub mod inertia;
pub mod motion;
pub mod registration;
pub mod variational;
