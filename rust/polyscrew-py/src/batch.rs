//! Binding of many owners' sampling in one call (`polyscrew::intent::batch`): the owners'
//! arrays concatenated, read, handed to the core owner by owner, the channels written back
//! concatenated. Conversion only.

use glam::DVec3;
use numpy::ndarray::{Array1, Array2};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArrayDyn};
use pyo3::prelude::*;

use polyscrew::intent::{
    sample_owner_channels, sample_owner_poses, OwnerMotion, Playback, Segment,
};
use polyscrew::memory::{try_vec, Footprint};
use polyscrew::{Error, Pose, RotationMode, Scheme, Timing};

use crate::args::{self, copy_of, float_array, int_array, Choice, Function, SampleOwners};
use crate::arrays::{read_keys, read_spec, read_vec3s, read_vector};
use crate::errors::{check_budget, invalid, shape_err, to_py_err};
use crate::intent::{playback_arg, PyPlayback};

/// How to ask for less memory.
const HINT: &str = "sample fewer owners or frames in one call";

/// The result: locations, rotation channels (or poses), log-scales, played rows, status per
/// owner.
type Out<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArrayDyn<f64>>,
    Option<Bound<'py, PyArray2<f64>>>,
    Option<Bound<'py, PyArray2<f64>>>,
    Bound<'py, PyArray1<i64>>,
);

/// `values` (`n x width`, row-major) as an `(n, width)` array.
fn rows(values: Vec<f64>, width: usize) -> PyResult<Array2<f64>> {
    let n = values.len() / width.max(1);
    Array2::from_shape_vec((n, width), values)
        .map_err(|e| invalid(format!("{}: {e}", SampleOwners::NAME)))
}

/// An optional per-owner float argument (`NaN`: none), `owners` long.
fn per_owner(
    what: &'static str,
    obj: Option<&Bound<'_, PyAny>>,
    owners: usize,
) -> PyResult<Vec<f64>> {
    const F: &str = SampleOwners::NAME;
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(vec![f64::NAN; owners]);
    };
    let arg = float_array(F, what, obj)?;
    if arg.shape() != [owners] {
        return Err(shape_err(F, what, &format!("({owners},)"), arg.shape()));
    }
    let array = arg.read()?;
    Ok(array.as_array().iter().copied().collect())
}

/// An optional per-owner flag (0 or 1), `owners` long (false when not given).
fn flags(what: &'static str, obj: Option<&Bound<'_, PyAny>>, owners: usize) -> PyResult<Vec<bool>> {
    args::per_owner_flags(SampleOwners::NAME, what, obj, owners, false)
}

/// An `(N, columns)` integer table.
fn table(what: &'static str, obj: &Bound<'_, PyAny>, columns: usize) -> PyResult<Vec<usize>> {
    const F: &str = SampleOwners::NAME;
    let arg = int_array(F, what, obj)?;
    let shape = arg.shape().to_vec();
    if shape.len() != 2 || shape[1] != columns {
        return Err(shape_err(F, what, &format!("(N, {columns})"), &shape));
    }
    let array = arg.read()?;
    array
        .as_array()
        .iter()
        .map(|&v| usize::try_from(v).map_err(|_| invalid(format!("{F}: {what}: {v} is negative"))))
        .collect()
}

/// sample_owners(
///     poses: ArrayLike,
///     key_frames: ArrayLike,
///     frames: ArrayLike,
///     counts: ArrayLike,
///     segments: ArrayLike,
///     mode: RotationModeName,
///     *,
///     closed: ArrayLike | None = None,
///     period: ArrayLike | None = None,
///     size: ArrayLike | None = None,
///     playbacks: Sequence[Playback | None] | None = None,
///     previous: ArrayLike | None = None,
///     log_scales: ArrayLike | None = None,
///     scaled: ArrayLike | None = None,
///     scheme: SchemeName = "four_point",
///     levels: int = 4,
///     timing: TimingName = "smooth",
///     played: bool = False,
///     as_poses: bool = False,
/// ) -> tuple[FloatArray, FloatArray, FloatArray | None, FloatArray | None, IntArray]
///
/// Many owners' smoothed motions (rotation ``mode``) as Blender channels in one call: for
/// each owner, exactly what ``timed_frames`` then ``sample_channels`` (and ``sample_vectors``
/// of its log-scales) give for each of its pieces, and ``rotation_channels`` for each hold,
/// channels continued from segment to segment.
///
/// The owners' arrays are concatenated: ``poses`` (K, 4, 4) and ``key_frames`` (K,) the keys,
/// ``frames`` (T,) the output frames (sorted per owner); ``counts`` (O, 3) each owner's keys,
/// frames and segments; ``segments`` (S, 4) rows ``(lo, hi, start, end)``: rows ``start:end``
/// of the owner's frames sampled from its keys ``lo..hi`` (a hold of key ``lo`` when ``hi ==
/// lo``; a piece that is not the whole motion is open). Per owner, optional: ``closed`` (0 or
/// 1) and ``period`` (NaN: none) of the whole motion, ``size`` (NaN: none), its ``playbacks``
/// entry, ``previous`` (O, width) rotation channels to continue from (a NaN row: none),
/// ``scaled`` (0 or 1) whether its rows of ``log_scales`` (K, 3) are sampled.
///
/// Returns locations (T, 3), rotation channels (T, width), log-scales (T, 3) (zero rows for
/// owners not scaled; None without ``log_scales``), with ``played`` the rows timing Keys
/// played (T, 3 + width; NaN elsewhere; else None), and per owner a status (int64): 1 sampled
/// with played rows, 0 sampled, -1 refused (its rows zero: sample that owner alone to learn
/// why). With ``as_poses`` the second array is the rigid poses (T, 4, 4) instead of rotation
/// channels: exactly what ``timed_frames`` then ``sample`` give for each piece, a hold its
/// key pose (``previous`` unused). GIL released. Raises ValueError for arrays that do not
/// fit together.
#[pyfunction]
#[pyo3(signature = (poses, key_frames, frames, counts, segments, mode, *, closed=None, period=None, size=None, playbacks=None, previous=None, log_scales=None, scaled=None, scheme=Choice::of(Scheme::FourPoint), levels=4, timing=Choice::of(Timing::Smooth), played=false, as_poses=false))]
#[pyo3(
    text_signature = "(poses, key_frames, frames, counts, segments, mode, *, closed=None, period=None, size=None, playbacks=None, previous=None, log_scales=None, scaled=None, scheme='four_point', levels=4, timing='smooth', played=False, as_poses=False)"
)]
#[allow(clippy::too_many_arguments)]
fn sample_owners<'py>(
    py: Python<'py>,
    poses: &Bound<'py, PyAny>,
    key_frames: &Bound<'py, PyAny>,
    frames: &Bound<'py, PyAny>,
    counts: &Bound<'py, PyAny>,
    segments: &Bound<'py, PyAny>,
    mode: Choice<SampleOwners, RotationMode>,
    closed: Option<&Bound<'py, PyAny>>,
    period: Option<&Bound<'py, PyAny>>,
    size: Option<&Bound<'py, PyAny>>,
    playbacks: Option<&Bound<'py, PyAny>>,
    previous: Option<&Bound<'py, PyAny>>,
    log_scales: Option<&Bound<'py, PyAny>>,
    scaled: Option<&Bound<'py, PyAny>>,
    scheme: Choice<SampleOwners, Scheme>,
    #[pyo3(from_py_with = args::levels::<SampleOwners>)] levels: u32,
    timing: Choice<SampleOwners, Timing>,
    #[pyo3(from_py_with = played_arg)] played: bool,
    #[pyo3(from_py_with = as_poses_arg)] as_poses: bool,
) -> PyResult<Out<'py>> {
    const F: &str = SampleOwners::NAME;
    let mode = mode.0;
    let width = mode.width();
    let out_rotation = if as_poses { 16 } else { width };
    let counts = table("counts", counts, 3)?;
    let owners = counts.len() / 3;
    let segments = table("segments", segments, 4)?;
    let closed = flags("closed", closed, owners)?;
    let scaled = flags("scaled", scaled, owners)?;
    let periods = per_owner("period", period, owners)?;
    let sizes = per_owner("size", size, owners)?;
    let playbacks: Vec<Option<Bound<'py, PyPlayback>>> = match playbacks.filter(|p| !p.is_none()) {
        None => vec![None; owners],
        Some(list) => {
            let items: Vec<Bound<'py, PyAny>> = list.try_iter()?.collect::<PyResult<_>>()?;
            if items.len() != owners {
                return Err(shape_err(
                    F,
                    "playbacks",
                    &format!("({owners},)"),
                    &[items.len()],
                ));
            }
            items
                .iter()
                .map(|p| {
                    (!p.is_none())
                        .then(|| playback_arg(F, "playbacks", p).cloned())
                        .transpose()
                })
                .collect::<PyResult<_>>()?
        }
    };
    let poses = float_array(F, "poses", poses)?;
    let key_frames = float_array(F, "key_frames", key_frames)?;
    let frames = float_array(F, "frames", frames)?;
    let previous = args::optional_float_array(F, "previous", previous)?;
    let log_scales = args::optional_float_array(F, "log_scales", log_scales)?;
    let (k, t) = (key_frames.len(), frames.len());
    let out_width = 3 + out_rotation + 3 + if played { 3 + width } else { 0 };
    check_budget(
        F,
        poses.copy()
            + key_frames.copy()
            + frames.copy()
            + copy_of(previous.as_ref())
            + copy_of(log_scales.as_ref())
            + Footprint::of::<Pose>(k).and::<DVec3>(k)
            + Footprint::of::<f64>(t.saturating_mul(2 * out_width)),
        "the sampled owners",
        HINT,
    )?;
    let (poses, key_frames, frames) = (poses.read()?, key_frames.read()?, frames.read()?);
    let previous = previous.as_ref().map(|p| p.read()).transpose()?;
    let log_scales = log_scales.as_ref().map(|p| p.read()).transpose()?;
    let inner: Vec<Option<&Playback>> = playbacks
        .iter()
        .map(|p| p.as_ref().map(|p| &p.get().inner))
        .collect();
    let (pv, kv, fv) = (poses.as_array(), key_frames.as_array(), frames.as_array());
    let (prev, logs) = (
        previous.as_ref().map(|p| p.as_array()),
        log_scales.as_ref().map(|l| l.as_array()),
    );
    let spec = read_spec(scheme.0, levels, false, None, timing.0);
    let any_scaled = logs.is_some();
    let (locations, rotations, scales, rows_played, status) = py.detach(|| -> PyResult<_> {
        let keys = read_keys(F, &pv)?;
        let key_frames = read_vector(F, "key_frames", &kv)?;
        let frames = read_vector(F, "frames", &fv)?;
        let logs = logs
            .as_ref()
            .map(|l| read_vec3s(F, "log_scales", l))
            .transpose()?;
        let previous = match &prev {
            Some(p) if p.shape() != [owners, width] => {
                return Err(shape_err(
                    F,
                    "previous",
                    &format!("({owners}, {width})"),
                    p.shape(),
                ))
            }
            Some(p) => Some(p.iter().copied().collect::<Vec<f64>>()),
            None => None,
        };
        if keys.len() != key_frames.len() || logs.as_ref().is_some_and(|l| l.len() != keys.len()) {
            return Err(invalid(format!(
                "{F}: poses, key_frames and log_scales: one row per key"
            )));
        }
        let fill = |what: &'static str, got: usize, expected: usize| {
            if got == expected {
                Ok(())
            } else {
                Err(to_py_err(
                    F,
                    Error::LengthMismatch {
                        what,
                        expected,
                        got,
                    },
                ))
            }
        };
        // Each column's sum, `usize::MAX` when it overflows (it then matches no length):
        // every owner's rows then lie inside the arrays.
        let total = |column: usize| {
            counts
                .chunks(3)
                .try_fold(0usize, |sum, c| sum.checked_add(c[column]))
                .unwrap_or(usize::MAX)
        };
        fill("keys of counts", total(0), keys.len())?;
        fill("frames of counts", total(1), frames.len())?;
        fill("segments of counts", total(2), segments.len() / 4)?;
        let t = frames.len();
        let run = || -> Result<_, Error> {
            let mut locations = try_vec(t.saturating_mul(3), "locations")?;
            let mut rotations = try_vec(t.saturating_mul(out_rotation), "rotation channels")?;
            let mut scales = try_vec(
                if any_scaled { t.saturating_mul(3) } else { 0 },
                "log-scales",
            )?;
            let played_width = 3 + width;
            let mut rows_played = try_vec(
                if played {
                    t.saturating_mul(played_width)
                } else {
                    0
                },
                "played rows",
            )?;
            let mut status = try_vec(owners, "status")?;
            let all: Vec<Segment> = segments
                .chunks(4)
                .map(|s| Segment {
                    lo: s[0],
                    hi: s[1],
                    start: s[2],
                    end: s[3],
                })
                .collect();
            let (mut key, mut frame, mut seg) = (0usize, 0usize, 0usize);
            for (o, c) in counts.chunks(3).enumerate() {
                let (nk, nf, ns) = (c[0], c[1], c[2]);
                let optional = |v: f64| (!v.is_nan()).then_some(v);
                let previous = previous
                    .as_ref()
                    .map(|p| &p[o * width..(o + 1) * width])
                    .filter(|p| !p.iter().any(|v| v.is_nan()));
                let owner = OwnerMotion {
                    keys: &keys[key..key + nk],
                    key_frames: &key_frames[key..key + nk],
                    log_scales: logs
                        .as_ref()
                        .filter(|_| scaled[o])
                        .map(|l| &l[key..key + nk]),
                    frames: &frames[frame..frame + nf],
                    segments: &all[seg..seg + ns],
                    spec: polyscrew::MotionSpec {
                        closed: closed[o],
                        period: optional(periods[o]),
                        ..spec
                    },
                    size: optional(sizes[o]),
                    playback: inner[o],
                    previous,
                    played,
                };
                let sampled = if as_poses {
                    sample_owner_poses(&owner).map(|s| {
                        let rows: Vec<f64> = s
                            .poses
                            .iter()
                            .flat_map(|p| p.to_rows().into_iter().flatten())
                            .collect();
                        let at: Vec<DVec3> = s.poses.iter().map(|p| p.translation).collect();
                        (at, rows, s.log_scales, s.played)
                    })
                } else {
                    sample_owner_channels(&owner, mode)
                        .map(|s| (s.locations, s.rotations, s.log_scales, s.played))
                };
                match sampled {
                    Ok(s) if s.3.as_ref().is_none_or(|p| p.len() == nf * played_width) => {
                        let (at, rotation, log_scales, rows_of) = s;
                        locations.extend(at.iter().flat_map(|v| v.to_array()));
                        rotations.extend_from_slice(&rotation);
                        if any_scaled {
                            match log_scales.is_empty() {
                                true => scales.extend(std::iter::repeat_n(0.0, nf * 3)),
                                false => {
                                    scales.extend(log_scales.iter().flat_map(|v| v.to_array()))
                                }
                            }
                        }
                        if played {
                            match &rows_of {
                                Some(p) => rows_played.extend_from_slice(p),
                                None => rows_played
                                    .extend(std::iter::repeat_n(f64::NAN, nf * played_width)),
                            }
                        }
                        status.push(i64::from(rows_of.is_some()));
                    }
                    // refused (or a playback in another mode): zero rows, told by the status
                    _ => {
                        locations.extend(std::iter::repeat_n(0.0, nf * 3));
                        rotations.extend(std::iter::repeat_n(0.0, nf * out_rotation));
                        if any_scaled {
                            scales.extend(std::iter::repeat_n(0.0, nf * 3));
                        }
                        if played {
                            rows_played.extend(std::iter::repeat_n(f64::NAN, nf * played_width));
                        }
                        status.push(-1);
                    }
                }
                key += nk;
                frame += nf;
                seg += ns;
            }
            Ok((locations, rotations, scales, rows_played, status))
        };
        let (locations, rotations, scales, rows_played, status) =
            run().map_err(|e| to_py_err(F, e))?;
        let rotations = match as_poses {
            true => rows(rotations, 16)?
                .into_shape_with_order((t, 4, 4))
                .map_err(|e| invalid(format!("{F}: {e}")))?
                .into_dyn(),
            false => rows(rotations, width)?.into_dyn(),
        };
        Ok((
            rows(locations, 3)?,
            rotations,
            any_scaled.then(|| rows(scales, 3)).transpose()?,
            played.then(|| rows(rows_played, 3 + width)).transpose()?,
            Array1::from_vec(status),
        ))
    })?;
    Ok((
        locations.into_pyarray(py),
        rotations.into_pyarray(py),
        scales.map(|s| s.into_pyarray(py)),
        rows_played.map(|p| p.into_pyarray(py)),
        status.into_pyarray(py),
    ))
}

/// `played`, a bool.
fn played_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    args::bool_arg(SampleOwners::NAME, "played", obj)
}

/// `as_poses`, a bool.
fn as_poses_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    args::bool_arg(SampleOwners::NAME, "as_poses", obj)
}

/// Registers `sample_owners`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sample_owners, m)?)?;
    Ok(())
}
