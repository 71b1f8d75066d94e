#!/usr/bin/env bash
# Builds the polyscrew wheel for this machine (maturin, release, stable ABI: one wheel for
# CPython 3.11 and newer) into OUT_DIR (default dist/wheels) and prints its path, last.
#
# Linux x86_64: linked by zig (the `ziglang` package in .venv, tests/requirements.txt) against
# glibc 2.28 and tagged manylinux_2_28_x86_64, so it loads wherever Blender 4.2+ runs (Blender
# itself needs glibc 2.28); a plain build here would need this machine's glibc.
# macOS: MACOSX_DEPLOYMENT_TARGET defaults to 11.0 (Blender 4.2 needs macOS 11.2).
#
# Usage: scripts/build_wheel.sh [OUT_DIR]
# Env:   MATURIN (default .venv/bin/maturin, else from PATH)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
out=${1:-$root/dist/wheels}
venv_bin="$root/.venv/bin"
maturin=${MATURIN:-$venv_bin/maturin}
[ -x "$maturin" ] || maturin=$(command -v maturin)

args=(build --release --quiet -o "$out")
case "$(uname -s)-$(uname -m)" in
  Linux-x86_64)
    args+=(--zig --compatibility manylinux_2_28)
    export PATH="$venv_bin:$PATH" ;;  # maturin runs zig as `python3 -m ziglang`
  Darwin-*)
    export MACOSX_DEPLOYMENT_TARGET=${MACOSX_DEPLOYMENT_TARGET:-11.0} ;;
esac
mkdir -p "$out"
rm -f "$out"/polyscrew-*.whl
"$maturin" "${args[@]}" 2>&1 | { grep -v -e '^ *Compiling' -e '^ *Finished' >&2 || true; }
wheels=("$out"/polyscrew-*.whl)
[ -f "${wheels[0]}" ] || { echo "build_wheel: maturin wrote no wheel to $out" >&2; exit 1; }
echo "${wheels[0]}"
