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
# .venv/pip-cache (SCREWBENDER_PIP_CACHE: another folder, e.g. a cache another clone filled).
#
#   scripts/bootstrap.sh           everything (the tests, the demo, the benchmarks)
#   BLENDER_VERSIONS=5.0 scripts/bootstrap.sh
#                                  the same with only the bpy wheels of the versions named (full
#                                  or major.minor, space-separated; scripts/blender_matrix.sh
#                                  reads it): what scripts/demo.sh installs (one Blender, about
#                                  350 MB, not four, about 1.4 GB); scripts/test.sh installs all
#   BLENDER_VERSIONS=5.0 scripts/bootstrap.sh --demo
#                                  what scripts/demo.sh runs, and nothing else: maturin and
#                                  ziglang (the wheel), numpy and matplotlib (the demo's parts) as
#                                  tests/requirements.txt pins them, and the bpy wheels named;
#                                  not the test-only oracles (scipy, numba, hypothesis, ...)
#   scripts/bootstrap.sh --build   only what building the extension needs (what
#                                  scripts/build_extension.sh runs when it misses it): maturin and
#                                  ziglang in .venv, and Blender's extension tool (blender_ext.py
#                                  and its tags.py) taken out of the newest CPython 3.11 bpy wheel
#                                  into .venv/bpy-tools/<major.minor>, without installing Blender
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
venv="$root/.venv"
source "$root/scripts/blender_matrix.sh"
build_only=false demo_only=false
case "${1:-}" in
  "") ;;
  --build) build_only=true ;;
  --demo) demo_only=true ;;
  *) echo "usage: scripts/bootstrap.sh [--build|--demo]" >&2; exit 2 ;;
esac
pip_cache=${SCREWBENDER_PIP_CACHE:-$venv/pip-cache}

python=$(find_cpython 3.11) ||
  { echo "bootstrap: CPython 3.11 is needed (the project venv and the bpy 4.2-5.0 wheels); set PYTHON=" >&2; exit 1; }

[ -x "$venv/bin/python" ] || "$python" -m venv "$venv"
pip_in() { # pip of the venv $1, with the shared download cache
  local env=$1; shift
  "$env/bin/python" -m pip --disable-pip-version-check --cache-dir "$pip_cache" "$@"
}

if $build_only; then
  # maturin and ziglang as tests/requirements.txt pins them
  build_reqs=$(grep -E '^(maturin|ziglang)\b' "$root/tests/requirements.txt" | sed -E 's/ *#.*//')
  stamp="$venv/.stamp-build-$(echo "$build_reqs" | sha256sum | cut -c1-16)"
  if [ ! -f "$stamp" ] && ! ls "$venv"/.stamp-requirements-* >/dev/null 2>&1; then
    echo "bootstrap: installing $(echo $build_reqs) into .venv (building only)"
    # shellcheck disable=SC2086
    pip_in "$venv" install -q $(echo "$build_reqs" | tr '\n' ' ')
    touch "$stamp"
  fi
  if ! "$venv/bin/python" "$root/scripts/extension.py" tools >/dev/null 2>&1; then
    # the newest Blender on CPython 3.11: its wheel holds the tool (plain Python 3.11)
    for row in "${BLENDER_MATRIX[@]}"; do
      read -r version cpython _ <<<"$row"
      [ "$cpython" = 3.11 ] && tool_version=$version
    done
    minor=${tool_version%.*}
    echo "bootstrap: taking Blender $minor's extension tool out of the bpy $tool_version wheel (about 350 MB download, cached)"
    download=$(mktemp -d)
    pip_in "$venv" download -q --no-deps --only-binary :all: --python-version 3.11 -d "$download" "bpy==$tool_version"
    rm -rf "$venv/bpy-tools/$minor"
    "$venv/bin/python" - "$download"/bpy-*.whl "$venv/bpy-tools/$minor" "$minor" <<'PY'
import sys, zipfile
wheel, into, minor = sys.argv[1:]
inside = [f"bpy/{minor}/scripts/addons_core/bl_pkg/cli/blender_ext.py",
          f"bpy/{minor}/scripts/modules/_bpy_internal/extensions/tags.py"]
with zipfile.ZipFile(wheel) as archive:
    for name in inside:
        archive.extract(name, into)
PY
    rm -rf "$download"
  fi
  echo "bootstrap: .venv ready for building ($("$venv/bin/python" --version); $("$venv/bin/maturin" --version))"
  exit 0
fi

req_hash=$(sha256sum "$root/tests/requirements.txt" | cut -c1-16)
if $demo_only; then
  # the demo's part of tests/requirements.txt (a full bootstrap's stamp covers it too)
  demo_reqs=$(grep -E '^(maturin|ziglang|numpy|matplotlib)\b' "$root/tests/requirements.txt" | sed -E 's/ *#.*//')
  stamp="$venv/.stamp-demo-$(echo "$demo_reqs" | sha256sum | cut -c1-16)"
  if [ ! -f "$stamp" ] && [ ! -f "$venv/.stamp-requirements-$req_hash" ]; then
    echo "bootstrap: installing $(echo $demo_reqs) into .venv (the demo only)"
    pip_in "$venv" install -q --upgrade pip
    # shellcheck disable=SC2086
    pip_in "$venv" install -q $(echo "$demo_reqs" | tr '\n' ' ')
    touch "$stamp"
  fi
elif [ ! -f "$venv/.stamp-requirements-$req_hash" ]; then
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
