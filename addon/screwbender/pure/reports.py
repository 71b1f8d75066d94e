# SPDX-License-Identifier: GPL-3.0-or-later
"""The words of the operators' reports that many features share."""

from __future__ import annotations


def _names(names: list[str], limit: int = 3) -> str:
    """"A, B, C and 297 more": a readable list of many names."""
    if len(names) <= limit:
        return ", ".join(names)
    return f"{', '.join(names[:limit])} and {len(names) - limit} more"


def summary(names: list[str], limit: int = 3) -> str:
    """The report's list of names: the first `limit` and how many more."""
    return _names(sorted(names), limit)
