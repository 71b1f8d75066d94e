//! Python bindings of `polyscrew`: conversion and nothing else. This file is the registry:
//! the modules and what each adds to the Python module `polyscrew._polyscrew`.
//!
//! Every function has one shape: read the arguments (the two-step [`args::Arg`] reader: its
//! cost known before anything is converted) -> check the memory budget -> release the GIL
//! (`py.detach`; [`detach_unless_small`] for work of constant size) -> call the core -> map
//! the error once ([`errors::to_py_err`]) -> wrap the result as numpy arrays. The `.pyi` stub is generated from the doc comments of these files
//! (`scripts/generate_stub.py`): a function's doc opens with its Python signature.

mod angular_velocity;
mod args;
mod arrays;
mod batch;
mod denoise;
mod errors;
mod fcurve;
mod feature;
mod intent;
mod many;
mod motion;
mod progress;
mod read;
mod reduce;
mod sweep;

use pyo3::marker::Ungil;
use pyo3::prelude::*;

/// Runs `work` with the GIL released, unless it is `small`: work of constant size (the screw
/// of two poses, one interpolated pose) runs attached, because releasing and taking back the
/// GIL costs more than the work (measured with callgrind: about 450 instructions of the
/// 7,100 a `screw` call takes). Whatever its size, the work reads no Python object.
pub(crate) fn detach_unless_small<T, F>(py: Python<'_>, small: bool, work: F) -> T
where
    F: Ungil + FnOnce() -> T,
    T: Ungil,
{
    if small {
        work()
    } else {
        py.detach(work)
    }
}

// stub: from collections.abc import Callable, Mapping, Sequence
// stub: from typing import Any, Literal, TypedDict, overload
// stub:
// stub: import numpy as np
// stub: import numpy.typing as npt
// stub:
// stub: ArrayLike = npt.ArrayLike
// stub: FloatArray = npt.NDArray[np.float64]
// stub: SchemeName = Literal["four_point", "bspline", "jarek"]
// stub: TimingName = Literal["smooth", "linear", "keys"]
// stub: TimeMapName = Literal["smooth", "linear"]
// stub: RotationModeName = Literal["QUATERNION", "AXIS_ANGLE", "XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]

// The extension module `polyscrew._polyscrew`; `polyscrew/__init__.py` re-exports it.
/// polyscrew: coordinate-free smoothing of rigid-body motions (the ScrewBender core).
///
/// Poses are float64 arrays of shape (4, 4) or (N, 4, 4) in Blender's layout (translation in
/// the last column). Any array-like of real numbers is accepted and converted to float64
/// (complex numbers, strings and objects raise ``TypeError``). Bad input raises ``ValueError``
/// whose message names the function, the argument, the offending index and the reason; a
/// wrong type raises ``TypeError`` naming the function and the argument. Each is a
/// ``PolyscrewError`` as well: ``InvalidArgument`` (a ``ValueError``), ``ArgumentTypeError``
/// (a ``TypeError``), ``BudgetExceeded`` (a ``ValueError`` and a ``MemoryError``),
/// ``OutOfMemory`` (a ``MemoryError``) and ``FitFailed`` (a ``ValueError``); numpy's own
/// failures while converting an argument keep numpy's type, with the names put before the
/// message. No call returns NaN
/// or infinity for finite input inside the working ranges below, and none takes the process
/// down: an oversized request is refused before anything is allocated.
///
/// Working ranges (every value Blender can store, float32 below 3.4e38, is inside the first):
///
/// - coordinates: pose translations, vectors (``subdivide_vectors``, ``sample_vectors``),
///   points (``register_points``, ``inertia_points``, ``feature_points``) within
///   ``+-MAX_COORDINATE`` (1e150). The screw formulas square lengths once, subdivision moves
///   poses at most a few times further out, so every square stays below about 1e303.
/// - sweep vertices within +-1e75 (the area of a face is the fourth power of coordinates);
///   the poses may move them anywhere within 1e150.
/// - ``t`` of ``interpolate`` within +-1e12.
/// - times (key times, sample times, the end of a period) within ``+-MAX_TIME`` (1e300), key
///   times at least 1e-300 apart: the time map only takes differences, ratios and the
///   reciprocal of two spacings.
/// - ``fit_angular_velocity``: times within +-1e30 (the tenth root of ``MAX_TIME``: the fit
///   multiplies up to about ten such factors in one product), key times at least 1e-30 apart, target
///   angular velocities and speeds within +-1e30, ``alpha`` in 0..=1e30, at most 1,000,000
///   fragments, ``max_iterations`` in 1..=1,000,000, ``max_frames`` in 0..=1,000,000
///   (``q''`` of a Hermite segment grows like ``1 / h^2`` and ``omega / h``: in these ranges
///   every energy and normal equation stays below about 1e200).
/// - ``stiffness`` and ``inserted_stiffness``: finite springs up to 1e100 (or ``inf``).
/// - ``previous`` angles of ``rotation_channels`` and ``sample_channels`` (Euler angles, the
///   axis-angle angle) within ``+-MAX_PREVIOUS_ANGLE`` (1e9 radians): a continued angle is
///   ``previous`` plus less than half a turn, and beyond 1e9 a double no longer holds it to
///   1e-7 radians (at 1e17 the doubles are 16 radians apart).
///
/// Memory: every call estimates what it will hold at its peak (its output, its working memory
/// and its copies of the input, numpy's conversion of an argument that is not float64 (or
/// int64 for integers) included, a broadcast one too; not the caller's own arrays) before it
/// allocates or converts anything, and
/// raises ``ValueError`` when that exceeds ``memory_budget()`` (default
/// ``DEFAULT_MEMORY_BUDGET``, 1 GiB): the message says how much was asked for and how to ask
/// for less (fewer levels, fewer times, fewer steps). Should the system still refuse memory
/// within the budget, the call raises ``MemoryError`` (numpy's own allocation failure too),
/// naming the function and the argument. Peak bytes per item, for planning:
/// ``sample`` 192 per time (208 when windowed; ``sample_channels`` 168 with Euler channels,
/// 176 otherwise) plus 84 per dense pose (keys x 2**levels) up to 2,097,152 dense poses,
/// beyond which the motion is subdivided in windows of key spans (memory independent of the
/// key count, the same result to the bit); ``subdivide`` 212 per output pose;
/// ``rotation_channels`` 56 per rotation (Euler); ``sweep`` 48 per output vertex and 36 per
/// output triangle (checked before each screw's quads are added) plus 320 per body triangle;
/// ``feature_motion`` 640 per output pose; ``denoise`` 1,792 per pose (its scratch measured at
/// 1,500). Any argument that is not float64 adds 8 bytes per entry, its converted copy. ``scripts/bench/memory_footprints.py`` prints the
/// estimates beside the peaks measured for the largest uses (all below 160 MB).
///
/// The module releases the GIL while it reads its input, computes and builds its output.
#[pymodule]
fn _polyscrew(m: &Bound<'_, PyModule>) -> PyResult<()> {
    errors::register(m)?;
    motion::register(m)?;
    angular_velocity::register(m)?;
    sweep::register(m)?;
    feature::register(m)?;
    fcurve::register(m)?;
    intent::register(m)?;
    batch::register(m)?;
    read::register(m)?;
    denoise::register(m)?;
    reduce::register(m)?;
    many::register(m)?;
    Ok(())
}
