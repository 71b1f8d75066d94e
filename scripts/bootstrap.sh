#!/usr/bin/env bash
# Creates the project-local virtual environment .venv with everything the project needs:
# the build and test requirements (tests/requirements.txt) and the Blender-as-a-module
# wheels of every version in scripts/blender_matrix.sh, each installed as an importable tree
# under .venv/bpy/<major.minor> with the numpy Blender itself bundles. A bpy built for another
# CPython than 3.11 (5.2: 3.13) gets a small venv of its own, .venv/py<XY> (pytest, numpy,
# scipy), from a CPython found on the machine (scripts/blender_matrix.sh: find_cpython).
# When that CPython is missing, the version is left out with a message and scripts/test.sh
# fails on it; the demo and benchmarks (bpy 5.0) still work.
# Idempotent: a stamp per part skips what is already there. Downloads are cached in
# .venv/pip-cache.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
venv="$root/.venv"
source "$root/scripts/blender_matrix.sh"

python=$(find_cpython 3.11) ||
  { echo "bootstrap: CPython 3.11 is needed (the project venv and the bpy 4.2-5.0 wheels); set PYTHON=" >&2; exit 1; }

[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
pip_in() { # pip of the venv $1, with the shared download cache
  local env=$1; shift
  "$env/bin/python" -m pip --disable-pip-version-check --cache-dir "$venv/pip-cache" "$@"
}

req_hash=$(sha256sum "$root/tests/requirements.txt" | cut -c1-16)
if [ ! -f "$venv/.stamp-requirements-$req_hash" ]; then
  echo "bootstrap: installing tests/requirements.txt into .venv"
  pip_in "$venv" install -q --upgrade pip
  pip_in "$venv" install -q -r "$root/tests/requirements.txt"
  rm -f "$venv"/.stamp-requirements-*
  touch "$venv/.stamp-requirements-$req_hash"
fi

ready=()
for row in "${BLENDER_MATRIX[@]}"; do
  read -r version cpython numpy_spec <<<"$row"
  env_dir=$(matrix_venv "$cpython")
  if [ "$env_dir" != "$venv" ]; then
    # The small venv of another CPython: what tests/blender needs besides bpy.
    stamp="$env_dir/.stamp-venv-$(echo "$numpy_spec" | sha256sum | cut -c1-16)"
    if [ ! -f "$stamp" ]; then
      if ! interpreter=$(find_cpython "$cpython"); then
        echo "bootstrap: bpy $version left out: $(missing_cpython "$cpython" "Blender $version")" >&2
        continue
      fi
      echo "bootstrap: creating .venv/$(basename "$env_dir") from $interpreter ($("$interpreter" --version))"
      rm -rf "$env_dir"
      "$interpreter" -m venv "$env_dir"
      pip_in "$env_dir" install -q --upgrade pip
      pip_in "$env_dir" install -q pytest "$numpy_spec" scipy
      touch "$stamp"
    fi
  fi
  target="$venv/bpy/${version%.*}"
  if [ ! -f "$target/.stamp-bpy-$version" ]; then
    echo "bootstrap: installing bpy $version (CPython $cpython) into .venv/bpy/${version%.*} (about 350 MB download)"
    rm -rf "$target"
    pip_in "$env_dir" install -q --target "$target" "bpy==$version" "$numpy_spec"
    touch "$target/.stamp-bpy-$version"
  fi
  ready+=("$version")
done
echo "bootstrap: .venv ready ($("$venv/bin/python" --version); bpy ${ready[*]})"
