//! # The four cubes on a microcontroller, checked against the host
//!
//! This firmware draws microraster's default scene (four cubes, a colour
//! per face) at 320x240 `Rgb565` with a `u16` depth buffer, the way a
//! device with a small SPI display would: through a strip buffer of a few
//! rows, in immediate mode (no setup storage; the vertices are processed
//! once per frame and the triangles submitted again for every strip),
//! pushed by the core's embedded-graphics adapter
//! [`StripDrawer`] into a display stand-in that checksums what it receives
//! (`display.rs`). It runs under QEMU on three cores:
//!
//! | QEMU machine | core       | target                  | rows per strip |
//! |--------------|------------|-------------------------|----------------|
//! | `mps2-an386` | Cortex-M4F | `thumbv7em-none-eabihf` | 15             |
//! | `mps2-an385` | Cortex-M3  | `thumbv7m-none-eabi`    | 15             |
//! | `microbit`   | Cortex-M0  | `thumbv6m-none-eabi`    | 8 (16 KB RAM)  |
//!
//! From this folder, with `qemu-system-arm` on the path (`apt-get install
//! qemu-system-arm`) and the target added (`rustup target add ...`):
//!
//! ```text
//! cargo run --release --target thumbv7em-none-eabihf
//! cargo run --release --target thumbv7m-none-eabi
//! cargo run --release --target thumbv6m-none-eabi
//! ```
//!
//! `build.rs` picks the board's `memory/*.x` and strip height from the
//! target, and renders the same frame on the host, with the same core
//! crate, by another path (one `Frame`, one 240-row strip), to embed the
//! host's checksum. The firmware prints over semihosting the frame's
//! checksum and the host's, the instructions the frame took (SysTick under
//! `-icount shift=0`, see `clock.rs`) and where they went, the pixels
//! written, and its RAM: statics plus the stack's high-water mark (the
//! stack is painted at reset by cortex-m-rt's `paint-stack`, and scanned
//! after the frame). It exits 0 only if the checksums are equal and the
//! stack stayed inside its RAM; QEMU passes the exit code on.
//!
//! Features: `no-depth` draws without a depth buffer (painter's order; the
//! host renders the same) and `flat` with a pixel type that never asks for
//! interpolated colour; each leaves that code out of the binary (see
//! `docs/embedded.md` for what that saves).
//!
//! Configuration features (cubes; the report's speed axis, see
//! `docs/embedded.md`): `subpixel4` (4 subpixel bits instead of 8, set
//! up once only), `depth-u32` (a `u32` depth buffer, fewer rows per
//! strip), `micromath` with `--no-default-features` (the float backend of
//! the core and the scenes; `libm` is the default) and `no-i32-edges`
//! (the core's measurement feature: no `i32` edge fast path). build.rs
//! renders the same configuration on the host.
//!
//! Features `spot-flat`, `spot-gouraud`, `spot-lit`, `spot-textured`,
//! `spot-textured-lit` and `spot-phong` draw baked Spot instead (`spot.rs`,
//! `spot_scene.rs`): the model and its texture in flash, immediate mode,
//! one shading variant per build. With one of them, `clusters` and the
//! `cull-*` features draw Spot with cluster tests or normal masks, and
//! `herd` and `herd-occlusion` a herd of 100 Spots without and with
//! occlusion culling (see `docs/culling.md`). Features `house` and
//! `house-portals` draw a baked house of rooms and doors without and with
//! portal culling (`house.rs`). Where the cubes' code is left out, the
//! build script sets `cfg(baked)` (a baked scene: Spot or the house).

#![no_std]
#![no_main]

mod clock;
mod display;
#[cfg(feature = "spot")]
mod spot;
#[cfg(feature = "spot")]
mod spot_scene;
#[cfg(feature = "house")]
mod house;

#[cfg(not(baked))]
use clock::Clock;
#[cfg(not(baked))]
use cortex_m_rt::entry;
use cortex_m_semihosting::debug;
use cortex_m_semihosting::hprintln;
#[cfg(not(baked))]
use display::HashDisplay;
#[cfg(all(feature = "flat", not(baked)))]
use microraster::pixelcolor::Rgb888;
#[cfg(not(baked))]
use microraster::pixelcolor::{Rgb565, RgbColor};
#[cfg(not(any(feature = "immediate", baked)))]
use microraster::SetupTriangle;
#[cfg(all(feature = "immediate", not(baked)))]
use microraster::StripRenderer;
#[cfg(not(baked))]
use microraster::{Config, ProcessedVertex, StripDrawer, Submit};
#[cfg(not(baked))]
use microraster_scenes::cubes;
use panic_semihosting as _;

#[cfg(all(feature = "spot", feature = "house"))]
compile_error!("`house` draws the house, not Spot: build one of them");
#[cfg(all(feature = "tiles", any(feature = "immediate", baked)))]
compile_error!("`tiles` is for the cubes set up once (not `immediate`, `clipless` or `spot-*`)");
#[cfg(all(feature = "subpixel4", any(feature = "immediate", baked)))]
compile_error!("`subpixel4` is for the cubes set up once (not `immediate` or `spot-*`)");
#[cfg(all(feature = "depth-u32", any(feature = "no-depth", baked)))]
compile_error!("`depth-u32` is for the cubes with a depth buffer (not `no-depth` or `spot-*`)");

/// Subpixel bits of the frame (`subpixel4`: 4, else 8).
#[cfg(not(baked))]
const SUBPIXEL: u32 = if cfg!(feature = "subpixel4") { 4 } else { 8 };

/// The depth buffer's word (`depth-u32`: `u32`, else `u16`).
#[cfg(not(any(baked, feature = "no-depth", feature = "depth-u32")))]
type DepthWord = u16;
#[cfg(all(not(any(baked, feature = "no-depth")), feature = "depth-u32"))]
type DepthWord = u32;

// BOARD, CORE, STRIP_ROWS and HOST_CHECKSUM, written by build.rs.
include!(concat!(env!("OUT_DIR"), "/board.rs"));

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;
/// Tiles (`tiles`): 32x32 pixels, 10x8 of them (the bottom row 16 high).
#[cfg(feature = "tiles")]
const TILE: u32 = 32;
#[cfg(feature = "tiles")]
const TILES: usize = (WIDTH.div_ceil(TILE) * HEIGHT.div_ceil(TILE)) as usize;
/// Bin entries: one per (stored triangle, tile its box touches); the
/// four cubes need 130 (checked each frame: binning fails if they do not
/// fit).
#[cfg(feature = "tiles")]
const BIN_ITEMS: usize = 256;
/// Pixels the colour and depth buffers hold: one tile (`tiles`) or one
/// strip.
#[cfg(feature = "tiles")]
const STRIP_LEN: usize = (TILE * TILE) as usize;
#[cfg(not(feature = "tiles"))]
const STRIP_LEN: usize = WIDTH as usize * STRIP_ROWS;
/// Set-up triangles the frame can hold: the four cubes' 48 triangles,
/// of which at most half face the camera (the rest are culled as back
/// faces before storage), with room for clipped pieces.
#[cfg(not(any(feature = "immediate", baked)))]
const SETUP_CAPACITY: usize = 32;

/// The strip buffer's pixel: the display's own `Rgb565`, or with `flat`
/// [`Flat565`].
#[cfg(not(baked))]
#[cfg(not(feature = "flat"))]
type StripPixel = Rgb565;
#[cfg(not(baked))]
#[cfg(feature = "flat")]
type StripPixel = Flat565;

/// An `Rgb565` pixel that never asks for interpolated colour
/// (`SHADED = false`): the rasterizer hands it each triangle's flat colour
/// (its first vertex's), and the perspective-correct colour code is never
/// instantiated. For the cubes, flat per face, the pixels are the same.
#[cfg(feature = "flat")]
#[derive(Clone, Copy)]
struct Flat565(Rgb565);

#[cfg(feature = "flat")]
impl microraster::PixelFormat for Flat565 {
    const SHADED: bool = false;
    #[inline]
    fn from_fragment(rgb: Rgb888, _: u32) -> Self {
        Flat565(Rgb565::from(rgb))
    }
}

#[cfg(feature = "flat")]
impl From<Flat565> for Rgb565 {
    #[inline]
    fn from(p: Flat565) -> Rgb565 {
        p.0
    }
}

#[cfg(not(baked))]
const BLACK: StripPixel = {
    #[cfg(feature = "flat")]
    {
        Flat565(Rgb565::BLACK)
    }
    #[cfg(not(feature = "flat"))]
    {
        Rgb565::BLACK
    }
};

/// The four cubes' corners, transformed, outcoded and snapped once per
/// frame (8 per cube): what every strip's submission starts from.
#[cfg(not(baked))]
type Vertices = [ProcessedVertex; 4 * 8];

/// Processes the four cubes' vertices for a frame of `config` (once per
/// frame: the result does not depend on the strip).
#[cfg(not(baked))]
fn process(config: Config, mvps: &[microraster::Mat4; 4], out: &mut Vertices) {
    // A frame with no storage is enough to run the vertex stage, which
    // does not depend on the mode (a frame refuses the clipless one).
    let config = Config {
        mode: microraster::RasterMode::Clipping,
        ..config
    };
    let probe = microraster::Frame::<SUBPIXEL>::with_subpixel_bits(config, &mut []);
    if let Ok(probe) = probe {
        for (mvp, cache) in mvps.iter().zip(out.chunks_exact_mut(8)) {
            probe.process_vertices(mvp, &cubes::POSITIONS, cache);
        }
    }
}

/// Submits the four cubes to one strip (triangle ids as in
/// `cubes::for_each_cube`); triangles wholly above or below the strip are
/// skipped before setup.
#[cfg(all(feature = "immediate", not(baked)))]
fn submit<D>(strip: &mut StripRenderer<'_, StripPixel, D>, vertices: &Vertices)
where
    D: microraster::DepthBuffer + ?Sized,
{
    for (i, cache) in vertices.chunks_exact(8).enumerate() {
        // A strip renderer never runs out of storage: nothing to handle.
        let _ = strip.submit_processed_mesh(
            &cubes::MESH,
            (i * cubes::CUBE_INDICES.len()) as u32,
            cache,
        );
    }
}

extern "C" {
    static _ram_start: u32;
    static _stack_start: u32;
    static _stack_end: u32;
}

/// Statics (`.data` + `.bss`) and the stack's high-water mark, in bytes;
/// `None` if not one word of paint is left (the stack may have overflowed).
fn ram_use() -> (usize, Option<usize>) {
    // Linker symbols: only their addresses are taken.
    let (ram, top, bottom) = (
        core::ptr::addr_of!(_ram_start) as usize,
        core::ptr::addr_of!(_stack_start) as usize,
        core::ptr::addr_of!(_stack_end) as usize,
    );
    let mut a = bottom;
    // SAFETY: `bottom..top` is the stack region, word aligned, in RAM.
    while a < top && unsafe { core::ptr::read_volatile(a as *const u32) } == 0xcccc_cccc {
        a += 4;
    }
    (bottom - ram, (a > bottom).then_some(top - a))
}

/// `n / d` with one decimal, as `(whole, tenths)` (no float formatting
/// is linked).
fn ratio(n: u64, d: u64) -> (u64, u64) {
    let t = (n * 10 + d / 2) / d.max(1);
    (t / 10, t % 10)
}

#[cfg(not(baked))]
#[entry]
fn main() -> ! {
    static mut COLOR: [StripPixel; STRIP_LEN] = [BLACK; STRIP_LEN];
    static mut VERTICES: Vertices = [ProcessedVertex::EMPTY; 32];
    #[cfg(not(feature = "immediate"))]
    static mut SETUP: [SetupTriangle; SETUP_CAPACITY] = [SetupTriangle::EMPTY; SETUP_CAPACITY];
    #[cfg(not(feature = "no-depth"))]
    static mut DEPTH: [DepthWord; STRIP_LEN] = [0; STRIP_LEN];
    #[cfg(feature = "tiles")]
    static mut OFFSETS: [u32; TILES + 1] = [0; TILES + 1];
    #[cfg(feature = "tiles")]
    static mut ITEMS: [u32; BIN_ITEMS] = [0; BIN_ITEMS];

    let p = cortex_m::Peripherals::take().unwrap();
    let mut clock = Clock::start(p.SYST);
    let (cal_instr, cal_ticks) = clock.instructions_per_tick();
    let instr = |ticks: u64| ticks * cal_instr / cal_ticks;

    #[cfg(not(feature = "no-depth"))]
    let depth = &mut DEPTH[..];
    #[cfg(feature = "no-depth")]
    let depth = microraster::NoDepth;
    #[allow(unused_mut)]
    let mut config = Config::new(WIDTH, HEIGHT);
    #[cfg(feature = "clipless")]
    {
        config.mode = microraster::RasterMode::Clipless;
    }
    #[cfg(feature = "inv-w")]
    {
        config.depth_func = microraster::DepthFunc::Greater;
    }
    // 1/w depth clears to 0 (the farthest), window z to the far plane.
    let clear_z32 = if cfg!(feature = "inv-w") { 0 } else { u32::MAX };
    let mut drawer = StripDrawer::new(&mut COLOR[..], depth, BLACK).with_clear_depth(clear_z32);
    let mut display = HashDisplay::new(WIDTH, HEIGHT, clock);

    // The frame: camera matrices and the vertex stage, (in set-up-once
    // mode) every triangle set up into the frame's storage, then every
    // strip.
    let t0 = display.clock.now();
    #[cfg(not(feature = "inv-w"))]
    let mvps = cubes::mvps(WIDTH, HEIGHT);
    #[cfg(feature = "inv-w")]
    let mvps = cubes::mvps_inv_w(WIDTH, HEIGHT);
    process(config, &mvps, VERTICES);
    let vertices: &Vertices = VERTICES;
    #[cfg(feature = "immediate")]
    let (drawn, setup_ticks) = {
        let setup_ticks = display.clock.now() - t0;
        let drawn = drawer.draw(&mut display, config, |strip| submit(strip, vertices));
        (drawn, setup_ticks)
    };
    #[cfg(not(feature = "immediate"))]
    let (drawn, setup_ticks) = {
        let mut frame = match microraster::Frame::<SUBPIXEL>::with_subpixel_bits(config, SETUP) {
            Ok(f) => f,
            Err(e) => {
                hprintln!("FAIL: frame: {}", e);
                exit(false)
            }
        };
        for (i, cache) in vertices.chunks_exact(8).enumerate() {
            let id = (i * cubes::CUBE_INDICES.len()) as u32;
            if let Err(e) = frame.submit_processed_mesh(&cubes::MESH, id, cache) {
                hprintln!("FAIL: setup: {}", e);
                exit(false)
            }
        }
        #[cfg(not(feature = "tiles"))]
        let drawn = {
            let setup_ticks = display.clock.now() - t0;
            (drawer.draw_frame(&mut display, &frame), setup_ticks)
        };
        // Binning is part of the frame's setup.
        #[cfg(feature = "tiles")]
        let drawn = {
            let bins = match frame.bin_tiles(TILE, TILE, &mut OFFSETS[..], &mut ITEMS[..]) {
                Ok(b) => b,
                Err(e) => {
                    hprintln!("FAIL: binning: {}", e);
                    exit(false)
                }
            };
            let setup_ticks = display.clock.now() - t0;
            (
                drawer.draw_frame_tiles(&mut display, &frame, &bins),
                setup_ticks,
            )
        };
        drawn
    };
    let frame_ticks = display.clock.now() - t0;

    let written = match drawn {
        Ok(stats) => stats.pixels_written,
        Err(e) => {
            hprintln!("FAIL: drawing the frame: {:?}", e);
            exit(false)
        }
    };
    let checksum = display.checksum();
    let (statics, stack) = ram_use();
    // What the strip clears restored (see the split below).
    #[cfg(not(feature = "tiles"))]
    let cleared_px = drawer.pixels_cleared();

    // Where the instructions went. Set-up-once mode measures them apart in
    // the frame itself: the vertex stage and setup (once per frame), the
    // strip clears (an empty scene through the same drawer), the rest
    // rasterization. Immediate mode repeats cull, clip and setup for every
    // strip: that is estimated as the scene submitted to a one-row strip
    // (which includes that one row's pixels), times the strips.
    let strips = HEIGHT.div_ceil(STRIP_ROWS as u32) as u64;
    // Strip clears. The drawer clears, before each strip, only what the
    // strip before it wrote (`pixels_cleared` counts those pixels), so
    // they are estimated: the same drawer draws an empty scene in
    // immediate mode twice, first with its buffers taken as unknown (its
    // first strip cleared whole, then nothing), then again (nothing
    // cleared), each less its pushes. The difference is the cost of the
    // pixels the first cleared; the frame's clears are its own pixels
    // cleared at that rate. (The clears' cost a strip and a row is left
    // in rasterization. Measuring with `draw_frame` instead would give it
    // a second call site and change how the frame itself compiles.)
    let mut empty = HashDisplay::new(WIDTH, HEIGHT, display.clock);
    #[cfg(not(feature = "tiles"))]
    let clear_ticks = {
        let mut drawer = drawer.with_clear_depth(clear_z32);
        let (t, px) = (empty.clock.now(), drawer.pixels_cleared());
        let _ = drawer.draw(&mut empty, config, |_| {});
        let whole = (empty.clock.now() - t) - empty.ticks;
        let whole_px = drawer.pixels_cleared() - px;
        empty = HashDisplay::new(WIDTH, HEIGHT, empty.clock);
        let t = empty.clock.now();
        let _ = drawer.draw(&mut empty, config, |_| {});
        let none = (empty.clock.now() - t) - empty.ticks;
        (whole.saturating_sub(none) * cleared_px).div_ceil(whole_px.max(1))
    };
    // Tiles: an empty frame through the same tiles (each cleared, its
    // empty bin drawn, pushed), less its pushes.
    #[cfg(feature = "tiles")]
    let clear_ticks = {
        let none = microraster::Frame::<SUBPIXEL>::with_subpixel_bits(config, &mut []);
        let t = empty.clock.now();
        if let Ok(none) = none {
            if let Ok(bins) = none.bin_tiles(TILE, TILE, &mut OFFSETS[..], &mut ITEMS[..]) {
                let _ = drawer.draw_frame_tiles(&mut empty, &none, &bins);
            }
        }
        (empty.clock.now() - t) - empty.ticks
    };
    #[cfg(not(feature = "immediate"))]
    let geometry_ticks = setup_ticks;
    #[cfg(feature = "immediate")]
    let geometry_ticks = {
        let clock = &mut empty.clock;
        let t = clock.now();
        let (row, rest) = COLOR.split_at_mut(WIDTH as usize);
        core::hint::black_box(rest);
        #[cfg(not(feature = "no-depth"))]
        let z = &mut DEPTH[..WIDTH as usize];
        #[cfg(feature = "no-depth")]
        let z = &mut microraster::NoDepth;
        let mut one = StripRenderer::new(config, HEIGHT / 2, HEIGHT / 2 + 1, row, z).unwrap();
        submit(&mut one, vertices);
        (clock.now() - t) * strips + setup_ticks
    };

    let frame = instr(frame_ticks);
    let shown = instr(display.ticks);
    let render = frame - shown;
    let clears = instr(clear_ticks);
    let geometry = instr(geometry_ticks).min(render - clears);
    let raster = render - clears - geometry;
    let per_px = |n: u64| ratio(n, written);

    // How the frame is cut: strips of STRIP_ROWS rows, or tiles.
    #[cfg(feature = "tiles")]
    let (pieces, piece) = (TILES as u64, ("tiles of", TILE, "x32 pixels"));
    #[cfg(not(feature = "tiles"))]
    let (pieces, piece) = (strips, ("strips of", STRIP_ROWS as u32, " rows"));
    hprintln!(
        "microraster firmware: {} ({}), {}x{} Rgb565, depth {}, colour {}, {}, {} {} {}{}",
        BOARD,
        CORE,
        WIDTH,
        HEIGHT,
        if cfg!(feature = "no-depth") {
            "none"
        } else if cfg!(feature = "depth-u32") {
            "u32"
        } else {
            "u16"
        },
        if cfg!(feature = "flat") {
            "flat"
        } else {
            "interpolated"
        },
        if cfg!(feature = "immediate") {
            "immediate"
        } else {
            "set up once"
        },
        pieces,
        piece.0,
        piece.1,
        piece.2,
    );
    hprintln!(
        "configuration: subpixel {}, math {}, i32 edge fast path {}",
        SUBPIXEL,
        if cfg!(feature = "libm") {
            "libm"
        } else {
            "micromath"
        },
        if cfg!(feature = "no-i32-edges") {
            "off"
        } else {
            "on"
        },
    );
    hprintln!("checksum {:#018x}", checksum.unwrap_or(0));
    hprintln!("host     {:#018x}", HOST_CHECKSUM);
    let (a, b) = ratio(cal_instr, cal_ticks);
    hprintln!("instructions per SysTick tick {}.{}", a, b);
    let (a, b) = per_px(frame);
    hprintln!(
        "instructions per frame {}; pixels written {}; per written pixel {}.{}",
        frame,
        written,
        a,
        b
    );
    let (a, b) = per_px(shown);
    hprintln!("  display push (checksum)  {} ({}.{}/px)", shown, a, b);
    let (a, b) = per_px(render);
    hprintln!("  render                   {} ({}.{}/px)", render, a, b);
    let (a, b) = per_px(clears);
    hprintln!("    strip clears           {} ({}.{}/px)", clears, a, b);
    let (a, b) = per_px(geometry);
    if cfg!(feature = "immediate") {
        hprintln!(
            "    geometry x {} strips   {} ({}.{}/px)",
            strips,
            geometry,
            a,
            b
        );
    } else {
        hprintln!("    geometry (once)        {} ({}.{}/px)", geometry, a, b);
    }
    let (a, b) = per_px(raster);
    hprintln!("    rasterization          {} ({}.{}/px)", raster, a, b);
    match stack {
        Some(s) => hprintln!(
            "ram statics {} B + stack high-water {} B = {} B",
            statics,
            s,
            statics + s
        ),
        None => hprintln!("ram statics {} B + stack: OVERFLOWED", statics),
    }

    let pass = checksum == Some(HOST_CHECKSUM) && stack.is_some();
    if pass {
        hprintln!("PASS: bit-identical to the host");
    } else {
        hprintln!("FAIL: the frame differs from the host's, or the stack overflowed");
    }
    exit(pass)
}

/// What a frame cost, as the baked scenes' builds print it (the lines
/// `.ci/firmware.sh` parses): instructions, their split and per pixel
/// written. (The cubes print the same lines inline: moving them into
/// these functions changed how the cubes' frame compiles, +31,560
/// instructions a frame on the M4F.)
#[cfg(baked)]
struct Counts {
    /// SysTick's instructions per tick, as `(instructions, ticks)`.
    per_tick: (u64, u64),
    written: u64,
    frame: u64,
    shown: u64,
    render: u64,
    clears: u64,
    geometry: u64,
    raster: u64,
    /// The strips the geometry was submitted to (`None`: set up once).
    strips: Option<u64>,
}

/// Prints the frame's checksum, the host's and `c`.
#[cfg(baked)]
fn print_counts(checksum: Option<u64>, c: &Counts) {
    let per_px = |n: u64| ratio(n, c.written);
    hprintln!("checksum {:#018x}", checksum.unwrap_or(0));
    hprintln!("host     {:#018x}", HOST_CHECKSUM);
    let (a, b) = ratio(c.per_tick.0, c.per_tick.1);
    hprintln!("instructions per SysTick tick {}.{}", a, b);
    let (a, b) = per_px(c.frame);
    hprintln!(
        "instructions per frame {}; pixels written {}; per written pixel {}.{}",
        c.frame,
        c.written,
        a,
        b
    );
    let (a, b) = per_px(c.shown);
    hprintln!("  display push (checksum)  {} ({}.{}/px)", c.shown, a, b);
    let (a, b) = per_px(c.render);
    hprintln!("  render                   {} ({}.{}/px)", c.render, a, b);
    let (a, b) = per_px(c.clears);
    hprintln!("    strip clears           {} ({}.{}/px)", c.clears, a, b);
    let (a, b) = per_px(c.geometry);
    match c.strips {
        Some(n) => hprintln!(
            "    geometry x {} strips   {} ({}.{}/px)",
            n,
            c.geometry,
            a,
            b
        ),
        None => hprintln!("    geometry (once)        {} ({}.{}/px)", c.geometry, a, b),
    }
    let (a, b) = per_px(c.raster);
    hprintln!("    rasterization          {} ({}.{}/px)", c.raster, a, b);
}

/// Prints the RAM used (`ram_use`'s statics and stack) and the verdict,
/// and exits: 0 only if `checksum` is the host's and the stack stayed in
/// its RAM.
#[cfg(baked)]
fn finish(checksum: Option<u64>, statics: usize, stack: Option<usize>) -> ! {
    match stack {
        Some(s) => hprintln!(
            "ram statics {} B + stack high-water {} B = {} B",
            statics,
            s,
            statics + s
        ),
        None => hprintln!("ram statics {} B + stack: OVERFLOWED", statics),
    }
    let pass = checksum == Some(HOST_CHECKSUM) && stack.is_some();
    if pass {
        hprintln!("PASS: bit-identical to the host");
    } else {
        hprintln!("FAIL: the frame differs from the host's, or the stack overflowed");
    }
    exit(pass)
}

/// Ends the run: QEMU exits 0 for success, 1 otherwise.
fn exit(success: bool) -> ! {
    debug::exit(if success {
        debug::EXIT_SUCCESS
    } else {
        debug::EXIT_FAILURE
    });
    // Not reached under QEMU; on a board without a debugger, stop here.
    loop {
        cortex_m::asm::wfi();
    }
}
