# SPDX-License-Identifier: GPL-3.0-or-later
"""The live preview's geometry without Blender: where an owner's own-space matrices land in the
world (:class:`Space`, measured from probes of Blender's bone transform), the shapes drawn per
instance (mesh, box, axes, bone) and their instanced vertex and index arrays.

The Blender layer (`blender/preview.py`) samples the motion and reads the meshes; the drawing
(`ops/preview_draw.py`) uploads these arrays.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .feature_points import BONE_BOX_WIDTH


def _times(start: float, end: float, count: int, closed: bool) -> np.ndarray:
    """`count` evenly spaced times from `start` to `end`; a cycle leaves out `end` (= `start`)."""
    if closed:
        return start + (end - start) * np.arange(count, dtype=np.float64) / count
    return np.linspace(start, end, count)


def with_scale(poses: np.ndarray, scales: np.ndarray) -> np.ndarray:
    """Object matrices `pose @ diag(scale)` from rigid poses (N, 4, 4) and scales (N, 3)."""
    out = poses.copy()
    out[:, :3, :3] *= scales[:, None, :]
    return out


@dataclass(frozen=True)
class Space:
    """Where an owner's own-space matrices land in the world at the current frame.

    For an object (and a bone that inherits its parent's whole transform, Blender's default)
    this is one matrix: `world = P @ M`. A bone with Inherit Rotation off, Local Location off
    or another Inherit Scale mode places its rotation and scale through one matrix and its
    location through another (Blender's `BKE_bone_parent_transform_apply`); Inherit Scale
    "Aligned" also scales the bone's own axes by its parent's scale afterwards. In general:

        world(M)[:3, :3] = rotation @ (M[:3, :3] * ratio)      (ratio: elementwise, d_j / d_i)
        world(M)[:3, 3]  = location[:3, :3] @ M[:3, 3] + location[:3, 3]

    where `rotation @ ratio-scaling` is `R_parent @ M3 @ diag(d)` written so that only the
    ratios of the post-scale `d` are needed.
    """

    #: The 3x3 matrix carrying the owner's rotation and scale.
    rotation: np.ndarray
    #: The 4x4 affine matrix carrying the owner's location.
    location: np.ndarray
    #: (3, 3) ratios d_j / d_i of the post-scale (all ones without one).
    ratio: np.ndarray

    @classmethod
    def of_matrix(cls, matrix) -> Space:
        """The space of one matrix: `world = matrix @ M`."""
        m = np.asarray(matrix, dtype=np.float64)
        return cls(m[:3, :3].copy(), m.copy(), np.ones((3, 3)))

    @property
    def matrix(self) -> np.ndarray | None:
        """The one 4x4 matrix this space is (`world = matrix @ M`), or None when location and
        rotation go through different matrices (the batches are then mapped on the CPU)."""
        if np.array_equal(self.ratio, np.ones((3, 3))) and np.array_equal(self.rotation, self.location[:3, :3]):
            return self.location
        return None

    def apply(self, matrices: np.ndarray) -> np.ndarray:
        """Own-space matrices (N, 4, 4) in the world."""
        out = np.zeros_like(matrices, dtype=np.float64)
        out[:, :3, :3] = self.rotation @ (matrices[:, :3, :3] * self.ratio)
        out[:, :3, 3] = matrices[:, :3, 3] @ self.location[:3, :3].T + self.location[:3, 3]
        out[:, 3, 3] = 1.0
        return out

    def apply_points(self, points: np.ndarray) -> np.ndarray:
        """Own-space origins (N, 3) in the world."""
        return points @ self.location[:3, :3].T + self.location[:3, 3]

    def key(self) -> bytes:
        """The bytes that identify this space (for caching what is drawn in it)."""
        return self.rotation.tobytes() + self.location.tobytes() + self.ratio.tobytes()


#: A bone's parent space is measured by mapping these matrices through Blender's own bone
#: transform (`Bone.convert_local_to_pose`): the identity, a unit translation along each axis
#: (the location matrix), and a quarter-turn cycling the axes (the post-scale ratios).
CYCLE = np.array([[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]])


def space_from_probes(world: np.ndarray, identity: np.ndarray, moved: np.ndarray, cycled: np.ndarray) -> Space:
    """The :class:`Space` of a bone from Blender's bone transform `f` (local to armature
    space) of the probes: `identity = f(I)`, `moved[i] = f(T(e_i))`, `cycled = f(CYCLE)`, and
    the armature's world matrix `world`.

    `f(M) = [A M3 D | L t + l]`: f(I) gives `B = A D` and `l`; f(T(e_i)) the columns of L;
    `B^-1 f(CYCLE)3 = D^-1 C D` holds the ratios of D's entries (where B is singular, a
    zero-scaled parent, the ratios are taken as one).
    """
    b = identity[:3, :3]
    origin = identity[:3, 3]
    location = np.eye(4)
    location[:3, :3] = np.stack([m[:3, 3] - origin for m in moved], axis=1)
    location[:3, 3] = origin
    ratio = np.ones((3, 3))
    if abs(np.linalg.det(b)) > 1e-12:
        q = np.linalg.solve(b, cycled[:3, :3])  # D^-1 C D: entries (0,2), (1,0), (2,1) are d2/d0, d0/d1, d1/d2
        d = np.array([1.0, 1.0 / q[1, 0], q[0, 2]]) if q[1, 0] != 0.0 else np.ones(3)
        ratio = d[None, :] / d[:, None]
        if np.allclose(ratio, 1.0, rtol=0.0, atol=1e-6):
            ratio = np.ones((3, 3))
    w3 = world[:3, :3]
    if np.allclose(location[:3, :3], b, rtol=0.0, atol=1e-7 * (1.0 + np.abs(b).max())):
        location[:3, :3] = b  # one matrix (float32 probes agree to rounding)
    return Space(w3 @ b, world @ location, ratio)


# Geometry drawn per instance --------------------------------------------------------------

#: Edges of a box whose corners are numbered like `Object.bound_box` (bit 2: x, bit 1: y, bit 0: z).
BOX_EDGES = np.array(
    [(0, 1), (1, 2), (2, 3), (3, 0), (4, 5), (5, 6), (6, 7), (7, 4), (0, 4), (1, 5), (2, 6), (3, 7)],
    dtype=np.int32,
)


#: Triangles of the same box.
BOX_TRIS = np.array(
    [
        (0, 1, 2), (0, 2, 3), (4, 6, 5), (4, 7, 6), (0, 4, 5), (0, 5, 1),
        (1, 5, 6), (1, 6, 2), (2, 6, 7), (2, 7, 3), (3, 7, 4), (3, 4, 0),
    ],
    dtype=np.int32,
)


@dataclass
class Geometry:
    """What one instance looks like, in the object's local coordinates."""

    points: np.ndarray  # (V, 3) float32
    edges: np.ndarray  # (E, 2) int32
    tris: np.ndarray  # (T, 3) int32
    #: "MESH", "BOX" (bounding box of a heavy mesh or of a non-mesh object), "AXES" or
    #: "BONE" (:func:`bone_geometry`).
    kind: str


def box_corners(low: np.ndarray, high: np.ndarray) -> np.ndarray:
    """The 8 corners of the box [low, high], numbered like `Object.bound_box`."""
    return np.array(
        [[(low, high)[(i >> 2) & 1][0], (low, high)[(i >> 1) & 1][1], (low, high)[i & 1][2]] for i in (0, 1, 3, 2, 4, 5, 7, 6)],
        dtype=np.float32,
    )


#: A bone's waist (where Blender's octahedral bone is widest) and half its width there, per
#: unit of bone length: the half width of the Feature Points method's bone box.
BONE_WAIST = BONE_BOX_WIDTH


#: Edges and triangles of the octahedral bone of :func:`bone_geometry`: head 0, tail 1, the
#: waist square 2 to 5.
BONE_EDGES = np.array(
    [(0, 2), (0, 3), (0, 4), (0, 5), (1, 2), (1, 3), (1, 4), (1, 5), (2, 3), (3, 4), (4, 5), (5, 2)], dtype=np.int32
)


BONE_TRIS = np.array(
    [(0, 3, 2), (0, 4, 3), (0, 5, 4), (0, 2, 5), (1, 2, 3), (1, 3, 4), (1, 4, 5), (1, 5, 2)], dtype=np.int32
)


def bone_geometry(length: float, box: bool = False) -> Geometry:
    """The instance shape of a bone of `length` in its own space (head at the origin, the
    bone along +Y, as `PoseBone.matrix` places it): Blender's octahedral bone (head, tail and
    a square waist at a tenth of the length, so its roll shows), or with `box` the box around
    it that the Feature Points method uses (:func:`feature.bone_points`)."""
    w = BONE_WAIST * length
    if box:
        corners = box_corners(np.array([-w, 0.0, -w]), np.array([w, length, w]))
        return Geometry(corners, BOX_EDGES, BOX_TRIS, "BOX")
    points = np.array(
        [(0.0, 0.0, 0.0), (0.0, length, 0.0), (w, w, 0.0), (0.0, w, w), (-w, w, 0.0), (0.0, w, -w)], dtype=np.float32
    )
    return Geometry(points, BONE_EDGES, BONE_TRIS, "BONE")


def instance_vertices(points: np.ndarray, matrices: np.ndarray) -> np.ndarray:
    """`points` (V, 3) placed by each of `matrices` (N, 4, 4): (N * V, 3) float32."""
    m = np.asarray(matrices, dtype=np.float32)
    out = np.matmul(np.asarray(points, dtype=np.float32)[None], m[:, :3, :3].transpose(0, 2, 1))
    out += m[:, None, :3, 3]
    return out.reshape(-1, 3)


def instance_indices(elements: np.ndarray, vertex_count: int, instances: int) -> np.ndarray:
    """Index arrays `elements` (E, k) repeated for `instances` copies of `vertex_count` vertices."""
    offsets = (np.arange(instances, dtype=np.int32) * vertex_count)[:, None, None]
    return (elements[None, :, :] + offsets).reshape(-1, elements.shape[1]).astype(np.int32)
