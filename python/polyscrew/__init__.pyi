"""polyscrew: coordinate-free smoothing of rigid-body motions (the ScrewBender core).

Poses are float64 arrays of shape (4, 4) or (N, 4, 4) in Blender's layout (translation in
the last column). Any array-like is accepted and converted to float64. Bad input raises
``ValueError`` whose message names the function, the offending index and the reason.
"""

from typing import Literal, overload

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]
SchemeName = Literal["four_point", "bspline", "jarek"]
TimingName = Literal["smooth", "linear"]
RotationModeName = Literal["QUATERNION", "AXIS_ANGLE", "XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]

MAX_LEVELS: int
"""The largest accepted number of subdivision levels (12)."""

class Screw:
    """The screw between two poses (Rossignac-Kim): ``b = M a`` with ``M`` a rotation by
    ``angle`` about the line through ``point`` along ``axis``, plus ``slide`` along it."""

    @property
    def axis(self) -> FloatArray:
        """Unit direction of the axis, shape (3,). Along the translation for a pure translation."""
    @property
    def point(self) -> FloatArray:
        """The point of the axis nearest to the first pose's origin, shape (3,)."""
    @property
    def angle(self) -> float:
        """Rotation angle, radians in [0, pi]."""
    @property
    def slide(self) -> float:
        """Translation along the axis."""

def screw(a: ArrayLike, b: ArrayLike) -> Screw:
    """The minimal screw carrying pose ``a`` (4, 4) to pose ``b`` (4, 4)."""

@overload
def interpolate(a: ArrayLike, b: ArrayLike, t: float) -> FloatArray: ...
@overload
def interpolate(a: ArrayLike, b: ArrayLike, t: ArrayLike) -> FloatArray: ...
def interpolate(a: ArrayLike, b: ArrayLike, t: float | ArrayLike) -> FloatArray:
    """``s(a, t, b)``: the pose a fraction ``t`` along the screw from ``a`` to ``b``.

    ``t = 0`` gives ``a``, ``t = 1`` gives ``b``, other values move along or past the screw.
    Returns (4, 4) for a float ``t``, (len(t), 4, 4) for an array.
    """

def subdivide(
    poses: ArrayLike, scheme: SchemeName = "jarek", levels: int = 4, closed: bool = False
) -> FloatArray:
    """Split&Tweak subdivision of the polyscrew through ``poses`` (N, 4, 4).

    Returns (N * 2**levels, 4, 4) closed, ((N - 1) * 2**levels + 1, 4, 4) open; an open
    sequence keeps its first and last pose exactly; "four_point" keeps every key.
    ``levels`` must be in 0..=12; at least 2 poses are needed.
    """

def sample(
    poses: ArrayLike,
    key_times: ArrayLike,
    times: ArrayLike,
    scheme: SchemeName = "jarek",
    levels: int = 4,
    closed: bool = False,
    period: float | None = None,
    timing: TimingName = "smooth",
) -> FloatArray:
    """The subdivided motion of ``poses`` keyed at ``key_times``, at ``times``: (len(times), 4, 4).

    ``key_times`` must be finite and strictly increasing. ``closed`` makes a cycle of length
    ``period`` (default: closed after the mean key spacing). ``timing="smooth"`` is the
    monotone C1 map from time to the motion parameter, ``"linear"`` maps each key span
    linearly. Open motions hold their end poses outside the keys' range.
    """

def subdivide_vectors(
    values: ArrayLike, scheme: SchemeName = "jarek", levels: int = 4, closed: bool = False
) -> FloatArray:
    """The same schemes on plain vectors ``values`` (N, 3) (the linear masks)."""

def sample_vectors(
    values: ArrayLike,
    key_times: ArrayLike,
    times: ArrayLike,
    scheme: SchemeName = "jarek",
    levels: int = 4,
    closed: bool = False,
    period: float | None = None,
    timing: TimingName = "smooth",
) -> FloatArray:
    """``sample`` for plain vectors ``values`` (N, 3) (for example log-scale): (len(times), 3)."""

def rotation_channels(
    rotations: ArrayLike, mode: RotationModeName, previous: ArrayLike | None = None
) -> FloatArray:
    """Blender rotation channels of ``rotations`` ((N, 3, 3) or (N, 4, 4)), continuous.

    "QUATERNION": (N, 4) w, x, y, z without sign flips; "AXIS_ANGLE": (N, 4) angle, x, y, z
    unwrapped; Euler orders: (N, 3) angles per axis (x, y, z), each frame compatible with the
    previous one (no jump above 180 degrees). ``previous`` continues from earlier values.
    """

# --- Angular-velocity editing (Xie et al. 2011, "Sketch-based rotation editing") ---

FitStatusName = Literal["converged", "iteration_limit", "above_delta"]

class AngularVelocityFit:
    """The rotation fitted by ``fit_angular_velocity`` and how well it fits.

    The rotation is the normalised Hermite quaternion spline ``q(t) / |q(t)|`` through the
    keys and the variable frames, so every orientation is exactly unit. Quaternions are
    (..., 4) arrays in w, x, y, z order; angular velocities are world-frame, rad per unit time.
    """

    @property
    def quaternions(self) -> FloatArray:
        """Fitted orientations at ``sample_times``, (S, 4) w, x, y, z: unit, sign-continuous,
        with the first key's sign; equal (up to sign) to the constrained keys at their times."""
    @property
    def sample_times(self) -> FloatArray:
        """The times of ``quaternions`` and ``omega``, (S,) (the key times by default)."""
    @property
    def omega(self) -> FloatArray:
        """Fitted angular velocity ``vec(2 q' q^-1)`` at ``sample_times``, (S, 3)."""
    @property
    def key_quaternions(self) -> FloatArray:
        """Fitted orientation at each key time, (N, 4): the free keys moved, the others kept."""
    @property
    def frame_times(self) -> FloatArray:
        """Times of the variable frames inserted (at most ``max_frames``), (F,) increasing."""
    @property
    def fit_error(self) -> float:
        """The largest fragment error ``max_n F_n``, ``F_n = ∫ |2 q' q^-1 - omega_s|^2 dt``
        over each fragment (the paper's eq. 2); the fit succeeded when it is <= ``delta``."""
    @property
    def fragment_errors(self) -> FloatArray:
        """Every fragment error ``F_n``, in time order."""
    @property
    def fragment_duration(self) -> float:
        """The fragment length used."""
    @property
    def iterations(self) -> int:
        """Levenberg-Marquardt steps taken over all rounds."""
    @property
    def rounds(self) -> int:
        """Optimisation rounds (variable frames are inserted between rounds)."""
    @property
    def converged(self) -> bool:
        """True when the optimiser converged and ``fit_error <= delta``."""
    @property
    def status(self) -> FitStatusName:
        """How the fit ended: "converged", "iteration_limit" (the optimiser ran out of
        ``max_iterations``) or "above_delta" (converged, but the error stays above ``delta``
        with the variable frames allowed: the target is infeasible for these keys)."""
    @property
    def energy(self) -> float:
        """The minimised energy ``alpha * W_T + W_A``."""
    @property
    def tangential(self) -> float:
        """``W_T``: the integrated squared tangential acceleration."""
    @property
    def deviation(self) -> float:
        """``W_A``: the integrated squared deviation from the target angular velocity."""
    @property
    def delta(self) -> float:
        """The threshold the fit was held to."""
    def sample(self, times: ArrayLike) -> FloatArray:
        """Fitted orientations at ``times`` (T,) inside the key range: (T, 4) w, x, y, z."""
    def angular_velocity(self, times: ArrayLike) -> FloatArray:
        """Fitted angular velocity at ``times`` (T,) inside the key range: (T, 3)."""

def fit_angular_velocity(
    key_quaternions: ArrayLike,
    key_times: ArrayLike,
    target_times: ArrayLike,
    target_omega: ArrayLike,
    constrained: ArrayLike | None = None,
    alpha: float = 0.002,
    delta: float = 0.1,
    max_iterations: int = 200,
    max_frames: int = 10,
    sample_times: ArrayLike | None = None,
    *,
    target_speed: ArrayLike | None = None,
    fragment_duration: float | None = None,
) -> AngularVelocityFit:
    """Fit the rotation between keys to a target angular velocity, keeping chosen keys
    (Xie, Xu, Yu, Weng 2011, "Sketch-based rotation editing").

    Minimises ``alpha * W_T + W_A`` over a Hermite quaternion spline through the keys, with
    ``W_T = ∫ |q''|^2 - (q . q'')^2 / |q|^2 dt`` (tangential acceleration) and
    ``W_A = ∫ |2 q' q^-1 - omega_s|^2 dt`` (deviation from the target), the constrained keys
    held exactly and unit norm exact; inserts variable frames at the midpoints of fragments
    whose error exceeds ``delta`` and fits again, up to ``max_frames`` in all.

    Args:
        key_quaternions: (N, 4) key orientations, w, x, y, z; N >= 2. Normalised (zero or
            NaN rejected); their signs are chosen to follow the target between keys.
        key_times: (N,) strictly increasing key times. Use seconds (and rad/s below) for the
            default ``alpha`` and ``delta`` to mean what they mean in the paper.
        target_times: (M,) strictly increasing times of the target samples, M >= 2, covering
            ``[key_times[0], key_times[-1]]``; the target is linear between samples.
        target_omega: (M, 3) world-frame target angular velocity. With ``target_speed`` these
            are directions instead (the sketch on the unit sphere): normalised, not
            required to be unit, zero length rejected.
        constrained: the keys held exactly: None (all), a boolean mask (N,) or key indices.
            The other keys are free: the fit moves them.
        alpha: weight of ``W_T`` (paper: 0.002; 0.001-0.005 works well), >= 0.
        delta: threshold on every fragment error (paper: 0.1), > 0.
        max_iterations: Levenberg-Marquardt steps allowed per round, >= 1.
        max_frames: variable frames allowed in total (paper: at most 10 were needed).
        sample_times: times for ``quaternions``/``omega`` within the key range (default:
            the key times).
        target_speed: (M,) magnitudes; when given, ``target_omega`` holds directions.
        fragment_duration: fragment length for the error test (default: two fragments per
            key span, at least 8 in all).

    Raises:
        ValueError: bad input (shapes, NaN, times not increasing, zero-length range, no or
            one key, zero directions, target not covering the keys, options out of range),
            with the argument and index named; or a fit that did not converge
            ("did not converge") or stayed above ``delta`` ("target infeasible"). In the
            latter two cases the exception's ``result`` attribute holds the best
            ``AngularVelocityFit`` found.
    """
