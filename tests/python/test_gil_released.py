"""The GIL is released during long calls (issue 15): a Python thread keeps running while the
module works.
"""

from __future__ import annotations

import threading
import time

import numpy as np
import polyscrew
import pytest

# --- The GIL is released during long calls --------------------------------------------------


def _fit():
    t = np.linspace(0.0, 1.0, 5)
    q = np.array([[np.cos(0.3 * x), 0, 0, np.sin(0.3 * x)] for x in t])
    return polyscrew.fit_angular_velocity(q, t, [0.0, 1.0], [[0, 0, 0.6], [0, 0, 0.6]])


def _points(seed):
    return np.random.default_rng(seed).normal(size=(3_000_000, 3))


# name: (inputs, made before the call is timed; the call)
LONG_CALLS = {
    "inertia_points": (lambda: (_points(0),), polyscrew.inertia_points),
    "register_points": (lambda: (_points(0), _points(1)), polyscrew.register_points),
    "rotation_channels": (lambda: (np.tile(np.eye(3), (1_500_000, 1, 1)), "XYZ"), polyscrew.rotation_channels),
    "AngularVelocityFit.sample": (lambda: (_fit(), np.linspace(0, 1, 3_000_000)), lambda fit, t: fit.sample(t)),
    "AngularVelocityFit.angular_velocity": (
        lambda: (_fit(), np.linspace(0, 1, 3_000_000)),
        lambda fit, t: fit.angular_velocity(t),
    ),
    "sample": (lambda: (np.tile(np.eye(4), (2, 1, 1)), [0.0, 1.0], np.linspace(0, 1, 1_500_000)), polyscrew.sample),
    "subdivide": (lambda: (np.tile(np.eye(4), (300, 1, 1)), "jarek", 12), polyscrew.subdivide),
}


@pytest.mark.parametrize("name", LONG_CALLS)
def test_other_threads_run_during_a_long_call(name):
    """A Python thread counting in a loop keeps counting while the call runs: the call
    released the GIL (with the GIL held it would stop for the whole call)."""
    inputs, call = LONG_CALLS[name]
    arguments = inputs()
    stop = threading.Event()
    count = [0]

    def counter():
        while not stop.is_set():
            count[0] += 1

    thread = threading.Thread(target=counter)
    thread.start()
    try:
        time.sleep(0.05)
        before, start = count[0], time.perf_counter()
        call(*arguments)
        during, elapsed = count[0] - before, time.perf_counter() - start
    finally:
        stop.set()
        thread.join()
    # Calibrate: how far the counter gets in the same time with the main thread asleep.
    stop.clear()
    count[0] = 0
    thread = threading.Thread(target=counter)
    thread.start()
    time.sleep(elapsed)
    stop.set()
    thread.join()
    alone = count[0]
    assert elapsed > 0.05, f"{name} took only {elapsed:.3f} s: too short to tell"
    assert during > 0.2 * alone, f"{name}: {during} counts during {elapsed:.3f} s, {alone} alone"
