#!/usr/bin/env bash
# Builds the crates with the Rust version they declare (`rust-version` in
# Cargo.toml): the core with both float backends, for the host and for a
# Cortex-M target, and the scenes crate. Installs that toolchain (minimal
# profile) when missing.
set -euo pipefail
cd "$(dirname "$0")/.."
msrv=$(sed -n 's/^rust-version = "\(.*\)"/\1/p' Cargo.toml | head -1)
test -n "$msrv"
echo "declared rust-version: $msrv"
if ! rustup toolchain list | grep -q "^$msrv"; then
  rustup toolchain install "$msrv" --profile minimal
fi
rustup target add --toolchain "$msrv" thumbv7em-none-eabihf
export CARGO_TARGET_DIR=target/msrv
cargo +"$msrv" check -p microraster -p microraster-scenes
cargo +"$msrv" check -p microraster --no-default-features --features micromath
cargo +"$msrv" check -p microraster --target thumbv7em-none-eabihf
if grep -q "^rust-version = \"$msrv\"" std-host/Cargo.toml; then
  cargo +"$msrv" check -p microraster-host
fi
echo "msrv $msrv: ok"
