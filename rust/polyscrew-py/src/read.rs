//! Binding of many owners' keys read in one call (`polyscrew::intent::read_owners`): the
//! owners' curves packed together, their options per owner, the results concatenated.
//! Conversion only.

use numpy::ndarray::{Array1, Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;
use pyo3::types::PyList;

use polyscrew::intent::{read_owners as core_read_owners, Channel, OwnerKeys, OwnerRead, Turns};
use polyscrew::memory::Footprint;
use polyscrew::RotationMode;

use crate::args::{self, float_array, int_array, Function, Most, Named, ReadOwners};
use crate::errors::{check_budget, invalid, shape_err, to_py_err};
use crate::fcurve::CurveInput;
use crate::intent::PyPlayback;

/// How to ask for less memory.
const HINT: &str = "read fewer owners in one call";

/// Numbers per owner in `unkeyed`: location, rotation (padded to 4), scale.
const ROW: usize = 10;

/// What `read_owners` returns.
type Out<'py> = (
    Bound<'py, PyList>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<i64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray3<f64>>,
    (
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<bool>>,
        Bound<'py, PyArray1<f64>>,
        Bound<'py, PyArray1<i64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
    ),
    Bound<'py, PyArray1<i64>>,
);

/// `owners` names of an enumeration, `None` entries allowed.
fn names<T: Named>(
    what: &'static str,
    obj: &Bound<'_, PyAny>,
    owners: usize,
) -> PyResult<Vec<Option<T>>> {
    const F: &str = ReadOwners::NAME;
    let expected = "a sequence of names, one per owner";
    let items = args::sequence(F, what, obj, Most::Exactly(owners), expected)?;
    if items.len() != owners {
        return Err(shape_err(F, what, &format!("({owners},)"), &[items.len()]));
    }
    items
        .iter()
        .map(|item| {
            if item.is_none() {
                return Ok(None);
            }
            let name: String = item.extract().map_err(|_| {
                crate::errors::wrong_type(format!("{F}: {what}: expected {expected}"))
            })?;
            T::from_name(&name).map(Some).map_err(|e| to_py_err(F, e))
        })
        .collect()
}

/// read_owners(
///     curves: ArrayLike,
///     channels: Sequence[tuple[str, int]],
///     unkeyed: ArrayLike,
///     modes: Sequence[RotationModeName],
///     *,
///     located: ArrayLike | None = None,
///     key_values: ArrayLike | None = None,
///     turns: Sequence[Literal["AUTO", "BLENDER", "SHORTEST"] | None] | None = None,
///     offsets: ArrayLike,
///     co: ArrayLike,
///     handle_left: ArrayLike,
///     handle_right: ArrayLike,
///     interpolation: ArrayLike,
///     easing: ArrayLike,
///     extrapolation: ExtrapolationName | Sequence[ExtrapolationName] | None = None,
///     back: ArrayLike | None = None,
///     amplitude: ArrayLike | None = None,
///     period: ArrayLike | None = None,
///     cycles: Sequence[Mapping[str, Any] | None] | None = None,
/// ) -> tuple[list[Playback | None], FloatArray, IntArray, FloatArray, FloatArray, FloatArray, FloatArray, tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_], FloatArray, npt.NDArray[np.bool_], FloatArray, IntArray, FloatArray, FloatArray, FloatArray], IntArray]
///
/// Many owners' keys read in one call: for each owner, exactly what ``Playback``, then
/// ``Playback.channels`` at its key frames, ``rotation_matrices``, ``analyse_turns`` and
/// ``Playback.channels`` at the frames it inserts give, one after the other.
///
/// The curves of every owner are packed together as ``evaluate_fcurves`` takes them (the
/// same keyword arguments), curve ``c`` driving ``channels[c]``; owner ``o`` plays curves
/// ``curves[o, 0]`` to ``curves[o, 0] + curves[o, 1]`` (``curves`` (O, 2); owners may share
/// curves), in rotation mode ``modes[o]``, with its own values ``unkeyed[o]`` (O, 10):
/// location, rotation (3 Euler angles and one number unused, or 4) and scale. Per owner,
/// optional: ``located`` (default 1: a bone connected to its parent has 0), ``key_values``
/// (1: when every curve is keyed on every key frame, its key values are the channels there,
/// not played), ``turns`` (None: not analysed).
///
/// Returns ``(playbacks, frames, counts, location, rotation, scale, poses, spans,
/// status)``: per owner its ``Playback`` (None when refused); its key frames (the union of
/// its curves' key frames, a frame within ``KEY_FRAME_TOLERANCE`` of the one before dropped)
/// concatenated (F,) with ``counts`` (O,) of them each; the channels there, location (F, 3),
/// rotation (F, 4: NaN in the last column for a 3-wide mode) and scale (F, 3); the rigid key
/// poses (F, 4, 4); ``spans``, ``analyse_turns``' held, pops, turn and flips of the analysed
/// owners' spans one after the other (K - 1 each), its inserted frames concatenated, how
/// many of those each owner has (O,), and the channels at them (location (M, 3), rotation
/// (M, 4) padded as above, scale (M, 3)); and a status per owner (int64): 1 read and
/// analysed, 0 read, -1 refused (nothing of it in the arrays: read it alone to learn why:
/// bad curves, fewer than two key frames, a key row not finite, a keyed scale not positive,
/// what ``analyse_turns`` refuses). GIL released. Raises ValueError for arrays that do not
/// fit together.
#[pyfunction]
#[pyo3(signature = (curves, channels, unkeyed, modes, *, located=None, key_values=None, turns=None, offsets, co, handle_left, handle_right, interpolation, easing, extrapolation=None, back=None, amplitude=None, period=None, cycles=None))]
#[allow(clippy::too_many_arguments)]
fn read_owners<'py>(
    py: Python<'py>,
    curves: &Bound<'py, PyAny>,
    channels: &Bound<'py, PyAny>,
    unkeyed: &Bound<'py, PyAny>,
    modes: &Bound<'py, PyAny>,
    located: Option<&Bound<'py, PyAny>>,
    key_values: Option<&Bound<'py, PyAny>>,
    turns: Option<&Bound<'py, PyAny>>,
    offsets: &Bound<'py, PyAny>,
    co: &Bound<'py, PyAny>,
    handle_left: &Bound<'py, PyAny>,
    handle_right: &Bound<'py, PyAny>,
    interpolation: &Bound<'py, PyAny>,
    easing: &Bound<'py, PyAny>,
    extrapolation: Option<&Bound<'py, PyAny>>,
    back: Option<&Bound<'py, PyAny>>,
    amplitude: Option<&Bound<'py, PyAny>>,
    period: Option<&Bound<'py, PyAny>>,
    cycles: Option<&Bound<'py, PyAny>>,
) -> PyResult<Out<'py>> {
    const F: &str = ReadOwners::NAME;
    let ranges = int_array(F, "curves", curves)?;
    if ranges.ndim() != 2 || ranges.shape()[1] != 2 {
        return Err(shape_err(F, "curves", "(O, 2)", ranges.shape()));
    }
    let owners = ranges.shape()[0];
    let ranges: Vec<(usize, usize)> = {
        let array = ranges.read()?;
        let view = array.as_array();
        let mut out = Vec::with_capacity(owners);
        for o in 0..owners {
            let at = |j: usize| {
                let v = view[[o, j]];
                usize::try_from(v)
                    .map_err(|_| invalid(format!("{F}: curves[{o}]: {v} is negative")))
            };
            out.push((at(0)?, at(1)?));
        }
        out
    };
    let modes: Vec<RotationMode> = names::<RotationMode>("modes", modes, owners)?
        .into_iter()
        .enumerate()
        .map(|(o, m)| m.ok_or_else(|| invalid(format!("{F}: modes[{o}]: expected a name"))))
        .collect::<PyResult<_>>()?;
    let turns: Vec<Option<Turns>> = match turns.filter(|t| !t.is_none()) {
        Some(t) => names::<Turns>("turns", t, owners)?,
        None => vec![None; owners],
    };
    let located = args::per_owner_flags(F, "located", located, owners, true)?;
    let key_values = args::per_owner_flags(F, "key_values", key_values, owners, false)?;
    let expected = "a sequence of (property, index) pairs";
    let pairs: Vec<(String, i64)> =
        args::sequence(F, "channels", channels, Most::AtMost(usize::MAX), expected)?
            .iter()
            .map(|item| {
                item.extract::<(String, i64)>().map_err(|_| {
                    crate::errors::wrong_type(format!("{F}: channels: expected {expected}"))
                })
            })
            .collect::<PyResult<_>>()?;
    let unkeyed = float_array(F, "unkeyed", unkeyed)?;
    if unkeyed.shape() != [owners, ROW] {
        return Err(shape_err(
            F,
            "unkeyed",
            &format!("({owners}, {ROW})"),
            unkeyed.shape(),
        ));
    }
    let input = CurveInput::read(
        F,
        0,
        unkeyed.copy() + Footprint::of::<f64>(owners.saturating_mul(ROW)),
        offsets,
        co,
        handle_left,
        handle_right,
        interpolation,
        easing,
        extrapolation,
        back,
        amplitude,
        period,
        cycles,
    )?;
    let unkeyed = unkeyed.read()?;
    let (unkeyed, views) = (unkeyed.as_array(), input.views());
    let (reads, status) = py.detach(|| -> PyResult<_> {
        let args = views.to_args()?;
        let packed = args.packed();
        if pairs.len() != packed.len() {
            return Err(shape_err(
                F,
                "channels",
                &format!("({},)", packed.len()),
                &[pairs.len()],
            ));
        }
        // the keys every owner plays (a curve shared by owners counted for each): its
        // playback's copy of them, and per key a row, a pose and the outputs
        let keys = ranges.iter().try_fold(0usize, |sum, &(start, count)| {
            let end = start.checked_add(count).filter(|&e| e <= packed.len())?;
            let span = packed.offsets[end].checked_sub(packed.offsets[start])?;
            sum.checked_add(usize::try_from(span).ok()?)
        });
        let Some(keys) = keys else {
            return Err(invalid(format!(
                "{F}: curves: a range outside the {} curves",
                packed.len()
            )));
        };
        check_budget(
            F,
            Footprint::of::<f64>(keys.saturating_mul(12 + 2 * (ROW + 16))),
            "the owners' keys",
            HINT,
        )?;
        // per owner its channels and static row, or why they are refused
        let mut statics = Vec::with_capacity(owners);
        let mut parsed = Vec::with_capacity(owners);
        for (o, &(start, count)) in ranges.iter().enumerate() {
            let mode = modes[o];
            let w = mode.width();
            let row = |j: usize| unkeyed[[o, j]];
            let mut s: Vec<f64> = (0..3 + w).map(row).collect();
            s.extend((7..ROW).map(row));
            statics.push(s);
            parsed.push(
                pairs[start..start + count]
                    .iter()
                    .map(|(p, i)| {
                        let i = usize::try_from(*i).map_err(|_| polyscrew::Error::Index {
                            what: "channels",
                            item: "index",
                            at: None,
                            index: *i,
                            len: 0,
                        })?;
                        Channel::from_property(p, i, mode)
                    })
                    .collect::<Result<Vec<Channel>, _>>(),
            );
        }
        let empty: Vec<Channel> = Vec::new();
        let asked: Vec<OwnerKeys<'_>> = (0..owners)
            .map(|o| OwnerKeys {
                curves: ranges[o].0..ranges[o].0 + ranges[o].1,
                channels: parsed[o].as_ref().unwrap_or(&empty),
                statics: &statics[o],
                mode: modes[o],
                located: located[o],
                key_values: key_values[o],
                turns: turns[o],
            })
            .collect();
        let reads = core_read_owners(&packed, &asked).map_err(|e| to_py_err(F, e))?;
        let mut status = Vec::with_capacity(owners);
        let reads: Vec<Option<OwnerRead>> = reads
            .into_iter()
            .zip(&parsed)
            .map(|(read, channels)| match (read, channels) {
                (Ok(read), Ok(_)) => {
                    status.push(i64::from(read.spans.is_some()));
                    Some(read)
                }
                _ => {
                    status.push(-1);
                    None
                }
            })
            .collect();
        Ok((reads, status))
    })?;
    let (arrays, spans) = py.detach(|| concatenated(&reads, &modes));
    let playbacks = PyList::empty(py);
    for read in reads {
        match read {
            Some(read) => playbacks.append(Py::new(
                py,
                PyPlayback {
                    inner: read.playback,
                },
            )?)?,
            None => playbacks.append(py.None())?,
        }
    }
    let (frames, counts, location, rotation, scale, poses) = arrays;
    let (held, pops, turn, flips, inserted, inserted_counts, played) = spans;
    let (inserted_location, inserted_rotation, inserted_scale) = played;
    Ok((
        playbacks,
        frames.into_pyarray(py),
        counts.into_pyarray(py),
        location.into_pyarray(py),
        rotation.into_pyarray(py),
        scale.into_pyarray(py),
        poses.into_pyarray(py),
        (
            held.into_pyarray(py),
            pops.into_pyarray(py),
            turn.into_pyarray(py),
            flips.into_pyarray(py),
            inserted.into_pyarray(py),
            inserted_counts.into_pyarray(py),
            inserted_location.into_pyarray(py),
            inserted_rotation.into_pyarray(py),
            inserted_scale.into_pyarray(py),
        ),
        Array1::from_vec(status).into_pyarray(py),
    ))
}

/// Frames, counts, location, rotation, scale, poses.
type Arrays = (
    Array1<f64>,
    Array1<i64>,
    Array2<f64>,
    Array2<f64>,
    Array2<f64>,
    Array3<f64>,
);
/// Held, pops, turn, flips, inserted, inserted counts, and the inserted frames' location,
/// rotation and scale.
type SpanArrays = (
    Array1<bool>,
    Array1<bool>,
    Array1<f64>,
    Array1<bool>,
    Array1<f64>,
    Array1<i64>,
    (Array2<f64>, Array2<f64>, Array2<f64>),
);

/// Channel rows of `mode` (`6 + width` each) split into location, rotation (padded to 4
/// with NaN) and scale, appended to `out`.
fn split_rows(rows: &[f64], mode: RotationMode, out: &mut [Vec<f64>; 3]) {
    let w = mode.width();
    for row in rows.chunks_exact(6 + w) {
        out[0].extend_from_slice(&row[..3]);
        out[1].extend_from_slice(&row[3..3 + w]);
        out[1].extend(std::iter::repeat_n(f64::NAN, 4 - w));
        out[2].extend_from_slice(&row[3 + w..]);
    }
}

/// The owners' reads concatenated (refused owners: nothing).
fn concatenated(reads: &[Option<OwnerRead>], modes: &[RotationMode]) -> (Arrays, SpanArrays) {
    let (mut frames, mut counts) = (Vec::new(), Vec::with_capacity(reads.len()));
    let mut keyed: [Vec<f64>; 3] = Default::default();
    let mut played: [Vec<f64>; 3] = Default::default();
    let mut poses = Vec::new();
    let (mut held, mut pops, mut turn, mut flips, mut inserted) =
        (Vec::new(), Vec::new(), Vec::new(), Vec::new(), Vec::new());
    let mut inserted_counts = Vec::with_capacity(reads.len());
    for (read, &mode) in reads.iter().zip(modes) {
        let Some(read) = read else {
            counts.push(0);
            inserted_counts.push(0);
            continue;
        };
        frames.extend_from_slice(&read.frames);
        counts.push(read.frames.len() as i64);
        split_rows(&read.rows, mode, &mut keyed);
        poses.extend(read.poses.iter().flatten());
        match &read.spans {
            Some(s) => {
                held.extend_from_slice(&s.held);
                pops.extend_from_slice(&s.pops);
                turn.extend_from_slice(&s.turn);
                flips.extend_from_slice(&s.flips);
                inserted.extend_from_slice(&s.inserted);
                inserted_counts.push(s.inserted.len() as i64);
                split_rows(&read.inserted_rows, mode, &mut played);
            }
            None => inserted_counts.push(0),
        }
    }
    let (f, m) = (frames.len(), inserted.len());
    let rows = |v: Vec<f64>, n: usize, w: usize| {
        Array2::from_shape_vec((n, w), v).expect("a row per frame")
    };
    let [location, rotation, scale] = keyed;
    let [at_location, at_rotation, at_scale] = played;
    (
        (
            Array1::from_vec(frames),
            Array1::from_vec(counts),
            rows(location, f, 3),
            rows(rotation, f, 4),
            rows(scale, f, 3),
            Array3::from_shape_vec((f, 4, 4), poses).expect("a pose per key frame"),
        ),
        (
            Array1::from_vec(held),
            Array1::from_vec(pops),
            Array1::from_vec(turn),
            Array1::from_vec(flips),
            Array1::from_vec(inserted),
            Array1::from_vec(inserted_counts),
            (
                rows(at_location, m, 3),
                rows(at_rotation, m, 4),
                rows(at_scale, m, 3),
            ),
        ),
    )
}

/// Registers `read_owners` and `KEY_FRAME_TOLERANCE`.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(read_owners, m)?)?;
    // stub:
    // stub: KEY_FRAME_TOLERANCE: float
    // stub: """Two key frames of an owner closer than this (frames) are one (``read_owners``; 1e-4)."""
    m.add(
        "KEY_FRAME_TOLERANCE",
        polyscrew::intent::KEY_FRAME_TOLERANCE,
    )?;
    Ok(())
}
