# SPDX-License-Identifier: GPL-3.0-or-later
"""The two ends of every writing operator's pipeline: owners grouped by the action that animates
them, and the one write of all results inside one transaction.

Smooth Motion (`bake.smooth`), Remove Noise (`denoise.remove_noise`) and Reduce Keys
(`reduce.reduce_keys`) run: :func:`by_action` (owners sharing an action and slot are one
group: linked duplicates, the bones of a rig) -> read each group's curves once -> compute (the
pure layer, `polyscrew`) -> :func:`write_all` (one new action per group, all or nothing). The
action a group reads is `bake.source_action`'s choice (the original keys under an earlier
result of the same operator, an edited result kept); the operator reports through
`ops/pipeline.py`.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterable
from dataclasses import dataclass, field
from typing import Any

import bpy

from . import channels, keys, owners, transaction


@dataclass
class Group:
    """The owners one action animates through one slot ("" before 4.4), in the order given."""

    action: bpy.types.Action
    identifier: str
    #: The owners asked for (objects or pose bones), as given (a repeated owner stays repeated).
    members: list[owners.Owner] = field(default_factory=list)


def by_action(selection: Iterable) -> tuple[list[Group], list[tuple[owners.Owner, str]]]:
    """The owners of `selection` (objects or :class:`owners.Owner`s) grouped by the action and
    slot that animate them, in the order given; and the owners refused here, with the reason
    (no active action: :func:`keys.no_action` says why, NLA strips included)."""
    groups: dict[tuple[int, str], Group] = {}
    skipped = []
    for item in selection:
        owner = owners.as_owner(item)
        adt = owner.obj.animation_data
        if adt is None or adt.action is None:
            skipped.append((owner, keys.no_action(owner.name, adt)))
            continue
        identifier = channels.slot_identifier(owner.obj)
        group = groups.get((adt.action.as_pointer(), identifier))
        if group is None:
            group = groups[adt.action.as_pointer(), identifier] = Group(adt.action, identifier)
        group.members.append(owner)
    return list(groups.values()), skipped


def write_all(
    plans: list,
    write: Callable[[Any, transaction.Transaction], bpy.types.Action],
    t: transaction.Transaction | None = None,
    progress: Callable[[int, int], None] | None = None,
    done: int = 0,
    total: int = 0,
) -> list[bpy.types.Action]:
    """`write(plan, t)` for every plan, inside `t` or one transaction of its own (all or
    nothing: a failure undoes every write); `progress(done + i + 1, total)` after each."""
    actions = []
    with contextlib.ExitStack() as stack:
        if t is None:
            t = stack.enter_context(transaction.atomic())
        for i, plan in enumerate(plans):
            actions.append(write(plan, t))
            if progress is not None:
                progress(done + i + 1, total)
    return actions
