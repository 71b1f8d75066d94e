# SPDX-License-Identifier: GPL-3.0-or-later
"""The live preview's settings, its panel, Apply Preview and Insert Key on Motion.

Scheme, levels, timing, cycle and frame range are Smooth Motion's own panel settings
(`scene.screwbender`): the preview shows what Smooth Motion would bake, and Apply bakes it
through the same :func:`bake.smooth`. The preview's display settings live in
`scene.screwbender_preview`; the per-object switch is `Object.screwbender_preview` (on an
armature it previews the bones Smooth Motion would smooth in Object Mode, per the panel's
Armatures option). Insert Key on Motion keys the owners Smooth Motion would smooth: in Pose
Mode the selected bones, in Object Mode the selected objects and armatures' bones.
"""

from __future__ import annotations

import math

import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, FloatVectorProperty, IntProperty, PointerProperty

from ..blender import bake, channels, insert_key, owners, preview, transaction
from ..blender.keys import SmoothError
from . import bake_ops, panels, pipeline, preview_draw

STYLES = (
    ("WIRE", "Wireframe", "Each instance drawn as the wireframe of its mesh"),
    ("SOLID", "Faint Solid", "Each instance drawn as a faint, see-through solid"),
    ("BOX", "Bounding Box", "Each instance drawn as its bounding box (cheapest)"),
)


def _color(name: str, default: tuple, description: str):
    return FloatVectorProperty(
        name=name, subtype="COLOR", size=4, min=0.0, max=1.0, default=default, description=description
    )


def _redraw(self, context) -> None:
    preview_draw.tag_redraw()


class ScrewBenderPreviewSettings(bpy.types.PropertyGroup):
    """Display settings of the live preview, stored in the scene."""

    instances: IntProperty(
        name="Instances", default=preview.DEFAULT_INSTANCES, min=1, soft_max=128, max=1024,
        description="How many copies of the object are drawn, evenly spaced in time along the smoothed motion",
        update=_redraw,
    )
    trajectory_points: IntProperty(
        name="Path Points", default=preview.DEFAULT_TRAJECTORY_POINTS, min=2, soft_max=2000, max=20000,
        description="How many points of the origin's trajectory are drawn", update=_redraw,
    )
    style: EnumProperty(name="Display", items=STYLES, default="WIRE", description="How each instance is drawn", update=_redraw)
    heavy_limit: IntProperty(
        name="Box Above", default=5000, min=0, soft_max=100000,
        description="Meshes with more vertices than this are drawn as their bounding box", update=_redraw,
    )
    show_trajectory: BoolProperty(name="Trajectory", default=True, description="Draw the path of the object's origin", update=_redraw)
    show_keys: BoolProperty(name="Key Poses", default=True, description="Highlight the key poses", update=_redraw)
    show_raw: BoolProperty(
        name="Raw Polyscrew", default=False,
        description="Also draw the raw polyscrew (one screw per key span, 0 levels, linear timing) for comparison",
        update=_redraw,
    )
    line_width: FloatProperty(name="Line Width", default=1.0, min=0.5, max=10.0, description="Width of the lines, pixels", update=_redraw)
    instance_color: _color("Instances", (0.15, 0.45, 0.95, 0.6), "Colour of the instances")
    key_color: _color("Keys", (0.9, 0.15, 0.1, 1.0), "Colour of the key poses")
    trajectory_color: _color("Trajectory", (1.0, 0.6, 0.1, 1.0), "Colour of the origin's trajectory")
    raw_color: _color("Raw", (0.4, 0.4, 0.4, 0.6), "Colour of the raw polyscrew")


def _toggled(self, context) -> None:
    preview_draw.sync()


def _keyed_selection(context) -> list[bpy.types.Object]:
    return [obj for obj in context.selected_objects if obj.animation_data is not None]


def _key_owners(context) -> list[owners.Owner]:
    """What Insert Key on Motion keys: the owners Smooth Motion would smooth (Pose Mode: the
    selected bones; Object Mode: the selected keyed objects, for armatures per the panel's
    Armatures option)."""
    armature = context.scene.screwbender.armature
    found = owners.selection(context, armature, channels.object_fcurves)
    return [o for o in found if o.obj.animation_data is not None]


class SCREWBENDER_OT_preview_apply(bpy.types.Operator):
    """Bake the previewed motion of the objects with the preview on, exactly as shown, through Smooth Motion (the old actions are kept); their preview is turned off"""

    bl_idname = "screwbender.preview_apply"
    bl_label = "Apply Preview"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        if context.mode not in ("OBJECT", "POSE"):
            cls.poll_message_set("Switch to Object Mode or Pose Mode")
            return False
        if not preview_draw.enabled_objects(context.scene):
            cls.poll_message_set("No object has its ScrewBender preview on")
            return False
        return True

    def execute(self, context: bpy.types.Context) -> set[str]:
        objects = sorted(preview_draw.enabled_objects(context.scene), key=lambda o: o.name)
        moved = preview_draw.moved_unkeyed(context.scene, objects)
        if moved:
            self.report(
                {"ERROR"},
                f"{', '.join(moved)}: moved at a key frame but not keyed; the preview shows that pose, "
                "the keys do not: key it (or undo the move) before applying",
            )
            return {"CANCELLED"}

        def work(progress: pipeline.Progress) -> bake.Smoothed:
            try:
                with transaction.atomic() as t:
                    selection = preview_draw.previewed_owners(context.scene, objects)
                    result = bake.smooth(selection, preview_draw.smooth_options(context.scene), t=t)
                    for obj in result.objects:
                        t.set(obj, preview_draw.OBJECT_PROP, False)
            finally:
                preview_draw.sync()
            return result

        return pipeline.run(
            self, "Apply Preview", work, lambda result: bake_ops.report_smoothed(self, result, "Applied the preview of")
        )


class SCREWBENDER_OT_insert_key(bpy.types.Operator):
    """Key, at the current frame, the pose the smoothed motion has there (on every keyed transform channel), to refine the motion locally; reports how much the motion moved. Pose Mode: the selected bones; Object Mode: the selected objects (armatures: their keyed bones, per the Armatures option)"""

    bl_idname = "screwbender.insert_key"
    bl_label = "Insert Key on Motion"
    bl_options = {"REGISTER", "UNDO"}

    max_translation: FloatProperty(
        name="Largest Move", subtype="DISTANCE",
        description="Largest displacement of an object's origin (a bone's head, in its own space) that the new key caused (output)",
    )
    max_angle: FloatProperty(
        name="Largest Turn", subtype="ANGLE",
        description="Largest change of orientation that the new key caused (output)",
    )

    @classmethod
    def poll(cls, context: bpy.types.Context) -> bool:
        return owners.poll_selection(cls, context, _keyed_selection)

    def draw(self, context: bpy.types.Context) -> None:
        col = self.layout.column()
        col.enabled = False
        col.prop(self, "max_translation")
        col.prop(self, "max_angle")

    def execute(self, context: bpy.types.Context) -> set[str]:
        scene = context.scene
        frame = scene.frame_current + scene.frame_subframe
        options = preview_draw.smooth_options(scene)
        selection = _key_owners(context)
        results = []
        errors = []
        grouped: dict = {}  # object -> its transform curves by owner: one pass over each action

        def work(progress: pipeline.Progress) -> None:
            requests = []
            for owner in selection:
                by_owner = grouped.get(owner.obj.as_pointer())
                if by_owner is None:
                    by_owner = owners.curves_by_owner(channels.object_fcurves(owner.obj))
                    grouped[owner.obj.as_pointer()] = by_owner
                requests.append((owner, by_owner.get(owner.bone, [])))
            with transaction.atomic() as t:  # a failure takes back every key inserted so far
                # every owner together (an owner that cannot be smoothed is skipped unchanged)
                for owner, outcome in zip(selection, insert_key.insert_keys(requests, frame, options, t)):
                    if isinstance(outcome, SmoothError):
                        errors.append(str(outcome))
                    else:
                        results.append((owner, outcome))

        return pipeline.run(self, "Insert Key on Motion", work, lambda _: self.report_inserted(scene, frame, results, errors))

    def report_inserted(self, scene: bpy.types.Scene, frame: float, results: list, errors: list[str]) -> set[str]:
        for message in errors:
            self.report({"WARNING" if results else "ERROR"}, message)
        if not results:
            return {"CANCELLED"}
        self.max_translation = max(r.max_translation for _, r in results)
        self.max_angle = max(r.max_angle for _, r in results)
        for owner, r in results:
            self.report(
                {"INFO"},
                f"{owner.name}: key at frame {frame:g}; the motion moved by at most {r.max_translation:.3g} "
                f"(frame {r.worst_frame:g}) and turned by at most {math.degrees(r.max_angle):.3g} deg "
                f"over {len(r.checked_frames)} frames",
            )
        scene.frame_set(scene.frame_current, subframe=scene.frame_subframe)  # show the keyed pose
        return {"FINISHED"}


class VIEW3D_PT_screwbender_preview(panels.View3DSidebar, bpy.types.Panel):
    """Live preview settings, under the ScrewBender panel of the 3D Viewport."""

    bl_label = "Live Preview"
    bl_parent_id = "VIEW3D_PT_screwbender"

    def draw_header(self, context: bpy.types.Context) -> None:
        obj = context.active_object
        if obj is not None:
            self.layout.prop(obj, preview_draw.OBJECT_PROP, text="")

    def draw(self, context: bpy.types.Context) -> None:
        layout = self.layout
        settings = getattr(context.scene, preview_draw.SCENE_PROP)
        obj = context.active_object
        if obj is not None:
            layout.prop(obj, preview_draw.OBJECT_PROP, text=f"Preview {obj.name}")
            if getattr(obj, preview_draw.OBJECT_PROP):
                shown = preview_draw.previewed_owners(context.scene, [obj])
                entries = [preview_draw.CACHE.entries.get(preview.cache_key(o)) for o in shown]
                errors = [e.error for e in entries if e is not None and e.error]
                for error in errors[:3]:
                    layout.label(text=error, icon="ERROR")
                if len(errors) > 3:
                    layout.label(text=f"... and {len(errors) - 3} more", icon="ERROR")
                if obj.type == "ARMATURE":
                    bones = sum(1 for o in shown if o.bone)
                    layout.label(text=f"{bones} bone(s), placed by the pose at the current frame", icon="BONE_DATA")
        layout.label(text="Scheme and levels: as Smooth Motion above", icon="INFO")
        layout.use_property_split = True
        layout.use_property_decorate = False
        col = layout.column()
        col.prop(settings, "instances")
        col.prop(settings, "style")
        if settings.style != "BOX":
            col.prop(settings, "heavy_limit")
        col.prop(settings, "trajectory_points")
        col.prop(settings, "line_width")
        col = layout.column(heading="Show")
        col.prop(settings, "show_trajectory")
        col.prop(settings, "show_keys")
        col.prop(settings, "show_raw")
        col = layout.column()
        col.prop(settings, "instance_color")
        col.prop(settings, "key_color")
        col.prop(settings, "trajectory_color")
        if settings.show_raw:
            col.prop(settings, "raw_color")
        row = layout.row(align=True)
        row.operator(SCREWBENDER_OT_preview_apply.bl_idname, icon="CHECKMARK")
        row.operator(SCREWBENDER_OT_insert_key.bl_idname, icon="KEY_HLT")


def menu_func(self, context: bpy.types.Context) -> None:
    """Object > Animation menu entry."""
    self.layout.operator(SCREWBENDER_OT_insert_key.bl_idname)


classes = (ScrewBenderPreviewSettings, SCREWBENDER_OT_preview_apply, SCREWBENDER_OT_insert_key, VIEW3D_PT_screwbender_preview)


def register_properties() -> None:
    setattr(bpy.types.Scene, preview_draw.SCENE_PROP, PointerProperty(type=ScrewBenderPreviewSettings))
    setattr(
        bpy.types.Object,
        preview_draw.OBJECT_PROP,
        BoolProperty(
            name="ScrewBender Preview", default=False, update=_toggled,
            description="Draw this object's smoothed motion live in the viewport (stroboscopic instances, "
            "origin trajectory, key poses), recomputed whenever its keys change. On an armature: its keyed "
            "bones (and its own keys, per the Armatures option) as bone shapes, each in the world through "
            "the armature and its parent bones as they are posed at the current frame",
        ),
    )
    bpy.types.VIEW3D_MT_object_animation.append(menu_func)
    preview_draw.register()
    try:
        preview_draw.sync()  # the add-on enabled in a session where objects have the preview on
    except AttributeError:
        pass  # bpy.data is restricted while Blender starts up: load_post syncs once the file is loaded


def unregister_properties() -> None:
    preview_draw.unregister()
    bpy.types.VIEW3D_MT_object_animation.remove(menu_func)
    delattr(bpy.types.Object, preview_draw.OBJECT_PROP)
    delattr(bpy.types.Scene, preview_draw.SCENE_PROP)
