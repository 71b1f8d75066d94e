"""Counting what an operator reads from Blender (issue 27: every source curve read once).

The add-on reads Blender data only through `bulk.get` (a test in test_read_count.py checks
that no other module calls `foreach_get`). :func:`counting_reads` wraps it for the duration of
a `with` block and records, for every F-curve whose keys were read, how many times each
keyframe property was read: ``reads[(action name, data_path, array_index, property)]``.
"""

from __future__ import annotations

import contextlib
from collections import Counter

from conftest import addon_module


@contextlib.contextmanager
def counting_reads():
    """`with counting_reads() as reads:` ... ; `reads` is a Counter of keyframe-property reads
    per F-curve (other collections, vertices for instance, are counted under their RNA type)."""
    bulk = addon_module("blender.bulk")
    original = bulk.get
    reads: Counter = Counter()

    def get(collection, attr, out):
        owner = getattr(collection, "data", None)
        if owner is not None and owner.rna_type.identifier == "FCurve":
            key = (owner.id_data.name, owner.data_path, owner.array_index, attr)
        else:
            key = (collection.rna_type.identifier if hasattr(collection, "rna_type") else type(collection).__name__, attr)
        reads[key] += 1
        return original(collection, attr, out)

    bulk.get = get
    try:
        yield reads
    finally:
        bulk.get = original


def read_more_than_once(reads: Counter) -> dict:
    """The F-curve properties read more than once: {(action, path, index, property): count}."""
    return {key: n for key, n in reads.items() if len(key) == 4 and n > 1}
