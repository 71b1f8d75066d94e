"""The memory the largest legitimate uses of `polyscrew` need: the module's own estimate
(what it checks against `memory_budget()`) beside the peak measured, for the figures in
`python/polyscrew/__init__.pyi` and the README.

Each case runs in a fresh Python process with glibc's mmap threshold fixed at 128 kB (so
every large block is mapped when allocated and unmapped when freed, and the resident set
follows what is live): the inputs are built, the call is made once, the peak resident set
is reset (`/proc/self/clear_refs`), the call is made again, and the growth of the peak
(`VmHWM`) over the resident set before it is the measured peak. The estimate is read from
the refusal the module gives with the budget set to 0 bytes (for `sweep`, whose output is
checked screw by screw, the body's estimate plus 48 bytes per output vertex and 36 per
output triangle: what its last check counts).

    .venv/bin/python scripts/bench/memory_footprints.py
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

SETUP = r"""
import json, re, sys
import numpy as np, polyscrew as ps
sys.path.insert(0, "scripts/bench")
from bench_shapes import bumpy_torus, spinning_playback

def keys(n, seed=1):
    rng = np.random.default_rng(seed)
    out = np.tile(np.eye(4), (n, 1, 1))
    for i in range(n):
        axis = rng.normal(size=3); axis /= np.linalg.norm(axis)
        angle = rng.uniform(0, 1.5)
        k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
        out[i, :3, :3] = np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k
        out[i, :3, 3] = rng.uniform(-2, 2, 3) + [i * 0.5, 0, 0]
    return out

def helix(n):
    s = np.arange(n) / (n - 1)
    out = np.tile(np.eye(4), (n, 1, 1))
    axis = np.array([0.3, 1.0, 0.5]); axis /= np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    for i, si in enumerate(s):
        a = 3.0 * si
        out[i, :3, :3] = np.eye(3) + np.sin(a) * k + (1 - np.cos(a)) * k @ k
        out[i, :3, 3] = [3 * np.cos(2 * np.pi * si), 3 * np.sin(2 * np.pi * si), 2 * si]
    return out

def status(field):
    for line in open("/proc/self/status"):
        if line.startswith(field + ":"):
            return int(line.split()[1]) * 1024

def estimate(call):
    old = ps.set_memory_budget(0)
    try:
        call()
    except ValueError as e:
        m = re.search(r"would need ([0-9.]+) (B|kB|MB|GB)", str(e))
        return float(m.group(1)) * {"B": 1, "kB": 1e3, "MB": 1e6, "GB": 1e9}[m.group(2)]
    finally:
        ps.set_memory_budget(old)
    return None

def measure(call):
    import time
    call()  # warm: the allocator's arenas, the module's first-call setup
    with open("/proc/self/clear_refs", "w") as f:
        f.write("5")
    before = status("VmRSS")
    start = time.process_time()
    call()
    cpu = time.process_time() - start
    return status("VmHWM") - before, cpu
"""

CASES = {
    "subdivide 1,000 keys x 8 levels (Jarek, open)": (
        "k = keys(1000)",
        "lambda: ps.subdivide(k, 'jarek', levels=8)",
    ),
    "sample 1,000 keys x 8 levels at 100,000 frames": (
        "k = keys(1000); kt = np.arange(1000) * 100.0; t = np.arange(100_000) * 1.0",
        "lambda: ps.sample(k, kt, t, levels=8)",
    ),
    "sample_channels (bake) 1,000 keys x 4 levels at 100,000 frames, XYZ": (
        "k = keys(1000); kt = np.arange(1000) * 100.0; t = np.arange(100_000) * 1.0",
        "lambda: ps.sample_channels(k, kt, t, 'XYZ', levels=4)",
    ),
    "sample 100,000 keys x 12 levels at 100,000 frames (windowed)": (
        "k = keys(100_000); kt = np.arange(100_000) * 1.0; t = np.arange(100_000) * 1.0",
        "lambda: ps.sample(k, kt, t, levels=12)",
    ),
    "sweep 100,000 triangles x 64 screws x 8 steps": (
        "v, tr = bumpy_torus(250, 200); p = helix(65)",
        "lambda: ps.sweep(v, tr, p, steps=8, tolerance=0)",
    ),
    "rotation_channels 1,000,000 rotations, XYZ": (
        "r = np.tile(np.eye(3), (1_000_000, 1, 1))",
        "lambda: ps.rotation_channels(r, 'XYZ')",
    ),
    # the largest calls the caps accept, where the caps bound time rather than memory;
    # analyse_spans' estimate is its first check's, before the inserted frames (4,982,729
    # here, 40 MB), which it checks when it has counted them
    "rotation_channels at its cap: 2**24 rotations, QUATERNION": (
        "r = np.broadcast_to(np.eye(3), (ps.MAX_ROTATIONS, 3, 3))",
        "lambda: ps.rotation_channels(r, 'QUATERNION')",
    ),
    "analyse_spans at its cap: 512 spans, each a spin": (
        "pb, f = spinning_playback(513)",
        "lambda: ps.analyse_spans(pb, f)",
    ),
}


def run(setup: str, call: str) -> dict:
    code = SETUP + setup + "\ncall = " + call + "\n" + (
        "e = estimate(call)\n"
        "if 'sweep' in " + repr(call) + ":\n"
        "    vo, to = call(); e += 48 * len(vo) + 36 * len(to)\n"
        "peak, cpu = measure(call)\n"
        "print(json.dumps({'estimate': e, 'peak': peak, 'cpu': cpu}))"
    )
    env = dict(os.environ, MALLOC_MMAP_THRESHOLD_="131072")
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True, env=env
    )
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    import polyscrew

    print(f"memory budget: {polyscrew.memory_budget() / 1e6:.0f} MB (default {polyscrew.DEFAULT_MEMORY_BUDGET})")
    print(f"{'case':72s} {'estimate':>10s} {'measured':>10s} {'CPU':>8s}")
    for name, (setup, call) in CASES.items():
        r = run(setup, call)
        estimate = "-" if r["estimate"] is None else f"{r['estimate'] / 1e6:.1f} MB"
        print(f"{name:72s} {estimate:>10s} {r['peak'] / 1e6:7.1f} MB {r['cpu']:6.2f} s")


if __name__ == "__main__":
    main()
