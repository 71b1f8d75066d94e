# SPDX-License-Identifier: GPL-3.0-or-later
"""Smoothing key poses with `polyscrew` and writing the result as a new action.

The pipeline, per object:

1. :func:`keys.read` turns the transform F-curves into key poses (nothing changes).
2. :func:`sample_channels` samples the subdivided motion at every baked frame as location,
   rotation and log-scale channels: for every owner of one Smooth Motion together, one
   `polyscrew.sample_owners` call per rotation mode (:func:`sampling.sample_many`; Feature
   Points: `polyscrew.sample_feature` then `polyscrew.rotation_channels` per owner).
3. :func:`write` copies the source action, replaces its transform F-curves of this object by
   the dense baked ones (`keyframe_points.add` + `foreach_set`) and assigns the copy; the
   source action keeps a fake user and is recorded on the copy for :func:`revert`.

Steps 1 and 2 run for every object before step 3 touches anything, so a refusal anywhere
leaves the scene as it was.
"""

from __future__ import annotations

import zlib
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import NamedTuple

import bpy
import numpy as np

from ..pure import intent, sampling
from ..pure.grids import MAX_KEYS, bake_frames, with_key_frames  # noqa: F401  (re-exported: bake.bake_frames)
from ..pure.reports import Outcome, _names, summary  # noqa: F401  (re-exported: bake.summary)
from ..pure.smooth_options import CLOSED_MODES, RANGE_MODES, SCHEMES, TIMINGS, Options  # noqa: F401  (re-exported: bake.Options)
from . import action_groups, bulk, channels, feature, keys, modifiers, owners, range_join, transaction
from .keys import SmoothError

#: Custom properties recorded on a smoothed action.
SOURCE_KEY = "screwbender_source"
SOURCE_SLOT_KEY = "screwbender_source_slot"
SOURCE_FAKE_USER_KEY = "screwbender_source_fake_user"
#: Which operator made a result ("smooth", "denoise"; absent: Smooth Motion).
MADE_BY_KEY = "screwbender_made_by"
#: A digest of the keys a result was written with (:func:`keys_digest`): an edit changes it.
WRITTEN_KEY = "screwbender_written"

_LINEAR = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["LINEAR"].value
_CONSTANT = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["CONSTANT"].value
_BEZIER = bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items["BEZIER"].value
_BEZIER_BYTE = bytes([_BEZIER])
#: The start of a :func:`keys_digest` that covers the handles of curves with a BEZIER key; a
#: digest written before it ("crc32:", keys and interpolations only) is compared as it was made.
DIGEST_HANDLES = "crc32h:"


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
        turns=getattr(settings, "turns", "AUTO"),
        key_mode=getattr(settings, "key_mode", "EVERY_STEP"),
        key_distance=getattr(settings, "key_distance", 0.001),
        key_angle=getattr(settings, "key_angle", 0.008726646259971648),
    )


@dataclass
class Baked:
    """Dense channel values of one owner (an object or a pose bone), before anything is written."""

    owner: owners.Owner
    motion: keys.KeyedMotion
    frames: np.ndarray
    #: property name -> (len(frames), components) values; for "scale" only the keyed axes,
    #: listed in `motion.scale_axes`.
    values: dict[str, np.ndarray]
    #: Whether the baked curves get a Cycles modifier (a closed motion baked over one period).
    cyclic: bool
    #: Per baked frame: whether its keys are CONSTANT (a held span that pops at its end).
    constant: np.ndarray | None = None
    #: Cycles modifier modes (before, after) per (property, index) for a motion extended by
    #: its Cycles modifier and baked over one period (Repeat with Offset, Mirror).
    cycle_modes: dict | None = None
    #: A Frame Range narrower than the keys: where the bake joins the source keys kept outside
    #: it (:mod:`range_join`), and the per-property maps of the source's channels at its ends.
    join: range_join.Join | None = None
    end_maps: dict | None = None
    #: (property, array index) of channels the source did not key and the smoothed motion
    #: leaves constant (to float32): not written, they stay unkeyed.
    unkeyed: frozenset = frozenset()
    #: Keys: Reduced: the reduced curves (:class:`reduce.Reduced`), written instead of `values`.
    reduced: object | None = None
    #: Blender's playback of the source at `frames` where the bake played it already
    #: (:attr:`sampling.Sampled.played`; NaN rows elsewhere), for the departure measure.
    played: np.ndarray | None = None
    #: :meth:`columns` per property, made once (the report, the removal of the curves
    #: replaced and the packing of the written ones each ask).
    _columns: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    @property
    def obj(self) -> bpy.types.Object:
        """The owner's object."""
        return self.owner.obj

    def columns(self, prop: str) -> list[tuple[int, int]]:
        """(column of `values[prop]`, array index) of every curve of `prop` the bake writes."""
        found = self._columns.get(prop)
        if found is not None:
            return found
        if prop == "scale":
            indices = [i for i, keyed in enumerate(self.motion.scale_axes.tolist()) if keyed]
        else:
            indices = range(self.values[prop].shape[1])
        unkeyed = self.unkeyed
        found = self._columns[prop] = [(c, i) for c, i in enumerate(indices) if not unkeyed or (prop, i) not in unkeyed]
        return found

    @property
    def written(self) -> list[tuple[str, int]]:
        """(property, array index) of every curve the bake writes: each column of `values`
        (for "scale" the keyed axes), but the channels left unkeyed."""
        return [(prop, i) for prop in self.values for _, i in self.columns(prop)]


@dataclass
class ActionBake:
    """Everything written into one new action: the bakes of every smoothed owner animated by
    one action (and slot), for every object that action animates."""

    #: The objects animated by the action (several when they share it: linked duplicates).
    objects: list[bpy.types.Object]
    #: One bake per smoothed owner (the object itself and/or its bones).
    parts: list[Baked]
    #: The action holding the keys that were smoothed (the original keys).
    source: bpy.types.Action
    #: The action the objects have now (the source, or a result of Smooth Motion replaced by
    #: this one); the new action is a copy of it, so curves edited since are kept.
    current: bpy.types.Action
    #: The slot of the objects in `current` (4.4+, else "").
    identifier: str = ""

    @property
    def obj(self) -> bpy.types.Object:
        return self.objects[0]


def sample_poses(
    motion: keys.KeyedMotion,
    frames: np.ndarray,
    options: Options,
    owner: owners.Owner | bpy.types.Object | None = None,
) -> tuple[np.ndarray, np.ndarray | None]:
    """The smoothed motion at `frames`: rigid poses (len(frames), 4, 4) and, when scale is
    keyed, scales (len(frames), 3) (else None). One `polyscrew.sample` call for the poses
    (`polyscrew.sample_feature` for the Feature Points method, which needs the owner for its
    feature points and key selection), one `polyscrew.sample_vectors` call for log-scale. Raises `ValueError`
    from polyscrew.

    The live preview samples through here, Insert Key on Motion through
    :func:`sample_poses_many` (all its owners at once, the same values); Smooth Motion's bake
    samples the same motion as channels (:func:`sample_channels`: `polyscrew.sample_channels`
    is `rotation_channels` of `polyscrew.sample`), so they show, key and bake one motion
    (:mod:`sampling`: pieces between holds, timing "keys").
    """
    owner = owners.as_owner(owner) if owner is not None else None
    sampled = sampling.sample(motion, frames, options, feature.sampler(owner, options))
    return sampled.poses, sampled.scales


def sample_poses_many(
    items: list[tuple[owners.Owner, keys.KeyedMotion, np.ndarray]], options: Options
) -> list[tuple[np.ndarray, np.ndarray | None] | SmoothError]:
    """:func:`sample_poses` of each `(owner, motion, frames)` of `items`, or the
    :class:`SmoothError` refusing it: the screw method samples every owner in one polyscrew
    call per rotation mode (:func:`sampling.sample_many` with poses: the same values to the
    bit), Feature Points and owners the batch refused each alone (:func:`_batched`)."""

    def alone(item: tuple) -> tuple[np.ndarray, np.ndarray | None]:
        owner, motion, frames = item
        try:
            return sample_poses(motion, frames, options, owner)
        except ValueError as err:  # polyscrew's ValueError
            raise SmoothError(f"{owner.name}: {err}") from err

    batch = [(motion, frames, None) for _, motion, frames in items]
    return [
        (got.poses, got.scales) if isinstance(got, sampling.Sampled) else got
        for got in _batched(items, batch, options, alone, poses=True)
    ]


def _batched(items: list, batch: list, options: Options, alone, poses: bool = False) -> list:
    """For each of `items`, its :func:`sampling.sample_many` result from `batch` (the items'
    `(motion, frames, previous)`, all in one call per rotation mode), or, for Feature Points
    and the owners the batch refused, `alone(item)`, or the :class:`SmoothError` it raised."""
    batched = [None] * len(items)
    if options.method != "FEATURE" and items:
        batched = sampling.sample_many(batch, options, poses=poses)
    out = []
    for item, sampled in zip(items, batched):
        if sampled is None:  # (Feature Points, or refused: alone, for its own error)
            try:
                sampled = alone(item)
            except SmoothError as err:
                sampled = err
        out.append(sampled)
    return out


def channel_count(motion: keys.KeyedMotion) -> int:
    """F-curves a bake of `motion` writes: location, rotation, keyed scale axes."""
    return len(keys.baked_channels(motion.rotation_mode, motion.located, motion.scale_axes))


def sample_channels(
    owner: owners.Owner | bpy.types.Object,
    motion: keys.KeyedMotion,
    options: Options,
    budget: list[int] | None = None,
    source_curves: list | None = None,
) -> Baked:
    """Samples the smoothed motion of `owner` at every baked frame (no Blender data changes).

    `budget` holds the keys still allowed (all owners of one Smooth Motion together, at most
    :data:`MAX_KEYS`); a bake that would exceed it is refused before anything is sampled.
    `source_curves`, the owner's curves the keys were read from, when given: a Frame Range
    narrower than the keys smooths that part and keeps the source keys outside it
    (:mod:`range_join`), and channels they do not key stay unkeyed where the smoothed motion
    leaves them constant. :func:`_sample_plans` samples many owners' plans at once.
    """
    plan = _plan(owners.as_owner(owner), motion, options, budget, source_curves)
    return _finish(plan, _sample_alone(plan))


@dataclass
class _Plan:
    """What sampling one owner takes (:func:`_plan`): the owner, its motion (cut to a Frame
    Range), the baked frames, the channels they continue from."""

    owner: owners.Owner
    motion: keys.KeyedMotion
    options: Options
    join: range_join.Join | None
    start: float
    end: float
    frames: np.ndarray
    previous: np.ndarray | None
    source_curves: list | None


def _plan(
    owner: owners.Owner, motion: keys.KeyedMotion, options: Options, budget: list[int] | None, source_curves: list | None
) -> _Plan:
    """Everything :func:`sample_channels` does before sampling: the Frame Range's cut, the
    budget's check, the baked frames. Raises :class:`SmoothError`."""
    join = None
    if source_curves is not None:
        try:
            motion, join = range_join.cut(motion, options.frame_range, source_curves, owner)
        except SmoothError:
            raise
        except ValueError as err:  # polyscrew playing the curves at the range's ends
            raise SmoothError(f"{owner.name}: {err}") from err
    start, end = options.frame_range if options.frame_range is not None else motion.frame_range
    if join is not None:  # (an end moved off an eased span: baked from there)
        start, end = (join.start if join.before else start), (join.end if join.after else end)
    if budget is not None and end > start and options.step > 0.0:
        keys_needed = ((end - start) / options.step + 2) * channel_count(motion)
        if keys_needed > budget[0]:
            raise SmoothError(
                f"{owner.name}: baking frames {start:g} to {end:g} every {options.step:g} frames would write "
                f"{keys_needed:,.0f} keys; one Smooth Motion writes at most {MAX_KEYS:,} "
                f"({budget[0]:,} left for this one): raise Step, shorten the Frame Range or smooth fewer objects"
            )
        budget[0] -= int(keys_needed)
    if options.method == "FEATURE" and options.approximate:
        feature.check_approximate(owner, motion, options.stiffness)
    try:
        frames = bake_frames(start, end, options.step)
        # every key frame of the source is a baked frame (spin poses taken from the playback
        # inside a span are not keys)
        key_frames = motion.frames if motion.is_key is None else motion.frames[motion.is_key]
        if motion.period is not None:  # a cycle: its keys in every period of the range
            first = int(np.floor((start - key_frames[0]) / motion.period))
            last = int(np.ceil((end - key_frames[0]) / motion.period))
            key_frames = (key_frames[None] + motion.period * np.arange(first, last + 1)[:, None]).ravel()
        frames = with_key_frames(frames, key_frames)
    except ValueError as err:  # ours (SmoothError) for the range
        raise SmoothError(f"{owner.name}: {err}") from err
    previous = keys.continued(motion.rotation_mode, motion.first_rotation)
    return _Plan(owner, motion, options, join, start, end, frames, previous, source_curves)


def _sample_alone(plan: _Plan) -> sampling.Sampled:
    """The channels of `plan`'s owner from its own polyscrew calls (one per piece: the
    Feature Points method, or to learn why :func:`sampling.sample_many`'s batch refused it)."""
    try:
        return sampling.sample(
            plan.motion, plan.frames, plan.options, feature.sampler(plan.owner, plan.options), channels=True,
            previous=plan.previous, played=True,
        )
    except ValueError as err:  # polyscrew's ValueError
        raise SmoothError(f"{plan.owner.name}: {err}") from err


def _sample_plans(plans: list[_Plan], options: Options) -> list[sampling.Sampled | SmoothError]:
    """The channels of every plan, or the error refusing it: the screw method samples every
    owner in one polyscrew call per rotation mode (:func:`_batched`), Feature Points each
    owner alone (its sampler reads the owner's points)."""
    return _batched(plans, [(p.motion, p.frames, p.previous) for p in plans], options, _sample_alone)


def _finish(plan: _Plan, sampled: sampling.Sampled) -> Baked:
    """The bake of `plan`'s owner from its sampled channels: the values per property, the
    Frame Range's join maps, the channels left unkeyed, the cycle."""
    owner, motion, options, join, end, frames = plan.owner, plan.motion, plan.options, plan.join, plan.end, plan.frames
    mode = motion.rotation_mode
    values = {"location": sampled.location, keys.rotation_path(mode): sampled.rotation}
    if not motion.located:
        del values["location"]
    if sampled.scales is not None:
        values["scale"] = sampled.scales[:, motion.scale_axes]
    end_maps = range_join.end_maps(join, motion, join.played, values, frames) if join is not None else None
    if join is not None:
        _check_mapped_modifiers(owner, join, end_maps)
    unkeyed = frozenset()
    if plan.source_curves is not None:
        unkeyed = _left_unkeyed(owner, plan.source_curves, values, motion)
    # The baked curves repeat (Cycles modifier) when they span exactly one period of a motion
    # that was cyclic in the source.
    whole_period = options.frame_range is None and abs(frames[-1] - end) < keys.FRAME_TOLERANCE
    cyclic = motion.cyclic and motion.closed and whole_period
    modes = motion.cycle_modes if whole_period and motion.cycle_modes else None
    return Baked(
        owner=owner, motion=motion, frames=frames, values=values, cyclic=cyclic, constant=sampled.constant,
        cycle_modes=modes, join=join, end_maps=end_maps, unkeyed=unkeyed, played=sampled.played,
    )


def _check_mapped_modifiers(owner: owners.Owner, join: range_join.Join, end_maps: dict) -> None:
    """Refuses an owner whose keys after a Frame Range are written as the same rotation in
    other values (:func:`range_join.end_maps`) on a curve whose modifiers would then play
    something else (:func:`modifiers.keeps_map`: a Limits, an Envelope)."""
    for prop, maps in end_maps.items():
        if "end" not in maps:
            continue
        for index, (a, c) in enumerate(zip(*maps["end"])):
            fcurve = join.curves.get((prop, index))
            if fcurve is not None and not modifiers.keeps_map(fcurve, float(a), float(c)):
                names = ", ".join(f"{modifiers.kind(m)} modifier {m.name!r}" for _, m in modifiers.active(fcurve))
                raise SmoothError(
                    f"{owner.name}: {owner.path(prop)}[{index}]: the smoothed motion ends the Frame Range a turn "
                    "(or on the twin Euler angles) away from the keys after it, which would be written as the same "
                    f"rotation in other values, and its {names} would act on them differently: extend the Frame "
                    "Range to the last key, or use Turns: As Blender Plays: skipped"
                )


def _left_unkeyed(owner: owners.Owner, source_curves: list, values: dict, motion: keys.KeyedMotion) -> frozenset:
    """(property, index) of the baked channels the source did not key (no curve with keys,
    or a muted one) whose baked values all equal the owner's own value in float32: the
    smoothed motion leaves them where they are, so they are not keyed."""
    keyed = motion.keyed
    if not keyed:  # (a motion not made by keys.read)
        keyed = set()
        for fc in source_curves:
            prop = owner.prop_of(fc.data_path)
            if prop is not None and not fc.mute and len(fc.keyframe_points):
                keyed.add((prop, fc.array_index))
    if all((prop, column) in keyed for prop, baked in values.items() if prop != "scale" for column in range(baked.shape[1])):
        return frozenset()  # every baked channel keyed: nothing to leave unkeyed
    out = set()
    for prop, baked in values.items():
        if prop == "scale":
            continue  # only keyed scale axes are baked
        own = np.array(getattr(owner.target, prop), dtype=np.float64)
        for column in range(baked.shape[1]):
            if (prop, column) in keyed:
                continue
            value = np.float32(own[column])
            if np.all(np.abs(baked[:, column].astype(np.float32) - value) <= 2 * np.spacing(np.abs(value) + np.float32(1))):
                out.add((prop, column))
    return frozenset(out)


@dataclass
class _Dense:
    """One owner's dense baked curves, ready to write (:func:`pack_dense`)."""

    #: (property, its (column, array index) pairs written: :meth:`Baked.columns`), in order.
    props: list[tuple[str, list[tuple[int, int]]]]
    #: One row per curve, in that order: its frames and values interleaved, float32 as
    #: Blender stores them (rows of the operator's one packed array).
    co: np.ndarray
    #: The keys' interpolations as a tuple of Blender's enum values (what `foreach_set` takes
    #: fastest for an enum) and as bytes (for the digest), shared by the owner's curves.
    interpolation: tuple
    kinds: bytes


def pack_dense(parts: Iterable[Baked]) -> dict[int, _Dense]:
    """The dense curves the bakes `parts` write (not those of a Frame Range joined to the
    source keys, nor reduced ones), per `id(part)`: the frames and values of all of them in
    one float32 array (one numpy assignment per owner and property, none per curve), the
    interpolations once per owner."""
    todo = []
    total = 0
    for part in parts:
        if part.reduced is not None or part.join is not None:
            continue
        props = [(prop, columns) for prop in part.values if (columns := part.columns(prop))]
        count = sum(len(columns) for _, columns in props)
        todo.append((part, props, count))
        total += 2 * count * len(part.frames)
    co = np.empty(total, dtype=np.float32)  # Blender stores keys as float32
    out: dict[int, _Dense] = {}
    lo = 0
    for part, props, count in todo:
        n = len(part.frames)
        rows = co[lo : lo + 2 * count * n].reshape(count, 2 * n)
        lo += 2 * count * n
        pairs = rows.reshape(count, n, 2)
        pairs[:, :, 0] = part.frames
        row = 0
        for prop, columns in props:
            values = part.values[prop]
            if len(columns) < values.shape[1]:  # channels left unkeyed are not written
                values = values[:, [c for c, _ in columns]]
            pairs[row : row + len(columns), :, 1] = values.T
            row += len(columns)
        constant = part.constant
        if constant is None or not constant.any():
            interpolation, kinds = _linear(n)
        else:
            kinds = np.where(constant, _CONSTANT, _LINEAR).astype(np.uint8)
            interpolation, kinds = tuple(kinds.tolist()), kinds.tobytes()
        out[id(part)] = _Dense(props, rows, interpolation, kinds)
    return out


_LINEARS: dict[int, tuple[tuple, bytes]] = {}


def _linear(n: int) -> tuple[tuple, bytes]:
    """(LINEAR,) * n and its bytes, made once per key count."""
    found = _LINEARS.get(n)
    if found is None:
        found = _LINEARS[n] = ((_LINEAR,) * n, bytes([_LINEAR]) * n)
    return found


def _write_dense(bag, part: Baked, dense: _Dense, digests: dict | None, groups: dict) -> None:
    """The dense curves of `part` (:func:`pack_dense`) into `bag`, in the owner's F-curve
    group, each with a Cycles modifier when the bake repeats (or the modes of
    `part.cycle_modes`) and the source curve's other modifiers copied on top; `digests` gets
    each curve's :func:`curve_digest` per (path, index), from the arrays written (no read
    back). Per curve only the Blender calls: the curve, its keys, one `foreach_set` per
    written attribute."""
    owner, stacks, cycle_modes, cyclic = part.owner, part.motion.modifiers, part.cycle_modes, part.cyclic
    group, interpolation, kinds = owner.group, dense.interpolation, dense.kinds
    n = len(interpolation)
    prefix = _count_prefix(n)
    rows = iter(dense.co)
    for prop, columns in dense.props:
        path = owner.path(prop)
        for _, index in columns:
            co = next(rows)
            fcurve = channels.new_fcurve(bag, path, index, group, groups)
            points = fcurve.keyframe_points
            points.add(n)
            bulk.put(points, "co", co)
            bulk.put(points, "interpolation", interpolation)
            if digests is not None:
                digests[path, index] = zlib.crc32(kinds, zlib.crc32(co, prefix))
            if cyclic:
                fcurve.modifiers.new("CYCLES")
            elif cycle_modes and (prop, index) in cycle_modes:
                before, after = cycle_modes[prop, index]
                modifier = fcurve.modifiers.new("CYCLES")
                modifier.mode_before, modifier.mode_after = before, after
            if stacks and (prop, index) in stacks:
                modifiers.copy_onto(stacks[prop, index], fcurve)
    # Keys are sorted, unique and linear: no fcurve.update() needed (as in Blender's baker).


def new_result(
    objects: list[bpy.types.Object],
    source: bpy.types.Action,
    current: bpy.types.Action,
    identifier: str,
    t: transaction.Transaction,
    edit,
    made_by: str = "smooth",
    digests: dict | None = None,
) -> bpy.types.Action:
    """A copy of `current` (the action `objects` have now) edited by `edit(bag)` (the copy's
    F-curve container for slot `identifier`), named after `source` (the action holding the
    original keys) and assigned to every object of `objects`; `source` keeps a fake user and
    is recorded on the copy for :func:`revert`. When `current` is an earlier result of the same
    operator (`made_by`: "smooth", "denoise") it is replaced: removed once everything has
    worked, if nothing uses it any more. A result of Smooth Motion or Reduce Keys records a
    digest of its keys (:func:`keys_digest`; `digests`: those of the curves `edit` wrote,
    filled by `edit`), so that a later edit is seen. Everything goes through the transaction `t`."""
    suffix = f".{made_by}" if made_by != "smooth" else ".smooth"
    result = current.copy()
    result.name = f"{source.name}{suffix}"
    result.use_fake_user = False
    edit(channels.ensure_container(result, channels.find_slot(result, identifier)))
    if made_by in ("smooth", "reduce"):  # (what its re-runs and Revert compare with)
        result[WRITTEN_KEY] = keys_digest(result, identifier, digests)
    elif WRITTEN_KEY in result:  # copied from an earlier Smooth Motion result: not this one's
        del result[WRITTEN_KEY]
    result[SOURCE_KEY] = source
    result[MADE_BY_KEY] = made_by
    if current is source:
        result[SOURCE_SLOT_KEY] = identifier
        result[SOURCE_FAKE_USER_KEY] = bool(source.use_fake_user)
    # (replacing an earlier result: its copy already records the original's slot and flag)
    t.set(source, "use_fake_user", True)
    for obj in objects:
        t.assign_action(obj, result, identifier)
    if current is not source and current.get(SOURCE_KEY) is not None:
        name = f"{source.name}{suffix}"

        def replace_earlier_result() -> None:
            if _remove_if_unused(current):
                result.name = name  # the earlier result's name is free again

        # Objects that shared the earlier result may each get a result of their own now
        # (they differ in unkeyed channels): it is removed once, and its name goes to the first.
        t.on_commit(replace_earlier_result, key=("remove", current.as_pointer()))
    return result


def curve_digest(
    co: np.ndarray, interpolation: np.ndarray, handle_left: np.ndarray | None = None, handle_right: np.ndarray | None = None
) -> int:
    """A checksum of one curve's keys: (K, 2) or (2K,) float32 frames and values, (K,) uint8
    interpolations (Blender's enum values, as `foreach_get` gives them) and, given, the
    float32 handles, which count when a key is BEZIER (the only interpolation that plays
    them: a handle edit there changes the motion; :data:`DIGEST_HANDLES`). CRC-32 of the key
    count and the arrays' bytes: not cryptographic, what a re-run needs is to notice a change
    of the keys it wrote (any one changed byte changes a CRC), at 0.6 of SHA-256's cost."""
    # (the arrays' bytes summed in place: no copy when they are float32 / uint8 already)
    kinds = np.ascontiguousarray(interpolation, dtype=np.uint8).tobytes()
    digest = zlib.crc32(np.ascontiguousarray(co, dtype=np.float32), _count_prefix(len(kinds)))
    digest = zlib.crc32(kinds, digest)
    if handle_left is not None and _BEZIER_BYTE in kinds:
        digest = zlib.crc32(np.ascontiguousarray(handle_left, dtype=np.float32), digest)
        digest = zlib.crc32(np.ascontiguousarray(handle_right, dtype=np.float32), digest)
    return digest


#: :func:`curve_digest`'s CRC-32 of "<key count>:" per key count (the curves of a scene share a few).
_COUNT_PREFIX: dict[int, int] = {}


def keys_digest(action: bpy.types.Action, identifier: str, known: dict | None = None, handles: bool = True) -> str:
    """A digest of the keys of `action` for slot `identifier`: every curve's data path, index,
    key frames, values and interpolations, and with `handles` the handles of a curve with a
    BEZIER key (:func:`curve_digest`), read once each (:func:`_read_digests`), but
    for the curves whose :func:`curve_digest` is `known` per (data path, index): those just
    written. A key moved, added or deleted, its interpolation changed, a BEZIER key's handle
    moved, a curve added or removed, changes it. Without `handles`: the digest written before
    handles counted ("crc32:"), to compare with one of those."""
    # (each curve's path and index read once: Revert checks every curve of every result)
    listed = sorted((fc.data_path, fc.array_index, i, fc) for i, fc in enumerate(channels.action_fcurves(action, identifier)))
    subs = [known.get((path, index)) if known else None for path, index, _, _ in listed]
    read = [fcurve for (*_, fcurve), sub in zip(listed, subs) if sub is None]
    if read:
        digests = iter(_read_digests([fc.keyframe_points for fc in read], handles))
        subs = [sub if sub is not None else next(digests) for sub in subs] if known else list(digests)
    digest = zlib.crc32(b"keys:")
    for (path, index, _, _), sub in zip(listed, subs):
        digest = zlib.crc32(f"{path}[{index}]:{sub}|".encode(), digest)
    return f"{DIGEST_HANDLES if handles else 'crc32:'}{digest:08x}"


def _read_digests(collections: list, handles: bool = True) -> list[int]:
    """:func:`curve_digest` of the keys of each of `collections` (`keyframe_points`): one
    `foreach_get` per attribute and curve (frames and values, interpolations; with `handles`
    both handles of a curve with a BEZIER key) into buffers shared by the curves of one key
    count (a packed array and its slices measured slower: 18.5 against 14.8 ms for 4,500
    curves), each curve's CRC-32 summed over them in place."""
    out = []
    buffers: dict[int, tuple] = {}  # per key count: (co, interpolation, prefix, left, right), reused
    for points in collections:
        n = len(points)
        arrays = buffers.get(n)
        if arrays is None:
            arrays = buffers[n] = (np.empty(2 * n, dtype=np.float32), np.empty(n, dtype=np.uint8), _count_prefix(n), None, None)
        co, kinds = arrays[0], arrays[1]
        bulk.get(points, "co", co)
        bulk.get(points, "interpolation", kinds)
        digest = zlib.crc32(kinds, zlib.crc32(co, arrays[2]))
        if handles and _BEZIER_BYTE in kinds.tobytes():
            if arrays[3] is None:
                arrays = buffers[n] = (*arrays[:3], np.empty(2 * n, dtype=np.float32), np.empty(2 * n, dtype=np.float32))
            bulk.get(points, "handle_left", arrays[3])
            bulk.get(points, "handle_right", arrays[4])
            digest = zlib.crc32(arrays[4], zlib.crc32(arrays[3], digest))
        out.append(digest)
    return out


def _count_prefix(n: int) -> int:
    """The CRC-32 of "<n>:", the start of :func:`curve_digest` of n keys (cached)."""
    prefix = _COUNT_PREFIX.get(n)
    if prefix is None:
        prefix = _COUNT_PREFIX[n] = zlib.crc32(f"{n}:".encode())
    return prefix


def was_edited(action: bpy.types.Action, identifier: str) -> bool:
    """Whether the keys of `action` (a result, slot `identifier`) changed after it was
    written (False for a result written before digests were kept: nothing to compare)."""
    written = action.get(WRITTEN_KEY)
    return isinstance(written, str) and written != keys_digest(action, identifier, handles=written.startswith(DIGEST_HANDLES))


def original_of(action: bpy.types.Action, made_by: str) -> tuple[bpy.types.Action, str] | None:
    """The action holding the original keys of `action` and its slot identifier, when `action`
    is a result of the operator `made_by` (whose reruns start from the original keys)."""
    original = action.get(SOURCE_KEY)
    if isinstance(original, bpy.types.Action) and action.get(MADE_BY_KEY, "smooth") == made_by:
        return original, action.get(SOURCE_SLOT_KEY, "")
    return None


def source_action(
    current: bpy.types.Action, identifier: str, made_by: str, again: bool, keep_edits: bool = True
) -> tuple[bpy.types.Action, str, bool]:
    """The action (and slot) a run of the operator `made_by` reads for owners animated by
    `current`: `current` itself, or, when `current` is that operator's result and `again` (run on
    the result) is off, the original it was made from, read again with the new options; with
    `keep_edits`, a result the animator edited since is read as it is (never thrown away). The
    third value says whether that happened (for the report)."""
    found = original_of(current, made_by)
    if found is None or again:
        return current, identifier, False
    if keep_edits and was_edited(current, identifier):
        return current, identifier, True
    return found[0], found[1], False


def write(bake: ActionBake, t: transaction.Transaction, dense: dict[int, _Dense] | None = None) -> bpy.types.Action:
    """Gives the objects of `bake` a copy of their current action whose transform curves of
    the smoothed owners are the baked ones (every other curve as it was); see
    :func:`new_result`. `dense`: :func:`pack_dense` of the operator's bakes (made here for
    this bake alone when not given)."""
    if dense is None:
        dense = pack_dense(bake.parts)

    def replace_curves(bag) -> None:
        # The curves the bake writes replace those of the same (data path, index); every other
        # curve stays as copied (an unkeyed scale axis's muted or keyless curve too).
        replaced = {(part.owner.path(prop), index) for part in bake.parts for prop, index in part.written}
        if bake.current is not bake.source:  # a channel left unkeyed loses an earlier result's curve
            replaced |= {(part.owner.path(prop), index) for part in bake.parts for prop, index in part.unkeyed}
        for fcurve in [fc for fc in channels.fcurves(bag) if (fc.data_path, fc.array_index) in replaced]:
            channels.remove_fcurve(bag, fcurve)
        groups: dict = {}  # (the F-curve groups made or found, once per action)
        for part in bake.parts:
            if part.reduced is not None:
                from . import reduce

                if part.join is not None:  # a Frame Range narrower than the keys: joined to them
                    reduce.write_joined(bag, part)
                    continue
                reduce.write_reduced(bag, part.reduced, part.cycle_modes, part.cyclic, digests)
                for (prop, index), stack in (part.motion.modifiers or {}).items():
                    fcurve = channels.find_fcurve(bag, part.owner.path(prop), index)
                    if stack and fcurve is not None and (prop, index) in part.reduced.curves:
                        modifiers.copy_onto(stack, fcurve)
                continue
            if part.join is not None:  # a Frame Range narrower than the keys: joined to them
                for prop in part.values:
                    columns = part.columns(prop)
                    if columns:
                        _write_joined(bag, part, prop, columns)
                continue
            _write_dense(bag, part, dense[id(part)], digests, groups)

    digests: dict = {}
    return new_result(bake.objects, bake.source, bake.current, bake.identifier, t, replace_curves, digests=digests)


def _write_joined(bag, part: Baked, prop: str, columns: list[tuple[int, int]]) -> None:
    """The curves of `prop` of a bake over a Frame Range narrower than the keys: the baked
    keys inside it, the source keys outside it (:func:`range_join.write`)."""
    constant = part.constant if part.constant is not None else np.zeros(len(part.frames), dtype=bool)
    interpolation = np.where(constant, _CONSTANT, _LINEAR)
    for column, index in columns:
        fcurve = channels.new_fcurve(bag, part.owner.path(prop), index, part.owner.group)
        range_join.write(
            fcurve, part.join, part.frames, part.values[prop][:, column], interpolation, prop, index, column,
            part.end_maps or {},
        )
        stack = part.motion.modifiers.get((prop, index)) if part.motion.modifiers else None
        if stack:
            modifiers.copy_onto(stack, fcurve)


def write_one(baked: Baked, t: transaction.Transaction) -> bpy.types.Action:
    """:func:`write` for one owner's bake into a copy of its object's action."""
    obj = baked.obj
    action = obj.animation_data.action
    return write(ActionBake([obj], [baked], action, action, channels.slot_identifier(obj)), t)


def _unused(action: bpy.types.Action) -> bool:
    """Whether nothing uses `action` (no user, no fake user); False when it is removed already."""
    try:
        return action.users == 0 and not action.use_fake_user
    except ReferenceError:  # removed already
        return False


def _remove_if_unused(action: bpy.types.Action) -> bool:
    """Removes `action` when nothing uses it (a replaced result of Smooth Motion); returns
    whether it did (not when it is already removed)."""
    if _unused(action):
        bpy.data.actions.remove(action)
        return True
    return False


def remove_unused(actions: list[bpy.types.Action]) -> None:
    """Removes those of `actions` that nothing uses, in one `bpy.data.batch_remove` (removing
    many data-blocks one by one scans the whole file for each: quadratic)."""
    unused = list({a.as_pointer(): a for a in actions if _unused(a)}.values())
    if unused:
        bpy.data.batch_remove(unused)


def _same_motion(a: keys.KeyedMotion, b: keys.KeyedMotion) -> bool:
    return (
        a.rotation_mode == b.rotation_mode
        and a.closed == b.closed
        and np.array_equal(a.frames, b.frames)
        and np.array_equal(a.poses, b.poses)
        and np.array_equal(a.scales, b.scales)
        and np.array_equal(a.scale_axes, b.scale_axes)
    )


@dataclass
class _Group:
    """Owners animated by one action and slot: the objects using it, the bones (or "" for
    the object itself) selected on any of them."""

    objects: list[bpy.types.Object]
    bones: list[str]


def _action_groups(selection: Iterable) -> tuple[list[_Group], list]:
    """The owners grouped by the action and slot that animates them (linked duplicates share
    one), in the order given; owners without an action are refused here."""
    found, skipped = action_groups.by_action(selection)
    # Per (action pointer, slot): its objects by pointer and its bones, each once, in order (dicts:
    # a list's `in` per owner grew as owners squared, a rig's bones or many linked duplicates).
    members: dict[tuple, tuple[dict[int, bpy.types.Object], dict[str, None]]] = {}
    for by_action in found:
        objects, bones = members[by_action.action.as_pointer(), by_action.identifier] = {}, {}
        for owner in by_action.members:
            objects.setdefault(owner.obj.as_pointer(), owner.obj)
            bones.setdefault(owner.bone, None)
    # Every object the action animates through that slot keeps sharing it, selected or not
    # (one pass over the scene's objects for all the actions).
    users = users_by_slot({pointer for pointer, _ in members})
    groups = []
    for key, (objects, bones) in members.items():
        for obj in users.get(key, ()):
            objects.setdefault(obj.as_pointer(), obj)
        groups.append(_Group(list(objects.values()), list(bones)))
    return groups, skipped


def users_by_slot(pointers: set[int]) -> dict[tuple[int, str], list[bpy.types.Object]]:
    """The objects animated by the actions whose `as_pointer()` is in `pointers`, per (action
    pointer, slot identifier), in the order of `bpy.data.objects`: one pass over the objects
    for many actions (one pass, not one per action)."""
    out: dict[tuple[int, str], list[bpy.types.Object]] = {}
    for o in bpy.data.objects:
        adt = o.animation_data
        action = adt.action if adt is not None else None
        if action is not None and action.as_pointer() in pointers:
            out.setdefault((action.as_pointer(), channels.slot_identifier(o)), []).append(o)
    return out


@dataclass
class _GroupRead:
    """One action group read (:func:`_read_group`): its motions, what the bake needs of the
    action, and what was skipped and noted so far."""

    group: _Group
    source: bpy.types.Action
    current: bpy.types.Action
    identifier: str
    #: motions[bone][object index]
    motions: dict[str, list[keys.KeyedMotion]]
    #: (objects, column of `motions`' rows): the objects given one action each.
    units: list[tuple[list[bpy.types.Object], int]]
    by_owner: dict
    #: (data path, index) -> "muted" / "empty": the current action's curves not read.
    unread: dict
    skipped: list
    notes: list[str]


def _read_groups(groups: list[_Group], options: Options) -> list[_GroupRead]:
    """Reads the owners of every group (the owners that share one action and slot): every
    owner of every group in one :func:`keys.read_many` call (one read of all their curves, one
    polyscrew call), then per group one bake for the whole group when every object has the
    same key poses for every owner, else one per object (`units`)."""
    heads, requests = [], []
    for group in groups:
        head = _group_head(group, options)
        heads.append((head, len(requests)))
        requests += [
            keys.Request(
                owners.Owner(obj, bone), options.closed, action=head.read_from, slot=head.source_slot,
                extend_to=options.frame_range, fcurves=head.by_owner.get(bone, []), turns=options.turns,
            )
            for bone in group.bones
            for obj in group.objects
        ]
    got = keys.read_many(requests, cache={})  # (objects sharing curves read them once)
    ends = [start for _, start in heads[1:]] + [len(requests)]
    return [_read_group(group, head, got[start:end]) for group, (head, start), end in zip(groups, heads, ends)]


class _Head(NamedTuple):
    """What the bake of a group reads from (:func:`_group_head`)."""

    current: bpy.types.Action
    identifier: str
    source: bpy.types.Action
    source_slot: str
    #: Whether the current action is a result edited since it was made.
    edited: bool
    #: The action the keys are read from (None: the current one).
    read_from: bpy.types.Action | None
    by_owner: dict
    #: The curves of `read_from` (or the current action) listed.
    listed: list


def _group_head(group: _Group, options: Options) -> _Head:
    """What the bake of `group` reads from."""
    first = group.objects[0]
    current = first.animation_data.action
    identifier = channels.slot_identifier(first)
    source, source_slot, edited = source_action(current, identifier, "smooth", options.smooth_result)
    read_from = None if source is current else source
    # The objects share the action: its curves grouped by owner once (not scanned per bone).
    listed = channels.object_fcurves(first) if read_from is None else channels.action_fcurves(read_from, source_slot)
    return _Head(current, identifier, source, source_slot, edited, read_from, owners.curves_by_owner(listed), listed)


def _read_group(group: _Group, head: _Head, got: list) -> _GroupRead:
    """One group read from `head` and `got`, the key motions (or errors) of its owners, bone
    after bone and for each bone object after object."""
    current, identifier, source, read_from, by_owner, listed = (
        head.current, head.identifier, head.source, head.read_from, head.by_owner, head.listed
    )
    notes = []
    if head.edited:
        notes.append(
            f"{_names([o.name for o in group.objects])}: '{current.name}' was edited after Smooth Motion made it "
            "(keys moved, added or deleted): smoothed the edited keys and kept them (Revert returns to "
            "them, a second Revert to the original)"
        )
    motions: dict[str, list[keys.KeyedMotion]] = {}
    skipped = []
    motion = iter(got)
    for bone in group.bones:
        row = [next(motion) for _ in group.objects]
        refused = next(((obj, m) for obj, m in zip(group.objects, row) if isinstance(m, SmoothError)), None)
        if refused is not None:  # the bone is skipped, with the first refusal's message
            skipped.append((owners.Owner(refused[0], bone), str(refused[1])))
        else:
            motions[bone] = row
    read = _GroupRead(group, source, current, identifier, motions, [], by_owner, {}, skipped, notes)
    if not motions:
        return read
    shared = all(_same_motion(row[0], m) for row in motions.values() for m in row[1:])
    if shared:
        read.units = [(group.objects, 0)]
    else:
        read.units = [([obj], i) for i, obj in enumerate(group.objects)]
        notes.append(
            f"{', '.join(o.name for o in group.objects)} share action '{current.name}' but differ in "
            "unkeyed channels or rotation mode: each got its own smoothed action"
        )
    # Curves of the current action that were not read (muted, keyless): a baked channel
    # replaces them, which the report tells.
    read.unread = {
        (fc.data_path, fc.array_index): "muted" if fc.mute else "empty"
        for fc in (listed if read_from is None else channels.action_fcurves(current, identifier))
        if fc.mute or len(fc.keyframe_points) == 0
    }
    return read


def _bake_groups(
    groups: list[_Group],
    options: Options,
    budget: list[int],
    progress: Callable[[int, int], None] | None = None,
    total: int = 0,
) -> tuple[list[ActionBake], list, list[str]]:
    """Reads and samples every group's owners: every group read, then every owner planned
    (in order, against `budget`), then sampled together (:func:`_sample_plans`: one polyscrew
    call per rotation mode), then each group's action bakes made, its skipped owners with
    their messages and its notes told in the order one group after another would give them.
    `progress(done, total)` as each group is done."""
    reads = _read_groups(groups, options)
    # (read, objects, owner, motion, plan or the error refusing it) per owner, in order
    planned = []
    for read in reads:
        for objects, column in read.units:
            for bone, row in read.motions.items():
                owner = owners.Owner(objects[0], bone)
                try:
                    plan = _plan(owner, row[column], options, budget, read.by_owner.get(bone, []))
                except SmoothError as err:
                    plan = err
                planned.append((read, objects, owner, row[column], plan))
    plans = [p for *_, p in planned if isinstance(p, _Plan)]
    sampled = iter(_sample_plans(plans, options))
    bakes, skipped, notes = [], [], []
    finished = []  # (read, objects, owner, motion, bake) per owner baked, in order
    for read, objects, owner, motion, plan in planned:
        try:
            if isinstance(plan, SmoothError):
                raise plan
            channels_of = next(sampled)
            if isinstance(channels_of, SmoothError):
                raise channels_of
            finished.append((read, objects, owner, motion, _finish(plan, channels_of)))
        except SmoothError as err:
            read.skipped.append((owner, str(err)))
    departures = _departure_notes([(owner, motion, part) for _, _, owner, motion, part in finished], options)
    by_unit: dict[tuple[int, int], list[Baked]] = {}
    for (read, objects, owner, motion, part), departed in zip(finished, departures):
        by_unit.setdefault((id(read), id(objects)), []).append(part)
        if motion.kept:
            read.notes.append(f"{owner.name}: kept {'; '.join(motion.kept)}")
        if motion.removed:
            read.notes.append(f"{owner.name}: removed {'; '.join(motion.removed)}")
        if departed is not None:
            read.notes.append(departed)
        for prop, index in part.written if read.unread else ():
            what = read.unread.get((owner.path(prop), index))
            if what is not None:
                read.notes.append(f"{owner.name}: {what} curve {prop}[{index}] replaced by the baked one")
    for i, read in enumerate(reads):
        for objects, _ in read.units:
            parts = by_unit.get((id(read), id(objects)))
            if parts:
                bakes.append(ActionBake(objects, parts, read.source, read.current, read.identifier))
        skipped += read.skipped
        notes += read.notes
        if progress is not None:
            progress(i + 1, total)
    return bakes, skipped, notes


def _departure_notes(
    items: list[tuple[owners.Owner, keys.KeyedMotion, Baked]], options: Options
) -> list[str | None]:
    """Per `(owner, motion, bake)` of `items`, the report's line when the bake departs from
    Blender's playback of its source by more than :data:`intent.DEPARTURE_DEGREES` or
    :data:`intent.DEPARTURE_FRACTION` of its size at its baked frames; None when it does not,
    or when the source's curves cannot be played (:attr:`keys.KeyedMotion.source` is None).
    Every owner measured in one `polyscrew` call (:func:`intent.departures`)."""
    measured = [(owner, motion, part) for owner, motion, part in items if motion.source is not None]
    found = iter(
        intent.departures([
            (
                motion.source, motion.size, part.frames, part.values.get("location"),
                part.values[keys.rotation_path(motion.rotation_mode)], motion.frames,
                part.played if part.motion.source is motion.source else None,  # (rows of this playback only)
            )
            for _, motion, part in measured
        ])
    )
    extra = []
    if options.method == "FEATURE" and options.approximate:
        extra.append("Approximate Keys passes near the selected keys")
    elif options.method != "FEATURE" and options.scheme != "four_point":
        label = {identifier: name for identifier, name, _ in SCHEMES}.get(options.scheme, options.scheme)
        extra.append(f"the {label} scheme cuts inside the keys")
    return [
        None if motion.source is None
        else intent.departure_note(owner.name, next(found), motion.size, [*motion.causes, *extra])
        for owner, motion, _ in items
    ]


@dataclass
class Smoothed(Outcome):
    """What Smooth Motion did: every object given a new action is among `owners`, selected or
    not (a linked duplicate sharing the action changes too)."""

    #: The objects given a new action.
    objects: list[bpy.types.Object] = field(default_factory=list)
    #: How many of the owners are bones.
    bones: int = 0


def _in_order(selection: list, skipped: list) -> list[str]:
    """The messages of skipped (owner, message) pairs, in the order of `selection`."""
    order = {owners.as_owner(item): i for i, item in enumerate(selection)}
    return [message for owner, message in sorted(skipped, key=lambda pair: order.get(pair[0], len(order)))]


def prepare(selection: Iterable, options: Options) -> tuple[list[ActionBake], list[str], list[str]]:
    """Reads and samples every owner (objects or :class:`owners.Owner`s; nothing changes);
    returns the action bakes, the messages of what was skipped, and notes."""
    selection = list(selection)
    groups, skipped = _action_groups(selection)
    bakes, messages, notes = _bake_groups(groups, options, [MAX_KEYS])
    return bakes, _in_order(selection, skipped + messages), notes


def smooth(
    selection: Iterable,
    options: Options,
    progress: Callable[[int, int], None] | None = None,
    strict: bool = False,
    t: transaction.Transaction | None = None,
) -> Smoothed:
    """Smooths the owners in `selection` (objects, or :class:`owners.Owner`s for bones);
    owners animated by one action get one new action, shared as the old one was.

    Owners that cannot be smoothed are skipped and left unchanged; the others are (with
    `strict`, anything skipped raises :class:`SmoothError` listing it all, before anything is
    changed). Everything is read and sampled before anything is written, and the writing is
    all or nothing (inside `t`, or a transaction of its own): a failure halfway leaves
    `bpy.data` as it was. `progress(done, total)` is called as actions are sampled and written.
    """
    selection = list(selection)
    groups, skipped = _action_groups(selection)
    total = len(groups) * 2
    bakes, messages, notes = _bake_groups(groups, options, [MAX_KEYS], progress, total)
    skipped = _in_order(selection, skipped + messages)
    if strict and skipped:
        raise SmoothError("; ".join(skipped))
    selected = {owners.as_owner(item).obj.name for item in selection}
    sharing = sorted({obj.name for b in bakes for obj in b.objects} - selected)
    if sharing:
        notes.append(
            f"{_names(sharing)} share{'s' if len(sharing) == 1 else ''} the smoothed action (linked "
            "duplicates): their motion changed too"
        )
    resmoothed = [b.obj.name for b in bakes if b.current is not b.source]
    joined = [p for b in bakes for p in b.parts if p.join is not None]
    # every owner the range changed: linked duplicates sharing the action too
    joined_names = [owners.Owner(obj, p.owner.bone).name for b in bakes for p in b.parts if p.join for obj in b.objects]
    if joined:
        first = joined[0].join
        start = first.start if first.before else options.frame_range[0]
        end = first.end if first.after else options.frame_range[1]
        moved = f" (moved its {' and '.join(first.moved)}: a span eased by a Blender preset cannot be cut)"
        notes.append(
            f"smoothed frames {start:g} to {end:g} of {_names(joined_names)}"
            f"{moved if first.moved else ''}; the keys outside the range kept as they were"
        )
    if resmoothed:
        notes.append(f"re-smoothed the original keys of {_names(resmoothed)} (replacing the earlier result)")
    if options.key_mode == "REDUCED" and bakes:
        from . import reduce

        notes.append(reduce.reduce_bakes(bakes, options.key_distance, options.key_angle))
    dense = pack_dense(p for b in bakes for p in b.parts)  # (every owner's curves in one pass)
    actions = action_groups.write_all(bakes, lambda b, t_: write(b, t_, dense), t, progress, len(groups), total)
    return Smoothed(
        actions=actions,
        objects=[obj for b in bakes for obj in b.objects],
        owners=[owners.Owner(obj, p.owner.bone).name for b in bakes for p in b.parts for obj in b.objects],
        bones=sum(len(b.objects) for b in bakes for p in b.parts if p.owner.bone),
        skipped=skipped,
        notes=notes,
    )


def source_of(obj: bpy.types.Object) -> bpy.types.Action | None:
    """The action `obj` had before it was smoothed, or None when its action is not a smoothed one."""
    adt = obj.animation_data
    if adt is None or adt.action is None:
        return None
    source = adt.action.get(SOURCE_KEY)
    return source if isinstance(source, bpy.types.Action) else None


def revert(objects: Iterable[bpy.types.Object], t: transaction.Transaction) -> tuple[list[bpy.types.Object], list[str]]:
    """Gives each of `objects` whose action Smooth Motion made (others are passed over), and
    every object sharing that action, back the action they had before smoothing (bones
    included: the whole action), inside the transaction `t`. Each smoothed copy is removed once
    `t` commits and nothing uses it, unless the animator edited it since it was made: that one
    is kept with a fake user. Returns the objects given their original back and the names of
    the edited results kept.

    One pass over `objects` for their actions, slots and originals, one over the scene's
    objects for those sharing them (:func:`users_by_slot`), each result's edit check once, and
    the unused results removed in one :func:`remove_unused` (per object, these made Revert of
    many objects grow faster than the objects)."""
    # (action pointer, slot identifier) -> (smoothed action, identifier, original, first object)
    found: dict[tuple[int, str], tuple] = {}
    for obj in objects:
        adt = obj.animation_data
        smoothed = adt.action if adt is not None else None
        source = smoothed.get(SOURCE_KEY) if smoothed is not None else None
        if isinstance(source, bpy.types.Action):
            identifier = channels.slot_identifier(obj)
            found.setdefault((smoothed.as_pointer(), identifier), (smoothed, identifier, source, obj))
    users = users_by_slot({pointer for pointer, _ in found})  # (before any is reverted)
    reverted, kept, removals = [], [], []
    for key, (smoothed, identifier, source, obj) in found.items():
        source_slot = smoothed.get(SOURCE_SLOT_KEY, "")
        for other in users.get(key) or [obj]:
            t.assign_action(other, source, source_slot)
            reverted.append(other)
        t.set(source, "use_fake_user", bool(smoothed.get(SOURCE_FAKE_USER_KEY, False)))
        if was_edited(smoothed, identifier):
            t.set(smoothed, "use_fake_user", True)  # an edit is never thrown away
            kept.append(smoothed.name)
        else:
            removals.append(smoothed)
    t.on_commit(lambda: remove_unused(removals))
    return reverted, kept
