"""Build Swept Region on open meshes at Closed Volume's default (issue 29 follow-up): the pure
decision, without Blender.

- `sweep_report.closed_choice`: Closed Volume at its default gives the closed meshes the closed
  boundary and the open ones the open sweep; turned on by the animator, an open mesh refuses
  the run, naming it and how to get the open sweep; off, every object gets the open sweep;
- `sweep_report.fallback_note`: one warning line naming every object that fell back, and why;
- the decision agrees with the core's: `sweep_report.is_closed` of a mesh is True exactly when
  `polyscrew.sweep_closed_work` does not refuse it as not closed (a closed box, the same box
  inside out, with a face missing, a triangle flipped, a fin on an edge, a plane), so no mesh
  the add-on sends to the closed boundary is refused there, and none it sends to the open
  sweep could have had one;
- the summary names the open sweep's figures beside the closed boundaries'.
"""

from __future__ import annotations

import numpy as np
import polyscrew
import pytest

from pure_layer import module
from test_sweep import box

sweep_report = module("sweep_report")  # the add-on's pure layer: no bpy

NAMES = ["Cube", "Plane", "Cone.001"]
CLOSED = [True, False, False]


def test_at_the_default_the_open_meshes_get_the_open_sweep():
    kinds, refusal = sweep_report.closed_choice(NAMES, CLOSED, closed=True, fallback=True)
    assert kinds == [True, False, False] and refusal is None
    note = sweep_report.fallback_note([n for n, k in zip(NAMES, kinds) if not k])
    assert note.startswith("Plane, Cone.001: the meshes are not closed, built the open sweep (Closed Volume needs a "
                           "closed mesh")
    assert "Cube" not in note
    assert sweep_report.fallback_note(["Plane"]).startswith("Plane: the mesh is not closed, built the open sweep")
    # Every mesh closed: all closed boundaries, nothing to say.
    assert sweep_report.closed_choice(NAMES, [True] * 3, True, True) == ([True] * 3, None)
    assert sweep_report.fallback_note([]) is None
    # Every mesh open: all open sweeps.
    assert sweep_report.closed_choice(NAMES, [False] * 3, True, True) == ([False] * 3, None)


def test_closed_volume_turned_on_refuses_open_meshes_naming_them():
    kinds, refusal = sweep_report.closed_choice(NAMES, CLOSED, closed=True, fallback=False)
    assert refusal is not None
    assert refusal.startswith("Plane, Cone.001: the meshes are not closed")
    assert "Cube" not in refusal
    assert refusal.endswith("Closed Volume needs a closed mesh: turn it off for the open sweep")
    _, one = sweep_report.closed_choice(["Cube", "Plane"], [True, False], True, False)
    assert one.startswith("Plane: the mesh is not closed (every edge in two faces")
    assert sweep_report.closed_choice(NAMES, [True] * 3, True, False) == ([True] * 3, None)


def test_closed_volume_off_gives_every_object_the_open_sweep():
    # (The meshes are not looked at: compute_all passes no closedness then.)
    assert sweep_report.closed_choice(NAMES, [], closed=False, fallback=False) == ([False] * 3, None)
    assert sweep_report.closed_choice(NAMES, [], closed=False, fallback=True) == ([False] * 3, None)


def _meshes():
    v, t = box()
    plane_v = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], float)
    flipped = t.copy()
    flipped[3] = flipped[3, [0, 2, 1]]
    fin_v = np.vstack([v, [[0.0, 0.0, 2.0]]])
    edge = t[0, :2]  # a third triangle on the box's first edge
    return {
        "box": (v, t, True),
        "box inside out": (v, t[:, [0, 2, 1]], True),
        "box with a face missing": (v, t[:-1], False),
        "box with a triangle flipped": (v, flipped, False),
        "box with a fin on an edge": (fin_v, np.vstack([t, [[edge[0], edge[1], 8]]]), False),
        "plane": (plane_v, np.array([[0, 1, 2], [0, 2, 3]]), False),
    }


@pytest.mark.parametrize("name", sorted(_meshes()))
def test_the_decision_is_the_cores(name):
    v, t, expected = _meshes()[name]
    poses = np.stack([np.eye(4), np.eye(4)])
    poses[1, :3, 3] = (0.5, 0.2, 0.1)
    try:
        polyscrew.sweep_closed_work(v, t, poses, tolerance=0.05)
        core = True
    except ValueError as err:
        assert "not closed" in str(err), err
        core = False
    assert sweep_report.is_closed(t) == core == expected


def test_the_summary_names_the_open_sweep_beside_closed_boundaries():
    text = sweep_report.summary(2, 5000, 1.0, 900.0, 0.00866, 0.0061, 20.0, None, cell=0.0108,
                                open_sweep=(1, 0.00283, 0.00278))
    assert "closed boundary, tolerance 0.00866 (vertices within 0.0061 of the swept boundary; cell 0.0108)" in text
    assert "; open sweep of 1 object(s): tolerance 0.00283 (met within 0.00278); area 20" in text
    assert "volume" not in text
    assert "open sweep" not in sweep_report.summary(1, 10, 0.1, 1.0, 0.0087, 0.006, 1.0, 1.0, cell=0.01)
