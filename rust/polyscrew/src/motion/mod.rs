//! The screw motion: rigid poses, the screw between two poses, polyscrew subdivision, the
//! time map from key frames to the motion parameter, sampling at any time, and Blender's
//! rotation channels.
//!
//! Sources: Rossignac-Kim, *Computing and visualizing pose-interpolating 3D motions*
//! (section "Screw motions": the minimal-angle screw `M` with `L1 = M L0` and
//! `s(L0, t, L1) = M^t L0`); Powell-Rossignac, *ScrewBender: Smoothing Piecewise Helical Motions* (section 4, formulation
//! A: the 4-point, cubic B-spline and Jarek Split&Tweak rules; section 1: the timing map).
//!
//! [`pose`] validates rigid poses, [`screw`] computes screws and `s`, [`subdivision`] refines
//! polyscrews (and polygons) by Split&Tweak, [`timing`] maps frames to the parameter,
//! [`sample`] evaluates the subdivided motion at any time, [`channels`] turns rotations into
//! Blender's quaternion, axis-angle and Euler channels, continuous frame to frame (and owns
//! the rotation modes: names, properties, widths, conversions), [`moves`] measures turns
//! between orientations and cuts moves short.

pub mod channels;
pub mod moves;
pub mod pose;
pub mod sample;
pub mod screw;
pub mod subdivision;
pub mod timing;
