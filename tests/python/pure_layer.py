"""The add-on's pure layer (`addon/screwbender/pure`), imported without Blender.

The folder is loaded as the package `screwbender_pure` (not through `screwbender/__init__.py`,
which registers the operators and needs bpy), so its modules import one another as they do in
the add-on (`from . import intent`), and a module that reached for the Blender layer
(`from ..blender import ...`) fails to import here.
"""

from __future__ import annotations

import importlib
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

FOLDER = Path(__file__).resolve().parents[2] / "addon" / "screwbender" / "pure"
PACKAGE = "screwbender_pure"


def names() -> list[str]:
    """Every module of the pure layer."""
    return sorted(p.stem for p in FOLDER.glob("*.py") if p.stem != "__init__")


def module(name: str) -> ModuleType:
    """`addon/screwbender/pure/<name>.py`, imported as `screwbender_pure.<name>`."""
    if PACKAGE not in sys.modules:
        spec = importlib.util.spec_from_file_location(
            PACKAGE, FOLDER / "__init__.py", submodule_search_locations=[str(FOLDER)]
        )
        package = importlib.util.module_from_spec(spec)
        sys.modules[PACKAGE] = package
        spec.loader.exec_module(package)
    return importlib.import_module(f"{PACKAGE}.{name}")
