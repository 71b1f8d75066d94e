"""What the demo scripts share: paths, options, and a Blender with the built extension.

Each `scripts/demo/NN_*.py` is standalone: run it with Python and the bpy wheel on the path
(scripts/demo.sh does), optionally with `--out-dir DIR` (default: out/).
"""

from __future__ import annotations

import argparse
import os
import shutil
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

#: The demo's motions: object name -> what it shows.
MOTIONS = {
    "LCycle": "the ScrewBender paper's L-shaped cycle of poses, four of them rotated",
    "Pendulum": "a pendulum from two poses",
    "SpinBlock": "a block spinning through four poses",
    "Flyer": "a mesh flown through six keys at uneven frames",
}

#: The smoothed variants written by 20_smooth.py: (collection, scheme, levels, timing).
VARIANTS = (
    ("Raw polyscrew", "jarek", 0, "linear"),
    ("4-point", "four_point", 5, "smooth"),
    ("B-spline", "bspline", 5, "smooth"),
    ("Jarek", "jarek", 5, "smooth"),
)


def out_dir() -> Path:
    """The output folder from `--out-dir` (default ROOT/out), created."""
    parser = argparse.ArgumentParser()
    parser.add_argument("--out-dir", type=Path, default=ROOT / "out")
    args, _ = parser.parse_known_args()
    args.out_dir.mkdir(parents=True, exist_ok=True)
    return args.out_dir.resolve()


def extension_zip() -> Path:
    env = os.environ.get("SCREWBENDER_EXTENSION_ZIP")
    if env:
        return Path(env)
    found = sorted((ROOT / "dist").glob("screwbender-*.zip"), key=lambda p: p.stat().st_mtime)
    if not found:
        sys.exit("demo: no dist/screwbender-*.zip; run scripts/build_extension.sh first")
    return found[-1]


def blender_with_addon():
    """Imports bpy with a private, temporary user directory where the built extension .zip is
    installed and enabled (as a user would), and returns the add-on's bake module."""
    if "bpy" in sys.modules:
        raise RuntimeError("blender_with_addon() must run before bpy is imported")
    user = Path(tempfile.mkdtemp(prefix="screwbender-demo-user-"))
    os.environ["BLENDER_USER_RESOURCES"] = str(user)
    # Where Blender unpacks the extension's wheels: put it first on the path so that the
    # bundled polyscrew is used even when an older one is installed in the Python running bpy.
    version = f"python{sys.version_info.major}.{sys.version_info.minor}"
    wheels = user / "extensions" / ".local" / "lib" / version / "site-packages"
    wheels.mkdir(parents=True)
    sys.path.insert(0, str(wheels))
    import atexit
    import importlib

    import bpy

    atexit.register(shutil.rmtree, user, ignore_errors=True)
    result = bpy.ops.extensions.package_install_files(
        filepath=str(extension_zip()), repo="user_default", enable_on_install=True
    )
    if result != {"FINISHED"}:
        sys.exit(f"demo: could not install {extension_zip()}")
    import polyscrew

    if not Path(polyscrew.__file__).resolve().is_relative_to(wheels.resolve()):
        sys.exit(f"demo: polyscrew comes from {polyscrew.__file__}, not from the extension")
    return importlib.import_module("bl_ext.user_default.screwbender.blender.bake")


def channels():
    """The add-on's channels.py (where F-curves live in each Blender's action API), loaded from
    the source tree for the parts that run without the extension installed. Needs bpy."""
    module = sys.modules.get("screwbender_channels")
    if module is None:
        import importlib.util

        spec = importlib.util.spec_from_file_location(
            "screwbender_channels", ROOT / "addon" / "screwbender" / "blender" / "channels.py"
        )
        module = importlib.util.module_from_spec(spec)
        sys.modules[spec.name] = module
        spec.loader.exec_module(module)
    return module
