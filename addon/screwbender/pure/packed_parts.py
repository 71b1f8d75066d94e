# SPDX-License-Identifier: GPL-3.0-or-later
"""Parts of packed F-curve keys (:class:`curves.Packed`): one curve alone, several joined.

Pure (numpy, no bpy): many owners' curves are read in one `curves.read` call and each owner
gets its part of the packed arrays, identical to reading its curves alone (every property of
a curve is packed per curve: which properties are read depends on that curve's keys only).
"""

from __future__ import annotations

import numpy as np

#: What the packed keys hold per key.
PER_KEY = ("co", "handle_left", "handle_right", "interpolation", "easing", "back", "amplitude", "period")


def one(packed, c: int):
    """Curve `c` of `packed` alone (views of its arrays)."""
    lo, hi = int(packed.offsets[c]), int(packed.offsets[c + 1])
    return type(packed)(
        offsets=np.array([0, hi - lo], dtype=np.int64),
        extrapolation=[packed.extrapolation[c]],
        cycles=[packed.cycles[c]] if packed.cycles else [None],
        **{name: getattr(packed, name)[lo:hi] for name in PER_KEY},
    )


def joined(parts: list):
    """One packed set of the curves of `parts` (each packed, one or more curves), in order."""
    offsets = [np.zeros(1, dtype=np.int64)]
    start = 0
    for p in parts:
        offsets.append(start + np.asarray(p.offsets[1:], dtype=np.int64))
        start += int(p.offsets[-1])
    return type(parts[0])(
        offsets=np.concatenate(offsets),
        extrapolation=[e for p in parts for e in p.extrapolation],
        cycles=[c for p in parts for c in (p.cycles or [None] * (len(p.offsets) - 1))],
        **{name: np.concatenate([getattr(p, name) for p in parts]) for name in PER_KEY},
    )


def subset(packed, columns: list[int]):
    """The curves `columns` (indices into `packed`) of `packed`, in that order (views when
    they are consecutive)."""
    first = columns[0]
    if columns != list(range(first, first + len(columns))):
        return joined([one(packed, c) for c in columns])
    end = first + len(columns)
    lo, hi = int(packed.offsets[first]), int(packed.offsets[end])
    return type(packed)(
        offsets=np.asarray(packed.offsets[first : end + 1], dtype=np.int64) - lo,
        extrapolation=list(packed.extrapolation[first:end]),
        cycles=list(packed.cycles[first:end]) if packed.cycles else [None] * len(columns),
        **{name: getattr(packed, name)[lo:hi] for name in PER_KEY},
    )
