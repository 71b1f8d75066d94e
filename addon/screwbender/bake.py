# SPDX-License-Identifier: GPL-3.0-or-later
"""Smoothing key poses with `polyscrew` and writing the result as a new action.

The pipeline, per object:

1. :func:`keys.read` turns the transform F-curves into key poses (nothing changes).
2. :func:`sample_channels` samples the subdivided motion at every baked frame: one
   `polyscrew.sample_channels` call for location and rotation channels (Feature Points:
   `polyscrew.sample_feature` then `polyscrew.rotation_channels`), one
   `polyscrew.sample_vectors` call for log-scale.
3. :func:`write` copies the source action, replaces its transform F-curves of this object by
   the dense baked ones (`keyframe_points.add` + `foreach_set`) and assigns the copy; the
   source action keeps a fake user and is recorded on the copy for :func:`revert`.

Steps 1 and 2 run for every object before step 3 touches anything, so a refusal anywhere
leaves the scene as it was.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from dataclasses import dataclass

import bpy
import numpy as np
import polyscrew

from . import channels, feature, keys
from .keys import SmoothError

#: Subdivision schemes: (identifier, label, description).
SCHEMES = (
    ("four_point", "4-Point", "Interpolating: the motion passes through every key pose (C1)"),
    ("bspline", "B-Spline", "Approximating: the smoothest motion (C2), it cuts inside the key poses"),
    ("jarek", "Jarek", "Between the two: nearly passes through the keys, smoother than 4-point"),
)
#: Timing of the motion between keys.
TIMINGS = (
    ("smooth", "Smooth", "Velocity continuous across keys at uneven frames (monotone C1 time map)"),
    ("linear", "Linear", "Constant pace between two keys, pace changes at each key"),
)
#: Whether the motion is a cycle.
CLOSED_MODES = (
    ("AUTO", "Auto", "Closed when a Cycles modifier is on the transform F-curves"),
    ("ON", "Closed", "Treat the keys as a cycle (a last key repeating the first one closes it)"),
    ("OFF", "Open", "Treat the keys as an open sequence, ignoring Cycles modifiers"),
)

#: Custom properties recorded on a smoothed action.
SOURCE_KEY = "screwbender_source"
SOURCE_SLOT_KEY = "screwbender_source_slot"
SOURCE_FAKE_USER_KEY = "screwbender_source_fake_user"

_LINEAR = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value


@dataclass
class Options:
    """Everything the smoothing needs besides the objects."""

    scheme: str = "jarek"
    levels: int = 4
    timing: str = "smooth"
    closed: str = "AUTO"
    #: Baked frame range; None bakes each object over its keys' range.
    frame_range: tuple[float, float] | None = None
    #: Frames between baked keys (1 frame, or less for subframes).
    step: float = 1.0
    #: "SCREW" (screw subdivision) or "FEATURE" (feature points, see :mod:`feature`).
    method: str = "SCREW"
    #: Feature points: "uniform" or "centripetal" spacing of the variational curves.
    parametrization: str = "uniform"
    #: Feature points: approximate the unselected keys (else every key is hit).
    approximate: bool = False
    #: Feature points: spring stiffness of the approximated keys (smaller is smoother).
    stiffness: float = 1.0


@dataclass
class Baked:
    """Dense channel values for one object, before anything is written."""

    obj: bpy.types.Object
    motion: keys.KeyedMotion
    frames: np.ndarray
    #: property name -> (len(frames), components) values.
    values: dict[str, np.ndarray]
    #: Whether the baked curves get a Cycles modifier (a closed motion baked over one period).
    cyclic: bool


def sample_poses(
    motion: keys.KeyedMotion,
    frames: np.ndarray,
    options: Options,
    obj: bpy.types.Object | None = None,
) -> tuple[np.ndarray, np.ndarray | None]:
    """The smoothed motion at `frames`: rigid poses (len(frames), 4, 4) and, when scale is
    keyed, scales (len(frames), 3) (else None). One `polyscrew.sample` call for the poses
    (`polyscrew.sample_feature` for the Feature Points method, which needs `obj` for its mesh
    and key selection), one `polyscrew.sample_vectors` call for log-scale. Raises `ValueError`
    from polyscrew.

    The live preview and Insert Key on Motion sample through here; Smooth Motion's bake
    samples the same motion as channels (:func:`sample_channels`: `polyscrew.sample_channels`
    is `rotation_channels` of `polyscrew.sample`), so they show, key and bake one motion.
    """
    if options.method == "FEATURE" and obj is not None:
        poses = feature.sample_poses(obj, motion, frames, options)
    else:
        poses = polyscrew.sample(motion.poses, motion.frames, frames, **_spec(motion, options))
    return poses, sample_scales(motion, frames, options)


def _spec(motion: keys.KeyedMotion, options: Options) -> dict:
    """The subdivision and timing arguments of `polyscrew.sample` and its siblings."""
    return dict(
        scheme=options.scheme,
        levels=options.levels,
        closed=motion.closed,
        period=motion.period,
        timing=options.timing,
    )


def sample_scales(motion: keys.KeyedMotion, frames: np.ndarray, options: Options) -> np.ndarray | None:
    """Scales (len(frames), 3) smoothed by the same scheme on log-scale, or None when scale
    is not keyed."""
    if not motion.scale_keyed:
        return None
    spec = _spec(motion, options)
    return np.exp(polyscrew.sample_vectors(np.log(motion.scales), motion.frames, frames, **spec))


def bake_frames(start: float, end: float, step: float) -> np.ndarray:
    """Frames from `start` to `end` (included when on the grid) every `step` frames."""
    if not step > 0.0:
        raise SmoothError(f"step must be positive, got {step:g}")
    if not end > start:
        raise SmoothError(f"frame range {start:g} to {end:g} is empty")
    count = int(np.floor((end - start) / step + 1e-9)) + 1
    return start + step * np.arange(count, dtype=np.float64)


def sample_channels(obj: bpy.types.Object, motion: keys.KeyedMotion, options: Options) -> Baked:
    """Samples the smoothed motion of `obj` at every baked frame (no Blender data changes)."""
    start, end = options.frame_range if options.frame_range is not None else motion.frame_range
    try:
        frames = bake_frames(start, end, options.step)
        mode = motion.rotation_mode
        previous = None if mode == "AXIS_ANGLE" else motion.first_rotation
        if options.method == "FEATURE":
            poses, scales = sample_poses(motion, frames, options, obj)
            location = poses[:, :3, 3].copy()
            rotation = polyscrew.rotation_channels(poses, mode, previous=previous)
        else:  # one call from keys to channels, no (frames, 4, 4) matrices in between
            location, rotation = polyscrew.sample_channels(
                motion.poses, motion.frames, frames, mode, previous, **_spec(motion, options)
            )
            scales = sample_scales(motion, frames, options)
        values = {"location": location, keys.rotation_path(mode): rotation}
        if scales is not None:
            values["scale"] = scales
    except ValueError as err:  # polyscrew's ValueError, or ours (SmoothError) for the range
        raise SmoothError(f"{obj.name}: {err}") from err
    # The baked curves repeat (Cycles modifier) when they span exactly one period of a motion
    # that was cyclic in the source.
    cyclic = (
        motion.cyclic
        and motion.closed
        and options.frame_range is None
        and abs(frames[-1] - end) < keys.FRAME_TOLERANCE
    )
    return Baked(obj=obj, motion=motion, frames=frames, values=values, cyclic=cyclic)


def _write_curves(bag, path: str, frames: np.ndarray, values: np.ndarray, cyclic: bool) -> None:
    """One dense linear F-curve per column of `values`, keyed at `frames`."""
    co = np.empty((len(frames), 2), dtype=np.float32)  # Blender stores keys as float32
    co[:, 0] = frames
    # A tuple of Python ints: foreach_set takes it several times faster than a numpy array
    # for an enum property (measured in Blender 4.2 and 5.0).
    linear = (_LINEAR,) * len(frames)
    for index in range(values.shape[1]):
        fcurve = channels.new_fcurve(bag, path, index)
        points = fcurve.keyframe_points
        points.add(len(frames))
        co[:, 1] = values[:, index]
        points.foreach_set("co", co.ravel())
        points.foreach_set("interpolation", linear)
        if cyclic:
            fcurve.modifiers.new("CYCLES")
    # Keys are sorted, unique and linear: no fcurve.update() needed (as in Blender's baker).


def write(baked: Baked) -> bpy.types.Action:
    """Assigns to the object a copy of its action whose transform curves are the baked ones."""
    obj = baked.obj
    adt = obj.animation_data
    source = adt.action
    identifier = channels.slot_identifier(obj)
    smoothed = source.copy()
    smoothed.name = f"{source.name}.smooth"
    smoothed.use_fake_user = False
    bag = channels.ensure_container(smoothed, channels.find_slot(smoothed, identifier))
    baked_paths = set(baked.values)
    # Transform curves of this object that the bake replaces; every other curve stays as copied.
    replaced = keys.transform_paths(baked.motion.rotation_mode)
    for fcurve in [fc for fc in channels.fcurves(bag) if fc.data_path in replaced and fc.data_path in baked_paths]:
        channels.remove_fcurve(bag, fcurve)
    for path, values in baked.values.items():
        _write_curves(bag, path, baked.frames, values, baked.cyclic)
    smoothed[SOURCE_KEY] = source
    smoothed[SOURCE_SLOT_KEY] = identifier
    smoothed[SOURCE_FAKE_USER_KEY] = bool(source.use_fake_user)
    source.use_fake_user = True
    channels.assign(obj, smoothed, identifier)
    return smoothed


def prepare(
    objects: Iterable[bpy.types.Object], options: Options
) -> tuple[list[Baked], list[str]]:
    """Reads and samples every object; returns the bakes and the messages of skipped objects."""
    bakes: list[Baked] = []
    skipped: list[str] = []
    for obj in objects:
        try:
            motion = keys.read(obj, options.closed)
            bakes.append(sample_channels(obj, motion, options))
        except SmoothError as err:
            skipped.append(str(err))
    return bakes, skipped


def smooth(
    objects: Iterable[bpy.types.Object],
    options: Options,
    progress: Callable[[int, int], None] | None = None,
    strict: bool = False,
) -> tuple[list[bpy.types.Action], list[str]]:
    """Smooths `objects`; returns the new actions and the messages of skipped objects.

    Objects that cannot be smoothed are skipped and left unchanged; the others get their new
    action (with `strict`, any skipped object raises :class:`SmoothError` listing them all,
    before anything is changed). `progress(done, total)` is called after each object is
    sampled and written.
    """
    objects = list(objects)
    total = 2 * len(objects)
    bakes: list[Baked] = []
    skipped: list[str] = []
    for i, obj in enumerate(objects):
        done, messages = prepare([obj], options)
        bakes += done
        skipped += messages
        if progress is not None:
            progress(i + 1, total)
    if strict and skipped:
        raise SmoothError("; ".join(skipped))
    actions = []
    for i, baked in enumerate(bakes):
        actions.append(write(baked))
        if progress is not None:
            progress(len(objects) + i + 1, total)
    return actions, skipped


def source_of(obj: bpy.types.Object) -> bpy.types.Action | None:
    """The action `obj` had before it was smoothed, or None when its action is not a smoothed one."""
    adt = obj.animation_data
    if adt is None or adt.action is None:
        return None
    source = adt.action.get(SOURCE_KEY)
    return source if isinstance(source, bpy.types.Action) else None


def revert(obj: bpy.types.Object) -> None:
    """Gives `obj` back the action it had before smoothing; drops the smoothed copy if unused."""
    source = source_of(obj)
    if source is None:
        raise SmoothError(f"{obj.name}: its action was not made by Smooth Motion: nothing to revert")
    smoothed = obj.animation_data.action
    channels.assign(obj, source, smoothed.get(SOURCE_SLOT_KEY, ""))
    source.use_fake_user = bool(smoothed.get(SOURCE_FAKE_USER_KEY, False))
    if smoothed.users == 0 and not smoothed.use_fake_user:
        bpy.data.actions.remove(smoothed)
