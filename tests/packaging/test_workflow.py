""".github/workflows/release.yml cannot run on these machines (no Windows or macOS runners):
it is parsed, validated against GitHub's workflow schema (check-jsonschema's copy), audited by
zizmor (offline), and read for what it must do: a wheel for each of the four platforms, one job
assembling a zip per platform with scripts/build_extension.sh, and the Blender suite on each
platform, all through the project's own scripts and pytest commands."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from conftest import ROOT

WORKFLOW = ROOT / ".github" / "workflows" / "release.yml"
PLATFORMS = {"linux-x64", "windows-x64", "macos-arm64", "macos-x64"}
VENV_BIN = Path(sys.executable).parent


@pytest.fixture(scope="module")
def workflow() -> dict:
    return yaml.safe_load(WORKFLOW.read_text())


def steps_text(job: dict) -> str:
    return "\n".join(str(step.get("run", "")) + str(step.get("uses", "")) + str(step.get("with", "")) for step in job["steps"])


def test_schema_of_github_workflows():
    done = subprocess.run(
        [str(VENV_BIN / "check-jsonschema"), "--builtin-schema", "vendor.github-workflows", str(WORKFLOW)],
        capture_output=True, text=True,
    )
    assert done.returncode == 0, done.stdout + done.stderr


def test_zizmor_finds_nothing():
    done = subprocess.run(
        [str(VENV_BIN / "zizmor"), "--offline", "--persona", "pedantic", str(WORKFLOW)],
        capture_output=True, text=True,
    )
    assert done.returncode == 0, done.stdout + done.stderr
    assert "No findings" in done.stdout + done.stderr


def test_wheels_for_the_four_platforms_abi3_manylinux_2_28(workflow):
    job = workflow["jobs"]["wheels"]
    rows = job["strategy"]["matrix"]["include"]
    assert {row["platform"] for row in rows} == PLATFORMS
    maturin = next(s for s in job["steps"] if str(s.get("uses", "")).startswith("PyO3/maturin-action@"))
    assert maturin["with"]["manylinux"] == "2_28"
    assert "--release" in maturin["with"]["args"]
    assert maturin["env"]["MACOSX_DEPLOYMENT_TARGET"] == "11.0"
    targets = {row["platform"]: row["target"] for row in rows}
    assert targets == {
        "linux-x64": "x86_64-unknown-linux-gnu",
        "windows-x64": "x86_64-pc-windows-msvc",
        "macos-arm64": "aarch64-apple-darwin",
        "macos-x64": "x86_64-apple-darwin",
    }
    # abi3: the binding's pyo3 feature makes one wheel per platform serve CPython 3.11+.
    assert '"abi3-py311"' in (ROOT / "rust" / "polyscrew-py" / "Cargo.toml").read_text()


def test_one_job_assembles_and_validates_with_the_projects_scripts(workflow):
    job = workflow["jobs"]["extension"]
    assert job["needs"] == "wheels"
    text = steps_text(job)
    assert "scripts/bootstrap.sh" in text
    assert "scripts/build_extension.sh --wheels" in text
    assert "-m pytest -q -p no:cacheprovider tests/packaging" in text


def test_blender_suite_on_each_platform_against_its_zip(workflow):
    job = workflow["jobs"]["blender-tests"]
    assert job["needs"] == "extension"
    rows = job["strategy"]["matrix"]["include"]
    assert {row["platform"] for row in rows} == PLATFORMS
    assert all(row["bpy"].split() for row in rows)
    assert job["env"]["BLENDER_VERSIONS"] == "${{ matrix.bpy }}"
    matrix = (ROOT / "scripts" / "blender_matrix.sh").read_text()
    for row in rows:  # every version named is one of the project's matrix
        for version in row["bpy"].split():
            assert f'"{version}.' in matrix, (row["platform"], version)
    text = steps_text(job)
    assert "scripts/bootstrap.sh" in text
    # the same script as scripts/test.sh runs the Blender tests with
    assert "scripts/test_blender.sh" in text
    assert "scripts/test_blender.sh" in (ROOT / "scripts" / "test.sh").read_text()


def test_runners_are_the_platforms_they_claim(workflow):
    """Blender tests run natively (bpy cannot be cross-run): Intel Mac on an Intel runner."""
    runners = {row["platform"]: row["runner"] for row in workflow["jobs"]["blender-tests"]["strategy"]["matrix"]["include"]}
    assert runners["macos-x64"] == "macos-15-intel"
    assert runners["macos-arm64"].startswith("macos-") and "intel" not in runners["macos-arm64"]
    assert runners["windows-x64"].startswith("windows-") and runners["linux-x64"].startswith("ubuntu-")
