#!/usr/bin/env bash
# The project's one test command: installs what it needs into .venv (scripts/bootstrap.sh),
# then the lint gates (cargo fmt --check, clippy -D warnings, ruff check: a failure stops the
# run with one line saying which gate and how to fix it), runs the Rust tests, builds the
# polyscrew wheel (release, once: abi3 for CPython 3.11 and later, manylinux_2_28 on Linux)
# and the extension zip from it, runs the Python tests of the module, the packaging tests,
# and the Blender tests headless under every Blender version of scripts/blender_matrix.sh
# (4.2, 4.5, 5.0 on CPython 3.11; 5.2 on 3.13).
# A version whose CPython or bpy is missing fails the run (it is never skipped).
set -euo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
export CARGO_TERM_COLOR=never PYTHONDONTWRITEBYTECODE=1
source scripts/blender_matrix.sh
start=$(date +%s)
stage_name="" stage_start=$start timings=()
stage() { # closes the previous stage (its duration goes to the summary) and opens the next
  local now; now=$(date +%s)
  [ -z "$stage_name" ] || timings+=("$(printf '%5d s  %s' $((now - stage_start)) "$stage_name")")
  stage_name="$*" stage_start=$now
  echo; echo "=== $* ($((now - start)) s)"
}

stage "bootstrap"
scripts/bootstrap.sh
py="$root/.venv/bin/python"
scripts/test_blender.sh --check  # fails now, not after 10 minutes, when a version cannot run
"$py" scripts/generate_stub.py --check  # the committed .pyi is what the binding's Rust doc comments generate

# Lint gates: each failure fails the run with one line naming the gate and the fix.
gate() { # gate NAME FIX COMMAND...: runs COMMAND; on failure prints what failed and how to fix it
  local name=$1 fix=$2; shift 2
  "$@" || { echo "test.sh: gate '$name' failed: $fix" >&2; exit 1; }
}
stage "lint gates (cargo fmt, clippy -D warnings, ruff)"
gate "cargo fmt" "run \`cargo fmt --all\` and commit the result" cargo fmt --all --check
gate "clippy" "fix the warnings above (or allow one with a comment saying why)" \
  cargo clippy --workspace --all-targets --quiet -- -D warnings
gate "ruff" "fix the findings above (\`.venv/bin/ruff check --fix\` sorts imports; rules: pyproject.toml [tool.ruff])" \
  "$root/.venv/bin/ruff" check --quiet addon tests scripts python

stage "cargo test (workspace; the closed sweep's tests run in release, next)"
cargo test --workspace --quiet -- --skip sweep::closed

# The closed sweep's tests check against slow references (minutes in a debug build), and its
# face-point acceptance tests are ignored in a debug build. They are built here and run in
# release beside the Python tests (below), which leave a core idle much of the time.
stage "cargo test (release): build the closed sweep's tests"
release_tests=$(cargo test --release -p polyscrew --lib --no-run --quiet --message-format=json-render-diagnostics |
  "$py" -c 'import json, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m["profile"]["test"] and m.get("executable"):
        print(m["executable"])')
[ -x "$release_tests" ] || { echo "test.sh: the release test binary was not built" >&2; exit 1; }

stage "cargo doc (warnings are errors)"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --quiet -p polyscrew

stage "build the polyscrew wheel (release; on Linux manylinux_2_28, zig-linked)"
rm -rf dist/wheel && mkdir -p dist/wheel
wheel=$(scripts/build_wheel.sh dist/wheel | tail -n 1)
# The one abi3 wheel, into every venv that runs tests (.venv and .venv/py313).
for env_dir in $(for row in "${BLENDER_MATRIX[@]}"; do read -r _ cpython _ <<<"$row"; matrix_venv "$cpython"; done | sort -u); do
  "$env_dir/bin/python" -m pip --disable-pip-version-check install -q --force-reinstall --no-deps "$wheel"
done
export SCREWBENDER_WHEEL="$wheel"
if [ -x scripts/build_extension.sh ]; then
  stage "build the extension"
  scripts/build_extension.sh
fi

# The closed sweep's release tests run in the background, into a log printed when they end:
# together the two stages take about 0.7 of their times one after the other.
release_log=$(mktemp)
release_began=$(date +%s)
(cd rust/polyscrew && "$release_tests" --include-ignored sweep::closed) > "$release_log" 2>&1 &
release_pid=$!
trap 'kill "$release_pid" 2>/dev/null || true' EXIT  # not left running if this run stops
stage "pytest tests/python (numpy $("$py" -c 'import numpy; print(numpy.__version__)')), the closed sweep's release tests beside it"
python_failed=0
"$py" -m pytest -q -p no:cacheprovider --durations=15 tests/python || python_failed=1
release_failed=0
wait "$release_pid" || release_failed=1
trap - EXIT
release_took=$(($(date +%s) - release_began))
timings+=("$(printf '%5d s  %s' "$release_took" "cargo test (release): the closed sweep, beside the Python tests")")
echo "--- cargo test (release): the closed sweep, with its face points ($release_took s)"
cat "$release_log"
rm -f "$release_log"
[ "$release_failed" = 0 ] || { echo "test.sh: the closed sweep's release tests failed (above)" >&2; exit 1; }
[ "$python_failed" = 0 ] || { echo "test.sh: tests/python failed (above)" >&2; exit 1; }

stage "fuzz the module (Hypothesis, seeded; children under a 4 GB address-space cap)"
"$py" tests/python/fuzz.py

# Packaging: the wheel's tag and GLIBC, Blender's validate on the zips, the multi-platform
# assembly, the release workflow, `cargo publish --dry-run`, `twine check` (issue 20).
stage "pytest tests/packaging"
"$py" -m pytest -q -p no:cacheprovider tests/packaging

# The Blender versions run two at a time (a run leaves a core idle much of the time; these
# machines have two), each into its own log; the logs are printed whole, in order, when all
# have run, and the run fails if any version fails.
versions=()
for row in "${BLENDER_MATRIX[@]}"; do read -r version _ <<<"$row"; versions+=("$version"); done
stage "pytest tests/blender under bpy ${versions[*]} (two at a time)"
logs=$(mktemp -d)
lane() { # runs every other version from index $1, each into its log, with its time and result
  local i version began
  for ((i = $1; i < ${#versions[@]}; i += 2)); do
    version=${versions[$i]} began=$(date +%s)
    if scripts/test_blender.sh "$version" > "$logs/$version.log" 2>&1; then
      echo "$version passed in $(($(date +%s) - began)) s" > "$logs/$version.status"
    else
      echo "$version FAILED in $(($(date +%s) - began)) s" > "$logs/$version.status"
    fi
  done
}
lane 0 & first=$!
lane 1 & second=$!
wait "$first" "$second"
for version in "${versions[@]}"; do cat "$logs/$version.log" 2>/dev/null || true; done
blender_failed=0 per_version=()
for version in "${versions[@]}"; do
  per_version+=("bpy $(cat "$logs/$version.status" 2>/dev/null || echo "$version did not run")")
  grep -q passed "$logs/$version.status" 2>/dev/null || blender_failed=1
done
rm -rf "$logs"
[ "$blender_failed" = 1 ] && stage "the Blender tests failed" || stage "all tests passed"
echo "time per stage:"
printf '  %s\n' "${timings[@]}"
printf '    %s\n' "${per_version[@]}"
exit "$blender_failed"
