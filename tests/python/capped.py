"""Running polyscrew calls in a child process under a 4 GB address-space cap (issue 15).

The child sets `RLIMIT_AS` before importing anything, runs the code it is given and prints
one JSON line per `report(...)`: the exception type and message of a `ValueError`,
`TypeError` or `MemoryError`, or whether the result is finite. Anything else (a signal, an
abort, a `PanicException`, which is a `BaseException`) ends the child abnormally, and
`run_capped` fails the test with its output.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

#: The address-space cap of the child processes: 4 GB.
CAP = 4 << 30

PRELUDE = f"""
import json, math, resource, sys
resource.setrlimit(resource.RLIMIT_AS, ({CAP}, {CAP}))
sys.path.insert(0, {str(Path(__file__).parent)!r})
import numpy as np
import polyscrew as ps

def finite(value):
    '''Whether every number in a result (arrays, tuples, a Screw, a fit) is finite.'''
    if isinstance(value, (tuple, list)):
        return all(finite(v) for v in value)
    if isinstance(value, np.ndarray):
        return bool(np.isfinite(value).all()) if value.dtype.kind in "fc" else True
    if isinstance(value, (float, int)):
        return math.isfinite(value)
    if isinstance(value, ps.Screw):
        return finite((value.axis, value.point, value.angle, value.slide))
    if isinstance(value, ps.AngularVelocityFit):
        return finite((value.quaternions, value.omega, value.key_quaternions, value.frame_times,
                       value.fit_error, value.fragment_errors, value.energy))
    return True

def report(call):
    '''Runs `call` and prints what came of it as one JSON line.'''
    try:
        out = call()
    except (ValueError, TypeError, MemoryError) as e:
        # the builtin kind (ValueError, TypeError, MemoryError): polyscrew's own classes
        # (polyscrew.InvalidArgument, ...) derive from it
        kind = next(c.__name__ for c in type(e).__mro__ if c.__module__ == "builtins")
        print(json.dumps({{"error": kind, "message": str(e)}}), flush=True)
        return None
    print(json.dumps({{"finite": finite(out)}}), flush=True)
    return out
"""

#: Child code: `need(call)`, the bytes `call` says it would need, read from its refusal with a
#: memory budget of 0 (what `test_limits.py` and `test_bad_input_memory.py` measure against).
NEED = r"""
import re
UNITS = {"B": 1, "kB": 1e3, "MB": 1e6, "GB": 1e9, "TB": 1e12, "PB": 1e15, "EB": 1e18}

def need(call):
    '''The bytes `call` says it would need, from its refusal with a budget of 0.'''
    old = ps.set_memory_budget(0)
    try:
        call()
    except ValueError as e:
        m = re.search(r"would need ([0-9.]+) (B|kB|MB|GB|TB|PB|EB), over the memory budget", str(e))
        assert m, str(e)
        return float(m.group(1)) * UNITS[m.group(2)]
    finally:
        ps.set_memory_budget(old)
    raise AssertionError("not refused with a budget of 0")
"""

#: Child code: `keys(n, seed)`, n rigid keys turning about z along a noisy line.
KEYS = r"""
def keys(n, seed=0):
    rng = np.random.default_rng(seed)
    out = np.tile(np.eye(4), (n, 1, 1))
    a = rng.uniform(0, 2, n)
    out[:, 0, 0] = out[:, 1, 1] = np.cos(a)
    out[:, 0, 1], out[:, 1, 0] = -np.sin(a), np.sin(a)
    out[:, :3, 3] = rng.normal(size=(n, 3)) + np.arange(n)[:, None]
    return out
"""


def run_capped(code: str, timeout: float = 600) -> list[dict]:
    """Runs `code` after the prelude in a capped child; returns its `report` lines. Fails
    unless the child exits normally (status 0)."""
    proc = subprocess.run(
        [sys.executable, "-c", PRELUDE + code], capture_output=True, text=True, timeout=timeout
    )
    assert proc.returncode == 0, (
        f"child ended with status {proc.returncode}\n{proc.stdout[-3000:]}\n{proc.stderr[-3000:]}"
    )
    return [json.loads(line) for line in proc.stdout.splitlines() if line.startswith("{")]
