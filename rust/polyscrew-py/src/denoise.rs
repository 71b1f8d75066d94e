//! `denoise`: the binding of `polyscrew::denoise` (Remove Noise). Conversion only: poses
//! arrive as `(N, 4, 4)` or `(B, N, 4, 4)` arrays and leave in the same shape.

use numpy::ndarray::{Array1, Array2, Array4, ArrayViewD};
use numpy::{IntoPyArray, PyArray1, PyArrayDyn};
use pyo3::prelude::*;
use pyo3::types::PyList;

use polyscrew::denoise::{
    denoise_footprint, denoised_rows, DENOISE_HINT, MAX_DENOISE_BATCH, MAX_DENOISE_POSES,
    MIN_DENOISE_POSES,
};
use polyscrew::memory::try_vec;
use polyscrew::{denoise_batch, DenoiseOptions, Denoised, Pose, Strength};

use crate::args::Most;
use crate::arrays::read_vector;
use crate::errors::{check_budget, shape_err, to_py_err};

const F: &str = "denoise";

/// The poses of a clip and the matrices of its held poses, as read (once) from the input.
type Clips = (Vec<Pose>, Vec<[[f64; 4]; 4]>);

/// The shape of `(N, 4, 4)` or `(B, N, 4, 4)` poses: (bodies, frames, batch?), within the
/// limits.
fn clip_shape(array: &ArrayViewD<'_, f64>) -> PyResult<(usize, usize, bool)> {
    let shape = array.shape().to_vec();
    let (bodies, n, batch) = match shape.as_slice() {
        [n, 4, 4] => (1, *n, false),
        [b, n, 4, 4] => (*b, *n, true),
        _ => return Err(shape_err(F, "poses", "(N, 4, 4) or (B, N, 4, 4)", &shape)),
    };
    if n > MAX_DENOISE_POSES || bodies.saturating_mul(n) > MAX_DENOISE_BATCH {
        return Err(crate::errors::invalid(format!(
            "{F}: poses: {bodies} x {n} poses exceed the limits ({MAX_DENOISE_POSES} per clip, {MAX_DENOISE_BATCH} in all)"
        )));
    }
    if n < MIN_DENOISE_POSES {
        return Err(crate::errors::invalid(format!(
            "{F}: poses: {n} poses given, at least {MIN_DENOISE_POSES} needed"
        )));
    }
    Ok((bodies, n, batch))
}

/// Reads the poses (body-major) of a `clip_shape` array in one pass, keeping the matrices
/// of the held ones as they were read: nothing is read from the caller's array again.
fn read_clips(
    array: ArrayViewD<'_, f64>,
    (bodies, n, batch): (usize, usize, bool),
    held: Option<&[bool]>,
) -> PyResult<Clips> {
    let mut poses = try_vec(bodies * n, "input poses").map_err(|e| to_py_err(F, e))?;
    let kept = held.map_or(0, |h| h.iter().filter(|h| **h).count());
    let mut held_rows = try_vec(kept, "held poses").map_err(|e| to_py_err(F, e))?;
    let mut m = [[0.0; 4]; 4];
    let mut it = array.iter();
    for g in 0..bodies * n {
        for row in m.iter_mut() {
            for v in row.iter_mut() {
                *v = *it.next().expect("16 values per pose");
            }
        }
        let (b, i) = (g / n, g % n);
        poses.push(Pose::from_rows(&m, i).map_err(|e| {
            if batch {
                crate::errors::invalid(format!("{F}: body {b}: {e}"))
            } else {
                to_py_err(F, e)
            }
        })?);
        if held.is_some_and(|h| h[g]) {
            held_rows.push(m);
        }
    }
    Ok((poses, held_rows))
}

/// `strength`: None (automatic), one time for both, or (rotation, translation).
fn read_strength(strength: Option<&Bound<'_, PyAny>>) -> PyResult<Strength> {
    let Some(s) = strength else {
        return Ok(Strength::Auto);
    };
    if let Ok(t) = s.extract::<f64>() {
        return Ok(Strength::Fixed {
            rotation: t,
            translation: t,
        });
    }
    let pair: (f64, f64) = s.extract().map_err(|_| {
        crate::errors::invalid(format!(
            "{F}: strength: expected None, a time or (rotation, translation) times"
        ))
    })?;
    Ok(Strength::Fixed {
        rotation: pair.0,
        translation: pair.1,
    })
}

/// `held`: None, a boolean mask (N,) for every body or (B, N) (read through numpy, its
/// length checked before anything is reserved for it).
fn read_held(
    held: Option<&Bound<'_, PyAny>>,
    bodies: usize,
    n: usize,
) -> PyResult<Option<Vec<bool>>> {
    let Some(h) = held else {
        return Ok(None);
    };
    let err = || {
        crate::errors::invalid(format!(
            "{F}: held: expected a boolean mask of shape ({n},) or ({bodies}, {n})"
        ))
    };
    let Some((shape, mask)) = crate::args::bool_array(F, "held", h, Most::AtMost(n.max(bodies)))?
    else {
        return Err(err());
    };
    match shape.as_slice() {
        [m] if *m == n => {
            let mut all = try_vec(bodies * n, "held mask").map_err(|e| to_py_err(F, e))?;
            for _ in 0..bodies {
                all.extend_from_slice(&mask);
            }
            Ok(Some(all))
        }
        [b, m] if *b == bodies && *m == n => Ok(Some(mask)),
        _ => Err(err()),
    }
}

/// The result of ``denoise``: the smooth poses and what was chosen on the way.
///
/// For one clip the strengths, noises and iterations are floats (ints) and the pivot is
/// (3,); for a batch of B clips they are (B,) arrays, the pivot (B, 3), the kinks a list.
#[pyclass(frozen, module = "polyscrew", name = "Denoised")]
pub struct PyDenoised {
    results: Vec<Denoised>,
    /// The smooth poses as (B, N, 4, 4), held ones the input's matrices as read, bit for bit
    /// (`Denoised::write_rows`).
    matrices: Array4<f64>,
    n: usize,
    batch: bool,
}

impl PyDenoised {
    fn scalar<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&Denoised) -> f64,
    ) -> PyResult<Bound<'py, PyAny>> {
        if self.batch {
            let v: Vec<f64> = self.results.iter().map(f).collect();
            Ok(Array1::from(v).into_pyarray(py).into_any())
        } else {
            Ok(f(&self.results[0]).into_pyobject(py)?.into_any())
        }
    }
}

#[pymethods]
impl PyDenoised {
    /// poses -> FloatArray
    ///
    /// The smooth poses, in the input's shape ((N, 4, 4) or (B, N, 4, 4)), rigid;
    /// held poses exactly as given.
    #[getter]
    fn poses<'py>(&self, py: Python<'py>) -> Bound<'py, PyArrayDyn<f64>> {
        let out = self.matrices.clone().into_dyn();
        if self.batch {
            out.into_pyarray(py)
        } else {
            out.index_axis_move(numpy::ndarray::Axis(0), 0)
                .into_pyarray(py)
        }
    }

    /// rotation_strength -> float | FloatArray
    ///
    /// The rotation's strength tau, a time in the units of ``times`` (chosen or given).
    #[getter]
    fn rotation_strength<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.scalar(py, |r| r.rotation_strength)
    }

    /// translation_strength -> float | FloatArray
    ///
    /// The translation's strength tau.
    #[getter]
    fn translation_strength<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.scalar(py, |r| r.translation_strength)
    }

    /// rotation_noise -> float | FloatArray
    ///
    /// Estimated rotation noise of the input: standard deviation per axis, radians.
    #[getter]
    fn rotation_noise<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.scalar(py, |r| r.rotation_noise)
    }

    /// translation_noise -> float | FloatArray
    ///
    /// Estimated position noise of the pivot, per axis, in the units of the poses.
    #[getter]
    fn translation_noise<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.scalar(py, |r| r.translation_noise)
    }

    /// pivot -> FloatArray
    ///
    /// The body point (body coordinates) whose world path was smoothed: (3,) or (B, 3).
    #[getter]
    fn pivot<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        let mut out = Array2::<f64>::zeros((self.results.len(), 3));
        for (b, r) in self.results.iter().enumerate() {
            for c in 0..3 {
                out[[b, c]] = r.pivot[c];
            }
        }
        if self.batch {
            out.into_pyarray(py).into_any()
        } else {
            out.row(0).to_owned().into_pyarray(py).into_any()
        }
    }

    /// rotation_kinks -> npt.NDArray[np.int64] | list[npt.NDArray[np.int64]]
    ///
    /// Indices of the poses where an abrupt turn of the rotation was let through.
    #[getter]
    fn rotation_kinks<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.kinks(py, |r| &r.rotation_kinks)
    }

    /// translation_kinks -> npt.NDArray[np.int64] | list[npt.NDArray[np.int64]]
    ///
    /// Indices of the poses where an abrupt turn of the path was let through.
    #[getter]
    fn translation_kinks<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.kinks(py, |r| &r.translation_kinks)
    }

    /// pops -> npt.NDArray[np.int64] | list[npt.NDArray[np.int64]]
    ///
    /// Indices of the first pose after each pop (a jump far faster than the motion
    /// around it) the clip was cut at; the pieces between are smoothed apart, each with its
    /// own strengths (those reported are the longest piece's), and the jump is kept.
    #[getter]
    fn pops<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        self.kinks(py, |r| &r.pops)
    }

    /// iterations -> int | npt.NDArray[np.int64]
    ///
    /// Gauss-Newton iterations of the rotation solve.
    #[getter]
    fn iterations<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        if self.batch {
            let v: Vec<i64> = self.results.iter().map(|r| r.iterations as i64).collect();
            Ok(Array1::from(v).into_pyarray(py).into_any())
        } else {
            Ok(self.results[0].iterations.into_pyobject(py)?.into_any())
        }
    }

    /// converged -> bool
    ///
    /// Whether every rotation solve converged (last step below 1e-9 rad).
    #[getter]
    fn converged(&self) -> bool {
        self.results.iter().all(|r| r.converged)
    }

    fn __repr__(&self) -> String {
        match (&self.results[..], self.batch) {
            (_, true) => format!("Denoised({} bodies x {} poses)", self.results.len(), self.n),
            ([r, ..], false) => format!(
                "Denoised({} poses, rotation_strength={:.4}, translation_strength={:.4}, rotation_noise={:.3e}, translation_noise={:.3e})",
                self.n, r.rotation_strength, r.translation_strength, r.rotation_noise, r.translation_noise
            ),
            ([], false) => format!("Denoised({} poses)", self.n),
        }
    }
}

impl PyDenoised {
    fn kinks<'py>(
        &self,
        py: Python<'py>,
        f: impl Fn(&Denoised) -> &Vec<usize>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let arrays: Vec<Bound<'py, PyArray1<i64>>> = self
            .results
            .iter()
            .map(|r| {
                Array1::from(f(r).iter().map(|k| *k as i64).collect::<Vec<_>>()).into_pyarray(py)
            })
            .collect();
        if self.batch {
            Ok(PyList::new(py, arrays)?.into_any())
        } else {
            Ok(arrays.into_iter().next().expect("one clip").into_any())
        }
    }
}

/// denoise(
///     poses: ArrayLike,
///     times: ArrayLike,
///     strength: float | tuple[float, float] | None = None,
///     held: ArrayLike | None = None,
///     order: int = 3,
///     kinks: bool = True,
///     threads: int = 0,
/// ) -> Denoised
///
/// Remove noise from a captured rigid motion (camera solve, motion capture, baked
/// simulation): the smooth motion nearest to ``poses`` (N, 4, 4) at ``times`` (N,), or to
/// each of B clips (B, N, 4, 4) at the same times, in one call.
///
/// Coordinate-free: ``denoise(G @ poses @ H)`` is ``G @ denoise(poses) @ H`` for rigid G, H,
/// with the automatic strengths too; a screw motion (and any motion turning at constant
/// angular velocity while one body point moves at constant velocity) comes back unchanged.
/// The rotation is smoothed on the rotation group and the path of one body point (the
/// ``pivot``, the point of least jitter) in space, each by a smoothing spline of ``order``
/// 3 (quintic: constant acceleration is free; 2: cubic) on the given, possibly uneven, times.
///
/// ``strength``: None chooses the strengths from the data (generalised cross-validation,
/// rotation and translation apart, reported back); a time tau (in the units of ``times``)
/// or (rotation, translation) times: motion faster than about ``2 pi tau`` per cycle is
/// removed, 0 leaves that part as is; any finite tau >= 0 is served, one above 100 median
/// spacings of ``times`` acts as 100 spacings (the strength reported). The work is done in
/// a normalised time: scaling ``times`` changes nothing but the strengths' unit. ``held``:
/// boolean mask (N,) or (B, N); held poses are kept exactly (their matrices as given, read
/// once) and the motion passes through them. ``kinks``: let abrupt turns (a prop stopping
/// against a wall) through instead of rounding them, and cut the clip at pops (see
/// ``Denoised.pops``). ``threads``: clips of a batch
/// are spread over this many threads (0: all the machine has). A batch of no clips
/// (0, N, 4, 4) is checked like any other and gives an empty result.
///
/// Raises ValueError for a wrong shape, fewer than 4 poses, more than 1,000,000 poses per
/// clip or 20,000,000 in all, a non-rigid or non-finite pose (naming the index, and the
/// body of a batch), times that are not finite and increasing, a held mask of the wrong
/// shape, an order other than 2 or 3, a negative or non-finite strength, and values so
/// large that the computation overflows.
#[pyfunction]
#[pyo3(signature = (poses, times, strength=None, held=None, order=None, kinks=None, threads=None))]
#[pyo3(text_signature = "(poses, times, strength=None, held=None, order=3, kinks=True, threads=0)")]
#[allow(clippy::too_many_arguments)]
fn denoise(
    py: Python<'_>,
    poses: &Bound<'_, PyAny>,
    times: &Bound<'_, PyAny>,
    strength: Option<&Bound<'_, PyAny>>,
    held: Option<&Bound<'_, PyAny>>,
    order: Option<&Bound<'_, PyAny>>,
    kinks: Option<&Bound<'_, PyAny>>,
    threads: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyDenoised> {
    let order = match order {
        Some(o) if !o.is_none() => crate::args::int_in(F, "order", o, 2, 3)? as usize,
        _ => 3,
    };
    let kinks = match kinks {
        Some(k) if !k.is_none() => k
            .extract::<bool>()
            .map_err(|_| crate::errors::wrong_type(format!("{F}: kinks: expected a bool")))?,
        _ => true,
    };
    let threads = match threads {
        Some(t) if !t.is_none() => crate::args::int_in(F, "threads", t, 0, 1024)? as usize,
        _ => 0,
    };
    let poses = crate::args::float_array(F, "poses", poses)?;
    let times = crate::args::float_array(F, "times", times)?;
    // Before anything is copied: the conversions of the arguments and what the call holds
    // at its peak (the core's estimate per pose), against the memory budget.
    let count: usize = poses.shape().iter().rev().skip(2).product();
    check_budget(
        F,
        poses.copy() + times.copy() + denoise_footprint(count),
        "the noise removal",
        DENOISE_HINT,
    )?;
    let (poses, times) = (poses.read()?, times.read()?);
    let (input, times) = (poses.as_array(), times.as_array());
    let shape = clip_shape(&input)?;
    let (bodies, n, batch) = shape;
    let held = read_held(held, bodies, n)?;
    let strength = read_strength(strength)?;
    let options = DenoiseOptions {
        strength,
        order,
        kinks,
    };
    // The one pass over the poses, with the GIL held: a held pose comes back as it was read,
    // and once the GIL is released another Python thread may write the caller's arrays
    // (nothing is read from them again). The work after it runs without the GIL.
    let (poses, held_rows) = read_clips(input.view(), shape, held.as_deref())?;
    let times = read_vector(F, "times", &times)?;
    if times.len() != n {
        return Err(crate::errors::invalid(format!(
            "{F}: times: expected {n} entries, got {}",
            times.len()
        )));
    }
    let (results, matrices) = py.detach(|| -> PyResult<(Vec<Denoised>, Vec<f64>)> {
        let results = denoise_batch(&poses, bodies, &times, held.as_deref(), &options, threads)
            .map_err(|e| to_py_err(F, e))?;
        drop(poses);
        let mut out = try_vec(bodies, "denoised bodies").map_err(|e| to_py_err(F, e))?;
        for (b, r) in results.into_iter().enumerate() {
            match r {
                Ok(d) => out.push(d),
                Err(e) if batch => return Err(to_py_err(&format!("{F}: body {b}"), e)),
                Err(e) => return Err(to_py_err(F, e)),
            }
        }
        let matrices =
            denoised_rows(&out, n, held.as_deref(), &held_rows).map_err(|e| to_py_err(F, e))?;
        Ok((out, matrices))
    })?;
    let matrices = Array4::from_shape_vec((bodies, n, 4, 4), matrices)
        .map_err(|e| crate::errors::invalid(format!("{F}: {e}")))?;
    Ok(PyDenoised {
        results,
        matrices,
        n,
        batch,
    })
}

/// Adds `denoise` and `Denoised` to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyDenoised>()?;
    m.add_function(wrap_pyfunction!(denoise, m)?)?;
    Ok(())
}
