"""The extension installed from the built .zip: registered, its bundled wheel used, and a clean
register / unregister cycle in a Blender of its own."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import bpy

import conftest


def test_installed_from_zip_and_enabled():
    assert conftest.ADDON in bpy.context.preferences.addons
    module = conftest.addon_module()
    installed = Path(module.__file__).resolve()
    assert installed.is_relative_to(conftest.USER_DIR.resolve()), installed
    source = conftest.ROOT / "addon" / "screwbender"
    # The layer folders (pure/, blender/, ops/) ship as they are in the source.
    shipped = sorted(p.relative_to(source).as_posix() for p in source.rglob("*") if p.suffix in (".py", ".toml"))
    assert len(shipped) >= 15, shipped
    for name in shipped:
        assert (installed.parent / name).is_file(), name
    # The wheel named in the manifest was unpacked into the extensions' site-packages.
    bundled = list(conftest.USER_DIR.glob("extensions/.local/lib/python*/site-packages/polyscrew/__init__.py"))
    assert bundled, "polyscrew wheel not installed with the extension"


def test_operators_panels_and_settings_registered():
    assert bpy.ops.screwbender.smooth.get_rna_type().name == "Smooth Motion"
    assert bpy.ops.screwbender.revert.get_rna_type().name == "Revert Smoothing"
    assert hasattr(bpy.types, "VIEW3D_PT_screwbender")
    assert hasattr(bpy.types, "GRAPH_PT_screwbender")
    # the defaults hit every key (4-point) at the pace of Blender's own curves (issue 17)
    assert bpy.context.scene.screwbender.scheme == "four_point"
    assert bpy.context.scene.screwbender.timing == "keys"
    rna = bpy.ops.screwbender.smooth.get_rna_type()
    for name in ("scheme", "levels", "timing", "closed", "range_mode", "frame_start", "frame_end", "step"):
        assert rna.properties[name].description, f"option {name} has no tooltip"
    op_class = bpy.types.Operator.bl_rna_get_subclass_py("SCREWBENDER_OT_smooth")
    assert {"REGISTER", "UNDO"} <= set(op_class.bl_options)


def test_register_unregister_clean_in_fresh_blender(tmp_path):
    """A separate Blender, with only the bpy wheel on its path (no development polyscrew):
    install the zip, enable (register), disable (unregister), enable again, with no error."""
    entries = os.environ.get("PYTHONPATH", "").split(os.pathsep) + sys.path
    bpy_dir = next(p for p in entries if p and (Path(p) / "bpy").is_dir() and not (Path(p) / "polyscrew").exists())
    script = textwrap.dedent(
        f"""
        import os, sys
        # Hide every polyscrew outside the extension (a development install in the venv, ...).
        sys.path[:] = [p for p in sys.path if not os.path.exists(os.path.join(p or ".", "polyscrew"))]
        os.environ["BLENDER_USER_RESOURCES"] = {str(tmp_path)!r}
        import bpy, addon_utils
        name = "bl_ext.user_default.screwbender"
        assert bpy.ops.extensions.package_install_files(
            filepath={str(conftest.ZIP)!r}, repo="user_default", enable_on_install=True) == {{"FINISHED"}}
        import polyscrew
        assert polyscrew.__file__.startswith({str(tmp_path)!r}), polyscrew.__file__
        assert hasattr(bpy.types, "SCREWBENDER_OT_smooth")
        addon_utils.disable(name, default_set=True, handle_error=None)
        assert not hasattr(bpy.types, "SCREWBENDER_OT_smooth")
        assert not hasattr(bpy.types.Scene, "screwbender")
        addon_utils.enable(name, default_set=True, handle_error=None)
        assert hasattr(bpy.types, "SCREWBENDER_OT_smooth")
        addon_utils.disable(name, default_set=True, handle_error=None)
        print("CYCLE-OK")
        """
    )
    env = dict(os.environ, PYTHONPATH=bpy_dir)
    env.pop("BLENDER_USER_RESOURCES", None)
    done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=300)
    output = done.stdout + done.stderr
    assert done.returncode == 0, output
    assert "CYCLE-OK" in done.stdout, output
    lowered = output.lower()
    for bad in ("traceback", "error", "exception"):
        assert bad not in lowered, output
