"""What Blender's own extension tool does not do for the ScrewBender package.

Blender's tool (`blender --command extension build|validate`, the same code as
`bl_pkg/cli/blender_ext.py` in every bpy wheel; it runs under plain CPython 3.11+, no Blender
binary needed) zips a source folder whose `blender_manifest.toml` lists the bundled wheels and
the platforms, splits it per platform and validates the manifest's fields. It does not know
which wheels a build produced, nor what our version is, and its `validate` does not look
inside the wheel list: a zip whose manifest names a wheel it does not hold validates, and
fails only on the animator's machine. So this script does three things, and nothing else:

    tools               the Blender tools in .venv/bpy/* (and .venv/bpy-tools/*, see
                        scripts/bootstrap.sh --build): "<blender_ext.py> <tags.py>" per
                        line, newest Blender first (BLENDER_EXT=<blender_ext.py> overrides)
    version, platform   the workspace version; this machine's Blender platform (linux-x64, ...)
    stage --wheels DIR --into DIR
                        copies addon/screwbender and the polyscrew wheels of DIR into a source
                        folder for Blender's `build`, its manifest given the version of the
                        workspace Cargo.toml (the one place the version is written), the
                        `wheels` list and the `platforms` those wheels run on (Blender's own
                        wheel-tag -> platform mapping); prints the platforms, one per line
    check ZIP...        the zip's manifest against its content: every listed wheel in the zip
                        and every wheel in the zip listed, each platform served by a wheel and
                        each wheel's platform declared, versions equal to Cargo.toml's

Blender's `build` and `validate` are run by scripts/build_extension.sh.
"""

from __future__ import annotations

import argparse
import importlib.util
import os
import re
import shutil
import sys
import tomllib
import zipfile
from functools import cache
from pathlib import Path
from types import ModuleType

ROOT = Path(__file__).resolve().parent.parent
ADDON = ROOT / "addon" / "screwbender"
MANIFEST = "blender_manifest.toml"
EXTENSION_ID = "screwbender"
WHEEL_PREFIX = "polyscrew-"

#: The platforms Blender builds for (the `platforms` values its manifest accepts).
BLENDER_PLATFORMS = ("linux-x64", "linux-arm64", "macos-arm64", "macos-x64", "windows-x64", "windows-arm64")

#: Where the tool and Blender's list of valid tags sit inside a bpy wheel's `bpy/<ver>/` tree.
TOOL_IN_BPY = Path("scripts/addons_core/bl_pkg/cli/blender_ext.py")
TAGS_IN_BPY = Path("scripts/modules/_bpy_internal/extensions/tags.py")


class PackagingError(Exception):
    """A wheel, a manifest or a zip that cannot make a working extension."""


def cargo_version() -> str:
    """The version written in the workspace Cargo.toml ([workspace.package] version)."""
    data = tomllib.loads((ROOT / "Cargo.toml").read_text())
    return data["workspace"]["package"]["version"]


def blender_tools() -> list[tuple[Path, Path]]:
    """(blender_ext.py, tags.py) of every bpy tree under .venv/bpy (and of the tools alone under
    .venv/bpy-tools), newest Blender first."""
    override = os.environ.get("BLENDER_EXT")
    if override:
        tool = Path(override).resolve()
        return [(tool, tool.parents[4] / TAGS_IN_BPY)]

    def version_key(tree: Path) -> tuple[int, ...]:
        return tuple(int(part) for part in tree.name.split(".") if part.isdigit())

    trees = [tool.parents[4] for tool in (ROOT / ".venv" / "bpy").glob(f"*/bpy/*/{TOOL_IN_BPY}")]
    # the tool alone, out of a bpy wheel (scripts/bootstrap.sh --build), for a Blender not installed
    installed = {tree.name for tree in trees}
    trees += [
        tool.parents[4]
        for tool in (ROOT / ".venv" / "bpy-tools").glob(f"*/bpy/*/{TOOL_IN_BPY}")
        if tool.parents[4].name not in installed
    ]
    found = []
    for tree in sorted(trees, key=version_key, reverse=True):
        tool = tree / TOOL_IN_BPY
        try:  # a newer Blender's copy may use syntax this Python (3.11, the venv's) lacks
            compile(tool.read_bytes(), str(tool), "exec")
        except SyntaxError as error:
            print(f"extension: skipping Blender {tree.name}'s tool, not Python "
                  f"{sys.version_info.major}.{sys.version_info.minor} code ({error})", file=sys.stderr)
            continue
        found.append((tool, tree / TAGS_IN_BPY))
    return found


@cache
def blender_ext(tool: Path | None = None) -> ModuleType:
    """Blender's extension tool as a module (its functions, not its command line)."""
    if tool is None:
        found = blender_tools()
        if not found:
            raise PackagingError("no Blender extension tool: scripts/bootstrap.sh installs the bpy wheels")
        tool = found[0][0]
    spec = importlib.util.spec_from_file_location("blender_ext", tool)
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def wheel_fields(name: str) -> tuple[str, str, str, str, str]:
    """(distribution, version, python tag, abi tag, platform tag) of a wheel file name."""
    parts = name.removesuffix(".whl").split("-")
    if not name.endswith(".whl") or len(parts) not in (5, 6):
        raise PackagingError(f"{name}: not a wheel file name (distribution-version-python-abi-platform.whl)")
    return parts[0], parts[1], parts[-3], parts[-2], parts[-1]


def wheel_platforms(name: str) -> list[str]:
    """The Blender platforms a wheel runs on, by Blender's own mapping of wheel platform tags
    (`manylinux_2_28_x86_64` -> linux-x64, `win_amd64` -> windows-x64, `macosx_11_0_arm64`
    -> macos-arm64, `universal2` -> both macOS platforms)."""
    platform_tag = wheel_fields(name)[4]
    found = [p for tag in platform_tag.split(".") for p in blender_ext().blender_platforms_from_wheel_platform(tag)]
    unknown = [p for p in found if p not in BLENDER_PLATFORMS]
    if unknown or not found:
        raise PackagingError(f"{name}: platform tag {platform_tag!r} is no Blender platform ({', '.join(unknown)})")
    return sorted(set(found), key=BLENDER_PLATFORMS.index)


def polyscrew_wheels(folder: Path, version: str) -> list[Path]:
    """The polyscrew wheels of a folder, each of the given version."""
    wheels = sorted(folder.glob(f"{WHEEL_PREFIX}*.whl"))
    if not wheels:
        raise PackagingError(f"no {WHEEL_PREFIX}*.whl in {folder}")
    for wheel in wheels:
        if wheel_fields(wheel.name)[1] != version:
            raise PackagingError(f"{wheel.name}: version is not {version} (the workspace Cargo.toml's)")
    return wheels


def set_manifest_fields(manifest: str, version: str, wheels: list[str], platforms: list[str]) -> str:
    """The source manifest with its version replaced and the wheels and platforms lists added
    as top-level keys (before the first [table])."""
    manifest, count = re.subn(r'^version\s*=\s*"[^"]*"', f'version = "{version}"', manifest, count=1, flags=re.M)
    if count != 1:
        raise PackagingError(f"{MANIFEST}: no top-level version line")
    if re.search(r"^(wheels|platforms)\s*=", manifest, re.M):
        raise PackagingError(f"{MANIFEST}: the source manifest must not list wheels or platforms (they are generated)")
    def toml_list(items: list[str]) -> str:
        return "[" + ", ".join(f'"{item}"' for item in items) + "]"

    lines = (
        "# Generated by scripts/extension.py stage from the wheels of this build.\n"
        f"wheels = {toml_list([f'./wheels/{w}' for w in wheels])}\n"
        f"platforms = {toml_list(platforms)}\n"
    )
    table = re.search(r"^\[", manifest, re.M)
    at = table.start() if table else len(manifest)
    return manifest[:at].rstrip("\n") + "\n\n" + lines + "\n" + manifest[at:]


def stage(wheel_dir: Path, into: Path) -> list[str]:
    """Writes the source folder for Blender's `build`; returns its platforms."""
    version = cargo_version()
    wheels = polyscrew_wheels(wheel_dir, version)
    by_platform: dict[str, list[str]] = {}
    for wheel in wheels:
        for platform in wheel_platforms(wheel.name):
            by_platform.setdefault(platform, []).append(wheel.name)
    doubled = {p: names for p, names in by_platform.items() if len(names) > 1}
    if doubled:
        raise PackagingError(f"several polyscrew wheels for one platform: {doubled}")
    platforms = sorted(by_platform, key=BLENDER_PLATFORMS.index)

    if into.exists():
        shutil.rmtree(into)
    shutil.copytree(ADDON, into, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "wheels", ".*"))
    (into / "wheels").mkdir()
    for wheel in wheels:
        shutil.copy2(wheel, into / "wheels" / wheel.name)
    manifest = set_manifest_fields((ADDON / MANIFEST).read_text(), version, [w.name for w in wheels], platforms)
    (into / MANIFEST).write_text(manifest)
    return platforms


def zip_manifest(archive: zipfile.ZipFile) -> dict:
    """The manifest of an extension zip as Blender reads it: `[build.generated]` (written by
    `build --split-platforms`) overrides the top-level `platforms` and `wheels`."""
    data = tomllib.loads(archive.read(MANIFEST).decode("utf-8"))
    generated = data.get("build", {}).get("generated", {})
    for key in ("platforms", "wheels"):
        if key in generated:
            data[key] = generated[key]
    return data


def check_zip(path: Path) -> list[str]:
    """The problems of an extension zip (empty when it can install and import polyscrew on
    each platform it declares)."""
    version = cargo_version()
    problems: list[str] = []
    with zipfile.ZipFile(path) as archive:
        names = set(archive.namelist())
        if MANIFEST not in names:
            return [f"{path.name}: no {MANIFEST} at the top of the zip"]
        try:
            manifest = zip_manifest(archive)
        except tomllib.TOMLDecodeError as error:
            return [f"{path.name}: {MANIFEST} is not TOML: {error}"]
    if manifest.get("id") != EXTENSION_ID:
        problems.append(f"id is {manifest.get('id')!r}, not {EXTENSION_ID!r}")
    if manifest.get("version") != version:
        problems.append(f"version is {manifest.get('version')!r}, the workspace Cargo.toml says {version!r}")
    listed = [w.removeprefix("./") for w in manifest.get("wheels", [])]
    platforms = manifest.get("platforms", [])
    zipped = sorted(n for n in names if n.endswith(".whl"))
    for wheel in listed:
        if wheel not in names:
            problems.append(f"wheel listed in the manifest but not in the zip: {wheel}")
    for wheel in zipped:
        if wheel not in listed:
            problems.append(f"wheel in the zip but not listed in the manifest: {wheel}")
    if not platforms:
        problems.append("no platforms declared (the bundled wheel is platform-specific)")
    served: set[str] = set()
    for wheel in listed:
        name = wheel.rsplit("/", 1)[-1]
        try:
            distribution, wheel_version = wheel_fields(name)[:2]
            runs_on = wheel_platforms(name)
        except PackagingError as error:
            problems.append(str(error))
            continue
        if distribution == "polyscrew" and wheel_version != version:
            problems.append(f"{name}: version {wheel_version}, the extension is {version}")
        outside = [p for p in runs_on if p not in platforms]
        if outside:
            problems.append(f"{name} runs on {', '.join(outside)}, which the manifest does not declare")
        served.update(runs_on)
    for platform in platforms:
        if platform not in served:
            problems.append(f"platform {platform} declared but no polyscrew wheel in the zip runs on it")
    suffix = re.fullmatch(rf"{EXTENSION_ID}-[^-]+-(\w+)\.zip", path.name)
    if suffix and [p.replace("-", "_") for p in platforms] != [suffix.group(1)]:
        problems.append(f"named for {suffix.group(1)} but declares {platforms}")
    return [f"{path.name}: {p}" for p in problems]


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="command", required=True)
    sub.add_parser("tools", help="the Blender extension tools in .venv/bpy, newest first")
    sub.add_parser("version", help="the workspace Cargo.toml's version")
    sub.add_parser("platform", help="this machine's Blender platform, as Blender names it")
    staging = sub.add_parser("stage", help="the source folder for Blender's build")
    staging.add_argument("--wheels", type=Path, required=True, help="folder holding polyscrew-*.whl")
    staging.add_argument("--into", type=Path, required=True, help="source folder to (re)create")
    checking = sub.add_parser("check", help="a built zip's manifest against its content")
    checking.add_argument("zips", type=Path, nargs="+")
    args = parser.parse_args(argv)
    try:
        if args.command == "tools":
            tools = blender_tools()
            if not tools:
                raise PackagingError("no bpy/<ver>/scripts/addons_core/bl_pkg/cli/blender_ext.py under .venv/bpy")
            for tool, tags in tools:
                print(tool, tags)
        elif args.command == "version":
            print(cargo_version())
        elif args.command == "platform":
            print(blender_ext().platform_from_this_system())
        elif args.command == "stage":
            for platform in stage(args.wheels, args.into):
                print(platform)
        else:
            problems = [p for path in args.zips for p in check_zip(path)]
            for problem in problems:
                print(f"extension check: {problem}", file=sys.stderr)
            if problems:
                return 1
            for path in args.zips:
                print(f"extension check: {path.name}: OK (wheels and platforms match, version {cargo_version()})")
    except PackagingError as error:
        print(f"extension: {error}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
