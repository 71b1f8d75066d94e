"""How many rows (one frame each) the owners' playbacks play while an operator runs: every
`intent.Source` made is tracked, and its playback's own count (`Playback.rows_evaluated`, the
core's counter of every function that plays it) summed. Counting `Source.channels` calls no
longer sees every play since `keys.read_many` plays the key frames inside one
`polyscrew.read_owners` call."""

from __future__ import annotations

import contextlib

from conftest import addon_module


@contextlib.contextmanager
def playing_rows():
    """Yields a dict whose "rows" is, on leaving, the rows played by the playbacks of every
    `intent.Source` made inside (and "sources" how many were made)."""
    intent = addon_module("pure.intent")
    made = intent.Source.__post_init__
    sources = []

    def tracked(self, *args):
        made(self, *args)
        sources.append(self)

    counts = {"rows": 0, "sources": 0}
    intent.Source.__post_init__ = tracked
    try:
        yield counts
    finally:
        intent.Source.__post_init__ = made
        counts["rows"] = sum(s.playback.rows_evaluated for s in sources)
        counts["sources"] = len(sources)
