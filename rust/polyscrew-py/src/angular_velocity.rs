//! `fit_angular_velocity`: the binding of `polyscrew::fit_angular_velocity` (Xie et al.
//! 2011). Conversion only: quaternions arrive and leave as `(N, 4)` w, x, y, z arrays.

use glam::{DQuat, DVec3};
use numpy::ndarray::{Array1, Array2, ArrayViewD};
use numpy::{IntoPyArray, PyArray1, PyArray2};
use pyo3::prelude::*;

// The defaults are written as literals so that Python's signature shows them; they are
// the core's DEFAULT_ALPHA, DEFAULT_DELTA, DEFAULT_MAX_ITERATIONS and DEFAULT_MAX_FRAMES,
// checked below at compile time.
const _: () = {
    use polyscrew::angular_velocity as av;
    assert!(av::DEFAULT_ALPHA == 0.002 && av::DEFAULT_DELTA == 0.1);
    assert!(av::DEFAULT_MAX_ITERATIONS == 200 && av::DEFAULT_MAX_FRAMES == 10);
};
use polyscrew::{
    fit_angular_velocity as core_fit, AngularVelocityFit, AngularVelocityTarget, FitOptions,
    FitStatus,
};

use crate::args::{self, FitAngularVelocity, Function, Most};
use crate::args::{copy_of, float_array};
use crate::arrays::{read_rows3, read_vector, vector_len};
use crate::errors::{check_budget, shape_err, to_py_err};
use polyscrew::angular_velocity::{fit_footprint, FIT_HINT};
use polyscrew::memory::{try_vec, Footprint};
use polyscrew::Error;

const F: &str = FitAngularVelocity::NAME;

/// Reads `(N, 4)` quaternions in w, x, y, z order (normalised by the core), no GIL needed.
fn read_quaternions(what: &str, array: &ArrayViewD<'_, f64>) -> PyResult<Vec<DQuat>> {
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != 4 {
        return Err(shape_err(F, what, "(N, 4)", shape));
    }
    let mut out = try_vec(shape[0], "key quaternions").map_err(|e| to_py_err(F, e))?;
    for q in array.rows() {
        out.push(DQuat::from_xyzw(q[1], q[2], q[3], q[0]));
    }
    Ok(out)
}

/// `constrained`: `None` (all keys), a boolean mask of length N, or key indices
/// (negative indices count from the end, as in numpy); read through numpy, the length
/// checked before anything is reserved for it.
fn read_constrained(constrained: Option<&Bound<'_, PyAny>>, n: usize) -> PyResult<Vec<bool>> {
    let Some(c) = constrained.filter(|c| !c.is_none()) else {
        return try_vec(n, "constrained mask")
            .map(|mut mask| {
                mask.resize(n, true);
                mask
            })
            .map_err(|e| to_py_err(F, e));
    };
    let most_indices = Most::AtMost(n.saturating_mul(4).max(64));
    if let Some((shape, mask)) = args::bool_array(F, "constrained", c, most_indices)? {
        if !mask.is_empty() {
            if shape.len() != 1 || mask.len() != n {
                return Err(crate::errors::invalid(format!(
                    "{F}: constrained: boolean mask has {} entries for {n} keys",
                    mask.len()
                )));
            }
            return Ok(mask);
        }
    }
    let indices = args::int_list(F, "constrained", c, most_indices)?;
    let mut mask = try_vec(n, "constrained mask").map_err(|e| to_py_err(F, e))?;
    mask.resize(n, false);
    for i in indices {
        let j = if i < 0 { i + n as i64 } else { i };
        if j < 0 || j >= n as i64 {
            return Err(crate::errors::invalid(format!(
                "{F}: constrained: index {i} out of range for {n} keys"
            )));
        }
        mask[j as usize] = true;
    }
    Ok(mask)
}

/// Quaternions as an `(N, 4)` w, x, y, z array.
fn quaternions_to_array(q: &[DQuat]) -> Array2<f64> {
    let mut out = Array2::<f64>::zeros((q.len(), 4));
    for (i, r) in q.iter().enumerate() {
        out[[i, 0]] = r.w;
        out[[i, 1]] = r.x;
        out[[i, 2]] = r.y;
        out[[i, 3]] = r.z;
    }
    out
}

fn vectors_to_array(v: &[DVec3]) -> Array2<f64> {
    let mut out = Array2::<f64>::zeros((v.len(), 3));
    for (i, p) in v.iter().enumerate() {
        out[[i, 0]] = p.x;
        out[[i, 1]] = p.y;
        out[[i, 2]] = p.z;
    }
    out
}

/// The fitted angular velocity at `times`, allocated fallibly.
fn angular_velocities(fit: &AngularVelocityFit, times: &[f64]) -> Result<Vec<DVec3>, Error> {
    let mut w = try_vec(times.len(), "angular velocities")?;
    w.extend(times.iter().map(|t| fit.angular_velocity(*t)));
    Ok(w)
}

// stub:
// stub: FitStatusName = Literal["converged", "iteration_limit", "above_delta"]
/// The rotation fitted by ``fit_angular_velocity`` and how well it fits.
///
/// The rotation is the normalised Hermite quaternion spline ``q(t) / |q(t)|`` through the
/// keys and the variable frames, so every orientation is exactly unit. Quaternions are
/// (..., 4) arrays in w, x, y, z order; angular velocities are world-frame, rad per unit time.
#[pyclass(frozen, module = "polyscrew", name = "AngularVelocityFit")]
pub struct PyAngularVelocityFit {
    inner: AngularVelocityFit,
    sample_times: Vec<f64>,
    quaternions: Vec<DQuat>,
    omega: Vec<DVec3>,
}

#[pymethods]
impl PyAngularVelocityFit {
    /// quaternions -> FloatArray
    ///
    /// Fitted orientations at ``sample_times``, (S, 4) w, x, y, z: unit, sign-continuous,
    /// with the first key's sign; equal (up to sign) to the constrained keys at their times.
    #[getter]
    fn quaternions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        quaternions_to_array(&self.quaternions).into_pyarray(py)
    }

    /// sample_times -> FloatArray
    ///
    /// The times of ``quaternions`` and ``omega``, (S,) (the key times by default).
    #[getter]
    fn sample_times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from(self.sample_times.clone()).into_pyarray(py)
    }

    /// omega -> FloatArray
    ///
    /// Fitted angular velocity ``vec(2 q' q^-1)`` at ``sample_times``, (S, 3).
    #[getter]
    fn omega<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        vectors_to_array(&self.omega).into_pyarray(py)
    }

    /// key_quaternions -> FloatArray
    ///
    /// Fitted orientation at each key time, (N, 4): the free keys moved, the others kept.
    #[getter]
    fn key_quaternions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        quaternions_to_array(&self.inner.keys).into_pyarray(py)
    }

    /// frame_times -> FloatArray
    ///
    /// Times of the variable frames inserted (at most ``max_frames``), (F,) increasing.
    #[getter]
    fn frame_times<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from(self.inner.frame_times.clone()).into_pyarray(py)
    }

    /// fit_error -> float
    ///
    /// The largest fragment error ``max_n F_n``, ``F_n = ∫ |2 q' q^-1 - omega_s|^2 dt``
    /// over each fragment (the paper's eq. 2); the fit succeeded when it is <= ``delta``.
    #[getter]
    fn fit_error(&self) -> f64 {
        self.inner.fit_error
    }

    /// fragment_errors -> FloatArray
    ///
    /// Every fragment error ``F_n``, in time order.
    #[getter]
    fn fragment_errors<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        Array1::from(self.inner.fragment_errors.clone()).into_pyarray(py)
    }

    /// fragment_duration -> float
    ///
    /// The fragment length used.
    #[getter]
    fn fragment_duration(&self) -> f64 {
        self.inner.fragment_duration
    }

    /// iterations -> int
    ///
    /// Levenberg-Marquardt steps taken over all rounds.
    #[getter]
    fn iterations(&self) -> usize {
        self.inner.iterations
    }

    /// rounds -> int
    ///
    /// Optimisation rounds (variable frames are inserted between rounds).
    #[getter]
    fn rounds(&self) -> usize {
        self.inner.rounds
    }

    /// converged -> bool
    ///
    /// True when the optimiser converged and ``fit_error <= delta``.
    #[getter]
    fn converged(&self) -> bool {
        self.inner.converged()
    }

    /// status -> FitStatusName
    ///
    /// How the fit ended: "converged", "iteration_limit" (the optimiser ran out of
    /// ``max_iterations``) or "above_delta" (converged, but the error stays above ``delta``
    /// with the variable frames allowed: the target is infeasible for these keys).
    #[getter]
    fn status(&self) -> &'static str {
        match self.inner.status {
            FitStatus::Converged => "converged",
            FitStatus::IterationLimit => "iteration_limit",
            _ => "above_delta",
        }
    }

    /// energy -> float
    ///
    /// The minimised energy ``alpha * W_T + W_A``.
    #[getter]
    fn energy(&self) -> f64 {
        self.inner.energy
    }

    /// tangential -> float
    ///
    /// ``W_T``: the integrated squared tangential acceleration.
    #[getter]
    fn tangential(&self) -> f64 {
        self.inner.tangential
    }

    /// deviation -> float
    ///
    /// ``W_A``: the integrated squared deviation from the target angular velocity.
    #[getter]
    fn deviation(&self) -> f64 {
        self.inner.deviation
    }

    /// delta -> float
    ///
    /// The threshold the fit was held to.
    #[getter]
    fn delta(&self) -> f64 {
        self.inner.delta
    }

    /// sample(times: ArrayLike) -> FloatArray
    ///
    /// Fitted orientations at ``times`` (T,) inside the key range: (T, 4) w, x, y, z.
    fn sample<'py>(
        &self,
        py: Python<'py>,
        times: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        const G: &str = "AngularVelocityFit.sample";
        let times = float_array(G, "times", times)?;
        let m = vector_len(G, "times", &times)?;
        check_budget(
            G,
            times.copy() + Footprint::of::<f64>(m).and::<DQuat>(m).and::<[f64; 4]>(m),
            "the sampled orientations",
            FIT_HINT,
        )?;
        let times = times.read()?;
        let view = times.as_array();
        let inner = &self.inner;
        let out = py.detach(|| -> PyResult<Array2<f64>> {
            let times = read_vector(G, "times", &view)?;
            let q = inner.sample(&times).map_err(|e| to_py_err(G, e))?;
            Ok(quaternions_to_array(&q))
        })?;
        Ok(out.into_pyarray(py))
    }

    /// angular_velocity(times: ArrayLike) -> FloatArray
    ///
    /// Fitted angular velocity at ``times`` (T,) inside the key range: (T, 3).
    fn angular_velocity<'py>(
        &self,
        py: Python<'py>,
        times: &Bound<'py, PyAny>,
    ) -> PyResult<Bound<'py, PyArray2<f64>>> {
        const G: &str = "AngularVelocityFit.angular_velocity";
        let times = float_array(G, "times", times)?;
        let m = vector_len(G, "times", &times)?;
        check_budget(
            G,
            times.copy()
                + Footprint::of::<f64>(m)
                    .and::<DQuat>(m)
                    .and::<DVec3>(m)
                    .and::<[f64; 3]>(m),
            "the angular velocities",
            FIT_HINT,
        )?;
        let times = times.read()?;
        let view = times.as_array();
        let inner = &self.inner;
        let out = py.detach(|| -> PyResult<Array2<f64>> {
            let times = read_vector(G, "times", &view)?;
            // Checks the times (range, NaN) as `sample` does.
            inner.sample(&times).map_err(|e| to_py_err(G, e))?;
            let w = angular_velocities(inner, &times).map_err(|e| to_py_err(G, e))?;
            Ok(vectors_to_array(&w))
        })?;
        Ok(out.into_pyarray(py))
    }

    fn __repr__(&self) -> String {
        format!(
            "AngularVelocityFit(status={:?}, fit_error={:.4e}, frames={}, iterations={})",
            self.status(),
            self.inner.fit_error,
            self.inner.frame_times.len(),
            self.inner.iterations
        )
    }
}

/// fit_angular_velocity(
///     key_quaternions: ArrayLike,
///     key_times: ArrayLike,
///     target_times: ArrayLike,
///     target_omega: ArrayLike,
///     constrained: ArrayLike | None = None,
///     alpha: float = 0.002,
///     delta: float = 0.1,
///     max_iterations: int = 200,
///     max_frames: int = 10,
///     sample_times: ArrayLike | None = None,
///     *,
///     target_speed: ArrayLike | None = None,
///     fragment_duration: float | None = None,
/// ) -> AngularVelocityFit
///
/// Fit the rotation between keys to a target angular velocity, keeping chosen keys
/// (Xie, Xu, Yu, Weng 2011, "Sketch-based rotation editing").
///
/// Minimises ``alpha * W_T + W_A`` over a Hermite quaternion spline through the keys, with
/// ``W_T = ∫ |q''|^2 - (q . q'')^2 / |q|^2 dt`` (tangential acceleration) and
/// ``W_A = ∫ |2 q' q^-1 - omega_s|^2 dt`` (deviation from the target), the constrained keys
/// held exactly and unit norm exact; inserts variable frames at the midpoints of fragments
/// whose error exceeds ``delta`` and fits again, up to ``max_frames`` in all.
///
/// Args:
///     key_quaternions: (N, 4) key orientations, w, x, y, z; N >= 2. Normalised (zero or
///         NaN rejected); their signs are chosen to follow the target between keys.
///     key_times: (N,) strictly increasing key times. Use seconds (and rad/s below) for the
///         default ``alpha`` and ``delta`` to mean what they mean in the paper.
///     target_times: (M,) strictly increasing times of the target samples, M >= 2, covering
///         ``[key_times[0], key_times[-1]]``; the target is linear between samples.
///     target_omega: (M, 3) world-frame target angular velocity. With ``target_speed`` these
///         are directions instead (the sketch on the unit sphere): normalised, not
///         required to be unit, zero length rejected.
///     constrained: the keys held exactly: None (all), a boolean mask (N,) or key indices
///         (integers, at most max(4 N, 64) of them; TypeError for anything else).
///         The other keys are free: the fit moves them.
///     alpha: weight of ``W_T`` (paper: 0.002; 0.001-0.005 works well), >= 0.
///     delta: threshold on every fragment error (paper: 0.1), > 0.
///     max_iterations: Levenberg-Marquardt steps allowed per round, >= 1.
///     max_frames: variable frames allowed in total (paper: at most 10 were needed).
///     sample_times: times for ``quaternions``/``omega`` within the key range (default:
///         the key times).
///     target_speed: (M,) magnitudes; when given, ``target_omega`` holds directions.
///     fragment_duration: fragment length for the error test (default: two fragments per
///         key span, at least 8 in all).
///
/// Raises:
///     ValueError: bad input (shapes, NaN, times not increasing, zero-length range, no or
///         one key, zero directions, target not covering the keys, options out of range),
///         with the argument and index named; or a fit that did not converge
///         ("did not converge") or stayed above ``delta`` ("target infeasible"). In the
///         latter two cases the exception's ``result`` attribute holds the best
///         ``AngularVelocityFit`` found.
#[pyfunction]
#[pyo3(signature = (
    key_quaternions, key_times, target_times, target_omega, constrained=None,
    alpha=0.002, delta=0.1, max_iterations=200, max_frames=10, sample_times=None, *,
    target_speed=None,
    fragment_duration=None
))]
#[allow(clippy::too_many_arguments)]
fn fit_angular_velocity(
    py: Python<'_>,
    key_quaternions: &Bound<'_, PyAny>,
    key_times: &Bound<'_, PyAny>,
    target_times: &Bound<'_, PyAny>,
    target_omega: &Bound<'_, PyAny>,
    constrained: Option<&Bound<'_, PyAny>>,
    #[pyo3(from_py_with = args::alpha::<FitAngularVelocity>)] alpha: f64,
    #[pyo3(from_py_with = args::delta::<FitAngularVelocity>)] delta: f64,
    #[pyo3(from_py_with = args::max_iterations::<FitAngularVelocity>)] max_iterations: usize,
    #[pyo3(from_py_with = args::max_frames::<FitAngularVelocity>)] max_frames: usize,
    sample_times: Option<&Bound<'_, PyAny>>,
    target_speed: Option<&Bound<'_, PyAny>>,
    fragment_duration: Option<&Bound<'_, PyAny>>,
) -> PyResult<PyAngularVelocityFit> {
    let key_quaternions = float_array(F, "key_quaternions", key_quaternions)?;
    let key_times = float_array(F, "key_times", key_times)?;
    let target_times = float_array(F, "target_times", target_times)?;
    let target_omega = float_array(F, "target_omega", target_omega)?;
    let target_speed = args::optional_float_array(F, "target_speed", target_speed)?;
    let sample_times = args::optional_float_array(F, "sample_times", sample_times)?;
    let fragment_duration = args::optional_float(F, "fragment_duration", fragment_duration)?;
    let n = key_quaternions.shape().first().copied().unwrap_or(0);
    let n_targets = target_times.len();
    let n_samples = match &sample_times {
        Some(s) => vector_len(F, "sample_times", s)?,
        None => vector_len(F, "key_times", &key_times)?,
    };
    let options = FitOptions {
        alpha,
        delta,
        max_iterations,
        max_frames,
        fragment_duration,
    };
    check_budget(
        F,
        key_quaternions.copy()
            + key_times.copy()
            + target_times.copy()
            + target_omega.copy()
            + copy_of(target_speed.as_ref())
            + copy_of(sample_times.as_ref())
            + Footprint::of::<[f64; 5]>(n)
            + Footprint::of::<[f64; 8]>(n_targets)
            + fit_footprint(n, n_targets, &options)
            + Footprint::of::<[f64; 8]>(n_samples).times(2),
        "the fit",
        FIT_HINT,
    )?;
    let constrained = read_constrained(constrained, n)?;
    let (key_quaternions, key_times, target_times, target_omega) = (
        key_quaternions.read()?,
        key_times.read()?,
        target_times.read()?,
        target_omega.read()?,
    );
    let target_speed = target_speed.as_ref().map(|s| s.read()).transpose()?;
    let sample_times = sample_times.as_ref().map(|s| s.read()).transpose()?;
    let views = (
        key_quaternions.as_array(),
        key_times.as_array(),
        target_times.as_array(),
        target_omega.as_array(),
        target_speed.as_ref().map(|s| s.as_array()),
        sample_times.as_ref().map(|s| s.as_array()),
    );
    let (fit, sample_times, quaternions, omega) = py.detach(|| -> PyResult<_> {
        let (kq, kt, tt, to, ts, st) = &views;
        let keys = read_quaternions("key_quaternions", kq)?;
        if keys.len() < 2 {
            return Err(crate::errors::invalid(format!(
                "{F}: key_quaternions: {} keys given, at least 2 needed",
                keys.len()
            )));
        }
        let key_times = read_vector(F, "key_times", kt)?;
        let target_times = read_vector(F, "target_times", tt)?;
        let target_omega = read_rows3(F, "target_omega", to, "(M, 3)")?;
        let target_speed = ts
            .as_ref()
            .map(|s| read_vector(F, "target_speed", s))
            .transpose()?;
        let sample_times = match st {
            Some(s) => read_vector(F, "sample_times", s)?,
            None => key_times.clone(),
        };
        let run = || -> Result<_, Error> {
            let target = match &target_speed {
                Some(speed) => {
                    AngularVelocityTarget::from_directions(&target_times, &target_omega, speed)
                }
                None => AngularVelocityTarget::new(&target_times, &target_omega),
            }?;
            let fit = core_fit(&keys, &key_times, &constrained, &target, &options)?;
            let q = fit.sample(&sample_times)?;
            let w = angular_velocities(&fit, &sample_times)?;
            Ok((fit, q, w))
        };
        let (fit, q, w) = run().map_err(|e| to_py_err(F, e))?;
        Ok((fit, sample_times, q, w))
    })?;
    let result = PyAngularVelocityFit {
        inner: fit,
        sample_times,
        quaternions,
        omega,
    };
    if result.inner.converged() {
        return Ok(result);
    }
    let message = match result.inner.clone().into_result() {
        Err(failure) => failure.to_string(),
        Ok(_) => String::from("fit failed"),
    };
    let err = crate::errors::raise(
        crate::errors::Kind::FitFailed,
        format!("{F}: {message}; the best result is the exception's `result` attribute"),
    );
    err.value(py).setattr("result", Py::new(py, result)?)?;
    Err(err)
}

/// Adds `fit_angular_velocity` and `AngularVelocityFit` to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyAngularVelocityFit>()?;
    m.add_function(wrap_pyfunction!(fit_angular_velocity, m)?)?;
    Ok(())
}
