"""The built polyscrew wheel(s): the Linux one loads on glibc 2.28 (what Blender 4.2+ itself
needs), and every wheel's metadata is ready for PyPI and carries the workspace version."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from elftools.elf.elffile import ELFFile
from elftools.elf.gnuversions import GNUVerNeedSection

from conftest import LINUX_WHEELS, WHEELS, extension

#: The oldest glibc Blender 4.2+ runs on (Blender's own Linux builds need 2.28).
GLIBC_CEILING = (2, 28)

#: Legacy manylinux tags and the glibc each stands for (PEP 600).
LEGACY_MANYLINUX = {"manylinux1": (2, 5), "manylinux2010": (2, 12), "manylinux2014": (2, 17)}


def glibc_of_tag(tag: str) -> tuple[int, int]:
    """The glibc a Linux platform tag promises to run on (`manylinux_2_28_x86_64` -> (2, 28))."""
    match = re.fullmatch(r"manylinux_(\d+)_(\d+)_\w+", tag)
    if match:
        return int(match.group(1)), int(match.group(2))
    legacy = tag.split("_", 1)[0]
    assert legacy in LEGACY_MANYLINUX, f"{tag} is not a manylinux tag: it promises no glibc at all"
    return LEGACY_MANYLINUX[legacy]


def version_tuple(text: str) -> tuple[int, ...]:
    return tuple(int(part) for part in text.split("."))


def shared_objects(wheel: Path, into: Path) -> list[Path]:
    with zipfile.ZipFile(wheel) as archive:
        names = [n for n in archive.namelist() if n.endswith(".so") or ".so." in n]
        archive.extractall(into, members=names)
    assert names, f"{wheel.name} holds no shared object"
    return [into / n for n in names]


def glibc_versions_objdump(so: Path) -> set[tuple[int, ...]]:
    """GLIBC_x.y versions of the dynamic symbols, as `objdump -T` prints them."""
    listing = subprocess.run(["objdump", "-T", str(so)], capture_output=True, text=True, check=True).stdout
    return {version_tuple(v) for v in re.findall(r"\bGLIBC_(\d+(?:\.\d+)+)\b", listing)}


def glibc_versions_elf(so: Path) -> set[tuple[int, ...]]:
    """GLIBC_x.y versions the object requires (its .gnu.version_r section, read by pyelftools)."""
    found = set()
    with so.open("rb") as handle:
        for section in ELFFile(handle).iter_sections():
            if isinstance(section, GNUVerNeedSection):
                for _need, auxiliaries in section.iter_versions():
                    for aux in auxiliaries:
                        if aux.name.startswith("GLIBC_") and aux.name[6:7].isdigit():
                            found.add(version_tuple(aux.name[6:]))
    return found


@pytest.mark.parametrize("wheel", LINUX_WHEELS, ids=lambda w: w.name)
def test_linux_wheel_tag_is_manylinux_2_28_or_older(wheel):
    platform_tags = extension.wheel_fields(wheel.name)[4].split(".")
    with zipfile.ZipFile(wheel) as archive:
        wheel_file = archive.read("polyscrew-" + extension.wheel_fields(wheel.name)[1] + ".dist-info/WHEEL").decode()
    recorded = [line.split(": ", 1)[1].split("-")[-1] for line in wheel_file.splitlines() if line.startswith("Tag: ")]
    assert sorted(recorded) == sorted(platform_tags), (wheel.name, wheel_file)
    for tag in platform_tags:
        glibc = glibc_of_tag(tag)
        print(f"{wheel.name}: tag {tag} -> glibc {glibc[0]}.{glibc[1]}")
        assert glibc <= GLIBC_CEILING, f"{tag} needs glibc {glibc}, Blender runs on {GLIBC_CEILING}"


@pytest.mark.parametrize("wheel", LINUX_WHEELS, ids=lambda w: w.name)
def test_linux_wheel_needs_no_glibc_symbol_newer_than_2_28(wheel, tmp_path):
    for so in shared_objects(wheel, tmp_path):
        from_elf = glibc_versions_elf(so)
        assert from_elf, f"{so.name}: no GLIBC version needed at all (not a glibc-linked object?)"
        newest = max(from_elf)
        if shutil.which("objdump"):
            from_objdump = glibc_versions_objdump(so)
            assert max(from_objdump) == newest, (sorted(from_objdump), sorted(from_elf))
        print(f"{so.name}: newest GLIBC symbol version {'.'.join(map(str, newest))}")
        assert newest <= GLIBC_CEILING, f"{so.name} needs GLIBC_{'.'.join(map(str, newest))}: {sorted(from_elf)}"


def test_glibc_readers_are_not_blind():
    """The reader is not blind: this Python interpreter's own libc needs are found, and a
    manylinux_2_35 tag is above the ceiling."""
    assert glibc_of_tag("manylinux_2_35_x86_64") > GLIBC_CEILING
    assert glibc_of_tag("manylinux2014_x86_64") == (2, 17)
    libc_users = [Path(sys.executable).resolve()]
    found = set().union(*(glibc_versions_elf(p) for p in libc_users))
    assert found and max(found) >= (2, 2), found


@pytest.mark.parametrize("wheel", WHEELS, ids=lambda w: w.name)
def test_wheel_metadata_passes_twine_check(wheel):
    done = subprocess.run(
        [sys.executable, "-m", "twine", "check", "--strict", str(wheel)], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "PASSED" in done.stdout, done.stdout


@pytest.mark.parametrize("wheel", WHEELS, ids=lambda w: w.name)
def test_wheel_metadata_is_complete_and_of_the_workspace_version(wheel):
    version = extension.cargo_version()
    assert extension.wheel_fields(wheel.name)[1] == version
    with zipfile.ZipFile(wheel) as archive:
        info = f"polyscrew-{version}.dist-info"
        metadata = archive.read(f"{info}/METADATA").decode()
        names = archive.namelist()
    fields = {}
    for line in metadata.split("\n\n", 1)[0].splitlines():
        key, _, value = line.partition(": ")
        fields.setdefault(key, []).append(value)
    assert fields["Version"] == [version]
    assert fields["License-Expression"] == ["GPL-3.0-or-later"]
    assert f"{info}/licenses/LICENSE" in names, names
    assert fields["Description-Content-Type"][0].startswith("text/markdown")
    assert "polyscrew" in metadata.split("\n\n", 1)[1], "no long description"
    assert {"Repository", "Changelog", "Issues"} <= {u.split(",")[0] for u in fields["Project-URL"]}
    assert any(c.startswith("Operating System :: Microsoft :: Windows") for c in fields["Classifier"])
    assert fields["Requires-Python"] == [">=3.11"]
    for typed in ("polyscrew/py.typed", "polyscrew/__init__.pyi"):
        assert typed in names, names
