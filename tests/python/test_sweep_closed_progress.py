"""`polyscrew.sweep_closed(..., progress=...)`: the closed boundary takes seconds, so a
caller (Blender's progress bar, a pipeline with a deadline) hears how far it is and can stop
it: the sweep runs on a thread of its own while the calling thread calls `progress(fraction)`
about ten times a second; what the callable raises, or Ctrl-C, stops the sweep and is raised.
The Rust test `progress_is_reported_and_a_stop_is_honoured` shows the stop leaves the rest of
the work undone.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import polyscrew
import pytest

sys.path.insert(0, str(Path(__file__).resolve().parent))
from test_sweep_closed import LONG  # noqa: E402
from test_sweep_tolerance import CUBE_T, CUBE_V  # noqa: E402

# About 2.6 s on these machines: a dozen or more calls.
TOLERANCE = 0.02


def test_progress_is_called_rising_to_the_end_and_changes_nothing():
    seen: list[float] = []
    v, t, info = polyscrew.sweep_closed(CUBE_V, CUBE_T, LONG, tolerance=TOLERANCE, info=True, progress=seen.append)
    print(f"\n{len(seen)} calls: {seen[:3]} ... {seen[-3:]}; {len(t)} triangles")
    assert len(seen) >= 3
    assert all(isinstance(f, float) and 0.0 <= f <= 1.0 for f in seen)
    if info["attempts"] == 1:  # a second grid starts from 0 again
        assert all(b >= a for a, b in zip(seen, seen[1:])), seen
    assert seen[-1] > seen[0]
    plain_v, plain_t = polyscrew.sweep_closed(CUBE_V, CUBE_T, LONG, tolerance=TOLERANCE)
    assert np.array_equal(v, plain_v) and np.array_equal(t, plain_t)


class Stop(Exception):
    pass


def test_what_progress_raises_stops_the_sweep_and_is_raised():
    seen: list[float] = []
    stop = Stop("enough")

    def progress(fraction: float) -> None:
        seen.append(fraction)
        if fraction > 0.2:
            raise stop

    with pytest.raises(Stop) as raised:
        polyscrew.sweep_closed(CUBE_V, CUBE_T, LONG, tolerance=TOLERANCE, progress=progress)
    assert raised.value is stop
    # not called again once it raised
    assert seen[-1] > 0.2 and all(f <= 0.2 for f in seen[:-1])


CTRL_C = f"""
import _thread, json, signal
import numpy as np
# Python's own Ctrl-C handler, which a Python started with SIGINT ignored (a background job
# of a non-interactive shell, as CI may run it) does not install: interrupt_main then does
# nothing
signal.signal(signal.SIGINT, signal.default_int_handler)
import polyscrew
LONG = np.array({np.asarray(LONG).tolist()!r})
CUBE_V, CUBE_T = np.array({np.asarray(CUBE_V).tolist()!r}), np.array({np.asarray(CUBE_T).tolist()!r})
seen = []
def progress(fraction):
    seen.append(fraction)
    if len(seen) == 2:
        _thread.interrupt_main()  # as Ctrl-C does: the next check of signals raises
try:
    polyscrew.sweep_closed(CUBE_V, CUBE_T, LONG, tolerance={TOLERANCE}, progress=progress)
    print(json.dumps({{"stopped": False, "calls": len(seen)}}))
except KeyboardInterrupt:
    print(json.dumps({{"stopped": True, "calls": len(seen)}}))
"""


def test_ctrl_c_stops_the_sweep():
    """In a fresh interpreter, with Python's Ctrl-C handler installed (the test process may
    have been started with SIGINT ignored), so the test's process keeps its own handlers."""
    run = subprocess.run([sys.executable, "-c", CTRL_C], capture_output=True, text=True, timeout=600)
    assert run.returncode == 0, run.stderr[-3000:]
    got = json.loads(run.stdout.strip().splitlines()[-1])
    assert got["stopped"] and got["calls"] in (2, 3), got


def test_a_progress_that_is_not_callable_is_refused_before_any_work():
    with pytest.raises(TypeError, match=r"^sweep_closed: progress: expected a callable or None, got int$"):
        polyscrew.sweep_closed(CUBE_V, CUBE_T, LONG, tolerance=TOLERANCE, progress=3)
    # None is no progress
    v, t = polyscrew.sweep_closed(CUBE_V, CUBE_T, LONG, tolerance=0.05, progress=None)
    assert len(t) > 0
