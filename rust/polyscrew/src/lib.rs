//! # polyscrew
//!
//! Coordinate-free smoothing of rigid-body motions: the screw between two poses
//! (Rossignac-Kim), polyscrew subdivision by the 4-point, cubic B-spline and Jarek
//! Split&Tweak schemes (Powell-Rossignac, ScrewBender), a monotone C1 timing map from key
//! times to the motion parameter, and sampling of the subdivided motion at any time.
//! A second method designs motions from feature points (Hofer-Pottmann-Ravani,
//! [`feature_motion()`]): curve schemes, including Kobbelt's variational subdivision
//! ([`variational`]), on the feature points' trajectories, then Horn's registration
//! ([`registration`]) of the rigid body at every sample.
//!
//! Everything is `f64` (glam's `DVec3`, `DQuat`). Functions are pure and report bad input
//! through [`Error`], never by panicking.
//!
//! ```
//! use glam::{DQuat, DVec3};
//! use polyscrew::{Pose, Scheme, subdivide, s};
//!
//! let a = Pose::IDENTITY;
//! let b = Pose::from_rotation_translation(DQuat::from_rotation_z(1.0), DVec3::new(0.0, 0.0, 2.0));
//! let mid = s(&a, 0.5, &b);
//! assert!((mid.translation.z - 1.0).abs() < 1e-15); // a helix: half the slide at half the turn
//! let dense = subdivide(&[a, b, a], Scheme::Jarek, 3, true).unwrap();
//! assert_eq!(dense.len(), 24);
//! ```
#![deny(missing_docs)]

pub mod angular_velocity;
mod banded;
pub mod channels;
pub(crate) mod cyclic_band;
pub mod denoise;
pub mod eigen;
pub mod error;
pub mod fastmath;
pub mod feature_motion;
pub mod inertia;
mod lanes;
pub mod pose;
pub mod quat_spline;
pub mod registration;
pub mod sample;
pub mod screw;
pub mod spinning_top;
pub mod subdivision;
pub mod sweep;
pub mod timing;
pub mod variational;

pub use angular_velocity::{
    fit_angular_velocity, AngularVelocityFit, AngularVelocityTarget, FitFailure, FitOptions,
    FitStatus,
};
pub use channels::{rotation_channels, EulerOrder, RotationMode};
pub use denoise::{denoise, denoise_batch, DenoiseOptions, Denoised, Strength};
pub use error::{Error, PoseDefect, Result};
pub use feature_motion::{
    feature_motion, feature_motion_timed, sample_feature_motion, CurveScheme, FeatureSpec,
    UNIT_FRAME_POINTS,
};
pub use inertia::InertiaFrame;
pub use pose::{poses_from_rows, Pose, RIGID_TOLERANCE};
pub use quat_spline::{QuatJet, QuatSpline};
pub use registration::register;
pub use sample::{sample, Motion, MotionSpec};
pub use screw::{midpoint, s, s_many, Screw};
pub use spinning_top::SpinningTop;
pub use subdivision::{subdivide, subdivided_len, Interpolant, Scheme, MAX_LEVELS, MIN_POSES};
pub use sweep::{sweep, sweep_mesh, Body, Generator, SweepOptions, SweptMesh};
pub use timing::{check_key_times, TimeMap, Timing};
pub use variational::{variational_curve, variational_subdivide, Parametrization, Stiffness};
