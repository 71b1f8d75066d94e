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

import contextlib
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import bpy
import numpy as np
import polyscrew

from . import channels, feature, keys, transaction
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

#: Which frames get baked keys.
RANGE_MODES = (
    ("KEYS", "Keys", "Bake each object from its first to its last key (a cycle: over one period)"),
    ("SCENE", "Scene", "Bake the scene's frame range"),
    ("CUSTOM", "Custom", "Bake the frame range given by Start and End"),
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
    #: Smooth the current action even when it is a result of Smooth Motion (else such an
    #: object's original keys are smoothed again, replacing the earlier result).
    smooth_result: bool = False


def options_from(settings, scene: bpy.types.Scene) -> Options:
    """The options set on `settings`: Smooth Motion's operator properties, or the panel's
    scene settings (`scene.screwbender`), which have the same names."""
    if settings.range_mode == "SCENE":
        frame_range = (float(scene.frame_start), float(scene.frame_end))
    elif settings.range_mode == "CUSTOM":
        frame_range = (settings.frame_start, settings.frame_end)
    else:
        frame_range = None
    return Options(
        scheme=settings.scheme,
        levels=settings.levels,
        timing=settings.timing,
        closed=settings.closed,
        frame_range=frame_range,
        step=settings.step,
        method=settings.method,
        parametrization=settings.parametrization,
        approximate=settings.approximate,
        stiffness=settings.stiffness,
        smooth_result=getattr(settings, "smooth_result", False),
    )


@dataclass
class Baked:
    """Dense channel values for the objects of one action, before anything is written."""

    #: The objects animated by the action (several when they share it: linked duplicates).
    objects: list[bpy.types.Object]
    motion: keys.KeyedMotion
    frames: np.ndarray
    #: property name -> (len(frames), components) values; for "scale" only the keyed axes,
    #: listed in `scale_axes`.
    values: dict[str, np.ndarray]
    #: Whether the baked curves get a Cycles modifier (a closed motion baked over one period).
    cyclic: bool
    #: The action holding the keys that were smoothed (the original keys).
    source: bpy.types.Action | None = None
    #: The action the objects have now (the source, or a result of Smooth Motion replaced by
    #: this one); the new action is a copy of it, so curves edited since are kept.
    current: bpy.types.Action | None = None
    #: The slot of the objects in `current` (4.4+, else "").
    identifier: str = ""

    @property
    def obj(self) -> bpy.types.Object:
        """The first object (the one named in messages)."""
        return self.objects[0]

    @property
    def key_count(self) -> int:
        """Keys the bake writes."""
        return len(self.frames) * sum(v.shape[1] for v in self.values.values())


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
    """Scales (len(frames), 3), the keyed axes smoothed by the same scheme on log-scale and the
    unkeyed ones constant (the object's own, possibly negative), or None when no scale axis
    is keyed."""
    if not motion.scale_keyed:
        return None
    axes = motion.scale_axes
    out = np.empty((len(frames), 3))
    out[:] = motion.scales[0]
    # (unkeyed axes ride along as constants, |static scale|, and are not used)
    logs = np.log(np.abs(motion.scales))
    smoothed = np.exp(polyscrew.sample_vectors(logs, motion.frames, frames, **_spec(motion, options)))
    out[:, axes] = smoothed[:, axes]
    return out


#: Most keys one Smooth Motion may write (all objects together). Blender keeps about 60 bytes
#: per key (a BezTriple) plus the undo copy of the action: 20 million keys are about 2.5 GB.
MAX_KEYS = 20_000_000


def bake_frames(start: float, end: float, step: float) -> np.ndarray:
    """The baked frames: `start`, every multiple of `step` strictly between, and `end`.

    Keys sit on the scene's frame grid (whole frames for a step of 1, multiples of the step
    otherwise) and the range's ends, usually the first and last key, are always baked exactly,
    also when they are subframes (1.5 ... 20.6) or when the step does not divide the range
    (0.1 over 1..30: 10 * 0.1 is not 1.0 in floating point, so grid frames are `k / 10`).
    A grid frame closer than :data:`keys.FRAME_TOLERANCE` to an end is that end.
    """
    if not step > 0.0:
        raise SmoothError(f"step must be positive, got {step:g}")
    if not end > start:
        raise SmoothError(f"frame range {start:g} to {end:g} is empty")
    count = (end - start) / step + 2
    if count > MAX_KEYS:
        raise SmoothError(
            f"frame range {start:g} to {end:g} at step {step:g} is {count:,.0f} frames; the most "
            f"Smooth Motion bakes is {MAX_KEYS:,} keys: raise Step or shorten the Frame Range"
        )
    tol = keys.FRAME_TOLERANCE
    first, last = int(np.ceil((start + tol) / step)), int(np.floor((end - tol) / step))
    k = np.arange(first, last + 1, dtype=np.float64)
    per_frame = 1.0 / step
    if abs(per_frame - round(per_frame)) < 1e-9:  # 0.1, 0.2, 0.5, 1: grid frames k / n exactly
        grid = k / round(per_frame)
    else:
        grid = k * step
    grid = grid[(grid > start + tol) & (grid < end - tol)]
    return np.concatenate(([start], grid, [end]))


def channel_count(motion: keys.KeyedMotion) -> int:
    """F-curves a bake of `motion` writes: location, rotation, keyed scale axes."""
    return 3 + (4 if motion.rotation_mode in ("QUATERNION", "AXIS_ANGLE") else 3) + int(motion.scale_axes.sum())


def sample_channels(
    obj: bpy.types.Object, motion: keys.KeyedMotion, options: Options, budget: list[int] | None = None
) -> Baked:
    """Samples the smoothed motion of `obj` at every baked frame (no Blender data changes).

    `budget` holds the keys still allowed (all objects of one Smooth Motion together, at most
    :data:`MAX_KEYS`); a bake that would exceed it is refused before anything is sampled.
    """
    start, end = options.frame_range if options.frame_range is not None else motion.frame_range
    if budget is not None and end > start and options.step > 0.0:
        keys_needed = ((end - start) / options.step + 2) * channel_count(motion)
        if keys_needed > budget[0]:
            raise SmoothError(
                f"{obj.name}: baking frames {start:g} to {end:g} every {options.step:g} frames would write "
                f"{keys_needed:,.0f} keys; one Smooth Motion writes at most {MAX_KEYS:,} "
                f"({budget[0]:,} left for this object): raise Step, shorten the Frame Range or smooth fewer objects"
            )
        budget[0] -= int(keys_needed)
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
            values["scale"] = scales[:, motion.scale_axes]
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
    return Baked(objects=[obj], motion=motion, frames=frames, values=values, cyclic=cyclic)


def _write_curves(
    bag, path: str, frames: np.ndarray, values: np.ndarray, cyclic: bool, indices: np.ndarray | None = None
) -> None:
    """One dense linear F-curve per column of `values` (array index `indices[column]`, by
    default the column), keyed at `frames`."""
    co = np.empty((len(frames), 2), dtype=np.float32)  # Blender stores keys as float32
    co[:, 0] = frames
    # A tuple of Python ints: foreach_set takes it several times faster than a numpy array
    # for an enum property (measured in Blender 4.2 and 5.0).
    linear = (_LINEAR,) * len(frames)
    for column in range(values.shape[1]):
        index = int(indices[column]) if indices is not None else column
        fcurve = channels.new_fcurve(bag, path, index)
        points = fcurve.keyframe_points
        points.add(len(frames))
        co[:, 1] = values[:, column]
        points.foreach_set("co", co.ravel())
        points.foreach_set("interpolation", linear)
        if cyclic:
            fcurve.modifiers.new("CYCLES")
    # Keys are sorted, unique and linear: no fcurve.update() needed (as in Blender's baker).


def write(baked: Baked, t: transaction.Transaction) -> bpy.types.Action:
    """Gives the objects of `baked` a copy of their current action whose transform curves are
    the baked ones (every other curve as it was); the original keys' action keeps a fake user
    and is recorded on the copy for :func:`revert`. A result of Smooth Motion that no object
    uses any more is removed once everything has worked."""
    source = baked.source if baked.source is not None else baked.obj.animation_data.action
    current = baked.current if baked.current is not None else source
    identifier = baked.identifier if baked.current is not None else channels.slot_identifier(baked.obj)
    smoothed = current.copy()
    smoothed.name = f"{source.name}.smooth"
    smoothed.use_fake_user = False
    slot = smoothed.slots.get(identifier) if channels.is_slotted(smoothed) else None
    bag = channels.ensure_container(smoothed, slot)
    # Transform curves of these objects that the bake replaces; every other curve stays as copied.
    replaced = set(baked.values)
    for fcurve in [fc for fc in bag.fcurves if fc.data_path in replaced]:
        bag.fcurves.remove(fcurve)
    for path, values in baked.values.items():
        indices = np.flatnonzero(baked.motion.scale_axes) if path == "scale" else None
        _write_curves(bag, path, baked.frames, values, baked.cyclic, indices)
    smoothed[SOURCE_KEY] = source
    if current is source:
        smoothed[SOURCE_SLOT_KEY] = identifier
        smoothed[SOURCE_FAKE_USER_KEY] = bool(source.use_fake_user)
    # (re-smoothing: the copy of the earlier result already records the original's slot and flag)
    t.set(source, "use_fake_user", True)
    for obj in baked.objects:
        t.assign_action(obj, smoothed, identifier)
    if current is not source:
        name = f"{source.name}.smooth"

        def replace_earlier_result() -> None:
            if _remove_if_unused(current):
                smoothed.name = name  # the earlier result's name is free again

        t.on_commit(replace_earlier_result)
    return smoothed


def _remove_if_unused(action: bpy.types.Action) -> bool:
    """Removes `action` when nothing uses it (a replaced result of Smooth Motion); returns
    whether it did."""
    if action.users == 0 and not action.use_fake_user:
        bpy.data.actions.remove(action)
        return True
    return False


def _read_group(
    objects: list[bpy.types.Object], options: Options, budget: list[int]
) -> tuple[list[Baked], list, list[str]]:
    """Reads and samples the objects that share one action (and slot).

    Returns the bakes (one for the whole group when every object has the same key poses, else
    one per object), the skipped objects with their messages and notes for the report.
    """
    first = objects[0]
    current = first.animation_data.action
    identifier = channels.slot_identifier(first)
    source, source_slot = current, identifier
    original = current.get(SOURCE_KEY)
    if isinstance(original, bpy.types.Action) and not options.smooth_result:
        # A result of Smooth Motion: smooth the original keys again with the new options.
        source, source_slot = original, current.get(SOURCE_SLOT_KEY, "")
    motions, skipped = [], []
    for obj in objects:
        try:
            keys.check_editable(obj)
            read_from = None if source is current else source
            motions.append((obj, keys.read(obj, options.closed, action=read_from, slot=source_slot)))
        except SmoothError as err:
            skipped.append((obj, str(err)))
    if not motions:
        return [], skipped, []
    notes = []
    same = all(_same_motion(motions[0][1], m) for _, m in motions[1:])
    if same:
        groups = [[obj for obj, _ in motions]]
    else:
        groups = [[obj] for obj, _ in motions]
        notes.append(
            f"{', '.join(o.name for o, _ in motions)} share action '{current.name}' but differ in "
            "unkeyed channels or rotation mode: each got its own smoothed action"
        )
    by_object = dict(motions)
    bakes = []
    for group in groups:
        try:
            baked = sample_channels(group[0], by_object[group[0]], options, budget)
        except SmoothError as err:
            skipped += [(obj, str(err)) for obj in group]
            continue
        baked.objects = group
        baked.source, baked.current, baked.identifier = source, current, identifier
        bakes.append(baked)
    return bakes, skipped, notes


def _same_motion(a: keys.KeyedMotion, b: keys.KeyedMotion) -> bool:
    return (
        a.rotation_mode == b.rotation_mode
        and a.closed == b.closed
        and np.array_equal(a.frames, b.frames)
        and np.array_equal(a.poses, b.poses)
        and np.array_equal(a.scales, b.scales)
        and np.array_equal(a.scale_axes, b.scale_axes)
    )


def _action_groups(objects: Iterable[bpy.types.Object]) -> tuple[list[list[bpy.types.Object]], list]:
    """The objects grouped by the action and slot they are animated by (linked duplicates
    share one), in the objects' order; objects without an action are refused here."""
    groups: dict[tuple, list[bpy.types.Object]] = {}
    skipped = []
    for obj in objects:
        adt = obj.animation_data
        if adt is None or adt.action is None:
            skipped.append((obj, f"{obj.name}: no animation (no active action): skipped"))
            continue
        groups.setdefault((adt.action.as_pointer(), channels.slot_identifier(obj)), []).append(obj)
    return list(groups.values()), skipped


@dataclass
class Smoothed:
    """What Smooth Motion did."""

    #: The new actions.
    actions: list[bpy.types.Action]
    #: The objects given a new action.
    objects: list[bpy.types.Object]
    #: Messages of the objects skipped (nothing changed on them).
    skipped: list[str]
    #: Other things worth telling (shared actions split, results re-smoothed).
    notes: list[str]


def _in_order(objects: list[bpy.types.Object], skipped: list) -> list[str]:
    """The messages of skipped (object, message) pairs, in the order of `objects`."""
    order = {obj.as_pointer(): i for i, obj in enumerate(objects)}
    return [message for obj, message in sorted(skipped, key=lambda pair: order[pair[0].as_pointer()])]


def prepare(objects: Iterable[bpy.types.Object], options: Options) -> tuple[list[Baked], list[str], list[str]]:
    """Reads and samples every object (nothing changes); returns the bakes, the messages of
    skipped objects and notes."""
    objects = list(objects)
    groups, skipped = _action_groups(objects)
    bakes, notes = [], []
    budget = [MAX_KEYS]
    for group in groups:
        done, messages, told = _read_group(group, options, budget)
        bakes += done
        skipped += messages
        notes += told
    return bakes, _in_order(objects, skipped), notes


def smooth(
    objects: Iterable[bpy.types.Object],
    options: Options,
    progress: Callable[[int, int], None] | None = None,
    strict: bool = False,
    t: transaction.Transaction | None = None,
) -> Smoothed:
    """Smooths `objects`; objects sharing an action keep sharing one smoothed action.

    Objects that cannot be smoothed are skipped and left unchanged; the others get their new
    action (with `strict`, any skipped object raises :class:`SmoothError` listing them all,
    before anything is changed). Every object is read and sampled before anything is written,
    and the writing is all or nothing (inside `t`, or a transaction of its own): a failure
    halfway leaves `bpy.data` as it was. `progress(done, total)` is called as objects are
    sampled and written.
    """
    objects = list(objects)
    groups, skipped = _action_groups(objects)
    total = len(groups) * 2
    bakes, notes = [], []
    budget = [MAX_KEYS]
    for i, group in enumerate(groups):
        done, messages, told = _read_group(group, options, budget)
        bakes += done
        skipped += messages
        notes += told
        if progress is not None:
            progress(i + 1, total)
    skipped = _in_order(objects, skipped)
    if strict and skipped:
        raise SmoothError("; ".join(skipped))
    resmoothed = [b.obj.name for b in bakes if b.current is not b.source]
    if resmoothed:
        notes.append(f"re-smoothed the original keys of {_names(resmoothed)} (replacing the earlier result)")
    with contextlib.ExitStack() as stack:
        if t is None:
            t = stack.enter_context(transaction.atomic())
        actions = []
        for i, baked in enumerate(bakes):
            actions.append(write(baked, t))
            if progress is not None:
                progress(len(groups) + i + 1, total)
    smoothed_objects = [obj for b in bakes for obj in b.objects]
    return Smoothed(actions=actions, objects=smoothed_objects, skipped=skipped, notes=notes)


def _names(names: list[str], limit: int = 3) -> str:
    """"A, B, C and 297 more": a readable list of many names."""
    if len(names) <= limit:
        return ", ".join(names)
    return f"{', '.join(names[:limit])} and {len(names) - limit} more"


def summary(names: list[str], limit: int = 3) -> str:
    """The report's list of names: the first `limit` and how many more."""
    return _names(sorted(names), limit)


def source_of(obj: bpy.types.Object) -> bpy.types.Action | None:
    """The action `obj` had before it was smoothed, or None when its action is not a smoothed one."""
    adt = obj.animation_data
    if adt is None or adt.action is None:
        return None
    source = adt.action.get(SOURCE_KEY)
    return source if isinstance(source, bpy.types.Action) else None


def revert(obj: bpy.types.Object, t: transaction.Transaction) -> list[bpy.types.Object]:
    """Gives `obj`, and every object sharing its smoothed action, back the action they had
    before smoothing; drops the smoothed copy once nothing uses it. Returns the objects."""
    source = source_of(obj)
    if source is None:
        raise SmoothError(f"{obj.name}: its action was not made by Smooth Motion: nothing to revert")
    smoothed = obj.animation_data.action
    identifier = channels.slot_identifier(obj)
    sharing = [
        o
        for o in bpy.data.objects
        if o.animation_data is not None
        and o.animation_data.action == smoothed
        and channels.slot_identifier(o) == identifier
    ]
    for other in sharing:
        t.assign_action(other, source, smoothed.get(SOURCE_SLOT_KEY, ""))
    t.set(source, "use_fake_user", bool(smoothed.get(SOURCE_FAKE_USER_KEY, False)))
    t.on_commit(lambda: _remove_if_unused(smoothed))
    return sharing
