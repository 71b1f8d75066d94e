#!/usr/bin/env bash
# The headless Blender tests (tests/blender) under each Blender version of
# scripts/blender_matrix.sh, against the extension zip in dist/ (scripts/build_extension.sh),
# each with the interpreter its bpy wheel is built for. scripts/test.sh and the release
# workflow both run the Blender tests through here.
#
#   scripts/test_blender.sh            every version (BLENDER_VERSIONS="4.2 5.0" narrows it)
#   scripts/test_blender.sh 4.5.15     one version
#   scripts/test_blender.sh --check    only check that every version can run (exit 1 if not)
# Extra arguments after the version go to pytest.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
export PYTHONDONTWRITEBYTECODE=1
source scripts/blender_matrix.sh

missing=()
for row in "${BLENDER_MATRIX[@]}"; do
  read -r version cpython _ <<<"$row"
  if [ ! -x "$(matrix_venv "$cpython")/bin/python" ]; then
    missing+=("bpy $version: $(missing_cpython "$cpython" "Blender $version"), then run scripts/bootstrap.sh")
  elif [ ! -f ".venv/bpy/${version%.*}/.stamp-bpy-$version" ]; then
    missing+=("bpy $version: not installed in .venv/bpy/${version%.*}: run scripts/bootstrap.sh")
  fi
done
if [ ${#missing[@]} -gt 0 ]; then
  printf 'test: cannot test every Blender version:\n' >&2
  printf '  %s\n' "${missing[@]}" >&2
  exit 1
fi
[ "${1:-}" = --check ] && exit 0

only=${1:-}
[ $# -gt 0 ] && shift
ran=0
for row in "${BLENDER_MATRIX[@]}"; do
  read -r version cpython _ <<<"$row"
  [ -z "$only" ] || [ "$only" = "$version" ] || [ "$only" = "${version%.*}" ] || continue
  dir="$root/.venv/bpy/${version%.*}"
  env_py="$(matrix_venv "$cpython")/bin/python"
  numpy_version=$(PYTHONPATH="$dir" "$env_py" -c 'import numpy; print(numpy.__version__)')
  echo "--- tests/blender under bpy $version (CPython $cpython, numpy $numpy_version)"
  PYTHONPATH="$dir" "$env_py" -m pytest -q -p no:cacheprovider --durations=10 tests/blender "$@"
  ran=$((ran + 1))
done
[ "$ran" -gt 0 ] || { echo "test_blender: no version $only in scripts/blender_matrix.sh" >&2; exit 1; }
