#!/usr/bin/env bash
# Builds the cargo-fuzz targets in fuzz/ and runs each one for a while.
# Exits non-zero when a target crashes (panic, overflow, assertion, ASan
# report); the crashing input is left in fuzz/artifacts/<target>/.
#
#   bash .ci/fuzz.sh                      # about a minute per target (CI)
#   FUZZ_SECONDS=3600 bash .ci/fuzz.sh    # the long run: an hour per target
#   FUZZ_JOBS=8 FUZZ_SECONDS=3600 bash .ci/fuzz.sh   # ... on 8 cores each
#   FUZZ_TARGETS=frame bash .ci/fuzz.sh   # one target
#
# Reproduce a crash: cd fuzz && cargo +nightly fuzz run -O -a <target> <file>
# Needs a nightly toolchain (ASan, sanitizer coverage) and cargo-fuzz,
# installed here when missing (about 30 s).
set -euo pipefail
cd "$(dirname "$0")/.."

SECONDS_PER_TARGET=${FUZZ_SECONDS:-60}
TARGETS=${FUZZ_TARGETS:-"frame strip_renderer"}
JOBS=${FUZZ_JOBS:-1}

if ! rustup toolchain list | grep -q '^nightly'; then
  rustup toolchain install nightly --profile minimal
fi
if ! cargo fuzz --version >/dev/null 2>&1; then
  cargo install cargo-fuzz --locked
fi

cd fuzz
# -O: optimised; -a: debug assertions. fuzz/Cargo.toml's release profile
# also turns overflow checks on.
cargo +nightly fuzz build -O -a
mkdir -p target/logs
status=0
for t in $TARGETS; do
  mkdir -p "corpus/$t"
  echo "== fuzz $t for ${SECONDS_PER_TARGET}s (jobs: $JOBS)"
  log="target/logs/$t.log"
  set +e
  cargo +nightly fuzz run -O -a "$t" --jobs "$JOBS" -- \
    -max_total_time="$SECONDS_PER_TARGET" -max_len=4096 -timeout=20 \
    -rss_limit_mb=4096 -print_final_stats=1 >"$log" 2>&1
  rc=$?
  set -e
  grep -E 'stat::number_of_executed_units|stat::peak_rss_mb|^Done [0-9]+ runs' "$log" || true
  if [ "$rc" -ne 0 ]; then
    echo "!! $t failed (exit $rc); the end of $log:"
    tail -n 60 "$log"
    ls -l "artifacts/$t" 2>/dev/null || true
    status=1
  else
    echo "ok: $t ran clean ($(ls "corpus/$t" | wc -l) inputs in its corpus)"
  fi
done
exit "$status"
