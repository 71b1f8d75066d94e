#!/usr/bin/env bash
# Builds the installable ScrewBender extension with Blender's own extension tool: the
# bl_pkg/cli/blender_ext.py of the bpy wheels in .venv/bpy, which is what
# `blender --command extension build|validate` runs (plain Python 3.11+, no Blender binary),
# given Blender's list of valid tags as Blender gives it.
#
#   scripts/build_extension.sh               this machine's wheel (scripts/build_wheel.sh, or
#                                            SCREWBENDER_WHEEL: an already built one)
#                                            -> dist/screwbender-<version>-<platform>.zip
#   scripts/build_extension.sh --wheels DIR  every polyscrew-*.whl in DIR (the release job: one
#                                            per platform) -> one zip per platform, split by
#                                            Blender's `build --split-platforms`
#   --out DIR                                where the zips go (default dist/; its old
#                                            screwbender-*.zip are removed)
#
# scripts/extension.py writes the copy of addon/screwbender that Blender's tool packages (the
# version from Cargo.toml, `wheels` and `platforms` from the wheels). Every zip is then
# validated by the tool of each Blender in .venv/bpy and checked by `extension.py check`
# (the wheels it lists are the wheels it holds, which Blender's validate does not look at).
# Prints the zips' paths, this machine's platform's last.
# On a fresh clone (no .venv) it first runs scripts/bootstrap.sh --build: maturin, ziglang and
# Blender's extension tool alone, not the Blender wheels the tests need.
# Env: PYTHON (default .venv/bin/python), BLENDER_EXT (a blender_ext.py instead of .venv/bpy's),
#      SCREWBENDER_PIP_CACHE (bootstrap's pip download cache, default .venv/pip-cache)
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
python=${PYTHON:-$root/.venv/bin/python}
[ -x "$python" ] || python=$(command -v python3)
ext() { "$python" "$root/scripts/extension.py" "$@"; }

wheels="" out="$root/dist"
while [ $# -gt 0 ]; do
  case "$1" in
    --wheels) wheels=$(cd "$2" && pwd); shift 2 ;;
    --out) mkdir -p "$2"; out=$(cd "$2" && pwd); shift 2 ;;
    *) echo "usage: scripts/build_extension.sh [--wheels DIR] [--out DIR]" >&2; exit 2 ;;
  esac
done
# A fresh clone has no .venv: take what building needs first (maturin and zig for the wheel,
# Blender's extension tool for the zip), and only that: scripts/bootstrap.sh --build.
builds_wheel=false
[ -z "$wheels" ] && [ -z "${SCREWBENDER_WHEEL:-}" ] && builds_wheel=true
has_build_tools() {
  [ -x "$root/.venv/bin/maturin" ] || [ -n "${MATURIN:-}" ] || return 1
  [ "$(uname -s)-$(uname -m)" != Linux-x86_64 ] || "$root/.venv/bin/python" -c "import ziglang" 2>/dev/null
}
if { $builds_wheel && ! has_build_tools; } || ! ext tools >/dev/null 2>&1; then
  echo "build_extension: .venv lacks what building needs: running scripts/bootstrap.sh --build" >&2
  scripts/bootstrap.sh --build >&2
  python=$root/.venv/bin/python
fi
if [ -z "$wheels" ]; then
  wheels="$root/dist/wheels"
  mkdir -p "$wheels"
  if [ -n "${SCREWBENDER_WHEEL:-}" ]; then
    [ -f "$SCREWBENDER_WHEEL" ] || { echo "build_extension: no wheel $SCREWBENDER_WHEEL" >&2; exit 1; }
    wheel="$(cd "$(dirname "$SCREWBENDER_WHEEL")" && pwd)/$(basename "$SCREWBENDER_WHEEL")"
    if [ "$(dirname "$wheel")" != "$wheels" ]; then
      rm -f "$wheels"/polyscrew-*.whl
      cp "$wheel" "$wheels/"
    fi
  else
    scripts/build_wheel.sh "$wheels" >&2
  fi
fi

stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
platforms=$(ext stage --wheels "$wheels" --into "$stage/screwbender")
version=$(ext version)
tools=$(ext tools)
read -r build_tool build_tags <<<"$(head -n 1 <<<"$tools")"

rm -f "$out"/screwbender-*.zip
if [ "$(wc -l <<<"$platforms")" -gt 1 ]; then
  target=(--output-dir "$out" --split-platforms)
else
  target=(--output-filepath "$out/screwbender-$version-${platforms//-/_}.zip")
fi
echo "build_extension: Blender's tool ($build_tool) build for $(tr '\n' ' ' <<<"$platforms")" >&2
"$python" "$build_tool" build --source-dir "$stage/screwbender" --valid-tags "$build_tags" "${target[@]}" </dev/null >&2

zips=("$out"/screwbender-*.zip)
[ -f "${zips[0]}" ] || { echo "build_extension: Blender's tool wrote no zip to $out" >&2; exit 1; }
while read -r tool tags; do
  blender=$(sed -E 's#.*/([^/]+)/scripts/addons_core/bl_pkg/cli/blender_ext.py$#\1#' <<<"$tool")
  for zip in "${zips[@]}"; do
    echo -n "build_extension: Blender $blender validate $(basename "$zip"): " >&2
    "$python" "$tool" validate --valid-tags "$tags" "$zip" </dev/null >&2
  done
done <<<"$tools"
ext check "${zips[@]}" >&2

this="-$(ext platform | tr - _).zip"
ours=()
for zip in "${zips[@]}"; do
  if [[ "$zip" == *"$this" ]]; then ours+=("$zip"); else echo "$zip"; fi
done
for zip in "${ours[@]}"; do echo "$zip"; done
