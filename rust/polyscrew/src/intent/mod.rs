//! What the animator meant between the keys, read from Blender's playback of an owner's
//! transform curves: spins, holds and pops, and the pace of Blender's own interpolation
//! (timing "Keys"). The numeric part of the add-on's `intent.py` and `sampling.py`, one call
//! per owner instead of a pipeline of small array operations.
//!
//! - [`Playback`]: an owner's transform channels as Blender plays them (location, rotation in
//!   its [`RotationMode`](crate::RotationMode), scale): its [`FCurve`](crate::FCurve)s
//!   evaluated exactly as Blender does ([`crate::fcurve`]), the owner's own values for the
//!   channels without a curve; [`rotation_matrix`] turns rotation channels into matrices with
//!   Blender's conventions (quaternions and axis-angle axes normalised, zero giving the
//!   identity; Euler `"XYZ"` meaning `R = Rz Ry Rx`).
//! - [`analyse_spans`]: per key span, whether it is **held** (every channel still over the
//!   span, within [`HOLD_TOLERANCE`]), whether the pose **pops** at its end, how far the
//!   rotation channels **turn** over it (the sum of the rotation angles between
//!   [`SPAN_SAMPLES`] or more consecutive samples of the playback), and the subframes where
//!   poses from the playback must be added so that no screw span of a **spin** (a span
//!   turning more than [`WIND_LIMIT`], and its neighbours turning more than [`WIND_STEP`])
//!   turns more than [`WIND_STEP`]. A screw between two key poses turns at most half a
//!   turn; with the added poses the smoothed motion turns as far and the same way as the
//!   channels. Quaternion channels keep the shortest arc (nothing is added). [`analyse_turns`]
//!   does the same under a [`Turns`] choice and tells the **flips** ([`turns`]: Euler wraps
//!   and quaternion sign flips, which Blender plays the long way round and [`Turns::Auto`]
//!   takes the short way) from the spins the animator typed.
//! - [`mod@departure`]: per frame, how far a smoothed result's channels are from the playback
//!   (distance of the origins, rotation angle), for the report; [`measure_departure`] gives
//!   the report's figures at once and compares with the rows [`keys_parameters_played`]
//!   has played already, so that each frame is played once.
//! - [`keys_parameters`]: timing "Keys". Within each span, the motion parameter of an output
//!   frame is the one at which the smoothed motion has travelled the same fraction of the
//!   span as Blender's playback has at that frame. Travel is the root mean square
//!   displacement of six points at `+-size` along the body's axes ([`travel`]),
//!   `sqrt(|dt|^2 + size^2 / 3 |dR|_F^2)`, summed over [`PACE_SAMPLES`] steps per span (and
//!   the output frames inside it) along both motions.
//! - [`sample_owner_channels`] ([`mod@batch`]): an owner's smoothed motion as Blender channels,
//!   piece after piece and hold after hold, each piece timed by [`timed_frames`]: what Smooth
//!   Motion bakes, many owners in one call of the binding; [`sample_owner_poses`] the same
//!   motion as rigid poses (what Insert Key on Motion keys and compares).
//!
//! Every size input can drive is checked in one place ([`limits`]) before it is allocated;
//! bad input is an [`Error`](crate::Error), never a panic.

pub mod batch;
pub mod departure;
pub(crate) mod interp;
pub mod limits;
pub mod many;
pub mod pace;
pub mod playback;
pub mod read;
pub mod spans;
pub mod turns;

#[cfg(test)]
mod departure_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod turns_tests;

pub use batch::{
    sample_owner_channels, sample_owner_poses, OwnerChannels, OwnerMotion, OwnerPoses, Segment,
};
pub use departure::{
    departure, measure_departure, measure_departures, measured_frames, Departure, DepartureLimits,
    DepartureOwner, DepartureSummary,
};
pub use many::{
    angles_near_many, channels_many, partial_moves_many, sample_many, AngleRun, MoveRun,
};
pub use pace::{
    keys_parameters, keys_parameters_played, pace_parameters, screw_pace_poses, timed_frames,
    travel, KeysTiming, PaceSource, Timed, DENSE_PACE_SAMPLES, PACE_SAMPLES,
};
pub use playback::{rotation_matrices, rotation_matrix, Channel, Playback};
pub use read::{key_frame_union, read_owners, OwnerKeys, OwnerRead, KEY_FRAME_TOLERANCE};
pub use spans::{
    analyse_spans, analyse_turns, Spans, HOLD_TOLERANCE, MAX_ANALYSIS_SAMPLES, MAX_SPAN_SAMPLES,
    SPAN_SAMPLES, WIND_LIMIT, WIND_STEP,
};
pub use turns::{is_euler_wrap, is_flip, is_sign_flip, Turns, RANGE_TOLERANCE, WRAP_MARGIN};
