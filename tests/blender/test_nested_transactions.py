"""Nested transactions (Insert Key on Motion runs one per owner) without per-owner work that
grows with the scene (issue 27).

- A nested transaction (Insert Key runs one per owner, so that an owner it cannot key is
  skipped unchanged) takes its outer transaction's snapshot of the file's data-blocks when
  nothing was created since, instead of scanning every data-block again: on main (5ee97d6)
  each owner scanned all objects, meshes, actions... (a run quadratic in the scene's size).

Counted or compared, not timed (times are printed; speed: scripts/bench/bench_floor.py).
"""

from __future__ import annotations

import time

import bpy

import bake_helpers as h
from conftest import addon_module
from test_speed_smooth import many


def _ids() -> dict:
    return {kind: {i.name for i in getattr(bpy.data, kind)} for kind in ("objects", "meshes", "actions")}


def test_nested_transaction_shares_the_snapshot_and_still_undoes_only_its_own():
    """Nothing created since the outer transaction began: the nested one shares its snapshot
    (no scan). Something created by the outer one first: the nested one scans, and its rollback
    removes what it created, not what the outer one did; the outer rollback removes the rest."""
    transaction = addon_module("blender.transaction")
    before = _ids()
    try:
        with transaction.atomic() as t:
            with transaction.atomic(t) as quiet:
                assert quiet._existing is t._existing  # shared: nothing was created
            try:
                with transaction.atomic(t) as sharing:
                    assert sharing._existing is t._existing
                    bpy.data.actions.new("MadeBySharing")
                    raise KeyError("sharing fails")
            except KeyError:
                pass
            assert _ids() == before, "a nested rollback on the shared snapshot removes what it made"
            outer = bpy.data.actions.new("MadeByOuter")
            try:
                with transaction.atomic(t) as nested:
                    assert nested._existing is not t._existing  # the outer one created an action: scanned
                    assert outer.as_pointer() in nested._existing["actions"]
                    bpy.data.actions.new("MadeByNested")
                    raise KeyError("nested fails")
            except KeyError:
                pass
            names = {a.name for a in bpy.data.actions}
            assert "MadeByOuter" in names and "MadeByNested" not in names
            with transaction.atomic(t) as later:
                # one created since the outer began: a scan (not the outer's snapshot, which lacks it)
                assert later._existing is not t._existing
            bpy.data.objects.new("MadeByOuterToo", None)
            with transaction.atomic(t) as inner:
                made = bpy.data.actions.new("MadeByInner")
                assert made.as_pointer() not in inner._existing["actions"]
            raise ValueError("outer fails")
    except ValueError:
        pass
    assert _ids() == before, "the outer rollback removes everything made inside it"


def test_insert_key_on_many_objects_scans_the_file_once():
    """Insert Key on Motion over 60 objects: every nested transaction (one per owner) shares
    the outer one's snapshot (on main: 61 scans of the file's data-blocks), and every object
    is keyed. CPU per object printed for 20 and 60 objects."""
    transaction = addon_module("blender.transaction")
    made = []
    original = transaction.Transaction.__init__

    def counted(self, parent=None):
        original(self, parent)
        made.append(self)

    per_object = {}
    for count in (20, 60):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        objects = many(count)
        h.select_only(*objects)
        bpy.context.scene.frame_set(20)
        made.clear()
        transaction.Transaction.__init__ = counted
        try:
            start = time.process_time()
            assert bpy.ops.screwbender.insert_key() == {"FINISHED"}
            per_object[count] = (time.process_time() - start) / count
        finally:
            transaction.Transaction.__init__ = original
        root = made[0]
        assert len(made) == count + 1
        scanned = [t for t in made if t._existing is not root._existing]
        assert scanned == [], f"{len(scanned)} nested transactions scanned the file again"
        for obj in objects:
            frames = {p.co[0] for fc in h.fcurves(obj) for p in fc.keyframe_points}
            assert 20.0 in frames, obj.name
    print(f"Insert Key on Motion CPU per object: {', '.join(f'{n}: {1e3 * s:.2f} ms' for n, s in per_object.items())}")

