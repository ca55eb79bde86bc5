//! A deferred clear ([`LazyClear`], `Frame::render_tile_lazy`) gives the
//! pixels of a clear followed by the same draws: a property test over
//! random frames (flat and smooth triangles, some covering whole rows,
//! some clipped at the near and far planes), any tile size, one or two
//! layers, `u16`, `u32`, `f32` and no depth, every depth test, writes on or off,
//! any clear depth, and buffers that start out holding garbage; and named
//! cases for what the deferred clear must refuse.

#![cfg(feature = "lazy-clear")]

use microraster::pixelcolor::Rgb888;
use microraster::prelude::*;
use microraster::{
    Config, CullMode, DepthF32, DepthFunc, DepthWord, Error, FragmentShader, Frame, LazyClear,
    NoDepth, SetupTriangle, Vec4,
};
use proptest::prelude::*;

/// Colours every pixel by a hash of its varyings' bits (the smooth spans'
/// entry points show in the colour).
#[derive(Clone, Copy, Debug)]
struct BitsHash;

impl FragmentShader<3> for BitsHash {
    fn shade(&self, v: &[f32; 3], id: u32) -> Rgb888 {
        let mut h = 0xcbf2_9ce4_8422_2325u64 ^ id as u64;
        for x in v {
            h = (h ^ x.to_bits() as u64).wrapping_mul(0x0100_0000_01b3);
        }
        Rgb888::new(h as u8, (h >> 8) as u8, (h >> 16) as u8)
    }
}

type Tri = ([Vec4; 3], [[f32; 3]; 3]);

fn vertex() -> impl Strategy<Value = Vec4> {
    // Some vertices beyond the frame's sides, past the near or far plane
    // or behind the eye: clipped triangles, boxes wider than tiles, depths
    // at the planes.
    (
        -2.5f32..2.5,
        -2.5f32..2.5,
        -1.3f32..1.3,
        prop_oneof![4 => 0.2f32..4.0, 1 => -1.0f32..-0.1],
    )
        .prop_map(|(x, y, z, w)| Vec4::new(x * w.abs(), y * w.abs(), z * w.abs(), w))
}

/// Triangles, half of them flat (equal varyings: the flat span loops),
/// and a few covering the whole frame at one depth (the full-screen case,
/// where the deferred clear writes every pixel once).
fn tris() -> impl Strategy<Value = Vec<Tri>> {
    let var = || prop::array::uniform::<_, 3>(0.0f32..1.0);
    let tri = (
        (vertex(), vertex(), vertex()).prop_map(|(a, b, c)| [a, b, c]),
        (var(), var(), var(), any::<u8>(), -0.95f32..0.95),
    )
        .prop_map(|(p, (a, b, c, k, z))| match k % 8 {
            0 => {
                let q = |x: f32, y: f32| Vec4::new(x, y, z, 1.0);
                ([q(-3.0, -3.0), q(3.0, -3.0), q(0.0, 3.0)], [a, a, a])
            }
            1..=4 => (p, [a, a, a]),
            _ => (p, [a, b, c]),
        });
    prop::collection::vec(tri, 1..9)
}

fn noise(seed: u64, n: usize) -> impl Iterator<Item = u64> {
    let mut x = seed | 1;
    (0..n).map(move |_| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    })
}

/// Depth words, cleared or as garbage.
trait Word: DepthWord {
    fn garbage(x: u64) -> Self;
}
impl Word for u16 {
    fn garbage(x: u64) -> Self {
        x as u16
    }
}
impl Word for u32 {
    fn garbage(x: u64) -> Self {
        x as u32
    }
}
impl Word for DepthF32 {
    fn garbage(x: u64) -> Self {
        DepthF32::from_z32(x as u32)
    }
}

/// One case: `layers` frames over the same tiles, drawn with a clear
/// first and with a deferred clear into garbage; colour, depth and the
/// pixels written must be the same.
#[allow(clippy::too_many_arguments)]
fn check<W: Word>(
    (w, h): (u32, u32),
    layers: &[Vec<Tri>],
    (func, write): (DepthFunc, bool),
    clear_z32: u32,
    (tw, th): (u32, u32),
    depth_on: bool,
    shaded: bool,
    seed: u64,
) -> Result<(), TestCaseError> {
    let mut config = Config::new(w, h);
    config.cull = CullMode::None;
    config.depth_func = func;
    config.depth_write = write;
    let mut storage: Vec<Vec<SetupTriangle>> = layers
        .iter()
        .map(|l| vec![SetupTriangle::EMPTY; l.len() * 7])
        .collect();
    let mut frames = Vec::new();
    for (st, tris) in storage.iter_mut().zip(layers) {
        let mut f = Frame::new(config, st).unwrap();
        for (i, (p, v)) in tris.iter().enumerate() {
            let c = v.map(|c| {
                Rgb888::new(
                    (c[0] * 255.0) as u8,
                    (c[1] * 255.0) as u8,
                    (c[2] * 255.0) as u8,
                )
            });
            f.submit_clip_triangle(*p, c, i as u32).unwrap();
        }
        frames.push(f);
    }
    let tiles = frames[0].tiles(tw, th);
    let mut bins = Vec::new();
    let mut store: Vec<(Vec<u32>, Vec<u32>)> = frames
        .iter()
        .map(|f| {
            (
                vec![0u32; f.tiles(tw, th) + 1],
                vec![0u32; f.tile_bin_entries(tw, th)],
            )
        })
        .collect();
    for (f, (o, i)) in frames.iter().zip(store.iter_mut()) {
        bins.push(f.bin_tiles(tw, th, o, i).unwrap());
    }
    let bg = Rgb888::new(7, 77, 177);
    let mut garbage = noise(seed, usize::MAX);
    for tile in 0..tiles as u32 {
        let rect = bins[0].rect(tile);
        let n = ((rect[1] - rect[0]) * (rect[3] - rect[2])) as usize;
        // With a clear first.
        let mut c1 = vec![bg; n];
        let mut d1 = vec![W::from_z32(clear_z32); n];
        let mut w1 = 0;
        for (f, b) in frames.iter().zip(&bins) {
            w1 += match (depth_on, shaded) {
                (true, false) => f.render_tile(b, tile, &mut c1, &mut d1[..]),
                (true, true) => f.render_tile_shaded(b, tile, &mut c1, &mut d1[..], &BitsHash),
                (false, false) => f.render_tile(b, tile, &mut c1, &mut NoDepth),
                (false, true) => f.render_tile_shaded(b, tile, &mut c1, &mut NoDepth, &BitsHash),
            }
            .unwrap()
            .pixels_written;
        }
        // Deferred, into garbage.
        let mut c2: Vec<Rgb888> = (&mut garbage)
            .take(n)
            .map(|x| Rgb888::new(x as u8, (x >> 8) as u8, (x >> 16) as u8))
            .collect();
        let mut d2: Vec<W> = (&mut garbage).take(n).map(W::garbage).collect();
        let mut hull = vec![0u32; (rect[3] - rect[2]) as usize + (seed % 3) as usize];
        let mut lazy = LazyClear::new(&mut hull, rect, bg, clear_z32).unwrap();
        let mut w2 = 0;
        for (f, b) in frames.iter().zip(&bins) {
            w2 += match (depth_on, shaded) {
                (true, false) => f.render_tile_lazy(b, tile, &mut c2, &mut d2[..], &mut lazy),
                (true, true) => {
                    f.render_tile_lazy_shaded(b, tile, &mut c2, &mut d2[..], &BitsHash, &mut lazy)
                }
                (false, false) => f.render_tile_lazy(b, tile, &mut c2, &mut NoDepth, &mut lazy),
                (false, true) => {
                    f.render_tile_lazy_shaded(b, tile, &mut c2, &mut NoDepth, &BitsHash, &mut lazy)
                }
            }
            .unwrap()
            .pixels_written;
        }
        let cleared = if depth_on {
            lazy.finish(&mut c2, &mut d2[..]).unwrap()
        } else {
            lazy.finish(&mut c2, &mut NoDepth).unwrap()
        };
        prop_assert!(cleared <= n as u64);
        prop_assert_eq!(w1, w2, "pixels written, tile {} {:?}", tile, rect);
        prop_assert!(c1 == c2, "colour, tile {} {:?}", tile, rect);
        if depth_on {
            prop_assert!(d1 == d2, "depth, tile {} {:?}", tile, rect);
        }
    }
    Ok(())
}

fn func() -> impl Strategy<Value = DepthFunc> {
    prop_oneof![
        6 => Just(DepthFunc::Less),
        1 => Just(DepthFunc::LessEqual),
        1 => Just(DepthFunc::Greater),
        1 => Just(DepthFunc::GreaterEqual),
        1 => Just(DepthFunc::Always),
        1 => Just(DepthFunc::Equal),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn deferred_clears_equal_clears_first(
        (w, h) in (1u32..72, 1u32..40),
        layers in prop::collection::vec(tris(), 1..=2),
        func in func(),
        write in prop::bool::weighted(0.85),
        clear in prop_oneof![3 => Just(u32::MAX), 1 => Just(0u32), 1 => any::<u32>()],
        (tw, th) in (prop_oneof![Just(0u32), 1u32..40], 1u32..20),
        kind in 0u8..4,
        shaded in prop::bool::weighted(0.3),
        seed in any::<u64>(),
    ) {
        // A tile width of 0 or past the frame: whole strips.
        let tw = if tw == 0 || tw >= w { w } else { tw };
        let fw = (func, write);
        match kind {
            0 => check::<u16>((w, h), &layers, fw, clear, (tw, th), true, shaded, seed)?,
            1 => check::<u32>((w, h), &layers, fw, clear, (tw, th), true, shaded, seed)?,
            2 => check::<DepthF32>((w, h), &layers, fw, clear, (tw, th), true, shaded, seed)?,
            _ => check::<u16>((w, h), &layers, fw, clear, (tw, th), false, shaded, seed)?,
        }
    }
}

/// A hull shorter than the rectangle's rows, a render of another
/// rectangle, and buffers shorter than the rectangle at the end are typed
/// errors; nothing is written.
#[test]
fn what_a_deferred_clear_refuses() {
    let mut short = [0u32; 3];
    assert_eq!(
        LazyClear::new(&mut short, [0, 8, 0, 4], Rgb888::new(0, 0, 0), u32::MAX).err(),
        Some(Error::HullSize {
            expected: 4,
            actual: 3
        })
    );
    let mut wide = [0u32; 1];
    assert!(matches!(
        LazyClear::new(&mut wide, [0, 70_000, 0, 1], Rgb888::new(0, 0, 0), 0),
        Err(Error::HullSize { .. })
    ));
    let mut st = vec![SetupTriangle::EMPTY; 4];
    let mut config = Config::new(16, 8);
    config.cull = CullMode::None;
    let mut frame = Frame::new(config, &mut st).unwrap();
    let v = |x: f32, y: f32| Vec4::new(x, y, 0.0, 1.0);
    frame
        .submit_clip_triangle(
            [v(-1.0, -1.0), v(1.0, -1.0), v(0.0, 1.0)],
            [Rgb888::new(9, 9, 9); 3],
            0,
        )
        .unwrap();
    let (mut o, mut i) = (
        vec![0u32; frame.tiles(16, 4) + 1],
        vec![0u32; frame.tile_bin_entries(16, 4)],
    );
    let bins = frame.bin_tiles(16, 4, &mut o, &mut i).unwrap();
    let mut hull = [0u32; 4];
    let mut lazy = LazyClear::new(&mut hull, bins.rect(0), Rgb888::new(1, 2, 3), u32::MAX).unwrap();
    let mut c = vec![Rgb888::new(5, 5, 5); 64];
    let mut d = [7u16; 64];
    assert_eq!(
        frame
            .render_tile_lazy(&bins, 1, &mut c, &mut d[..], &mut lazy)
            .err(),
        Some(Error::LazyClearRect)
    );
    assert!(c.iter().all(|&p| p == Rgb888::new(5, 5, 5)) && d.iter().all(|&z| z == 7));
    assert_eq!(
        lazy.finish(&mut c[..63], &mut d[..]).err(),
        Some(Error::ColorBufferSize {
            expected: 64,
            actual: 63
        })
    );
    let mut hull = [0u32; 4];
    let lazy = LazyClear::new(&mut hull, bins.rect(0), Rgb888::new(1, 2, 3), u32::MAX).unwrap();
    assert!(matches!(
        lazy.finish(&mut c, &mut d[..40]),
        Err(Error::DepthBufferSize { .. })
    ));
    assert!(d.iter().all(|&z| z == 7));
    // Nothing drawn: finish clears the whole rectangle.
    let mut hull = [0u32; 4];
    let lazy = LazyClear::new(&mut hull, bins.rect(0), Rgb888::new(1, 2, 3), u32::MAX).unwrap();
    assert_eq!(lazy.finish(&mut c, &mut d[..]), Ok(64));
    assert!(c.iter().all(|&p| p == Rgb888::new(1, 2, 3)) && d.iter().all(|&z| z == u16::MAX));
}

/// A full-screen flat triangle pair under `Less` writes every pixel once
/// and leaves nothing for `finish` to clear; its pixels are the cleared
/// frame's.
#[test]
fn a_full_screen_quad_leaves_nothing_to_clear() {
    let mut st = vec![SetupTriangle::EMPTY; 4];
    let config = Config::new(64, 16);
    let mut frame = Frame::new(config, &mut st).unwrap();
    let v = |x: f32, y: f32| Vec4::new(x, y, 0.0, 1.0);
    let c = [Rgb888::new(40, 120, 200); 3];
    frame
        .submit_clip_triangle([v(-1.0, -1.0), v(1.0, -1.0), v(1.0, 1.0)], c, 0)
        .unwrap();
    frame
        .submit_clip_triangle([v(-1.0, -1.0), v(1.0, 1.0), v(-1.0, 1.0)], c, 1)
        .unwrap();
    let (mut o, mut i) = (
        vec![0u32; frame.tiles(64, 16) + 1],
        vec![0u32; frame.tile_bin_entries(64, 16)],
    );
    let bins = frame.bin_tiles(64, 16, &mut o, &mut i).unwrap();
    let mut hull = [0u32; 16];
    let mut lazy = LazyClear::new(&mut hull, bins.rect(0), Rgb888::new(0, 0, 0), u32::MAX).unwrap();
    let mut cg = vec![Rgb888::new(1, 1, 1); 1024];
    let mut dg = vec![0u16; 1024];
    let written = frame
        .render_tile_lazy(&bins, 0, &mut cg, &mut dg[..], &mut lazy)
        .unwrap()
        .pixels_written;
    assert_eq!(written, 1024);
    assert_eq!(lazy.finish(&mut cg, &mut dg[..]), Ok(0));
    let mut c1 = vec![Rgb888::new(0, 0, 0); 1024];
    let mut d1 = vec![u16::MAX; 1024];
    frame.render_tile(&bins, 0, &mut c1, &mut d1[..]).unwrap();
    assert!(c1 == cg && d1 == dg);
}
