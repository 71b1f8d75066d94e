"""A fresh clone builds the extension with the one README command (issue 24, item 10).

`git clone` of this repository's committed HEAD into a temporary folder (no `.venv`, no
`dist/`, no `target/`), then `scripts/build_extension.sh` there, with nothing of this checkout's
environment: it must take what building needs itself (`scripts/bootstrap.sh --build`: maturin,
ziglang and Blender's extension tool, not the Blender wheels) and write this machine's zip.

Cost: the clone's own release build of polyscrew (the cargo registry is shared) and no second
download: bootstrap's pip cache is pointed at this checkout's `.venv/pip-cache`, which
`scripts/bootstrap.sh` fills (or SCREWBENDER_PIP_CACHE). The time taken is printed.
"""

from __future__ import annotations

import os
import subprocess
import time
import zipfile
from pathlib import Path

import extension  # scripts/extension.py (tests/packaging/conftest.py puts scripts/ on the path)

ROOT = Path(__file__).resolve().parents[2]

#: Variables of this checkout's environment that would let the clone use its tools.
_FOREIGN = ("PYTHON", "VIRTUAL_ENV", "MATURIN", "BLENDER_EXT", "SCREWBENDER_WHEEL", "CARGO_TARGET_DIR", "PYTHONPATH")


def _clone_env() -> dict[str, str]:
    env = {k: v for k, v in os.environ.items() if k not in _FOREIGN}
    venv_bin = str(ROOT / ".venv" / "bin")
    env["PATH"] = os.pathsep.join(p for p in env.get("PATH", "").split(os.pathsep) if p and Path(p) != Path(venv_bin))
    env.setdefault("SCREWBENDER_PIP_CACHE", str(ROOT / ".venv" / "pip-cache"))
    return env


def test_fresh_clone_builds_the_extension_with_the_readme_command(tmp_path: Path) -> None:
    readme = (ROOT / "README.md").read_text()
    assert "`scripts/build_extension.sh`" in readme, "the README names the command that builds from source"
    head = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "HEAD"], check=True, capture_output=True, text=True)
    clone = tmp_path / "screwbender"
    subprocess.run(["git", "clone", "-q", "--no-checkout", str(ROOT), str(clone)], check=True)
    subprocess.run(["git", "-C", str(clone), "checkout", "-q", "--detach", head.stdout.strip()], check=True)
    assert not (clone / ".venv").exists() and not (clone / "dist").exists() and not (clone / "target").exists()

    started = time.monotonic()
    done = subprocess.run(
        ["scripts/build_extension.sh"], cwd=clone, env=_clone_env(), capture_output=True, text=True,
        stdin=subprocess.DEVNULL, timeout=3600,
    )
    elapsed = time.monotonic() - started
    print(f"\nfresh clone: scripts/build_extension.sh took {elapsed:.0f} s (exit {done.returncode})")
    assert done.returncode == 0, f"build_extension.sh failed on a fresh clone:\n{done.stderr[-4000:]}"
    assert "scripts/bootstrap.sh --build" in done.stderr, done.stderr[-2000:]
    # only what building needs: no Blender installed into the clone's .venv
    assert not (clone / ".venv" / "bpy").exists(), "bootstrap --build installed Blender wheels"
    assert list((clone / ".venv" / "bpy-tools").glob(f"*/bpy/*/{extension.TOOL_IN_BPY}"))

    this_zip = Path(done.stdout.strip().splitlines()[-1])
    platform = extension.blender_ext().platform_from_this_system().replace("-", "_")
    assert this_zip == clone / "dist" / f"screwbender-{extension.cargo_version()}-{platform}.zip"
    assert this_zip.is_file()
    assert extension.check_zip(this_zip) == []
    with zipfile.ZipFile(this_zip) as archive:
        wheels = [n for n in archive.namelist() if n.startswith("wheels/polyscrew-") and n.endswith(".whl")]
    assert len(wheels) == 1, wheels

    # A second run finds everything in place: no bootstrap again.
    again = subprocess.run(
        ["scripts/build_extension.sh"], cwd=clone, env={**_clone_env(), "SCREWBENDER_WHEEL": str(
            next((clone / "dist" / "wheels").glob("polyscrew-*.whl")))},
        capture_output=True, text=True, stdin=subprocess.DEVNULL, timeout=600,
    )
    assert again.returncode == 0, again.stderr[-2000:]
    assert "bootstrap.sh" not in again.stderr
