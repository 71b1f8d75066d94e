"""polyscrew: coordinate-free smoothing of rigid-body motions (the ScrewBender core).

Poses are float64 arrays of shape (4, 4) or (N, 4, 4) in Blender's layout (translation in
the last column). Any array-like of real numbers is accepted and converted to float64
(complex numbers, strings and objects raise ``TypeError``). Bad input raises ``ValueError``
whose message names the function, the argument, the offending index and the reason; a
wrong type raises ``TypeError`` naming the function and the argument. No call returns NaN
or infinity for finite input inside the working ranges below, and none takes the process
down: an oversized request is refused before anything is allocated.

Working ranges (every value Blender can store, float32 below 3.4e38, is inside the first):

- coordinates: pose translations, vectors (``subdivide_vectors``, ``sample_vectors``),
  points (``register_points``, ``inertia_points``, ``feature_points``) within
  ``+-MAX_COORDINATE`` (1e150). The screw formulas square lengths once, subdivision moves
  poses at most a few times further out, so every square stays below about 1e303.
- sweep vertices within +-1e75 (the area of a face is the fourth power of coordinates);
  the poses may move them anywhere within 1e150.
- ``t`` of ``interpolate`` within +-1e12.
- times (key times, sample times, the end of a period) within ``+-MAX_TIME`` (1e300), key
  times at least 1e-300 apart: the time map only takes differences, ratios and the
  reciprocal of two spacings.
- ``fit_angular_velocity``: times within +-1e30, key times at least 1e-30 apart, target
  angular velocities and speeds within +-1e30, ``alpha`` in 0..=1e30, at most 1,000,000
  fragments, ``max_iterations`` in 1..=1,000,000, ``max_frames`` in 0..=1,000,000
  (``q''`` of a Hermite segment grows like ``1 / h^2`` and ``omega / h``: in these ranges
  every energy and normal equation stays below about 1e200).
- ``stiffness`` and ``inserted_stiffness``: finite springs up to 1e100 (or ``inf``).
- ``previous`` angles of ``rotation_channels`` and ``sample_channels`` (Euler angles, the
  axis-angle angle) within ``+-MAX_PREVIOUS_ANGLE`` (1e9 radians): a continued angle is
  ``previous`` plus less than half a turn, and beyond 1e9 a double no longer holds it to
  1e-7 radians (at 1e17 the doubles are 16 radians apart).

Memory: every call estimates what it will hold at its peak (its output, its working memory
and its copies of the input, numpy's conversion of an argument that is not float64 (or
int64 for integers) included, a broadcast one too; not the caller's own arrays) before it
allocates or converts anything, and
raises ``ValueError`` when that exceeds ``memory_budget()`` (default
``DEFAULT_MEMORY_BUDGET``, 1 GiB): the message says how much was asked for and how to ask
for less (fewer levels, fewer times, fewer steps). Should the system still refuse memory
within the budget, the call raises ``MemoryError`` (numpy's own allocation failure too),
naming the function and the argument. Peak bytes per item, for planning:
``sample`` 192 per time (208 when windowed; ``sample_channels`` 168 with Euler channels,
176 otherwise) plus 84 per dense pose (keys x 2**levels) up to 2,097,152 dense poses,
beyond which the motion is subdivided in windows of key spans (memory independent of the
key count, the same result to the bit); ``subdivide`` 212 per output pose;
``rotation_channels`` 56 per rotation (Euler); ``sweep`` 48 per output vertex and 36 per
output triangle (checked before each screw's quads are added) plus 320 per body triangle;
``feature_motion`` 640 per output pose; ``denoise`` 1,792 per pose (its scratch measured at
1,500). Any argument that is not float64 adds 8 bytes per entry, its converted copy. ``scripts/memory_footprints.py`` prints the
estimates beside the peaks measured for the largest uses (all below 160 MB).

The module releases the GIL while it reads its input, computes and builds its output.
"""

from collections.abc import Mapping, Sequence
from typing import Any, Literal, TypedDict, overload

import numpy as np
import numpy.typing as npt

ArrayLike = npt.ArrayLike
FloatArray = npt.NDArray[np.float64]
SchemeName = Literal["four_point", "bspline", "jarek"]
TimingName = Literal["smooth", "linear"]
RotationModeName = Literal["QUATERNION", "AXIS_ANGLE", "XYZ", "XZY", "YXZ", "YZX", "ZXY", "ZYX"]

MAX_LEVELS: int
"""The largest accepted number of subdivision levels (12)."""

MAX_COORDINATE: float
"""The working range of coordinates: ``|x| <= 1e150`` (see the module documentation)."""

MAX_TIME: float
"""The working range of times outside ``fit_angular_velocity``: ``|t| <= 1e300``."""

MAX_PREVIOUS_ANGLE: float
"""The largest ``previous`` angle (radians, either sign) the rotation channels continue
from: 1e9 (see the module documentation); beyond it ``ValueError``."""

MAX_ROTATIONS: int
"""The most rotations one ``rotation_channels`` call converts: 2**24 (16,777,216), the most
the default memory budget accepts in quaternion and axis-angle modes. It bounds the call's
time (a few seconds of one core) whatever the budget; more raise ``ValueError`` before any
is read."""

DEFAULT_MEMORY_BUDGET: int
"""The default memory budget per call, 1 GiB (1073741824 bytes): about 5 times the largest
legitimate use (the 10,000 keys x 8 levels subdivision benchmark in Rust, 215 MB by the
estimate; through Python a 100,000-triangle sweep over 64 screws in 8 steps, 154 MB
estimated, 118 MB measured)."""

def memory_budget() -> int:
    """The memory budget in bytes: the most one call may hold at its peak (output, working
    memory, copies of the input). A call that would need more raises ``ValueError`` up
    front, naming the bytes asked for and how to ask for less."""

def set_memory_budget(bytes: int) -> int:
    """Sets the memory budget (bytes, >= 0) for every later call in the process; returns
    the previous one. ``set_memory_budget(DEFAULT_MEMORY_BUDGET)`` restores the default.
    Raise it on a machine that has the memory; lower it to keep a host application safe."""

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
    """The minimal screw carrying pose ``a`` (4, 4) to pose ``b`` (4, 4).

    A relative rotation within round-off of the identity (``|q.xyz| <= 16 eps``, a turn
    below 7e-15 rad) is a pure translation: axis along it, slide its length, angle 0.
    Errors name the pose: ``"screw: b: not rigid: ..."``.
    """

@overload
def interpolate(a: ArrayLike, b: ArrayLike, t: float) -> FloatArray: ...
@overload
def interpolate(a: ArrayLike, b: ArrayLike, t: ArrayLike) -> FloatArray: ...
def interpolate(a: ArrayLike, b: ArrayLike, t: float | ArrayLike) -> FloatArray:
    """``s(a, t, b)``: the pose a fraction ``t`` along the screw from ``a`` to ``b``.

    ``t = 0`` gives ``a``, ``t = 1`` gives ``b``, other values move along or past the screw,
    within +-1e12 (beyond, ``t**2`` times a coordinate could overflow).
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

    ``key_times`` must be strictly increasing, within +-1e300 and at least 1e-300 apart;
    ``times`` within +-1e300. ``closed`` makes a cycle of length
    ``period`` (default: closed after the mean key spacing). ``timing="smooth"`` is the
    monotone C1 map from time to the motion parameter, ``"linear"`` maps each key span
    linearly. Open motions hold their end poses outside the keys' range.
    """

def sample_channels(
    poses: ArrayLike,
    key_times: ArrayLike,
    times: ArrayLike,
    mode: RotationModeName,
    previous: ArrayLike | None = None,
    scheme: SchemeName = "jarek",
    levels: int = 4,
    closed: bool = False,
    period: float | None = None,
    timing: TimingName = "smooth",
) -> tuple[FloatArray, FloatArray]:
    """``sample`` as Blender channels: locations (len(times), 3) and the rotation channels
    ``rotation_channels(sample(...), mode, previous)``, without the (len(times), 4, 4)
    matrices in between (what a bake writes)."""

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
    previous one (no jump above 180 degrees). ``previous`` continues from earlier values;
    its angles (Euler, the axis-angle angle) within ``+-MAX_PREVIOUS_ANGLE`` (1e9), else
    ``ValueError``. At most ``MAX_ROTATIONS`` rotations per call.
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
        constrained: the keys held exactly: None (all), a boolean mask (N,) or key indices
            (integers, at most max(4 N, 64) of them; TypeError for anything else).
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

MAX_STEPS: int
"""The largest accepted number of sweep steps per screw (4096)."""

DEFAULT_SWEEP_TOLERANCE: float
"""The default tolerance of ``sweep``, as a fraction of the body's bounding radius (0.002)."""

IntArray = npt.NDArray[np.int64]

class SweepInfo(TypedDict):
    tolerance: float
    error_bound: float
    max_steps: int
    generator_segments: int

@overload
def sweep(
    vertices: ArrayLike,
    triangles: ArrayLike,
    poses: ArrayLike,
    steps: int = 1,
    caps: bool = True,
    tolerance: float | None = None,
    info: Literal[False] = False,
) -> tuple[FloatArray, IntArray]: ...
@overload
def sweep(
    vertices: ArrayLike,
    triangles: ArrayLike,
    poses: ArrayLike,
    steps: int = 1,
    caps: bool = True,
    tolerance: float | None = None,
    *,
    info: Literal[True],
) -> tuple[FloatArray, IntArray, SweepInfo]:
    """The region swept by a triangle mesh moving through ``poses``, as one triangle mesh.

    ``vertices`` (V, 3) and ``triangles`` (T, 3) are the body in its local frame; ``poses``
    (N >= 2, 4, 4) its world poses, one screw per span (Rossignac-Kim, "Swept volumes").
    Each screw's generator (silhouette edge segments and characteristic segments inside
    faces, computed in the body frame) is swept in quads; ``caps`` adds the body at the first
    and the last pose; at interior poses the faces where the motion turns back are added. The
    result is a superset of the swept region's boundary whose excess lies inside the region:
    its depth image from outside equals that of the union of the body's instances.

    Accuracy: each screw takes the fewest steps (at least ``steps``) that keep every swept
    triangle within ``tolerance`` (a length, the body's units) of the exact surface its
    generator sweeps: the chord sagitta ``rho (1 - cos(theta / 2k))`` (``rho`` the farthest
    generator point from the screw's axis, ``theta`` its angle, ``k`` steps) and the quads'
    twist ``sin(theta / 2k) l / (2 n)`` (a segment of length ``l`` across the axis cut into
    ``n`` pieces), each held to half the tolerance. ``tolerance=None``: ``DEFAULT_SWEEP_TOLERANCE``
    (0.2 %) of the body's bounding radius (half its bounding box's diagonal);
    ``tolerance=0``: no tolerance, exactly ``steps`` per screw.

    Returns ``(vertices (V', 3) float64, triangles (T', 3) int64)`` in world coordinates,
    triangles counter-clockwise seen from outside, none degenerate; with ``info=True`` also a
    dict: ``tolerance`` (asked for; 0 without), ``error_bound`` (the bound met: at most
    ``tolerance`` unless ``MAX_STEPS`` capped a screw), ``max_steps``, ``generator_segments``.

    Raises ``ValueError`` for an empty mesh, a NaN or infinite vertex or one beyond +-1e75, a
    triangle with an index out of range or zero area (naming the triangle), a fractional
    index (``2.7``: float arrays are accepted only with whole numbers), fewer than 2 poses, a
    non-rigid pose (naming it), ``steps`` outside ``1..=MAX_STEPS``, a negative or non-finite
    ``tolerance``, or a swept mesh over the memory budget (checked before each screw's quads
    are added: 48 bytes per vertex, 36 per triangle).
    """

# --- Feature-point motion design (Hofer-Pottmann-Ravani), issue 5 -------------------------

CurveSchemeName = Literal["variational", "four_point", "bspline", "jarek"]
ParametrizationName = Literal["uniform", "centripetal"]

def register_points(src: ArrayLike, dst: ArrayLike, weights: ArrayLike | None = None) -> FloatArray:
    """The rigid pose (4, 4) minimising ``sum_k w_k |pose(src_k) - dst_k|^2`` (Horn's method).

    ``src``, ``dst``: (K, 3) corresponding points, K >= 3; ``weights``: (K,) >= 0, default 1.
    The rotation is the eigenvector of the largest eigenvalue of Horn's symmetric 4x4
    matrix; when that eigenvalue is repeated (collinear points, or a target too distorted to
    have a unique best fit) ValueError is raised instead of an arbitrary rotation.
    """

def inertia_points(points: ArrayLike) -> FloatArray:
    """The six inertia points (6, 3) of a cloud ``points`` (K, 3): barycentre
    ``+- sqrt(lambda_j / 2) e_j`` along the principal axes of its inertia tensor.

    They share the cloud's barycentre and inertia tensor, so they stand in for a whole mesh
    as ``feature_points``. Raises ValueError for fewer than 3 or collinear points.
    """

def feature_motion(
    poses: ArrayLike,
    scheme: CurveSchemeName = "variational",
    levels: int = 5,
    closed: bool = False,
    feature_points: ArrayLike | None = None,
    parametrization: ParametrizationName = "uniform",
    stiffness: float | ArrayLike | None = None,
    inserted_stiffness: float | None = None,
) -> FloatArray:
    """Feature-point motion design (Hofer-Pottmann-Ravani) of the keys ``poses`` (N, 4, 4).

    The curve ``scheme`` runs on the homologous positions of ``feature_points`` (K, 3, in
    the body frame; default the six unit points +-x, +-y, +-z, whose isotropic inertia makes
    the result independent of how the local axes are turned), then the rigid body is
    registered to the distorted points at every output pose. Returns (N * 2**levels, 4, 4)
    closed, ((N - 1) * 2**levels + 1, 4, 4) open; pose ``i * 2**levels`` belongs to key i.
    Rigid (unit quaternions) and independent of the world frame.

    ``"variational"`` is Kobbelt's variational subdivision (C2), the only scheme that takes
    ``parametrization`` (``"centripetal"``: spacing sqrt of the feature points' distance
    between keys) and ``stiffness``: the spring lambda per key, a float for all keys or an
    (N,) array; ``inf`` (or ``None``) hits that key exactly, a finite lambda >= 0 lets the
    motion pass near it (smaller = smoother; an open motion needs two keys and a closed one
    one key with lambda > 0). ``inserted_stiffness`` is lambda for the poses inserted at
    earlier levels (``None`` = ``inf``: kept once inserted). ``"four_point"`` interpolates (C1),
    ``"bspline"`` and ``"jarek"`` approximate (C2).
    Raises ValueError naming the bad pose, key or sample and the reason.
    """

def sample_feature(
    poses: ArrayLike,
    key_times: ArrayLike,
    times: ArrayLike,
    scheme: CurveSchemeName = "variational",
    levels: int = 5,
    closed: bool = False,
    feature_points: ArrayLike | None = None,
    parametrization: ParametrizationName = "uniform",
    stiffness: float | ArrayLike | None = None,
    inserted_stiffness: float | None = None,
    period: float | None = None,
    timing: TimingName = "smooth",
) -> FloatArray:
    """``feature_motion`` as a function of time, at ``times``: (len(times), 4, 4).

    Key i sits at ``key_times[i]`` (finite, strictly increasing); ``period`` and ``timing``
    as in ``sample``; between dense poses the motion is the screw joining them.
    """

# --- Blender's F-curve evaluation, issue 17 --------------------------------------------------

InterpolationName = Literal[
    "CONSTANT", "LINEAR", "BEZIER", "SINE", "QUAD", "CUBIC", "QUART", "QUINT", "EXPO", "CIRC",
    "BACK", "BOUNCE", "ELASTIC",
]
EasingName = Literal["AUTO", "EASE_IN", "EASE_OUT", "EASE_IN_OUT"]
ExtrapolationName = Literal["CONSTANT", "LINEAR"]
CycleModeName = Literal["NONE", "REPEAT", "REPEAT_OFFSET", "MIRROR"]

INTERPOLATIONS: tuple[InterpolationName, ...]
"""Blender's ``Keyframe.interpolation`` identifiers; a key's code is its index here."""
EASINGS: tuple[EasingName, ...]
"""Blender's ``Keyframe.easing`` identifiers; a key's code is its index here."""
EXTRAPOLATIONS: tuple[ExtrapolationName, ...]
"""Blender's ``FCurve.extrapolation`` identifiers."""
CYCLE_MODES: tuple[CycleModeName, ...]
"""Blender's ``FModifierCycles.mode_before`` / ``mode_after`` identifiers."""
MAX_FCURVE_KEYS: int
"""The most keys one ``evaluate_fcurves`` call accepts (2**26)."""
MAX_FCURVE_VALUES: int
"""The most values (curves x times) one ``evaluate_fcurves`` call returns (2**27)."""

def evaluate_fcurves(
    times: ArrayLike,
    *,
    offsets: ArrayLike,
    co: ArrayLike,
    handle_left: ArrayLike,
    handle_right: ArrayLike,
    interpolation: ArrayLike,
    easing: ArrayLike,
    extrapolation: ExtrapolationName | Sequence[ExtrapolationName] | None = None,
    back: ArrayLike | None = None,
    amplitude: ArrayLike | None = None,
    period: ArrayLike | None = None,
    cycles: Sequence[Mapping[str, Any] | None] | None = None,
) -> FloatArray:
    """C keyframed F-curves at T ``times`` as Blender evaluates them: (C, T) float64.

    Each value is exactly Blender's ``FCurve.evaluate(time)`` (4.2 and later): every step
    is done in float32 (and float64 where Blender uses double) in Blender's order, so the
    result is Blender's float32 value, widened. Times may be in any order and are rounded to
    float32, as Blender's frame is.

    Keys are packed one curve after the other (K keys in all); curve ``c`` owns keys
    ``offsets[c]:offsets[c + 1]`` (``offsets`` (C + 1,), from 0 to K, non-decreasing; every
    curve needs a key):

    - ``co``, ``handle_left``, ``handle_right``: (K, 2) ``(frame, value)``; frames of a
      curve's keys must not decrease;
    - ``interpolation``: (K,) integer codes, indices into ``INTERPOLATIONS`` (the segment
      from each key to the next); ``easing``: (K,) indices into ``EASINGS`` (AUTO is
      ease-out for BACK, BOUNCE, ELASTIC and ease-in for the others, as in Blender);
    - ``back``, ``amplitude``, ``period``: (K,), default Blender's 1.70158, 0.8, 4.1.

    ``extrapolation``: one name of ``EXTRAPOLATIONS`` for every curve or one per curve
    (default ``"CONSTANT"``). ``cycles``: None, or C entries, each None (no modifier) or a
    dict of the Cycles modifier's RNA properties: ``mode_before``, ``mode_after`` (names
    of ``CYCLE_MODES``, default ``"REPEAT"``), ``cycles_before``, ``cycles_after`` (0:
    unlimited), ``use_restricted_range`` with ``frame_start``, ``frame_end``, ``blend_in``,
    ``blend_out``, ``use_influence`` with ``influence``. Other modifiers, drivers and muted
    curves are not evaluated (the add-on's ``curves.py`` refuses them).

    The GIL is released. Raises ValueError naming the argument, curve and key: wrong shapes
    or lengths, bad offsets, codes or names, integer codes or offsets that are not whole
    numbers (``2.7``, NaN), numbers not finite in float32, keys out of time order, a curve
    without keys, more than ``MAX_FCURVE_KEYS`` keys or ``MAX_FCURVE_VALUES`` values, more
    memory than the budget (the prepared curves, the values and the copies of the input,
    checked before anything is copied), or a value that is not finite (where Blender's
    would be NaN or infinite); TypeError for complex, string or object arrays.
    """

# --- what the animator meant between the keys (polyscrew::intent) ----------------------------

WIND_LIMIT: float
"""A span whose rotation channels turn further than this (radians, 150 degrees) is a spin."""
WIND_STEP: float
"""The most a screw span of a spin turns once poses are added (radians, 45 degrees); the
neighbouring spans of a spin turning more than this are cut too."""
SPAN_SAMPLES: int
"""Samples of the playback per key span in ``analyse_spans`` (8; more for spinning spans)."""
MAX_SPAN_SAMPLES: int
"""At most this many samples per span in ``analyse_spans`` (4096; one per 10 degrees)."""
MAX_ANALYSIS_SAMPLES: int
"""At most this many samples in one ``analyse_spans`` call, all spans together (2,097,152):
its work is not bounded by memory, this bounds its time (about 2 s of one core at the
limit: 512 spans of 4,096 samples, each a spin)."""
HOLD_TOLERANCE: float
"""A channel moving less than this times (its size + 1) over a span is still (1e-6)."""
PACE_SAMPLES: int
"""Steps per span along which ``keys_parameters`` measures travel (16)."""
WRAP_MARGIN: float
"""An Euler span is a wrap when an equivalent triple of its second key is at least this much
closer (radians, 45 degrees, sum over the three angles) to its first key (``analyse_turns``)."""
RANGE_TOLERANCE: float
"""How far beyond -pi..pi an Euler key may lie and still be inside the range (1e-6 radians)."""

class Playback:
    """An owner's transform channels as Blender plays them.

    C keyframed curves, packed as ``evaluate_fcurves`` takes them (the same keyword
    arguments, evaluated exactly as it does), curve ``c`` driving ``channels[c]``, a
    ``(property, index)`` pair: ``"location"``, ``"scale"`` or the rotation property of
    ``mode`` (``"rotation_euler"``, ``"rotation_quaternion"``, ``"rotation_axis_angle"``).
    ``unkeyed``: the owner's own values of all channels, location (3), rotation (3 Euler
    angles, or 4: quaternion w, x, y, z / axis-angle angle, x, y, z) and scale (3), used where
    no curve drives a channel. ``located=False``: location is ignored (0), as Blender does
    for a bone connected to its parent. Raises ValueError for bad curves (as
    ``evaluate_fcurves``), an unknown property or mode, an index out of range, more channels
    than the owner has (``6 + width``), two curves on one channel, or ``unkeyed`` of the
    wrong length or not finite.
    """

    def __init__(
        self,
        *,
        channels: Sequence[tuple[str, int]],
        unkeyed: ArrayLike,
        mode: RotationModeName,
        located: bool = True,
        offsets: ArrayLike,
        co: ArrayLike,
        handle_left: ArrayLike,
        handle_right: ArrayLike,
        interpolation: ArrayLike,
        easing: ArrayLike,
        extrapolation: ExtrapolationName | Sequence[ExtrapolationName] | None = None,
        back: ArrayLike | None = None,
        amplitude: ArrayLike | None = None,
        period: ArrayLike | None = None,
        cycles: Sequence[Mapping[str, Any] | None] | None = None,
    ) -> None: ...
    def channels(self, frames: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]:
        """Location (T, 3), rotation (T, 3 or 4) and scale (T, 3) at ``frames`` (T,), any
        order, subframes allowed: keyed channels exactly Blender's float32 values, the
        others ``unkeyed``. GIL released."""
    def __len__(self) -> int:
        """The number of curves."""
    def departure(
        self, frames: ArrayLike, location: ArrayLike, rotation: ArrayLike
    ) -> tuple[FloatArray, FloatArray]:
        """How far a result's ``location`` (T, 3) and ``rotation`` (T, 3 or 4, in the owner's
        mode) at ``frames`` (T,) are from this playback: per frame the distance between the
        locations (0 when ``located`` is false) and the angle (radians, in [0, pi]) between
        the rotations, both (T,). GIL released. Raises ValueError for shapes that do not
        match or values that are not finite."""

def analyse_turns(
    playback: Playback, frames: ArrayLike, turns: Literal["AUTO", "BLENDER", "SHORTEST"] = "AUTO"
) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_], FloatArray, FloatArray, npt.NDArray[np.bool_]]:
    """``analyse_spans`` and, per span, ``flips`` (K - 1,): not held, and its key values are
    an Euler wrap (every value of both keys inside -pi..pi, and an equivalent triple of the
    second key, 2 pi added or the twin triple, at least ``WRAP_MARGIN`` closer to the first,
    sum of absolute differences) or a quaternion sign flip (q0 . q1 < 0): what Blender plays
    the long way round although the animator did not type a spin.

    ``turns`` picks the spans whose playback is followed (poses added, the rule of
    ``analyse_spans``): "AUTO", Euler and axis-angle spans that are not flips (typed spins
    turn as Blender plays them; flips and quaternion keys take the short screw); "BLENDER",
    every span (flips and quaternion sign flips too, as Blender plays them); "SHORTEST",
    none (the short screw between every two key poses; nothing inserted).
    """

def analyse_spans(
    playback: Playback, frames: ArrayLike, turns: Literal["AUTO", "BLENDER", "SHORTEST"] = "AUTO"
) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_], FloatArray, FloatArray]:
    """What each key span of ``frames`` (K,) (strictly increasing, K >= 2) does along the
    playback: ``(held, pops, turn, inserted)``.

    Each span is sampled at ``SPAN_SAMPLES`` frames from its start (included) to its end
    (excluded), more where the rotation channels change a lot between its keys (one per 10
    degrees, at most ``MAX_SPAN_SAMPLES``). ``held`` (K - 1,): no channel of any sample moves
    from the span's start by more than ``HOLD_TOLERANCE`` (relative to the value + 1);
    ``pops`` (K - 1,): held, and a channel differs between its keys; ``turn`` (K - 1,):
    radians the rotation turns through, the sum of the angles between consecutive samples
    and the span's end. ``inserted`` (M,), ascending: the frames where poses of the playback
    must be added: a span that ``turns`` follows (``analyse_turns``; by default Euler and
    axis-angle spans that are not Euler wraps) turning more than ``WIND_LIMIT`` (not held),
    and the runs of its followed neighbours turning more than ``WIND_STEP``, get
    ``ceil(turn / WIND_STEP) - 1`` frames where the accumulated turn
    reaches equal fractions of the span's (linear between samples). GIL released. Raises
    ValueError for fewer than two frames, frames that do not increase, or spans that would
    take more than ``MAX_ANALYSIS_SAMPLES`` samples in all (refused before any is taken).
    """

def keys_parameters(
    key_frames: ArrayLike,
    frames: ArrayLike,
    *,
    size: float,
    closed: bool = False,
    period: float | None = None,
    playback: Playback | None = None,
    poses: ArrayLike | None = None,
    scheme: SchemeName = "four_point",
    levels: int = 4,
    smooth: ArrayLike | None = None,
) -> FloatArray:
    """Timing "Keys": the motion parameter (key i at i) of each of ``frames`` (T,).

    Within span s (keys s, s + 1; for a ``closed`` cycle of ``period`` frames the last span
    returns to the first key), a frame at the fraction ``tau`` of the span's time gets the
    parameter at which the smoothed motion has travelled the same fraction of the span as
    the ``playback`` has at that frame (the fraction of time without ``playback``, or where
    it does not move). Travel is ``sqrt(|dt|^2 + size^2 / 3 |dR|_F^2)`` (the root mean square
    displacement of six points at +-``size``), summed over ``PACE_SAMPLES`` steps per span
    and the output frames inside it; the smoothed motion's travel is measured at
    ``pace_parameters(spans)`` and inverted linearly. Frames at keys and outside the spans
    keep ``s + tau``.

    The smoothed motion: the screw motion of the key ``poses`` (K, 4, 4) by ``scheme`` and
    ``levels`` (keys at parameters 0..K-1, linear timing), or ``smooth``, its poses at
    ``pace_parameters(spans)`` computed by the caller (feature points). GIL released.
    Raises ValueError naming the argument: key frames that do not increase, a period not
    beyond the keys, a size that is not positive, frames not finite, neither or both of
    ``poses`` and ``smooth``, or ``smooth`` of the wrong length.
    """

def pace_parameters(spans: int) -> FloatArray:
    """``s + j / PACE_SAMPLES`` for j in 0..PACE_SAMPLES of each span s in 0..spans, span
    after span: where ``keys_parameters`` measures the smoothed motion."""

def rotation_matrices(values: ArrayLike, mode: RotationModeName) -> FloatArray:
    """(N, 3, 3) rotation matrices of (N, k) rotation channel values in Blender's ``mode``:
    quaternions (w, x, y, z) normalised (zero: identity); axis-angle (angle, x, y, z) about
    the normalised axis (zero axis: identity); Euler (x, y, z) radians, ``"XYZ"`` meaning X
    applied first (``R = Rz Ry Rx``). GIL released. Raises ValueError for a wrong shape or a
    row that is not finite."""
# --- Remove Noise (coordinate-free smoothing of captured motion), issue 19 -----------------

class Denoised:
    """The result of ``denoise``: the smooth poses and what was chosen on the way.

    For one clip the strengths, noises and iterations are floats (ints) and the pivot is
    (3,); for a batch of B clips they are (B,) arrays, the pivot (B, 3), the kinks a list.
    """

    @property
    def poses(self) -> FloatArray:
        """The smooth poses, in the input's shape ((N, 4, 4) or (B, N, 4, 4)), rigid;
        held poses exactly as given."""
    @property
    def rotation_strength(self) -> float | FloatArray:
        """The rotation's strength tau, a time in the units of ``times`` (chosen or given)."""
    @property
    def translation_strength(self) -> float | FloatArray:
        """The translation's strength tau."""
    @property
    def rotation_noise(self) -> float | FloatArray:
        """Estimated rotation noise of the input: standard deviation per axis, radians."""
    @property
    def translation_noise(self) -> float | FloatArray:
        """Estimated position noise of the pivot, per axis, in the units of the poses."""
    @property
    def pivot(self) -> FloatArray:
        """The body point (body coordinates) whose world path was smoothed: (3,) or (B, 3)."""
    @property
    def rotation_kinks(self) -> npt.NDArray[np.int64] | list[npt.NDArray[np.int64]]:
        """Indices of the poses where an abrupt turn of the rotation was let through."""
    @property
    def translation_kinks(self) -> npt.NDArray[np.int64] | list[npt.NDArray[np.int64]]:
        """Indices of the poses where an abrupt turn of the path was let through."""
    @property
    def pops(self) -> npt.NDArray[np.int64] | list[npt.NDArray[np.int64]]:
        """Indices of the first pose after each pop (a jump far faster than the motion
        around it) the clip was cut at; the pieces between are smoothed apart, each with its
        own strengths (those reported are the longest piece's), and the jump is kept."""
    @property
    def iterations(self) -> int | npt.NDArray[np.int64]:
        """Gauss-Newton iterations of the rotation solve."""
    @property
    def converged(self) -> bool:
        """Whether every rotation solve converged (last step below 1e-9 rad)."""

def denoise(
    poses: ArrayLike,
    times: ArrayLike,
    strength: float | tuple[float, float] | None = None,
    held: ArrayLike | None = None,
    order: int = 3,
    kinks: bool = True,
    threads: int = 0,
) -> Denoised:
    """Remove noise from a captured rigid motion (camera solve, motion capture, baked
    simulation): the smooth motion nearest to ``poses`` (N, 4, 4) at ``times`` (N,), or to
    each of B clips (B, N, 4, 4) at the same times, in one call.

    Coordinate-free: ``denoise(G @ poses @ H)`` is ``G @ denoise(poses) @ H`` for rigid G, H,
    with the automatic strengths too; a screw motion (and any motion turning at constant
    angular velocity while one body point moves at constant velocity) comes back unchanged.
    The rotation is smoothed on the rotation group and the path of one body point (the
    ``pivot``, the point of least jitter) in space, each by a smoothing spline of ``order``
    3 (quintic: constant acceleration is free; 2: cubic) on the given, possibly uneven, times.

    ``strength``: None chooses the strengths from the data (generalised cross-validation,
    rotation and translation apart, reported back); a time tau (in the units of ``times``)
    or (rotation, translation) times: motion faster than about ``2 pi tau`` per cycle is
    removed, 0 leaves that part as is; any finite tau >= 0 is served, one above 100 median
    spacings of ``times`` acts as 100 spacings (the strength reported). The work is done in
    a normalised time: scaling ``times`` changes nothing but the strengths' unit. ``held``:
    boolean mask (N,) or (B, N); held poses are kept exactly (their matrices as given, read
    once) and the motion passes through them. ``kinks``: let abrupt turns (a prop stopping
    against a wall) through instead of rounding them, and cut the clip at pops (see
    ``Denoised.pops``). ``threads``: clips of a batch
    are spread over this many threads (0: all the machine has). A batch of no clips
    (0, N, 4, 4) is checked like any other and gives an empty result.

    Raises ValueError for a wrong shape, fewer than 4 poses, more than 1,000,000 poses per
    clip or 20,000,000 in all, a non-rigid or non-finite pose (naming the index, and the
    body of a batch), times that are not finite and increasing, a held mask of the wrong
    shape, an order other than 2 or 3, a negative or non-finite strength, and values so
    large that the computation overflows.
    """

# --- Key reduction (the fewest Bezier keys within a world-space tolerance), issue 26 -------

HandleTypeName = Literal["FREE", "ALIGNED", "VECTOR", "AUTO", "AUTO_CLAMPED"]

HANDLE_TYPES: tuple[HandleTypeName, ...]
"""Blender's ``Keyframe.handle_left_type`` / ``handle_right_type`` identifiers; a key's code
in ``reduce_keys``' ``"handle_type"`` is its index here."""

def reduce_keys(
    poses: ArrayLike,
    frames: ArrayLike,
    modes: RotationModeName | Sequence[RotationModeName],
    radius: float | ArrayLike,
    distance: float,
    angle: float,
    *,
    scales: ArrayLike | None = None,
    channels: ArrayLike | None = None,
    parents: ArrayLike | None = None,
    offsets: ArrayLike | None = None,
    constant: ArrayLike | None = None,
    cyclic: bool = False,
    per_channel: bool = False,
    start: ArrayLike | None = None,
    threads: int = 0,
    between: Literal["screw", "cubic", "linear"] = "screw",
) -> dict[str, Any]:
    """The fewest Bezier keys whose playback by Blender stays within a world-space tolerance
    of B owners' dense rigid motions.

    ``poses`` (B, N, 4, 4): each owner's rigid pose at each of the N >= 2 ``frames`` (strictly
    increasing, shared, subframes allowed), in the space its channels key (an object's parent
    space, a bone's ``matrix_basis``), scale separated. ``modes``: one Blender rotation mode
    for all owners or B of them ("QUATERNION", "AXIS_ANGLE", "XYZ", "XZY", "YXZ", "YZX",
    "ZXY", "ZYX"). ``radius``: float or (B,), the body's radius (>= 0). ``distance`` (> 0):
    no point of the body within ``radius`` of its origin moves further than this from the
    dense motion; ``angle`` (> 0, radians): no rotation differs more. The measure of a played
    pose against the dense one is ``|dt| + 2 radius sin(theta / 2)`` (+ ``radius |ds|`` with
    scale) and ``theta``.

    The dense motion is the poses at ``frames`` and the screw between two consecutive ones
    (across a ``constant`` span: the first pose until the next frame). The tolerance is
    checked at every frame and 3 subframes between two (1/4, 1/2, 3/4) through Blender's own
    F-curve evaluation of the float32 keys (``evaluate_fcurves``, bit-identical), quaternions
    normalised as Blender plays them.

    - ``scales``: None, or (B, N, 3) positive scales to reduce too (linear between frames).
    - ``channels``: None (location and rotation, and scale when ``scales`` is given) or (B, 3)
      bool: which of location / rotation / scale each owner keys; unkeyed groups get no
      curves and count as exact.
    - ``parents``: None, or (B,) int: each owner's parent's batch index (-1: none). The
      tolerance then holds in world space, ``world_i = world_parent @ offsets[i] @ poses[i]``
      (roots: ``offsets[i] @ poses[i]``): parents are reduced first and each child keys
      ``(world_parent_reduced @ offset)^-1 @ world_child_dense``, compensating its parents'
      errors. Scale is not propagated to children.
    - ``offsets``: None (identity) or (B, 4, 4) rigid constant offsets.
    - ``constant``: None, or (B, N-1) bool: span i -> i+1 is a step or hold (CONSTANT in the
      source); it stays a CONSTANT key, its end keyed.
    - ``cyclic``: the frames are one period of a cycle (first pose == last pose): the first
      and last keys sit at the first and last frame, with equal values on every channel that
      returns to its first value (a cycle that turns a whole turn keeps its offset).
    - ``per_channel``: each channel gets its own key frames (each reduced within a share of
      the tolerance, halved until the whole holds); default: an owner's channels share them.
    - ``start``: None or (B, 4): each owner's channel values at the first frame as the source
      had them (Euler: the first 3; axis-angle: angle, axis; quaternion: w, x, y, z for its
      sign); the first key takes the equivalent values nearest to them (a spin from 360 to 720
      degrees stays there). None: those nearest zero.
    - ``threads``: owners of one depth of the hierarchy spread over this many threads (0: all).
    - ``between``: the dense motion at the subframes. "screw" (default): the screw between
      two frames, what a source keyed on every frame with LINEAR keys plays (to first order).
      "cubic": the cubic through the two poses each side (fewer at the clip's ends and
      around CONSTANT spans) by Aitken-Neville's scheme with screws for straight lines,
      what a source keyed on every frame with Bezier keys plays (smooth: an ``nla.bake``, an
      imported capture); a smooth reduction can follow it much more closely than the
      screw's corners at every frame, so it needs fewer keys at tight tolerances. Both
      reproduce screw motions exactly and are coordinate-free. "linear": the owner's channels
      interpolated linearly between two frames, exactly what a source keyed on every frame
      with LINEAR keys plays (a Smooth Motion bake); not coordinate-free (Euler channels are
      not).

    Keys sit on the dense values (first and last frame always keyed); rotation channels are
    unwrapped along the dense samples (quaternion signs continuous, Euler triples compatible,
    axis-angle unwrapped), so spins keep turning and no key wraps. Each span between keys is
    a Bezier with its handles at 1/3 and 2/3 of the span in time (a cubic in time), the two
    inner handle values fitted by least squares; handles are FREE (C0 at keys: editing a
    key keeps its neighbours' segments as they are). Where even a one-frame span cannot meet
    the tolerance, keys go at the subframes. Where float32 storage alone cannot (a tolerance
    below float32's resolution at the motion's scale), the errors reported say so.

    Returns a dict of the curves packed as ``evaluate_fcurves`` takes them, so
    ``evaluate_fcurves(times, offsets=r["offsets"], co=r["co"], handle_left=r["handle_left"],
    handle_right=r["handle_right"], interpolation=r["interpolation"], easing=r["easing"])``
    plays them: ``"owner"`` (C,) int64, ``"path"`` list of C str ("location",
    "rotation_quaternion", "rotation_euler", "rotation_axis_angle", "scale"), ``"index"``
    (C,) int64, ``"offsets"`` (C+1,) int64, ``"co"``, ``"handle_left"``, ``"handle_right"``
    (K, 2) float64 (frame, value), ``"interpolation"``, ``"easing"``, ``"handle_type"`` (K,)
    int64 codes into ``INTERPOLATIONS``, ``EASINGS``, ``HANDLE_TYPES`` (BEZIER or CONSTANT,
    AUTO, FREE); ``"keys"`` (B,) int64 distinct key frames per owner; ``"distance_error"``,
    ``"angle_error"`` (B,) float64, the largest errors measured at the checked samples
    (world space with ``parents``).

    The GIL is released. Raises ValueError / TypeError naming ``reduce_keys``, the argument
    and the owner: wrong shapes, non-rigid or non-finite poses or offsets, frames not finite
    and strictly increasing, fewer than 2 frames, tolerances not positive and finite, unknown
    modes, negative radii, non-positive scales, scale keyed without ``scales``, parents out
    of range or forming a cycle, more than 1,000,000 frames or 20,000,000 poses, more memory
    than the budget (checked before anything is copied).
    """
