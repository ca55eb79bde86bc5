//! The house (`--features house`, `house-portals`): portal culling on the
//! microcontroller (issue 11).
//!
//! The `house` scene of the host, 8x8 rooms and their doors (`microraster
//! bake-house`: `baked/house.rs`, 54,744 triangles in 256 objects, one
//! cell a room, two portals a door, 1.2 MB of flash), at 320x240 `Rgb565`
//! with a `u16` depth buffer, in immediate mode: every strip submits the
//! objects again, each with its bounding sphere (skipped outside the
//! strip before any vertex is transformed), as the Spot builds do.
//!
//! With `house-portals`, once a frame, the walk of the portal graph
//! (`PortalGraph::visible`: each reached room's screen rectangle narrowed
//! through the portals' boxes) gives every room the strips its rectangle
//! meets; a strip skips the objects of every other room before
//! transforming them (a room the walk does not reach, in every strip).
//! Conservative for a scene that keeps the portal promise (see
//! `microraster::portal`; `std-host/tests/portal.rs` proves the per-strip
//! use over random houses and cameras), so the frame is the house drawn
//! whole, which build.rs renders on the host (and the host test from the
//! generator itself: host-checksums.txt `house`). Then a sweep of the
//! host's 64 cameras draws each frame culled and whole and compares
//! them on the board.
//!
//! The split is measured as the Spot builds measure it: geometry is the
//! objects drawn in the middle row's strip submitted to a one-row strip,
//! times the strips, and the walk.

use crate::clock::Clock;
use crate::display::{push, HashDisplay};
use crate::{
    exit, finish, print_counts, ram_use, ratio, Counts, BOARD, CORE, HEIGHT, STRIP_LEN, STRIP_ROWS,
    WIDTH,
};
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use microraster::pixelcolor::{Rgb565, RgbColor};
use microraster::{Config, Mesh, MeshColors, StripRenderer, Submit};

/// The baked house (`microraster bake-house`, see docs/culling.md).
#[allow(dead_code)]
pub mod baked {
    include!("../baked/house.rs");
}

/// Rooms (cells) of the house.
const CELLS: usize = baked::ROOMS * baked::ROOMS;

/// Object `o` as a mesh (its colours per vertex or per triangle).
fn mesh(o: &baked::HouseObject) -> Option<Mesh<'static>> {
    let range = |r: [u32; 2]| r[0] as usize..r[1] as usize;
    let colors = baked::COLORS.get(range(o.colors))?;
    Some(Mesh {
        positions: baked::POSITIONS.get(range(o.positions))?,
        indices: baked::INDICES.get(range(o.triangles))?,
        attributes: if o.per_vertex {
            MeshColors::PerVertex(colors)
        } else {
            MeshColors::PerTriangle(colors)
        },
        bounds: Some(o.sphere),
    })
}

/// Strips of the frame: a bit each in a `u32`.
const STRIPS: usize = HEIGHT.div_ceil(STRIP_ROWS as u32) as usize;
const _: () = assert!(STRIPS <= 32);

/// Writes into `out` the strips that draw each room, a bit a strip: with
/// `house-portals` those its rectangle from the portal walk meets (none
/// where the walk does not reach it), else all. Kept as bits, not
/// rectangles (256 B instead of 512, and the rectangles' stack is given
/// back before the strips are drawn: out of line). `false` if the baked
/// graph is refused.
#[inline(never)]
fn room_strips(config: &Config, camera: &baked::HouseCamera, out: &mut [u32; CELLS]) -> bool {
    #[cfg(feature = "house-portals")]
    {
        use microraster::portal::{PixelRect, PortalGraph};
        let Ok(graph) = PortalGraph::new(&baked::CELLS, &baked::PORTALS) else {
            return false;
        };
        let mut rects = [PixelRect::EMPTY; CELLS];
        if graph
            .visible(&camera.view_proj, config, camera.start, &mut rects)
            .is_err()
        {
            return false;
        }
        for (bits, r) in out.iter_mut().zip(&rects) {
            *bits = 0;
            for s in 0..STRIPS {
                let y0 = (s * STRIP_ROWS) as u32;
                if r.meets_rows(y0, y0 + STRIP_ROWS as u32) {
                    *bits |= 1 << s;
                }
            }
        }
        true
    }
    #[cfg(not(feature = "house-portals"))]
    {
        let _ = (config, camera);
        out.fill(u32::MAX);
        true
    }
}

/// Rooms drawn in some strip.
fn reached(rooms: &[u32; CELLS]) -> usize {
    rooms.iter().filter(|&&r| r != 0).count()
}

/// A hash of the strips' rooms (to compare two walks without a second
/// copy on the stack).
fn fold(rooms: &[u32; CELLS]) -> u64 {
    rooms.iter().fold(0xcbf2_9ce4_8422_2325, |h, &r| {
        (h ^ u64::from(r)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The camera of record.
const RECORD: baked::HouseCamera = baked::HouseCamera {
    view_proj: baked::VIEW_PROJ,
    start: baked::START,
};

/// Submits to `strip` (strip number `s`) the objects of the rooms seen in
/// it, triangle ids counting over the whole house. The triangles skipped.
fn submit<S: Submit<8, 3>>(
    strip: &mut S,
    view_proj: &microraster::Mat4,
    rooms: &[u32; CELLS],
    s: usize,
) -> Result<u64, &'static str> {
    let mut skipped = 0;
    for o in baked::OBJECTS.iter() {
        let m = mesh(o).ok_or("baked object ranges")?;
        let seen = rooms.get(o.room as usize).ok_or("baked room")?;
        if seen & (1 << s) == 0 {
            skipped += m.indices.len() as u64;
            continue;
        }
        strip
            .submit_mesh(&m, view_proj, o.triangles[0])
            .map_err(|_| "submit")?;
    }
    Ok(skipped)
}

/// The frame from `camera`: the walk (with `culled`; else every room in
/// every strip) into `rooms`, then every strip cleared, drawn and pushed.
/// The pixels written and the triangles the strips skipped (summed over
/// the strips).
fn frame(
    config: Config,
    camera: &baked::HouseCamera,
    culled: bool,
    rooms: &mut [u32; CELLS],
    color: &mut [Rgb565],
    depth: &mut [u16],
    display: &mut HashDisplay,
) -> Result<(u64, u64), &'static str> {
    if !culled {
        rooms.fill(u32::MAX);
    } else if !room_strips(&config, camera, rooms) {
        return Err("the baked portal graph");
    }
    let (mut written, mut skipped) = (0, 0);
    let (mut y0, mut s) = (0, 0);
    while y0 < HEIGHT {
        let y1 = (y0 + STRIP_ROWS as u32).min(HEIGHT);
        let len = WIDTH as usize * (y1 - y0) as usize;
        let (color, depth) = (&mut color[..len], &mut depth[..len]);
        color.fill(Rgb565::BLACK);
        depth.fill(u16::MAX);
        let mut strip =
            StripRenderer::new(config, y0, y1, color, depth).map_err(|_| "strip renderer")?;
        skipped += submit(&mut strip, &camera.view_proj, rooms, s)?;
        written += strip.render_stats().pixels_written;
        push(display, y0, y1, color)?;
        (y0, s) = (y1, s + 1);
    }
    Ok((written, skipped))
}

/// The sweep's sums over its cameras.
#[cfg(feature = "house-portals")]
#[derive(Default)]
struct Sweep {
    /// Rooms reached and triangles the strips skipped.
    reached: u64,
    skipped: u64,
    /// Ticks of the culled frames (walk and strips, pushes excluded) and
    /// of the same frames with every room drawn.
    culled: u64,
    every: u64,
    /// Whether every culled frame's checksum is its every-room frame's.
    identical: bool,
}

/// Draws each of `baked::SWEEP`'s cameras culled and with every room, and
/// compares the two frames' checksums (the frame of record's set aside).
#[cfg(feature = "house-portals")]
#[inline(never)]
fn sweep(
    config: Config,
    rooms: &mut [u32; CELLS],
    color: &mut [Rgb565],
    depth: &mut [u16],
    display: &mut HashDisplay,
) -> Sweep {
    use crate::display::Saved;
    let saved = display.save();
    let mut s = Sweep {
        identical: true,
        ..Sweep::default()
    };
    for camera in baked::SWEEP.iter() {
        let mut sums = [None; 2];
        for (i, culled) in [true, false].into_iter().enumerate() {
            display.restore(Saved::default());
            let t = display.clock.now();
            let drawn = frame(config, camera, culled, rooms, color, depth, display);
            let ticks = display.clock.now() - t - display.ticks;
            sums[i] = display.checksum().filter(|_| drawn.is_ok());
            if culled {
                s.culled += ticks;
                if let Ok((_, skipped)) = drawn {
                    s.skipped += skipped;
                    s.reached += reached(rooms) as u64;
                }
            } else {
                s.every += ticks;
            }
        }
        s.identical &= sums[0].is_some() && sums[0] == sums[1];
    }
    display.restore(saved);
    s
}

#[entry]
fn main() -> ! {
    static mut COLOR: [Rgb565; STRIP_LEN] = [Rgb565::BLACK; STRIP_LEN];
    static mut DEPTH: [u16; STRIP_LEN] = [0; STRIP_LEN];

    let p = cortex_m::Peripherals::take().unwrap();
    let mut clock = Clock::start(p.SYST);
    let (cal_instr, cal_ticks) = clock.instructions_per_tick();
    let instr = |ticks: u64| ticks * cal_instr / cal_ticks;
    let mut display = HashDisplay::new(WIDTH, HEIGHT, clock);
    let config = Config::new(WIDTH, HEIGHT);
    if (baked::WIDTH, baked::HEIGHT) != (WIDTH, HEIGHT) {
        hprintln!("FAIL: the baked camera is for another frame size");
        exit(false)
    }

    let mut rooms = [0u32; CELLS];
    let t0 = display.clock.now();
    let drawn = frame(
        config,
        &RECORD,
        true,
        &mut rooms,
        &mut COLOR[..],
        &mut DEPTH[..],
        &mut display,
    );
    let end = display.clock.now();
    let (written, skipped) = match drawn {
        Ok(d) => d,
        Err(e) => {
            hprintln!("FAIL: drawing the frame: {}", e);
            exit(false)
        }
    };
    let checksum = display.checksum();

    // The split, measured again on its own: one strip's clear, the walk,
    // and the objects drawn submitted to one row (times the strips).
    let clock = &mut display.clock;
    let t = clock.now();
    COLOR.fill(Rgb565::BLACK);
    DEPTH.fill(u16::MAX);
    let one_clear = clock.now() - t;
    let (first, n_first) = (fold(&rooms), reached(&rooms));
    let t = clock.now();
    let again = room_strips(&config, &RECORD, &mut rooms);
    let walk = clock.now() - t;
    let same = again && fold(&rooms) == first;
    let t = clock.now();
    let w = WIDTH as usize;
    if let Ok(mut one) = StripRenderer::new(
        config,
        HEIGHT / 2,
        HEIGHT / 2 + 1,
        &mut COLOR[..w],
        &mut DEPTH[..w],
    ) {
        // The middle row's rooms: an estimate of the strips' average.
        let s = (HEIGHT / 2) as usize / STRIP_ROWS;
        let _ = submit(&mut one, &baked::VIEW_PROJ, &rooms, s);
    }
    let one_row = clock.now() - t;
    #[cfg(feature = "house-portals")]
    let sweep = sweep(
        config,
        &mut rooms,
        &mut COLOR[..],
        &mut DEPTH[..],
        &mut display,
    );
    let (statics, stack) = ram_use();

    let strips = HEIGHT.div_ceil(STRIP_ROWS as u32) as u64;
    let frame = instr(end - t0);
    let shown = instr(display.ticks);
    let render = frame - shown;
    let clears = instr(one_clear * strips);
    let geometry = instr(one_row * strips + walk).min(render - clears);
    let raster = render - clears - geometry;
    let total = baked::INDICES.len() as u64;
    let reached_rooms = n_first;

    hprintln!(
        "microraster firmware: {} ({}), {}x{} Rgb565, depth u16, a {}x{} house ({} triangles, {} objects, {}), immediate, {} strips of {} rows",
        BOARD,
        CORE,
        WIDTH,
        HEIGHT,
        baked::ROOMS,
        baked::ROOMS,
        total,
        baked::OBJECTS.len(),
        if cfg!(feature = "house-portals") {
            "portal culling"
        } else {
            "every room"
        },
        strips,
        STRIP_ROWS,
    );
    print_counts(
        checksum,
        &Counts {
            per_tick: (cal_instr, cal_ticks),
            written,
            frame,
            shown,
            render,
            clears,
            geometry,
            raster,
            strips: Some(strips),
        },
    );
    let (a, b) = ratio(skipped * 100, total * strips);
    hprintln!(
        "portals: {} of {} rooms reached, skipped before transform {} of {} triangles over the {} strips ({}.{} %), walk {} instructions a frame",
        reached_rooms,
        CELLS,
        skipped,
        total * strips,
        strips,
        a,
        b,
        instr(walk)
    );
    if !same {
        hprintln!("FAIL: the portal walk decided differently the second time");
        exit(false)
    }
    #[cfg(feature = "house-portals")]
    {
        let s = &sweep;
        let n = baked::SWEEP.len() as u64;
        let (a, b) = ratio(s.skipped * 100, total * strips * n);
        let (r, rb) = ratio(s.reached, n);
        let (culled, every) = (instr(s.culled) / n, instr(s.every) / n);
        let q = (culled * 1000 + every / 2) / every.max(1);
        hprintln!(
            "sweep of {} cameras: {}.{} rooms reached, skipped before transform {}.{} %; render a frame {} culled, {} with every room ({}.{:03}x)",
            n,
            r,
            rb,
            a,
            b,
            culled,
            every,
            q / 1000,
            q % 1000
        );
        if !s.identical {
            hprintln!(
                "FAIL: a sweep frame culled differs from the same frame with every room drawn"
            );
            exit(false)
        }
    }
    finish(checksum, statics, stack)
}
