//! Tiles: any rectangle of a frame, rendered into buffers that hold only
//! it, has the pixels and depths of the whole frame there
//! (`Frame::render_rect`, `Frame::bin_tiles` + `Frame::render_tile`).
//!
//! The colours come from a shader that hashes the bits of every varying it
//! is given, so a tile that entered a span's varyings anywhere but where
//! the whole row does (a different re-synchronisation point, one float step
//! more or less) changes the colour. Depth is compared word for word in
//! `u32` and `u16` buffers (the `u16` flat spans take the unchecked path).

use microraster::pixelcolor::{Rgb565, Rgb888};
use microraster::prelude::*;
use microraster::{
    Config, CullMode, DepthFunc, Error, FragmentShader, Frame, NoDepth, SetupTriangle, TriangleId,
    Vec4,
};
use proptest::prelude::*;

/// Colours every pixel by an FNV-1a hash of its varyings' bits.
#[derive(Clone, Copy, Debug)]
struct BitsHash;

impl<const N: usize> FragmentShader<N> for BitsHash {
    fn shade(&self, v: &[f32; N], id: u32) -> Rgb888 {
        let mut h = 0xcbf2_9ce4_8422_2325u64 ^ id as u64;
        for x in v {
            h = (h ^ x.to_bits() as u64).wrapping_mul(0x0100_0000_01b3);
        }
        Rgb888::new(h as u8, (h >> 8) as u8, (h >> 16) as u8)
    }
}

type Tri<const N: usize> = ([Vec4; 3], [[f32; N]; 3]);

fn vertex() -> impl Strategy<Value = Vec4> {
    // Some vertices beyond the frame sides, behind the eye or past the
    // near and far planes: clipped triangles and boxes wider than tiles.
    (
        -1.8f32..1.8,
        -1.8f32..1.8,
        -1.3f32..1.3,
        prop_oneof![0.2f32..4.0, -1.0f32..-0.1],
    )
        .prop_map(|(x, y, z, w)| Vec4::new(x * w.abs(), y * w.abs(), z * w.abs(), w))
}

/// Triangles with `N` varyings, about a third of them flat (equal
/// varyings: one colour, the flat span loops).
fn tris<const N: usize>() -> impl Strategy<Value = Vec<Tri<N>>> {
    let var = || prop::array::uniform::<_, N>(0.0f32..1.0);
    let tri = (
        (vertex(), vertex(), vertex()).prop_map(|(a, b, c)| [a, b, c]),
        (var(), var(), var(), any::<u8>()),
    )
        .prop_map(|(p, (a, b, c, k))| (p, if k % 3 == 0 { [a, a, a] } else { [a, b, c] }));
    prop::collection::vec(tri, 1..10)
}

fn config(w: u32, h: u32, le: bool) -> Config {
    let mut c = Config::new(w, h);
    c.cull = CullMode::None;
    c.depth_func = if le {
        DepthFunc::LessEqual
    } else {
        DepthFunc::Less
    };
    c
}

/// Every image a rectangle renders to: hashed colours over `u32` and
/// `u16` depth, both depths, ids over `u16` depth and over none, and
/// `Rgb565` vertex colours (for `N = 3`) over `u16` depth.
#[derive(Debug, PartialEq, Eq, Clone)]
struct Images {
    hashed32: Vec<Rgb888>,
    z32: Vec<u32>,
    hashed16: Vec<Rgb888>,
    z16: Vec<u16>,
    ids16: Vec<u32>,
    ids: Vec<u32>,
    rgb565: Vec<Rgb565>,
    written: u64,
}

impl Images {
    fn blank(n: usize) -> Images {
        Images {
            hashed32: vec![Rgb888::new(1, 2, 3); n],
            z32: vec![u32::MAX; n],
            hashed16: vec![Rgb888::new(1, 2, 3); n],
            z16: vec![u16::MAX; n],
            ids16: vec![0; n],
            ids: vec![0; n],
            rgb565: vec![Rgb565::new(1, 2, 3); n],
            written: 0,
        }
    }

    /// Copies `tile` (the images of rectangle `r`) into `self`, a whole
    /// frame `w` pixels wide.
    fn paste(&mut self, tile: &Images, [x0, x1, y0, y1]: [u32; 4], w: u32) {
        let tw = (x1 - x0) as usize;
        for y in y0..y1 {
            let src = (y - y0) as usize * tw..(y - y0) as usize * tw + tw;
            let dst = (y * w + x0) as usize..(y * w + x0) as usize + tw;
            self.hashed32[dst.clone()].copy_from_slice(&tile.hashed32[src.clone()]);
            self.z32[dst.clone()].copy_from_slice(&tile.z32[src.clone()]);
            self.hashed16[dst.clone()].copy_from_slice(&tile.hashed16[src.clone()]);
            self.z16[dst.clone()].copy_from_slice(&tile.z16[src.clone()]);
            self.ids16[dst.clone()].copy_from_slice(&tile.ids16[src.clone()]);
            self.ids[dst.clone()].copy_from_slice(&tile.ids[src.clone()]);
            self.rgb565[dst].copy_from_slice(&tile.rgb565[src]);
        }
        self.written += tile.written;
    }
}

/// Renders rectangle `r` of `frame` by `render_rect` (`tile: None`) or
/// as tile `tile` of `bins`.
fn render<const S: u32, const N: usize>(
    frame: &Frame<'_, S, N>,
    r: [u32; 4],
    tile: Option<(&microraster::Bins<'_>, u32)>,
) -> Images {
    let n = ((r[1] - r[0]) * (r[3] - r[2])) as usize;
    let mut im = Images::blank(n);
    let mut ids = vec![TriangleId(0); n];
    let mut ids16 = vec![TriangleId(0); n];
    let mut z16b = vec![u16::MAX; n];
    let go = |c: &mut dyn FnMut(&Frame<'_, S, N>) -> Result<microraster::RenderStats, Error>| {
        c(frame).unwrap().pixels_written
    };
    let mut written = 0;
    match tile {
        None => {
            written +=
                go(&mut |f| f.render_rect_shaded(r, &mut im.hashed32, &mut im.z32[..], &BitsHash));
            written +=
                go(&mut |f| f.render_rect_shaded(r, &mut im.hashed16, &mut im.z16[..], &BitsHash));
            written += go(&mut |f| f.render_rect_shaded(r, &mut ids16, &mut z16b[..], &BitsHash));
            written += go(&mut |f| f.render_rect_shaded(r, &mut ids, &mut NoDepth, &BitsHash));
        }
        Some((b, t)) => {
            assert_eq!(b.rect(t), r);
            written += go(&mut |f| {
                f.render_tile_shaded(b, t, &mut im.hashed32, &mut im.z32[..], &BitsHash)
            });
            written += go(&mut |f| {
                f.render_tile_shaded(b, t, &mut im.hashed16, &mut im.z16[..], &BitsHash)
            });
            written +=
                go(&mut |f| f.render_tile_shaded(b, t, &mut ids16, &mut z16b[..], &BitsHash));
            written += go(&mut |f| f.render_tile_shaded(b, t, &mut ids, &mut NoDepth, &BitsHash));
        }
    }
    if N == 3 {
        // Vertex colours into Rgb565: the u16 flat spans' unchecked loop.
        let mut z = vec![u16::MAX; n];
        let shader = Rgb565Colors;
        written += match tile {
            None => frame.render_rect_shaded(r, &mut im.rgb565, &mut z[..], &shader),
            Some((b, t)) => frame.render_tile_shaded(b, t, &mut im.rgb565, &mut z[..], &shader),
        }
        .unwrap()
        .pixels_written;
        assert_eq!(z, z16b, "depth depends on the pixel format");
    }
    assert_eq!(im.z16, z16b, "depth depends on the pixel format");
    im.ids = ids.into_iter().map(|t| t.0).collect();
    im.ids16 = ids16.into_iter().map(|t| t.0).collect();
    im.written = written;
    im
}

/// The first three varyings as a colour (`VertexColor` for any `N`).
#[derive(Clone, Copy, Debug)]
struct Rgb565Colors;

impl<const N: usize> FragmentShader<N> for Rgb565Colors {
    fn shade(&self, v: &[f32; N], _: u32) -> Rgb888 {
        let c = |x: f32| (x.clamp(0.0, 1.0) * 255.0) as u8;
        Rgb888::new(c(v[0]), c(v[1 % N]), c(v[2 % N]))
    }
}

fn check_tiles<const S: u32, const N: usize>(
    (w, h): (u32, u32),
    tris: &[Tri<N>],
    le: bool,
    (tw, th): (u32, u32),
    rect: [u32; 4],
) -> Result<(), TestCaseError> {
    let mut st = vec![SetupTriangle::<N>::EMPTY; tris.len() * 7];
    let mut frame = Frame::<S, N>::with_subpixel_bits(config(w, h, le), &mut st).unwrap();
    for (i, (p, v)) in tris.iter().enumerate() {
        frame.submit_clip_triangle(*p, *v, i as u32).unwrap();
    }
    let whole = render(&frame, [0, w, 0, h], None);

    let mut offsets = vec![0u32; frame.tiles(tw, th) + 1];
    let need = frame.tile_bin_entries(tw, th);
    let mut items = vec![0u32; need];
    let bins = frame.bin_tiles(tw, th, &mut offsets, &mut items).unwrap();
    prop_assert_eq!(bins.tiles() as usize, frame.tiles(tw, th));
    // The same bins with the items given once their number is known: the
    // storage is asked for once, for exactly what `tile_bin_entries` says.
    {
        let mut offsets2 = vec![0u32; frame.tiles(tw, th) + 1];
        let (mut items2, mut asked) = (Vec::new(), Vec::new());
        let bins2 = frame
            .bin_tiles_with(tw, th, &mut offsets2, |need| {
                asked.push(need);
                items2.resize(need, u32::MAX);
                &mut items2[..]
            })
            .unwrap();
        prop_assert_eq!(bins2.tiles(), bins.tiles());
        for t in 0..bins.tiles() {
            prop_assert_eq!(bins2.strip_items(t), bins.strip_items(t));
        }
        prop_assert_eq!(asked, vec![need]);
    }
    let mut tiled = Images::blank((w * h) as usize);
    for t in 0..bins.tiles() {
        let r = bins.rect(t);
        tiled.paste(&render(&frame, r, Some((&bins, t))), r, w);
    }
    prop_assert!(
        tiled == whole,
        "tiles of {}x{} differ from the whole frame",
        tw,
        th
    );

    // One rectangle anywhere, drawn from all triangles (no bins).
    let [x0, x1, y0, y1] = rect;
    let r = [
        x0 % w,
        (x0 % w) + 1 + x1 % (w - x0 % w),
        y0 % h,
        (y0 % h) + 1 + y1 % (h - y0 % h),
    ];
    let one = render(&frame, r, None);
    let mut part = Images::blank((w * h) as usize);
    part.paste(&one, r, w);
    let inside = |i: usize| {
        let (x, y) = (i as u32 % w, i as u32 / w);
        (r[0]..r[1]).contains(&x) && (r[2]..r[3]).contains(&y)
    };
    for i in (0..(w * h) as usize).filter(|&i| inside(i)) {
        prop_assert_eq!(
            part.hashed32[i],
            whole.hashed32[i],
            "pixel {} of rect {:?}",
            i,
            r
        );
        prop_assert_eq!(part.z32[i], whole.z32[i]);
        prop_assert_eq!(part.hashed16[i], whole.hashed16[i]);
        prop_assert_eq!(part.z16[i], whole.z16[i]);
        prop_assert_eq!(part.ids16[i], whole.ids16[i]);
        prop_assert_eq!(part.ids[i], whole.ids[i]);
        prop_assert_eq!(part.rgb565[i], whole.rgb565[i]);
    }
    Ok(())
}

fn size() -> impl Strategy<Value = (u32, u32)> {
    (1u32..=96, 1u32..=72)
}

fn tile() -> impl Strategy<Value = (u32, u32)> {
    (
        prop_oneof![1u32..=40, Just(32), Just(16), Just(200)],
        1u32..=40,
    )
}

proptest! {
    #![proptest_config(ProptestConfig {
        cases: 256,
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    /// Colour varyings (`N = 3`: re-synchronised every 16 pixels, stepped
    /// in between): any tile size gives the whole frame, bit for bit.
    #[test]
    fn tiles_equal_the_whole_frame_colours(
        wh in size(),
        tris in tris::<3>(),
        le in any::<bool>(),
        s4 in any::<bool>(),
        t in tile(),
        rect in prop::array::uniform4(0u32..1000),
    ) {
        if s4 {
            check_tiles::<4, 3>(wh, &tris, le, t, rect)?;
        } else {
            check_tiles::<8, 3>(wh, &tris, le, t, rect)?;
        }
    }

    /// Five varyings (texture coordinates and more: re-synchronised at
    /// every pixel) and the same.
    #[test]
    fn tiles_equal_the_whole_frame_five_varyings(
        wh in size(),
        tris in tris::<5>(),
        le in any::<bool>(),
        s4 in any::<bool>(),
        t in tile(),
        rect in prop::array::uniform4(0u32..1000),
    ) {
        if s4 {
            check_tiles::<4, 5>(wh, &tris, le, t, rect)?;
        } else {
            check_tiles::<8, 5>(wh, &tris, le, t, rect)?;
        }
    }
}

/// A wide triangle across a 320x48 frame: spans of up to 320 pixels, cut
/// by tiles at every width from 1 to 70 and at the usual 32x32, 64x16.
#[test]
fn wide_spans_are_entered_where_the_row_enters_them() {
    let t: Tri<3> = (
        [
            Vec4::new(-1.0, -1.0, 0.1, 1.0),
            Vec4::new(3.0, -0.8, 0.9, 3.0),
            Vec4::new(-0.2, 0.9, -0.5, 0.7),
        ],
        [[0.1, 0.2, 0.3], [0.9, 0.5, 0.0], [0.3, 1.0, 0.6]],
    );
    let flat: Tri<3> = (
        [
            Vec4::new(-0.9, 0.9, 0.5, 1.0),
            Vec4::new(0.95, 0.7, -0.6, 1.0),
            Vec4::new(0.9, -0.95, 0.2, 1.0),
        ],
        [[0.5, 0.5, 0.5]; 3],
    );
    for tw in (1..=70).chain([32, 64, 160, 320]) {
        for th in [1, 7, 16, 32] {
            check_tiles::<8, 3>((320, 48), &[t, flat], false, (tw, th), [5, 200, 3, 9]).unwrap();
        }
    }
}

#[test]
fn bad_rectangles_and_tile_sizes_are_typed_errors() {
    let mut st = vec![SetupTriangle::<3>::EMPTY; 8];
    let mut frame: Frame = Frame::new(config(32, 16, false), &mut st).unwrap();
    frame
        .submit_clip_triangle(
            [
                Vec4::new(-1.0, -1.0, 0.0, 1.0),
                Vec4::new(1.0, -1.0, 0.0, 1.0),
                Vec4::new(0.0, 1.0, 0.0, 1.0),
            ],
            [Rgb888::new(200, 10, 10); 3],
            0,
        )
        .unwrap();
    let mut c = vec![Rgb888::new(0, 0, 0); 64];
    let err = |r: [u32; 4], c: &mut [Rgb888]| frame.render_rect(r, c, &mut NoDepth).unwrap_err();
    assert_eq!(
        err([4, 4, 0, 1], &mut c),
        Error::InvalidColumns {
            x0: 4,
            x1: 4,
            width: 32
        }
    );
    assert_eq!(
        err([30, 33, 0, 1], &mut c),
        Error::InvalidColumns {
            x0: 30,
            x1: 33,
            width: 32
        }
    );
    assert_eq!(
        err([0, 8, 9, 8], &mut c),
        Error::InvalidRows {
            y0: 9,
            y1: 8,
            height: 16
        }
    );
    // 8x8 is 64 pixels: 63 or 65 are size errors, and nothing is written.
    assert_eq!(
        err([0, 8, 0, 8], &mut c[..63]),
        Error::ColorBufferSize {
            expected: 64,
            actual: 63
        }
    );
    assert!(c.iter().all(|p| *p == Rgb888::new(0, 0, 0)));
    let mut z = [u16::MAX; 65];
    assert_eq!(
        frame
            .render_rect([0, 8, 0, 8], &mut c, &mut z[..])
            .unwrap_err(),
        Error::DepthBufferSize {
            expected: 64,
            actual: 65
        }
    );
    assert!(frame
        .render_rect([0, 8, 0, 8], &mut c, &mut z[..64])
        .is_ok());

    let (mut o, mut i) = (vec![0u32; 64], vec![0u32; 64]);
    assert_eq!(
        frame.bin_tiles(0, 8, &mut o, &mut i).unwrap_err(),
        Error::InvalidTileSize
    );
    assert_eq!(
        frame.bin_tiles(8, 0, &mut o, &mut i).unwrap_err(),
        Error::InvalidStripRows
    );
    // 5x3 tiles of 7x6: 15 tiles, 16 offsets.
    assert_eq!(frame.tiles(7, 6), 15);
    assert_eq!(
        frame.bin_tiles(7, 6, &mut o[..15], &mut i).unwrap_err(),
        Error::BinStorageSize {
            expected: 16,
            actual: 15
        }
    );
    let need = frame.tile_bin_entries(7, 6);
    assert!(need > 1);
    assert!(matches!(
        frame.bin_tiles(7, 6, &mut o, &mut i[..need - 1]),
        Err(Error::BinStorageSize { .. })
    ));
    // `bin_tiles_with` checks the tile size and the offsets before it asks
    // for items, and takes short items as the same error.
    let mut asked = 0;
    assert_eq!(
        frame
            .bin_tiles_with(0, 6, &mut o, |_| {
                asked += 1;
                &mut []
            })
            .unwrap_err(),
        Error::InvalidTileSize
    );
    assert_eq!(
        frame
            .bin_tiles_with(7, 6, &mut o[..15], |_| {
                asked += 1;
                &mut []
            })
            .unwrap_err(),
        Error::BinStorageSize {
            expected: 16,
            actual: 15
        }
    );
    assert_eq!(asked, 0, "items asked for before the checks");
    let mut short = vec![0u32; need - 1];
    assert_eq!(
        frame
            .bin_tiles_with(7, 6, &mut o, |n| {
                assert_eq!(n, need);
                &mut short[..]
            })
            .unwrap_err(),
        Error::BinStorageSize {
            expected: need,
            actual: need - 1
        }
    );
    // It counted the entries into the offsets on the way.
    assert_eq!(o[0], 0);
    assert_eq!(o[1..16].iter().sum::<u32>() as usize, need);
    let bins = frame.bin_tiles(7, 6, &mut o, &mut i).unwrap();
    assert_eq!(
        bins.rect(4),
        [28, 32, 0, 6],
        "right-hand tiles are narrower"
    );
    assert_eq!(bins.rect(14), [28, 32, 12, 16]);
    assert_eq!(bins.rect(15), [0, 0, 16, 16], "past the end: empty");
    // A tile's buffers hold its rectangle, not a full tile.
    let mut small = vec![Rgb888::new(0, 0, 0); 4 * 6];
    assert!(frame
        .render_tile(&bins, 4, &mut small, &mut NoDepth)
        .is_ok());
    assert_eq!(
        frame
            .render_tile(&bins, 0, &mut small, &mut NoDepth)
            .unwrap_err(),
        Error::ColorBufferSize {
            expected: 42,
            actual: 24
        }
    );
    assert_eq!(
        frame
            .render_tile(&bins, 15, &mut small, &mut NoDepth)
            .unwrap_err(),
        Error::InvalidRows {
            y0: 16,
            y1: 16,
            height: 16
        }
    );
}

/// Tiles as wide as the frame are strips: the same bins as `Frame::bin`,
/// and bins of one kind are refused for a frame that changed.
#[test]
fn full_width_tiles_are_strips() {
    let mut st = vec![SetupTriangle::<3>::EMPTY; 8];
    let mut frame: Frame = Frame::new(config(40, 30, false), &mut st).unwrap();
    let tri = [
        Vec4::new(-0.9, -0.9, 0.0, 1.0),
        Vec4::new(0.8, -0.7, 0.0, 1.0),
        Vec4::new(0.1, 0.9, 0.0, 1.0),
    ];
    frame
        .submit_clip_triangle(tri, [Rgb888::new(9, 9, 9); 3], 0)
        .unwrap();
    let (mut o1, mut i1) = (vec![0u32; 8], vec![0u32; 8]);
    let (mut o2, mut i2) = (vec![0u32; 8], vec![0u32; 8]);
    assert_eq!(frame.tile_bin_entries(40, 7), frame.bin_entries(7));
    assert_eq!(frame.tile_bin_entries(400, 7), frame.bin_entries(7));
    let a = frame.bin(7, &mut o1, &mut i1).unwrap();
    let b = frame.bin_tiles(400, 7, &mut o2, &mut i2).unwrap();
    assert_eq!(a.tiles(), b.tiles());
    for s in 0..a.tiles() {
        assert_eq!(a.rect(s), b.rect(s));
        assert_eq!(a.rows(s), b.rows(s));
        assert_eq!(a.strip_items(s), b.strip_items(s));
    }
    frame
        .submit_clip_triangle(tri, [Rgb888::new(9, 9, 9); 3], 1)
        .unwrap();
    let mut c = vec![Rgb888::new(0, 0, 0); 40 * 7];
    assert_eq!(
        frame.render_tile(&a, 0, &mut c, &mut NoDepth).unwrap_err(),
        Error::BinsMismatch
    );
}
