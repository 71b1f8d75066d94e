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
    inserted_stiffness: float = float("inf"),
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
    earlier levels (default ``inf``: kept once inserted). ``"four_point"`` interpolates (C1),
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
    inserted_stiffness: float = float("inf"),
    period: float | None = None,
    timing: TimingName = "smooth",
) -> FloatArray:
    """``feature_motion`` as a function of time, at ``times``: (len(times), 4, 4).

    Key i sits at ``key_times[i]`` (finite, strictly increasing); ``period`` and ``timing``
    as in ``sample``; between dense poses the motion is the screw joining them.
    """
