//! Picks the board for the target, and renders the firmware's frame on the
//! host to embed its checksum.
//!
//! Board: one per target triple (the runner in `.cargo/config.toml` starts
//! the matching QEMU machine). Its `memory/*.x` is copied to `OUT_DIR` as
//! `memory.x` for cortex-m-rt's `link.x`, and the strip height that fits
//! its RAM goes into `board.rs`.
//!
//! Checksum: the same scene, frame size, pixel format and depth buffer as
//! the firmware, rendered here by the same core crate on the host. On
//! purpose by the other path: the whole frame set up once in a [`Frame`]
//! and rendered as one 240-row strip, where the firmware submits the scene
//! strip by strip (set up once into a `Frame`, or submitted to a
//! `StripRenderer` for every strip with `--features immediate`). The hash is the
//! firmware's: `microraster_scenes::checksum::FrameChecksum` over the
//! `Rgb565` pixels, rows top to bottom.

use microraster::pixelcolor::{IntoStorage, Rgb565, RgbColor};
use microraster::{Config, Frame, NoDepth, SetupTriangle, Submit};
use microraster_scenes::checksum::FrameChecksum;
use microraster_scenes::cubes;
use std::env;
use std::fmt::Write as _;
use std::fs;
use std::path::PathBuf;

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;

struct Board {
    name: &'static str,
    core: &'static str,
    memory: &'static str,
    strip_rows: u32,
}

/// The board for `target`, and its strip height for the mode: immediate
/// mode (`immediate` feature) needs no setup storage, so its strips can
/// be taller; set-up-once mode keeps the frame's set-up triangles
/// (`SETUP_CAPACITY` of them, 112 B each) and pays for them in strip rows.
fn board(target: &str, immediate: bool) -> Board {
    let rows = |setup_once: u32, immediate_rows: u32| {
        if immediate {
            immediate_rows
        } else {
            setup_once
        }
    };
    match target {
        "thumbv7em-none-eabihf" => Board {
            name: "mps2-an386",
            core: "Cortex-M4F",
            // Of the 24 KB budget: 12 rows of colour and depth (15 KB) and
            // the set-up triangles (3.5 KB), or 15 rows (18.75 KB) in
            // immediate mode; both keep the frame's processed vertices
            // (1.1 KB).
            memory: "mps2.x",
            strip_rows: rows(12, 15),
        },
        "thumbv7m-none-eabi" => Board {
            name: "mps2-an385",
            core: "Cortex-M3",
            memory: "mps2.x",
            strip_rows: rows(12, 15),
        },
        // 16 KB of RAM: 5 rows (6.25 KB) and the set-up triangles, or 8
        // rows (10 KB) in immediate mode.
        "thumbv6m-none-eabi" => Board {
            name: "microbit",
            core: "Cortex-M0",
            memory: "microbit.x",
            strip_rows: rows(5, 8),
        },
        other => panic!(
            "no board for target {other}: build with --target thumbv7em-none-eabihf \
             (mps2-an386), thumbv7m-none-eabi (mps2-an385) or thumbv6m-none-eabi (microbit)"
        ),
    }
}

/// The frame's checksum as the display receives it.
fn frame_checksum(pixels: &[Rgb565]) -> u64 {
    let mut c = FrameChecksum::new();
    c.extend(pixels.iter().map(|p| p.into_storage()));
    c.value()
}

fn host_checksum(depth: bool) -> u64 {
    let mut storage = vec![SetupTriangle::EMPTY; cubes::CUBE_INDICES.len() * 4 * 7];
    let mut frame = Frame::new(Config::new(WIDTH, HEIGHT), &mut storage).unwrap();
    cubes::for_each_cube(WIDTH, HEIGHT, |mesh, mvp, id| {
        frame.submit_mesh(mesh, mvp, id).unwrap()
    });
    let n = (WIDTH * HEIGHT) as usize;
    let mut color = vec![Rgb565::BLACK; n];
    if depth {
        let mut z = vec![u16::MAX; n];
        frame.render_rows(0, HEIGHT, &mut color, &mut z[..])
    } else {
        frame.render_rows(0, HEIGHT, &mut color, &mut NoDepth)
    }
    .unwrap();
    frame_checksum(&color)
}

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    let target = env::var("TARGET").unwrap();
    let immediate = env::var_os("CARGO_FEATURE_IMMEDIATE").is_some();
    let b = board(&target, immediate);
    let depth = env::var_os("CARGO_FEATURE_NO_DEPTH").is_none();

    let memory = fs::read_to_string(format!("memory/{}", b.memory)).unwrap();
    fs::write(out.join("memory.x"), memory).unwrap();
    println!("cargo:rustc-link-search={}", out.display());

    let checksum = host_checksum(depth);
    let mut s = String::new();
    writeln!(
        s,
        "/// QEMU machine.\npub const BOARD: &str = {:?};",
        b.name
    )
    .unwrap();
    writeln!(s, "/// Processor.\npub const CORE: &str = {:?};", b.core).unwrap();
    writeln!(
        s,
        "/// Rows per strip.\npub const STRIP_ROWS: usize = {};",
        b.strip_rows
    )
    .unwrap();
    writeln!(
        s,
        "/// The host's checksum of the same frame (build.rs).\npub const HOST_CHECKSUM: u64 = {checksum:#018x};"
    )
    .unwrap();
    fs::write(out.join("board.rs"), s).unwrap();

    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=memory");
}
