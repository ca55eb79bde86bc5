#!/usr/bin/env bash
# Runs the core's unit tests under Miri (undefined behaviour, out-of-bounds
# and uninitialised reads, also inside dependencies such as heapless).
#
#   bash .ci/miri.sh              # libm backend: about 6-7 minutes on 2 cores
#   MIRI_ALL=1 bash .ci/miri.sh   # also the micromath-only build (as long again)
#
# libm computes sqrtf with inline assembly (sqrtss) on x86-64, which Miri
# cannot run, so its portable soft-float code is forced with the dependency
# feature `libm/force-soft-floats` (the results are the same: sqrt is
# correctly rounded either way).
set -euo pipefail
cd "$(dirname "$0")/.."
rustup toolchain list | grep -q '^nightly' || rustup toolchain install nightly --profile minimal
rustup +nightly component add miri rust-src
cargo +nightly miri setup

step() { printf '\n== %s\n' "$*"; }

step "miri: core lib tests, libm backend"
time cargo +nightly miri test -p microraster --lib --features libm/force-soft-floats

if [ "${MIRI_ALL:-0}" = 1 ]; then
  step "miri: core lib tests, micromath backend only"
  time cargo +nightly miri test -p microraster --lib --no-default-features --features micromath
fi
echo "miri: ok"
