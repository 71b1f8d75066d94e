//! How far a result departs from the playback it was made from: per frame, the distance
//! between the origins and the angle between the rotations.

use glam::DVec3;

use super::limits::{check_footprint, collected, filled};
use super::playback::{rotation_matrix, Playback};
use super::spans::rotation_angle;
use crate::memory::try_vec;
use crate::motion::channels::rotation_quat;
use crate::{Error, Result};

/// Frames evaluated at once (bounds the work buffer whatever the number of frames).
const CHUNK: usize = 4096;

/// Frames per worker below which [`departure`] runs on one thread (a thread costs more than
/// measuring fewer frames).
pub(crate) const PARALLEL_FRAMES: usize = 4_096;

/// Per frame, how far a result is from the playback (see [`departure`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Departure {
    /// Distance between the result's location and the playback's (0 for an owner whose
    /// location is not played, a connected bone).
    pub distance: Vec<f64>,
    /// Angle (radians, in `[0, pi]`) of the rotation from the playback's to the result's.
    pub angle: Vec<f64>,
}

/// How far the channels `location` (`T x 3`, row-major) and `rotation` (`T x w`, in the
/// playback's rotation mode) are from `playback` at `frames` (`T`): per frame
/// `|l - l_played|` and the [`rotation_angle`] between `R(rotation)` and `R(played)`
/// (rotations converted with Blender's conventions, [`rotation_matrix`]). At `t = 0` of a
/// span a result that keeps the key pose departs by 0.
///
/// # Errors
/// [`Error::LengthMismatch`] when `location` or `rotation` do not have one row per frame,
/// [`Error::NotFinite`] for a value that is not finite, the errors of
/// [`Playback::channels`], and a request over the size limit ([`check_footprint`]).
pub fn departure(
    playback: &Playback,
    frames: &[f64],
    location: &[f64],
    rotation: &[f64],
) -> Result<Departure> {
    let t = frames.len();
    let w = playback.mode().width();
    let width = playback.width();
    check_result(t, w, location, rotation)?;
    // Long bakes are measured on every core: the playback's curves are evaluated at every
    // frame, the cost of this function (bounded: each worker has one chunk's buffer).
    // (the cores asked only when there is work for two: asking reads the process's CPU
    // limits, which costs more than measuring a short bake)
    let workers = if t < 2 * PARALLEL_FRAMES {
        1
    } else {
        let cores = std::thread::available_parallelism().map_or(1, |p| p.get());
        cores.min(t / PARALLEL_FRAMES).max(1)
    };
    check_footprint(
        t.saturating_mul(2)
            .saturating_add(workers.saturating_mul(CHUNK).saturating_mul(width))
            .saturating_mul(std::mem::size_of::<f64>()),
        "departure",
        "measure fewer frames",
    )?;
    let mut distance = filled(t, 0.0, "departure")?;
    let mut angle = filled(t, 0.0, "departure")?;
    if workers <= 1 {
        measure(
            playback,
            frames,
            location,
            rotation,
            &mut distance,
            &mut angle,
        )?;
        return Ok(Departure { distance, angle });
    }
    let per = t.div_ceil(workers);
    let parts = std::thread::scope(|scope| {
        let handles: Vec<_> = distance
            .chunks_mut(per)
            .zip(angle.chunks_mut(per))
            .enumerate()
            .map(|(k, (d, a))| {
                let range = k * per..k * per + d.len();
                let (l, r) = (
                    &location[3 * range.start..3 * range.end],
                    &rotation[w * range.start..w * range.end],
                );
                let f = &frames[range];
                scope.spawn(move || measure(playback, f, l, r, d, a))
            })
            .collect();
        handles.into_iter().map(|h| h.join()).collect::<Vec<_>>()
    });
    for part in parts {
        // A worker only fails by a bug (the core does not panic on data): report it.
        part.map_err(|_| Error::Worker { what: "frames" })??;
    }
    Ok(Departure { distance, angle })
}

/// Checks a result's channels for `t` frames: `location` `t x 3`, `rotation` `t x w`, all
/// finite.
fn check_result(t: usize, w: usize, location: &[f64], rotation: &[f64]) -> Result<()> {
    for (values, per) in [(location, 3), (rotation, w)] {
        if values.len() != t.saturating_mul(per) {
            return Err(Error::LengthMismatch {
                what: "result channels",
                expected: t.saturating_mul(per),
                got: values.len(),
            });
        }
    }
    if let Some(index) = location.iter().chain(rotation).position(|v| !v.is_finite()) {
        return Err(Error::NotFinite {
            what: "result channel value",
            index,
        });
    }
    Ok(())
}

/// [`departure`] of the frames `frames` into `distance` and `angle` (one value per frame),
/// `CHUNK` frames of the playback at a time.
pub(crate) fn measure(
    playback: &Playback,
    frames: &[f64],
    location: &[f64],
    rotation: &[f64],
    distance: &mut [f64],
    angle: &mut [f64],
) -> Result<()> {
    let w = playback.mode().width();
    let width = playback.width();
    let mut rows = Vec::new();
    for start in (0..frames.len()).step_by(CHUNK) {
        let end = (start + CHUNK).min(frames.len());
        // location and rotation only: the scale curves do not enter the departure
        playback.pose_channels_into(&frames[start..end], &mut rows)?;
        for (j, row) in rows.chunks_exact(width).enumerate() {
            let i = start + j;
            (distance[i], angle[i]) = compare(
                playback,
                row,
                &location[3 * i..3 * i + 3],
                &rotation[w * i..w * (i + 1)],
            );
        }
    }
    Ok(())
}

/// The distance (0 when the playback is not `located`) and angle between the played pose
/// `row` (a channel row, or its location and rotation) and a result's `location` (3) and
/// `rotation` (the mode's width).
fn compare(playback: &Playback, row: &[f64], location: &[f64], rotation: &[f64]) -> (f64, f64) {
    let distance = if playback.located() {
        (DVec3::from_slice(location) - DVec3::from_slice(&row[..3])).length()
    } else {
        0.0
    };
    let played = row.get(3..).unwrap_or(&[]);
    let angle = match (
        rotation_quat(playback.mode(), played),
        rotation_quat(playback.mode(), rotation),
    ) {
        // `2 atan2(|v|, |w|)` of `(v, w) = conj(q_played) q_ours`: the angle between the
        // rotations, whatever the quaternions' lengths (a third of the matrices' work)
        (Some(a), Some(b)) => {
            let d = a.conjugate() * b;
            2.0 * DVec3::new(d.x, d.y, d.z).length().atan2(d.w.abs())
        }
        _ => rotation_angle(
            &rotation_matrix(playback.mode(), played),
            &rotation_matrix(playback.mode(), rotation),
        ),
    };
    (distance, angle)
}

/// What the report needs of a departure (see [`measure_departure`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DepartureSummary {
    /// The largest angle over the measured frames, in degrees (`angle.to_degrees()`), 0
    /// without frames.
    pub degrees: f64,
    /// The largest distance over the measured frames, 0 without frames.
    pub distance: f64,
    /// Per frame: whether it departs by more than the limits (a frame not measured: as the
    /// nearest measured frame, the earlier one when both are as near).
    pub over: Vec<bool>,
}

/// Limits of a [`measure_departure`]: a frame departs when its angle exceeds `degrees` or
/// its distance exceeds `distance`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DepartureLimits {
    /// Degrees.
    pub degrees: f64,
    /// Units of location.
    pub distance: f64,
}

/// The add-on's departure measure in one call: [`departure`] of a result at its baked
/// `frames` (sorted), at every frame or, with `spans` (`(key_frames, most)`, `most >= 2`),
/// only at [`measured_frames`]; the largest angle (degrees) and distance, and per frame
/// whether it departs beyond `limits` (a frame not measured as its nearest measured one).
///
/// `played`, when given, holds a pose row (`3 + w` numbers: location, rotation) per frame as
/// [`super::keys_parameters_played`] returns them: a frame whose row is not NaN is compared
/// with that row (the row the playback gives there, played once already) instead of being
/// played again. The result is the same as without it, bit for bit.
///
/// # Errors
/// As [`departure`]; [`Error::LengthMismatch`] for `played` not of `frames.len()` rows,
/// [`Error::Count`] for `most < 2`.
pub fn measure_departure(
    playback: &Playback,
    frames: &[f64],
    location: &[f64],
    rotation: &[f64],
    played: Option<&[f64]>,
    spans: Option<(&[f64], usize)>,
    limits: DepartureLimits,
) -> Result<DepartureSummary> {
    let t = frames.len();
    let w = playback.mode().width();
    let pw = 3 + w;
    if let Some(rows) = played {
        if rows.len() != t.saturating_mul(pw) {
            return Err(Error::LengthMismatch {
                what: "played rows",
                expected: t.saturating_mul(pw),
                got: rows.len(),
            });
        }
    }
    check_result(t, w, location, rotation)?;
    let measured = match spans {
        Some((key_frames, most)) => measured_frames(frames, key_frames, most)?,
        None => None,
    };
    let count = measured.as_ref().map_or(t, Vec::len);
    let index = |k: usize| measured.as_ref().map_or(k, |m| m[k]);
    check_footprint(
        count
            .saturating_mul(4 + pw + 3)
            .saturating_add(t)
            .saturating_mul(std::mem::size_of::<f64>()),
        "departure",
        "measure fewer frames",
    )?;
    // the measured frames the playback has not played yet: measured as `departure` does
    let is_played = |i: usize| played.is_some_and(|rows| !rows[i * pw].is_nan());
    let mut again = try_vec(count, "departure frames")?;
    again.extend((0..count).map(index).filter(|&i| !is_played(i)));
    let gather = |per: usize, values: &[f64]| -> Result<Vec<f64>> {
        collected(
            again.len().saturating_mul(per),
            again
                .iter()
                .flat_map(|&i| values[per * i..per * (i + 1)].iter().copied()),
            "departure frames",
        )
    };
    let fresh = if again.is_empty() {
        Departure {
            distance: Vec::new(),
            angle: Vec::new(),
        }
    } else {
        departure(
            playback,
            &collected(
                again.len(),
                again.iter().map(|&i| frames[i]),
                "departure frames",
            )?,
            &gather(3, location)?,
            &gather(w, rotation)?,
        )?
    };
    let mut degrees = 0.0f64;
    let mut distance = 0.0f64;
    let mut over_measured = try_vec(count, "departure")?;
    let mut next = 0; // into `again`
    for k in 0..count {
        let i = index(k);
        let (d, a) = if next < again.len() && again[next] == i {
            next += 1;
            (fresh.distance[next - 1], fresh.angle[next - 1])
        } else {
            let rows = played.unwrap_or_default();
            compare(
                playback,
                &rows[i * pw..(i + 1) * pw],
                &location[3 * i..3 * i + 3],
                &rotation[w * i..w * (i + 1)],
            )
        };
        let deg = a.to_degrees();
        degrees = degrees.max(deg);
        distance = distance.max(d);
        over_measured.push(deg > limits.degrees || d > limits.distance);
    }
    let over = match &measured {
        None => over_measured,
        Some(m) => {
            // every frame departs as its nearest measured frame
            let fm = collected(m.len(), m.iter().map(|&i| frames[i]), "departure")?;
            let last = m.len().saturating_sub(1).max(1);
            collected(
                t,
                frames.iter().map(|&f| {
                    let at = fm.partition_point(|&x| x < f).clamp(1, last);
                    let (before, after) = (fm[at - 1], fm[at.min(m.len() - 1)]);
                    over_measured[if f - before <= after - f { at - 1 } else { at }]
                }),
                "departure",
            )?
        }
    };
    Ok(DepartureSummary {
        degrees,
        distance,
        over,
    })
}

/// One owner of [`measure_departures`]: the arguments of one [`measure_departure`] call.
#[derive(Debug, Clone, Copy)]
pub struct DepartureOwner<'a> {
    /// The owner's playback.
    pub playback: &'a Playback,
    /// The result's frames (sorted).
    pub frames: &'a [f64],
    /// The result's location (`frames.len() x 3`) and rotation (`frames.len() x w`).
    pub location: &'a [f64],
    /// See `location`.
    pub rotation: &'a [f64],
    /// The rows played already (see [`measure_departure`]).
    pub played: Option<&'a [f64]>,
    /// `(key_frames, most)` (see [`measure_departure`]).
    pub spans: Option<(&'a [f64], usize)>,
    /// The owner's limits.
    pub limits: DepartureLimits,
}

/// [`measure_departure`] of every owner in turn, each to the bit what its own call gives:
/// one call for all the owners of an operator.
///
/// # Errors
/// What [`measure_departure`] refuses, in [`Error::In`] (`"part"`, the owner's index).
pub fn measure_departures(owners: &[DepartureOwner<'_>]) -> Result<Vec<DepartureSummary>> {
    let mut out = try_vec(owners.len(), "departures")?;
    for (i, o) in owners.iter().enumerate() {
        out.push(
            measure_departure(
                o.playback, o.frames, o.location, o.rotation, o.played, o.spans, o.limits,
            )
            .map_err(|e| e.within("part", i))?,
        );
    }
    Ok(out)
}

/// Indices of the frames (sorted) a departure measures: every frame of a key span (of
/// `key_frames`) baked at no more than `most` frames; of a span of `c > most` frames, the
/// `most` frames `round(k (c - 1) / (most - 1))` (evenly spaced, its first and last
/// included; rounding half to even). `None` when that is every frame.
///
/// # Errors
/// [`Error::Count`] for `most < 2`; a request over the size limit.
pub fn measured_frames(
    frames: &[f64],
    key_frames: &[f64],
    most: usize,
) -> Result<Option<Vec<usize>>> {
    if most < 2 {
        return Err(Error::Count {
            what: "frames measured per span",
            got: most,
            need: 2,
        });
    }
    let t = frames.len();
    // the span of each frame: key frames at or before it (a run of equal spans is one span)
    let span = |f: f64| key_frames.partition_point(|&k| k <= f);
    let mut runs: Vec<(usize, usize)> = Vec::new(); // (start, count)
    let mut previous = None;
    for (i, &f) in frames.iter().enumerate() {
        let s = span(f);
        if previous == Some(s) {
            if let Some(last) = runs.last_mut() {
                last.1 += 1;
            }
        } else {
            runs.push((i, 1));
            previous = Some(s);
        }
    }
    if runs.iter().all(|&(_, c)| c <= most) {
        return Ok(None);
    }
    check_footprint(
        t.saturating_mul(std::mem::size_of::<usize>()),
        "departure frames",
        "measure fewer frames",
    )?;
    let mut out = try_vec(t, "departure frames")?;
    for &(start, c) in &runs {
        if c <= most {
            out.extend(start..start + c);
            continue;
        }
        let step = (c - 1).max(1) as f64 / (most - 1) as f64;
        out.extend((0..c).filter_map(|i| {
            let i = i as f64;
            ((i / step).round_ties_even() * step)
                .round_ties_even()
                .eq(&i)
                .then_some(start + i as usize)
        }));
    }
    Ok(Some(out))
}

#[cfg(test)]
mod angle_tests {
    use super::*;
    use crate::RotationMode;

    /// The angle between two rotations as [`compare`] takes it from quaternions equals
    /// [`rotation_angle`] of their matrices, in every quaternion and Euler mode (unnormalised,
    /// sign-flipped and zero quaternions, angles beyond a turn, near 0 and near pi).
    #[test]
    fn quaternion_angle_equals_the_matrices_angle() {
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        // the six Euler orders (after quaternion and axis-angle in `ALL`), then quaternion
        let modes = RotationMode::ALL
            .into_iter()
            .skip(2)
            .chain([RotationMode::Quaternion]);
        let mut worst = 0.0f64;
        let mut count = 0;
        for mode in modes {
            for case in 0..2000 {
                let scale = if mode == RotationMode::Quaternion {
                    3.0
                } else {
                    9.0
                };
                let a: Vec<f64> = (0..4).map(|_| scale * next()).collect();
                let mut b: Vec<f64> = match case % 4 {
                    0 => (0..4).map(|_| scale * next()).collect(),
                    1 => a.iter().map(|x| x + 1e-7 * next()).collect(), // near 0
                    2 if mode == RotationMode::Quaternion => a.iter().map(|x| -2.5 * x).collect(),
                    _ => a.iter().map(|x| x + 0.3 * next()).collect(),
                };
                if case == 7 && mode == RotationMode::Quaternion {
                    b = vec![0.0; 4]; // the identity, as rotation_matrix reads it
                }
                if case % 4 == 3 && mode != RotationMode::Quaternion {
                    b[0] = a[0] + std::f64::consts::PI - 1e-6 * next().abs(); // near pi
                    b[1..3].copy_from_slice(&a[1..3]);
                }
                let (qa, qb) = (
                    rotation_quat(mode, &a).unwrap(),
                    rotation_quat(mode, &b).unwrap(),
                );
                let d = qa.conjugate() * qb;
                let ours = 2.0 * DVec3::new(d.x, d.y, d.z).length().atan2(d.w.abs());
                let reference =
                    rotation_angle(&rotation_matrix(mode, &a), &rotation_matrix(mode, &b));
                assert!(
                    (ours - reference).abs() < 1e-9,
                    "{mode:?} {a:?} {b:?}: {ours} against {reference}"
                );
                worst = worst.max((ours - reference).abs());
                count += 1;
            }
        }
        println!("{count} pairs, largest difference {worst:e} rad");
        assert!(rotation_quat(RotationMode::AxisAngle, &[1.0, 0.0, 0.0, 1.0]).is_none());
    }
}
