//! Many owners' keys read in one call: what the add-on's `keys.read` computes per owner from
//! its packed transform curves, for every selected owner at once.
//!
//! For each owner, from its curves (a range of one [`PackedCurves`] set, which owners sharing
//! an action share): its [`Playback`], its **key frames** (the union of its curves' key
//! frames, two closer than [`KEY_FRAME_TOLERANCE`] being one), its channel rows there (played,
//! or with `key_values` the curves' key values when every curve is keyed on every key frame),
//! its rigid **key poses** `T R` ([`rotation_matrix`]), and, when asked, what
//! [`analyse_turns`] says of its spans, with the channel rows at the frames it inserts into
//! spins. This is, to the bit, `Playback(...)`, `Playback.channels(frames)`,
//! `rotation_matrices`, `analyse_turns` and `Playback.channels(inserted)` called one after
//! the other for each owner, as `keys.read` calls them.

use std::ops::Range;

use glam::DMat3;

use crate::error::{At, Error, Expected, Result};
use crate::fcurve::PackedCurves;
use crate::intent::playback::{rotation_matrix, Channel, Playback};
use crate::intent::spans::{analyse_turns, Spans};
use crate::intent::turns::Turns;
use crate::memory::try_vec;
use crate::RotationMode;

/// Two key frames closer than this (frames) are one key frame of the owner (the add-on's
/// `keyed.FRAME_TOLERANCE`): of the sorted distinct frames of its curves, a frame is kept when
/// it lies more than this beyond the frame before it.
pub const KEY_FRAME_TOLERANCE: f64 = 1e-4;

/// One owner's curves and what to read of them ([`read_owners`]).
#[derive(Clone, Debug)]
pub struct OwnerKeys<'a> {
    /// Its curves: a range of the packed set's curves.
    pub curves: Range<usize>,
    /// The channel each of its curves drives.
    pub channels: &'a [Channel],
    /// A channel row of the owner's own values (`6 + mode.width()`).
    pub statics: &'a [f64],
    /// Its rotation mode.
    pub mode: RotationMode,
    /// Whether location moves it (not a bone connected to its parent).
    pub located: bool,
    /// Read the channels from the key values when every curve is keyed on every key frame
    /// (a capture: what Blender plays there), without playing the curves.
    pub key_values: bool,
    /// Analyse its spans under this choice ([`analyse_turns`]); `None`: not analysed.
    pub turns: Option<Turns>,
}

/// What [`read_owners`] reads of one owner.
#[derive(Debug)]
pub struct OwnerRead {
    /// Its curves as Blender plays them.
    pub playback: Playback,
    /// The key frames: strictly increasing, at least two.
    pub frames: Vec<f64>,
    /// The channel rows at the key frames, `6 + mode.width()` numbers each.
    pub rows: Vec<f64>,
    /// The rigid key poses, row-major 4 x 4 each: `[R t; 0 0 0 1]`.
    pub poses: Vec<[f64; 16]>,
    /// [`analyse_turns`] of the key frames, when asked.
    pub spans: Option<Spans>,
    /// The channel rows at the spans' inserted frames (`Playback::channels` of them; empty
    /// when none is inserted).
    pub inserted_rows: Vec<f64>,
}

/// The curves `range` of `packed` (checked: [`PackedCurves::check_lengths`]) as a packed
/// set of their own, `offsets` theirs rebased to 0.
fn part<'a>(
    packed: &PackedCurves<'a>,
    range: &Range<usize>,
    offsets: &'a [i64],
) -> PackedCurves<'a> {
    let (lo, hi) = (
        packed.offsets[range.start] as usize,
        packed.offsets[range.end] as usize,
    );
    PackedCurves {
        offsets,
        co: &packed.co[2 * lo..2 * hi],
        handle_left: &packed.handle_left[2 * lo..2 * hi],
        handle_right: &packed.handle_right[2 * lo..2 * hi],
        interpolation: &packed.interpolation[lo..hi],
        easing: &packed.easing[lo..hi],
        back: &packed.back[lo..hi],
        amplitude: &packed.amplitude[lo..hi],
        period: &packed.period[lo..hi],
        extrapolation: &packed.extrapolation[range.clone()],
        cycles: if packed.cycles.is_empty() {
            &[]
        } else {
            &packed.cycles[range.clone()]
        },
    }
}

/// The union of `frames` (any order): sorted, equal frames once, and a frame within
/// [`KEY_FRAME_TOLERANCE`] of the distinct frame before it dropped.
pub fn key_frame_union(mut frames: Vec<f64>) -> Vec<f64> {
    frames.sort_by(f64::total_cmp);
    frames.dedup();
    let mut out = Vec::with_capacity(frames.len());
    for (i, &f) in frames.iter().enumerate() {
        if i == 0 || f - frames[i - 1] > KEY_FRAME_TOLERANCE {
            out.push(f);
        }
    }
    out
}

/// One owner's playback, key frames, channel rows, key poses and spans, from its curves
/// `owner.curves` of `packed` (its lengths and offsets checked: [`read_owners`]; see the
/// module's documentation).
///
/// # Errors
/// What `Playback::new` refuses of its curves (errors name the curve within the owner's);
/// [`Error::TooFew`] for fewer than two key frames; the errors of [`Playback::channels`]
/// and [`analyse_turns`]; [`Error::NotFinite`] for a key row that is not finite;
/// [`Error::Value`] for a keyed scale that is not positive at a key; [`Error::Index`] for a
/// range outside the packed curves.
fn read_owner(packed: &PackedCurves<'_>, owner: &OwnerKeys<'_>) -> Result<OwnerRead> {
    let range = owner.curves.clone();
    if range.start > range.end || range.end > packed.len() {
        return Err(Error::Index {
            what: "owner curves",
            item: "curve",
            at: None,
            index: i64::try_from(range.end).unwrap_or(i64::MAX),
            len: packed.len(),
        });
    }
    let base = packed.offsets[range.start];
    let offsets: Vec<i64> = packed.offsets[range.start..=range.end]
        .iter()
        .map(|o| o - base)
        .collect();
    let curves = part(packed, &range, &offsets).to_curves()?;
    let playback = Playback::new(
        curves,
        owner.channels,
        owner.statics.to_vec(),
        owner.mode,
        owner.located,
    )?;
    let keyed = playback.curves();
    let frames = key_frame_union(
        keyed
            .iter()
            .flat_map(|c| c.keys().iter().map(|k| f64::from(k.co[0])))
            .collect(),
    );
    if frames.len() < 2 {
        return Err(Error::TooFew {
            got: frames.len(),
            need: 2,
        });
    }
    let width = playback.width();
    let every_frame = owner.key_values
        && keyed.iter().all(|c| {
            c.keys().len() == frames.len()
                && c.keys()
                    .iter()
                    .zip(&frames)
                    .all(|(k, &f)| f64::from(k.co[0]) == f)
        });
    let rows = if every_frame {
        // what Blender plays at the keys of a capture: the key values
        let mut rows = try_vec(frames.len().saturating_mul(width), "channel rows")?;
        for _ in 0..frames.len() {
            rows.extend_from_slice(owner.statics);
        }
        for (channel, curve) in owner.channels.iter().zip(keyed) {
            let column = channel.column(owner.mode);
            for (i, key) in curve.keys().iter().enumerate() {
                rows[i * width + column] = f64::from(key.co[1]);
            }
        }
        if !owner.located {
            rows.chunks_exact_mut(width).for_each(|r| r[..3].fill(0.0));
        }
        rows
    } else {
        playback.channels(&frames)?
    };
    let w = owner.mode.width();
    let scaled: Vec<usize> = owner
        .channels
        .iter()
        .filter_map(|c| match c {
            Channel::Scale(i) => Some(3 + w + i),
            _ => None,
        })
        .collect();
    let mut poses = try_vec(frames.len(), "key poses")?;
    for (k, row) in rows.chunks_exact(width).enumerate() {
        if let Some(index) = row.iter().position(|v| !v.is_finite()) {
            return Err(Error::NotFinite {
                what: "key channel",
                index: k * width + index,
            }
            .within("key", k));
        }
        if let Some(&column) = scaled.iter().find(|&&c| row[c] <= 0.0) {
            return Err(Error::Value {
                what: "keyed scale",
                at: Some(At::new("key", k)),
                value: row[column],
                expected: Expected::Positive("scale"),
            });
        }
        poses.push(pose_rows(
            rotation_matrix(owner.mode, &row[3..3 + w]),
            &row[..3],
        ));
    }
    let spans = owner
        .turns
        .map(|turns| analyse_turns(&playback, &frames, turns))
        .transpose()?;
    let inserted_rows = match &spans {
        Some(s) if !s.inserted.is_empty() => playback.channels(&s.inserted)?,
        _ => Vec::new(),
    };
    Ok(OwnerRead {
        playback,
        frames,
        rows,
        poses,
        spans,
        inserted_rows,
    })
}

/// `[R t; 0 0 0 1]` row-major.
fn pose_rows(r: DMat3, t: &[f64]) -> [f64; 16] {
    let mut out = [0.0; 16];
    for i in 0..3 {
        out[4 * i] = r.x_axis[i];
        out[4 * i + 1] = r.y_axis[i];
        out[4 * i + 2] = r.z_axis[i];
        out[4 * i + 3] = t[i];
    }
    out[15] = 1.0;
    out
}

/// Every owner of `owners` read on its own (its playback, key frames, channel rows, key
/// poses and spans: see the module's documentation): an owner refused does not stop the
/// others.
///
/// # Errors
/// The errors of [`PackedCurves::to_curves`] for arrays whose lengths or offsets do not fit
/// together (checked once, for all owners).
pub fn read_owners(
    packed: &PackedCurves<'_>,
    owners: &[OwnerKeys<'_>],
) -> Result<Vec<Result<OwnerRead>>> {
    packed.check_lengths()?;
    Ok(owners.iter().map(|o| read_owner(packed, o)).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fcurve::Extrapolation;

    /// Linear curves of `(frame, value)` keys, packed.
    struct Keys {
        offsets: Vec<i64>,
        co: Vec<f64>,
        ints: Vec<i64>,
        zeros: Vec<i64>,
        ones: Vec<f64>,
        ext: Vec<Extrapolation>,
    }

    impl Keys {
        fn new(curves: &[&[(f64, f64)]]) -> Self {
            let mut offsets = vec![0];
            let mut co = Vec::new();
            for keys in curves {
                co.extend(keys.iter().flat_map(|&(x, y)| [x, y]));
                offsets.push(co.len() as i64 / 2);
            }
            let k = co.len() / 2;
            Keys {
                offsets,
                co,
                ints: vec![1; k], // LINEAR
                zeros: vec![0; k],
                ones: vec![1.0; k],
                ext: vec![Extrapolation::Constant; curves.len()],
            }
        }

        fn packed(&self) -> PackedCurves<'_> {
            PackedCurves {
                offsets: &self.offsets,
                co: &self.co,
                handle_left: &self.co,
                handle_right: &self.co,
                interpolation: &self.ints,
                easing: &self.zeros,
                back: &self.ones,
                amplitude: &self.ones,
                period: &self.ones,
                extrapolation: &self.ext,
                cycles: &[],
            }
        }
    }

    const STATICS: [f64; 9] = [0.5, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0];

    fn owner(curves: Range<usize>, channels: &[Channel]) -> OwnerKeys<'_> {
        OwnerKeys {
            curves,
            channels,
            statics: &STATICS,
            mode: RotationMode::Euler(crate::motion::channels::EulerOrder::Xyz),
            located: true,
            key_values: false,
            turns: Some(Turns::Auto),
        }
    }

    #[test]
    fn each_owner_is_read_alone_and_a_refused_one_stops_nobody() {
        // curve 0: location y keyed 1, 5, 9; curve 1: rotation z keyed 1, 9 (a spin of 6 rad);
        // curve 2: scale x reaching 0 at frame 5; curve 3: one key
        let keys = Keys::new(&[
            &[(1.0, 0.0), (5.0, 1.0), (9.0, 0.0)],
            &[(1.0, 0.0), (9.0, 6.0)],
            &[(1.0, 1.0), (5.0, 0.0)],
            &[(2.0, 1.0)],
        ]);
        let packed = keys.packed();
        let both = [Channel::Location(1), Channel::Rotation(2)];
        let scaled = [Channel::Scale(0)];
        let one = [Channel::Location(0)];
        let asked = [
            owner(0..2, &both),
            owner(2..3, &scaled),
            owner(3..4, &one),
            owner(1..2, &both[1..]),
        ];
        let got = read_owners(&packed, &asked).unwrap();
        let first = got[0].as_ref().unwrap();
        assert_eq!(first.frames, vec![1.0, 5.0, 9.0]);
        let own = Keys::new(&[
            &[(1.0, 0.0), (5.0, 1.0), (9.0, 0.0)],
            &[(1.0, 0.0), (9.0, 6.0)],
        ]);
        let alone = Playback::new(
            own.packed().to_curves().unwrap(),
            &both,
            STATICS.to_vec(),
            RotationMode::Euler(crate::motion::channels::EulerOrder::Xyz),
            true,
        )
        .unwrap();
        assert_eq!(first.rows, alone.channels(&first.frames).unwrap());
        let spans = analyse_turns(&alone, &first.frames, Turns::Auto).unwrap();
        assert_eq!(first.spans.as_ref().unwrap().inserted, spans.inserted);
        assert_eq!(
            first.inserted_rows,
            alone.channels(&spans.inserted).unwrap()
        );
        assert!(
            !spans.inserted.is_empty(),
            "3 radians a span: a spin: {spans:?}"
        );
        // the pose at frame 5: location (0.5, 1, 0), a turn of 3 rad about z
        let (c, s) = (3.0f64.cos(), 3.0f64.sin());
        let p = first.poses[1];
        let want = [
            c, -s, 0.0, 0.5, s, c, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0,
        ];
        for (a, b) in p.iter().zip(want) {
            assert!((a - b).abs() < 1e-6, "{p:?}");
        }
        assert!(matches!(got[1], Err(Error::Value { .. })), "{:?}", got[1]);
        assert!(
            matches!(got[2], Err(Error::TooFew { got: 1, .. })),
            "{:?}",
            got[2]
        );
        assert_eq!(got[3].as_ref().unwrap().frames, vec![1.0, 9.0]);
    }

    #[test]
    fn a_capture_is_read_from_its_key_values_without_playing() {
        let keys = Keys::new(&[&[(1.0, 0.25), (2.0, 0.5), (3.0, 0.75)]]);
        let channels = [Channel::Scale(2)];
        let mut asked = owner(0..1, &channels);
        asked.key_values = true;
        asked.turns = None;
        let got = read_owners(&keys.packed(), &[asked]).unwrap();
        let read = got[0].as_ref().unwrap();
        assert_eq!(read.playback.rows_evaluated(), 0);
        let z: Vec<f64> = read.rows.chunks(9).map(|r| r[8]).collect();
        assert_eq!(z, vec![0.25, 0.5, 0.75]);
    }

    #[test]
    fn key_frames_closer_than_the_tolerance_are_one() {
        let got = key_frame_union(vec![3.0, 1.0, 1.00005, 2.0, 3.0, 1.0002]);
        assert_eq!(got, vec![1.0, 1.0002, 2.0, 3.0]);
    }

    #[test]
    fn a_range_outside_the_curves_is_refused_for_that_owner() {
        let keys = Keys::new(&[&[(1.0, 0.0), (2.0, 1.0)]]);
        let channels = [Channel::Location(0)];
        let got = read_owners(
            &keys.packed(),
            &[owner(0..2, &channels), owner(0..1, &channels)],
        )
        .unwrap();
        assert!(matches!(got[0], Err(Error::Index { .. })));
        assert!(got[1].is_ok());
    }
}
