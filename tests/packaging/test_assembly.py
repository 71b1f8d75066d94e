"""The release assembly: scripts/build_extension.sh --wheels DIR turns a folder of wheels, one per
platform, into one zip per platform through Blender's `build --split-platforms`, validated by
each Blender's tool and checked.

This checks the assembly logic only: the folder holds the real Linux wheel and renamed copies
of it under the Windows and macOS tags (the wheels' structure, not their code). The real
wheels of those platforms are built, assembled the same way and installed in Blender on their
own platforms by .github/workflows/release.yml, which has not been run here."""

from __future__ import annotations

import os
import shutil
import subprocess
import zipfile
from pathlib import Path

import pytest

from conftest import ROOT, TOOLS, extension

#: Wheel platform tags the release builds, and the Blender platform of each zip.
RELEASE_TAGS = {
    "manylinux_2_28_x86_64": "linux-x64",
    "win_amd64": "windows-x64",
    "macosx_11_0_arm64": "macos-arm64",
    "macosx_11_0_x86_64": "macos-x64",
}


def renamed_copies(linux_wheel: Path, folder: Path, tags) -> dict[str, Path]:
    folder.mkdir()
    base = linux_wheel.name.rsplit("-", 1)[0]
    copies = {}
    for tag in tags:
        copies[tag] = folder / f"{base}-{tag}.whl"
        shutil.copy2(linux_wheel, copies[tag])
    return copies


def build_extension(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [str(ROOT / "scripts" / "build_extension.sh"), *args],
        capture_output=True, text=True, timeout=600, env=dict(os.environ),
    )


@pytest.fixture(scope="module")
def assembled(linux_wheel, tmp_path_factory):
    root = tmp_path_factory.mktemp("assembly")
    wheels = renamed_copies(linux_wheel, root / "wheels", RELEASE_TAGS)
    done = build_extension("--wheels", str(root / "wheels"), "--out", str(root / "out"))
    assert done.returncode == 0, done.stdout + done.stderr
    return root / "out", wheels, done


def test_one_zip_per_platform_each_with_its_wheel_only(assembled):
    out, wheels, _ = assembled
    version = extension.cargo_version()
    zips = sorted(out.glob("*.zip"))
    expected = {f"screwbender-{version}-{p.replace('-', '_')}.zip": tag for tag, p in RELEASE_TAGS.items()}
    assert sorted(z.name for z in zips) == sorted(expected)
    for archive in zips:
        tag = expected[archive.name]
        with zipfile.ZipFile(archive) as zipped:
            held = sorted(n for n in zipped.namelist() if n.endswith(".whl"))
            manifest = extension.zip_manifest(zipped)
        assert held == [f"wheels/{wheels[tag].name}"], (archive.name, held)
        assert manifest["platforms"] == [RELEASE_TAGS[tag]], (archive.name, manifest["platforms"])
        assert manifest["wheels"] == [f"./wheels/{wheels[tag].name}"], (archive.name, manifest["wheels"])
        assert manifest["version"] == version
        assert extension.check_zip(archive) == []


def test_split_by_blender_and_validated_by_every_blender(assembled):
    out, _, done = assembled
    for archive in out.glob("*.zip"):
        with zipfile.ZipFile(archive) as zipped:
            text = zipped.read("blender_manifest.toml").decode()
        assert "[build.generated]" in text, "not split by Blender's build --split-platforms"
        for tool in TOOLS:
            blender = tool[0].parents[4].name
            assert f'Blender {blender} validate {archive.name}: Success parsing TOML in "{archive}"' in done.stderr
        assert f"extension check: {archive.name}: OK" in done.stderr


def test_this_platforms_zip_is_printed_last(assembled):
    out, _, done = assembled
    printed = done.stdout.split()
    assert sorted(printed) == sorted(str(z) for z in out.glob("*.zip"))
    this = extension.blender_ext().platform_from_this_system().replace("-", "_")
    assert printed[-1].endswith(f"-{this}.zip")


def test_two_wheels_for_one_platform_are_refused(linux_wheel, tmp_path):
    renamed_copies(linux_wheel, tmp_path / "wheels", ["manylinux_2_28_x86_64", "manylinux2014_x86_64"])
    done = build_extension("--wheels", str(tmp_path / "wheels"), "--out", str(tmp_path / "out"))
    assert done.returncode != 0
    assert "several polyscrew wheels for one platform" in done.stderr, done.stderr
    assert not list((tmp_path / "out").glob("*.zip"))


def test_a_wheel_of_another_version_is_refused(linux_wheel, tmp_path):
    (tmp_path / "wheels").mkdir()
    fields = linux_wheel.name.split("-")
    fields[1] = "9.9.9"
    shutil.copy2(linux_wheel, tmp_path / "wheels" / "-".join(fields))
    done = build_extension("--wheels", str(tmp_path / "wheels"), "--out", str(tmp_path / "out"))
    assert done.returncode != 0
    assert "version is not" in done.stderr, done.stderr
