//! Timing "Keys": the pace of Blender's own interpolation, kept while the path becomes a
//! screw path.

use glam::{DMat3, DVec3};

use super::interp::interp;
use super::limits::{check_footprint, collected};
use super::playback::Playback;
use crate::memory::try_vec;
use crate::motion::pose::MAX_COORDINATE;
use crate::motion::timing::{check_period, check_time};
use crate::{
    check_key_times, At, Error, Expected, Motion, MotionSpec, Pose, Result, Scheme, Timing,
};

/// Steps per key span along which the travel of Blender's playback and of the smoothed
/// motion is measured (the output frames inside a span are measured too).
pub const PACE_SAMPLES: usize = 16;

/// Blender's playback is measured at every output frame inside a span with at most this many
/// of them; a span with more (a long bake, subframes) is measured at this many evenly spaced
/// frames instead and the output frames interpolate between them (their travel fraction is
/// then exact to the interpolation of a smooth curve over `1 / DENSE_PACE_SAMPLES` of the
/// span: below 1e-4 of the span for Blender's sharpest ease, EXPO in-out), so the cost of
/// timing Keys does not grow with the number of frames.
pub const DENSE_PACE_SAMPLES: usize = 256;

/// How far a body moves from `(ta, ra)` to `(tb, rb)` (translation, rotation matrix): the root
/// mean square displacement of the six points at `+-size` along its axes,
/// `sqrt(|tb - ta|^2 + size^2 / 3 |Rb - Ra|_F^2)` (the cross terms cancel).
fn travel_between(ta: DVec3, ra: &DMat3, tb: DVec3, rb: &DMat3, size: f64) -> f64 {
    let dt = tb - ta;
    let dr = *rb - *ra;
    let frobenius =
        dr.x_axis.length_squared() + dr.y_axis.length_squared() + dr.z_axis.length_squared();
    (dt.length_squared() + size * size / 3.0 * frobenius).sqrt()
}

/// How far a body of half-extent `size` moves from pose `a` to pose `b`: the root mean
/// square displacement of the six points at `+-size` along its axes,
/// `sqrt(|t_b - t_a|^2 + size^2 / 3 |R_b - R_a|_F^2)`. Zero for equal poses; for a pure
/// translation its length; for a turn by `angle` about any axis through the origin,
/// `size sqrt(8 / 3) sin(angle / 2)`.
pub fn travel(a: &Pose, b: &Pose, size: f64) -> f64 {
    travel_between(
        a.translation,
        &DMat3::from_quat(a.rotation),
        b.translation,
        &DMat3::from_quat(b.rotation),
        size,
    )
}

/// The motion parameters `s + j / PACE_SAMPLES` (`j = 0..=PACE_SAMPLES`) of each span `s` in
/// `0..spans`, span after span: where [`keys_parameters`] measures the smoothed motion.
///
/// # Errors
/// A request over the size limit ([`check_footprint`]).
pub fn pace_parameters(spans: usize) -> Result<Vec<f64>> {
    let n = spans.saturating_mul(PACE_SAMPLES + 1);
    check_footprint(
        n.saturating_mul(std::mem::size_of::<f64>()),
        "pace parameters",
        "pass fewer keys",
    )?;
    let grid = |j: usize| j as f64 / PACE_SAMPLES as f64;
    collected(
        n,
        (0..spans).flat_map(|s| (0..=PACE_SAMPLES).map(move |j| s as f64 + grid(j))),
        "pace parameters",
    )
}

/// The smoothed screw motion of `keys` at [`pace_parameters`]: keys at parameters
/// `0, 1, ..., K - 1` (a cycle of period `K` when `closed`), subdivided by `scheme` over
/// `levels` and sampled with linear timing (the parameter is the motion's own).
///
/// # Errors
/// As [`Motion::new`] and [`Motion::sample`], and a request over the size limit.
pub fn screw_pace_poses(
    keys: &[Pose],
    scheme: Scheme,
    levels: u32,
    closed: bool,
) -> Result<Vec<Pose>> {
    let k = keys.len();
    let spans = if closed { k } else { k.saturating_sub(1) };
    let parameters = pace_parameters(spans)?;
    check_footprint(
        parameters.len().saturating_mul(std::mem::size_of::<Pose>()),
        "pace poses",
        "pass fewer keys",
    )?;
    let times = collected(k, (0..k).map(|i| i as f64), "key parameters")?;
    let spec = MotionSpec {
        scheme,
        levels,
        closed,
        period: closed.then_some(k as f64),
        timing: Timing::Linear,
    };
    Motion::new(keys, &times, &spec)?.sample(&parameters)
}

/// What timing "Keys" needs besides the output frames and the smoothed motion.
#[derive(Debug, Clone, Copy)]
pub struct KeysTiming<'a> {
    /// The key frames, finite and strictly increasing, at least two.
    pub key_frames: &'a [f64],
    /// The cycle length in frames of a closed motion (its last span runs from the last key
    /// to `key_frames[0] + period`); `None` for an open one.
    pub period: Option<f64>,
    /// The body's half-extent: how much rotation counts in [`travel`] (positive, finite).
    pub size: f64,
    /// Blender's playback of the keys, or `None` (a motion read from key values alone):
    /// the fraction of the way is then the fraction of time.
    pub playback: Option<&'a Playback>,
}

/// Timing "Keys": the motion parameter of each frame of `frames` (key `i` at parameter `i`).
///
/// Within span `s` (keys `s`, `s + 1`; for a cycle the last span closes it), a frame at the
/// fraction `tau` of the span's time gets the parameter `s + v` at which the smoothed motion
/// has travelled the same fraction of the span's travel as Blender's playback has at that
/// frame:
///
/// - the playback is sampled at [`PACE_SAMPLES`] `+ 1` evenly spaced frames per span and at
///   every output frame inside a span; `done(tau)` is the travel ([`travel`]) summed along
///   these samples from the span's start, divided by the span's total (the fraction of time
///   over a span where the playback does not move, or without playback);
/// - the smoothed motion `smooth` is given at [`pace_parameters`] (span after span,
///   `PACE_SAMPLES + 1` poses each, for example [`screw_pace_poses`]); `along(j)` is its
///   travel summed to pose `j` over the span's total (`j / PACE_SAMPLES` where it does not
///   move);
/// - `v` interpolates `(along(j), j / PACE_SAMPLES)` linearly at `done(tau)`.
///
/// Frames at keys, before the first key and after the last span keep `s + tau`
/// (extrapolating linearly). Overshoot (BACK, ELASTIC) counts as travel: the pace follows it
/// and the parameter stays within the span.
///
/// # Errors
/// [`Error::TooFew`] for fewer than two keys, the errors of
/// [`check_key_times`] for the key frames (strictly increasing,
/// within the time range), [`Error::Period`] for a period [`check_period`] refuses,
/// [`Error::Value`] for a size outside `(0, 1e150]`, [`Error::Overflow`] for a frame so far outside the keys that
/// its parameter is not finite, [`Error::NotFinite`] or [`Error::OutOfRange`] for a frame
/// outside the time range, [`Error::LengthMismatch`] when `smooth` does not hold
/// `PACE_SAMPLES + 1` poses per span, [`Error::BadPose`] for a smoothed pose outside the
/// coordinate range, the errors of [`Playback::channels`], and a request over the memory
/// budget ([`check_footprint`]).
pub fn keys_parameters(
    timing: &KeysTiming<'_>,
    frames: &[f64],
    smooth: &[Pose],
) -> Result<Vec<f64>> {
    Ok(parameters_and_played(timing, frames, smooth, false)?.0)
}

/// [`keys_parameters`], and the playback's pose rows it evaluated at the output frames
/// themselves: `frames.len()` rows of `3 + w` numbers (location, rotation in the playback's
/// mode; `w` its [`RotationMode::width`](crate::RotationMode::width)), row-major, each the
/// row [`Playback::channels`] gives at that frame (bit for bit: the same evaluation), and
/// NaN where the frame was not played at exactly that frame (a span measured on its dense
/// grid, a frame outside the spans, no playback). A caller that measures the result against
/// the playback at these frames ([`super::departure::measure_departure`]) then plays each
/// frame once.
///
/// # Errors
/// As [`keys_parameters`].
pub fn keys_parameters_played(
    timing: &KeysTiming<'_>,
    frames: &[f64],
    smooth: &[Pose],
) -> Result<(Vec<f64>, Vec<f64>)> {
    parameters_and_played(timing, frames, smooth, true)
}

/// The smoothed motion a paced timing measures its travel along.
#[derive(Debug, Clone, Copy)]
pub enum PaceSource<'a> {
    /// The key poses, smoothed by the [`MotionSpec`]'s scheme and levels
    /// ([`screw_pace_poses`]).
    Keys(&'a [Pose]),
    /// The smoothed motion's poses at [`pace_parameters`], computed by the caller (feature
    /// points).
    Given(&'a [Pose]),
}

/// Where a motion keyed at the key frames is sampled for the output frames
/// ([`timed_frames`]).
#[derive(Debug, Clone, PartialEq)]
pub enum Timed {
    /// At the frames themselves, keys at their frames, with the [`MotionSpec`] as given: the
    /// timing is a map of time ([`TimeMap`](crate::TimeMap): Smooth, Linear).
    Frames,
    /// At `parameters`, keys at `0, 1, ..., K - 1`, with `spec` (linear timing, period `K`
    /// for a cycle): the motion parameter is the motion's own.
    Parameters {
        /// Key `i` at `i`.
        key_times: Vec<f64>,
        /// The motion parameter of each output frame ([`keys_parameters`]).
        parameters: Vec<f64>,
        /// The given spec with linear timing and, closed, the period `K`.
        spec: MotionSpec,
        /// With `played`: the playback's rows at the output frames
        /// ([`keys_parameters_played`]); else empty.
        played: Vec<f64>,
    },
}

/// How the motion of keys at `key_frames` with `spec` is sampled at `frames`: one entry for
/// every [`Timing`]. A map of time (Smooth, Linear) samples at the frames themselves
/// ([`Timed::Frames`]); a [`paced`](Timing::paced) timing (Keys) at the motion parameters
/// [`keys_parameters`] gives from `size` and `playback` (the body's half-extent and
/// Blender's playback, see [`KeysTiming`]), along the smoothed motion `source`, with the
/// playback's rows at the frames when `played` ([`keys_parameters_played`]); sampling the
/// motion there with [`Timed::Parameters`]' key times and spec is timing Keys, to the bit.
///
/// # Errors
/// For a paced timing: [`Error::Value`] without a size, [`Error::Period`] for a closed
/// motion without its period, then the errors of [`screw_pace_poses`] and
/// [`keys_parameters`].
pub fn timed_frames(
    key_frames: &[f64],
    frames: &[f64],
    spec: &MotionSpec,
    size: Option<f64>,
    playback: Option<&Playback>,
    source: PaceSource<'_>,
    played: bool,
) -> Result<Timed> {
    if !spec.timing.paced() {
        return Ok(Timed::Frames);
    }
    let size = size.ok_or(Error::Value {
        what: "size",
        at: None,
        value: f64::NAN,
        expected: Expected::PositiveUpTo(MAX_COORDINATE),
    })?;
    let period = match (spec.closed, spec.period) {
        (true, None) => {
            return Err(Error::Period {
                period: f64::NAN,
                span: 0.0,
            })
        }
        (true, period) => period,
        (false, _) => None,
    };
    let timing = KeysTiming {
        key_frames,
        period,
        size,
        playback,
    };
    let smoothed;
    let smooth = match source {
        PaceSource::Keys(keys) => {
            smoothed = screw_pace_poses(keys, spec.scheme, spec.levels, spec.closed)?;
            &smoothed[..]
        }
        PaceSource::Given(smooth) => smooth,
    };
    let (parameters, played) = parameters_and_played(&timing, frames, smooth, played)?;
    let k = key_frames.len();
    Ok(Timed::Parameters {
        key_times: collected(k, (0..k).map(|i| i as f64), "key parameters")?,
        parameters,
        spec: MotionSpec {
            period: spec.closed.then_some(k as f64),
            timing: Timing::Linear,
            ..*spec
        },
        played,
    })
}

/// [`keys_parameters`], with the played rows of [`keys_parameters_played`] when `played`
/// (else an empty vector).
fn parameters_and_played(
    timing: &KeysTiming<'_>,
    frames: &[f64],
    smooth: &[Pose],
    played: bool,
) -> Result<(Vec<f64>, Vec<f64>)> {
    let key_frames = timing.key_frames;
    let k = key_frames.len();
    if k < 2 {
        return Err(Error::TooFew { got: k, need: 2 });
    }
    check_key_times(key_frames)?;
    let mut ends = collected(k + 1, key_frames.iter().copied(), "span ends")?;
    if let Some(period) = timing.period {
        ends.push(check_period(key_frames, period)?);
    }
    let spans = ends.len() - 1;
    let size = timing.size;
    if !(size > 0.0 && size <= MAX_COORDINATE) {
        return Err(Error::Value {
            what: "size",
            at: None,
            value: size,
            expected: Expected::PositiveUpTo(MAX_COORDINATE),
        });
    }
    for (index, &f) in frames.iter().enumerate() {
        check_time("frame", index, f)?;
    }
    for (index, pose) in smooth.iter().enumerate() {
        pose.check_range(index)?;
    }
    let per_span = PACE_SAMPLES + 1;
    let grid_len = spans * per_span;
    if smooth.len() != grid_len {
        return Err(Error::LengthMismatch {
            what: "smooth poses",
            expected: grid_len,
            got: smooth.len(),
        });
    }
    let t = frames.len();
    let samples = grid_len.saturating_add(t);
    // Per frame: span, fraction, travelled, output; per sample: span, fraction, done, the two
    // interpolation tables; per grid pose: the two tables; one channel row.
    // (and, asked for, a pose row per frame, the rows at the span ends)
    let pose_width = timing.playback.map_or(0, |p| 3 + p.mode().width());
    let rows_len = if played {
        t.saturating_add(2 * spans).saturating_mul(pose_width)
    } else {
        0
    };
    let bytes = t
        .saturating_mul(4 * 8)
        .saturating_add(samples.saturating_mul(6 * 8))
        .saturating_add(grid_len.saturating_mul(2 * 8))
        .saturating_add(rows_len.saturating_mul(8));
    check_footprint(bytes, "timing Keys", "bake fewer frames")?;

    let span_of = |frame: f64| {
        ends.partition_point(|&e| e <= frame)
            .saturating_sub(1)
            .min(spans - 1)
    };
    let located = collected(
        t,
        frames.iter().map(|&f| {
            let s = span_of(f);
            (s, (f - ends[s]) / (ends[s + 1] - ends[s]))
        }),
        "frame spans",
    )?;
    let inside = |tau: f64| tau > 0.0 && tau < 1.0;
    let grid = |j: usize| j as f64 / PACE_SAMPLES as f64;

    // Blender's playback: per span the grid, plus the output frames inside it (or, for a span
    // with more than DENSE_PACE_SAMPLES of them, a grid that fine instead), in order.
    let mut inside_count = vec![0usize; spans];
    for &(s, tau) in &located {
        if inside(tau) {
            inside_count[s] += 1;
        }
    }
    // (span, fraction of time, the output frame it is, or NOT_OUTPUT)
    let mut sampled: Vec<Sample> = try_vec(samples, "pace samples")?;
    sampled.extend((0..spans).flat_map(|s| (0..per_span).map(move |j| (s, grid(j), NOT_OUTPUT))));
    sampled.extend(
        located
            .iter()
            .enumerate()
            .filter(|&(_, &(s, tau))| inside(tau) && inside_count[s] <= DENSE_PACE_SAMPLES)
            .map(|(i, &(s, tau))| (s, tau, i)),
    );
    for (s, &count) in inside_count.iter().enumerate() {
        if count > DENSE_PACE_SAMPLES {
            sampled.extend(
                (1..DENSE_PACE_SAMPLES)
                    .map(|j| (s, j as f64 / DENSE_PACE_SAMPLES as f64, NOT_OUTPUT)),
            );
        }
    }
    sampled.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let mut rows = if played && pose_width > 0 {
        let mut rows = try_vec(rows_len, "played rows")?;
        rows.resize(rows_len, f64::NAN);
        Some(Played {
            rows,
            width: pose_width,
            frames,
        })
    } else {
        None
    };
    let done = playback_fractions(
        timing.playback,
        &ends,
        frames,
        &sampled,
        size,
        rows.as_mut(),
    )?;
    let xp = collected(
        samples,
        sampled.iter().map(|&(s, f, _)| s as f64 + f),
        "pace samples",
    )?;
    let fp = collected(
        samples,
        sampled
            .iter()
            .zip(&done)
            .map(|(&(s, _, _), d)| s as f64 + d),
        "pace samples",
    )?;
    drop(sampled);

    // The smoothed motion's own travel along each span.
    let mut x = try_vec(grid_len, "pace table")?;
    let mut y = try_vec(grid_len, "pace table")?;
    let mut along = Vec::with_capacity(per_span);
    for s in 0..spans {
        let poses = &smooth[s * per_span..(s + 1) * per_span];
        along.clear();
        along.push(0.0);
        let mut sum = 0.0;
        for pair in poses.windows(2) {
            sum += travel(&pair[0], &pair[1], size);
            along.push(sum);
        }
        for (j, a) in along.iter().enumerate() {
            x.push(s as f64 + if sum > 0.0 { a / sum } else { grid(j) });
            y.push(s as f64 + grid(j));
        }
    }
    let out = collected(
        t,
        located.iter().map(|&(s, tau)| {
            let base = s as f64;
            if inside(tau) {
                let travelled = interp(base + tau, &xp, &fp) - base;
                interp(base + travelled, &x, &y)
            } else {
                base + tau
            }
        }),
        "motion parameters",
    )?;
    // Outside the keys the parameter extrapolates: a frame far from keys very close together
    // could leave the floating-point range.
    if let Some(index) = out.iter().position(|u| !u.is_finite()) {
        return Err(Error::Overflow {
            what: "frames",
            at: Some(At::new("frame", index)),
            hint: "the frame is too far from the keys for their spacing: its motion parameter \
                   is not finite",
        });
    }
    let Some(mut rows) = rows else {
        return Ok((out, Vec::new()));
    };
    // Frames at a key (the start of their span) and at the end of the last span were played
    // as the span's first and last grid samples: their rows, when played at that very frame.
    for (i, &(s, tau)) in located.iter().enumerate() {
        let end = if tau == 0.0 {
            0
        } else if tau == 1.0 {
            1
        } else {
            continue;
        };
        let at = (rows.frames.len() + 2 * s + end) * rows.width;
        if rows.rows[at].is_nan() || sample_frame(&ends, s, end as f64) != frames[i] {
            continue;
        }
        rows.rows.copy_within(at..at + rows.width, i * rows.width);
    }
    rows.rows.truncate(t * rows.width);
    Ok((out, rows.rows))
}

/// A pace sample: (span, fraction of its time, the output frame it is or [`NOT_OUTPUT`]).
type Sample = (usize, f64, usize);

/// A pace sample that is not an output frame.
const NOT_OUTPUT: usize = usize::MAX;

/// The playback's pose rows kept for the caller: one per output frame, then the first and
/// last grid sample of each span (NaN where not played).
struct Played<'a> {
    rows: Vec<f64>,
    width: usize,
    frames: &'a [f64],
}

impl Played<'_> {
    /// Keeps `row` (a channel row) of `sample`: an output frame's, or a span's first or last.
    fn keep(&mut self, sample: &Sample, row: &[f64]) {
        let &(s, f, output) = sample;
        let slot = if output != NOT_OUTPUT {
            output
        } else if f == 0.0 {
            self.frames.len() + 2 * s
        } else if f == 1.0 {
            self.frames.len() + 2 * s + 1
        } else {
            return;
        };
        let at = slot * self.width;
        self.rows[at..at + self.width].copy_from_slice(&row[..self.width]);
    }
}

/// The frame of the fraction `f` of span `s`'s time.
fn sample_frame(ends: &[f64], s: usize, f: f64) -> f64 {
    ends[s] + f * (ends[s + 1] - ends[s])
}

/// The fraction of its span's travel along Blender's playback done at each sample
/// (`(span, fraction of time)`, sorted): 0 at the span's start, 1 at its end; the fraction
/// of time without playback or over a span where the playback does not move.
fn playback_fractions(
    playback: Option<&Playback>,
    ends: &[f64],
    frames: &[f64],
    sampled: &[Sample],
    size: f64,
    mut rows: Option<&mut Played<'_>>,
) -> Result<Vec<f64>> {
    let Some(playback) = playback else {
        return collected(
            sampled.len(),
            sampled.iter().map(|&(_, f, _)| f),
            "pace fractions",
        );
    };
    let mut done = try_vec(sampled.len(), "pace fractions")?;
    let mut row = Vec::with_capacity(playback.width());
    let mut previous: Option<(usize, DVec3, DMat3)> = None;
    let mut start = 0; // the first sample of the current span
    let mut sum = 0.0;
    let finish = |done: &mut Vec<f64>, start: usize, sum: f64| {
        if sum > 0.0 {
            for d in &mut done[start..] {
                *d /= sum;
            }
        } else {
            for (d, &(_, f, _)) in done[start..].iter_mut().zip(&sampled[start..]) {
                *d = f;
            }
        }
    };
    for (i, sample) in sampled.iter().enumerate() {
        let (s, f, output) = *sample;
        // an output frame is played at that very frame, a grid sample at its fraction
        let frame = if output == NOT_OUTPUT {
            sample_frame(ends, s, f)
        } else {
            frames[output]
        };
        playback.pose_channels_into(&[frame], &mut row)?;
        if let Some(rows) = rows.as_deref_mut() {
            rows.keep(sample, &row);
        }
        let location = DVec3::new(row[0], row[1], row[2]);
        let rotation = playback.rotation(&row);
        match previous {
            Some((p, ref pl, ref pr)) if p == s => {
                sum += travel_between(*pl, pr, location, &rotation, size);
            }
            Some(_) => {
                finish(&mut done, start, sum);
                start = i;
                sum = 0.0;
            }
            None => {}
        }
        done.push(sum);
        previous = Some((s, location, rotation));
    }
    finish(&mut done, start, sum);
    Ok(done)
}

#[cfg(test)]
mod timed_tests {
    use glam::DQuat;

    use super::super::tests::{curve, playback};
    use super::*;
    use crate::{sample, Channel, EulerOrder, Interpolation, RotationMode};

    /// Three keys: a move along X and a turn about Z, Blender's playback of them (Bezier,
    /// auto handles) and the key poses.
    fn scene() -> (Playback, Vec<f64>, Vec<Pose>) {
        let key_frames = vec![1.0, 9.0, 30.0];
        let x = [(1.0, 0.0), (9.0, 2.0), (30.0, 7.0)];
        let z = [(1.0, 0.0), (9.0, 0.8), (30.0, 2.5)];
        let p = playback(
            vec![
                (Channel::Location(0), curve(&x, Interpolation::Bezier)),
                (Channel::Rotation(2), curve(&z, Interpolation::Bezier)),
            ],
            RotationMode::Euler(EulerOrder::Xyz),
        );
        let poses = x
            .iter()
            .zip(&z)
            .map(|(&(_, tx), &(_, rz))| {
                Pose::from_rotation_translation(
                    DQuat::from_rotation_z(f64::from(rz)),
                    DVec3::new(f64::from(tx), 0.0, 0.0),
                )
            })
            .collect();
        (p, key_frames, poses)
    }

    #[test]
    fn a_map_of_time_samples_at_the_frames_themselves() {
        let (p, key_frames, poses) = scene();
        for timing in [Timing::Smooth, Timing::Linear] {
            let spec = MotionSpec {
                timing,
                ..MotionSpec::default()
            };
            let timed = timed_frames(
                &key_frames,
                &[2.0, 5.0],
                &spec,
                None,
                Some(&p),
                PaceSource::Keys(&poses),
                true,
            );
            assert_eq!(timed, Ok(Timed::Frames), "{timing:?}");
        }
    }

    #[test]
    fn timing_keys_is_keys_parameters_and_samples_as_before_to_the_bit() {
        let (p, key_frames, poses) = scene();
        let frames: Vec<f64> = (0..=70).map(|i| 0.5 * i as f64).collect();
        for closed in [false, true] {
            let period = closed.then_some(35.0);
            let spec = MotionSpec {
                scheme: Scheme::FourPoint,
                levels: 3,
                closed,
                period,
                timing: Timing::Keys,
            };
            let Timed::Parameters {
                key_times,
                parameters,
                spec: linear,
                played,
            } = timed_frames(
                &key_frames,
                &frames,
                &spec,
                Some(1.5),
                Some(&p),
                PaceSource::Keys(&poses),
                true,
            )
            .unwrap()
            else {
                panic!("timing Keys is paced");
            };
            // what the add-on computed before: keys_parameters on the screw pace poses, then
            // the motion at those parameters, keys at 0..K-1, linear timing
            let smooth = screw_pace_poses(&poses, Scheme::FourPoint, 3, closed).unwrap();
            let timing = KeysTiming {
                key_frames: &key_frames,
                period,
                size: 1.5,
                playback: Some(&p),
            };
            let (want, want_rows) = keys_parameters_played(&timing, &frames, &smooth).unwrap();
            assert_eq!(parameters, want, "closed {closed}");
            assert_eq!(played.len(), want_rows.len());
            assert!(played
                .iter()
                .zip(&want_rows)
                .all(|(a, b)| a.to_bits() == b.to_bits()));
            assert_eq!(key_times, [0.0, 1.0, 2.0]);
            let before = MotionSpec {
                scheme: Scheme::FourPoint,
                levels: 3,
                closed,
                period: closed.then_some(3.0),
                timing: Timing::Linear,
            };
            assert_eq!(linear, before);
            assert_eq!(
                sample(&poses, &key_times, &parameters, &linear).unwrap(),
                sample(&poses, &[0.0, 1.0, 2.0], &want, &before).unwrap()
            );
            // the pace's smoothed motion given by the caller: the same parameters
            let given = timed_frames(
                &key_frames,
                &frames,
                &spec,
                Some(1.5),
                Some(&p),
                PaceSource::Given(&smooth),
                false,
            )
            .unwrap();
            assert!(
                matches!(&given, Timed::Parameters { parameters: u, played, .. } if *u == want && played.is_empty()),
                "{given:?}"
            );
        }
    }

    #[test]
    fn timing_keys_needs_the_size_and_a_closed_motion_its_period() {
        let (p, key_frames, poses) = scene();
        let keys = MotionSpec {
            timing: Timing::Keys,
            ..MotionSpec::default()
        };
        let source = PaceSource::Keys(&poses);
        let err = timed_frames(&key_frames, &[2.0], &keys, None, Some(&p), source, false);
        assert!(
            matches!(err, Err(Error::Value { what: "size", .. })),
            "{err:?}"
        );
        let closed = MotionSpec {
            closed: true,
            ..keys
        };
        let err = timed_frames(&key_frames, &[2.0], &closed, Some(1.0), None, source, false);
        assert!(matches!(err, Err(Error::Period { .. })), "{err:?}");
        // and the motion itself refuses a paced timing: it is not a map of time alone
        let err = sample(&poses, &key_frames, &[2.0], &keys).unwrap_err();
        assert!(
            matches!(err, Error::Conflict { what: "timing", .. }),
            "{err}"
        );
        assert_eq!(
            err.to_string(),
            "timing: timing keys follows a playback's pace: it needs the body's size and the \
             playback, not only the key times"
        );
    }
}
