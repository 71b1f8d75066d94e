#!/usr/bin/env bash
# The ScrewBender demo, one command on a fresh machine:
#   1. BLENDER_VERSIONS=5.0 scripts/bootstrap.sh --demo: .venv with maturin, ziglang, numpy,
#      matplotlib and the one bpy wheel the demo runs (Blender 5.0, about 350 MB), not the four
#      bpy wheels and the test-only packages scripts/test.sh needs;
#   2. scripts/build_extension.sh: the polyscrew wheel and the installable extension .zip;
#   3. every scripts/demo/NN_*.py in order, each a standalone script run with the Blender 5.0
#      bpy wheel and `--out-dir out`:
#        10_scene.py   the keyed demo scene           -> out/demo_source.blend
#        20_smooth.py  smoothed with every scheme     -> out/demo.blend
#        30_render.py  stroboscopic Workbench renders -> out/demo_*.png
#      Other features add their own NN_*.py parts; they run in the same way.
# Everything is written under out/ (git-ignored): the checkout stays clean.
#
#   scripts/demo.sh --update-docs   also copies the renders the README shows (every file of
#                                   docs/images/) from out/ over docs/images/, for a commit.
set -euo pipefail
update_docs=0
for arg in "$@"; do
  case "$arg" in
    --update-docs) update_docs=1 ;;
    -h|--help) sed -n '2,15p' "$0"; exit 0 ;;
    *) echo "demo: unknown option $arg (try --help)" >&2; exit 2 ;;
  esac
done
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
start=$(date +%s)
stage() { echo; echo "=== $* ($(( $(date +%s) - start )) s)"; }

demo_blender=5.0  # the Blender whose bpy wheel runs the demo (a row of scripts/blender_matrix.sh)
stage "bootstrap (bpy $demo_blender only)"
BLENDER_VERSIONS=$demo_blender scripts/bootstrap.sh --demo
py="$root/.venv/bin/python"
bpy_dir="$root/.venv/bpy/$demo_blender"
[ -d "$bpy_dir" ] || { echo "demo: $bpy_dir missing (scripts/bootstrap.sh installs it)" >&2; exit 1; }

stage "build the extension"
zip=$(PYTHON="$py" MATURIN="$root/.venv/bin/maturin" scripts/build_extension.sh | tail -n 1)
export SCREWBENDER_EXTENSION_ZIP="$zip"
echo "$zip"

mkdir -p out
for part in scripts/demo/[0-9][0-9]_*.py; do
  stage "$part"
  # (headless Workbench renders print harmless "EGL Error" lines: filtered out)
  if ! PYTHONPATH="$bpy_dir" "$py" "$part" --out-dir "$root/out" 2>&1 | { grep -v '^EGL Error' || true; }; then
    echo "demo: $part failed" >&2; exit 1
  fi
done
if [ "$update_docs" = 1 ]; then
  stage "update docs/images from out/"
  for image in docs/images/*.png; do
    name=$(basename "$image")
    [ -f "out/$name" ] || { echo "demo: out/$name was not rendered; docs/images left as they were" >&2; exit 1; }
  done
  for image in docs/images/*.png; do cp "out/$(basename "$image")" "$image"; echo "updated $image"; done
fi
stage "demo done"
ls -1 out/*.blend out/*.png
