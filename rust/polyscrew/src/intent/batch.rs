//! Many owners' smoothed motions sampled as Blender channels in one call: what Smooth
//! Motion bakes, for every selected owner at once.
//!
//! Each owner's output frames are cut (by the add-on, from its held spans) into
//! [`Segment`]s: a **piece** of keys `lo..=hi` smoothed together, or the **hold** of key `lo`.
//! A piece is timed by [`timed_frames`] (every [`Timing`](crate::Timing): a map of time, or
//! timing Keys along Blender's playback), then sampled by [`sample`] (poses, and log-scales
//! when keyed) and turned into rotation channels by [`rotation_channels`], continued from the
//! segment before ([`RotationMode::continued`]); a hold repeats its key pose. This is, to the
//! bit, one `timed_frames`, `sample_channels` and `sample_vectors` call per piece and one
//! `rotation_channels` call per hold, as the add-on's `sampling.sample` makes them.

use glam::{DQuat, DVec3};

use crate::intent::pace::{timed_frames, PaceSource, Timed};
use crate::intent::Playback;
use crate::memory::try_vec;
use crate::motion::channels::{rotation_channels, RotationMode};
use crate::motion::sample::{sample, MotionSpec};
use crate::{Pose, Result};

/// Consecutive output frames of one owner sampled the same way: rows `start..end` of its
/// frames, sampled from the piece of keys `lo..=hi`, or held at key `lo` when `hi == lo`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Segment {
    /// The first key of the piece (the held key).
    pub lo: usize,
    /// The last key of the piece (`lo`: a hold).
    pub hi: usize,
    /// The first output row.
    pub start: usize,
    /// One past the last output row.
    pub end: usize,
}

impl Segment {
    /// Whether the segment holds key `lo`.
    pub fn held(&self) -> bool {
        self.hi == self.lo
    }
}

/// One owner's keyed motion and where to sample it ([`sample_owner_channels`]).
#[derive(Clone, Copy, Debug)]
pub struct OwnerMotion<'a> {
    /// The key poses.
    pub keys: &'a [Pose],
    /// The keys' frames (strictly increasing).
    pub key_frames: &'a [f64],
    /// The keys' log-scales, when scale is keyed.
    pub log_scales: Option<&'a [DVec3]>,
    /// The output frames (sorted).
    pub frames: &'a [f64],
    /// The output frames in segments, in order, covering every row once.
    pub segments: &'a [Segment],
    /// Scheme, levels, timing, and the whole motion's cycle (a piece of an open motion cut
    /// at holds is open).
    pub spec: MotionSpec,
    /// The body's half-extent (timing Keys).
    pub size: Option<f64>,
    /// Blender's playback of the owner's curves (timing Keys).
    pub playback: Option<&'a Playback>,
    /// The rotation channels the first segment continues from.
    pub previous: Option<&'a [f64]>,
    /// Whether to return the rows timing Keys played ([`Timed::Parameters`]' `played`).
    pub played: bool,
}

/// One owner's sampled channels, a row per output frame.
#[derive(Clone, Debug, Default)]
pub struct OwnerChannels {
    /// Locations.
    pub locations: Vec<DVec3>,
    /// Rotation channels, `mode.width()` per row.
    pub rotations: Vec<f64>,
    /// Log-scales (empty when scale is not keyed).
    pub log_scales: Vec<DVec3>,
    /// With `played`, Blender's playback rows (location, rotation channels) at the frames
    /// timing Keys played, NaN elsewhere; `None` when no piece played any.
    pub played: Option<Vec<f64>>,
}

/// One owner's sampled rigid poses, a row per output frame ([`sample_owner_poses`]).
#[derive(Clone, Debug, Default)]
pub struct OwnerPoses {
    /// The poses (a hold: its key pose).
    pub poses: Vec<Pose>,
    /// Log-scales (empty when scale is not keyed).
    pub log_scales: Vec<DVec3>,
    /// As [`OwnerChannels::played`].
    pub played: Option<Vec<f64>>,
}

/// What one segment gives ([`sample_segments`]): the poses of a piece, or a hold.
enum Rows {
    /// The piece's sampled poses, a row per frame of the segment.
    Sampled(Vec<Pose>),
    /// The segment holds its key `lo`.
    Held,
}

/// The smoothed motion of `owner` at its frames as location and rotation channels in `mode`
/// (and log-scales), segment after segment; see the [module](self).
///
/// # Errors
/// What [`timed_frames`], [`sample`] or [`rotation_channels`] refuse, and
/// [`Error::LengthMismatch`](crate::Error::LengthMismatch) for segments that do not fit the
/// keys or frames.
pub fn sample_owner_channels(owner: &OwnerMotion<'_>, mode: RotationMode) -> Result<OwnerChannels> {
    let n = owner.frames.len();
    let width = mode.width();
    let mut locations = try_vec(n, "sampled locations")?;
    let mut all = try_vec(n.saturating_mul(width), "sampled rotation channels")?;
    let mut last: Option<Vec<f64>> = owner.previous.map(<[f64]>::to_vec);
    let (log_scales, played) = sample_segments(owner, |seg, rows| {
        let count = seg.end - seg.start;
        let rotations = match rows {
            Rows::Held => {
                let key = owner.keys[seg.lo];
                locations.extend(std::iter::repeat_n(key.translation, count));
                let mut quats = try_vec(count, "held rotations")?;
                quats.extend(std::iter::repeat_n(key.rotation, count));
                rotation_channels(&quats, mode, last.as_deref())?
            }
            Rows::Sampled(dense) => {
                let mut quats: Vec<DQuat> = try_vec(dense.len(), "sampled rotations")?;
                quats.extend(dense.iter().map(|p| p.rotation));
                locations.extend(dense.iter().map(|p| p.translation));
                drop(dense);
                rotation_channels(&quats, mode, last.as_deref())?
            }
        };
        last = mode
            .continued()
            .then(|| rotations[rotations.len() - width..].to_vec());
        all.extend_from_slice(&rotations);
        Ok(())
    })?;
    Ok(OwnerChannels {
        locations,
        rotations: all,
        log_scales,
        played,
    })
}

/// The smoothed motion of `owner` at its frames as rigid poses (and log-scales), segment
/// after segment: the poses [`sample_owner_channels`] turns into channels, a hold its key
/// pose; one [`timed_frames`] and [`sample`] per piece, as `polyscrew.sample` gives them.
///
/// # Errors
/// As [`sample_owner_channels`].
pub fn sample_owner_poses(owner: &OwnerMotion<'_>) -> Result<OwnerPoses> {
    let mut poses = try_vec(owner.frames.len(), "sampled poses")?;
    let (log_scales, played) = sample_segments(owner, |seg, rows| {
        match rows {
            Rows::Held => {
                poses.extend(std::iter::repeat_n(owner.keys[seg.lo], seg.end - seg.start))
            }
            Rows::Sampled(dense) => poses.extend(dense),
        }
        Ok(())
    })?;
    Ok(OwnerPoses {
        poses,
        log_scales,
        played,
    })
}

/// Samples `owner`'s segments in order, handing each one's rows to `put`; returns the
/// log-scales (empty when scale is not keyed) and the played rows. Checks that the segments
/// fit the keys and frames.
fn sample_segments(
    owner: &OwnerMotion<'_>,
    mut put: impl FnMut(&Segment, Rows) -> Result<()>,
) -> Result<(Vec<DVec3>, Option<Vec<f64>>)> {
    let n = owner.frames.len();
    let k = owner.keys.len();
    let fits = owner.key_frames.len() == k
        && owner.log_scales.is_none_or(|l| l.len() == k)
        && owner
            .segments
            .iter()
            .all(|s| s.lo <= s.hi && s.hi < k && s.start < s.end)
        // Contiguous from row 0 to row n: every row once, in order.
        && owner
            .segments
            .iter()
            .try_fold(0, |row, s| (s.start == row).then_some(s.end))
            == Some(n);
    if !fits {
        return Err(crate::Error::LengthMismatch {
            what: "segments",
            expected: n,
            got: owner.segments.iter().map(|s| s.end - s.start).sum(),
        });
    }
    let mut log_scales = try_vec(
        if owner.log_scales.is_some() { n } else { 0 },
        "sampled log-scales",
    )?;
    let mut out_played: Option<Vec<f64>> = None;
    for seg in owner.segments {
        let count = seg.end - seg.start;
        if seg.held() {
            if let Some(logs) = owner.log_scales {
                log_scales.extend(std::iter::repeat_n(logs[seg.lo], count));
            }
            put(seg, Rows::Held)?;
            continue;
        }
        let whole = seg.lo == 0 && seg.hi == k - 1;
        let spec = if whole {
            owner.spec
        } else {
            MotionSpec {
                closed: false,
                period: None,
                ..owner.spec
            }
        };
        let (keys, key_frames) = (
            &owner.keys[seg.lo..=seg.hi],
            &owner.key_frames[seg.lo..=seg.hi],
        );
        let frames = &owner.frames[seg.start..seg.end];
        let timed = timed_frames(
            key_frames,
            frames,
            &spec,
            owner.size,
            owner.playback,
            PaceSource::Keys(keys),
            owner.played && owner.playback.is_some(),
        )?;
        let (key_times, times, spec, played) = match &timed {
            Timed::Frames => (key_frames, frames, spec, &[][..]),
            Timed::Parameters {
                key_times,
                parameters,
                spec,
                played,
            } => (&key_times[..], &parameters[..], *spec, &played[..]),
        };
        if !played.is_empty() {
            let row = played.len() / count;
            let rows = out_played.get_or_insert_with(Vec::new);
            if rows.is_empty() {
                *rows = try_vec(n.saturating_mul(row), "played rows")?;
                rows.resize(n.saturating_mul(row), f64::NAN);
            }
            rows[seg.start * row..seg.end * row].copy_from_slice(played);
        }
        let dense = sample(keys, key_times, times, &spec)?;
        if let Some(logs) = owner.log_scales {
            log_scales.extend(sample(&logs[seg.lo..=seg.hi], key_times, times, &spec)?);
        }
        put(seg, Rows::Sampled(dense))?;
    }
    Ok((log_scales, out_played))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{EulerOrder, Scheme, Timing};

    fn keys() -> (Vec<Pose>, Vec<f64>) {
        let poses = (0..5)
            .map(|i| {
                let a = 0.9 * i as f64;
                Pose::from_rotation_translation(
                    DQuat::from_euler(glam::EulerRot::ZYX, a, 0.3 * a, -0.2 * a),
                    DVec3::new(a, (2.0 * a).sin(), 0.1 * a * a),
                )
            })
            .collect();
        (poses, vec![1.0, 4.0, 11.0, 15.0, 24.0])
    }

    fn spec(timing: Timing) -> MotionSpec {
        MotionSpec {
            scheme: Scheme::FourPoint,
            levels: 3,
            closed: false,
            period: None,
            timing,
        }
    }

    /// An owner of `poses` at `key_frames` sampled at `frames` in `segments`: no scale, size,
    /// playback or previous channels.
    fn motion<'a>(
        poses: &'a [Pose],
        key_frames: &'a [f64],
        frames: &'a [f64],
        segments: &'a [Segment],
        timing: Timing,
    ) -> OwnerMotion<'a> {
        OwnerMotion {
            keys: poses,
            key_frames,
            log_scales: None,
            frames,
            segments,
            spec: spec(timing),
            size: None,
            playback: None,
            previous: None,
            played: false,
        }
    }

    #[test]
    fn one_piece_is_sample_then_rotation_channels_to_the_bit() {
        let (poses, key_frames) = keys();
        let frames: Vec<f64> = (0..26).map(|f| f as f64).collect();
        let mode = RotationMode::Euler(EulerOrder::Xyz);
        for timing in [Timing::Smooth, Timing::Linear] {
            let segments = [Segment {
                lo: 0,
                hi: 4,
                start: 0,
                end: frames.len(),
            }];
            let owner = OwnerMotion {
                size: Some(1.0),
                previous: Some(&[0.0, 0.0, 0.0]),
                played: true,
                ..motion(&poses, &key_frames, &frames, &segments, timing)
            };
            let got = sample_owner_channels(&owner, mode).unwrap();
            let dense = sample(&poses, &key_frames, &frames, &spec(timing)).unwrap();
            let quats: Vec<DQuat> = dense.iter().map(|p| p.rotation).collect();
            let want = rotation_channels(&quats, mode, Some(&[0.0, 0.0, 0.0])).unwrap();
            assert_eq!(got.rotations, want, "{timing:?}");
            assert!(got
                .locations
                .iter()
                .zip(&dense)
                .all(|(a, b)| *a == b.translation));
            assert!(got.played.is_none() && got.log_scales.is_empty());
        }
    }

    /// [`keys`] with keys 1..2 held, frames 1..24 in segments (rows 0..3 the piece 0..1, 3..10
    /// the hold of key 1, 10..24 the piece 2..4), log-scales per key.
    #[allow(clippy::type_complexity)]
    fn held_keys() -> (Vec<Pose>, Vec<f64>, Vec<f64>, [Segment; 3], Vec<DVec3>) {
        let (mut poses, key_frames) = keys();
        poses[2] = poses[1];
        let frames: Vec<f64> = (1..25).map(|f| f as f64).collect();
        let segments = [
            Segment {
                lo: 0,
                hi: 1,
                start: 0,
                end: 3,
            },
            Segment {
                lo: 1,
                hi: 1,
                start: 3,
                end: 10,
            },
            Segment {
                lo: 2,
                hi: 4,
                start: 10,
                end: 24,
            },
        ];
        let logs: Vec<DVec3> = (0..5).map(|i| DVec3::splat(0.1 * i as f64)).collect();
        (poses, key_frames, frames, segments, logs)
    }

    #[test]
    fn a_hold_repeats_its_key_and_the_next_piece_continues_from_it() {
        let (poses, key_frames, frames, segments, logs) = held_keys();
        let mode = RotationMode::Quaternion;
        let owner = OwnerMotion {
            log_scales: Some(&logs),
            ..motion(&poses, &key_frames, &frames, &segments, Timing::Smooth)
        };
        let got = sample_owner_channels(&owner, mode).unwrap();
        assert_eq!(got.locations.len(), 24);
        assert!(got.locations[3..10]
            .iter()
            .all(|l| *l == poses[1].translation));
        assert!(got.log_scales[3..10].iter().all(|l| *l == logs[1]));
        // the last piece, sampled alone from the hold's last channels
        let dense = sample(
            &poses[2..],
            &key_frames[2..],
            &frames[10..],
            &spec(Timing::Smooth),
        )
        .unwrap();
        let quats: Vec<DQuat> = dense.iter().map(|p| p.rotation).collect();
        let want = rotation_channels(&quats, mode, Some(&got.rotations[9 * 4..10 * 4])).unwrap();
        assert_eq!(&got.rotations[10 * 4..], &want[..]);
        let scales = sample(
            &logs[2..],
            &key_frames[2..],
            &frames[10..],
            &spec(Timing::Smooth),
        )
        .unwrap();
        assert_eq!(&got.log_scales[10..], &scales[..]);
    }

    #[test]
    fn poses_are_sample_per_piece_and_the_key_per_hold_to_the_bit() {
        let (poses, key_frames, frames, segments, logs) = held_keys();
        let owner = OwnerMotion {
            log_scales: Some(&logs),
            ..motion(&poses, &key_frames, &frames, &segments, Timing::Linear)
        };
        let got = sample_owner_poses(&owner).unwrap();
        let channels = sample_owner_channels(&owner, RotationMode::Quaternion).unwrap();
        assert_eq!(got.log_scales, channels.log_scales);
        assert!(got.poses[3..10].iter().all(|p| *p == poses[1]));
        for (lo, hi, rows) in [(0, 1, 0..3), (2, 4, 10..24)] {
            let want = sample(
                &poses[lo..=hi],
                &key_frames[lo..=hi],
                &frames[rows.clone()],
                &spec(Timing::Linear),
            )
            .unwrap();
            assert_eq!(&got.poses[rows.clone()], &want[..], "keys {lo}..{hi}");
            let locations: Vec<DVec3> = want.iter().map(|p| p.translation).collect();
            assert_eq!(&channels.locations[rows], &locations[..], "keys {lo}..{hi}");
        }
    }

    #[test]
    fn segments_that_do_not_cover_the_frames_are_refused() {
        let (poses, key_frames) = keys();
        let frames = [1.0, 2.0, 3.0];
        for segments in [
            vec![Segment {
                lo: 0,
                hi: 4,
                start: 0,
                end: 2,
            }],
            vec![Segment {
                lo: 0,
                hi: 5,
                start: 0,
                end: 3,
            }],
            vec![Segment {
                lo: 3,
                hi: 2,
                start: 0,
                end: 3,
            }],
            // as many rows as the frames, but row 0 twice and row 2 never
            vec![
                Segment {
                    lo: 0,
                    hi: 4,
                    start: 0,
                    end: 2,
                },
                Segment {
                    lo: 4,
                    hi: 4,
                    start: 0,
                    end: 1,
                },
            ],
        ] {
            let owner = motion(&poses, &key_frames, &frames, &segments, Timing::Smooth);
            let err = sample_owner_channels(&owner, RotationMode::Quaternion).unwrap_err();
            assert!(
                matches!(
                    err,
                    crate::Error::LengthMismatch {
                        what: "segments",
                        ..
                    }
                ),
                "{segments:?}: {err}"
            );
        }
    }
}
