#!/usr/bin/env bash
# The project's one test command: installs what it needs into .venv (scripts/bootstrap.sh),
# then runs the Rust tests, builds the polyscrew wheel (release, once), runs the Python tests
# of the module, and the Blender tests headless under every bpy version in .venv/bpy/.
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

stage "cargo doc (warnings are errors)"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --quiet -p polyscrew

stage "build the polyscrew wheel (release)"
rm -rf dist/wheel && mkdir -p dist/wheel
"$root/.venv/bin/maturin" build --release --quiet -o dist/wheel 2>&1 | grep -v '^ *Compiling' || true
wheel=$(ls dist/wheel/polyscrew-*.whl)
"$py" -m pip --disable-pip-version-check install -q --force-reinstall --no-deps "$wheel"
export SCREWBENDER_WHEEL="$wheel"
if [ -x scripts/build_extension.sh ]; then
  stage "build the extension"
  scripts/build_extension.sh
fi

stage "pytest tests/python (numpy $("$py" -c 'import numpy; print(numpy.__version__)'))"
"$py" -m pytest -q -p no:cacheprovider tests/python

stage "fuzz the module (Hypothesis, seeded; children under a 4 GB address-space cap)"
"$py" tests/python/fuzz.py

for dir in "$root"/.venv/bpy/*/; do
  version=$(basename "$dir")
  stage "pytest tests/blender under bpy $version"
  PYTHONPATH="$dir" "$py" -m pytest -q -p no:cacheprovider tests/blender
done
stage "all tests passed"
