//! # polyscrew
//!
//! Coordinate-free smoothing of rigid-body motions: the screw between two poses
//! (Rossignac-Kim), polyscrew subdivision by the 4-point, cubic B-spline and Jarek
//! Split&Tweak schemes (Powell-Rossignac, ScrewBender), a monotone C1 timing map from key
//! times to the motion parameter, and sampling of the subdivided motion at any time.
//! A second method designs motions from feature points (Hofer-Pottmann-Ravani,
//! [`feature_motion()`]): curve schemes, including Kobbelt's variational subdivision
//! ([`variational_subdivide`]), on the feature points' trajectories, then Horn's
//! registration ([`register`]) of the rigid body at every sample.
//!
//! The crate is grouped by domain, one module folder each:
//!
//! | module | what | source |
//! | --- | --- | --- |
//! | [`motion`] | poses, screws, Split&Tweak subdivision, timing, sampling, Blender rotation channels | Rossignac-Kim; Powell-Rossignac (ScrewBender) |
//! | [`sweep`](mod@sweep) | the region a mesh sweeps along a polyscrew | Rossignac-Kim, "Swept volumes" |
//! | [`feature`] | feature-point motion design: registration, inertia points, variational subdivision | Hofer-Pottmann-Ravani |
//! | [`angular_velocity`] | fitting a rotation to a sketched angular velocity | Xie-Xu-Yu-Weng |
//! | [`fcurve`] | Blender's F-curve evaluation (keys, easing, extrapolation, Cycles), exact and in batches | Blender's `fcurve.cc`, `easing.cc` |
//! | [`intent`] | what the animator meant between the keys: Blender's playback of an owner's channels, holds, pops, spins, the pace of timing "Keys" | ScrewBender issue 17 |
//! | [`reduce`](mod@reduce) | key reduction: the fewest Bezier keys whose Blender playback stays within a world-space tolerance | ScrewBender issue 26 |
//! | `numeric` (private) | sin/cos and lanes for `s`, small eigenproblems, one banded solver (`L D L^T`, scalar or 3x3-block entries, a cyclic border on top) | |
//!
//! Beside them, [`error`] holds the one error type and [`memory`] the memory rule: every
//! allocation whose size depends on input is checked against one budget before it is made.
//!
//! One home for each rule: the rotation modes are [`RotationMode`]'s
//! ([`motion::channels`]: the list [`RotationMode::ALL`], Blender's names, properties and
//! widths, channel values to matrices ([`motion::channels::rotation_matrix`]), matrices to
//! continuous channels ([`rotation_channels`]) or to channels written like a reference
//! ([`channels_near`]: quaternion signs, Euler twins, whole turns)); the turn between two
//! orientations and a move cut short are [`motion::moves`]'; the Python module exposes them
//! (`ROTATION_MODES`, `rotation_matrices`, `rotation_channels`, `rotation_channels_near`,
//! `turn_vectors`, `partial_moves`) and the add-on calls them. Adding a rotation mode touches
//! `motion/channels.rs` (its variant, [`RotationMode::ALL`], the name, property and width
//! matches, the three conversions) and the binding's `lib.rs` (the `RotationModeName` literal
//! of the generated stub). Adding a timing mode like [`Timing::Smooth`] or [`Timing::Linear`]
//! touches `motion/timing.rs` (the variant, [`Timing::from_name`], the slopes of
//! [`TimeMap`]), the binding's `lib.rs` (`TimingName`) and the add-on's option list
//! (`bake_ops.py`); timing "Keys" is still its own path ([`intent::keys_parameters`]).
//!
//! What users reach for is re-exported here.
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
pub mod denoise;
pub mod error;
pub mod fcurve;
pub mod feature;
pub mod intent;
pub mod memory;
pub mod motion;
pub(crate) mod numeric;
pub mod reduce;
pub mod sweep;

pub use angular_velocity::{
    fit_angular_velocity, AngularVelocityFit, AngularVelocityTarget, FitOptions, FitStatus,
    QuatJet, QuatSpline,
};
pub use denoise::{denoise, denoise_batch, DenoiseOptions, Denoised, Strength};
pub use error::{At, Error, Expected, PoseDefect, Result};
pub use fcurve::{
    evaluate_fcurves, CycleMode, Cycles, Easing, Extrapolation, FCurve, Interpolation, Key,
    PackedCurves,
};
pub use feature::inertia::InertiaFrame;
pub use feature::motion::{
    feature_motion, feature_motion_timed, sample_feature_motion, CurveScheme, FeatureSpec,
    UNIT_FRAME_POINTS,
};
pub use feature::registration::register;
pub use feature::variational::{
    variational_curve, variational_subdivide, Parametrization, Stiffness,
};
pub use intent::{
    analyse_spans, keys_parameters, rotation_matrices, rotation_matrix, timed_frames, Channel,
    KeysTiming, PaceSource, Playback, Spans, Timed,
};
pub use memory::{memory_budget, set_memory_budget, Footprint, DEFAULT_MEMORY_BUDGET};
pub use motion::channels::{
    angles_near, channels_near, rotation_channels, same_rotation_map, EulerOrder, RotationMode,
    MAX_PREVIOUS_ANGLE, MAX_ROTATIONS,
};
pub use motion::moves::{direction_steps, partial_moves, turn_vectors, MoveBounds};
pub use motion::pose::{poses_from_rows, Pose, RIGID_TOLERANCE};
pub use motion::sample::{sample, Motion, MotionSpec};
pub use motion::screw::{midpoint, s, s_many, Screw};
pub use motion::subdivision::{
    subdivide, subdivided_len, Interpolant, Scheme, MAX_LEVELS, MIN_POSES,
};
pub use motion::timing::{check_key_times, TimeMap, Timing};
pub use reduce::{
    reduce_keys, Between, Group, HandleType, ReduceInput, ReduceOptions, Reduced, ReducedCurve,
    ReducedKey, Tolerance,
};
pub use sweep::{sweep, sweep_mesh, Body, Generator, SweepOptions, SweptMesh};
