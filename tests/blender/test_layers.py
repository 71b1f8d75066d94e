"""Issue 25 item 1, the installed add-on: its three layer folders, and what reaches into them
from outside (scripts/smooth_blend.py) finds the modules where they now live."""

from __future__ import annotations

import importlib.util
import sys

import conftest
from conftest import addon_module


def test_the_installed_addon_has_its_three_layers():
    """Every module of the installed add-on sits in `pure/`, `blender/` or `ops/` (only the
    registering `__init__.py` at the top), and the installed pure modules use no bpy."""
    installed = conftest.USER_DIR.glob("extensions/user_default/screwbender/**/*.py")
    where = sorted(p.relative_to(next(conftest.USER_DIR.glob("extensions/user_default/screwbender"))).as_posix()
                   for p in installed if "__pycache__" not in p.parts)
    print(f"{len(where)} modules:", where)
    top = [p for p in where if "/" not in p]
    assert top == ["__init__.py"], top
    assert {p.split("/")[0] for p in where if "/" in p} == {"pure", "blender", "ops"}
    for name in ("keyed", "sampling", "intent", "grids"):
        module = addon_module(f"pure.{name}")
        assert "bpy" not in vars(module), name
    assert addon_module("blender.keys").SmoothError is addon_module("pure.keyed").SmoothError


def test_smooth_blend_finds_the_installed_extension():
    """scripts/smooth_blend.py inside a Blender with the extension enabled takes the installed
    add-on's Smooth Motion (`<extension>.blender.bake`), not a copy from the checkout."""
    spec = importlib.util.spec_from_file_location("smooth_blend_script", conftest.ROOT / "scripts" / "smooth_blend.py")
    script = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = script
    try:
        spec.loader.exec_module(script)
        bake = script.load_addon()
    finally:
        del sys.modules[spec.name]
    assert bake is addon_module("blender.bake")
