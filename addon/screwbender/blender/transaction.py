# SPDX-License-Identifier: GPL-3.0-or-later
"""All or nothing: what an operator changes in `bpy.data`, undone when it fails halfway.

Blender's undo system records a step only when an operator finishes; an operator that fails
halfway through writing (a bug, a Blender API that changed, an out-of-memory error) would leave
half a change in the user's scene: a new action nobody uses, keys inserted on some curves but
not on others. Every operator that writes runs its writing inside :func:`atomic`::

    with transaction.atomic() as t:
        action = source.copy()          # new data-blocks are found and removed on failure
        t.assign_action(obj, action, identifier)  # changes of existing data are journaled
        t.set(source, "use_fake_user", True)

On an exception the journal is replayed backwards, every data-block created since the start
(objects, meshes, curves, materials, actions, collections) is removed, and the exception propagates to the
operator, which reports it and cancels. What cannot be undone (removing a replaced data-block)
is registered with :meth:`Transaction.on_commit` and runs only once the body has succeeded;
should it fail, the operator says that its changes were made (:class:`CommitIncomplete`).
Nothing here is specific to one operator.
"""

from __future__ import annotations

import contextlib
from collections.abc import Callable, Iterator
from typing import Any

import bpy
import numpy as np

from . import bulk, channels

#: `bpy.data` collections whose new members a failed operator removes, in removal order
#: (users first: objects before the meshes and curves they use, collections last).
CREATED_KINDS = ("objects", "meshes", "curves", "materials", "actions", "collections")

#: Keyframe properties restored when an F-curve's keys are put back: (name, items per key, dtype).
KEYFRAME_PROPERTIES = (
    ("co", 2, np.float32),
    ("handle_left", 2, np.float32),
    ("handle_right", 2, np.float32),
    ("interpolation", 1, np.int32),
    ("easing", 1, np.int32),
    ("handle_left_type", 1, np.int32),
    ("handle_right_type", 1, np.int32),
    ("type", 1, np.int32),
    ("back", 1, np.float32),
    ("amplitude", 1, np.float32),
    ("period", 1, np.float32),
    ("select_control_point", 1, bool),
    ("select_left_handle", 1, bool),
    ("select_right_handle", 1, bool),
)

_MISSING = object()


def _enum_values(points, name: str) -> np.ndarray:
    """Enum keyframe properties through `foreach_get` as integers (their RNA values)."""
    out = np.empty(len(points), dtype=np.int32)
    bulk.get(points, name, out)
    return out


class Transaction:
    """The journal of one operator's changes; see the module docstring."""

    def __init__(self, parent: Transaction | None = None) -> None:
        self._parent = parent
        self._undo: list[Callable[[], None]] = []
        #: (key or None, action) of each commit action, in order (see :meth:`on_commit`).
        self._on_commit: list[tuple[Any, Callable[[], None]]] = []
        self._commit_keys: set = set()
        #: The outermost transaction, and the size of each collection when this one began.
        self._root: Transaction = parent._root if parent is not None else self
        self._counts = tuple(len(getattr(bpy.data, kind)) for kind in CREATED_KINDS)
        if parent is not None and self._counts == self._root._counts:
            # Nothing was created since the outermost transaction began (no data-block is removed
            # before the outermost commits, and a nested rollback removes what it created): its
            # snapshot is this one's. A scan of every data-block per nested transaction (Insert Key
            # runs one per owner) made the run quadratic in the scene's size.
            self._existing = self._root._existing
        else:
            self._existing = {kind: {id_.as_pointer() for id_ in getattr(bpy.data, kind)} for kind in CREATED_KINDS}

    # Journaled changes of existing data ------------------------------------------------------

    def on_rollback(self, undo: Callable[[], None]) -> None:
        """Registers `undo`, run (newest first) when the transaction fails."""
        self._undo.append(undo)

    def on_commit(self, action: Callable[[], None], key: Any = None) -> None:
        """Registers `action`, run when the transaction succeeds (for what cannot be undone,
        such as removing a data-block: it happens only once everything else has worked).

        With a `key` (hashable, e.g. `("remove", id.as_pointer())`) the action is registered
        once: a later action with the same key, here or in a nested transaction, is dropped
        (several results replacing one earlier result remove it once)."""
        if key is not None:
            if key in self._commit_keys:
                return
            self._commit_keys.add(key)
        self._on_commit.append((key, action))

    def set(self, target: Any, name: str, value: Any) -> None:
        """`setattr(target, name, value)`, undone on failure."""
        old = getattr(target, name)
        self.on_rollback(lambda: setattr(target, name, old))
        setattr(target, name, value)

    def set_item(self, target: Any, key: str, value: Any) -> None:
        """`target[key] = value` (an ID property), undone on failure (removed if it was new)."""
        old = target.get(key, _MISSING)

        def undo() -> None:
            if old is _MISSING:
                if key in target:
                    del target[key]
            else:
                target[key] = old

        self.on_rollback(undo)
        target[key] = value

    def assign_action(self, obj: bpy.types.Object, action: bpy.types.Action | None, identifier: str = "") -> None:
        """Makes `action` the active action of `obj` (on slot `identifier`), undone on failure:
        the old action and slot come back, and animation data created here goes again."""
        had_adt = obj.animation_data is not None
        old_action = obj.animation_data.action if had_adt else None
        old_identifier = channels.slot_identifier(obj) if had_adt else ""

        def undo() -> None:
            if not had_adt:
                obj.animation_data_clear()
            else:
                channels.assign(obj, old_action, old_identifier)

        self.on_rollback(undo)
        channels.assign(obj, action, identifier)

    def keep_keys(self, fcurve: bpy.types.FCurve) -> None:
        """Snapshots every key of `fcurve` (positions, handles, interpolation, easing, types,
        selection); on failure the curve gets exactly these keys back."""
        points = fcurve.keyframe_points
        n = len(points)
        saved = {}
        for name, width, dtype in KEYFRAME_PROPERTIES:
            if dtype is np.int32:
                saved[name] = _enum_values(points, name)
            else:
                values = np.empty(n * width, dtype=dtype)
                bulk.get(points, name, values)
                saved[name] = values

        def undo() -> None:
            points = fcurve.keyframe_points
            while len(points) > n:
                points.remove(points[len(points) - 1], fast=True)
            if len(points) < n:
                points.add(n - len(points))
            for name, values in saved.items():
                bulk.put(points, name, values)
            fcurve.update()

        self.on_rollback(undo)

    def keep_selection(self, view_layer: bpy.types.ViewLayer) -> None:
        """Snapshots which objects are selected and which is active; put back on failure."""
        selected = [o for o in view_layer.objects if o.select_get(view_layer=view_layer)]
        active = view_layer.objects.active

        def undo() -> None:
            for o in view_layer.objects:
                o.select_set(False, view_layer=view_layer)
            for o in selected:
                o.select_set(True, view_layer=view_layer)
            view_layer.objects.active = active

        self.on_rollback(undo)

    def keep_face_selection(self, mesh: bpy.types.Mesh) -> None:
        """Snapshots the face selection of `mesh`; put back on failure."""
        mask = np.empty(len(mesh.polygons), dtype=bool)
        bulk.get(mesh.polygons, "select", mask)

        def undo() -> None:
            bulk.put(mesh.polygons, "select", mask)
            mesh.update()

        self.on_rollback(undo)

    def new_fcurve(
        self, bag: Any, data_path: str, index: int, group: str = channels.TRANSFORM_GROUP
    ) -> bpy.types.FCurve:
        """A new F-curve in `bag`, in F-curve group `group` (see :func:`channels.new_fcurve`),
        removed on failure (with the group, when it was made for it)."""
        had_group = channels.has_group(bag, group)
        fcurve = channels.new_fcurve(bag, data_path, index, group)

        def undo() -> None:
            channels.remove_fcurve_at(bag, data_path, index)
            if not had_group:
                channels.remove_group_if_empty(bag, group)

        self.on_rollback(undo)
        return fcurve

    # Outcome ----------------------------------------------------------------------------------

    def rollback(self) -> list[str]:
        """Undoes everything (journal newest first, then new data-blocks); returns what could
        not be undone, for the report (empty when everything was put back)."""
        problems = []
        for undo in reversed(self._undo):
            try:
                undo()
            except Exception as err:  # keep undoing the rest
                problems.append(repr(err))
        self._undo.clear()
        self._on_commit.clear()
        self._commit_keys.clear()
        for kind in CREATED_KINDS:
            collection = getattr(bpy.data, kind)
            for id_ in [i for i in collection if i.as_pointer() not in self._existing[kind]]:
                try:
                    collection.remove(id_)
                except Exception as err:
                    problems.append(f"{kind}: {err!r}")
        return problems

    def commit(self) -> None:
        """Ends the transaction: a nested one hands its journal to its parent (which may still
        fail and undo it); the outermost runs the commit actions.

        The changes are done by then and the commit actions cannot be undone, so nothing is
        rolled back any more: every commit action runs even when an earlier one fails, and
        failures raise :class:`CommitIncomplete` afterwards (the changes stay, and the operator
        says so)."""
        actions, self._on_commit, self._commit_keys = self._on_commit, [], set()
        if self._parent is not None:
            self._parent._undo += self._undo
            self._undo.clear()
            for key, action in actions:
                self._parent.on_commit(action, key)
            return
        self._undo.clear()
        problems = []
        for _, action in actions:
            try:
                action()
            except Exception as err:  # run the others: the changes are done either way
                problems.append(f"{type(err).__name__}: {err}")
        if problems:
            raise CommitIncomplete(problems)


class RolledBack(RuntimeError):
    """An operator failed and its changes were undone; the message says why."""


class CommitIncomplete(RuntimeError):
    """An operator's changes were all made, but some of what it does once they are (removing
    a replaced data-block) failed; nothing was undone. :attr:`problems` lists the failures."""

    def __init__(self, problems: list[str]):
        self.problems = problems
        super().__init__("; ".join(problems))


@contextlib.contextmanager
def atomic(parent: Transaction | None = None) -> Iterator[Transaction]:
    """Runs the body with a :class:`Transaction`; on any exception, rolls everything back and
    re-raises (as :class:`RolledBack` when the undoing itself had problems). Nested in
    `parent`, a failure undoes only the body's own changes, and a success leaves them to the
    parent's outcome: one object can be skipped while the others go on. A commit action that
    fails once the body has succeeded raises :class:`CommitIncomplete` (nothing is undone then:
    the changes are made)."""
    t = Transaction(parent)
    try:
        yield t
    except BaseException as err:
        problems = t.rollback()
        if problems:
            raise RolledBack(f"{err}; undoing it also failed: {'; '.join(problems)}") from err
        raise
    t.commit()


def report_failure(operator: bpy.types.Operator, err: BaseException, what: str) -> set[str]:
    """Reports an unexpected failure of `operator` (after :func:`atomic` undid its changes)
    and returns `{'CANCELLED'}`; the traceback goes to the console for a bug report. A
    :class:`CommitIncomplete` is reported as what it is (the changes were made, a clean-up
    after them failed) and returns `{'FINISHED'}`, so that Blender records an undo step."""
    import traceback

    traceback.print_exception(err)
    if isinstance(err, CommitIncomplete):
        # The changes are made: finishing lets Blender record them, so Undo takes them back.
        operator.report(
            {"ERROR"},
            f"{what} made its changes, but tidying up after them failed ({err}); the changes were made "
            "and Undo takes them back",
        )
        return {"FINISHED"}
    operator.report({"ERROR"}, f"{what} failed ({type(err).__name__}: {err}); nothing was changed")
    return {"CANCELLED"}
