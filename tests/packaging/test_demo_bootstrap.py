"""The demo installs only the Blender it runs; the tests install every Blender (issue 25, item 6).

`scripts/demo.sh` and `scripts/bootstrap.sh` run, unchanged, in a scratch copy of the project
whose `.venv` Python is a stand-in: every `python -m pip ...` it is asked for is written to a
log and not run (an `install --target DIR` only makes DIR), anything else goes to this Python.
So the test downloads nothing and sees exactly what each command would install:
- `scripts/demo.sh`: the demo's requirements (maturin, numpy, matplotlib, ziglang: not the test
  oracles of tests/requirements.txt) and the bpy wheel of Blender 5.0 alone, then it goes on to
  build the extension (here a stand-in that stops the demo);
- `scripts/bootstrap.sh` as `scripts/test.sh` runs it: the bpy wheel of every row of
  `scripts/blender_matrix.sh`.
"""

from __future__ import annotations

import os
import re
import shutil
import stat
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

_STAND_IN = """#!/usr/bin/env bash
if [ "${1:-}" = -m ] && [ "${2:-}" = pip ]; then
  echo "$0 $*" >> "$PIP_LOG"
  while [ $# -gt 0 ]; do
    if [ "$1" = --target ]; then mkdir -p "$2"; fi
    shift
  done
  exit 0
fi
exec "$REAL_PYTHON" "$@"
"""


def _matrix() -> list[tuple[str, str, str]]:
    rows = subprocess.run(
        ["bash", "-c", 'root=.; source scripts/blender_matrix.sh; printf "%s\\n" "${BLENDER_MATRIX[@]}"'],
        cwd=ROOT, check=True, capture_output=True, text=True, env={k: v for k, v in os.environ.items()
                                                                    if k != "BLENDER_VERSIONS"},
    ).stdout.splitlines()
    return [tuple(row.split()) for row in rows]


def _scratch(tmp_path: Path) -> tuple[Path, dict[str, str]]:
    """A copy of the scripts bootstrap needs, a stand-in .venv Python (and one per other CPython
    of the matrix, its venv stamped as made), and the environment to run them in."""
    root = tmp_path / "project"
    (root / "scripts").mkdir(parents=True)
    (root / "tests").mkdir()
    for name in ("bootstrap.sh", "blender_matrix.sh", "demo.sh"):
        shutil.copy2(ROOT / "scripts" / name, root / "scripts" / name)
    shutil.copy2(ROOT / "tests" / "requirements.txt", root / "tests" / "requirements.txt")
    stop = root / "scripts" / "build_extension.sh"
    stop.write_text("#!/usr/bin/env bash\necho 'build_extension stand-in: the demo stops here' >&2\nexit 3\n")
    stop.chmod(stop.stat().st_mode | stat.S_IEXEC)
    envs = {root / ".venv"}
    for _version, cpython, numpy_spec in _matrix():
        if cpython != "3.11":
            env_dir = root / ".venv" / f"py{cpython.replace('.', '')}"
            envs.add(env_dir)
            digest = subprocess.run(["bash", "-c", 'echo "$1" | sha256sum | cut -c1-16', "-", numpy_spec],
                                    check=True, capture_output=True, text=True).stdout.strip()
            env_dir.mkdir(parents=True, exist_ok=True)
            (env_dir / f".stamp-venv-{digest}").touch()
    for env_dir in envs:
        (env_dir / "bin").mkdir(parents=True, exist_ok=True)
        python = env_dir / "bin" / "python"
        python.write_text(_STAND_IN)
        python.chmod(0o755)
    env = {k: v for k, v in os.environ.items() if k not in ("BLENDER_VERSIONS", "VIRTUAL_ENV", "PYTHONPATH")}
    env.update(PIP_LOG=str(tmp_path / "pip.log"), REAL_PYTHON=sys.executable, PYTHON=sys.executable,
               SCREWBENDER_PIP_CACHE=str(tmp_path / "pip-cache"))
    return root, env


def _bpy_installed(log: Path) -> list[str]:
    return re.findall(r"install -q --target \S+/\.venv/bpy/\S+ bpy==(\S+)", log.read_text() if log.exists() else "")


def test_the_demo_installs_only_the_blender_it_runs(tmp_path: Path) -> None:
    root, env = _scratch(tmp_path)
    done = subprocess.run(["scripts/demo.sh"], cwd=root, env=env, capture_output=True, text=True,
                          stdin=subprocess.DEVNULL, timeout=300)
    log = Path(env["PIP_LOG"])
    installed = _bpy_installed(log)
    print(f"\ndemo.sh: bpy wheels installed {installed}; bootstrap said:\n"
          + "\n".join(line for line in done.stdout.splitlines() if line.startswith("bootstrap:")))
    assert "build_extension stand-in" in done.stderr, (done.stdout[-2000:], done.stderr[-2000:])
    demo_row = [row for row in _matrix() if row[0].startswith("5.0.")]
    assert installed == [demo_row[0][0]], installed
    # the demo's requirements alone (building the wheel, the demo's parts), not the test oracles
    pips = [line.split(" install -q ", 1)[1].split() for line in log.read_text().splitlines()
            if " install -q " in line and "--target" not in line and "--upgrade pip" not in line]
    print(f"demo.sh: pip installs {pips}")
    assert [[spec.split(">")[0].split("=")[0] for spec in specs] for specs in pips] \
        == [["maturin", "numpy", "matplotlib", "ziglang"]], pips
    assert "-r " not in log.read_text() and "requirements.txt" not in log.read_text()
    assert sorted(p.name for p in (root / ".venv" / "bpy").iterdir()) == ["5.0"]


def test_the_tests_bootstrap_installs_every_blender(tmp_path: Path) -> None:
    root, env = _scratch(tmp_path)
    done = subprocess.run(["scripts/bootstrap.sh"], cwd=root, env=env, capture_output=True, text=True,
                          stdin=subprocess.DEVNULL, timeout=300)
    assert done.returncode == 0, done.stderr[-2000:]
    installed = _bpy_installed(Path(env["PIP_LOG"]))
    print(f"\nbootstrap.sh: bpy wheels installed {installed}")
    assert installed == [row[0] for row in _matrix()], installed
    # and a second run finds them in place (the per-version stamps)
    Path(env["PIP_LOG"]).unlink()
    again = subprocess.run(["scripts/bootstrap.sh"], cwd=root, env=env, capture_output=True, text=True,
                           stdin=subprocess.DEVNULL, timeout=300)
    assert again.returncode == 0 and _bpy_installed(Path(env["PIP_LOG"])) == [], again.stdout[-2000:]
