"""Ready to publish: `cargo publish --dry-run -p polyscrew` passes (crates.io's index is read,
nothing is uploaded) and leaves the tree as it was; the version is written once; the crate's
README example is the crate's compiled doc example; CHANGELOG.md has the version's section."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
import tomllib

import pytest

from conftest import ROOT, extension

#: The files of the published crate (cargo refuses uncommitted changes to them).
CRATE_FILES = ["rust/polyscrew", "Cargo.toml", "Cargo.lock", "LICENSE"]


def git_status(*paths: str) -> str:
    done = subprocess.run(
        ["git", "status", "--porcelain", "--untracked-files=all", "--", *paths],
        cwd=ROOT, capture_output=True, text=True,
    )
    assert done.returncode == 0, f"git status failed: {done.stderr}"
    return done.stdout


@pytest.mark.skipif(shutil.which("cargo") is None, reason="no cargo")
def test_cargo_publish_dry_run(capsys):
    before = git_status()
    command = ["cargo", "publish", "--dry-run", "--locked", "-p", "polyscrew"]
    # A clean checkout (CI) is published as it is. Uncommitted work on the crate (a developer
    # running scripts/test.sh before committing) needs --allow-dirty, which changes nothing
    # else in a dry run: the package is still built and verified from the working tree.
    dirty = git_status(*CRATE_FILES)
    if dirty:
        command.insert(3, "--allow-dirty")
        with capsys.disabled():
            print(f"\n(cargo publish --dry-run --allow-dirty: uncommitted changes in\n{dirty})")
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True, timeout=900)
    output = done.stdout + done.stderr
    assert done.returncode == 0, output
    assert "Verifying polyscrew" in output and "aborting upload due to dry run" in output, output
    assert "warning" not in output.lower().replace("warning: aborting upload due to dry run", ""), output
    assert git_status() == before, "cargo publish --dry-run changed the working tree"


def test_crate_metadata_complete():
    crate = tomllib.loads((ROOT / "rust" / "polyscrew" / "Cargo.toml").read_text())["package"]
    workspace = tomllib.loads((ROOT / "Cargo.toml").read_text())["workspace"]["package"]
    for key in ("description", "readme", "keywords", "categories", "documentation"):
        assert crate.get(key), key
    for key in ("version", "license", "repository", "edition", "rust-version"):
        assert crate.get(key) == {"workspace": True} and workspace.get(key), key
    assert len(crate["keywords"]) <= 5 and all(len(k) <= 20 for k in crate["keywords"])
    assert (ROOT / "rust" / "polyscrew" / "LICENSE").read_text() == (ROOT / "LICENSE").read_text()
    assert "GNU GENERAL PUBLIC LICENSE" in (ROOT / "LICENSE").read_text()[:200]


def test_crate_readme_example_is_the_compiled_doc_example():
    readme = (ROOT / "rust" / "polyscrew" / "README.md").read_text()
    example = re.search(r"```rust\n(.*?)```", readme, re.S).group(1)
    lib = (ROOT / "rust" / "polyscrew" / "src" / "lib.rs").read_text()
    doc = "".join(line[4:] + "\n" for line in lib.splitlines() if line.startswith("//! ") or line == "//!")
    assert example in doc, "README example differs from the lib.rs doc test (which cargo test compiles)"


def test_version_is_written_once():
    version = extension.cargo_version()
    assert re.fullmatch(r"\d+\.\d+\.\d+", version)
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    assert "version" not in pyproject and "version" in pyproject["dynamic"]
    for member in ("rust/polyscrew", "rust/polyscrew-py"):
        package = tomllib.loads((ROOT / member / "Cargo.toml").read_text())["package"]
        assert package["version"] == {"workspace": True}, member


def test_changelog_has_the_current_version():
    changelog = (ROOT / "CHANGELOG.md").read_text()
    versions = re.findall(r"^## \[?(\d+\.\d+\.\d+)\]?", changelog, re.M)
    assert versions and versions[0] == extension.cargo_version(), versions


def test_git_status_failing_is_an_error(monkeypatch, tmp_path):
    """Outside a checkout `git status` fails: that is an error, not an empty (clean) status
    that would let the tree-unchanged check pass whatever happened."""
    monkeypatch.setattr(sys.modules[__name__], "ROOT", tmp_path)
    monkeypatch.setenv("GIT_CEILING_DIRECTORIES", str(tmp_path.parent))
    with pytest.raises(AssertionError, match="git status failed"):
        git_status()
