"""Issue 27, item 4: no operator grows faster than linearly. What grew as the owners squared
is counted here (wrappers in the test), never timed (the growth itself:
scripts/bench/bench_floor.py's exponents).

- Smooth Motion grouped its owners by action with a list's `in` per owner: every bone of a
  rig compared with the bones before it, every object sharing an action (linked duplicates)
  with the objects before it: bones x bones and duplicates x duplicates comparisons (on
  5894662: 40 bones and 30 duplicates, 1,793 list elements scanned; 2,000 duplicates took
  43 ms to group, 500 took 3.8 ms).
"""

from __future__ import annotations

import pytest

import bake_helpers as h
from conftest import addon_module
from test_speed_smooth import many


class _Scanned(list):
    """A list that counts the elements its `in` compares (all of them when the item is not
    there, up to the item when it is)."""

    scanned = 0

    def __contains__(self, item) -> bool:
        for i, x in enumerate(self):
            if x == item:
                _Scanned.scanned += i + 1
                return True
        _Scanned.scanned += len(self)
        return False


@pytest.fixture
def scanned_groups(monkeypatch):
    """`bake._Group` made with lists that count the elements their `in` scans."""
    bake = addon_module("blender.bake")
    made = bake._Group
    monkeypatch.setattr(bake, "_Group", lambda objects, bones: made(_Scanned(objects), _Scanned(bones)))
    _Scanned.scanned = 0
    return bake


def test_grouping_owners_by_action_scans_no_list(scanned_groups):
    """A rig's 40 bones and 30 linked duplicates sharing one action (and one duplicate not
    selected), some owners given twice: every group lists its objects and bones once each, in
    the order given (the unselected duplicate last), without a scan of the owners grouped so
    far (on 5894662: 1,793 elements scanned, bones x bones and duplicates x duplicates)."""
    bake, owners, channels = scanned_groups, addon_module("blender.owners"), addon_module("blender.channels")
    rig = h.new_object("Rig", "EMPTY")
    rig.keyframe_insert("location", frame=1)  # (grouping needs an action, not the bones' curves)
    bones = [f"Bone{i:03d}" for i in range(40)]
    shared = many(31)
    for obj in shared[1:]:
        channels.assign(obj, shared[0].animation_data.action, channels.slot_identifier(shared[0]))
    unselected = shared.pop()
    selection = [owners.Owner(rig, b) for b in bones] + shared + [owners.Owner(rig, bones[3]), shared[7]]
    groups, skipped = bake._action_groups(selection)
    print(f"grouping 40 bones and 30 linked duplicates: {_Scanned.scanned} list elements scanned (5894662: 1,793)")
    assert _Scanned.scanned == 0
    assert skipped == []
    assert [g.objects for g in groups] == [[rig], [*shared, unselected]]
    assert [g.bones for g in groups] == [bones, [""]]
