#!/usr/bin/env bash
# The project's one test command: installs what it needs into .venv (scripts/bootstrap.sh),
# then runs the Rust tests, builds the polyscrew wheel (release, once) and the extension zip
# from it, runs the Python tests of the module, the packaging tests, and the Blender tests
# headless under every bpy version in .venv/bpy/.
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
export CARGO_TERM_COLOR=never PYTHONDONTWRITEBYTECODE=1
start=$(date +%s)
stage() { echo; echo "=== $* ($(( $(date +%s) - start )) s)"; }

stage "bootstrap"
scripts/bootstrap.sh
py="$root/.venv/bin/python"

stage "cargo test (workspace)"
cargo test --workspace --quiet

stage "build the polyscrew wheel (release; on Linux manylinux_2_28, zig-linked)"
rm -rf dist/wheel && mkdir -p dist/wheel
wheel=$(scripts/build_wheel.sh dist/wheel | tail -n 1)
"$py" -m pip --disable-pip-version-check install -q --force-reinstall --no-deps "$wheel"
export SCREWBENDER_WHEEL="$wheel"
if [ -x scripts/build_extension.sh ]; then
  stage "build the extension"
  scripts/build_extension.sh
fi

stage "pytest tests/python (numpy $("$py" -c 'import numpy; print(numpy.__version__)'))"
"$py" -m pytest -q -p no:cacheprovider tests/python

# Packaging: the wheel's tag and GLIBC, Blender's validate on the zips, the multi-platform
# assembly, the release workflow, `cargo publish --dry-run`, `twine check` (issue 20).
stage "pytest tests/packaging"
"$py" -m pytest -q -p no:cacheprovider tests/packaging

for dir in "$root"/.venv/bpy/*/; do
  version=$(basename "$dir")
  stage "pytest tests/blender under bpy $version"
  PYTHONPATH="$dir" "$py" -m pytest -q -p no:cacheprovider tests/blender
done
stage "all tests passed"
