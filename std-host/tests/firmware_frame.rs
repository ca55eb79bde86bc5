//! The firmware's frame, computed on the host by a path of its own.
//!
//! `examples/firmware` renders the four cubes at 320x240 `Rgb565` under
//! QEMU and compares its checksum with the one its `build.rs` computes on
//! the host (one `Frame`, one 240-row strip). This test computes the same
//! checksum through the embedded-graphics adapter instead, in immediate
//! mode for several strip heights (the firmware's 16 and 8 among them) and
//! from a set-up frame, into a display stand-in that hashes what it is
//! sent, and requires all of them to equal
//! `examples/firmware/host-checksums.txt`, which `.ci/firmware.sh` also
//! holds the firmware's printed checksum to.

use embedded_graphics_core::draw_target::DrawTarget;
use embedded_graphics_core::geometry::{OriginDimensions, Size};
use embedded_graphics_core::pixelcolor::{IntoStorage, Rgb565, RgbColor};
use embedded_graphics_core::primitives::Rectangle;
use embedded_graphics_core::Pixel;
use microraster::prelude::Submit;
use microraster::{Config, DepthBuffer, Frame, NoDepth, SetupTriangle, StripDrawer, StripRenderer};
use microraster_scenes::checksum::FrameChecksum;
use microraster_scenes::cubes;

const WIDTH: u32 = 320;
const HEIGHT: u32 = 240;
const CHECKSUMS: &str = include_str!("../../examples/firmware/host-checksums.txt");

fn expected(key: &str) -> u64 {
    let line = CHECKSUMS
        .lines()
        .find_map(|l| l.strip_prefix(key)?.strip_prefix(' '))
        .unwrap_or_else(|| panic!("no {key} line in host-checksums.txt"));
    u64::from_str_radix(line.trim().trim_start_matches("0x"), 16).unwrap()
}

/// A display that takes whole rows in order and checksums them as the
/// firmware's display stand-in does.
struct Hasher {
    rows: u32,
    sum: FrameChecksum,
}

impl Hasher {
    fn new() -> Hasher {
        Hasher {
            rows: 0,
            sum: FrameChecksum::new(),
        }
    }
}

impl OriginDimensions for Hasher {
    fn size(&self) -> Size {
        Size::new(WIDTH, HEIGHT)
    }
}

impl DrawTarget for Hasher {
    type Color = Rgb565;
    type Error = String;

    fn draw_iter<I: IntoIterator<Item = Pixel<Rgb565>>>(&mut self, _: I) -> Result<(), String> {
        Err("pixel-at-a-time write".into())
    }

    fn fill_contiguous<I: IntoIterator<Item = Rgb565>>(
        &mut self,
        area: &Rectangle,
        colors: I,
    ) -> Result<(), String> {
        if area.top_left.x != 0 || area.top_left.y != self.rows as i32 || area.size.width != WIDTH {
            return Err(format!("rectangle {area:?} after {} rows", self.rows));
        }
        let mut n = 0;
        for c in colors.into_iter().take((WIDTH * area.size.height) as usize) {
            self.sum.push(c.into_storage());
            n += 1;
        }
        assert_eq!(n, WIDTH * area.size.height);
        self.rows += area.size.height;
        Ok(())
    }
}

/// The scene, submitted to one strip.
fn scene<D: DepthBuffer + ?Sized>(strip: &mut StripRenderer<'_, Rgb565, D>) {
    cubes::for_each_cube(WIDTH, HEIGHT, |mesh, mvp, id| {
        strip.submit_mesh(mesh, mvp, id).unwrap()
    })
}

fn immediate(rows: u32, depth: bool) -> u64 {
    let n = (WIDTH * rows) as usize;
    let mut color = vec![Rgb565::BLACK; n];
    let mut target = Hasher::new();
    let config = Config::new(WIDTH, HEIGHT);
    if depth {
        let mut z = vec![0u16; n];
        StripDrawer::new(&mut color, &mut z[..], Rgb565::BLACK)
            .draw(&mut target, config, scene)
            .unwrap();
    } else {
        StripDrawer::new(&mut color, NoDepth, Rgb565::BLACK)
            .draw(&mut target, config, scene)
            .unwrap();
    }
    assert_eq!(target.rows, HEIGHT);
    target.sum.value()
}

fn from_frame(rows: u32, depth: bool) -> u64 {
    let mut storage = vec![SetupTriangle::EMPTY; 48 * 7];
    let mut frame: Frame = Frame::new(Config::new(WIDTH, HEIGHT), &mut storage).unwrap();
    cubes::for_each_cube(WIDTH, HEIGHT, |mesh, mvp, id| {
        frame.submit_mesh(mesh, mvp, id).unwrap()
    });
    let n = (WIDTH * rows) as usize;
    let mut color = vec![Rgb565::BLACK; n];
    let mut target = Hasher::new();
    if depth {
        let mut z = vec![0u16; n];
        StripDrawer::new(&mut color, &mut z[..], Rgb565::BLACK)
            .draw_frame(&mut target, &frame)
            .unwrap();
    } else {
        StripDrawer::new(&mut color, NoDepth, Rgb565::BLACK)
            .draw_frame(&mut target, &frame)
            .unwrap();
    }
    target.sum.value()
}

fn check(key: &str, depth: bool) {
    let want = expected(key);
    for rows in [1, 7, 8, 16, 240] {
        let got = immediate(rows, depth);
        assert_eq!(
            got, want,
            "{key}, immediate, {rows} rows: {got:#018x}, host-checksums.txt says {want:#018x} \
             (if the core changed the frame on purpose, update that file)"
        );
    }
    for rows in [16, 240] {
        assert_eq!(
            from_frame(rows, depth),
            want,
            "{key}, from a Frame, {rows} rows"
        );
    }
}

#[test]
fn firmware_frame_with_u16_depth_matches_the_recorded_checksum() {
    check("depth-u16", true);
}

#[test]
fn firmware_frame_without_depth_matches_the_recorded_checksum() {
    check("no-depth", false);
}
