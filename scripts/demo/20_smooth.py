"""Demo part 20: smooth the demo scene with every scheme and save out/demo.blend.

Opens out/demo_source.blend; the keyed objects go into a "Source (Bezier keys)" collection,
and for each variant of demo_common.VARIANTS a collection gets copies of them, smoothed with
the installed extension's Smooth Motion operator (each copy with its own copy of the action) (levels 0 is the raw polyscrew: one screw
per key span, constant speed along it). Only the Jarek collection is left visible.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import demo_common  # noqa: E402

demo_common.blender_with_addon()
import bpy  # noqa: E402

SOURCE = "Source (Bezier keys)"


def main() -> None:
    out = demo_common.out_dir()
    bpy.ops.wm.open_mainfile(filepath=str(out / "demo_source.blend"))
    scene = bpy.context.scene
    sources = [scene.objects[name] for name in demo_common.MOTIONS]
    source_collection = bpy.data.collections.new(SOURCE)
    scene.collection.children.link(source_collection)
    for obj in sources:
        source_collection.objects.link(obj)
        scene.collection.objects.unlink(obj)

    for label, scheme, levels, timing in demo_common.VARIANTS:
        collection = bpy.data.collections.new(label)
        scene.collection.children.link(collection)
        copies = []
        for obj in sources:
            copy = obj.copy()  # shares the mesh
            copy.name = f"{obj.name}.{label}"
            # its own copy of the keys: objects sharing one action are linked duplicates, which
            # Smooth Motion smooths together (the source and every variant would get one result)
            adt = copy.animation_data
            slot = getattr(adt, "action_slot", None)
            adt.action = obj.animation_data.action.copy()
            if slot is not None and getattr(adt, "action_slot", None) is None:
                adt.action_slot = adt.action.slots[0]
            collection.objects.link(copy)
            copies.append(copy)
        for obj in scene.objects:
            obj.select_set(obj in copies)
        bpy.context.view_layer.objects.active = copies[0]
        start = time.perf_counter()
        result = bpy.ops.screwbender.smooth(scheme=scheme, levels=levels, timing=timing)
        elapsed = time.perf_counter() - start
        assert result == {"FINISHED"}, result
        print(f"20_smooth: {label:14s} {scheme:10s} {levels} levels, {timing} timing: {len(copies)} objects in {elapsed * 1000:.0f} ms")

    # every variant has a result of its own and the sources keep their keys (the renders compare them)
    actions = [o.animation_data.action for o in scene.objects if o.animation_data and o.animation_data.action]
    assert len({a.as_pointer() for a in actions}) == len(actions), "20_smooth: objects share an action"
    for obj in sources:
        assert "screwbender_source" not in obj.animation_data.action, f"20_smooth: {obj.name} was smoothed"

    layer = bpy.context.view_layer.layer_collection
    for child in layer.children:
        child.hide_viewport = child.name != "Jarek"
    for obj in scene.objects:
        obj.select_set(False)
    path = out / "demo.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(path))
    print(f"20_smooth: -> {path}")


if __name__ == "__main__":
    main()
