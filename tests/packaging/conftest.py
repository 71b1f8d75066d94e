"""Packaging tests: the built wheels and extension zips, as shipped (plain .venv Python, no bpy).

Run after scripts/build_extension.sh (scripts/test.sh does):
    .venv/bin/python -m pytest tests/packaging
The wheels come from SCREWBENDER_WHEELS (a folder; default dist/wheels), the zips from
SCREWBENDER_ZIPS (a folder; default dist). Blender's extension tool is taken from every bpy
wheel under .venv/bpy (scripts/extension.py tools).
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scripts"))

import extension  # noqa: E402  (scripts/extension.py)

WHEEL_DIR = Path(os.environ.get("SCREWBENDER_WHEELS", ROOT / "dist" / "wheels")).resolve()
ZIP_DIR = Path(os.environ.get("SCREWBENDER_ZIPS", ROOT / "dist")).resolve()
WHEELS = sorted(WHEEL_DIR.glob("polyscrew-*.whl"))
ZIPS = sorted(ZIP_DIR.glob("screwbender-*.zip"))
LINUX_WHEELS = [w for w in WHEELS if "linux" in w.name]
TOOLS = extension.blender_tools()

if not WHEELS or not ZIPS:
    raise pytest.UsageError(f"no wheel in {WHEEL_DIR} or no zip in {ZIP_DIR}: run scripts/build_extension.sh first")
if not TOOLS:
    raise pytest.UsageError("no Blender extension tool under .venv/bpy: run scripts/bootstrap.sh first")


def tool_id(tool: tuple[Path, Path]) -> str:
    """The Blender version of a tool (its bpy/<ver> folder), for test ids."""
    return f"blender-{tool[0].parents[4].name}"


def pytest_report_header(config):
    return [
        f"wheels: {', '.join(w.name for w in WHEELS)}",
        f"zips: {', '.join(z.name for z in ZIPS)}",
        f"Blender extension tools: {', '.join(tool_id(t) for t in TOOLS)}",
    ]


@pytest.fixture(scope="session")
def linux_wheel() -> Path:
    """The Linux x86_64 wheel: the real one, the base of the assembly tests."""
    found = [w for w in LINUX_WHEELS if w.name.endswith("_x86_64.whl")]
    if not found:
        pytest.skip(f"no Linux x86_64 wheel in {WHEEL_DIR}")
    return found[0]


@pytest.fixture(scope="session")
def this_zip() -> Path:
    """The zip for this machine's platform."""
    suffix = "-" + extension.blender_ext().platform_from_this_system().replace("-", "_") + ".zip"
    found = [z for z in ZIPS if z.name.endswith(suffix)]
    assert found, f"no zip for this platform ({suffix}) in {ZIP_DIR}"
    return found[0]
