//! Remove Noise's and Reduce Keys' per-owner steps for many owners in one call: each is, to
//! the bit, the single-owner function called on each owner's part of the arrays in turn
//! ([`angles_near`], [`partial_moves`], [`sample`], [`Playback::channels`]), so that the
//! add-on makes one call per operator, not one per owner or curve. An error names the part
//! (`"part 3"`) it comes from.

use glam::DVec3;

use crate::error::{Error, Result};
use crate::intent::Playback;
use crate::memory::{try_vec, Footprint};
use crate::motion::channels::{angles_near, RotationMode, CHANNELS_HINT};
use crate::motion::moves::{partial_moves, MoveBounds};
use crate::motion::sample::{sample, MotionSpec, SAMPLE_HINT};
use crate::Pose;

/// Consecutive values of one curve for [`angles_near_many`]: `len` values of rotation
/// channel `channel` in `mode`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AngleRun {
    /// The rotation mode of the curve.
    pub mode: RotationMode,
    /// The rotation channel (0 to the mode's width - 1).
    pub channel: usize,
    /// How many values.
    pub len: usize,
}

/// Nothing when `lens` add up to `total`, else [`Error::LengthMismatch`] (`what`).
fn check_total(lens: impl Iterator<Item = usize>, total: usize, what: &'static str) -> Result<()> {
    let mut sum = 0usize;
    for len in lens {
        sum = sum.checked_add(len).ok_or(Error::LengthMismatch {
            what,
            expected: total,
            got: usize::MAX,
        })?;
    }
    if sum != total {
        return Err(Error::LengthMismatch {
            what,
            expected: total,
            got: sum,
        });
    }
    Ok(())
}

/// [`angles_near`] of every run of `values` (with the same rows of `reference`), the runs
/// taking the values in order: run `i` is one `angles_near(values[a..b], reference[a..b],
/// mode, channel)` call, so `v - round((v - r) / 2 pi) 2 pi` on an angle channel and `v`
/// otherwise, per value.
///
/// # Errors
/// [`Error::LengthMismatch`] when `reference` is not as long as `values` or the runs do not
/// add up to it, [`Error::In`] (`"part"`) for a channel outside its mode,
/// [`Error::Memory`] over the memory budget.
pub fn angles_near_many(values: &[f64], reference: &[f64], runs: &[AngleRun]) -> Result<Vec<f64>> {
    if reference.len() != values.len() {
        return Err(Error::LengthMismatch {
            what: "reference",
            expected: values.len(),
            got: reference.len(),
        });
    }
    check_total(runs.iter().map(|r| r.len), values.len(), "counts")?;
    Footprint::of::<f64>(values.len()).check("angles", CHANNELS_HINT)?;
    let mut out = try_vec(values.len(), "angles")?;
    let mut lo = 0;
    for (i, run) in runs.iter().enumerate() {
        if run.channel >= run.mode.width() {
            return Err(Error::Index {
                what: "channel",
                at: None,
                item: "rotation channel",
                index: i64::try_from(run.channel).unwrap_or(i64::MAX),
                len: run.mode.width(),
            }
            .within("part", i));
        }
        let hi = lo + run.len;
        out.extend(
            angles_near(&values[lo..hi], &reference[lo..hi], run.mode, run.channel)
                .map_err(|e| e.within("part", i))?,
        );
        lo = hi;
    }
    Ok(out)
}

/// The poses of one owner for [`partial_moves_many`]: `len` rows, the pivot and bounds of
/// its [`partial_moves`] call.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MoveRun {
    /// How many poses.
    pub len: usize,
    /// The point whose travel is bounded (body coordinates).
    pub pivot: DVec3,
    /// How far each pose may move.
    pub bounds: MoveBounds,
}

/// [`partial_moves`] of every run of `source` and `target` (same rows), each with its own
/// pivot and bounds: the poses and which were cut short, in order.
///
/// # Errors
/// [`Error::LengthMismatch`] when the runs do not add up to `source` or to `target`,
/// [`Error::In`] (`"part"`) for what [`partial_moves`] refuses in a run,
/// [`Error::Memory`] over the memory budget.
pub fn partial_moves_many(
    source: &[Pose],
    target: &[Pose],
    runs: &[MoveRun],
) -> Result<(Vec<Pose>, Vec<bool>)> {
    check_total(runs.iter().map(|r| r.len), source.len(), "counts")?;
    check_total(runs.iter().map(|r| r.len), target.len(), "target poses")?;
    Footprint::of::<Pose>(source.len())
        .and::<bool>(source.len())
        .check("moved poses", CHANNELS_HINT)?;
    let (mut poses, mut cut) = (
        try_vec(source.len(), "moved poses")?,
        try_vec(source.len(), "cut poses")?,
    );
    let mut lo = 0;
    for (i, run) in runs.iter().enumerate() {
        let hi = lo + run.len;
        let (p, c) = partial_moves(&source[lo..hi], &target[lo..hi], run.pivot, run.bounds)
            .map_err(|e| e.within("part", i))?;
        poses.extend(p);
        cut.extend(c);
        lo = hi;
    }
    Ok((poses, cut))
}

/// [`sample`] of many owners keyed at the same `key_times`, at the same `times`: `keys`
/// holds `owners` runs of `key_times.len()` poses, the result `owners` runs of
/// `times.len()` poses, run `i` one `sample(keys_i, key_times, times, spec)` call.
///
/// # Errors
/// [`Error::LengthMismatch`] when `keys` is not `owners * key_times.len()` long,
/// [`Error::In`] (`"part"`) for what [`sample`] refuses, [`Error::Memory`] over the
/// memory budget.
pub fn sample_many(
    keys: &[Pose],
    key_times: &[f64],
    times: &[f64],
    owners: usize,
    spec: &MotionSpec,
) -> Result<Vec<Pose>> {
    let k = key_times.len();
    let expected = owners.checked_mul(k).ok_or(Error::LengthMismatch {
        what: "keys",
        expected: usize::MAX,
        got: keys.len(),
    })?;
    if keys.len() != expected {
        return Err(Error::LengthMismatch {
            what: "keys",
            expected,
            got: keys.len(),
        });
    }
    let total = owners.saturating_mul(times.len());
    Footprint::of::<Pose>(total).check("sampled poses", SAMPLE_HINT)?;
    let mut out = try_vec(total, "sampled poses")?;
    for i in 0..owners {
        out.extend(
            sample(&keys[i * k..(i + 1) * k], key_times, times, spec)
                .map_err(|e| e.within("part", i))?,
        );
    }
    Ok(out)
}

/// [`Playback::channels`] of every playback at the same `times`: per playback, its rows
/// (`times.len()` rows of [`Playback::width`] numbers), one after the other.
///
/// # Errors
/// [`Error::In`] (`"part"`) for what [`Playback::channels`] refuses, [`Error::Memory`]
/// over the memory budget.
pub fn channels_many(playbacks: &[&Playback], times: &[f64]) -> Result<Vec<Vec<f64>>> {
    let mut out = try_vec(playbacks.len(), "channel values")?;
    for (i, playback) in playbacks.iter().enumerate() {
        out.push(playback.channels(times).map_err(|e| e.within("part", i))?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::motion::channels::EulerOrder;

    #[test]
    fn angles_near_many_is_one_call_per_run() {
        let values: Vec<f64> = (0..12).map(|i| 7.0 * (i as f64) - 30.0).collect();
        let reference: Vec<f64> = (0..12).map(|i| 0.3 * (i as f64)).collect();
        let runs = [
            AngleRun {
                mode: RotationMode::Euler(EulerOrder::Xyz),
                channel: 1,
                len: 5,
            },
            AngleRun {
                mode: RotationMode::Quaternion,
                channel: 0,
                len: 3,
            },
            AngleRun {
                mode: RotationMode::AxisAngle,
                channel: 0,
                len: 4,
            },
        ];
        let got = angles_near_many(&values, &reference, &runs).unwrap();
        let mut want = Vec::new();
        let mut lo = 0;
        for r in runs {
            want.extend(
                angles_near(
                    &values[lo..lo + r.len],
                    &reference[lo..lo + r.len],
                    r.mode,
                    r.channel,
                )
                .unwrap(),
            );
            lo += r.len;
        }
        assert_eq!(got, want, "values {values:?} runs {runs:?}");
        assert_ne!(got, values, "some angle wrapped: {got:?}");
        let short = [AngleRun {
            mode: RotationMode::Quaternion,
            channel: 0,
            len: 11,
        }];
        assert!(matches!(
            angles_near_many(&values, &reference, &short),
            Err(Error::LengthMismatch { .. })
        ));
        let wide = [AngleRun {
            mode: RotationMode::Euler(EulerOrder::Xyz),
            channel: 3,
            len: 12,
        }];
        assert!(matches!(
            angles_near_many(&values, &reference, &wide),
            Err(Error::In { .. })
        ));
    }
}
