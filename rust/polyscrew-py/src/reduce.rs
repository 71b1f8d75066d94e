//! `reduce_keys`: the binding of `polyscrew::reduce_keys` (key reduction). Conversion only:
//! read the arguments -> check the memory budget -> release the GIL -> call the core -> map
//! the error -> wrap the curves as the packed arrays `evaluate_fcurves` takes.

use glam::DVec3;
use numpy::ndarray::{Array1, Array2, ArrayViewD};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList, PyString, PyTuple};

use polyscrew::memory::{try_vec, Footprint};
use polyscrew::reduce::{
    reduce_footprint, Between, HandleType, ReduceInput, ReduceOptions, Tolerance,
    MAX_REDUCE_FRAMES, MAX_REDUCE_POSES, REDUCE_HINT,
};
use polyscrew::{reduce_keys as core_reduce_keys, Pose, RotationMode};

use crate::args::{
    bool_array, float_array, float_scalar, int_in, int_list, sequence, Choice, Function, Most,
    ReduceKeys,
};
use crate::errors::{shape_err, to_py_err};

const F: &str = ReduceKeys::NAME;

/// Reads `(B, N, 4, 4)` poses (no GIL needed), errors naming the owner and the frame.
fn read_poses(view: &ArrayViewD<'_, f64>, b: usize, n: usize) -> PyResult<Vec<Pose>> {
    let mut poses = try_vec(b * n, "input poses").map_err(|e| to_py_err(F, e))?;
    let mut it = view.iter();
    let mut m = [[0.0; 4]; 4];
    for g in 0..b * n {
        for row in m.iter_mut() {
            for v in row.iter_mut() {
                *v = *it.next().expect("16 values per pose");
            }
        }
        poses
            .push(Pose::from_rows(&m, g % n).map_err(|e| {
                crate::errors::invalid(format!("{F}: poses: owner {}: {e}", g / n))
            })?);
    }
    Ok(poses)
}

/// `modes`: one name for all owners or `B` of them.
fn read_modes(obj: &Bound<'_, PyAny>, b: usize) -> PyResult<Vec<RotationMode>> {
    let parse = |o: Option<usize>, s: &str| {
        RotationMode::from_name(s).map_err(|e| {
            let at = o.map_or_else(String::new, |o| format!("owner {o}: "));
            crate::errors::invalid(format!("{F}: modes: {at}{e}"))
        })
    };
    if let Ok(s) = obj.cast::<PyString>() {
        let mode = parse(None, s.to_str()?)?;
        return Ok(vec![mode; b]);
    }
    let items = sequence(
        F,
        "modes",
        obj,
        Most::Exactly(b),
        "a mode name or a sequence of them",
    )?;
    if items.len() != b {
        return Err(crate::errors::invalid(format!(
            "{F}: modes: expected one name or {b} of them, got {}",
            items.len()
        )));
    }
    items
        .iter()
        .enumerate()
        .map(|(o, item)| {
            let s = crate::args::str_arg(F, "modes", item)?;
            parse(Some(o), s)
        })
        .collect()
}

/// `radius`: one float for all owners or `(B,)`.
fn read_radius(obj: &Bound<'_, PyAny>, b: usize) -> PyResult<Vec<f64>> {
    if let Ok(r) = float_scalar(F, "radius", obj) {
        return Ok(vec![r; b]);
    }
    let array = float_array(F, "radius", obj)?.read()?;
    let view = array.as_array();
    match view.shape() {
        [] => Ok(vec![view.iter().copied().next().unwrap_or(f64::NAN); b]),
        [m] if *m == b => Ok(view.iter().copied().collect()),
        s => Err(shape_err(F, "radius", &format!("a float or ({b},)"), s)),
    }
}

/// A boolean mask of shape `shape`, or a `TypeError`/`ValueError` naming it.
fn read_mask(
    obj: Option<&Bound<'_, PyAny>>,
    what: &str,
    shape: &[usize],
) -> PyResult<Option<Vec<bool>>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let expected = format!("{shape:?}").replace('[', "(").replace(']', ")");
    let Some((got, mask)) = bool_array(F, what, obj, Most::Exactly(shape[0]))? else {
        return Err(crate::errors::wrong_type(format!(
            "{F}: {what}: expected a boolean array of shape {expected}"
        )));
    };
    if got != shape {
        return Err(shape_err(F, what, &expected, &got));
    }
    Ok(Some(mask))
}

/// A float array of shape `shape`, or `None`.
fn read_floats(
    obj: Option<&Bound<'_, PyAny>>,
    what: &'static str,
    shape: &[usize],
) -> PyResult<Option<Vec<f64>>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(None);
    };
    let array = float_array(F, what, obj)?.read()?;
    let view = array.as_array();
    if view.shape() != shape {
        let expected = format!("{shape:?}").replace('[', "(").replace(']', ")");
        return Err(shape_err(F, what, &expected, view.shape()));
    }
    let mut out = try_vec(view.len(), "input values").map_err(|e| to_py_err(F, e))?;
    out.extend(view.iter().copied());
    Ok(Some(out))
}

// stub:
// stub: HandleTypeName = Literal["FREE", "ALIGNED", "VECTOR", "AUTO", "AUTO_CLAMPED"]
/// reduce_keys(
///     poses: ArrayLike,
///     frames: ArrayLike,
///     modes: RotationModeName | Sequence[RotationModeName],
///     radius: float | ArrayLike,
///     distance: float,
///     angle: float,
///     *,
///     scales: ArrayLike | None = None,
///     channels: ArrayLike | None = None,
///     parents: ArrayLike | None = None,
///     offsets: ArrayLike | None = None,
///     constant: ArrayLike | None = None,
///     cyclic: bool = False,
///     per_channel: bool = False,
///     start: ArrayLike | None = None,
///     threads: int = 0,
///     between: Literal["screw", "cubic", "linear"] = "screw",
/// ) -> dict[str, Any]
///
/// The fewest Bezier keys whose playback by Blender stays within a world-space tolerance
/// of B owners' dense rigid motions.
///
/// ``poses`` (B, N, 4, 4): each owner's rigid pose at each of the N >= 2 ``frames`` (strictly
/// increasing, shared, subframes allowed), in the space its channels key (an object's parent
/// space, a bone's ``matrix_basis``), scale separated. ``modes``: one Blender rotation mode
/// for all owners or B of them ("QUATERNION", "AXIS_ANGLE", "XYZ", "XZY", "YXZ", "YZX",
/// "ZXY", "ZYX"). ``radius``: float or (B,), the body's radius (>= 0). ``distance`` (> 0):
/// no point of the body within ``radius`` of its origin moves further than this from the
/// dense motion; ``angle`` (> 0, radians): no rotation differs more. The measure of a played
/// pose against the dense one is ``|dt| + 2 radius sin(theta / 2)`` (+ ``radius |ds|`` with
/// scale) and ``theta``.
///
/// The dense motion is the poses at ``frames`` and the screw between two consecutive ones
/// (across a ``constant`` span: the first pose until the next frame). The tolerance is
/// checked at every frame and 3 subframes between two (1/4, 1/2, 3/4) through Blender's own
/// F-curve evaluation of the float32 keys (``evaluate_fcurves``, bit-identical), quaternions
/// normalised as Blender plays them.
///
/// - ``scales``: None, or (B, N, 3) positive scales to reduce too (linear between frames).
/// - ``channels``: None (location and rotation, and scale when ``scales`` is given) or (B, 3)
///   bool: which of location / rotation / scale each owner keys; unkeyed groups get no
///   curves and count as exact.
/// - ``parents``: None, or (B,) int: each owner's parent's batch index (-1: none). The
///   tolerance then holds in world space, ``world_i = world_parent @ offsets[i] @ poses[i]``
///   (roots: ``offsets[i] @ poses[i]``): parents are reduced first and each child keys
///   ``(world_parent_reduced @ offset)^-1 @ world_child_dense``, compensating its parents'
///   errors. Scale is not propagated to children.
/// - ``offsets``: None (identity) or (B, 4, 4) rigid constant offsets.
/// - ``constant``: None, or (B, N-1) bool: span i -> i+1 is a step or hold (CONSTANT in the
///   source); it stays a CONSTANT key, its end keyed.
/// - ``cyclic``: the frames are one period of a cycle (first pose == last pose): the first
///   and last keys sit at the first and last frame, with equal values on every channel that
///   returns to its first value (a cycle that turns a whole turn keeps its offset).
/// - ``per_channel``: each channel gets its own key frames (each reduced within a share of
///   the tolerance, halved until the whole holds); default: an owner's channels share them.
/// - ``start``: None or (B, 4): each owner's channel values at the first frame as the source
///   had them (Euler: the first 3; axis-angle: angle, axis; quaternion: w, x, y, z for its
///   sign); the first key takes the equivalent values nearest to them (a spin from 360 to 720
///   degrees stays there). None: those nearest zero.
/// - ``threads``: owners of one depth of the hierarchy spread over this many threads (0: all).
/// - ``between``: the dense motion at the subframes. "screw" (default): the screw between
///   two frames, what a source keyed on every frame with LINEAR keys plays (to first order).
///   "cubic": the cubic through the two poses each side (fewer at the clip's ends and
///   around CONSTANT spans) by Aitken-Neville's scheme with screws for straight lines,
///   what a source keyed on every frame with Bezier keys plays (smooth: an ``nla.bake``, an
///   imported capture); a smooth reduction can follow it much more closely than the
///   screw's corners at every frame, so it needs fewer keys at tight tolerances. Both
///   reproduce screw motions exactly and are coordinate-free. "linear": the owner's channels
///   interpolated linearly between two frames, exactly what a source keyed on every frame
///   with LINEAR keys plays (a Smooth Motion bake); not coordinate-free (Euler channels are
///   not).
///
/// Keys sit on the dense values (first and last frame always keyed); rotation channels are
/// unwrapped along the dense samples (quaternion signs continuous, Euler triples compatible,
/// axis-angle unwrapped), so spins keep turning and no key wraps. Each span between keys is
/// a Bezier with its handles at 1/3 and 2/3 of the span in time (a cubic in time), the two
/// inner handle values fitted by least squares; handles are FREE (C0 at keys: editing a
/// key keeps its neighbours' segments as they are). Where even a one-frame span cannot meet
/// the tolerance, keys go at the subframes. Where float32 storage alone cannot (a tolerance
/// below float32's resolution at the motion's scale), the errors reported say so.
///
/// Returns a dict of the curves packed as ``evaluate_fcurves`` takes them, so
/// ``evaluate_fcurves(times, offsets=r["offsets"], co=r["co"], handle_left=r["handle_left"],
/// handle_right=r["handle_right"], interpolation=r["interpolation"], easing=r["easing"])``
/// plays them: ``"owner"`` (C,) int64, ``"path"`` list of C str ("location",
/// "rotation_quaternion", "rotation_euler", "rotation_axis_angle", "scale"), ``"index"``
/// (C,) int64, ``"offsets"`` (C+1,) int64, ``"co"``, ``"handle_left"``, ``"handle_right"``
/// (K, 2) float64 (frame, value), ``"interpolation"``, ``"easing"``, ``"handle_type"`` (K,)
/// int64 codes into ``INTERPOLATIONS``, ``EASINGS``, ``HANDLE_TYPES`` (BEZIER or CONSTANT,
/// AUTO, FREE); ``"keys"`` (B,) int64 distinct key frames per owner; ``"distance_error"``,
/// ``"angle_error"`` (B,) float64, the largest errors measured at the checked samples
/// (world space with ``parents``).
///
/// The GIL is released. Raises ValueError / TypeError naming ``reduce_keys``, the argument
/// and the owner: wrong shapes, non-rigid or non-finite poses or offsets, frames not finite
/// and strictly increasing, fewer than 2 frames, tolerances not positive and finite, unknown
/// modes, negative radii, non-positive scales, scale keyed without ``scales``, parents out
/// of range or forming a cycle, more than 1,000,000 frames or 20,000,000 poses, more memory
/// than the budget (checked before anything is copied).
#[pyfunction]
#[pyo3(signature = (poses, frames, modes, radius, distance, angle, *, scales=None, channels=None, parents=None, offsets=None, constant=None, cyclic=None, per_channel=None, start=None, threads=None, between=None))]
#[pyo3(
    text_signature = "(poses, frames, modes, radius, distance, angle, *, scales=None, channels=None, parents=None, offsets=None, constant=None, cyclic=False, per_channel=False, start=None, threads=0, between=\"screw\")"
)]
#[allow(clippy::too_many_arguments)]
fn reduce_keys<'py>(
    py: Python<'py>,
    poses: &Bound<'py, PyAny>,
    frames: &Bound<'py, PyAny>,
    modes: &Bound<'py, PyAny>,
    radius: &Bound<'py, PyAny>,
    distance: &Bound<'py, PyAny>,
    angle: &Bound<'py, PyAny>,
    scales: Option<&Bound<'py, PyAny>>,
    channels: Option<&Bound<'py, PyAny>>,
    parents: Option<&Bound<'py, PyAny>>,
    offsets: Option<&Bound<'py, PyAny>>,
    constant: Option<&Bound<'py, PyAny>>,
    cyclic: Option<&Bound<'py, PyAny>>,
    per_channel: Option<&Bound<'py, PyAny>>,
    start: Option<&Bound<'py, PyAny>>,
    threads: Option<&Bound<'py, PyAny>>,
    between: Option<Choice<ReduceKeys, Between>>,
) -> PyResult<Bound<'py, PyDict>> {
    let between = between.map_or(Between::Screw, |b| b.0);
    let flag = |what: &str, o: Option<&Bound<'py, PyAny>>| match o {
        Some(o) if !o.is_none() => o
            .extract::<bool>()
            .map_err(|_| crate::errors::wrong_type(format!("{F}: {what}: expected a bool"))),
        _ => Ok(false),
    };
    let cyclic = flag("cyclic", cyclic)?;
    let per_channel = flag("per_channel", per_channel)?;
    let threads = match threads {
        Some(t) if !t.is_none() => int_in(F, "threads", t, 0, 1024)? as usize,
        _ => 0,
    };
    let distance = float_scalar(F, "distance", distance)?;
    let angle = float_scalar(F, "angle", angle)?;
    let poses = float_array(F, "poses", poses)?;
    let frames = float_array(F, "frames", frames)?;
    let (b, n) = match poses.shape() {
        [b, n, 4, 4] => (*b, *n),
        s => return Err(shape_err(F, "poses", "(B, N, 4, 4)", s)),
    };
    if frames.shape() != [n] {
        return Err(shape_err(
            F,
            "frames",
            &format!("({n},) (N of poses)"),
            frames.shape(),
        ));
    }
    if n > MAX_REDUCE_FRAMES || b.saturating_mul(n) > MAX_REDUCE_POSES {
        return Err(crate::errors::invalid(format!(
            "{F}: poses: {b} owners x {n} frames exceed the limits ({MAX_REDUCE_FRAMES} frames per owner, {MAX_REDUCE_POSES} poses in all)"
        )));
    }
    let with_parents = parents.is_some_and(|p| !p.is_none());
    // Before anything input-sized is copied: the copies of the input, the core's peak and
    // the output arrays (every channel keyed at every frame at most).
    let keys_bound = b.saturating_mul(n).saturating_mul(10);
    crate::errors::check_budget(
        F,
        poses.copy()
            + frames.copy()
            + Footprint::of::<Pose>(b.saturating_mul(n).saturating_mul(2))
                .and::<f64>(b.saturating_mul(n).saturating_mul(3))
            + reduce_footprint(b, n, threads, with_parents)
            + Footprint::of::<f64>(keys_bound.saturating_mul(6))
            + Footprint::of::<i64>(keys_bound.saturating_mul(3)),
        "the key reduction",
        REDUCE_HINT,
    )?;
    let modes = read_modes(modes, b)?;
    let radius = read_radius(radius, b)?;
    let scales = read_floats(scales, "scales", &[b, n, 3])?;
    let channels = read_mask(channels, "channels", &[b, 3])?;
    let constant = read_mask(constant, "constant", &[b, n.saturating_sub(1)])?;
    let start = read_floats(start, "start", &[b, 4])?;
    let parents = match parents.filter(|p| !p.is_none()) {
        None => None,
        Some(p) => {
            let list = int_list(F, "parents", p, Most::Exactly(b))?;
            if list.len() != b {
                return Err(shape_err(F, "parents", &format!("({b},)"), &[list.len()]));
            }
            let mut out = Vec::with_capacity(b);
            for (o, q) in list.iter().enumerate() {
                out.push(match *q {
                    -1 => None,
                    q if q >= 0 => Some(q as usize),
                    q => {
                        return Err(crate::errors::invalid(format!(
                            "{F}: parents: owner {o}: {q} is neither -1 nor an owner index"
                        )))
                    }
                });
            }
            Some(out)
        }
    };
    let offsets = match offsets.filter(|o| !o.is_none()) {
        None => None,
        Some(o) => {
            let array = float_array(F, "offsets", o)?.read()?;
            let view = array.as_array();
            if view.shape() != [b, 4, 4] {
                return Err(shape_err(
                    F,
                    "offsets",
                    &format!("({b}, 4, 4)"),
                    view.shape(),
                ));
            }
            let mut out = Vec::with_capacity(b);
            let mut it = view.iter();
            for o in 0..b {
                let mut m = [[0.0; 4]; 4];
                for row in m.iter_mut() {
                    for v in row.iter_mut() {
                        *v = *it.next().expect("16 values per offset");
                    }
                }
                out.push(Pose::from_rows(&m, o).map_err(|e| {
                    crate::errors::invalid(format!("{F}: offsets: owner {o}: {e}"))
                })?);
            }
            Some(out)
        }
    };
    let (poses, frames) = (poses.read()?, frames.read()?);
    let (pv, fv) = (poses.as_array(), frames.as_array());
    let reduced = py.detach(|| -> PyResult<polyscrew::Reduced> {
        let poses = read_poses(&pv, b, n)?;
        let frames: Vec<f64> = fv.iter().copied().collect();
        let scales: Option<Vec<DVec3>> = scales
            .as_ref()
            .map(|s| s.chunks_exact(3).map(DVec3::from_slice).collect());
        let channels: Option<Vec<[bool; 3]>> = channels
            .as_ref()
            .map(|c| c.chunks_exact(3).map(|r| [r[0], r[1], r[2]]).collect());
        let start: Option<Vec<[f64; 4]>> = start.as_ref().map(|s| {
            s.chunks_exact(4)
                .map(|r| [r[0], r[1], r[2], r[3]])
                .collect()
        });
        let input = ReduceInput {
            poses: &poses,
            frames: &frames,
            modes: &modes,
            radius: &radius,
            scales: scales.as_deref(),
            channels: channels.as_deref(),
            parents: parents.as_deref(),
            offsets: offsets.as_deref(),
            constant: constant.as_deref(),
            start: start.as_deref(),
        };
        let options = ReduceOptions {
            tolerance: Tolerance { distance, angle },
            cyclic,
            per_channel,
            threads,
            between,
        };
        core_reduce_keys(&input, &options).map_err(|e| to_py_err(F, e))
    })?;
    wrap(py, &reduced, &modes)
}

/// The result as a dict of packed arrays (the layout of `evaluate_fcurves`).
fn wrap<'py>(
    py: Python<'py>,
    r: &polyscrew::Reduced,
    modes: &[RotationMode],
) -> PyResult<Bound<'py, PyDict>> {
    let c = r.curves.len();
    let k: usize = r.curves.iter().map(|c| c.keys.len()).sum();
    let err = |e| to_py_err(F, e);
    let mut owner = try_vec(c, "curve owners").map_err(err)?;
    let mut index = try_vec(c, "curve indices").map_err(err)?;
    let mut offsets = try_vec(c + 1, "curve offsets").map_err(err)?;
    let mut co = try_vec(2 * k, "keys").map_err(err)?;
    let mut hl = try_vec(2 * k, "keys").map_err(err)?;
    let mut hr = try_vec(2 * k, "keys").map_err(err)?;
    let mut interpolation = try_vec(k, "keys").map_err(err)?;
    let mut handle_type = try_vec(k, "keys").map_err(err)?;
    let mut paths = Vec::with_capacity(c);
    offsets.push(0i64);
    for curve in &r.curves {
        owner.push(curve.owner as i64);
        index.push(curve.index as i64);
        paths.push(curve.group.path(modes[curve.owner]));
        for key in &curve.keys {
            co.extend(key.co);
            hl.extend(key.handle_left);
            hr.extend(key.handle_right);
            interpolation.push(key.interpolation as i64);
            handle_type.push(curve.handle_type.code());
        }
        offsets.push(offsets[offsets.len() - 1] + curve.keys.len() as i64);
    }
    let pairs = |v: Vec<f64>| Array2::from_shape_vec((k, 2), v).expect("2 values per key");
    let d = PyDict::new(py);
    d.set_item("owner", Array1::from(owner).into_pyarray(py))?;
    d.set_item("path", PyList::new(py, paths)?)?;
    d.set_item("index", Array1::from(index).into_pyarray(py))?;
    d.set_item("offsets", Array1::from(offsets).into_pyarray(py))?;
    d.set_item("co", pairs(co).into_pyarray(py))?;
    d.set_item("handle_left", pairs(hl).into_pyarray(py))?;
    d.set_item("handle_right", pairs(hr).into_pyarray(py))?;
    d.set_item(
        "interpolation",
        Array1::from(interpolation).into_pyarray(py),
    )?;
    d.set_item("easing", Array1::<i64>::zeros(k).into_pyarray(py))?;
    d.set_item("handle_type", Array1::from(handle_type).into_pyarray(py))?;
    let keys: Vec<i64> = r.keys.iter().map(|k| *k as i64).collect();
    d.set_item("keys", Array1::from(keys).into_pyarray(py))?;
    d.set_item(
        "distance_error",
        Array1::from(r.distance_error.clone()).into_pyarray(py),
    )?;
    d.set_item(
        "angle_error",
        Array1::from(r.angle_error.clone()).into_pyarray(py),
    )?;
    Ok(d)
}

/// Adds `reduce_keys` and `HANDLE_TYPES` to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(reduce_keys, m)?)?;
    // stub:
    // stub: HANDLE_TYPES: tuple[HandleTypeName, ...]
    // stub: """Blender's ``Keyframe.handle_left_type`` / ``handle_right_type`` identifiers; a key's code
    // stub: in ``reduce_keys``' ``"handle_type"`` is its index here."""
    m.add("HANDLE_TYPES", PyTuple::new(m.py(), HandleType::NAMES)?)?;
    Ok(())
}
