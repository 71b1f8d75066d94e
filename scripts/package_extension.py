"""Zips addon/screwbender with the polyscrew wheel into an installable Blender extension.

Blender's extension zip holds the add-on files at its top level, a `blender_manifest.toml`
whose `wheels = [...]` lists the bundled wheels (paths relative to the manifest) and whose
`platforms = [...]` says where those wheels run. The source manifest carries neither line
(the wheel's name depends on the build), so they are written here, into the zip only.

Usage: python scripts/package_extension.py --wheels dist/wheels --out dist
Prints the path of the written .zip.
"""

from __future__ import annotations

import argparse
import re
import shutil
import sys
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ADDON = ROOT / "addon" / "screwbender"

#: Wheel platform tag fragment -> Blender extension platform.
PLATFORMS = (
    ("manylinux", "x86_64", "linux-x64"),
    ("musllinux", "x86_64", "linux-x64"),
    ("linux", "x86_64", "linux-x64"),
    ("linux", "aarch64", "linux-arm64"),
    ("macosx", "arm64", "macos-arm64"),
    ("macosx", "x86_64", "macos-x64"),
    ("win", "amd64", "windows-x64"),
    ("win", "arm64", "windows-arm64"),
)


def platform_of(wheel: Path) -> str:
    """The Blender platform of a wheel, from the platform tag of its file name."""
    tag = wheel.stem.split("-")[-1].lower()
    for os_name, arch, platform in PLATFORMS:
        if tag.startswith(os_name) and tag.endswith(arch):
            return platform
    raise SystemExit(f"package_extension: unknown wheel platform tag {tag!r} in {wheel.name}")


def version_of(manifest: str) -> str:
    match = re.search(r'^version\s*=\s*"([^"]+)"', manifest, re.MULTILINE)
    if match is None:
        raise SystemExit("package_extension: no version in blender_manifest.toml")
    return match.group(1)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--wheels", type=Path, required=True, help="folder holding polyscrew-*.whl")
    parser.add_argument("--out", type=Path, required=True, help="folder for the .zip")
    args = parser.parse_args()

    wheels = sorted(args.wheels.glob("polyscrew-*.whl"))
    if not wheels:
        raise SystemExit(f"package_extension: no polyscrew wheel in {args.wheels}")
    bundled = ADDON / "wheels"
    bundled.mkdir(exist_ok=True)
    for old in bundled.glob("*.whl"):
        old.unlink()
    for wheel in wheels:
        shutil.copy2(wheel, bundled / wheel.name)

    manifest = (ADDON / "blender_manifest.toml").read_text()
    wheel_list = ", ".join(f'"./wheels/{w.name}"' for w in wheels)
    platform_list = ", ".join(f'"{p}"' for p in sorted({platform_of(w) for w in wheels}))
    lines = f"wheels = [{wheel_list}]\nplatforms = [{platform_list}]\n"
    table = re.search(r"^\[", manifest, re.MULTILINE)  # top-level keys go before any [table]
    at = table.start() if table else len(manifest)
    manifest = manifest[:at].rstrip("\n") + "\n\n" + lines + "\n" + manifest[at:]

    args.out.mkdir(parents=True, exist_ok=True)
    target = args.out / f"screwbender-{version_of(manifest)}.zip"
    with zipfile.ZipFile(target, "w", compression=zipfile.ZIP_DEFLATED) as archive:
        for path in sorted(ADDON.rglob("*")):
            rel = path.relative_to(ADDON)
            if path.is_dir() or "__pycache__" in rel.parts or path.suffix == ".pyc":
                continue
            if rel.as_posix() == "blender_manifest.toml":
                archive.writestr("blender_manifest.toml", manifest)
            else:
                archive.write(path, rel.as_posix())
    print(target)


if __name__ == "__main__":
    sys.exit(main())
