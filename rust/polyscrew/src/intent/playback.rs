//! An owner's transform channels as Blender plays them, and rotation channels as matrices.
//!
//! A *channel row* holds an owner's transform at one frame, in Blender's properties: location
//! `x, y, z`; the rotation in the owner's mode (`rotation_euler` `x, y, z` in radians,
//! `rotation_quaternion` `w, x, y, z` or `rotation_axis_angle` `angle, x, y, z`); scale
//! `x, y, z`: `6 + w` numbers, `w` the mode's [`RotationMode::width`].

use std::sync::atomic::{AtomicU64, Ordering};

use glam::DMat3;

use super::limits::{check_footprint, collected};
use crate::memory::try_reserve;
use crate::{Error, FCurve, Result, RotationMode};

/// One transform channel: a property and an index into it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Channel {
    /// `location[i]`, `i` in `0..3`.
    Location(usize),
    /// The rotation property of the owner's mode, index `i` in `0..width`.
    Rotation(usize),
    /// `scale[i]`, `i` in `0..3`.
    Scale(usize),
}

impl Channel {
    /// The channel of Blender's property `property` (`"location"`, `"scale"`, or the rotation
    /// property of `mode`: `"rotation_euler"`, `"rotation_quaternion"`,
    /// `"rotation_axis_angle"`) at `index`.
    ///
    /// # Errors
    /// [`Error::Choice`] for another property (a rotation property of another mode
    /// included), [`Error::Index`] for an index out of the property's range.
    pub fn from_property(property: &str, index: usize, mode: RotationMode) -> Result<Self> {
        let rotation = rotation_property(mode);
        let channel = match property {
            "location" => Self::Location(index),
            "scale" => Self::Scale(index),
            p if p == rotation => Self::Rotation(index),
            _ => {
                return Err(Error::Choice {
                    what: "property",
                    got: property.to_owned(),
                    expected: mode.transform_properties(),
                })
            }
        };
        channel.check(mode)?;
        Ok(channel)
    }

    /// Its place in a channel row of `mode`, for an index within its property
    /// ([`Channel::check`]; past it the column is another channel's, or saturates at
    /// `usize::MAX`).
    pub fn column(self, mode: RotationMode) -> usize {
        match self {
            Self::Location(i) => i,
            Self::Rotation(i) => i.saturating_add(3),
            Self::Scale(i) => i.saturating_add(3 + mode.width()),
        }
    }

    /// Checks that the index is within its property in `mode`: `0..3` for location and
    /// scale, `0..mode.width()` for the rotation.
    ///
    /// # Errors
    /// [`Error::Index`] naming the property and the range.
    pub fn check(self, mode: RotationMode) -> Result<()> {
        let (property, index, size) = match self {
            Self::Location(i) => ("location", i, 3),
            Self::Scale(i) => ("scale", i, 3),
            Self::Rotation(i) => (rotation_property(mode), i, mode.width()),
        };
        if index >= size {
            return Err(Error::Index {
                what: property,
                item: "index",
                at: None,
                index: i64::try_from(index).unwrap_or(i64::MAX),
                len: size,
            });
        }
        Ok(())
    }
}

/// Blender's rotation property of `mode` ([`RotationMode::property`]).
pub fn rotation_property(mode: RotationMode) -> &'static str {
    mode.property()
}

pub use crate::motion::channels::rotation_matrix;

/// [`rotation_matrix`] of every row of `values` (row-major, `N x width` numbers).
///
/// # Errors
/// [`Error::LengthMismatch`] when `values` is not a whole number of rows,
/// [`Error::NotFinite`] naming the first row holding NaN or infinity, and a request over the
/// size limit ([`check_footprint`]).
pub fn rotation_matrices(values: &[f64], mode: RotationMode) -> Result<Vec<DMat3>> {
    let width = mode.width();
    if values.len() % width != 0 {
        return Err(Error::LengthMismatch {
            what: "rotation values",
            expected: values.len() / width * width,
            got: values.len(),
        });
    }
    let n = values.len() / width;
    check_footprint(
        n.saturating_mul(std::mem::size_of::<DMat3>()),
        "rotation matrices",
        "pass fewer rotations",
    )?;
    if let Some(index) = values
        .chunks_exact(width)
        .position(|row| !row.iter().all(|x| x.is_finite()))
    {
        return Err(Error::NotFinite {
            what: "rotation",
            index,
        });
    }
    collected(
        n,
        values
            .chunks_exact(width)
            .map(|row| rotation_matrix(mode, row)),
        "rotation matrices",
    )
}

/// An owner's transform channels as Blender plays them: the keyed channels from their
/// F-curves (evaluated exactly as Blender's `FCurve.evaluate`), every other channel from the
/// owner's own value, location zero for an owner Blender does not move by it (a bone
/// connected to its parent).
///
/// It counts the channel rows it has evaluated ([`Playback::rows_evaluated`]): how often a
/// caller plays the same curves is observable (the add-on plays each owner's once per frame).
#[derive(Debug)]
pub struct Playback {
    curves: Vec<FCurve>,
    /// The channel-row column each curve drives.
    columns: Vec<usize>,
    /// A channel row of the owner's own values.
    statics: Vec<f64>,
    mode: RotationMode,
    located: bool,
    /// Channel rows evaluated so far (every call, every thread).
    evaluated: AtomicU64,
}

impl Clone for Playback {
    /// The same curves and values; its count of rows evaluated starts at 0.
    fn clone(&self) -> Self {
        Self {
            curves: self.curves.clone(),
            columns: self.columns.clone(),
            statics: self.statics.clone(),
            mode: self.mode,
            located: self.located,
            evaluated: AtomicU64::new(0),
        }
    }
}

impl PartialEq for Playback {
    /// The same curves, channels, values, mode and `located` (whatever each has evaluated).
    fn eq(&self, other: &Self) -> bool {
        self.curves == other.curves
            && self.columns == other.columns
            && self.statics == other.statics
            && self.mode == other.mode
            && self.located == other.located
    }
}

impl Playback {
    /// The playback of `curves`, curve `c` driving channel `channels[c]`; `statics` is a
    /// channel row of the owner's own values (used where no curve drives a channel);
    /// `located` is false for an owner whose location Blender ignores (its location is 0).
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `channels` and `curves`, or `statics` and the row
    /// width `6 + mode.width()`, differ in length; [`Error::Index`] inside [`Error::In`] for a
    /// channel whose index is outside its property ([`Channel::check`]), [`Error::Conflict`]
    /// when two curves drive one channel; [`Error::NotFinite`] for a static value that is not finite.
    pub fn new(
        curves: Vec<FCurve>,
        channels: &[Channel],
        statics: Vec<f64>,
        mode: RotationMode,
        located: bool,
    ) -> Result<Self> {
        if channels.len() != curves.len() {
            return Err(Error::LengthMismatch {
                what: "channels",
                expected: curves.len(),
                got: channels.len(),
            });
        }
        let width = 6 + mode.width();
        if statics.len() != width {
            return Err(Error::LengthMismatch {
                what: "static values",
                expected: width,
                got: statics.len(),
            });
        }
        if let Some(index) = statics.iter().position(|v| !v.is_finite()) {
            return Err(Error::NotFinite {
                what: "static value",
                index,
            });
        }
        for (c, channel) in channels.iter().enumerate() {
            channel.check(mode).map_err(|e| e.within("channel", c))?;
        }
        let columns: Vec<usize> = channels.iter().map(|c| c.column(mode)).collect();
        for (c, column) in columns.iter().enumerate() {
            if let Some(first) = columns[..c].iter().position(|o| o == column) {
                return Err(Error::Conflict {
                    what: "channels",
                    reason: format!(
                        "curves {first} and {c} drive the same channel {:?}",
                        channels[c]
                    ),
                });
            }
        }
        Ok(Self {
            curves,
            columns,
            statics,
            mode,
            located,
            evaluated: AtomicU64::new(0),
        })
    }

    /// How many channel rows (one frame each) this playback has evaluated since it was made,
    /// by every function that plays it ([`Playback::channels`], [`super::analyse_spans`],
    /// [`super::keys_parameters`], [`fn@super::departure`], ...).
    pub fn rows_evaluated(&self) -> u64 {
        self.evaluated.load(Ordering::Relaxed)
    }

    /// The owner's rotation mode.
    pub fn mode(&self) -> RotationMode {
        self.mode
    }

    /// Numbers per channel row: `6 + mode.width()`.
    pub fn width(&self) -> usize {
        self.statics.len()
    }

    /// Whether location moves the owner.
    pub fn located(&self) -> bool {
        self.located
    }

    /// The curves.
    pub fn curves(&self) -> &[FCurve] {
        &self.curves
    }

    /// The channel rows at `times` (any order, subframes allowed), row-major
    /// `times.len() x width()`: each keyed channel exactly Blender's value (`float32`,
    /// widened), the others the owner's own.
    ///
    /// # Errors
    /// [`Error::NotFinite`] for a time that is not finite in `float32`, [`Error::Evaluates`]
    /// for a value that is not finite (as [`crate::evaluate_fcurves`]), [`Error::Limit`] for a request over the
    /// size limit ([`check_footprint`]).
    pub fn channels(&self, times: &[f64]) -> Result<Vec<f64>> {
        check_footprint(
            times
                .len()
                .saturating_mul(self.width())
                .saturating_mul(std::mem::size_of::<f64>()),
            "channel values",
            "evaluate fewer frames",
        )?;
        let mut out = Vec::new();
        self.channels_into(times, &mut out)?;
        Ok(out)
    }

    /// [`Playback::channels`] into `out` (cleared first): the loops that evaluate span after
    /// span reuse one buffer. The caller has checked the size.
    pub(crate) fn channels_into(&self, times: &[f64], out: &mut Vec<f64>) -> Result<()> {
        self.rows_into(times, out, self.width())
    }

    /// [`Playback::channels_into`] for the pose alone: the scale channels keep the owner's
    /// own values (timing "Keys" measures travel, which scale does not enter).
    pub(crate) fn pose_channels_into(&self, times: &[f64], out: &mut Vec<f64>) -> Result<()> {
        self.rows_into(times, out, 3 + self.mode.width())
    }

    /// The channel rows at `times` into `out`, evaluating only the curves of the first
    /// `upto` columns.
    fn rows_into(&self, times: &[f64], out: &mut Vec<f64>, upto: usize) -> Result<()> {
        let width = self.width();
        out.clear();
        try_reserve(out, times.len().saturating_mul(width), "channel values")?;
        self.evaluated
            .fetch_add(times.len() as u64, Ordering::Relaxed);
        for (index, &t) in times.iter().enumerate() {
            let t32 = t as f32;
            if !t32.is_finite() {
                return Err(Error::NotFinite {
                    what: "time",
                    index,
                });
            }
            out.extend_from_slice(&self.statics);
            let row = &mut out[index * width..];
            // curves keyed together share their Bezier roots at one time
            let mut shared = None;
            for (c, (curve, &column)) in self.curves.iter().zip(&self.columns).enumerate() {
                if column >= upto {
                    continue;
                }
                let v = curve.evaluate_f32_sharing(t32, &mut shared);
                if !v.is_finite() {
                    return Err(Error::Evaluates {
                        curve: Some(c),
                        value: v.into(),
                        time: Some(index),
                        frame: t32.into(),
                    });
                }
                row[column] = v as f64;
            }
            if !self.located {
                row[..3].fill(0.0);
            }
        }
        Ok(())
    }

    /// The rotation matrix of a channel row (see [`rotation_matrix`]).
    pub fn rotation(&self, row: &[f64]) -> DMat3 {
        rotation_matrix(self.mode, row.get(3..).unwrap_or(&[]))
    }
}
