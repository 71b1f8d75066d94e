"""The parts the operators and panels share (issue 25's duplicates: `ops/panels.py` and
`reduce_ops.SelectionOperator`) give every registered class what it declared one by one
before: the same place and label for each sidebar panel, the same buttons, icons and hint
lines, the same poll messages, and the same default tolerance when invoked."""

from __future__ import annotations

import bpy
import numpy as np
import pytest

import bake_helpers as h
from conftest import addon_module

#: The panels as they were declared before they shared their parts (release 5ee97d6):
#: class -> (space, region, tab, label, [(operator, icon)], hint lines).
PANELS = {
    "VIEW3D_PT_screwbender_denoise": (
        "VIEW_3D", "UI", "Animation", "ScrewBender Remove Noise", [("screwbender.denoise", "MOD_SMOOTH")],
        ["Strength is chosen from the data; select keys to hold the others"],
    ),
    "GRAPH_PT_screwbender_denoise": (
        "GRAPH_EDITOR", "UI", "ScrewBender", "Remove Noise", [("screwbender.denoise", "MOD_SMOOTH")], [],
    ),
    "VIEW3D_PT_screwbender_reduce": (
        "VIEW_3D", "UI", "Animation", "ScrewBender Reduce Keys", [("screwbender.reduce_keys", "IPO_BEZIER")],
        ["Tolerance in world space: 1 mm and 0.5 degrees by default"],
    ),
    "GRAPH_PT_screwbender_reduce": (
        "GRAPH_EDITOR", "UI", "ScrewBender", "Reduce Keys", [("screwbender.reduce_keys", "IPO_BEZIER")], [],
    ),
    "VIEW3D_PT_screwbender_angular_velocity": (
        "VIEW_3D", "UI", "Animation", "ScrewBender Angular Velocity",
        [("screwbender.add_angular_velocity_sketch", "SPHERE"), ("screwbender.fit_angular_velocity", "FORCE_VORTEX")],
        [],
    ),
    "VIEW3D_PT_screwbender_sweep": (
        "VIEW_3D", "UI", "Animation", "ScrewBender Swept Region",
        [("screwbender.sweep", "MOD_SCREW"), ("screwbender.check_clearance", "MOD_BOOLEAN")], [],
    ),
}

#: Panels that draw more than buttons: only where they sit is shared.
PLACED = {
    "VIEW3D_PT_screwbender": ("VIEW_3D", "UI", "Animation", "ScrewBender"),
    "GRAPH_PT_screwbender": ("GRAPH_EDITOR", "UI", "ScrewBender", "ScrewBender"),
    "VIEW3D_PT_screwbender_preview": ("VIEW_3D", "UI", "Animation", "Live Preview"),
}


class _Recorder:
    """A stand-in for `UILayout` that records the buttons and labels a panel draws."""

    def __init__(self) -> None:
        self.operators: list[tuple[str, str]] = []
        self.labels: list[str] = []

    def operator(self, idname: str, icon: str = "NONE", **_):
        self.operators.append((idname, icon))

    def label(self, text: str = "", **_):
        self.labels.append(text)


class _Drawn:
    """A stand-in for a panel instance: the class's attributes, and a recording layout."""

    def __init__(self, cls) -> None:
        self.layout = _Recorder()
        self._cls = cls

    def __getattr__(self, name: str):
        return getattr(self._cls, name)


def _panel(name: str):
    cls = bpy.types.Panel.bl_rna_get_subclass_py(name)
    assert cls is not None, f"{name} is not registered"
    return cls


@pytest.mark.parametrize("name", sorted(PANELS))
def test_each_operator_panel_sits_labels_and_draws_as_declared(name):
    space, region, tab, label, operators, hints = PANELS[name]
    cls = _panel(name)
    got = (cls.bl_space_type, cls.bl_region_type, cls.bl_category, cls.bl_label)
    print(f"{name}: {got}")
    assert got == (space, region, tab, label)
    assert cls.__module__.startswith(addon_module().__name__ + ".ops."), cls.__module__
    drawn = _Drawn(cls)
    cls.draw(drawn, bpy.context)
    assert drawn.layout.operators == operators
    assert drawn.layout.labels == hints
    for idname, _ in operators:  # every button names a registered operator
        group, op = idname.split(".")
        assert getattr(getattr(bpy.ops, group), op).get_rna_type().identifier


@pytest.mark.parametrize("name", sorted(PLACED))
def test_the_other_panels_sit_where_they_did(name):
    cls = _panel(name)
    assert (cls.bl_space_type, cls.bl_region_type, cls.bl_category, cls.bl_label) == PLACED[name]


OPERATORS = {"smooth": "key_distance", "denoise": "key_distance", "reduce_keys": "distance"}


@pytest.mark.parametrize("op", sorted(OPERATORS))
def test_poll_explains_an_empty_selection(op):
    operator = getattr(bpy.ops.screwbender, op)
    assert not operator.poll()
    obj = h.new_object("Body", "MESH", "XYZ")
    h.select_only(obj)
    assert operator.poll()


class _Invoked:
    """A stand-in for an operator instance: the class's attributes, properties of which
    `given` are set, and an `execute` that records the distance it runs with."""

    def __init__(self, cls, name: str, given: float | None) -> None:
        self._cls, self._name, self.ran = cls, name, []
        if given is not None:
            setattr(self, name, given)
        self.properties = type("Props", (), {"is_property_set": lambda _, n: given is not None and n == name})()

    def __getattr__(self, name: str):
        return getattr(self._cls, name)

    def execute(self, context):
        self.ran.append(getattr(self, self._name))
        return {"FINISHED"}


@pytest.mark.parametrize("op", sorted(OPERATORS))
@pytest.mark.parametrize("scale", [1.0, 0.01, 2.54])
def test_invoke_sets_the_tolerance_to_a_millimetre_at_the_unit_scale(op, scale):
    """Invoked from the interface, the distance the run uses is 1 mm at the scene's unit scale
    (0.1 units of 1 cm); a value given to the operator is used as it is. (The registered
    class's `invoke`, called directly: Blender restores an operator's last-used values on
    INVOKE_DEFAULT, so a real invoke shows the default only once per session.)"""
    bpy.context.scene.unit_settings.scale_length = scale
    name = OPERATORS[op]
    cls = bpy.types.Operator.bl_rna_get_subclass_py(f"SCREWBENDER_OT_{op}")
    fresh, given = _Invoked(cls, name, None), _Invoked(cls, name, 0.25)
    assert cls.invoke(fresh, bpy.context, None) == {"FINISHED"}
    assert cls.invoke(given, bpy.context, None) == {"FINISHED"}
    print(f"{op}: unit scale {scale}: {name} used {fresh.ran} (default), {given.ran} (given)")
    stored = float(bpy.context.scene.unit_settings.scale_length)  # float32
    assert stored == pytest.approx(scale, rel=1e-6)
    assert fresh.ran == [pytest.approx(0.001 / stored, rel=1e-12)]
    assert given.ran == [0.25]


@pytest.mark.parametrize("op", sorted(OPERATORS))
def test_a_real_invoke_runs_with_the_distance_given(op, monkeypatch):
    obj = h.new_object("Body", "MESH", "XYZ")
    t = np.arange(48) / 24.0  # keyed on every frame along a gentle curve: every operator runs
    loc = np.stack([np.cos(t), np.sin(0.7 * t), 0.2 * t], axis=1)
    angle = 0.5 * t
    rot = np.zeros((len(t), 3, 3))
    rot[:, 0, 0], rot[:, 0, 1], rot[:, 1, 0], rot[:, 1, 1], rot[:, 2, 2] = (
        np.cos(angle), -np.sin(angle), np.sin(angle), np.cos(angle), 1.0
    )
    obj.animation_data_create().action = bpy.data.actions.new("BodyAction")
    h.key_poses(obj, np.arange(1, len(t) + 1, dtype=float), h.rigid(loc, rot))
    h.select_only(obj)
    name = OPERATORS[op]
    cls = bpy.types.Operator.bl_rna_get_subclass_py(f"SCREWBENDER_OT_{op}")
    used: list[float] = []
    execute = cls.execute

    def recording(self, context):
        used.append(getattr(self, name))
        return execute(self, context)

    monkeypatch.setattr(cls, "execute", recording)
    assert getattr(bpy.ops.screwbender, op)("INVOKE_DEFAULT", **{name: 0.25}) == {"FINISHED"}
    assert used == [pytest.approx(0.25, rel=1e-6)]
    assert obj.animation_data.action.name != "BodyAction"  # the run wrote its result
