"""The zip of another platform, installed as a user would (Install from Disk): Blender refuses
it with the message the README's install section quotes, and installs nothing.

The other platform's zip is made here from the zip under test: its wheel renamed to the other
platform's tag and its manifest's platforms changed to match. It checks Blender's platform
check only (the renamed wheel holds this machine's code)."""

from __future__ import annotations

import os
import re
import subprocess
import sys
import textwrap
import tomllib
import zipfile
from pathlib import Path

import conftest

#: A Blender platform other than this machine's, and a wheel platform tag for it.
OTHER = {"windows-x64": "win_amd64", "linux-x64": "manylinux_2_28_x86_64"}


def other_platform_zip(folder: Path) -> tuple[Path, str, str]:
    """(zip, this machine's platform, the zip's platform)."""
    with zipfile.ZipFile(conftest.ZIP) as source:
        text = source.read("blender_manifest.toml").decode()
        manifest = tomllib.loads(text)
        platforms = manifest.get("build", {}).get("generated", {}).get("platforms", manifest["platforms"])
        assert len(platforms) == 1, f"{conftest.ZIP.name} is not a one-platform zip: {platforms}"
        this = platforms[0]
        other = next(p for p in OTHER if p != this)
        renames = {}
        for name in source.namelist():
            if name.endswith(".whl"):
                renames[name] = re.sub(r"-[^-]+\.whl$", f"-{OTHER[other]}.whl", name)
        for old, new in renames.items():
            text = text.replace(old, new)
        text = text.replace(f'"{this}"', f'"{other}"')
        target = folder / f"screwbender-other-{other.replace('-', '_')}.zip"
        with zipfile.ZipFile(target, "w") as out:
            for info in source.infolist():
                data = text.encode() if info.filename == "blender_manifest.toml" else source.read(info)
                out.writestr(renames.get(info.filename, info.filename), data)
    return target, this, other


def test_zip_for_another_platform_is_refused(tmp_path):
    archive, this, other = other_platform_zip(tmp_path)
    user = tmp_path / "user"
    script = textwrap.dedent(
        f"""
        import os, sys
        os.environ["BLENDER_USER_RESOURCES"] = {str(user)!r}
        import bpy
        result = bpy.ops.extensions.package_install_files(
            filepath={str(archive)!r}, repo="user_default", enable_on_install=True)
        print("RESULT", sorted(result))
        print("ENABLED", "bl_ext.user_default.screwbender" in bpy.context.preferences.addons)
        """
    )
    entries = os.environ.get("PYTHONPATH", "").split(os.pathsep) + sys.path
    bpy_dir = next(p for p in entries if p and (Path(p) / "bpy").is_dir() and not (Path(p) / "polyscrew").exists())
    env = dict(os.environ, PYTHONPATH=bpy_dir)
    env.pop("BLENDER_USER_RESOURCES", None)
    done = subprocess.run([sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=300)
    output = done.stdout + done.stderr
    assert done.returncode == 0, output
    assert f"screwbender: This platform ({this}) isn't one of ({other})" in output, output
    assert "ENABLED False" in done.stdout, output
    installed = list(user.glob("extensions/**/screwbender/__init__.py")) + list(user.glob("extensions/**/polyscrew"))
    assert not installed, installed
