# SPDX-License-Identifier: GPL-3.0-or-later
"""What the writing operators report, shared: the outcome of a run over many owners and the
words for many names."""

from __future__ import annotations

from dataclasses import dataclass, field


@dataclass
class Outcome:
    """What a writing operator did over many owners (`ops/pipeline.report_outcome` reports it):
    Smooth Motion's, Remove Noise's and Reduce Keys' results add their own figures."""

    #: The new actions (Blender's `Action`s; none: nothing was written).
    actions: list
    #: The owners whose motion changed (objects and bones), by name.
    owners: list[str]
    #: Why each owner left unchanged was skipped.
    skipped: list[str]
    #: Other things worth telling (what was kept, results re-run, shared actions).
    notes: list[str] = field(default_factory=list)


def _names(names: list[str], limit: int = 3) -> str:
    """"A, B, C and 297 more": a readable list of many names."""
    if len(names) <= limit:
        return ", ".join(names)
    return f"{', '.join(names[:limit])} and {len(names) - limit} more"


def summary(names: list[str], limit: int = 3) -> str:
    """The report's list of names: the first `limit` and how many more."""
    return _names(sorted(names), limit)
