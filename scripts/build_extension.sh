#!/usr/bin/env bash
# Builds the polyscrew wheel (maturin, release) and the installable ScrewBender extension
# .zip: dist/screwbender-<version>.zip, with the wheel bundled under wheels/ and listed in
# the zip's blender_manifest.toml. The wheel is also copied to addon/screwbender/wheels/
# (git-ignored) so the source folder works as a development extension.
#
# Usage: scripts/build_extension.sh            (prints the .zip path last)
# Env:   PYTHON, MATURIN (default: .venv/bin/python, .venv/bin/maturin, else from PATH);
#        SCREWBENDER_WHEEL: an already built polyscrew wheel to bundle (skips the maturin build)
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$ROOT"

pick() { # first executable of: $1 (env override), $2 (venv path), $3 (name on PATH)
    if [[ -n "$1" ]]; then echo "$1"; elif [[ -x "$2" ]]; then echo "$2"; else command -v "$3"; fi
}
PYTHON="$(pick "${PYTHON:-}" "$ROOT/.venv/bin/python" python3)"
MATURIN="$(pick "${MATURIN:-}" "$ROOT/.venv/bin/maturin" maturin)"

WHEEL_DIR="$ROOT/dist/wheels"
mkdir -p "$WHEEL_DIR"
if [[ -n "${SCREWBENDER_WHEEL:-}" ]]; then
    wheel="$(cd "$(dirname "$SCREWBENDER_WHEEL")" && pwd)/$(basename "$SCREWBENDER_WHEEL")"
    [[ -f "$wheel" ]] || { echo "build_extension: no wheel $SCREWBENDER_WHEEL" >&2; exit 1; }
    for old in "$WHEEL_DIR"/polyscrew-*.whl; do
        [[ -e "$old" && "$old" != "$wheel" ]] && rm -f "$old"
    done
    [[ "$(dirname "$wheel")" == "$WHEEL_DIR" ]] || cp "$wheel" "$WHEEL_DIR/"
else
    rm -f "$WHEEL_DIR"/polyscrew-*.whl
    "$MATURIN" build --release --quiet -o "$WHEEL_DIR" >&2
fi
"$PYTHON" "$ROOT/scripts/package_extension.py" --wheels "$WHEEL_DIR" --out "$ROOT/dist"
