//! The clipless mode ([`RasterMode::Clipless`]): exact coverage against an
//! `i128` reference of the same quantization, the hard cases of
//! `RASTER_TEST_CASES.md` (§7 clipping, §9 near and far, w <= 0, slivers),
//! depth, strip invariance, and agreement with the clipping mode.
//!
//! The reference is written from the definition, independent of
//! `src/clipless.rs`: a pixel centre `p` (doubled window units) is covered
//! when Cramer's rule writes `p = sum l_k v_k / det` with every `l_k >= 0`
//! (a tie `l_k = 0` counts where `l_k` grows to the right, or downwards on
//! a horizontal edge: top-left), and the near and far distances `sum l_k
//! N_k`, `sum l_k F_k` are `>= 0`. Nothing is normalised, nothing is
//! stepped.

#![cfg(feature = "clipless")]

mod common;

use microraster::clipless::{determinant, quantize, HomVertex};
use microraster::pixelcolor::Rgb888;
use microraster::prelude::*;
use microraster::{
    Config, CullMode, DepthFunc, Error, Frame, NoDepth, RasterMode, SetupTriangle, StripRenderer,
    TriangleId, Vec4,
};
use proptest::prelude::*;

fn clipless(width: u32, height: u32, cull: CullMode) -> Config {
    let mut c = Config::new(width, height);
    c.cull = cull;
    c.mode = RasterMode::Clipless;
    c
}

/// The frame drawn in strips of `rows` rows, triangle ids (`index + 1`) per
/// pixel, no depth: the last triangle covering a pixel wins.
fn render(config: Config, tris: &[[Vec4; 3]], rows: u32) -> Vec<u32> {
    let (w, h) = (config.width, config.height);
    let mut out = Vec::with_capacity((w * h) as usize);
    let mut y0 = 0;
    while y0 < h {
        let y1 = (y0 + rows).min(h);
        let mut ids = vec![TriangleId(0); (w * (y1 - y0)) as usize];
        let mut none = NoDepth;
        let mut r = StripRenderer::new(config, y0, y1, &mut ids, &mut none).unwrap();
        for (i, t) in tris.iter().enumerate() {
            r.submit_clip_triangle(*t, [Rgb888::WHITE; 3], i as u32)
                .unwrap();
        }
        out.extend(ids.iter().map(|t| t.0));
        y0 = y1;
    }
    out
}

type V3 = [i128; 3];

fn det3(a: V3, b: V3, c: V3) -> i128 {
    a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0])
}

/// Whether the quantized triangle `h` covers the centre of pixel `(col,
/// row)` (see the file's note), culling as `cull` with CCW front faces, on
/// a frame whose larger side is `scale` (the centre is `(2 col + 1, 2 row +
/// 1, scale)` in the quantized vertices' coordinates).
fn reference_covers(h: &[HomVertex; 3], col: i64, row: i64, scale: i64, cull: CullMode) -> bool {
    let v = |k: usize| [h[k].x as i128, h[k].y as i128, h[k].w as i128];
    let d = det3(v(0), v(1), v(2));
    if d == 0 {
        return false;
    }
    // Window y down: counter-clockwise in NDC is a negative determinant.
    let front = d < 0;
    if (cull == CullMode::Back && !front) || (cull == CullMode::Front && front) {
        return false;
    }
    let sign = d.signum();
    // l_k(p) * sign: vertex k's column replaced by p.
    let weight = |k: usize, p: V3| {
        let mut m = [v(0), v(1), v(2)];
        m[k] = p;
        det3(m[0], m[1], m[2]) * sign
    };
    let p = [2 * col as i128 + 1, 2 * row as i128 + 1, scale as i128];
    let mut l = [0i128; 3];
    for (k, lk) in l.iter_mut().enumerate() {
        *lk = weight(k, p);
        if *lk < 0 {
            return false;
        }
        if *lk == 0 {
            let gx = weight(k, [p[0] + 2, p[1], p[2]]) - *lk;
            let gy = weight(k, [p[0], p[1] + 2, p[2]]) - *lk;
            if !(gx > 0 || (gx == 0 && gy > 0)) {
                return false;
            }
        }
    }
    let near: i128 = (0..3).map(|k| l[k] * h[k].near as i128).sum();
    let far: i128 = (0..3).map(|k| l[k] * h[k].far as i128).sum();
    near >= 0 && far >= 0
}

/// The reference frame: ids of the last covering triangle.
fn reference(config: Config, tris: &[[Vec4; 3]]) -> Vec<u32> {
    let (w, h) = (config.width, config.height);
    let q: Vec<[HomVertex; 3]> = tris.iter().map(|t| t.map(|p| quantize(p, w, h))).collect();
    let mut out = vec![0u32; (w * h) as usize];
    for row in 0..h as i64 {
        for col in 0..w as i64 {
            for (i, t) in q.iter().enumerate() {
                if reference_covers(t, col, row, w.max(h) as i64, config.cull) {
                    out[(row * w as i64 + col) as usize] = i as u32 + 1;
                }
            }
        }
    }
    out
}

fn assert_same(got: &[u32], want: &[u32], w: u32, what: &str) {
    let bad: Vec<(u32, u32, u32, u32)> = (0..got.len())
        .filter(|&i| got[i] != want[i])
        .map(|i| (i as u32 % w, i as u32 / w, got[i], want[i]))
        .collect();
    assert!(
        bad.is_empty(),
        "{what}: {} pixels differ from the reference, e.g. (x, y, got, want) {:?}",
        bad.len(),
        &bad[..bad.len().min(6)]
    );
}

fn check_exact(config: Config, tris: &[[Vec4; 3]], what: &str) -> usize {
    let want = reference(config, tris);
    for rows in [config.height, 1, 7] {
        let got = render(config, tris, rows);
        assert_same(
            &got,
            &want,
            config.width,
            &format!("{what}, strips of {rows}"),
        );
    }
    want.iter().filter(|&&i| i != 0).count()
}

fn v(x: f32, y: f32, z: f32, w: f32) -> Vec4 {
    Vec4::new(x, y, z, w)
}

// ---------------------------------------------------------------------------
// Hard cases, by name
// ---------------------------------------------------------------------------

/// RASTER_TEST_CASES.md: the triangle (-0.5,-0.5,0,1), (0.5,-0.5,0,1),
/// (0,-0.5,0,-1) on 64x64 with culling off covers the wedge below y =
/// -0.5, 640 pixels, in the clipping mode; the clipless mode draws the
/// same pixels without clipping.
#[test]
fn wedge_through_w_zero_covers_the_clipping_modes_640_pixels() {
    let tri = [
        v(-0.5, -0.5, 0.0, 1.0),
        v(0.5, -0.5, 0.0, 1.0),
        v(0.0, -0.5, 0.0, -1.0),
    ];
    let config = clipless(64, 64, CullMode::None);
    let n = check_exact(config, &[tri], "wedge");
    assert_eq!(n, 640);
    let clipped = common::render_ids::<8>(common::config_nocull(64, 64), &[tri]);
    let got = render(config, &[tri], 64);
    let same = (0..got.len()).all(|i| (got[i] != 0) == (clipped[i] != 0));
    assert!(same, "the wedge differs from the clipping mode's");
}

/// Every vertex behind the eye: nothing is in front of it.
#[test]
fn all_vertices_behind_the_eye_draw_nothing() {
    let tri = [
        v(-0.5, -0.5, 0.0, -1.0),
        v(0.5, -0.5, 0.0, -1.0),
        v(0.0, 0.5, 0.0, -1.0),
    ];
    for cull in [CullMode::None, CullMode::Back, CullMode::Front] {
        assert_eq!(check_exact(clipless(32, 32, cull), &[tri], "behind"), 0);
    }
}

/// Vertices at w = 0 exactly and at w a few ulps from 0, either side.
#[test]
fn vertices_at_and_near_w_zero() {
    let mut tris = vec![];
    for w in [0.0f32, 1e-30, -1e-30, 1e-7, -1e-7, f32::MIN_POSITIVE, 1e-40] {
        tris.push([
            v(-0.6, -0.5, 0.0, 1.0),
            v(0.7, -0.4, 0.0, 1.0),
            v(0.1, 0.3, 0.0, w),
        ]);
        tris.push([
            v(-0.6, -0.5, 0.2, 1.0),
            v(0.3 * w, 0.9 * w, 0.0, w),
            v(0.1, 0.3, 0.5, 2.0),
        ]);
    }
    for (i, t) in tris.iter().enumerate() {
        check_exact(
            clipless(48, 40, CullMode::None),
            &[*t],
            &format!("w ~ 0, case {i}"),
        );
    }
}

/// §7: vertices at 30,000 w and 100,000 along the axes and diagonals,
/// the others near the centre, each with its own w in [0.2, 16]; plus
/// huge w ratios (1e-6 against 1e6).
#[test]
fn far_vertices_and_huge_w_ratios() {
    let mut rng = common::SplitMix(77);
    let dirs: Vec<[f32; 3]> = (0..27)
        .map(|i| {
            [
                (i % 3) as f32 - 1.0,
                ((i / 3) % 3) as f32 - 1.0,
                (i / 9) as f32 - 1.0,
            ]
        })
        .filter(|d| d != &[0.0, 0.0, 0.0])
        .collect();
    let mut tris = vec![];
    for (i, d) in dirs.iter().enumerate() {
        let w = rng.range(0.2, 16.0) as f32;
        let s = if i % 2 == 0 { 30000.0 * w } else { 100_000.0 };
        let near = |rng: &mut common::SplitMix| {
            let w = rng.range(0.2, 16.0) as f32;
            let c = |rng: &mut common::SplitMix| rng.range(-0.5, 0.5) as f32 * w;
            v(c(rng), c(rng), c(rng), w)
        };
        tris.push([
            v(d[0] * s, d[1] * s, d[2] * s, w),
            near(&mut rng),
            near(&mut rng),
        ]);
    }
    for (a, b) in [(1e-6f32, 1e6f32), (1e6, 1e-6), (1e-20, 1e20)] {
        tris.push([
            v(-0.5 * a, -0.5 * a, 0.0, a),
            v(0.5 * b, -0.4 * b, 0.0, b),
            v(0.0, 0.6, 0.0, 1.0),
        ]);
    }
    for (i, t) in tris.iter().enumerate() {
        check_exact(
            clipless(40, 32, CullMode::None),
            &[*t],
            &format!("far case {i}"),
        );
    }
}

/// Slivers: long triangles a fraction of a pixel wide, at many angles.
#[test]
fn slivers() {
    let mut tris = vec![];
    for k in 0..24 {
        let a = k as f32 * 0.27;
        let (c, s) = (a.cos(), a.sin());
        let t = 0.004 * (k % 5 + 1) as f32;
        tris.push([
            v(-0.9 * c, -0.9 * s, 0.1, 1.0),
            v(0.9 * c, 0.9 * s, 0.1, 1.0),
            v(0.9 * c - t * s, 0.9 * s + t * c, 0.1, 1.0),
        ]);
    }
    let n = check_exact(clipless(64, 48, CullMode::None), &tris, "slivers");
    assert!(n > 0);
}

/// Zero area (collinear, repeated vertices) draws nothing.
#[test]
fn zero_area_draws_nothing() {
    let tris = [
        [
            v(-0.5, -0.5, 0.0, 1.0),
            v(0.5, 0.5, 0.0, 1.0),
            v(0.0, 0.0, 0.0, 1.0),
        ],
        [
            v(-0.5, -0.5, 0.0, 1.0),
            v(-0.5, -0.5, 0.0, 1.0),
            v(0.4, 0.1, 0.0, 1.0),
        ],
        // The same point twice, at different w.
        [
            v(-0.5, -0.5, 0.0, 1.0),
            v(-1.0, -1.0, 0.0, 2.0),
            v(0.4, 0.1, 0.0, 1.0),
        ],
    ];
    assert_eq!(
        check_exact(clipless(32, 32, CullMode::None), &tris, "zero area"),
        0
    );
}

/// §9: primitives on the near and far planes and between are drawn, those
/// beyond are not; triangles crossing a plane are cut exactly there (the
/// reference decides, per pixel), at the same pixel count as the clipping
/// mode where the cut passes no pixel centre closely.
#[test]
fn near_and_far_planes() {
    let quad = |z: f32| {
        [
            [
                v(-0.8, -0.8, z, 1.0),
                v(0.8, -0.8, z, 1.0),
                v(0.8, 0.8, z, 1.0),
            ],
            [
                v(-0.8, -0.8, z, 1.0),
                v(0.8, 0.8, z, 1.0),
                v(-0.8, 0.8, z, 1.0),
            ],
        ]
    };
    let config = clipless(40, 40, CullMode::None);
    let inside = check_exact(config, &quad(-1.0), "z = -1");
    assert_eq!(inside, 32 * 32);
    assert_eq!(check_exact(config, &quad(0.0), "z = 0"), 32 * 32);
    assert_eq!(check_exact(config, &quad(1.0), "z = 1"), 32 * 32);
    assert_eq!(check_exact(config, &quad(-1.5), "z = -1.5"), 0);
    assert_eq!(check_exact(config, &quad(1.5), "z = 1.5"), 0);
    // Tilted through the near plane (z from -2 to 0 across x), and through
    // the far plane: half the columns survive.
    for (z0, z1) in [(-2.03f32, 0.0f32), (0.0, 2.03)] {
        let tris = [
            [
                v(-0.8, -0.8, z0, 1.0),
                v(0.8, -0.8, z1, 1.0),
                v(0.8, 0.8, z1, 1.0),
            ],
            [
                v(-0.8, -0.8, z0, 1.0),
                v(0.8, 0.8, z1, 1.0),
                v(-0.8, 0.8, z0, 1.0),
            ],
        ];
        let n = check_exact(config, &tris, "crossing");
        let clipped = common::render_ids::<8>(common::config_nocull(40, 40), &tris);
        let m = clipped.iter().filter(|&&i| i != 0).count();
        assert_eq!(n, m, "crossing {z0}..{z1}: clipless {n}, clipping {m}");
        assert_eq!(n, 32 * 16);
    }
}

/// Back faces are culled by the determinant's sign, for triangles through
/// w = 0 too: the wedge is front-facing exactly when its visible part is.
#[test]
fn culling_by_the_determinant() {
    let ccw = [
        v(-0.5, -0.5, 0.0, 1.0),
        v(0.5, -0.5, 0.0, 1.0),
        v(0.0, 0.5, 0.0, 1.0),
    ];
    let cw = [ccw[0], ccw[2], ccw[1]];
    let wedge = [
        v(-0.5, -0.5, 0.0, 1.0),
        v(0.5, -0.5, 0.0, 1.0),
        v(0.0, -0.5, 0.0, -1.0),
    ];
    let wedge_cw = [wedge[0], wedge[2], wedge[1]];
    for t in [ccw, cw, wedge, wedge_cw] {
        let back = check_exact(clipless(32, 32, CullMode::Back), &[t], "back");
        let front = check_exact(clipless(32, 32, CullMode::Front), &[t], "front");
        let none = check_exact(clipless(32, 32, CullMode::None), &[t], "none");
        assert!(none > 0 && back.min(front) == 0 && back.max(front) == none);
        // The clipping mode culls the same triangles.
        let mut c = common::config_nocull(32, 32);
        c.cull = CullMode::Back;
        let clipped = common::render_ids::<8>(c, &[t])
            .iter()
            .filter(|&&i| i != 0)
            .count();
        assert_eq!(back == 0, clipped == 0);
    }
}

/// A frame stores snapped triangles only: it refuses the clipless mode.
#[test]
fn frame_refuses_the_clipless_mode() {
    let mut storage = [SetupTriangle::EMPTY; 4];
    let r = Frame::new(clipless(8, 8, CullMode::Back), &mut storage);
    assert_eq!(r.err(), Some(Error::ModeUnsupported));
}

/// Depth is the floor of the exact `N(p) / (2 D det)` in `Z32`, or one off
/// (stepping error where the value lies that close to an integer), on
/// triangles crossing the near plane and behind-the-eye wedges too.
#[test]
fn depth_within_one_lsb_of_the_exact_plane() {
    let mut rng = common::SplitMix(5);
    let (w, h) = (48u32, 40u32);
    for case in 0..200 {
        let mut c = || rng.range(-1.6, 1.6) as f32;
        let tri = [
            v(c(), c(), c(), 1.0),
            v(c(), c(), c(), 1.0 + c().abs()),
            v(c(), c(), c(), if case % 4 == 0 { -0.5 } else { 0.7 }),
        ];
        let mut config = clipless(w, h, CullMode::None);
        config.depth_func = DepthFunc::Always;
        let mut ids = vec![TriangleId(0); (w * h) as usize];
        let mut depth = vec![0u32; (w * h) as usize];
        StripRenderer::new(config, 0, h, &mut ids, &mut depth[..])
            .unwrap()
            .submit_clip_triangle(tri, [Rgb888::WHITE; 3], 0)
            .unwrap();
        let q = tri.map(|p| quantize(p, w, h));
        let d = determinant(&q);
        for row in 0..h as i64 {
            for col in 0..w as i64 {
                let i = (row * w as i64 + col) as usize;
                assert_eq!(
                    ids[i].0 != 0,
                    reference_covers(&q, col, row, w.max(h) as i64, CullMode::None),
                    "case {case} ({col}, {row})"
                );
                if ids[i].0 == 0 {
                    continue;
                }
                // N(p) by Cramer's rule, then Z32 = N 2^31 / det, in f64
                // from exact integers (|error| far below 1 LSB).
                let dd = w.max(h) as i128;
                let p = [2 * col as i128 + 1, 2 * row as i128 + 1, dd];
                let vk = |k: usize| [q[k].x as i128, q[k].y as i128, q[k].w as i128];
                let n: i128 = (0..3)
                    .map(|k| {
                        let mut m = [vk(0), vk(1), vk(2)];
                        m[k] = p;
                        det3(m[0], m[1], m[2]) * q[k].near as i128
                    })
                    .sum();
                let exact = n as f64 / (d * dd) as f64 * 2_147_483_648.0;
                let got = depth[i] as f64;
                assert!(
                    (got - exact.clamp(0.0, 4_294_967_295.0).floor()).abs() <= 1.0,
                    "case {case} ({col}, {row}): depth {got}, exact {exact}"
                );
            }
        }
    }
}

/// Colour interpolation is perspective-correct: a triangle drawn with two
/// vertices' w scaled (the same points) shades the same as without, and
/// the clipless and clipping modes agree within one step per channel.
#[test]
fn varyings_are_perspective_correct() {
    let (w, h) = (48u32, 40u32);
    let base = [
        v(-0.8, -0.7, 0.1, 1.0),
        v(0.9, -0.6, 0.2, 1.0),
        v(0.1, 0.8, 0.3, 1.0),
    ];
    let colors = [
        Rgb888::new(255, 0, 0),
        Rgb888::new(0, 255, 0),
        Rgb888::new(0, 0, 255),
    ];
    let draw = |tri: [Vec4; 3], mode: RasterMode| {
        let mut c = Config::new(w, h);
        c.cull = CullMode::None;
        c.mode = mode;
        let mut px = vec![Rgb888::BLACK; (w * h) as usize];
        let mut none = NoDepth;
        StripRenderer::new(c, 0, h, &mut px, &mut none)
            .unwrap()
            .submit_clip_triangle(tri, colors, 0)
            .unwrap();
        px
    };
    let scale = |p: Vec4, s: f32| v(p.x * s, p.y * s, p.z * s, p.w * s);
    let scaled = [scale(base[0], 4.0), base[1], scale(base[2], 0.25)];
    let a = draw(scaled, RasterMode::Clipless);
    let b = draw(scaled, RasterMode::Clipping);
    let mut worst = 0;
    let mut covered = 0;
    for i in 0..a.len() {
        if a[i] == Rgb888::BLACK || b[i] == Rgb888::BLACK {
            continue;
        }
        covered += 1;
        let d = |x: u8, y: u8| (x as i32 - y as i32).abs();
        worst = worst
            .max(d(a[i].r(), b[i].r()))
            .max(d(a[i].g(), b[i].g()))
            .max(d(a[i].b(), b[i].b()));
    }
    assert!(covered > 400);
    assert!(
        worst <= 1,
        "clipless and clipping colours differ by {worst}"
    );
}

/// The same scene in strips of any height: the same frame (colours and
/// depth), with Gouraud colours and a u16 depth buffer.
#[test]
fn any_strip_height_gives_the_same_frame() {
    let mut rng = common::SplitMix(9);
    let (w, h) = (50u32, 37u32);
    let mut tris = vec![];
    for k in 0..40 {
        let mut c = || rng.range(-1.4, 1.4) as f32;
        let ww = if k % 7 == 0 { -0.3 } else { 1.0 };
        tris.push([
            v(c(), c(), c() * 0.9, 1.0),
            v(c(), c(), c() * 0.9, 1.3),
            v(c(), c(), c(), ww),
        ]);
    }
    let colors = [
        Rgb888::new(250, 10, 10),
        Rgb888::new(10, 250, 10),
        Rgb888::new(10, 10, 250),
    ];
    let draw = |rows: u32| {
        let config = clipless(w, h, CullMode::None);
        let mut px = vec![];
        let mut dz = vec![];
        let mut y0 = 0;
        while y0 < h {
            let y1 = (y0 + rows).min(h);
            let n = (w * (y1 - y0)) as usize;
            let (mut p, mut d) = (vec![Rgb888::BLACK; n], vec![u16::MAX; n]);
            let mut r = StripRenderer::new(config, y0, y1, &mut p, &mut d[..]).unwrap();
            for (i, t) in tris.iter().enumerate() {
                let col = if i % 3 == 0 { [colors[0]; 3] } else { colors };
                r.submit_clip_triangle(*t, col, i as u32).unwrap();
            }
            px.extend(p);
            dz.extend(d);
            y0 = y1;
        }
        (px, dz)
    };
    let whole = draw(h);
    assert!(whole.0.iter().filter(|&&p| p != Rgb888::BLACK).count() > 500);
    for rows in [1, 2, 5, 16] {
        assert!(draw(rows) == whole, "strips of {rows} rows differ");
    }
}

/// Tiles ([`StripRenderer::with_rect`]) of any size give the frame of
/// strips, colours and depth, in both modes.
#[test]
fn any_tile_size_gives_the_same_frame() {
    let mut rng = common::SplitMix(19);
    let (w, h) = (45u32, 34u32);
    let mut tris = vec![];
    for k in 0..30 {
        let mut c = || rng.range(-1.4, 1.4) as f32;
        let ww = if k % 6 == 0 { -0.4 } else { 1.0 };
        tris.push([
            v(c(), c(), c() * 0.9, 1.0),
            v(c(), c(), c() * 0.9, 1.2),
            v(c(), c(), c(), ww),
        ]);
    }
    let colors = [
        Rgb888::new(250, 10, 10),
        Rgb888::new(10, 250, 10),
        Rgb888::new(10, 10, 250),
    ];
    for mode in [RasterMode::Clipping, RasterMode::Clipless] {
        let mut config = Config::new(w, h);
        config.cull = CullMode::None;
        config.mode = mode;
        let draw = |tw: u32, th: u32| {
            let mut px = vec![Rgb888::BLACK; (w * h) as usize];
            let mut dz = vec![u32::MAX; (w * h) as usize];
            for ty in (0..h).step_by(th as usize) {
                for tx in (0..w).step_by(tw as usize) {
                    let (x1, y1) = ((tx + tw).min(w), (ty + th).min(h));
                    let n = ((x1 - tx) * (y1 - ty)) as usize;
                    let (mut p, mut d) = (vec![Rgb888::BLACK; n], vec![u32::MAX; n]);
                    let mut r = StripRenderer::<_, _, 8>::with_rect(
                        config,
                        [tx, x1, ty, y1],
                        &mut p,
                        &mut d[..],
                    )
                    .unwrap();
                    for (i, t) in tris.iter().enumerate() {
                        let col = if i % 3 == 0 { [colors[1]; 3] } else { colors };
                        r.submit_clip_triangle(*t, col, i as u32).unwrap();
                    }
                    for (k, (pp, dd)) in p.iter().zip(&d).enumerate() {
                        let (x, y) = (tx + k as u32 % (x1 - tx), ty + k as u32 / (x1 - tx));
                        px[(y * w + x) as usize] = *pp;
                        dz[(y * w + x) as usize] = *dd;
                    }
                }
            }
            (px, dz)
        };
        let strips = draw(w, h);
        assert!(strips.0.iter().filter(|&&p| p != Rgb888::BLACK).count() > 400);
        for (tw, th) in [(1, 1), (7, 5), (16, 16), (32, 8), (45, 3)] {
            assert!(
                draw(tw, th) == strips,
                "{mode:?}: tiles of {tw}x{th} differ"
            );
        }
    }
}

/// On a scene wholly in front of the eye the two modes differ only where
/// their quantizations do: pixel centres within a hair of an edge.
#[test]
fn clipless_and_clipping_agree_away_from_edges() {
    let mut rng = common::SplitMix(3);
    let (w, h) = (64u32, 64u32);
    let mut differ = 0;
    let mut covered = 0;
    for _ in 0..100 {
        let mut c = || rng.range(-1.2, 1.2) as f32;
        let tri = [
            v(c(), c(), 0.1, 1.0),
            v(c(), c(), 0.2, 1.5),
            v(c(), c(), 0.3, 0.8),
        ];
        let a = render(clipless(w, h, CullMode::None), &[tri], h);
        let b = common::render_ids::<8>(common::config_nocull(w, h), &[tri]);
        differ += (0..a.len()).filter(|&i| (a[i] != 0) != (b[i] != 0)).count();
        covered += b.iter().filter(|&&i| i != 0).count();
    }
    assert!(covered > 10_000);
    // A pixel centre closer to an edge than the two quantizations' error
    // (2^-9 px snapping, 2^-21 relative here) is the only way to differ.
    assert!(
        differ * 1000 < covered,
        "{differ} of {covered} pixels differ"
    );
}

// ---------------------------------------------------------------------------
// The property: exact coverage for random triangles, any strip split
// ---------------------------------------------------------------------------

fn coord() -> impl Strategy<Value = f32> {
    prop_oneof![
        4 => -1.5f32..1.5,
        1 => -40.0f32..40.0,
        1 => (-8i32..=8).prop_map(|k| k as f32 * 0.125),
    ]
}

fn vertex() -> impl Strategy<Value = Vec4> {
    (
        coord(),
        coord(),
        coord(),
        prop_oneof![
            4 => 0.3f32..3.0,
            1 => -2.0f32..0.05,
            1 => Just(0.0f32),
            1 => 1e-4f32..1e4,
        ],
    )
        .prop_map(|(x, y, z, w)| {
            // Mostly inside the clip volume (x, y, z scaled by w), some not.
            Vec4::new(
                x * w.abs().max(0.1),
                y * w.abs().max(0.1),
                z * w.abs().max(0.1),
                w,
            )
        })
}

/// Vertices on the half-pixel grid of a 32-pixel frame (NDC `k/32`), at
/// `w` a power of two: edges run through pixel centres, so the top-left
/// rule decides many pixels.
fn grid_vertex() -> impl Strategy<Value = Vec4> {
    (
        -40i32..=40,
        -40i32..=40,
        prop_oneof![Just(1.0f32), Just(2.0), Just(0.5), Just(-1.0)],
    )
        .prop_map(|(x, y, w)| Vec4::new(x as f32 / 32.0 * w, y as f32 / 32.0 * w, 0.0, w))
}

proptest! {
    #![proptest_config(ProptestConfig {
        failure_persistence: None,
        ..ProptestConfig::default()
    })]

    #[test]
    fn coverage_matches_the_i128_reference(
        tris in prop::collection::vec([vertex(), vertex(), vertex()], 1..5),
        width in 1u32..40,
        height in 1u32..40,
        cull in prop_oneof![Just(CullMode::None), Just(CullMode::Back), Just(CullMode::Front)],
        rows in 1u32..9,
    ) {
        let config = clipless(width, height, cull);
        let want = reference(config, &tris);
        let got = render(config, &tris, rows);
        prop_assert_eq!(got, want);
    }

    #[test]
    fn coverage_matches_the_reference_on_pixel_centres(
        tris in prop::collection::vec([grid_vertex(), grid_vertex(), grid_vertex()], 1..6),
        cull in prop_oneof![Just(CullMode::None), Just(CullMode::Back)],
        rows in 1u32..9,
    ) {
        let config = clipless(32, 32, cull);
        let want = reference(config, &tris);
        let got = render(config, &tris, rows);
        prop_assert_eq!(got, want);
    }
}

/// Two triangles sharing edges through pixel centres (horizontal,
/// vertical, diagonal) cover every pixel of their union exactly once: the
/// top-left rule, exactly, in both windings.
#[test]
fn shared_edges_through_pixel_centres_draw_each_pixel_once() {
    let config = clipless(32, 32, CullMode::None);
    // Corners on pixel centres of a 32x32 frame: NDC (2i + 1) / 32 - 1.
    let c = |i: i32| (2 * i + 1) as f32 / 32.0 - 1.0;
    for (a, b) in [
        ((3, 5), (20, 5)),
        ((7, 2), (7, 25)),
        ((4, 4), (24, 24)),
        ((2, 28), (29, 3)),
    ] {
        let (p, q) = (v(c(a.0), -c(a.1), 0.0, 1.0), v(c(b.0), -c(b.1), 0.0, 1.0));
        for (l, r) in [
            (v(c(1), -c(30), 0.0, 1.0), v(c(30), -c(1), 0.0, 1.0)),
            (v(c(30), -c(30), 0.0, 2.0), v(c(0), -c(0), 0.0, 1.0)),
        ] {
            let tris = [[p, q, l], [q, p, r]];
            check_exact(config, &tris, "shared edge");
            let single: Vec<Vec<u32>> = tris.iter().map(|t| render(config, &[*t], 32)).collect();
            let twice = (0..32 * 32)
                .filter(|&i| single[0][i] != 0 && single[1][i] != 0)
                .count();
            assert_eq!(twice, 0, "edge {a:?}-{b:?}: pixels drawn by both");
        }
    }
}
