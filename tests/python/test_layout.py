"""The README's Layout table against `git ls-files`: every path in it exists, and every
tracked file lies under one of its paths (a file named exactly, or a folder)."""

from __future__ import annotations

import re
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]


def layout_paths() -> list[str]:
    text = (ROOT / "README.md").read_text()
    section = text.split("\n## Layout\n", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| `")]
    paths = []
    for row in rows:
        first_cell = row.split("|")[1]
        paths += re.findall(r"`([^`]+)`", first_cell)
    return paths


def tracked_files() -> list[str]:
    if shutil.which("git") is None or not (ROOT / ".git").exists():
        pytest.fail("the layout check needs git and a git checkout")
    out = subprocess.run(["git", "ls-files"], cwd=ROOT, capture_output=True, text=True, check=True).stdout
    return [line for line in out.splitlines() if line]


def covers(path: str, file: str) -> bool:
    return file == path or file.startswith(path.rstrip("/") + "/")


def test_every_layout_path_is_tracked():
    files = tracked_files()
    paths = layout_paths()
    assert len(paths) >= 20, paths
    missing = [p for p in paths if not any(covers(p, f) for f in files)]
    assert not missing, f"README Layout names paths that git does not track: {missing}"


def test_every_tracked_file_is_in_the_layout():
    paths = layout_paths()
    left_out = [f for f in tracked_files() if not any(covers(p, f) for p in paths)]
    assert not left_out, f"tracked files the README Layout table does not cover: {left_out}"


def test_each_core_module_folder_opens_with_its_doc():
    src = ROOT / "rust" / "polyscrew" / "src"
    folders = [p for p in src.iterdir() if p.is_dir()]
    assert {p.name for p in folders} >= {"motion", "sweep", "feature", "angular_velocity", "numeric"}
    for folder in folders:
        first = (folder / "mod.rs").read_text().splitlines()[0]
        assert first.startswith("//! "), f"{folder.name}/mod.rs does not open with a module doc"
        assert f"`rust/polyscrew/src/{folder.name}`" in (ROOT / "README.md").read_text(), folder.name
