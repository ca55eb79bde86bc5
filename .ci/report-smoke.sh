#!/usr/bin/env bash
# A reduced speed-vs-error report for CI (160x120, 3 repetitions, all four
# scenes, all eight configurations): checks that the report runs on a fresh
# clone, writes its table and plot, and that every difference from the f64
# reference is explained by snapping (see docs/accuracy.md).
#
#   bash .ci/report-smoke.sh [OUT_DIR]     (default target/ci/report)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-target/ci/report}
# The report is a cargo feature of the host (not in the default build).
cargo run --release -q -p microraster-host --features report -- report speed-vs-error "$out" --quick --no-progress
test -s "$out/speed-vs-error.md"
test -s "$out/speed-vs-error.png"
sed -n '/^## By configuration/,/^★/p' "$out/speed-vs-error.md"
if ! grep -q '^None: every differing pixel' "$out/speed-vs-error.md"; then
  echo "report-smoke: differences from the f64 reference that snapping does not explain:"
  sed -n '/^## Unexplained differences/,/^## Columns/p' "$out/speed-vs-error.md"
  exit 1
fi
echo "report-smoke: ok"
