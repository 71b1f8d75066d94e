"""Blender test session: the built extension .zip installed into a fresh user directory.

Run inside the bpy wheel (one session per Blender version):
    PYTHONPATH=<pylib>:.venv/bpy/<ver> python -m pytest tests/blender
The .zip comes from SCREWBENDER_EXTENSION_ZIP (default: the newest dist/screwbender-*.zip for
this machine's platform, built by scripts/build_extension.sh). Blender's user directory is
pointed at a temporary folder *before* bpy is imported, so nothing of the machine's own Blender
set-up is used or touched, and the add-on is installed exactly as a user would install it.
"""

from __future__ import annotations

import importlib
import os
import platform
import shutil
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))  # the helpers module beside this file
sys.path.insert(0, str(ROOT / "tests" / "fixtures"))  # helpers shared with tests/python (spinning_top)


def extension_zip() -> Path:
    """The extension .zip under test."""
    env = os.environ.get("SCREWBENDER_EXTENSION_ZIP")
    if env:
        return Path(env)
    found = sorted((ROOT / "dist").glob("screwbender-*.zip"), key=lambda p: p.stat().st_mtime)
    # One zip per platform (screwbender-<version>-linux_x64.zip, ...): this machine's.
    system = {"darwin": "macos", "win32": "windows"}.get(sys.platform, sys.platform)
    machine = platform.machine().lower()
    machine = {"x86_64": "x64", "amd64": "x64", "aarch64": "arm64"}.get(machine, machine)
    found = [p for p in found if p.stem.endswith(f"-{system}_{machine}")] or found
    if not found:
        raise pytest.UsageError("no dist/screwbender-*.zip: run scripts/build_extension.sh first")
    return found[-1]


ZIP = extension_zip()
USER_DIR = Path(tempfile.mkdtemp(prefix="screwbender-blender-user-"))
os.environ["BLENDER_USER_RESOURCES"] = str(USER_DIR)

import bpy  # noqa: E402  (after BLENDER_USER_RESOURCES)

#: The add-on's module name once installed into the "user_default" extension repository.
ADDON = "bl_ext.user_default.screwbender"

_result = bpy.ops.extensions.package_install_files(
    filepath=str(ZIP), repo="user_default", enable_on_install=True
)
if _result != {"FINISHED"} or ADDON not in bpy.context.preferences.addons:
    raise pytest.UsageError(f"could not install and enable {ZIP} (result {_result})")


def addon_module(name: str = ""):
    """A module of the installed add-on, e.g. addon_module("blender.bake")."""
    return importlib.import_module(f"{ADDON}.{name}" if name else ADDON)


def pytest_report_header(config):
    return f"Blender {bpy.app.version_string}; extension {ZIP.name}; user dir {USER_DIR}"


def pytest_unconfigure(config):
    shutil.rmtree(USER_DIR, ignore_errors=True)


@pytest.fixture(autouse=True)
def factory_scene():
    """An empty factory scene for every test (the add-on stays enabled)."""
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    yield bpy.context.scene


@pytest.fixture
def sb():
    """The installed add-on's modules: sb.keys, sb.bake, sb.channels."""
    class Modules:
        keys = addon_module("blender.keys")
        bake = addon_module("blender.bake")
        channels = addon_module("blender.channels")

    return Modules
