#!/usr/bin/env bash
# Runs every benchmark of issue 7 and writes BENCHMARKS.md (machine, versions, medians,
# ratios). One command: scripts/bench.sh. Each comparison runs side by side in one process:
#   - criterion (every rust/polyscrew/benches/*.rs): s(a, t, b) ours vs nalgebra, subdivision
#     per scheme, growth over 10 .. 10,000 keys x 1 .. 8 levels (core.rs, scaling.rs: thread
#     CPU time), and the other issues' benches (angular velocity, ...);
#   - callgrind instruction counts of s (ours one by one and through s_many, vs nalgebra) and
#     of one subdivision;
#   - scripts/bench/bench_python.py: batch vs per-call loops (pytransform3d; mathutils in bpy);
#   - scripts/bench/bench_bake.py (the add-on's bake vs nla.bake vs a keyframe_insert loop);
#   - scripts/bench/bench_reduce.py (Reduce Keys vs graph.decimate, five clips, three tolerances);
#   - scripts/bench/bench_sweep_peers.py (polyscrew.sweep vs stroboscopic instancing, gpytoolbox and
#     NVIDIA Warp, against a dense-stamp reference) and scripts/bench/bench_sweep_cases.py (issue
#     29's three cases: polyscrew.sweep_closed vs gpytoolbox and sweep3d against a fine reference),
#     with scripts/bench/requirements.txt (bench-only: gpytoolbox, warp-lang, sweep3d,
#     scikit-image; never needed by the tests or CI) installed into .venv;
#   - scripts/bench/bench_floor.py (every writing operator against its floor, the Blender calls it
#     cannot avoid, and against nla.bake / graph.gaussian_smooth / graph.decimate; its growth
#     against owners and frames: issue 27; 31 minutes at load 15-20, about 10 estimated quiet);
#   - scripts/bench/bench_denoise.py, scripts/bench/bench_denoise_rig.py (Remove Noise vs Blender's filters);
#   - the measurements the docs quote (part "measure"): what Smooth Motion keeps of the
#     animator's intent (measure_intent.py), how far each scheme strays from the keys
#     (measure_schemes.py), where a bake's time goes (profile_bake.py), each writing operator
#     against its floor, profiled (profile_floor.py, docs/performance.md), Revert, Smooth Motion
#     and Insert Key against owners beside Blender-only floors (growth_floor.py), the live preview's
#     recompute (bench_preview.py), Build Swept Region on a 100,000-triangle mesh
#     (bench_sweep_blender.py), the closed swept boundary against the open sweep
#     (bench_sweep_closed.py), key fractions of reduce_keys (measure_reduce.py), memory
#     estimates beside measured peaks (memory_footprints.py), and the paper's smoothness
#     figures (plot_smoothness.py, into docs/): each one's printout in BENCHMARKS.md.
# Every script bench.sh runs is in scripts/bench/; bench_report.py is the one writer of
# BENCHMARKS.md (the others write JSON or text into the run folder).
# A part that is missing or fails is reported in BENCHMARKS.md as "not available: <why>"
# and the others still run. Intermediate results go to target/bench/ (log: target/bench/log.txt;
# a refresh's: log-<parts>.txt).
# Env: BENCH_QUICK=1 for a smoke run (short criterion times, small Python runs; the
#      BENCHMARKS.md it writes says so); BPY=.venv/bpy/5.0 selects the Blender module.
#      BENCH_ONLY=<part>[,<part>] runs only those parts and rewrites only their sections of
#      BENCHMARKS.md, keeping the others as they are (each refreshed section says so). Parts:
#      criterion, callgrind, python, bake, reduce, floor, denoise, sweep, measure. E.g.
#      BENCH_ONLY=floor scripts/bench.sh (the floor part; the reduce part alone takes ~22 minutes).
#      A refresh uses .venv as it is (no bootstrap when .venv/bin/python exists) and keeps the
#      other parts' results in target/bench; a section that shows a refreshed part and another
#      part whose results are not there is kept as it was (bench_report.py says which).
#      BENCH_AGAINST=<checkout>[:<checkout>...] also times Smooth Motion (part bake) against other
#      checkouts of this repository, interleaved (scripts/bench/bench_bake_against.py; log only).
set -uo pipefail
root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
cd "$root"
export CARGO_TERM_COLOR=never PYTHONDONTWRITEBYTECODE=1
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-$root/target}
run="$CARGO_TARGET_DIR/bench"
only=${BENCH_ONLY:-}
parts="criterion callgrind python bake reduce floor denoise sweep measure"
for p in ${only//,/ }; do
  case " $parts " in *" $p "*) ;; *) echo "bench: unknown part '$p' in BENCH_ONLY (the parts: $parts)"; exit 2 ;; esac
done
want() { [ -z "$only" ] || case ",$only," in *",$1,"*) true ;; *) false ;; esac; }
if [ -z "$only" ]; then
  rm -rf "$run" "$CARGO_TARGET_DIR/criterion" "$CARGO_TARGET_DIR/criterion-reuse"
else  # a refresh: only the named parts' results are removed, the others kept for the report
  mkdir -p "$run"
  want criterion && rm -rf "$CARGO_TARGET_DIR/criterion" "$CARGO_TARGET_DIR/criterion-reuse"
  want callgrind && rm -f "$run"/callgrind-* "$run"/branches-* "$run"/time-10000x8.txt
  want python && rm -f "$run/python.json" "$run/blender.json"
  want bake && rm -f "$run"/bake.*
  want reduce && rm -f "$run"/reduce.*
  want floor && rm -f "$run"/floor.*
  want denoise && rm -f "$run"/denoise.* "$run"/denoise_rig.json
  want sweep && rm -f "$run"/sweep.*
  want measure && rm -f "$run"/measure-*
  rm -rf "$run/wheel" "$run/pylib" "$run/extension.txt"
fi
mkdir -p "$run"
exec > >(tee "$run/log${only:+-${only//,/-}}.txt") 2>&1
start=$(date +%s)
stage() { echo; echo "=== $* ($(( $(date +%s) - start )) s)"; }
load_start=$(cut -d' ' -f1-3 /proc/loadavg)
date_start=$(date -u '+%Y-%m-%d %H:%M')
quick=${BENCH_QUICK:-0}

if [ -z "$only" ] || [ ! -x "$root/.venv/bin/python" ]; then
  stage "bootstrap"
  scripts/bootstrap.sh || { echo "bench: bootstrap failed"; exit 1; }
fi
py="$root/.venv/bin/python"
bpy_dir=${BPY:-$root/.venv/bpy/5.0}
peers_ok=1
if want sweep; then
  "$py" -m pip --disable-pip-version-check install -q -r scripts/bench/requirements.txt \
    || { peers_ok=0; echo "bench: scripts/bench/requirements.txt did not install; the sweep comparison will be missing"; }
fi

pylib="$run/pylib"
wheel=""
needs_wheel=0  # every part but criterion and callgrind runs the Python module
for p in python bake reduce floor denoise sweep measure; do want "$p" && needs_wheel=1; done
if [ "$needs_wheel" = 1 ]; then
  stage "build the polyscrew wheel (release, once)"
  if "$root/.venv/bin/maturin" build --release --quiet -o "$run/wheel" 2>&1 | grep -v '^ *Compiling'; then :; fi
  wheel=$(ls "$run"/wheel/polyscrew-*.whl 2>/dev/null | head -1)
  if [ -n "$wheel" ]; then
    "$py" -m pip --disable-pip-version-check install -q --no-deps --target "$pylib" "$wheel"
  else
    echo "bench: the wheel did not build; the Python parts will be missing"
  fi
fi

if want criterion; then
# Every criterion bench of the core crate (core.rs, scaling.rs, and those the other issues add).
benches=()
for f in rust/polyscrew/benches/*.rs; do benches+=(--bench "$(basename "$f" .rs)"); done
stage "criterion: ${benches[*]}"
crit_args=()
[ "$quick" = 1 ] && crit_args=(--warm-up-time 0.1 --measurement-time 0.3 --sample-size 10)
cargo bench -p polyscrew "${benches[@]}" -- "${crit_args[@]}" 2>&1 \
  | grep --line-buffered -v -e '^ *Compiling' -e '^Gnuplot' -e 'Plotting' -e '^Benchmarking' || true

# The same scaling rows for 1,000 and 10,000 keys with freed memory kept for reuse: glibc
# otherwise maps every block above 32 MB afresh on each call, and the kernel's page faults
# on those fresh pages (not the subdivision) bend the growth of the largest outputs.
stage "criterion: scaling with memory reused (glibc tunables)"
CRITERION_HOME="$CARGO_TARGET_DIR/criterion-reuse" \
  GLIBC_TUNABLES=glibc.malloc.mmap_max=0:glibc.malloc.trim_threshold=4294967295 \
  cargo bench -p polyscrew --bench scaling -- "${crit_args[@]}" 'scaling/.*/10{3,4}x' 2>&1 \
  | grep --line-buffered -v -e '^ *Compiling' -e '^Gnuplot' -e 'Plotting' -e '^Benchmarking' || true
fi

if want callgrind; then
stage "callgrind instruction counts"
if command -v valgrind >/dev/null; then
  cargo build --profile bench -p polyscrew --example count_s --example count_subdivide 2>&1 | grep -v '^ *Compiling' || true
  n=100000; [ "$quick" = 1 ] && n=10000
  echo "$n" > "$run/callgrind-n.txt"
  cg() { valgrind --tool=callgrind --callgrind-out-file="$1" "${@:2}" 2>&1 | grep -E 'Collected|evaluations|runs of' ; }
  for which in ours many nalgebra; do
    cg "$run/callgrind-$which-0.out" "$CARGO_TARGET_DIR/release/examples/count_s" "$which" 0
    cg "$run/callgrind-$which-N.out" "$CARGO_TARGET_DIR/release/examples/count_s" "$which" "$n"
  done
  cg "$run/callgrind-subdivide-0.out" "$CARGO_TARGET_DIR/release/examples/count_subdivide" 0
  cg "$run/callgrind-subdivide-1.out" "$CARGO_TARGET_DIR/release/examples/count_subdivide" 1
  # What limits the targets: instructions per output pose across sizes (algorithmic
  # linearity), simulated branch mispredictions of s (ours vs nalgebra).
  for kl in "100 6" "10000 6"; do
    set -- $kl
    cg "$run/callgrind-subdivide-$1x$2-0.out" "$CARGO_TARGET_DIR/release/examples/count_subdivide" 0 "$1" "$2"
    cg "$run/callgrind-subdivide-$1x$2-1.out" "$CARGO_TARGET_DIR/release/examples/count_subdivide" 1 "$1" "$2"
  done
  for which in ours nalgebra; do
    valgrind --tool=callgrind --branch-sim=yes --callgrind-out-file="$run/branches-$which-0.out" \
      "$CARGO_TARGET_DIR/release/examples/count_s" "$which" 0 >/dev/null 2>&1
    valgrind --tool=callgrind --branch-sim=yes --callgrind-out-file="$run/branches-$which-N.out" \
      "$CARGO_TARGET_DIR/release/examples/count_s" "$which" "$n" >/dev/null 2>&1
  done
else
  echo "not available: valgrind is not installed (apt-get install valgrind)"
fi
if [ -x /usr/bin/time ] && [ -x "$CARGO_TARGET_DIR/release/examples/count_subdivide" ]; then
  # User and system (page-fault) time of the largest subdivision, 10,000 keys x 8 levels.
  /usr/bin/time -o "$run/time-10000x8.txt" -f "%U %S %R %M" \
    "$CARGO_TARGET_DIR/release/examples/count_subdivide" 1 10000 8 && cat "$run/time-10000x8.txt"
fi
fi

if want python; then
pyargs=(); [ "$quick" = 1 ] && pyargs=(--n 2000 --repeat 3)
stage "Python: batch vs loops (pytransform3d)"
PYTHONPATH="$pylib" "$py" scripts/bench/bench_python.py --out "$run/python.json" "${pyargs[@]}" \
  || echo "bench: bench_python.py failed"
stage "Python inside Blender: batch vs mathutils.Matrix.lerp"
if [ -d "$bpy_dir" ]; then
  PYTHONPATH="$pylib:$bpy_dir" "$py" scripts/bench/bench_python.py --blender --out "$run/blender.json" "${pyargs[@]}" \
    || echo "bench: bench_python.py --blender failed"
else
  echo "not available: no Blender module at $bpy_dir"
fi
fi

if want bake; then
stage "bake: ScrewBender vs nla.bake vs a keyframe_insert loop"
if [ ! -f scripts/bench/bench_bake.py ]; then
  echo "scripts/bench/bench_bake.py is not in this checkout (the add-on branch's bake benchmark has not landed)" | tee "$run/bake.missing"
elif [ -z "$wheel" ] || [ ! -d "$bpy_dir" ]; then
  echo "the wheel or the Blender module is missing" | tee "$run/bake.missing"
elif ! SCREWBENDER_WHEEL="$wheel" scripts/build_extension.sh > "$run/extension.txt" 2>&1; then
  echo "scripts/build_extension.sh failed (see target/bench/extension.txt)" | tee "$run/bake.missing"
else
  bake_args=(--out "$run/bake.json"); [ "$quick" = 1 ] && bake_args+=(--quick)
  if PYTHONPATH="$bpy_dir" "$py" scripts/bench/bench_bake.py "${bake_args[@]}" > "$run/bake.out" 2>&1; then
    grep -v -e '^Warning' -e '^Read blend' "$run/bake.out" > "$run/bake.txt"; cat "$run/bake.txt"
  else
    tail -5 "$run/bake.out"
    echo "scripts/bench/bench_bake.py failed: $(tail -1 "$run/bake.out")" | tee "$run/bake.missing"
  fi
  # BENCH_AGAINST=<checkout>[:<checkout>...]: Smooth Motion's CPU time against those checkouts
  # (each with its extension built in its dist/), interleaved processes; printed to the log only.
  if [ -n "${BENCH_AGAINST:-}" ]; then
    IFS=: read -r -a against <<<"$BENCH_AGAINST"
    PYTHONPATH="$bpy_dir" "$py" scripts/bench/bench_bake_against.py "${against[@]}" "$root" \
      || echo "bench: scripts/bench/bench_bake_against.py failed"
  fi
fi
fi

if want sweep; then
stage "sweep: ours vs stroboscopic instancing, gpytoolbox, Warp"
if ! PYTHONPATH="$pylib" "$py" -c 'import polyscrew, sys; sys.exit(0 if hasattr(polyscrew, "sweep") else 1)' 2>/dev/null; then
  echo "polyscrew.sweep is not in this build" | tee "$run/sweep.missing"
elif [ "$peers_ok" != 1 ]; then
  echo "scripts/bench/requirements.txt (gpytoolbox, warp-lang) did not install" | tee "$run/sweep.missing"
else
  sweep_args=(--out "$run/sweep.json"); [ "$quick" = 1 ] && sweep_args+=(--quick)
  # (Warp's start-up banner filtered out: no CUDA here, the CPU device is used.)
  PYTHONPATH="$pylib" "$py" scripts/bench/bench_sweep_peers.py "${sweep_args[@]}" 2>&1 \
    | grep --line-buffered -v -i -e 'cuda' -e '^Warp ' -e '^ *Devices:' -e '"cpu"' -e 'Kernel cache' -e '\.cache/warp' -e '^Module warp' || true
  [ -f "$run/sweep.json" ] || echo "scripts/bench/bench_sweep_peers.py failed (see target/bench/log.txt)" | tee "$run/sweep.missing"
fi
# Issue 29's three cases: the closed boundary against gpytoolbox and sweep3d, each result against
# a reference surface; and sweep_closed on 100,000 triangles over 64 screws.
stage "sweep: issue 29's three cases, sweep_closed vs gpytoolbox and sweep3d against a fine reference"
if ! PYTHONPATH="$pylib" "$py" -c 'import polyscrew, sys; sys.exit(0 if hasattr(polyscrew, "sweep_closed") else 1)' 2>/dev/null; then
  echo "polyscrew.sweep_closed is not in this build" | tee "$run/sweep.cases.missing"
else
  cases_args=(--out "$run/sweep.cases.json" --big); [ "$quick" = 1 ] && cases_args+=(--quick)
  # (60 minutes: the torus's exact reference alone took 22 minutes of CPU at stop 39, before its pruning)
  PYTHONPATH="$pylib" timeout 3600 "$py" scripts/bench/bench_sweep_cases.py "${cases_args[@]}" 2>&1 | grep --line-buffered -v '\[sweep\] \[info\]' || true
  [ -f "$run/sweep.cases.json" ] || echo "scripts/bench/bench_sweep_cases.py failed (see target/bench/log.txt)" | tee "$run/sweep.cases.missing"
fi
fi

if want reduce; then
stage "reduce: Reduce Keys vs graph.decimate (five clips, three tolerances)"
if [ -z "$wheel" ] || [ ! -d "$bpy_dir" ]; then
  echo "the wheel or the Blender module is missing" | tee "$run/reduce.missing"
elif ! PYTHONPATH="$pylib" "$py" -c 'import polyscrew, sys; sys.exit(0 if hasattr(polyscrew, "reduce_keys") else 1)' 2>/dev/null; then
  echo "polyscrew.reduce_keys is not in this build" | tee "$run/reduce.missing"
else
  [ -f "$run/extension.txt" ] || SCREWBENDER_WHEEL="$wheel" scripts/build_extension.sh > "$run/extension.txt" 2>&1
  reduce_args=(--json "$run/reduce.json"); [ "$quick" = 1 ] && reduce_args+=(--quick)
  PYTHONPATH="$bpy_dir" "$py" scripts/bench/bench_reduce.py "${reduce_args[@]}" 2>&1 | grep --line-buffered -v -e '^Warning' -e '^Read blend' -e '^Info: ' \
    || true
  [ -f "$run/reduce.json" ] || echo "scripts/bench/bench_reduce.py failed (see target/bench/log.txt)" | tee "$run/reduce.missing"
fi
fi

if want floor; then
stage "floor: every writing operator against the Blender calls it cannot avoid, and its growth"
if [ -z "$wheel" ] || [ ! -d "$bpy_dir" ]; then
  echo "the wheel or the Blender module is missing" | tee "$run/floor.missing"
elif ! { [ -f "$run/extension.txt" ] || SCREWBENDER_WHEEL="$wheel" scripts/build_extension.sh > "$run/extension.txt" 2>&1; }; then
  echo "scripts/build_extension.sh failed (see target/bench/extension.txt)" | tee "$run/floor.missing"
else
  floor_args=(--out "$run/floor.json"); [ "$quick" = 1 ] && floor_args+=(--quick)
  PYTHONPATH="$bpy_dir" "$py" scripts/bench/bench_floor.py "${floor_args[@]}" 2>&1 \
    | grep --line-buffered -v -e '^Warning' -e '^Read blend' -e '^Info: ' -e '^ScrewBender: ' || true
  [ -f "$run/floor.json" ] || echo "scripts/bench/bench_floor.py failed (see target/bench/log.txt)" | tee "$run/floor.missing"
fi
fi

# Remove Noise against Blender's own filters: its section (denoise.md in the run folder, put
# into BENCHMARKS.md by bench_report.py) and docs/denoise_error.png; then the operator on a
# 100-bone rig against graph.gaussian_smooth (printed, and kept in the run folder).
if want denoise; then
stage "denoise: ours vs Blender's Smooth Keys, Gaussian, Butterworth (five clips, two noise levels)"
[ -z "$wheel" ] || [ -f "$run/extension.txt" ] || SCREWBENDER_WHEEL="$wheel" scripts/build_extension.sh > "$run/extension.txt" 2>&1
PYTHONPATH="$bpy_dir" "$py" scripts/bench/bench_denoise.py --json "$run/denoise.json" --section "$run/denoise.md" \
  || echo "scripts/bench/bench_denoise.py failed"
stage "denoise: Remove Noise on a 100-bone rig x 1,000 frames vs graph.gaussian_smooth"
PYTHONPATH="$bpy_dir" "$py" scripts/bench/bench_denoise_rig.py --json "$run/denoise_rig.json" || echo "scripts/bench/bench_denoise_rig.py failed"
fi

# The measurements the docs quote: each script's printout (target/bench/measure-<name>.txt),
# put into BENCHMARKS.md by bench_report.py; a script that fails leaves measure-<name>.missing.
if want measure; then
stage "measure: the figures the docs quote"
if [ -z "$wheel" ] || [ ! -d "$bpy_dir" ]; then
  echo "the wheel or the Blender module is missing" | tee "$run/measure.missing"
else
  [ -f "$run/extension.txt" ] || SCREWBENDER_WHEEL="$wheel" scripts/build_extension.sh > "$run/extension.txt" 2>&1
  profile_args=(); preview_args=(); floor_profile_args=()
  [ "$quick" = 1 ] && profile_args=(--objects 30 --runs 2) && preview_args=(--quick) && floor_profile_args=(--quick)
  measure() {  # name, PYTHONPATH, arguments...
    local name=$1 path=$2; shift 2
    echo "--- $name"
    if PYTHONPATH="$path" "$py" "scripts/bench/$name.py" "$@" > "$run/measure-$name.out" 2>&1; then
      grep -v -e '^Warning' -e '^Read blend' -e '^Info: ' -e '^ScrewBender: ' "$run/measure-$name.out" > "$run/measure-$name.txt"
      cat "$run/measure-$name.txt"
    else
      tail -5 "$run/measure-$name.out"
      echo "scripts/bench/$name.py failed: $(tail -1 "$run/measure-$name.out")" | tee "$run/measure-$name.missing"
    fi
  }
  measure measure_intent "$pylib:$bpy_dir"
  measure measure_schemes "$pylib:$bpy_dir"
  measure profile_bake "$pylib:$bpy_dir" "${profile_args[@]}"
  measure profile_floor "$pylib:$bpy_dir" "${floor_profile_args[@]}"
  measure growth_floor "$pylib:$bpy_dir" "${floor_profile_args[@]}"
  measure bench_preview "$pylib:$bpy_dir" "${preview_args[@]}"
  measure bench_sweep_blender "$pylib:$bpy_dir"
  measure bench_sweep_closed "$pylib"
  measure measure_reduce "$pylib"
  measure memory_footprints "$pylib"
  measure plot_smoothness "$pylib" --bpy "$bpy_dir" --out-dir docs
fi
fi

stage "write BENCHMARKS.md"
RUN="$run" LOAD_START="$load_start" DATE_START="$date_start" BPY_DIR="$bpy_dir" QUICK="$quick" "$py" - <<'PY'
import json, os, platform, subprocess
def out(cmd):
    try:
        return subprocess.run(cmd, capture_output=True, text=True, check=True).stdout.strip()
    except Exception as exc:
        return f"unknown ({exc.__class__.__name__})"
cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), "unknown")
env = {"date": os.environ["DATE_START"] + (" (BENCH_QUICK=1: a smoke run, not the real figures)" if os.environ["QUICK"] == "1" else ""),
       "cpu": cpu, "nproc": out(["nproc"]),
       "load_start": os.environ["LOAD_START"], "load_end": " ".join(open("/proc/loadavg").read().split()[:3]),
       "kernel": platform.release(), "rustc": out(["rustc", "--version"]), "python": platform.python_version(),
       "valgrind": out(["valgrind", "--version"])}
import numpy; env["numpy"] = numpy.__version__ + " (1.26 inside Blender)"
try:
    import pytransform3d; env["pytransform3d"] = pytransform3d.__version__
except ImportError:
    pass
bpy_json = os.path.join(os.environ["RUN"], "blender.json")
if os.path.exists(bpy_json):
    env["bpy"] = json.load(open(bpy_json))["env"].get("bpy", "?")
json.dump(env, open(os.path.join(os.environ["RUN"], "machine.json"), "w"), indent=1)
PY
"$py" scripts/bench/bench_report.py --run "$run" --criterion "$CARGO_TARGET_DIR/criterion" \
  --criterion-reuse "$CARGO_TARGET_DIR/criterion-reuse" --out BENCHMARKS.md ${only:+--only "$only"}
stage "done"
