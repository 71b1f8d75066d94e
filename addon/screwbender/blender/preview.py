# SPDX-License-Identifier: GPL-3.0-or-later
"""The live stroboscopic preview's data: what the overlay draws, computed without a GPU.

For each previewed owner (ScrewBender paper, section 5 and figure 13: the "3D rubber band"):
an object, or a keyed bone of a previewed armature (:func:`preview_owners`):

- N instances of the object (of the bone: its octahedral shape, :func:`bone_geometry`) at
  evenly spaced times over the motion's frame range,
- the trajectory of its origin (a bone's head) at M evenly spaced times,
- the key poses,
- optionally the raw polyscrew (0 levels, linear timing: one screw per key span).

The keys are read by :func:`keys.read` and the motion sampled by :func:`bake.sample_poses`,
the very functions Smooth Motion bakes with, in ONE `polyscrew.sample` call for instances and
trajectory together (plus one `sample_vectors` call when scale is keyed, plus one call for
the raw polyscrew when it is shown). :class:`PreviewCache` keeps the result per owner under
a hash of the owner's transform F-curves (raw key data: co, handles, interpolation, ...) and
the settings, and recomputes only when that hash changes. Nothing here writes Blender data.

All matrices are in the owner's own space (what `matrix_basis` means: an object's parent
space, a bone's rest pose under its parent bone); the draw code maps them to the world at
the current frame (:mod:`preview_draw`: the parent's world matrix, or for a bone the armature
and its parent bones as posed now).
"""

from __future__ import annotations

import dataclasses
import functools
import hashlib
from dataclasses import astuple, dataclass, field

import bpy
import numpy as np

from ..pure import packed_parts
from ..pure.preview_geometry import (  # noqa: F401  (re-exported: preview.Space, preview.bone_geometry, ...)
    BONE_EDGES,
    BONE_TRIS,
    BONE_WAIST,
    BOX_EDGES,
    BOX_TRIS,
    CYCLE,
    Geometry,
    Space,
    _times,
    bone_geometry,
    box_corners,
    instance_indices,
    instance_vertices,
    space_from_probes,
    with_scale,
)
from . import bake, bulk, channels, keys, owners
from . import curves as curves_
from .keys import SmoothError

#: Default number of stroboscopic instances.
DEFAULT_INSTANCES = 16
#: Default number of trajectory points.
DEFAULT_TRAJECTORY_POINTS = 200

#: Keyframe attributes that decide the value of an F-curve anywhere: (name, width, dtype).
_KEY_ATTRS = (
    ("co", 2, np.float32),
    ("handle_left", 2, np.float32),
    ("handle_right", 2, np.float32),
    ("interpolation", 1, np.int32),
)
#: ... and those that matter only for the easing interpolations (Sine ... Elastic).
_EASING_ATTRS = (
    ("easing", 1, np.int32),
    ("back", 1, np.float32),
    ("amplitude", 1, np.float32),
    ("period", 1, np.float32),
)
_INTERPOLATIONS = {item.identifier: item.value for item in bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items}
#: Interpolation values above this are easing interpolations (Blender numbers Constant,
#: Linear, Bezier first); checked here rather than assumed.
_PLAIN_MAX = max(_INTERPOLATIONS[name] for name in ("CONSTANT", "LINEAR", "BEZIER"))
assert all(v > _PLAIN_MAX for k, v in _INTERPOLATIONS.items() if k not in ("CONSTANT", "LINEAR", "BEZIER"))


@dataclass(frozen=True)
class PreviewOptions:
    """What the preview of one object depends on besides its keys."""

    #: Smooth Motion's options (scheme, levels, timing, cycle, frame range): shared with the bake.
    smooth: bake.Options = field(default_factory=bake.Options)
    #: Number of stroboscopic instances.
    instances: int = DEFAULT_INSTANCES
    #: Number of trajectory points.
    trajectory_points: int = DEFAULT_TRAJECTORY_POINTS
    #: Whether the raw polyscrew (0 levels, linear timing) is computed for comparison.
    show_raw: bool = False

    def key(self) -> tuple:
        """A hashable summary of these options."""
        return (astuple(self.smooth), self.instances, self.trajectory_points, self.show_raw)

    @functools.cached_property
    def key_bytes(self) -> bytes:
        """:meth:`key` as bytes for a digest, made once (every previewed owner hashes it)."""
        return repr(self.key()).encode()


@dataclass
class PreviewBatches:
    """Everything the overlay draws for one object, as arrays (parent space, float64)."""

    #: Times of the instances, shape (N,).
    instance_times: np.ndarray
    #: Object matrices (rigid pose times scale) at those times, shape (N, 4, 4).
    instances: np.ndarray
    #: Times of the trajectory points, shape (M,).
    trajectory_times: np.ndarray
    #: The origin at those times, shape (M, 3).
    trajectory: np.ndarray
    #: Key frames, shape (K,).
    key_frames: np.ndarray
    #: Object matrices at the key poses, shape (K, 4, 4).
    keys: np.ndarray
    #: Raw polyscrew instances (N, 4, 4) and trajectory (M, 3), when asked for.
    raw_instances: np.ndarray | None = None
    raw_trajectory: np.ndarray | None = None


def frame_range(motion: keys.KeyedMotion, options: bake.Options) -> tuple[float, float]:
    """The frames the preview spans: the bake's range (Smooth Motion's Frame Range setting)."""
    if options.frame_range is not None:
        return float(options.frame_range[0]), float(options.frame_range[1])
    return motion.frame_range


def compute(
    motion: keys.KeyedMotion, options: PreviewOptions, obj: bpy.types.Object | owners.Owner | None = None
) -> PreviewBatches:
    """The preview of `motion`: one :func:`bake.sample_poses` call for instances and trajectory.

    `obj` is the owner the motion was read from (an object or a bone): the Feature Points
    method needs its body (mesh, bone length) and key selection (without it the preview falls
    back to screw subdivision, as the bake would).
    Raises `ValueError` from polyscrew for motions it refuses.
    """
    start, end = frame_range(motion, options.smooth)
    # A cycle over one period ends where it starts: the last instance would repeat the first.
    cycle = motion.closed and motion.period is not None and options.smooth.frame_range is None
    instance_times = _times(start, end, max(1, options.instances), cycle)
    trajectory_times = _times(start, end, max(2, options.trajectory_points), False)
    times = np.concatenate([instance_times, trajectory_times])
    n = len(instance_times)
    poses, scales = bake.sample_poses(motion, times, options.smooth, obj)
    if scales is None:  # unkeyed scale: the object's own, constant
        scales = np.broadcast_to(motion.scales[0], (len(times), 3))
    matrices = with_scale(poses, scales)
    batches = PreviewBatches(
        instance_times=instance_times,
        instances=matrices[:n],
        trajectory_times=trajectory_times,
        trajectory=poses[n:, :3, 3].copy(),
        key_frames=motion.frames.copy(),
        keys=with_scale(motion.poses, motion.scales),
    )
    if options.show_raw:
        raw = bake.Options(scheme=options.smooth.scheme, levels=0, timing="linear", closed=options.smooth.closed)
        raw_poses, raw_scales = bake.sample_poses(motion, times, raw)
        if raw_scales is None:
            raw_scales = scales
        raw_matrices = with_scale(raw_poses, raw_scales)
        batches.raw_instances = raw_matrices[:n]
        batches.raw_trajectory = raw_poses[n:, :3, 3].copy()
    return batches


#: Current transform values differing from the curves by more than this (relative) at a key
#: frame mean the user is moving the object there.
LIVE_TOLERANCE = 1e-5


@dataclass
class LiveKey:
    """The object's current transform, differing from its animation at the current frame:
    the user is moving or rotating it. At a key frame it stands for that key pose; elsewhere
    (with auto-keying on) for the key auto-keying will insert there."""

    frame: float
    #: location (3,), rotation channel values, scale (3,).
    location: np.ndarray
    rotation: np.ndarray
    scale: np.ndarray


def _transform_curves(owner: owners.Owner, fcurves: list) -> list:
    """The owner's location, rotation (its mode) and scale curves among `fcurves` (not the
    location of a connected bone, which is not read)."""
    paths = tuple(owner.path(p) for p in keys.transform_paths(owner.target.rotation_mode))
    located = not owner.bone or not owner.obj.data.bones[owner.bone].use_connect
    return [fc for fc in fcurves if fc.data_path in paths and (located or fc.data_path != paths[0])]


def _played(listed: list) -> list:
    """The curves :func:`keys.read` reads among the owner's transform curves: keyed, not muted."""
    return [fc for fc in listed if not fc.mute and len(fc.keyframe_points)]


def played_curves(owner: owners.Owner, fcurves: list) -> list:
    """The owner's transform curves among `fcurves` that :func:`keys.read` reads (keyed, not
    muted): the curves of its part in :func:`read_together`'s `memo`."""
    return _played(_transform_curves(owner, fcurves))


def read_together(pairs: list[tuple[owners.Owner, list]], memo: dict) -> None:
    """Reads the played transform curves of every owner of `pairs` ((owner, its curves) each,
    see :func:`key_hash`) in one `curves.read` call, each curve once, and gives each owner its
    part in `memo` (:func:`key_hash`'s): a refresh of many objects reads their keys in one
    pass instead of one per owner. Curves it cannot pack are left to each owner's own read
    (which says why)."""
    union, at, wanted = [], {}, []
    for owner, fcurves in pairs:
        played = _played(_transform_curves(owner, fcurves))
        handle = tuple(fc.as_pointer() for fc in played)
        if not played or handle in memo:
            continue
        for fc in played:
            if fc.as_pointer() not in at:
                at[fc.as_pointer()] = len(union)
                union.append(fc)
        wanted.append((handle, [at[p] for p in handle]))
    if not union:
        return
    try:
        packed = curves_.read(union, keys_only=True)
    except curves_.UnsupportedCurve:
        return
    for handle, columns in wanted:
        memo.setdefault(handle, packed_parts.subset(packed, columns))


def key_hash(
    owner: owners.Owner | bpy.types.Object,
    options: PreviewOptions,
    frame: float | None = None,
    auto_key: bool = False,
    fcurves: list | None = None,
    memo: dict | None = None,
) -> tuple[bytes, LiveKey | None, tuple[list, curves_.Packed] | None]:
    """A digest of everything :func:`keys.read` reads from `owner` (an object or a pose
    bone), and of `options`; the live key at `frame` (see :class:`LiveKey`), which enters
    the digest too; and the keys read (below).

    Raw F-curve data of the transform channels (key coordinates, handles, interpolation,
    easing, extrapolation, mute, modifiers), the rotation mode, the values of unkeyed
    transform channels, the action and slot, NLA strips and transform drivers (for a bone
    also whether it is connected, which decides whether its location is read, and its
    length). Reading it is a few `foreach_get` calls: far cheaper than reading and sampling
    the keys. The current transform enters only when `frame` is a key frame (or `auto_key` is
    on) and it differs from the curves there, so playing or scrubbing the timeline never
    recomputes anything. `fcurves`: the owner's curves when the caller has grouped them
    already (:func:`owners.curves_by_owner`), else the object's curves are searched.

    The keys are read as :func:`keys.read` reads them (`curves.read`, one `foreach_get` per
    property and curve) and returned with the digest, (curves, packed keys), for
    :func:`keys.read` to use: a recomputed preview reads each curve once. `memo` (a dict kept
    over one refresh) holds the keys read so far: owners sharing an action (linked duplicates)
    read its curves once.
    """
    owner = owners.as_owner(owner)
    obj, target = owner.obj, owner.target
    digest = hashlib.blake2b(digest_size=16)
    digest.update(options.key_bytes)
    mode = target.rotation_mode
    props = keys.transform_paths(mode)
    paths = tuple(owner.path(p) for p in props)
    adt = obj.animation_data
    digest.update(f"{mode}|{obj.name_full}".encode())
    located = True
    if owner.bone:
        bone = obj.data.bones[owner.bone]
        located = not bone.use_connect
        digest.update(f"|{owner.bone}|{located}|{bone.length!r}".encode())
    if adt is not None:
        action = adt.action
        digest.update(
            f"|{action.name_full if action else ''}|{channels.slot_identifier(obj)}"
            f"|{[(t.mute, t.is_solo, [s.mute for s in t.strips]) for t in adt.nla_tracks]}|{adt.use_nla}"
            f"|{adt.use_tweak_mode}"
            f"|{sorted((d.data_path, d.array_index) for d in adt.drivers if d.data_path in paths)}".encode()
        )
    feature_method = options.smooth.method == "FEATURE"
    curves = {}
    at_key = False
    listed = _transform_curves(owner, channels.object_fcurves(obj) if fcurves is None else fcurves)
    for fc in listed:
        prop = props[paths.index(fc.data_path)]
        curves[(prop, fc.array_index)] = fc
        digest.update(
            f"|{fc.data_path}[{fc.array_index}]{len(fc.keyframe_points)}{fc.mute}{fc.extrapolation}"
            f"{[(m.type, m.mute) for m in fc.modifiers]}".encode()
        )
    # The curves keys.read reads (not muted, keyed), packed as it packs them.
    played = _played(listed)
    memo = {} if memo is None else memo
    handle = tuple(fc.as_pointer() for fc in played)
    if handle not in memo:
        try:
            memo[handle] = curves_.read(played, keys_only=True) if played else None
        except curves_.UnsupportedCurve:
            memo[handle] = None  # (keys.read reads them its own way; hashed below)
    packed = memo[handle]
    if packed is not None:
        for name in ("offsets", "co", "handle_left", "handle_right", "interpolation", "easing", "back", "amplitude", "period"):
            digest.update(np.ascontiguousarray(getattr(packed, name)).tobytes())
        digest.update(f"{packed.cycles}".encode())
        if frame is not None:
            at_key = bool(np.any(np.abs(packed.co[:, 0] - frame) < keys.FRAME_TOLERANCE))
    for fc in listed:
        points = fc.keyframe_points
        count = len(points)
        if packed is not None and not fc.mute and count:
            if feature_method and options.smooth.approximate:  # selected keys are approximated
                flags = np.empty(count, dtype=bool)
                bulk.get(points, "select_control_point", flags)
                digest.update(flags.tobytes())
            continue
        for attr, width, dtype in _KEY_ATTRS:
            buf = np.empty(width * count, dtype=dtype)
            bulk.get(points, attr, buf)
            digest.update(buf.tobytes())
            if attr == "co" and frame is not None and count and not fc.mute:
                at_key = at_key or bool(np.any(np.abs(buf[0::2] - frame) < keys.FRAME_TOLERANCE))
        if count and int(buf.max()) > _PLAIN_MAX:  # buf: the interpolations
            for attr, width, dtype in _EASING_ATTRS:
                extra = np.empty(width * count, dtype=dtype)
                bulk.get(points, attr, extra)
                digest.update(extra.tobytes())
        if feature_method and options.smooth.approximate:  # selected keys are approximated
            flags = np.empty(count, dtype=bool)
            bulk.get(points, "select_control_point", flags)
            digest.update(flags.tobytes())
    if feature_method and not owner.bone and obj.type == "MESH":  # the feature points are the mesh's inertia points
        co = np.empty(3 * len(obj.data.vertices), dtype=np.float32)
        bulk.get(obj.data.vertices, "co", co)
        digest.update(co.tobytes())
    # Unkeyed channels enter the key poses with their current (static) value.
    current = {}
    changed = False
    for path in props:
        values = np.array(getattr(target, path), dtype=np.float64)
        if path == "location" and not located:
            values = np.zeros(3)  # Blender ignores it: the pose has no translation
        current[path] = values
        static = [v for i, v in enumerate(values) if (path, i) not in curves]
        digest.update(np.asarray(static, dtype=np.float64).tobytes())
        if at_key or (auto_key and frame is not None):
            for i, value in enumerate(values):
                fc = curves.get((path, i))
                if fc is not None and not fc.mute and abs(fc.evaluate(frame) - value) > LIVE_TOLERANCE * (1.0 + abs(value)):
                    changed = True
    live = None
    if changed:
        live = LiveKey(frame, current[props[0]], current[props[1]], current[props[2]])
        digest.update(np.concatenate([[frame], live.location, live.rotation, live.scale]).tobytes())
    return digest.digest(), live, (None if packed is None else (played, packed))


def with_live_key(motion: keys.KeyedMotion, live: LiveKey) -> keys.KeyedMotion:
    """`motion` with the live transform as its key at `live.frame`: replacing the key pose
    there, or inserted as a new key (open motions; a cycle keeps its keys)."""
    if not np.all(live.scale > 0.0):
        return motion
    rotation = keys.rotation_matrices(live.rotation[None, :], motion.rotation_mode)
    location = live.location if motion.located else np.zeros(3)  # a connected bone: no translation
    pose = keys.compose(location[None, :], rotation)[0]
    hits = np.flatnonzero(np.abs(motion.frames - live.frame) < keys.FRAME_TOLERANCE)
    if len(hits):
        k = hits[0]
        poses, scales = motion.poses.copy(), motion.scales.copy()
        poses[k], scales[k] = pose, live.scale
        return dataclasses.replace(motion, poses=poses, scales=scales)
    if motion.closed:
        return motion
    k = int(np.searchsorted(motion.frames, live.frame))
    return dataclasses.replace(
        motion,
        frames=np.insert(motion.frames, k, live.frame),
        poses=np.insert(motion.poses, k, pose, axis=0),
        scales=np.insert(motion.scales, k, live.scale, axis=0),
    )


@dataclass
class PreviewEntry:
    """The cached preview of one owner (an object or a bone)."""

    digest: bytes
    #: The batches, or None when the object's keys cannot be previewed.
    batches: PreviewBatches | None
    #: Why there is nothing to draw ("" when there is).
    error: str = ""


def cache_key(owner: owners.Owner | bpy.types.Object) -> int | tuple[int, str]:
    """Where the preview of `owner` is cached: an object under its `session_uid`, a bone
    under (its armature object's `session_uid`, the bone's name)."""
    owner = owners.as_owner(owner)
    uid = owner.obj.session_uid
    return (uid, owner.bone) if owner.bone else uid


def preview_owners(
    obj: bpy.types.Object, armature: str = "BOTH", fcurves: list | None = None, grouped: dict | None = None
) -> list[owners.Owner]:
    """What the preview of `obj` shows: the object itself; for an armature what Smooth Motion
    would smooth in Object Mode (:func:`owners.of_object`, per the Armatures option
    `armature`): its keyed bones (hidden ones only when selected) and/or its own keys.
    `fcurves` are the object's F-curves (read from its action when not given), `grouped`
    their :func:`owners.curves_by_owner` when the caller has it."""
    if obj.type != "ARMATURE":
        return [owners.Owner(obj)]
    return owners.of_object(obj, armature, channels.object_fcurves(obj) if fcurves is None else fcurves, grouped)


class PreviewCache:
    """Previews per owner (:func:`cache_key`: objects by `session_uid`, bones by
    (`session_uid`, bone name)), recomputed only when their key hash changes."""

    def __init__(self) -> None:
        self.entries: dict[int | tuple[int, str], PreviewEntry] = {}
        #: How many times each owner (by name: "Cube", "Rig: Hand") was recomputed: for tests
        #: and statistics.
        self.recomputed: dict[str, int] = {}

    def refresh(
        self,
        owner: owners.Owner | bpy.types.Object,
        options: PreviewOptions,
        frame: float | None = None,
        auto_key: bool = False,
        fcurves: list | None = None,
        memo: dict | None = None,
    ) -> tuple[PreviewEntry, bool]:
        """The preview of `owner` (an object or a bone) and whether it was recomputed now
        (its hash changed).

        `frame` is the current frame: when the owner is being moved there, at a key frame or
        with auto-keying on (`auto_key`), the preview shows the motion with the owner's
        current pose as the key at that frame. `fcurves`: the owner's own transform curves
        when the caller has grouped them (:func:`owners.curves_by_owner`). `memo`: the keys
        read so far in this refresh (:func:`key_hash`): each curve is read once.
        """
        return self.refresh_many([(owners.as_owner(owner), fcurves)], options, frame, auto_key, memo)[0]

    def refresh_many(
        self,
        pairs: list[tuple[owners.Owner, list | None]],
        options: PreviewOptions,
        frame: float | None = None,
        auto_key: bool = False,
        memo: dict | None = None,
    ) -> list[tuple[PreviewEntry, bool]]:
        """:meth:`refresh` of every (owner, its curves or None) of `pairs`: the owners whose
        hash changed are read together (:func:`keys.read_many`: one read of their curves, one
        polyscrew call), then each recomputed."""
        memo = {} if memo is None else memo
        hashed = [(owner, fcurves, *key_hash(owner, options, frame, auto_key, fcurves, memo)) for owner, fcurves in pairs]
        stale, seen = [], set()
        for owner, fcurves, digest, live, read in hashed:
            entry, key = self.entries.get(cache_key(owner)), cache_key(owner)
            if key not in seen and (entry is None or entry.digest != digest):
                stale.append((owner, fcurves, digest, live, read))
            seen.add(key)
        smooth = options.smooth
        motions = keys.read_many([
            keys.Request(owner, smooth.closed, extend_to=smooth.frame_range, fcurves=fcurves, turns=smooth.turns, packed=read)
            for owner, fcurves, _, _, read in stale
        ])
        for (owner, _, digest, live, _), motion in zip(stale, motions):
            name = owner.name
            try:
                if isinstance(motion, SmoothError):
                    raise motion
                if live is not None:
                    motion = with_live_key(motion, live)
                entry = PreviewEntry(digest, compute(motion, options, owner))
            except (SmoothError, ValueError) as err:
                message = str(err)
                entry = PreviewEntry(digest, None, message if message.startswith(name) else f"{name}: {message}")
            self.entries[cache_key(owner)] = entry
            self.recomputed[name] = self.recomputed.get(name, 0) + 1
        recomputed = {cache_key(owner) for owner, *_ in stale}
        return [(self.entries[cache_key(o)], cache_key(o) in recomputed) for o, *_ in hashed]

    def forget(self, keep: set | None = None) -> None:
        """Drops every entry (or every entry whose :func:`cache_key` is not in `keep`)."""
        if keep is None:
            self.entries.clear()
        else:
            for uid in [u for u in self.entries if u not in keep]:
                del self.entries[uid]


# Geometry drawn per instance --------------------------------------------------------------


def object_geometry(obj: bpy.types.Object, heavy_limit: int) -> Geometry:
    """The instance shape of `obj`: its mesh, its mesh's bounding box when the mesh has more
    than `heavy_limit` vertices, its bounding box (non-mesh objects) or axes (empties)."""
    if obj.type == "MESH":
        mesh = obj.data
        n = len(mesh.vertices)
        co = np.empty(3 * n, dtype=np.float32)
        bulk.get(mesh.vertices, "co", co)
        co = co.reshape(-1, 3)
        if n > heavy_limit:
            return Geometry(box_corners(co.min(axis=0), co.max(axis=0)), BOX_EDGES, BOX_TRIS, "BOX")
        edges = np.empty(2 * len(mesh.edges), dtype=np.int32)
        bulk.get(mesh.edges, "vertices", edges)
        tris_rna = mesh.loop_triangles
        if len(tris_rna) == 0 and len(mesh.polygons) > 0:
            mesh.calc_loop_triangles()  # runtime cache only, not saved data
            tris_rna = mesh.loop_triangles
        tris = np.empty(3 * len(tris_rna), dtype=np.int32)
        bulk.get(tris_rna, "vertices", tris)
        return Geometry(co, edges.reshape(-1, 2), tris.reshape(-1, 3), "MESH")
    corners = np.array([tuple(c) for c in obj.bound_box], dtype=np.float32)
    if obj.type != "EMPTY" and np.ptp(corners, axis=0).max() > 0.0:
        return Geometry(corners, BOX_EDGES, BOX_TRIS, "BOX")
    size = float(getattr(obj, "empty_display_size", 1.0))
    axes = np.array([(0, 0, 0), (size, 0, 0), (0, 0, 0), (0, size, 0), (0, 0, 0), (0, 0, size)], dtype=np.float32)
    return Geometry(axes, np.array([(0, 1), (2, 3), (4, 5)], dtype=np.int32), np.zeros((0, 3), dtype=np.int32), "AXES")


