#!/usr/bin/env bash
# Builds the cargo-fuzz targets in fuzz/ and runs each one for a while,
# starting from the committed seed corpus (fuzz/seeds/<target>/, pieces of
# the shared models written by fuzz/seeds.py) copied into the run's corpus.
# Two builds: the default one (libm the core's default float backend, with
# micromath arms through `*_with::<Micromath>`) and one with micromath as
# the default backend (`--no-default-features`, its own target dir), so
# `Mat4::perspective` and `BoundingSphere::from_points` run on micromath.
# Targets: frame, strip_renderer, clusters (cluster culling, honest and
# arbitrary sets), occlusion (honest and arbitrary bounds and tile counts), portal (arbitrary cells, portals and boxes: typed errors, rectangles in the frame), clipless (the clipless mode: no panic, splits alike), shading (every shading: colours, lit
# colours, textures, Phong; ids, depth and counters independent of it).
# Before fuzzing, every file in fuzz/findings/ (minimised inputs of fixed
# core issues, README.md there; the .md files skipped) is replayed once
# through each target on each build, every check strict: a regression.
# Exits non-zero when a target crashes (panic, overflow, assertion, ASan
# report) or a finding replays to a crash; the crashing input is left in
# fuzz/artifacts/<target>/.
#
#   bash .ci/fuzz.sh                      # CI: a minute per target
#                                         # (40 s libm build, 20 s micromath),
#                                         # one campaign a core at once
#   FUZZ_SECONDS=1800 bash .ci/fuzz.sh    # 30 min per target, one after the
#                                         # other (docs/accuracy.md has the
#                                         # long run, both targets at once)
#   FUZZ_JOBS=8 FUZZ_SECONDS=3600 bash .ci/fuzz.sh   # ... on 8 cores each
#   FUZZ_PARALLEL=1 bash .ci/fuzz.sh      # one campaign at a time
#   FUZZ_TARGETS=frame bash .ci/fuzz.sh   # one target
#   FUZZ_BUILDS=libm bash .ci/fuzz.sh     # one build (libm or micromath)
#
# Reproduce a crash:
#   cd fuzz && cargo +nightly fuzz run -O -a <target> <file>
#   cd fuzz && cargo +nightly fuzz run -O -a --no-default-features \
#     --target-dir target/micromath <target> <file>      # micromath build
# Needs a nightly toolchain (ASan, sanitizer coverage) and cargo-fuzz,
# installed here when missing (a few minutes).
set -euo pipefail
cd "$(dirname "$0")/.."

# FUZZ_SECONDS per target in all: two thirds on the libm build, a third
# on the micromath build (unless FUZZ_BUILDS names one only).
TOTAL_SECONDS=${FUZZ_SECONDS:-60}
TARGETS=${FUZZ_TARGETS:-"frame strip_renderer shading clusters clipless occlusion portal"}
BUILDS=${FUZZ_BUILDS:-"libm micromath"}
if [ "$(echo $BUILDS | wc -w)" -gt 1 ]; then
  MICROMATH_SECONDS=$(( TOTAL_SECONDS / 3 ))
  SECONDS_PER_TARGET=$(( TOTAL_SECONDS - MICROMATH_SECONDS ))
else
  MICROMATH_SECONDS=$TOTAL_SECONDS
  SECONDS_PER_TARGET=$TOTAL_SECONDS
fi
JOBS=${FUZZ_JOBS:-1}
# Inputs grow to real meshes: a 2,400-triangle piece is about 25 KB.
MAX_LEN=${FUZZ_MAX_LEN:-32768}

if ! rustup toolchain list | grep -q '^nightly'; then
  rustup toolchain install nightly --profile minimal
fi
if ! cargo fuzz --version >/dev/null 2>&1; then
  cargo install cargo-fuzz --locked
fi

cd fuzz
build_args() {
  case "$1" in
    libm) ;;
    micromath) echo "--no-default-features --target-dir target/micromath" ;;
    *) echo "unknown build $1" >&2; exit 2 ;;
  esac
}
# -O: optimised; -a: debug assertions. fuzz/Cargo.toml's release profile
# also turns overflow checks on.
for b in $BUILDS; do
  # shellcheck disable=SC2046
  cargo +nightly fuzz build -O -a $(build_args "$b")
done
mkdir -p target/logs
status=0
# Findings first: every file through each target and build in one run
# (libFuzzer runs each file given as an argument once, and stops at the
# first that fails); where that run fails, one run per file names them.
findings=()
for f in findings/*; do
  case "$f" in *.md) continue ;; esac
  [ -f "$f" ] && findings+=("$f")
done
replay() { # TARGET BUILD LOG FILE...: runs the files once each
  local t=$1 b=$2 log=$3
  shift 3
  # shellcheck disable=SC2046
  cargo +nightly fuzz run -O -a $(build_args "$b") "$t" "$@" -- \
    -rss_limit_mb=4096 -timeout=30 >"$log" 2>&1
}
for t in $TARGETS; do
  for b in $BUILDS; do
    [ "${#findings[@]}" -gt 0 ] || continue
    replay "$t" "$b" "target/logs/$t-$b-findings.log" "${findings[@]}" && rc=0 || rc=$?
    if [ "$rc" -ne 0 ]; then
      status=1
      named=0
      for f in "${findings[@]}"; do
        log="target/logs/$t-$b-finding-$(basename "$f").log"
        replay "$t" "$b" "$log" "$f" && rc=0 || rc=$?
        if [ "$rc" -ne 0 ]; then
          echo "!! $t ($b build): finding $f fails (exit $rc); from $log:"
          grep -A2 -m1 'panicked at\|ERROR: ' "$log" || tail -n 20 "$log"
          named=1
        fi
      done
      if [ "$named" = 0 ]; then
        echo "!! $t ($b build): the findings fail run together, each passes alone; see target/logs/$t-$b-findings.log"
      fi
    fi
    echo "== $t ($b build): ${#findings[@]} findings replayed"
  done
done
for t in $TARGETS; do
  mkdir -p "corpus/$t"
  # The clipless target reads the strip renderer's input: its seeds too.
  seed=$t
  [ "$t" = clipless ] && seed=strip_renderer
  if [ -d "seeds/$seed" ]; then
    cp -n seeds/"$seed"/* "corpus/$t/" 2>/dev/null || true
  fi
done
# One campaign: TARGET BUILD SECONDS; prints its summary at its end (the
# campaigns run FUZZ_PARALLEL at once) and leaves target/logs/T-B.status.
campaign() {
  local t=$1 b=$2 secs=$3 log="target/logs/$1-$2.log" rc report
  # shellcheck disable=SC2046
  cargo +nightly fuzz run -O -a $(build_args "$b") "$t" "corpus/$t" --jobs "$JOBS" -- \
    -max_total_time="$secs" -max_len="$MAX_LEN" -timeout=30 \
    -rss_limit_mb=4096 -print_final_stats=1 >"$log" 2>&1 && rc=0 || rc=$?
  report="== fuzz $t ($b build) for ${secs}s (jobs: $JOBS)"$'\n'
  report+=$(grep -E 'stat::number_of_executed_units|stat::peak_rss_mb|^Done [0-9]+ runs' "$log" || true)$'\n'
  report+=$(grep -E '^#[0-9]+' "$log" | tail -n 1 || true)$'\n'
  if [ "$rc" -ne 0 ]; then
    report+="!! $t ($b build) failed (exit $rc); the end of $log:"$'\n'
    report+=$(tail -n 60 "$log"; ls -l "artifacts/$t" 2>/dev/null || true)
  else
    report+="ok: $t ($b build) ran clean ($(ls "corpus/$t" | wc -l) inputs in its corpus)"
  fi
  printf '%s\n' "$report"
  echo "$rc" >"target/logs/$t-$b.status"
}
# Campaigns FUZZ_PARALLEL at once (default: the cores over FUZZ_JOBS),
# each build's in turn: two campaigns of one target never run at once,
# and the micromath build starts from what the libm build found.
PARALLEL=${FUZZ_PARALLEL:-$(( $(nproc) / JOBS > 0 ? $(nproc) / JOBS : 1 ))}
rm -f target/logs/*.status
running=0
for b in $BUILDS; do
  secs=$SECONDS_PER_TARGET
  [ "$b" = micromath ] && secs=$MICROMATH_SECONDS
  for t in $TARGETS; do
    if [ "$running" -ge "$PARALLEL" ]; then
      wait -n || true
      running=$((running - 1))
    fi
    campaign "$t" "$b" "$secs" &
    running=$((running + 1))
  done
  wait
  running=0
done
for t in $TARGETS; do
  for b in $BUILDS; do
    rc=$(cat "target/logs/$t-$b.status" 2>/dev/null || echo missing)
    if [ "$rc" != 0 ]; then
      echo "!! $t ($b build): campaign exit $rc"
      status=1
    fi
  done
done
exit "$status"
