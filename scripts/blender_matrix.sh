# Sourced by scripts/bootstrap.sh and scripts/test.sh: the Blender versions the add-on is tested
# against, and where the CPython each one needs is found and its venv lives.
#
# One row per Blender release line: the newest bpy patch release on PyPI, the CPython it is
# built for, and the numpy that Blender itself bundles (what the bpy wheel is tested with).
BLENDER_MATRIX=(
  "4.2.23 3.11 numpy>=1.26,<2"
  "4.5.15 3.11 numpy>=1.26,<2"
  "5.0.1 3.11 numpy>=1.26,<2"
  "5.2.3 3.13 numpy>=2.5,<2.6"
)

# BLENDER_VERSIONS (e.g. "4.2 5.0", or full versions): only these rows, for a machine that
# cannot run the others (the release workflow's Intel Mac has no bpy 5.x). Unset: all.
if [ -n "${BLENDER_VERSIONS:-}" ]; then
  _selected=()
  for _row in "${BLENDER_MATRIX[@]}"; do
    read -r _version _ _ <<<"$_row"
    for _want in $BLENDER_VERSIONS; do
      if [ "$_version" = "$_want" ] || [ "${_version%.*}" = "$_want" ]; then _selected+=("$_row"); fi
    done
  done
  if [ ${#_selected[@]} -eq 0 ]; then
    echo "BLENDER_VERSIONS=$BLENDER_VERSIONS names no version of scripts/blender_matrix.sh" >&2
    exit 1
  fi
  BLENDER_MATRIX=("${_selected[@]}")
fi

# The venv whose interpreter runs the tests of CPython $1: .venv for 3.11 (the project's own,
# with the build and test requirements), .venv/py<XY> for any other (pytest, numpy, scipy).
matrix_venv() {
  if [ "$1" = 3.11 ]; then echo "$root/.venv"; else echo "$root/.venv/py${1//./}"; fi
}

# Prints the path of a working CPython $1 (e.g. 3.13), or nothing. Looks at, in order: the
# environment variable PYTHON<XY> (e.g. PYTHON313; PYTHON also for 3.11), python<X.Y> and
# python3 on PATH, and pyenv's versions (newest patch first). Each candidate must run and
# report exactly that minor version (a pyenv shim for an inactive version does not run).
find_cpython() {
  local want=$1 var="PYTHON${1//./}" candidate pyenv_root=""
  local -a candidates=()
  [ -n "${!var:-}" ] && candidates+=("${!var}")
  [ "$want" = 3.11 ] && [ -n "${PYTHON:-}" ] && candidates+=("$PYTHON")
  candidates+=("python$want" python3)
  if command -v pyenv >/dev/null 2>&1; then pyenv_root=$(pyenv root 2>/dev/null || true); fi
  [ -n "$pyenv_root" ] || pyenv_root="${PYENV_ROOT:-$HOME/.pyenv}"
  while IFS= read -r candidate; do candidates+=("$candidate"); done < <(
    ls -d "$pyenv_root/versions/$want".*/bin/python"$want" 2>/dev/null | sort -rV)
  for candidate in "${candidates[@]}"; do
    if command -v "$candidate" >/dev/null 2>&1 &&
      "$candidate" -c "import sys, venv; sys.exit(sys.version_info[:2] != tuple(map(int, '$want'.split('.'))))" \
        >/dev/null 2>&1; then
      command -v "$candidate"; return 0
    fi
  done
  return 1
}

# What to tell the user when CPython $1 is missing.
missing_cpython() {
  echo "CPython $1 is needed (the bpy wheel of $2 is built for it) and none was found: install it" \
    "(e.g. \`pyenv install $1\`, or the python$1 and python$1-venv packages) or point" \
    "PYTHON${1//./}= at one"
}
