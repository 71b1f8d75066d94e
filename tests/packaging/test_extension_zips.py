"""Every extension zip built: Blender's own `validate` (the tool of each Blender in .venv/bpy)
passes, its manifest matches its content, and it holds the add-on's files unchanged."""

from __future__ import annotations

import subprocess
import sys
import tomllib
import zipfile
from pathlib import Path

import pytest

from conftest import ROOT, TOOLS, ZIPS, extension, tool_id


def blender_validate(tool: tuple[Path, Path], archive: Path) -> subprocess.CompletedProcess:
    """`blender --command extension validate` as Blender runs it (its list of valid tags)."""
    blender_ext, tags = tool
    return subprocess.run(
        [sys.executable, str(blender_ext), "validate", "--valid-tags", str(tags), str(archive)],
        capture_output=True, text=True, stdin=subprocess.DEVNULL, timeout=120,
    )


@pytest.mark.parametrize("tool", TOOLS, ids=tool_id)
@pytest.mark.parametrize("archive", ZIPS, ids=lambda z: z.name)
def test_blender_validate_passes(archive, tool):
    done = blender_validate(tool, archive)
    output = done.stdout + done.stderr
    print(f"{tool_id(tool)} validate {archive.name}: {output.strip()}")
    assert done.returncode == 0, output
    assert f'Success parsing TOML in "{archive}"' in output, output


@pytest.mark.parametrize("archive", ZIPS, ids=lambda z: z.name)
def test_manifest_matches_content(archive):
    assert extension.check_zip(archive) == []


@pytest.mark.parametrize("archive", ZIPS, ids=lambda z: z.name)
def test_zip_holds_the_addon_unchanged_and_one_wheel_per_platform(archive):
    addon = ROOT / "addon" / "screwbender"
    sources = {
        p.relative_to(addon).as_posix(): p.read_bytes()
        for p in addon.rglob("*")
        if p.is_file() and "__pycache__" not in p.parts and "wheels" not in p.parts and p.suffix != ".pyc"
    }
    with zipfile.ZipFile(archive) as zipped:
        names = set(zipped.namelist())
        manifest = extension.zip_manifest(zipped)
        for name, data in sources.items():
            if name == "blender_manifest.toml":
                continue
            assert name in names, f"{archive.name} lacks {name}"
            assert zipped.read(name) == data, f"{archive.name}: {name} differs from addon/screwbender"
    extra = {n for n in names if not n.startswith("wheels/")} - set(sources)
    assert not extra, f"{archive.name} holds files that are not the add-on's: {sorted(extra)}"
    source_manifest = tomllib.loads(sources["blender_manifest.toml"].decode())
    for key, value in source_manifest.items():
        if key != "version":
            assert manifest[key] == value, f"{archive.name}: manifest {key} {manifest[key]!r} != {value!r}"
    assert manifest["version"] == extension.cargo_version()
    assert len(manifest["platforms"]) == len(manifest["wheels"]) >= 1, manifest


def test_the_source_manifest_leaves_wheels_platforms_and_version_to_the_build():
    source = tomllib.loads((ROOT / "addon" / "screwbender" / "blender_manifest.toml").read_text())
    assert "wheels" not in source and "platforms" not in source
    assert source["version"] == "0.0.0", "the version is written once, in the workspace Cargo.toml"
