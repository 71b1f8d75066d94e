# SPDX-License-Identifier: GPL-3.0-or-later
"""The one way a writing operator runs and reports.

Every writing operator's `execute` is: collect options -> :func:`run` its work -> report.
The work is the Blender layer's pipeline for that feature (group owners -> read each curve
once -> compute in the pure layer, one `polyscrew` call per operator where the data allows ->
write once, inside one :func:`transaction.atomic`; `blender/action_groups.py` holds the two
ends Smooth Motion, Remove Noise and Reduce Keys share): `bake.smooth`, `bake.revert`,
`denoise.remove_noise`, `reduce.reduce_keys`, `insert_key.insert_key`, `angvel.add_sketch`,
`angvel.fit`, `swept.compute` + `swept.create_object`, `swept.clearance`. :func:`run` gives it the progress bar, and turns what it raises into
the one kind of report: a refusal (:class:`SmoothError`, or the feature's own refusal) is the
animator's message and `{'CANCELLED'}`; anything else is reported by
:func:`transaction.report_failure` (the journal has undone every change; the traceback goes
to the console). Nothing is reported twice and no traceback reaches the user.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import bpy

from ..blender import transaction
from ..blender.keys import SmoothError

#: `progress(done, total)`, or None where the operator shows no progress bar.
Progress = Callable[[int, int], None] | None


def run(
    operator: bpy.types.Operator,
    what: str,
    work: Callable[[Progress], Any],
    report: Callable[[Any], set[str]],
    context: bpy.types.Context | None = None,
    refusals: tuple[type[BaseException], ...] = (SmoothError,),
) -> set[str]:
    """Runs `work(progress)` for `operator` (named `what` in failure reports) and returns what
    `report(result)` returns. With `context`, a progress bar follows `progress(done, total)`.
    A refusal among `refusals` is reported as its message, anything else through
    :func:`transaction.report_failure`; both return `{'CANCELLED'}` (or `{'FINISHED'}` for a
    commit whose clean-up failed, so that Undo takes its changes back)."""
    wm = context.window_manager if context is not None else None
    if wm is not None:
        wm.progress_begin(0.0, 1.0)
    try:
        progress = (lambda done, total: wm.progress_update(done / total)) if wm is not None else None
        result = work(progress)
    except refusals as err:
        operator.report({"ERROR"}, str(err))
        return {"CANCELLED"}
    except Exception as err:  # the work's transaction has undone its changes
        return transaction.report_failure(operator, err, what)
    finally:
        if wm is not None:
            wm.progress_end()
    return report(result)


def report_skipped(operator: bpy.types.Operator, skipped: list[str], level: str) -> None:
    """One line per skipped object for a few, else one line: how many, and the first reasons."""
    if len(skipped) <= 3:
        for message in skipped:
            operator.report({level}, message)
        return
    for message in skipped:  # the whole list for the console (a pipeline's log)
        print(f"ScrewBender: {message}")
    operator.report(
        {level}, f"{len(skipped)} objects skipped (the list is in the console): {'; '.join(skipped[:2])}; ..."
    )



def report_notes(operator: bpy.types.Operator, notes: list[str]) -> None:
    """The notes of a run (what was kept, a rerun from the original keys): one line each for
    a few, else two and how many more (the whole list in the console)."""
    if len(notes) <= 3:
        for note in notes:
            operator.report({"INFO"}, note)
        return
    for note in notes:  # many owners: one line, the list in the console
        print(f"ScrewBender: {note}")
    operator.report({"INFO"}, f"{'; '.join(notes[:2])}; and {len(notes) - 2} more notes (in the console)")


def report_outcome(operator: bpy.types.Operator, result, line: Callable[[], str] | None = None) -> set[str]:
    """The report of a run over many owners (`result` has `actions`, `skipped`, `notes`):
    nothing written is an error naming why each owner was skipped; else the skipped owners as
    warnings, the notes, and `line()` (the run's one summary line)."""
    if not result.actions:
        report_skipped(operator, result.skipped, "ERROR")
        return {"CANCELLED"}
    report_skipped(operator, result.skipped, "WARNING")
    report_notes(operator, result.notes)
    if line is not None:
        operator.report({"INFO"}, line())
    return {"FINISHED"}
