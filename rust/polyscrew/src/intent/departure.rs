//! How far a result departs from the playback it was made from: per frame, the distance
//! between the origins and the angle between the rotations.

use glam::DVec3;

use super::limits::{check_footprint, filled};
use super::playback::{rotation_matrix, Playback};
use super::spans::rotation_angle;
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
    // Long bakes are measured on every core: the playback's curves are evaluated at every
    // frame, the cost of this function (bounded: each worker has one chunk's buffer).
    let cores = std::thread::available_parallelism().map_or(1, |p| p.get());
    let workers = cores.min(t / PARALLEL_FRAMES).max(1);
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
    let located = playback.located();
    let mut rows = Vec::new();
    for start in (0..frames.len()).step_by(CHUNK) {
        let end = (start + CHUNK).min(frames.len());
        // location and rotation only: the scale curves do not enter the departure
        playback.pose_channels_into(&frames[start..end], &mut rows)?;
        for (j, row) in rows.chunks_exact(width).enumerate() {
            let i = start + j;
            if located {
                let ours = DVec3::from_slice(&location[3 * i..3 * i + 3]);
                distance[i] = (ours - DVec3::from_slice(&row[..3])).length();
            }
            let ours = rotation_matrix(playback.mode(), &rotation[w * i..w * (i + 1)]);
            angle[i] = rotation_angle(&playback.rotation(row), &ours);
        }
    }
    Ok(())
}
