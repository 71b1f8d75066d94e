#!/usr/bin/env bash
# Creates the project-local virtual environment .venv with everything the project needs:
# the build and test requirements (tests/requirements.txt) and the Blender-as-a-module
# wheels, each installed as an importable tree under .venv/bpy/<major.minor> with numpy 1.26
# (what Blender itself bundles). Idempotent: a stamp per part skips what is already there.
# Downloads are cached in .venv/pip-cache.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
venv="$root/.venv"
python=${PYTHON:-}
if [ -z "$python" ]; then
  for candidate in python3.11 python3; do
    if command -v "$candidate" >/dev/null && "$candidate" -c 'import sys; sys.exit(sys.version_info[:2] != (3, 11))'; then
      python=$candidate; break
    fi
  done
fi
[ -n "$python" ] || { echo "bootstrap: CPython 3.11 is needed (the bpy wheels are built for it); set PYTHON=" >&2; exit 1; }

# The Blender versions the add-on is tested against (bpy wheels from PyPI, CPython 3.11).
BPY_VERSIONS=${BPY_VERSIONS:-"4.2.23 5.0.1"}

[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
pip=("$venv/bin/python" -m pip --disable-pip-version-check --cache-dir "$venv/pip-cache")

req_hash=$(sha256sum "$root/tests/requirements.txt" | cut -c1-16)
if [ ! -f "$venv/.stamp-requirements-$req_hash" ]; then
  echo "bootstrap: installing tests/requirements.txt into .venv"
  "${pip[@]}" install -q --upgrade pip
  "${pip[@]}" install -q -r "$root/tests/requirements.txt"
  rm -f "$venv"/.stamp-requirements-*
  touch "$venv/.stamp-requirements-$req_hash"
fi

for version in $BPY_VERSIONS; do
  target="$venv/bpy/${version%.*}"
  if [ ! -f "$target/.stamp-bpy-$version" ]; then
    echo "bootstrap: installing bpy $version into .venv/bpy/${version%.*} (about 350 MB download)"
    rm -rf "$target"
    "${pip[@]}" install -q --target "$target" "bpy==$version" "numpy>=1.26,<2"
    touch "$target/.stamp-bpy-$version"
  fi
done
echo "bootstrap: .venv ready ($("$venv/bin/python" --version); bpy $BPY_VERSIONS)"
