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
#                                         # (40 s libm build, 20 s micromath)
#   FUZZ_SECONDS=1800 bash .ci/fuzz.sh    # 30 min per target, one after the
#                                         # other (docs/accuracy.md has the
#                                         # long run, both targets at once)
#   FUZZ_JOBS=8 FUZZ_SECONDS=3600 bash .ci/fuzz.sh   # ... on 8 cores each
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
# Findings first, one run per file (libFuzzer runs a file given as an
# argument once; it would stop at the first that fails).
for t in $TARGETS; do
  for b in $BUILDS; do
    n=0
    for f in findings/*; do
      case "$f" in *.md) continue ;; esac
      [ -f "$f" ] || continue
      n=$((n + 1))
      log="target/logs/$t-$b-finding-$(basename "$f").log"
      set +e
      # shellcheck disable=SC2046
      cargo +nightly fuzz run -O -a $(build_args "$b") "$t" "$f" -- \
        -rss_limit_mb=4096 -timeout=30 >"$log" 2>&1
      rc=$?
      set -e
      if [ "$rc" -ne 0 ]; then
        echo "!! $t ($b build): finding $f fails (exit $rc); from $log:"
        grep -A2 -m1 'panicked at\|ERROR: ' "$log" || tail -n 20 "$log"
        status=1
      fi
    done
    echo "== $t ($b build): $n findings replayed"
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
  for b in $BUILDS; do
    secs=$SECONDS_PER_TARGET
    [ "$b" = micromath ] && secs=$MICROMATH_SECONDS
    echo "== fuzz $t ($b build) for ${secs}s (jobs: $JOBS)"
    log="target/logs/$t-$b.log"
    set +e
    # shellcheck disable=SC2046
    cargo +nightly fuzz run -O -a $(build_args "$b") "$t" "corpus/$t" --jobs "$JOBS" -- \
      -max_total_time="$secs" -max_len="$MAX_LEN" -timeout=30 \
      -rss_limit_mb=4096 -print_final_stats=1 >"$log" 2>&1
    rc=$?
    set -e
    grep -E 'stat::number_of_executed_units|stat::peak_rss_mb|^Done [0-9]+ runs' "$log" || true
    grep -E '^#[0-9]+' "$log" | tail -n 1 || true
    if [ "$rc" -ne 0 ]; then
      echo "!! $t ($b build) failed (exit $rc); the end of $log:"
      tail -n 60 "$log"
      ls -l "artifacts/$t" 2>/dev/null || true
      status=1
    else
      echo "ok: $t ($b build) ran clean ($(ls "corpus/$t" | wc -l) inputs in its corpus)"
    fi
  done
done
exit "$status"
