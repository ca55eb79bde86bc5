//! Build script: detects whether the compiler has a stable
//! `core::hint::cold_path` (Rust 1.95) and sets `microraster_cold_path`
//! when it does, so the crate keeps its declared `rust-version` (1.87)
//! while newer compilers lay out the span loops' rare paths out of line
//! (`depth::cold`). No dependency: `$RUSTC --version` is parsed by hand.

use std::env;
use std::process::Command;

fn main() {
    println!("cargo::rustc-check-cfg=cfg(microraster_cold_path)");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-env-changed=RUSTC");
    let rustc = env::var("RUSTC").unwrap_or_else(|_| "rustc".into());
    let Ok(out) = Command::new(rustc).arg("--version").output() else {
        return;
    };
    let text = String::from_utf8_lossy(&out.stdout);
    // "rustc 1.95.0 (59807616e 2026-04-14)", "rustc 1.96.0-nightly (...)".
    let minor = text
        .split_whitespace()
        .nth(1)
        .and_then(|v| v.split('.').nth(1))
        .and_then(|m| m.parse::<u32>().ok());
    if minor.is_some_and(|m| m >= 95) {
        println!("cargo:rustc-cfg=microraster_cold_path");
    }
}
