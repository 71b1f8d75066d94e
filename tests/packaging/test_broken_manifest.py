"""Broken extension zips are caught before an animator gets them: each is this machine's built
zip with one thing wrong in its manifest (or content).

Blender's `validate` checks the manifest's fields (and fails on the malformed ones below); it
does not compare the `wheels` list with the zip's content, so `scripts/extension.py check`
(run by scripts/build_extension.sh on every zip) does."""

from __future__ import annotations

import json
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from conftest import ROOT, TOOLS, extension, tool_id
from test_extension_zips import blender_validate


def dump_toml(data: dict) -> str:
    """A flat manifest (strings and lists of strings) as TOML."""
    return "".join(f"{key} = {json.dumps(value)}\n" for key, value in data.items())


def rewrite(source: Path, target: Path, edit=None, drop: str | None = None, raw: str | None = None) -> Path:
    """A copy of the zip whose manifest is edited (a function of the flat manifest dict) or
    replaced by raw text, optionally without one member."""
    with zipfile.ZipFile(source) as zipped:
        manifest = extension.zip_manifest(zipped)
        manifest.pop("build", None)  # [build.generated] already folded in
        if edit is not None:
            edit(manifest)
        text = raw if raw is not None else dump_toml(manifest)
        with zipfile.ZipFile(target, "w") as out:
            for info in zipped.infolist():
                if info.filename == drop:
                    continue
                data = text.encode() if info.filename == "blender_manifest.toml" else zipped.read(info)
                out.writestr(info, data)
    return target


def other_wheel(manifest: dict) -> str:
    return manifest["wheels"][0].rsplit("-", 1)[0] + "-win_amd64.whl"


def test_the_unbroken_copy_passes(this_zip, tmp_path):
    """The rewriting itself breaks nothing: the copy with the manifest as it was passes."""
    copy = rewrite(this_zip, tmp_path / this_zip.name)
    assert extension.check_zip(copy) == []
    for tool in TOOLS:
        assert blender_validate(tool, copy).returncode == 0


BROKEN = {
    "listed wheel not in the zip": (
        lambda m: (m["wheels"].append(other_wheel(m)), m["platforms"].append("windows-x64")),
        "wheel listed in the manifest but not in the zip: wheels/polyscrew-",
    ),
    "wheel in the zip not listed": (
        lambda m: m.update(wheels=[]),
        "wheel in the zip but not listed in the manifest: wheels/polyscrew-",
    ),
    "platform without a wheel": (
        lambda m: m["platforms"].append("macos-arm64" if "macos-arm64" not in m["platforms"] else "linux-x64"),
        "declared but no polyscrew wheel in the zip runs on it",
    ),
    "wheel's platform not declared": (
        lambda m: m.update(platforms=["windows-x64" if m["platforms"] != ["windows-x64"] else "linux-x64"]),
        "which the manifest does not declare",
    ),
    "no platforms": (lambda m: m.pop("platforms"), "no platforms declared"),
    "version not the workspace's": (lambda m: m.update(version="9.9.9"), "the workspace Cargo.toml says"),
}


@pytest.mark.parametrize("case", BROKEN, ids=list(BROKEN))
def test_extension_check_fails_on_a_broken_manifest(case, this_zip, tmp_path):
    edit, expected = BROKEN[case]
    broken = rewrite(this_zip, tmp_path / this_zip.name, edit=edit)
    problems = extension.check_zip(broken)
    assert any(expected in p for p in problems), problems
    done = subprocess.run(
        [sys.executable, str(ROOT / "scripts" / "extension.py"), "check", str(broken)], capture_output=True, text=True
    )
    assert done.returncode == 1 and expected in done.stderr, done.stdout + done.stderr


MALFORMED = {
    "platforms not a list": ('platforms = "linux-x64"', None),
    "wheel path with backslashes": ('wheels = ["wheels\\\\polyscrew-0.1.0-cp311-abi3-win_amd64.whl"]', None),
    "unknown tag": ('tags = ["Smoothing"]', None),
    "no __init__.py": (None, "__init__.py"),
}


@pytest.mark.parametrize("tool", TOOLS, ids=tool_id)
@pytest.mark.parametrize("case", MALFORMED, ids=list(MALFORMED))
def test_blender_validate_fails_on_a_malformed_manifest(case, tool, this_zip, tmp_path):
    line, drop = MALFORMED[case]
    with zipfile.ZipFile(this_zip) as zipped:
        manifest = extension.zip_manifest(zipped)
    manifest.pop("build", None)
    text = dump_toml(manifest)
    if line is not None:
        key = line.split(" = ")[0]
        text = "".join(l for l in text.splitlines(keepends=True) if not l.startswith(f"{key} = ")) + line + "\n"
    broken = rewrite(this_zip, tmp_path / this_zip.name, raw=text, drop=drop)
    done = blender_validate(tool, broken)
    assert done.returncode != 0, f"{case}: {done.stdout}{done.stderr}"
    assert "Success parsing TOML" not in done.stdout + done.stderr
