# SPDX-License-Identifier: GPL-3.0-or-later
"""Build Swept Region and Check Clearance: collect options, call :mod:`swept`, report."""

from __future__ import annotations

import time

import bpy
from bpy.props import BoolProperty, FloatProperty, IntProperty

from ..blender import swept, transaction
from ..pure import sweep_report
from . import panels, pipeline


class SCREWBENDER_OT_sweep(bpy.types.Operator):
    """Build the region swept by each selected mesh object along its motion over the frame range (the smoothed motion where there is one, otherwise its animation sampled at every frame) as a new object in the "Swept Regions" collection"""

    bl_idname = "screwbender.sweep"
    bl_label = "Build Swept Region"
    bl_options = {"REGISTER", "UNDO"}

    tolerance: FloatProperty(
        name="Tolerance",
        default=0.0,
        min=0.0,
        soft_max=0.1,
        precision=4,
        subtype="DISTANCE",
        description="Largest distance of the result from the exact swept boundary. Closed Volume: every "
        "vertex within it (0: 0.5 % of the object's bounding box diagonal; smaller is slower and heavier). "
        "Open sweep: every swept surface within it (0: 0.2 % of the object's bounding radius)",
    )
    steps: IntProperty(
        name="Minimum Steps",
        default=1,
        min=1,
        max=256,
        soft_max=32,
        options={"HIDDEN", "SKIP_SAVE"},
        description="Least number of steps per span of the open sweep (scripts; the tolerance adds more where needed)",
    )
    caps: BoolProperty(
        name="Caps", default=True, description="Include the object at the first and last pose (open sweep)"
    )
    closed: BoolProperty(
        name="Closed Volume",
        default=True,
        description="Build the region's boundary as a closed, consistently oriented, self-intersection-free "
        "mesh (for booleans, printing, volume, clearance): seconds, many triangles. Off: the open sweep, the "
        "live preview's fast superset (milliseconds; not closed). Left at its default, a mesh that is not "
        "closed gets the open sweep; turned on, it is refused",
    )
    decimate: BoolProperty(
        name="Fewer Triangles",
        default=True,
        description="Closed Volume: remove vertices where the boundary is flat and along its creases "
        "(3.8 to 5.7 times fewer triangles at the default tolerance, every vertex left still within it; "
        "1.6 to 2.1 times as long). Off: the contoured mesh as it is",
    )
    cell: FloatProperty(
        name="Cell Size",
        default=0.0,
        min=0.0,
        soft_max=1.0,
        precision=4,
        subtype="DISTANCE",
        options={"HIDDEN", "SKIP_SAVE"},
        description="Scripts: a fixed grid cell for the closed boundary instead of one derived from the "
        "tolerance (0: from the tolerance)",
    )
    voxel_size: FloatProperty(
        name="Voxel Size",
        default=0.05,
        min=1e-4,
        soft_max=1.0,
        subtype="DISTANCE",
        options={"HIDDEN", "SKIP_SAVE"},
        description="Former voxel remesh size (scripts): the cell of the closed boundary when Cell Size is 0",
    )

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if context.mode != "OBJECT":
            cls.poll_message_set("Switch to Object Mode")
            return False
        if not any(o.type == "MESH" for o in context.selected_objects):
            cls.poll_message_set("Select one or more moving mesh objects")
            return False
        return True

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        layout.use_property_split = True
        layout.prop(self, "closed")
        layout.prop(self, "tolerance")
        row = layout.row()
        row.enabled = self.closed
        row.prop(self, "decimate")
        row = layout.row()
        row.enabled = not self.closed
        row.prop(self, "caps")

    def execute(self, context: bpy.types.Context) -> set[str]:
        objects = sorted((o for o in context.selected_objects if o.type == "MESH"), key=lambda o: o.name)
        start = time.perf_counter()

        def work(progress: pipeline.Progress) -> tuple[list, list, list]:
            tolerance = self.tolerance if self.tolerance > 0.0 else None
            cell = self.cell if self.cell > 0.0 else (self.voxel_size if self.properties.is_property_set("voxel_size") else None)
            read: dict = {}  # each key curve read once, also when meshes share an action or a rig
            # Closed Volume left at its default: a mesh that is not closed gets the open sweep.
            fallback = not self.properties.is_property_set("closed")
            computed = swept.compute_all(objects, context, self.steps, self.caps, tolerance, read, self.closed, cell,
                                         fallback, progress, decimate=self.decimate)
            with transaction.atomic() as t:  # a failure removes every object and mesh made so far
                created = [swept.create_object(s, context, t) for s in computed]
                # Area, volume (a closed result) and the tolerance met, on each new object.
                found = [sweep_report.measures(*swept.created_triangles(s)) for s in computed]
                for obj, s, m in zip(created, computed, found):
                    obj["screwbender_tolerance"] = s.tolerance
                    obj["screwbender_error_bound"] = s.error_bound
                    if s.cell > 0.0:
                        obj["screwbender_cell"] = s.cell
                        obj["screwbender_vertex_bound"] = s.vertex_bound
                    obj["screwbender_area"] = m.area
                    if m.volume is not None:
                        obj["screwbender_volume"] = m.volume
                t.keep_selection(context.view_layer)
                for obj in context.selected_objects:
                    obj.select_set(False)
                for obj in created:
                    obj.select_set(True)
                context.view_layer.objects.active = created[-1]
            return computed, created, found

        def report(done: tuple[list, list, list]) -> set[str]:
            computed, created, found = done
            seconds = time.perf_counter() - start
            tris = sum(swept.triangle_count(o.data) for o in created)
            sweep_ms = 1e3 * sum(s.seconds for s in computed)
            volumes = [m.volume for m in found]
            fell = [s for s in computed if s.fallback]
            # The figures of the kind asked for, and beside them those of the objects that fell back.
            kept = [s for s in computed if not s.fallback]
            main = kept or fell
            beside = (len(fell), max(s.tolerance for s in fell), max(s.error_bound for s in fell)) if kept and fell else None
            self.report(
                {"INFO"},
                sweep_report.summary(
                    len(created), tris, seconds, sweep_ms, max(s.tolerance for s in main),
                    max(s.error_bound for s in main), sum(m.area for m in found),
                    None if any(v is None for v in volumes) else sum(volumes),
                    cell=max(s.cell for s in main), attempts=max(s.attempts for s in main), open_sweep=beside,
                ),
            )
            notes = [sweep_report.fallback_note([s.obj.name for s in fell]),
                     sweep_report.over_tolerance_note([(s.obj.name, s.tolerance, s.error_bound, s.finer_refused)
                                                       for s in computed
                                                       if s.cell > 0.0 and 0.0 < s.tolerance < s.error_bound])]
            for note in notes:  # last: the status bar shows the last report
                if note is not None:
                    self.report({"WARNING"}, note)
            return {"FINISHED"}

        return pipeline.run(self, "Build Swept Region", work, report, context, refusals=(swept.SweepError,))


class SCREWBENDER_OT_check_clearance(bpy.types.Operator):
    """Check the active object (a swept region) against the other selected objects: whether they intersect and their smallest distance; the colliding faces are selected"""

    bl_idname = "screwbender.check_clearance"
    bl_label = "Check Clearance"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        active = context.active_object
        if context.mode != "OBJECT" or active is None or active.type != "MESH":
            cls.poll_message_set("Make a swept region (a mesh) the active object, in Object Mode")
            return False
        if not any(o is not active and o.type == "MESH" for o in context.selected_objects):
            cls.poll_message_set("Also select the objects to check against")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        region = context.active_object
        others = sorted((o for o in context.selected_objects if o is not region and o.type == "MESH"), key=lambda o: o.name)
        depsgraph = context.evaluated_depsgraph_get()

        def work(progress: pipeline.Progress) -> dict:
            results = {o.name: swept.clearance(region, o, depsgraph) for o in others}
            with transaction.atomic() as t:
                for o in [region, *others]:
                    t.keep_face_selection(o.data)
                swept.select_faces(region, sorted({f for r in results.values() for f in r.faces_a}))
                for o in others:
                    swept.select_faces(o, results[o.name].faces_b)
                t.set_item(region, "screwbender_clearance", {name: r.distance for name, r in results.items()})
                t.set_item(region, "screwbender_intersects", [name for name, r in results.items() if r.intersects])
            return results

        def report(results: dict) -> set[str]:
            for name, r in results.items():
                if r.intersects:
                    self.report({"WARNING"}, f"{region.name} intersects {name} ({len(r.faces_a)} faces selected)")
                else:
                    self.report({"INFO"}, f"{region.name} clears {name} by {r.distance:.6g}")
            return {"FINISHED"}

        return pipeline.run(self, "Check Clearance", work, report, refusals=(swept.SweepError,))


class VIEW3D_PT_screwbender_sweep(panels.OperatorsPanel, panels.View3DSidebar, bpy.types.Panel):
    """Swept regions in the 3D Viewport sidebar, Animation tab."""

    bl_label = "ScrewBender Swept Region"
    panel_operators = (
        (SCREWBENDER_OT_sweep.bl_idname, "MOD_SCREW"),
        (SCREWBENDER_OT_check_clearance.bl_idname, "MOD_BOOLEAN"),
    )


classes = (SCREWBENDER_OT_sweep, SCREWBENDER_OT_check_clearance, VIEW3D_PT_screwbender_sweep)
