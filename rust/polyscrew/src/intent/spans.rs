//! Holds, pops and spins: what each key span of an owner's playback does.

use std::f64::consts::PI;

use glam::DMat3;

use super::interp::interp;
use super::limits::{check_footprint, collected, filled};
use super::playback::Playback;
use super::turns::{is_flip, Turns};
use crate::memory::try_vec;
use crate::{check_key_times, Error, Result, RotationMode};

/// A span whose channels turn further than this (radians, 150 degrees) along Blender's
/// playback gets poses from that playback added inside it: the screw between its keys alone,
/// the shortest one, would turn less (at half a turn and beyond: the other way round).
pub const WIND_LIMIT: f64 = 150.0 * (PI / 180.0);

/// The turn (radians, 45 degrees) each screw span of a spin is cut into, at most: the spin
/// span and its neighbours turning more than this, so the screw spans of a spin are short and
/// about equal (approximating schemes then stay within a degree of the keys).
pub const WIND_STEP: f64 = 45.0 * (PI / 180.0);

/// Samples of Blender's playback per key span when looking for holds and turns (more in a
/// span whose rotation channels change a lot: one per [`DEGREES_PER_SAMPLE`]).
pub const SPAN_SAMPLES: usize = 8;

/// At most this many samples per span.
pub const MAX_SPAN_SAMPLES: usize = 4096;

/// At most this many samples of the playback in one [`analyse_spans`] call, all spans
/// together (2**21; spins are walked a second time to place their added frames, so the
/// playback is evaluated at most twice this often). The work is not bounded by memory (a
/// span's samples are reused): this bounds its time, about 2 s of one core at the limit
/// (512 spans of 4,096 samples, each a spin, on a playback of nine curves).
pub const MAX_ANALYSIS_SAMPLES: usize = 1 << 21;

/// Degrees of rotation-channel change (the sum over the Euler angles, or the axis-angle
/// angle) per sample of a span.
pub const DEGREES_PER_SAMPLE: f64 = 10.0;

/// A channel that moves by less than this, relative to its size plus one
/// (`|v - v0| <= HOLD_TOLERANCE (|v0| + 1)`), over a span is still.
pub const HOLD_TOLERANCE: f64 = 1e-6;

/// What each of the `K - 1` key spans does (see [`analyse_spans`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Spans {
    /// Every channel stays at its value at the span's start over the span (its end excluded).
    pub held: Vec<bool>,
    /// Held, and some channel jumps at the span's end (a CONSTANT pop).
    pub pops: Vec<bool>,
    /// The angle (radians) the rotation turns through over the span: the sum of the
    /// rotation angles between consecutive samples of the playback and the span's end.
    pub turn: Vec<f64>,
    /// Frames where poses of the playback must be added (ascending): inside the spans of
    /// spins, so that each screw span of a spin turns at most [`WIND_STEP`]. Which spans
    /// are followed depends on [`Turns`] (quaternion rotation: none with [`Turns::Auto`]).
    pub inserted: Vec<f64>,
    /// Not held, and a flip by the key values ([`is_flip`]: an Euler wrap or a quaternion sign
    /// flip), whatever [`Turns`] does with it.
    pub flips: Vec<bool>,
}

/// The samples of a span from `start` (included) to `end` (excluded), `count` of them:
/// `start + (end - start) j / count`.
fn span_samples(start: f64, end: f64, count: usize, out: &mut Vec<f64>) {
    out.clear();
    let width = end - start;
    out.extend((0..count).map(|j| start + width * (j as f64 / count as f64)));
}

/// Samples for a span whose rotation channels change from `a` to `b` (channel rows' rotation
/// parts): one per [`DEGREES_PER_SAMPLE`] of their change ([`RotationMode::channel_change`]),
/// within [`SPAN_SAMPLES`]..=[`MAX_SPAN_SAMPLES`]. A mode whose values hold no spins
/// (quaternions, [`RotationMode::holds_spins`]): [`SPAN_SAMPLES`], unless every span's turns
/// are followed (`follow_all`, [`Turns::AsPlayed`]): then by the change too (for
/// quaternions the angle between the keys' 4-vectors, doubled: up to 360 degrees for a sign
/// flip that Blender plays the long way).
fn sample_count(mode: RotationMode, a: &[f64], b: &[f64], follow_all: bool) -> usize {
    if !mode.holds_spins() && !follow_all {
        return SPAN_SAMPLES;
    }
    let Some(change) = mode.channel_change(a, b) else {
        return SPAN_SAMPLES;
    };
    let count = (change.to_degrees() / DEGREES_PER_SAMPLE).ceil();
    count.clamp(SPAN_SAMPLES as f64, MAX_SPAN_SAMPLES as f64) as usize
}

/// The angle (radians, in `[0, pi]`) of the rotation taking `a` to `b`:
/// `atan2(|skew(A)| / 2, (tr A - 1) / 2)` with `A = a^T b`.
pub fn rotation_angle(a: &DMat3, b: &DMat3) -> f64 {
    let r = a.transpose() * *b;
    let cos = ((r.x_axis.x + r.y_axis.y + r.z_axis.z - 1.0) / 2.0).clamp(-1.0, 1.0);
    // r[i][j] is row i, column j: col(j)[i].
    let skew = glam::DVec3::new(
        r.y_axis.z - r.z_axis.y,
        r.z_axis.x - r.x_axis.z,
        r.x_axis.y - r.y_axis.x,
    );
    (skew.length() / 2.0).atan2(cos)
}

/// Whether channel row `v` differs from `v0` by more than [`HOLD_TOLERANCE`] anywhere.
fn moves(v0: &[f64], v: &[f64]) -> bool {
    v0.iter()
        .zip(v)
        .any(|(a, b)| (b - a).abs() > HOLD_TOLERANCE * (a.abs() + 1.0))
}

/// [`analyse_turns`] with [`Turns::Auto`].
///
/// # Errors
/// Those of [`analyse_turns`].
pub fn analyse_spans(playback: &Playback, frames: &[f64]) -> Result<Spans> {
    analyse_turns(playback, frames, Turns::Auto)
}

/// Per key span of `frames` (`K >= 2`, strictly increasing): whether it is held, whether the
/// pose pops at its end, its turn, whether it is a flip, and the frames where poses must be
/// added for the spins `turns` follows.
///
/// Each span is sampled at [`SPAN_SAMPLES`] evenly spaced frames from its start (included)
/// to its end (excluded), more where the rotation channels change a lot between its keys
/// (one per [`DEGREES_PER_SAMPLE`], at most [`MAX_SPAN_SAMPLES`]). A span is held when no
/// channel of any sample moves from the span's start by more than [`HOLD_TOLERANCE`]; it
/// pops when it is held and a channel differs between its keys. Its turn is the sum of
/// [`rotation_angle`]s between consecutive samples and from the last sample to the span's
/// end. All spans together take at most [`MAX_ANALYSIS_SAMPLES`] samples. A span is a flip when it is not held and its key values are an Euler wrap or a
/// quaternion sign flip ([`is_flip`]). A span is *followed* when `turns` is
/// [`Turns::AsPlayed`]; with [`Turns::Auto`] when it is not a flip and the mode's values hold
/// spins ([`RotationMode::holds_spins`]: Euler, axis-angle; quaternion keys keep the shortest
/// arc); never with [`Turns::Shortest`]. Spins:
/// a followed span that is not held and turns more than [`WIND_LIMIT`], together with the
/// runs of neighbouring followed spans that are not held and turn more than [`WIND_STEP`],
/// gets `ceil(turn / WIND_STEP) - 1` frames where the accumulated turn along its samples
/// reaches equal fractions of the span's turn (linear between samples).
///
/// # Errors
/// [`Error::TooFew`] for fewer than two frames, [`Error::KeyTimes`] for frames that are not
/// finite and strictly increasing, the errors of [`Playback::channels`], and a request over
/// the size limit ([`check_footprint`]), [`Error::LimitOver`] for spans that would
/// take more than [`MAX_ANALYSIS_SAMPLES`] samples in all (before any is taken).
pub fn analyse_turns(playback: &Playback, frames: &[f64], turns: Turns) -> Result<Spans> {
    let k = frames.len();
    if k < 2 {
        return Err(Error::TooFew { got: k, need: 2 });
    }
    check_key_times(frames)?;
    let spans = k - 1;
    let width = playback.width();
    let mode = playback.mode();
    let rotation = 3..3 + mode.width();
    // The key rows, per-span results, one span's samples (frames, rows, steps).
    let f64s = k
        .saturating_mul(width)
        .saturating_add(spans.saturating_mul(4))
        .saturating_add(MAX_SPAN_SAMPLES.saturating_mul(width + 2));
    check_footprint(
        f64s.saturating_mul(std::mem::size_of::<f64>()),
        "span analysis",
        "analyse fewer key frames",
    )?;
    let at_keys = playback.channels(frames)?;
    let key_row = |i: usize| &at_keys[i * width..(i + 1) * width];
    let counts = collected(
        spans,
        (0..spans).map(|s| {
            sample_count(
                mode,
                &key_row(s)[rotation.clone()],
                &key_row(s + 1)[rotation.clone()],
                turns == Turns::AsPlayed,
            )
        }),
        "spans",
    )?;
    let total = counts.iter().fold(0usize, |a, &c| a.saturating_add(c));
    if total > MAX_ANALYSIS_SAMPLES {
        return Err(Error::LimitOver {
            what: "frames",
            parts: spans,
            of: "key spans",
            counted: "samples of the playback",
            count: total,
            limit: MAX_ANALYSIS_SAMPLES,
            hint: "analyse fewer key frames at once (a span takes one sample per few degrees \
                   its rotation channels turn)",
        });
    }

    let mut held = filled(spans, true, "spans")?;
    let mut pops = filled(spans, false, "spans")?;
    let mut turn = filled(spans, 0.0, "spans")?;
    let mut times = Vec::with_capacity(MAX_SPAN_SAMPLES);
    let mut rows = Vec::with_capacity(MAX_SPAN_SAMPLES * width);
    let mut steps = Vec::with_capacity(MAX_SPAN_SAMPLES);
    // The rotation steps of span `s` along its samples, into `steps`; whether it is held.
    let mut walk = |s: usize, steps: &mut Vec<f64>| -> Result<bool> {
        span_samples(frames[s], frames[s + 1], counts[s], &mut times);
        playback.channels_into(&times, &mut rows)?;
        let start = key_row(s);
        let still = !rows.chunks_exact(width).any(|row| moves(start, row));
        steps.clear();
        let mut previous = playback.rotation(&rows[..width]);
        for j in 1..=counts[s] {
            let next = if j < counts[s] {
                playback.rotation(&rows[j * width..(j + 1) * width])
            } else {
                playback.rotation(key_row(s + 1))
            };
            steps.push(rotation_angle(&previous, &next));
            previous = next;
        }
        Ok(still)
    };
    for s in 0..spans {
        held[s] = walk(s, &mut steps)?;
        turn[s] = steps.iter().sum();
        pops[s] = held[s] && moves(key_row(s), key_row(s + 1));
    }

    let mut flips = filled(spans, false, "spans")?;
    for s in 0..spans {
        flips[s] = !held[s]
            && is_flip(
                mode,
                &key_row(s)[rotation.clone()],
                &key_row(s + 1)[rotation.clone()],
            );
    }
    let follows = |s: usize| {
        !held[s]
            && match turns {
                Turns::AsPlayed => true,
                Turns::Auto => mode.holds_spins() && !flips[s],
                Turns::Shortest => false,
            }
    };
    let mut inserted = Vec::new();
    if turns != Turns::Shortest {
        let mut spinning = filled(spans, false, "spans")?;
        let turning = |s: usize| turn[s] > WIND_STEP && follows(s);
        for s in 0..spans {
            let spin = turn[s] > WIND_LIMIT && follows(s);
            if !spin {
                continue; // the runs of neighbours are found from the spins
            }
            spinning[s] = true;
            let mut left = s;
            while left > 0 && turning(left - 1) {
                left -= 1;
                spinning[left] = true;
            }
            let mut right = s;
            while right + 1 < spans && turning(right + 1) {
                right += 1;
                spinning[right] = true;
            }
        }
        let pieces = |s: usize| (turn[s] / WIND_STEP).ceil() as usize;
        let added: usize = (0..spans)
            .filter(|&s| spinning[s])
            .map(|s| pieces(s).saturating_sub(1))
            .fold(0, usize::saturating_add);
        check_footprint(
            added.saturating_mul(std::mem::size_of::<f64>()),
            "inserted frames",
            "analyse fewer key frames",
        )?;
        inserted = try_vec(added, "inserted frames")?;
        let mut cumulative = Vec::with_capacity(MAX_SPAN_SAMPLES + 1);
        let mut at = Vec::with_capacity(MAX_SPAN_SAMPLES + 1);
        for s in (0..spans).filter(|&s| spinning[s]) {
            walk(s, &mut steps)?;
            cumulative.clear();
            cumulative.push(0.0);
            let mut sum = 0.0;
            for step in &steps {
                sum += step;
                cumulative.push(sum);
            }
            span_samples(frames[s], frames[s + 1], counts[s], &mut at);
            at.push(frames[s + 1]);
            let n = pieces(s);
            for j in 1..n {
                let target = turn[s] * j as f64 / n as f64;
                inserted.push(interp(target, &cumulative, &at));
            }
        }
    }
    Ok(Spans {
        held,
        pops,
        turn,
        inserted,
        flips,
    })
}
