# SPDX-License-Identifier: GPL-3.0-or-later
"""What Build Swept Region reports about a swept mesh (pure: numpy, no bpy).

- :func:`measures`: the surface area and, for a closed mesh, the enclosed volume (the
  divergence theorem: the sum over triangles of ``a . (b x c) / 6``);
- :func:`summary`: the operator's one-line report;
- :func:`closed_refusal`: whether a closed boundary's work (`polyscrew.sweep_closed_work`,
  told before the call) is too much to run inside Blender, and what to change;
- :func:`closed_choice`: which objects get the closed boundary (Closed Volume) and which the
  open sweep, decided from their meshes (:func:`is_closed`) before any work, or why the run is
  refused; :func:`fallback_note`: the warning naming the objects that got the open sweep.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: The most world-grid points a closed boundary may sample from the operator: at the rate
#: measured on issue 29's three cases at the default tolerance (docs/sweep.md: 0.6 to 0.8 CPU
#: seconds per million grid points, 20 to 66 million of them) about a minute to a minute and a
#: half of CPU; beyond it the call would run for minutes with Blender waiting.
MAX_CLOSED_GRID_POINTS = 100_000_000
#: The most dense poses a closed boundary may sample from the operator (the longest default
#: case, the smoothed torus, samples 1,230).
MAX_CLOSED_POSES = 20_000


def closed_refusal(work: dict, budget: int | None = None) -> str | None:
    """None when the closed boundary's work (`polyscrew.sweep_closed_work`'s dict: ``cell``,
    ``tolerance``, ``poses``, ``grid_points``, ``bytes``) is within
    :data:`MAX_CLOSED_GRID_POINTS` and :data:`MAX_CLOSED_POSES`, and its grids' ``bytes`` within
    `budget` (`polyscrew.memory_budget()`; None: not checked); otherwise why not and what to
    change (a coarser tolerance, or the open sweep, which takes milliseconds). Since the cell
    became three tolerances (stop 44), the body's grid, six times finer than the cell, can
    pass the budget before the world grid passes its limit."""
    grid, poses, needed = int(work["grid_points"]), int(work["poses"]), int(work["bytes"])
    over_budget = budget is not None and needed > budget
    if grid <= MAX_CLOSED_GRID_POINTS and poses <= MAX_CLOSED_POSES and not over_budget:
        return None
    asked = f"tolerance {work['tolerance']:.3g}" if work["tolerance"] > 0.0 else f"cell {work['cell']:.3g}"
    what = (f"would need {needed / 1e9:.2f} GB for its grids (the memory budget: {budget / 1e9:.2f} GB)"
            if over_budget and grid <= MAX_CLOSED_GRID_POINTS and poses <= MAX_CLOSED_POSES else
            f"would sample {grid:,} grid points over {poses:,} poses (at most {MAX_CLOSED_GRID_POINTS:,} and "
            f"{MAX_CLOSED_POSES:,}: minutes of work)")
    return (f"Closed Volume at {asked} {what}; raise the Tolerance (the work grows as its cube), shorten the "
            f"frame range, or turn Closed Volume off for the open sweep")


#: Why a mesh cannot have a closed boundary (the core's own rule: `Body::is_closed`).
NOT_CLOSED_WHY = "every edge in two faces, consistently oriented"


def _not_closed(names: list[str]) -> str:
    """``Plane: the mesh is not closed``, ``Plane, Cone.001: the meshes are not closed``."""
    return f"{', '.join(names)}: {'the mesh is' if len(names) == 1 else 'the meshes are'} not closed"


def closed_choice(names: list[str], closed_meshes: list[bool], closed: bool, fallback: bool) -> tuple[list[bool], str | None]:
    """For each object (`names`, with whether its mesh is closed: :func:`is_closed` of its
    triangles), whether it gets the closed boundary, and the refusal of the whole run (None
    when it runs).

    - `closed` False (Closed Volume off): every object gets the open sweep;
    - `closed` True and `fallback` False (the animator turned Closed Volume on): every object
      gets the closed boundary, and the run is refused, naming the open meshes and how to get
      the open sweep, when any mesh is not closed (it has no inside);
    - `closed` True and `fallback` True (Closed Volume at its default): the closed meshes get
      the closed boundary, the others the open sweep (:func:`fallback_note` names them)."""
    if not closed:
        return [False] * len(names), None
    open_names = [n for n, c in zip(names, closed_meshes) if not c]
    if open_names and not fallback:
        return [True] * len(names), (f"{_not_closed(open_names)} ({NOT_CLOSED_WHY}); Closed Volume needs a closed "
                                     "mesh: turn it off for the open sweep")
    return list(closed_meshes), None


def fallback_note(names: list[str]) -> str | None:
    """The warning naming the objects that got the open sweep at Closed Volume's default
    (:func:`closed_choice`), in one line; None when there are none."""
    if not names:
        return None
    return f"{_not_closed(names)}, built the open sweep (Closed Volume needs a closed mesh: {NOT_CLOSED_WHY})"


def over_tolerance_note(over: list[tuple[str, float, float, str | None]]) -> str | None:
    """The warning for the closed boundaries whose bound is over their Tolerance: for each,
    `(name, tolerance, bound, reason)`, in one line; `reason` why no finer grid was tried
    (`polyscrew.sweep_closed`'s ``finer_refused``: its memory, saying what to change), or None
    when the finest grid was contoured and still missed it. None when there are none. The
    meshes are kept: closed, within their bounds."""
    if not over:
        return None

    def why(reason: str | None) -> str:
        return f"the finer grid was not tried: {reason}" if reason else "after the finest grid"

    each = "; ".join(f"{name} is within {bound:.3g} of the swept boundary, over the Tolerance {tolerance:.3g} "
                     f"({why(reason)})" for name, tolerance, bound, reason in over)
    return f"Closed Volume: {each}. Kept as made: closed, within that bound"


@dataclass
class Measures:
    """Area (sum of the triangles' areas) and volume (None when the mesh is not closed)."""

    area: float
    volume: float | None
    closed: bool


def is_closed(triangles: np.ndarray) -> bool:
    """Whether every edge of the triangles is used exactly twice, once in each direction
    (closed and consistently oriented).

    Each directed edge (a, b) is packed into one integer a n + b (n above every index), so
    the check is two 1-D sorts: no repeated forward edge, and the reversed edges sort to the
    forward ones (a row-wise `np.unique(axis=0)` took 28 ms of Build Swept Region's 34 ms per
    object on a 20,000-triangle result; docs/performance.md)."""
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    if len(t) == 0:
        return False
    t = t - t.min()  # (indices from 0: a n + b is then one-to-one and sorts as the pairs)
    n = int(t.max()) + 1
    start, end = t.ravel(), t[:, [1, 2, 0]].ravel()
    forward = np.sort(start * n + end)
    if np.any(forward[1:] == forward[:-1]):
        return False
    return bool(np.array_equal(forward, np.sort(end * n + start)))


def measures(vertices: np.ndarray, triangles: np.ndarray) -> Measures:
    """The area of the triangles and, when they close up (:func:`is_closed`), their volume."""
    v = np.asarray(vertices, dtype=np.float64).reshape(-1, 3)
    t = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    a, b, c = v[t[:, 0]], v[t[:, 1]], v[t[:, 2]]
    area = float(0.5 * np.linalg.norm(np.cross(b - a, c - a), axis=1).sum())
    closed = is_closed(t)
    volume = float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0) if closed else None
    return Measures(area, volume, closed)


def summary(objects: int, triangles: int, seconds: float, sweep_ms: float, tolerance: float, bound: float,
            area: float, volume: float | None, cell: float = 0.0, attempts: int = 1,
            open_sweep: tuple[int, float, float] | None = None) -> str:
    """``Swept 1 object(s): 6536 triangles in 0.05 s (sweep 2.1 ms); tolerance 0.00173 (met
    within 0.00164); area 12.3; volume 5.08`` (volume only for a closed result). A closed
    boundary (`cell` > 0) names the tolerance its vertices meet (when it was given one) and its
    cell: ``closed boundary, tolerance 0.00866 (vertices within 0.0061 of the swept boundary;
    cell 0.0108)``, and a second grid when the first did not meet the tolerance. `open_sweep`:
    (objects, tolerance, bound) of the objects that got the open sweep beside closed
    boundaries (:func:`closed_choice`), named after them: ``; open sweep of 1 object(s):
    tolerance 0.00283 (met within 0.00278)``."""
    text = f"Swept {objects} object(s): {triangles} triangles in {seconds:.2f} s (sweep {sweep_ms:.1f} ms)"
    if cell > 0.0:
        grids = f", {attempts} grids" if attempts > 1 else ""
        if tolerance > 0.0:
            text += (f"; closed boundary, tolerance {tolerance:.3g} (vertices within {bound:.3g} of the swept "
                     f"boundary; cell {cell:.3g}{grids})")
        else:
            text += f"; closed boundary, cell {cell:.3g} (vertices within {bound:.3g} of the swept boundary)"
    elif tolerance > 0.0:
        text += f"; tolerance {tolerance:.3g} (met within {bound:.3g})"
    if open_sweep is not None:
        count, open_tolerance, open_bound = open_sweep
        text += f"; open sweep of {count} object(s): tolerance {open_tolerance:.3g} (met within {open_bound:.3g})"
    text += f"; area {area:.6g}"
    if volume is not None:
        text += f"; volume {volume:.6g}"
    return text
