#!/usr/bin/env bash
# The simulator binary (std-host, feature `simulator`): build it, let it
# draw its first frame headless with EG_SIMULATOR_DUMP, and require that
# picture to equal the host renderer's image of the same frame (320x240,
# u16 depth) once the host's Rgb888 pixels are taken through Rgb565 as the
# simulator's are. Also its unit tests, a check that the comparison does
# catch a different frame, and a few seconds of the interactive loop on
# SDL's dummy video driver.
set -euo pipefail
cd "$(dirname "$0")/.."

step() { printf '\n== %s\n' "$*"; }

step "SDL2 (libsdl2-dev)"
if ! pkg-config --exists sdl2 2>/dev/null; then
  apt-get update -qq
  DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libsdl2-dev pkg-config >/dev/null
fi
pkg-config --modversion sdl2

step "build and unit tests"
cargo build --release -p microraster-host --features simulator --bin simulator --bin microraster
# Its unit tests in the release profile: 2 minutes on 2 cores (the test
# harness builds its dependencies again), where the test profile took 3.5
# (`.ci/run` has removed target/debug by now).
cargo test --release -p microraster-host --features simulator --bin simulator
cargo clippy -p microraster-host --features simulator --bin simulator -- -D warnings
sim=target/release/simulator
host=target/release/microraster
out=target/simulator
mkdir -p "$out"
rm -f "$out"/*.png

step "simulator dump (headless)"
EG_SIMULATOR_DUMP=$out/simulator.png timeout 120 "$sim" </dev/null
test -s "$out/simulator.png"

step "host render of the same frame"
timeout 120 "$host" render --size 320x240 --depth u16 --out "$out/host.png"

step "compare through Rgb565"
"$sim" compare "$out/simulator.png" "$out/host.png"

step "the comparison catches a different frame"
timeout 120 "$host" render --size 320x240 --depth none --out "$out/other.png"
if "$sim" compare "$out/simulator.png" "$out/other.png"; then
  echo "FAIL: the frame drawn without depth buffer compared equal"
  exit 1
fi

step "interactive loop, 3 s on SDL's dummy video driver"
set +e
SDL_VIDEODRIVER=dummy timeout 3 "$sim" </dev/null
rc=$?
set -e
if [ "$rc" -ne 124 ]; then
  echo "FAIL: the window loop stopped with exit code $rc"
  exit 1
fi

echo
echo "simulator: passed"
