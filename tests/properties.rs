//! Property tests (proptest). Case counts default to at least 256 per
//! property and follow `PROPTEST_CASES` when it is set.
//!
//! - Coverage equals the exact reference rasterizer for random triangles on
//!   the subpixel grid and off it, at S = 4 and 8, both windings, slivers,
//!   tiny and huge (guard-band) triangles; with culling, exactly the right
//!   windings are drawn.
//! - Any split into strips renders the identical frame (colour, ids, u16
//!   and u32 depth), bit for bit.
//! - Closed fans cover every pixel strictly inside once and nothing twice.
//! - Moving a scene by whole pixels moves its images and nothing else.
//! - `Stats`: every submitted triangle is stored or counted exactly once.

mod common;

use common::*;
use microraster::clip::outcode;
use microraster::fixed::guard_band_ndc;
use microraster::pixelcolor::Rgb888;
use microraster::prelude::*;
use microraster::{
    BoundingSphere, ClipVertex, Config, CullMode, DepthFunc, Error, Frame, FrontFace, Mat4, Mesh,
    MeshColors, NoDepth, ProcessedVertex, Stats, StripRenderer, TriangleId, Vec3, Vec4,
};
use proptest::prelude::*;

// ---------------------------------------------------------------------------
// Strategies
// ---------------------------------------------------------------------------

/// Power-of-two frame sizes 1..=64 (exact window-to-clip conversion).
fn pow2_size() -> impl Strategy<Value = (u32, u32)> {
    (0u32..=6, 0u32..=6).prop_map(|(a, b)| (1 << a, 1 << b))
}

/// A triangle with vertices on the `Sub<s>` grid of a `w x h` frame, of a
/// random kind: general, small, tiny, sliver, on the half-pixel lattice
/// (many centres exactly on edges), axis-aligned edges, or huge (far
/// off-screen, up to 2^20 units).
fn grid_tri(s: u32, w: u32, h: u32) -> BoxedStrategy<[SubPt; 3]> {
    let one = 1i64 << s;
    let (fw, fh) = ((w as i64) << s, (h as i64) << s);
    let m = 3 * one;
    let pt = move || (-m..fw + m, -m..fh + m);
    let general = (pt(), pt(), pt()).prop_map(|(a, b, c)| [a, b, c]);
    let small = (
        pt(),
        (-3 * one..=3 * one, -3 * one..=3 * one),
        (-3 * one..=3 * one, -3 * one..=3 * one),
    )
        .prop_map(|(a, d1, d2)| [a, (a.0 + d1.0, a.1 + d1.1), (a.0 + d2.0, a.1 + d2.1)]);
    let tiny = (pt(), (-one..=one, -one..=one), (-one..=one, -one..=one))
        .prop_map(|(a, d1, d2)| [a, (a.0 + d1.0, a.1 + d1.1), (a.0 + d2.0, a.1 + d2.1)]);
    let sliver = (pt(), pt(), -8i64..=24, (-3i64..=3, -3i64..=3)).prop_map(|(a, b, t, d)| {
        let c = (
            a.0 + (b.0 - a.0) * t / 16 + d.0,
            a.1 + (b.1 - a.1) * t / 16 + d.1,
        );
        [a, b, c]
    });
    let half = one / 2;
    let hw = 2 * w as i64 + 6;
    let hh = 2 * h as i64 + 6;
    let lattice = ((-3..hw, -3..hh), (-3..hw, -3..hh), (-3..hw, -3..hh))
        .prop_map(move |(a, b, c)| [a, b, c].map(|p| (p.0 * half, p.1 * half)));
    let axis = (pt(), pt(), any::<bool>()).prop_map(|(a, b, vertical)| {
        let c = if vertical { (a.0, b.1) } else { (b.0, a.1) };
        [a, b, c]
    });
    let big = 1i64 << 20;
    let huge =
        ((-big..big, -big..big), (-big..big, -big..big), pt()).prop_map(|(a, b, c)| [a, b, c]);
    prop_oneof![
        3 => general,
        2 => small,
        1 => tiny,
        2 => sliver,
        2 => lattice,
        1 => axis,
        1 => huge,
    ]
    .boxed()
}

/// Clip-space vertices (w = 1) that snap exactly to the grid points `v`.
fn grid_to_clip(v: [SubPt; 3], s: u32, w: u32, h: u32) -> [Vec4; 3] {
    let u = (1u64 << s) as f64;
    v.map(|(x, y)| wv(x as f64 / u, y as f64 / u, w, h))
}

/// Off-grid clip-space triangles: NDC positions (within 0.9 of the guard
/// band, so the core does not clip) times a random w per vertex, z inside
/// [-w, w]. Kinds: in and around the frame, small, sliver, huge.
fn clip_tri(gx: f32, gy: f32) -> BoxedStrategy<[Vec4; 3]> {
    let wv = || prop_oneof![Just(1.0f32), 0.1f32..8.0];
    let vtx = move |r: f32| {
        let (lx, ly) = (r.min(gx * 0.9), r.min(gy * 0.9));
        (-lx..=lx, -ly..=ly, -1.0f32..=1.0, wv())
            .prop_map(|(x, y, z, w)| Vec4::new(x * w, y * w, z * w, w))
    };
    let near = (vtx(1.3), vtx(1.3), vtx(1.3)).prop_map(|(a, b, c)| [a, b, c]);
    let huge = (vtx(1.0e6), vtx(1.0e6), vtx(1.3)).prop_map(|(a, b, c)| [a, b, c]);
    let small = (
        vtx(1.1),
        (-0.1f32..0.1, -0.1f32..0.1),
        (-0.1f32..0.1, -0.1f32..0.1),
    )
        .prop_map(|(a, d1, d2)| {
            let p = |d: (f32, f32)| Vec4::new(a.x + d.0 * a.w, a.y + d.1 * a.w, a.z, a.w);
            [a, p(d1), p(d2)]
        });
    let sliver = (vtx(1.3), vtx(1.3), -0.5f32..1.5, -1e-3f32..1e-3).prop_map(|(a, b, t, e)| {
        let (ax, ay) = (a.x / a.w, a.y / a.w);
        let (bx, by) = (b.x / b.w, b.y / b.w);
        let c = Vec4::new(ax + (bx - ax) * t + e, ay + (by - ay) * t - e, 0.0, 1.0);
        [a, b, c]
    });
    prop_oneof![3 => near, 1 => huge, 2 => small, 2 => sliver].boxed()
}

/// Per-vertex colours.
fn colors() -> impl Strategy<Value = [Rgb888; 3]> {
    prop::array::uniform3(
        (any::<u8>(), any::<u8>(), any::<u8>()).prop_map(|(r, g, b)| Rgb888::new(r, g, b)),
    )
}

// ---------------------------------------------------------------------------
// Coverage vs the reference
// ---------------------------------------------------------------------------

fn check_coverage<const S: u32>(config: Config, pos: [Vec4; 3]) -> Result<(), TestCaseError> {
    let (w, h) = (config.width, config.height);
    let expected = match snap_tri::<S>(&pos, w, h) {
        Some(v) => reference_coverage(v, S, w, h),
        None => vec![false; (w * h) as usize],
    };
    for order in [pos, [pos[0], pos[2], pos[1]]] {
        let got = coverage::<S>(config, order);
        if got != expected {
            let diff: Vec<usize> = (0..got.len()).filter(|&k| got[k] != expected[k]).collect();
            return Err(TestCaseError::fail(format!(
                "S={S} {w}x{h} {order:?}: {} pixels differ, first at ({}, {}) (core {}, reference {}); snapped {:?}",
                diff.len(),
                diff[0] as u32 % w,
                diff[0] as u32 / w,
                got[diff[0]],
                expected[diff[0]],
                snap_tri::<S>(&order, w, h)
            )));
        }
    }
    Ok(())
}

fn grid_case(s: u32) -> impl Strategy<Value = (u32, u32, [SubPt; 3])> {
    pow2_size().prop_flat_map(move |(w, h)| (Just(w), Just(h), grid_tri(s, w, h)))
}

fn clip_case<const S: u32>() -> impl Strategy<Value = (u32, u32, [Vec4; 3])> {
    (1u32..=40, 1u32..=40).prop_flat_map(|(w, h)| {
        let (gx, gy) = guard_band_ndc::<S>(w, h);
        (Just(w), Just(h), clip_tri(gx, gy))
    })
}

proptest! {
    #![proptest_config(cases(2048))]

    /// Vertices on the 1/256 grid: coverage equals the reference exactly,
    /// drawn alone and through `u16` and `u32` depth buffers (the `u16`
    /// one by the batched flat rows, `flat_rows_in_range`).
    #[test]
    fn coverage_matches_reference_on_grid_s8((w, h, v) in grid_case(8)) {
        let pos = grid_to_clip(v, 8, w, h);
        prop_assert_eq!(snap_tri::<8>(&pos, w, h), Some(v), "construction must be exact");
        check_coverage::<8>(config_nocull(w, h), pos)?;
        check_depth_coverage::<8>(config_nocull(w, h), pos)?;
    }

    /// Vertices on the 1/16 grid: coverage equals the reference exactly.
    #[test]
    fn coverage_matches_reference_on_grid_s4((w, h, v) in grid_case(4)) {
        let pos = grid_to_clip(v, 4, w, h);
        prop_assert_eq!(snap_tri::<4>(&pos, w, h), Some(v), "construction must be exact");
        check_coverage::<4>(config_nocull(w, h), pos)?;
        check_depth_coverage::<4>(config_nocull(w, h), pos)?;
    }

    /// Random f32 clip coordinates (any w > 0, no clipping needed): the
    /// core's coverage equals the reference run on `fixed::snap`'s output.
    #[test]
    fn coverage_matches_reference_off_grid_s8((w, h, pos) in clip_case::<8>()) {
        check_coverage::<8>(config_nocull(w, h), pos)?;
        check_depth_coverage::<8>(config_nocull(w, h), pos)?;
    }

    /// As above at 4 subpixel bits.
    #[test]
    fn coverage_matches_reference_off_grid_s4((w, h, pos) in clip_case::<4>()) {
        check_coverage::<4>(config_nocull(w, h), pos)?;
        check_depth_coverage::<4>(config_nocull(w, h), pos)?;
    }

    /// With culling, a triangle is drawn (exactly as the reference) iff its
    /// winding survives; counter-clockwise in NDC means clockwise in
    /// window space (y down).
    #[test]
    fn culling_keeps_exactly_the_right_windings(
        (w, h, v) in grid_case(8),
        cull in prop_oneof![Just(CullMode::Back), Just(CullMode::Front), Just(CullMode::None)],
        front in prop_oneof![Just(FrontFace::Ccw), Just(FrontFace::Cw)],
    ) {
        let pos = grid_to_clip(v, 8, w, h);
        let mut cfg = Config::new(w, h);
        cfg.cull = cull;
        cfg.front_face = front;
        let area = orient(v[0], v[1], v[2]);
        let ccw_ndc = area < 0;
        let is_front = (front == FrontFace::Ccw) == ccw_ndc;
        let drawn = match cull {
            CullMode::None => true,
            CullMode::Back => is_front,
            CullMode::Front => !is_front,
        };
        let expected = if drawn {
            reference_coverage(v, 8, w, h)
        } else {
            vec![false; (w * h) as usize]
        };
        prop_assert_eq!(coverage::<8>(cfg, pos), expected);
    }
}

// ---------------------------------------------------------------------------
// Strip invariance
// ---------------------------------------------------------------------------

/// A scene: clip-space triangles (some crossing the near/far planes or the
/// frame edges) with Gouraud colours.
/// A frame size and its coloured triangles.
type Scene = (u32, u32, Vec<([Vec4; 3], [Rgb888; 3])>);

fn scene() -> impl Strategy<Value = Scene> {
    let v = || {
        (-1.6f32..1.6, -1.6f32..1.6, -1.4f32..1.4, 0.2f32..4.0)
            .prop_map(|(x, y, z, w)| Vec4::new(x * w, y * w, z * w, w))
    };
    let tri = ((v(), v(), v()).prop_map(|(a, b, c)| [a, b, c]), colors());
    (1u32..=40, 1u32..=40, prop::collection::vec(tri, 1..8))
}

struct Images {
    color: Vec<Rgb888>,
    z32: Vec<u32>,
    color16: Vec<Rgb888>,
    z16: Vec<u16>,
    ids: Vec<u32>,
    written: [u64; 3],
}

/// Renders the frame through the strips `cuts` (row boundaries, sorted,
/// 0 and height included), each into fresh buffers.
fn render_strips<const S: u32>(frame: &Frame<'_, S>, cuts: &[u32]) -> Images {
    let w = frame.config().width as usize;
    let mut im = Images {
        color: vec![],
        z32: vec![],
        color16: vec![],
        z16: vec![],
        ids: vec![],
        written: [0; 3],
    };
    for pair in cuts.windows(2) {
        let (y0, y1) = (pair[0], pair[1]);
        let n = w * (y1 - y0) as usize;
        let mut c = vec![Rgb888::new(1, 2, 3); n];
        let mut z = vec![u32::MAX; n];
        im.written[0] += frame
            .render_rows(y0, y1, &mut c[..], &mut z[..])
            .unwrap()
            .pixels_written;
        im.color.extend(c);
        im.z32.extend(z);
        let mut c = vec![Rgb888::new(1, 2, 3); n];
        let mut z = vec![u16::MAX; n];
        im.written[1] += frame
            .render_rows(y0, y1, &mut c[..], &mut z[..])
            .unwrap()
            .pixels_written;
        im.color16.extend(c);
        im.z16.extend(z);
        let mut ids = vec![TriangleId(0); n];
        im.written[2] += frame
            .render_rows(y0, y1, &mut ids[..], &mut NoDepth)
            .unwrap()
            .pixels_written;
        im.ids.extend(ids.into_iter().map(|t| t.0));
    }
    im
}

fn check_strips<const S: u32>(
    w: u32,
    h: u32,
    tris: &[([Vec4; 3], [Rgb888; 3])],
    func: DepthFunc,
    cuts: &[u32],
) -> Result<(), TestCaseError> {
    let mut cfg = config_nocull(w, h);
    cfg.depth_func = func;
    let mut st = storage(tris.len());
    let mut frame = Frame::<S>::with_subpixel_bits(cfg, &mut st).unwrap();
    for (i, (p, c)) in tris.iter().enumerate() {
        frame.submit_clip_triangle(*p, *c, i as u32).unwrap();
    }
    let whole = render_strips(&frame, &[0, h]);
    let mut all = vec![0];
    all.extend(cuts.iter().copied().filter(|&c| c > 0 && c < h));
    all.push(h);
    all.sort_unstable();
    all.dedup();
    let split = render_strips(&frame, &all);
    prop_assert!(
        whole.color == split.color,
        "Rgb888 colour differs for cuts {:?}",
        all
    );
    prop_assert!(
        whole.z32 == split.z32,
        "u32 depth differs for cuts {:?}",
        all
    );
    prop_assert!(
        whole.color16 == split.color16,
        "colour (u16 depth) differs for cuts {:?}",
        all
    );
    prop_assert!(
        whole.z16 == split.z16,
        "u16 depth differs for cuts {:?}",
        all
    );
    prop_assert!(whole.ids == split.ids, "ids differ for cuts {:?}", all);
    prop_assert_eq!(whole.written, split.written);
    // One-row strips as well: the finest split.
    let rows: Vec<u32> = (0..=h).collect();
    let fine = render_strips(&frame, &rows);
    prop_assert!(
        whole.color == fine.color
            && whole.z32 == fine.z32
            && whole.z16 == fine.z16
            && whole.ids == fine.ids
    );
    Ok(())
}

proptest! {
    #![proptest_config(cases(512))]

    /// Any split into strips gives the identical frame, bit for bit: Gouraud
    /// Rgb888 colour with u32 and with u16 depth, and triangle ids.
    #[test]
    fn strip_split_gives_identical_frame(
        (w, h, tris) in scene(),
        cuts in prop::collection::vec(0u32..40, 0..6),
        less_equal in any::<bool>(),
        s4 in any::<bool>(),
    ) {
        let func = if less_equal { DepthFunc::LessEqual } else { DepthFunc::Less };
        if s4 {
            check_strips::<4>(w, h, &tris, func, &cuts)?;
        } else {
            check_strips::<8>(w, h, &tris, func, &cuts)?;
        }
    }
}

// ---------------------------------------------------------------------------
// Closed fans (piglit triangle-rasterization-overdraw)
// ---------------------------------------------------------------------------

/// Builds a fan around window point `c` (px): rim at radius `r` (+ noise)
/// with tangential steps in `[0, step)` px, every vertex scaled by a
/// random w when `projected`. Rim vertices are kept only if they turn
/// strictly counter-clockwise (window space) from the previous one after
/// snapping, so the fan is star-shaped and closed.
fn build_fan<const S: u32>(
    w: u32,
    h: u32,
    c: (f64, f64),
    r: f64,
    step: f64,
    projected: bool,
    rng: &mut SplitMix,
) -> (Vec<[microraster::Vec4; 3]>, Vec<SubPt>, SubPt) {
    let wgen = |rng: &mut SplitMix| if projected { rng.range(0.25, 4.0) } else { 1.0 };
    let snap1 = |v: Vec4| {
        let s = microraster::fixed::snap::<S>(v.x, v.y, v.z, v.w, w, h).unwrap();
        (s.x as i64, s.y as i64)
    };
    let cv = wvzw(c.0, c.1, 0.0, wgen(rng), w, h);
    let cs = snap1(cv);
    let theta0 = rng.range(0.0, std::f64::consts::TAU);
    let mut theta = theta0;
    let mut rim: Vec<(Vec4, SubPt)> = Vec::new();
    while theta < theta0 + std::f64::consts::TAU {
        let rr = r + rng.range(-0.5, 0.5);
        let p = (c.0 + rr * theta.cos(), c.1 + rr * theta.sin());
        let v = wvzw(p.0, p.1, 0.0, wgen(rng), w, h);
        let s = snap1(v);
        let ok = match rim.last() {
            None => true,
            Some(&(_, last)) => orient(cs, last, s) > 0,
        };
        if ok {
            rim.push((v, s));
        }
        theta += rng.range(0.0, step) / r;
    }
    while rim.len() > 3 && orient(cs, rim[rim.len() - 1].1, rim[0].1) <= 0 {
        rim.pop();
    }
    let n = rim.len();
    let tris = (0..n).map(|k| [cv, rim[k].0, rim[(k + 1) % n].0]).collect();
    (tris, rim.iter().map(|r| r.1).collect(), cs)
}

fn check_fan<const S: u32>(
    w: u32,
    h: u32,
    c: (f64, f64),
    r: f64,
    step: f64,
    projected: bool,
    seed: u64,
) -> Result<(), TestCaseError> {
    let mut rng = SplitMix(seed);
    let (tris, rim, cs) = build_fan::<S>(w, h, c, r, step, projected, &mut rng);
    prop_assume!(rim.len() >= 3);
    // The fan is closed: the rim turns once around the centre.
    let (wn_c, on) = winding(&rim, cs);
    prop_assert!(!on && wn_c == 1, "fan centre not inside its rim");
    let cfg = config_nocull(w, h);
    let counts = hit_counts::<S>(cfg, &tris);
    let (mut double, mut holes, mut strays) = (vec![], vec![], vec![]);
    for j in 0..h as i64 {
        for i in 0..w as i64 {
            let n = counts[(j * w as i64 + i) as usize];
            let (wn, on_rim) = winding(&rim, (centre(i, S), centre(j, S)));
            if n > 1 {
                double.push((i, j));
            } else if !on_rim && wn == 1 && n != 1 {
                holes.push((i, j));
            } else if !on_rim && wn == 0 && n != 0 {
                strays.push((i, j));
            }
        }
    }
    prop_assert!(
        double.is_empty() && holes.is_empty() && strays.is_empty(),
        "S={} {} triangles: double hits {:?}, holes {:?}, strays {:?}",
        S,
        tris.len(),
        double,
        holes,
        strays
    );
    // The whole fan in one frame writes exactly the summed hits.
    let written = with_frame::<S, _>(cfg, &tris, |f| {
        let mut ids = vec![TriangleId(0); (w * h) as usize];
        f.render_rows(0, h, &mut ids[..], &mut NoDepth)
            .unwrap()
            .pixels_written
    });
    prop_assert_eq!(written, counts.iter().map(|&n| n as u64).sum::<u64>());
    Ok(())
}

proptest! {
    #![proptest_config(cases(512))]

    /// A fan with its centre in the frame: every pixel whose centre is
    /// strictly inside the rim polygon is hit exactly once, pixels outside
    /// never, and no pixel twice (centres on the rim may go either way).
    #[test]
    fn closed_fan_covers_inside_exactly_once(
        cx in 16.0f64..48.0,
        cy in 16.0f64..48.0,
        r in 3.0f64..16.0,
        projected in any::<bool>(),
        s4 in any::<bool>(),
        seed in any::<u64>(),
    ) {
        if s4 {
            check_fan::<4>(64, 64, (cx, cy), r, 1.0, projected, seed)?;
        } else {
            check_fan::<8>(64, 64, (cx, cy), r, 1.0, projected, seed)?;
        }
    }

    /// piglit's `-clip` mode: the centre anywhere in [-0.5, 1.5] x the
    /// frame and the rim outside the frame, so every triangle is cut by the
    /// frame edges: every pixel of the frame is hit exactly once.
    #[test]
    fn closed_fan_around_the_frame_covers_every_pixel_once(
        cx in -16.0f64..48.0,
        cy in -16.0f64..48.0,
        s4 in any::<bool>(),
        seed in any::<u64>(),
    ) {
        let far = [(0.0, 0.0), (32.0, 0.0), (0.0, 32.0), (32.0, 32.0)]
            .iter()
            .map(|&(x, y): &(f64, f64)| (x - cx).hypot(y - cy))
            .fold(0.0, f64::max);
        let r = far + 5.0;
        if s4 {
            check_fan::<4>(32, 32, (cx, cy), r, 2.0, false, seed)?;
        } else {
            check_fan::<8>(32, 32, (cx, cy), r, 2.0, false, seed)?;
        }
    }
}

// ---------------------------------------------------------------------------
// Translation invariance
// ---------------------------------------------------------------------------

type Shot = (Vec<Rgb888>, Vec<u32>, Vec<u32>);

fn shoot<const S: u32>(w: u32, h: u32, tris: &[([Vec4; 3], [Rgb888; 3])]) -> Shot {
    let mut cfg = config_nocull(w, h);
    cfg.depth_func = DepthFunc::LessEqual;
    let mut st = storage(tris.len());
    let mut frame = Frame::<S>::with_subpixel_bits(cfg, &mut st).unwrap();
    for (i, (p, c)) in tris.iter().enumerate() {
        frame.submit_clip_triangle(*p, *c, i as u32).unwrap();
    }
    let n = (w * h) as usize;
    let mut color = vec![Rgb888::new(0, 0, 0); n];
    let mut z = vec![u32::MAX; n];
    frame.render_rows(0, h, &mut color[..], &mut z[..]).unwrap();
    (color, z, frame_ids(&frame))
}

proptest! {
    #![proptest_config(cases(512))]

    /// A scene built in window space with w = 1 (exact), moved by whole
    /// pixels (dx, dy), renders the same colour, depth and id images moved
    /// by (dx, dy); every other pixel stays background.
    #[test]
    fn moving_scene_by_whole_pixels_moves_images(
        tris in prop::collection::vec(
            (prop::array::uniform3((8i64 * 256..=56 * 256, 8i64 * 256..=56 * 256, -1.0f64..=1.0)), colors()),
            1..6,
        ),
        dx in -8i64..=8,
        dy in -8i64..=8,
        s4 in any::<bool>(),
    ) {
        let (w, h) = (64u32, 64u32);
        let build = |ox: i64, oy: i64| -> Vec<([Vec4; 3], [Rgb888; 3])> {
            tris.iter()
                .map(|(vs, c)| {
                    let p = vs.map(|(x, y, z)| {
                        let (cx, cy) = win_to_clip((x + ox * 256) as f64 / 256.0, (y + oy * 256) as f64 / 256.0, w, h);
                        Vec4::new(cx, cy, z as f32, 1.0)
                    });
                    (p, *c)
                })
                .collect()
        };
        let (a, b) = if s4 {
            (shoot::<4>(w, h, &build(0, 0)), shoot::<4>(w, h, &build(dx, dy)))
        } else {
            (shoot::<8>(w, h, &build(0, 0)), shoot::<8>(w, h, &build(dx, dy)))
        };
        for j in 0..h as i64 {
            for i in 0..w as i64 {
                let k = (j * w as i64 + i) as usize;
                let (si, sj) = (i - dx, j - dy);
                let src = (si >= 0 && sj >= 0 && si < w as i64 && sj < h as i64)
                    .then(|| (sj * w as i64 + si) as usize);
                let (ec, ez, eid) = match src {
                    Some(s) => (a.0[s], a.1[s], a.2[s]),
                    None => (Rgb888::new(0, 0, 0), u32::MAX, 0),
                };
                prop_assert_eq!(b.0[k], ec, "colour at ({}, {})", i, j);
                prop_assert_eq!(b.1[k], ez, "depth at ({}, {})", i, j);
                prop_assert_eq!(b.2[k], eid, "id at ({}, {})", i, j);
            }
        }
        // Nothing of the original image fell off the frame.
        let drawn = |s: &Shot| s.2.iter().filter(|&&v| v != 0).count();
        prop_assert_eq!(drawn(&a), drawn(&b));
    }
}

// ---------------------------------------------------------------------------
// Stats accounting
// ---------------------------------------------------------------------------

fn component() -> impl Strategy<Value = f32> {
    prop_oneof![
        8 => -1.5f32..1.5,
        2 => -40.0f32..40.0,
        1 => -1.0e6f32..1.0e6,
        1 => prop_oneof![
            Just(f32::NAN),
            Just(f32::INFINITY),
            Just(f32::NEG_INFINITY),
            Just(f32::MAX),
            Just(-f32::MAX),
            Just(1.0e30),
            Just(0.0),
        ],
    ]
}

fn any_vertex() -> impl Strategy<Value = Vec4> {
    let w = prop_oneof![6 => 0.2f32..4.0, 1 => -2.0f32..0.0, 1 => Just(0.0f32), 1 => component()];
    (
        component(),
        component(),
        prop_oneof![3 => -0.9f32..0.9, 1 => component()],
        w,
    )
        .prop_map(|(x, y, z, w)| {
            Vec4::new(
                x * w.abs().max(1e-3),
                y * w.abs().max(1e-3),
                z * w.abs().max(1e-3),
                w,
            )
        })
}

fn any_triangle() -> impl Strategy<Value = [Vec4; 3]> {
    let general = (any_vertex(), any_vertex(), any_vertex()).prop_map(|(a, b, c)| [a, b, c]);
    let degenerate = (any_vertex(), any_vertex(), -2.0f32..2.0).prop_map(|(a, b, t)| {
        let c = Vec4::new(a.x + (b.x - a.x) * t, a.y + (b.y - a.y) * t, a.z, 1.0);
        [a, b, if t > 1.5 { a } else { c }]
    });
    let tiny = (-1.0f32..1.0, -1.0f32..1.0).prop_map(|(x, y)| {
        let d = 1.0e-3;
        [
            Vec4::new(x, y, 0.0, 1.0),
            Vec4::new(x + d, y, 0.0, 1.0),
            Vec4::new(x, y + d, 0.0, 1.0),
        ]
    });
    prop_oneof![6 => general, 1 => degenerate, 1 => tiny]
}

fn dropped(s: &Stats) -> u64 {
    s.dropped()
}

fn check_stats<const S: u32>(cfg: Config, tris: &[[Vec4; 3]]) -> Result<(), TestCaseError> {
    let mut st = storage(tris.len());
    let mut frame = Frame::<S>::with_subpixel_bits(cfg, &mut st).unwrap();
    let mut kept = 0u64;
    for (i, t) in tris.iter().enumerate() {
        let before = frame.stats();
        let len = frame.triangles().len();
        frame
            .submit_clip_triangle(*t, [Rgb888::new(9, 9, 9); 3], i as u32)
            .unwrap();
        let after = frame.stats();
        let d_stored = after.stored - before.stored;
        let d_dropped = dropped(&after) - dropped(&before);
        let d_clipped = after.clipped - before.clipped;
        let pieces = frame.triangles().len() - len;
        prop_assert_eq!(after.submitted - before.submitted, 1);
        prop_assert_eq!(pieces as u64, d_stored, "stored counts the pieces");
        prop_assert!(
            (d_dropped == 1 && d_stored == 0) || (d_dropped == 0 && d_stored >= 1),
            "{:?}: counted {} times, stored {}: {:?} -> {:?}",
            t,
            d_dropped,
            d_stored,
            before,
            after
        );
        prop_assert!(d_clipped <= 1);
        prop_assert!(
            d_stored <= 1 || d_clipped == 1,
            "several pieces without clipping"
        );
        prop_assert!(frame.triangles()[len..].iter().all(|s| s.id() == i as u32));
        let non_finite = t
            .iter()
            .any(|v| !(v.x.is_finite() && v.y.is_finite() && v.z.is_finite() && v.w.is_finite()));
        if non_finite {
            prop_assert_eq!(after.rejected_nonfinite - before.rejected_nonfinite, 1);
        }
        kept += (d_stored > 0) as u64;
    }
    let s = frame.stats();
    prop_assert_eq!(s.submitted, tris.len() as u64);
    prop_assert_eq!(s.submitted, dropped(&s) + kept);
    prop_assert_eq!(s.stored as usize, frame.triangles().len());
    // And whatever was stored renders without panicking, in strips too.
    let _ = frame_ids(&frame);
    let _ = frame_ids_strips(&frame, 3);
    Ok(())
}

proptest! {
    #![proptest_config(cases(1024))]

    /// Every submitted triangle is stored (as one or more pieces) or counted
    /// in exactly one culled/rejected counter, whatever its coordinates
    /// (NaN, infinities, w <= 0, huge, degenerate, off-screen, culled).
    #[test]
    fn stats_account_for_every_triangle(
        tris in prop::collection::vec(any_triangle(), 1..24),
        cull in prop_oneof![Just(CullMode::Back), Just(CullMode::Front), Just(CullMode::None)],
        front in prop_oneof![Just(FrontFace::Ccw), Just(FrontFace::Cw)],
        (w, h) in (1u32..=64, 1u32..=64),
        s4 in any::<bool>(),
    ) {
        let mut cfg = Config::new(w, h);
        cfg.cull = cull;
        cfg.front_face = front;
        if s4 { check_stats::<4>(cfg, &tris)?; } else { check_stats::<8>(cfg, &tris)?; }
    }

    /// Triangles inside the near, far and guard-band planes are never
    /// clipped: each is stored as exactly one piece or counted once.
    #[test]
    fn unclipped_triangles_store_at_most_one_piece((w, h, pos) in clip_case::<8>()) {
        let (gx, gy) = guard_band_ndc::<8>(w, h);
        prop_assume!(pos.iter().all(|p| outcode(*p, gx, gy) & outcode::CLIP == 0));
        let mut st = storage(1);
        let mut frame = Frame::<8>::new(config_nocull(w, h), &mut st).unwrap();
        frame.submit_clip_triangle(pos, [Rgb888::new(0, 0, 0); 3], 0).unwrap();
        let s = frame.stats();
        prop_assert_eq!(s.clipped, 0);
        prop_assert_eq!(s.stored + dropped(&s), 1);
    }

    /// Colour non-finite (only reachable through `push_triangle`) is
    /// rejected and counted.
    #[test]
    fn non_finite_colour_is_rejected(k in 0usize..3, ch in 0usize..3, bad in prop_oneof![Just(f32::NAN), Just(f32::INFINITY), Just(f32::NEG_INFINITY)]) {
        let mut st = storage(1);
        let mut frame = Frame::<8>::new(config_nocull(8, 8), &mut st).unwrap();
        let mut tri = [
            ClipVertex { pos: Vec4::new(-1.0, -1.0, 0.0, 1.0), varyings: [1.0; 3] },
            ClipVertex { pos: Vec4::new(1.0, -1.0, 0.0, 1.0), varyings: [1.0; 3] },
            ClipVertex { pos: Vec4::new(0.0, 1.0, 0.0, 1.0), varyings: [1.0; 3] },
        ];
        tri[k].varyings[ch] = bad;
        frame.submit_triangle(tri, 0).unwrap();
        prop_assert_eq!(frame.stats().rejected_nonfinite, 1);
        prop_assert_eq!(frame.triangles().len(), 0);
    }
}

// ---------------------------------------------------------------------------
// Other paths to the same pixels: bins, immediate strips, cached meshes
// ---------------------------------------------------------------------------

/// Whole-frame colour (Gouraud, u32 depth) and id images of a frame.
fn whole_frame<const S: u32>(frame: &Frame<'_, S>) -> (Vec<Rgb888>, Vec<u32>, Vec<u32>) {
    let Config { width, height, .. } = *frame.config();
    let n = (width * height) as usize;
    let mut c = vec![Rgb888::new(1, 2, 3); n];
    let mut z = vec![u32::MAX; n];
    frame
        .render_rows(0, height, &mut c[..], &mut z[..])
        .unwrap();
    (c, z, frame_ids(frame))
}

proptest! {
    #![proptest_config(cases(512))]

    /// `Frame::bin` + `render_strip` over every strip gives exactly the
    /// pixels of `render_rows` over the whole frame, for any strip height.
    #[test]
    fn binned_strips_equal_render_rows(
        (w, h, tris) in scene(),
        strip_rows in 1u32..48,
    ) {
        let mut st = storage(tris.len());
        let mut frame: Frame = Frame::new(config_nocull(w, h), &mut st).unwrap();
        for (i, (p, c)) in tris.iter().enumerate() {
            frame.submit_clip_triangle(*p, *c, i as u32).unwrap();
        }
        let (wc, wz, wid) = whole_frame(&frame);
        let strips = h.div_ceil(strip_rows) as usize;
        let mut offsets = vec![0u32; strips + 1];
        let mut items = vec![0u32; frame.bin_entries(strip_rows)];
        let bins = frame.bin(strip_rows, &mut offsets, &mut items).unwrap();
        prop_assert_eq!(bins.strips() as usize, strips);
        let (mut c, mut z, mut ids) = (vec![], vec![], vec![]);
        for s in 0..bins.strips() {
            let (y0, y1) = bins.rows(s);
            let n = (w * (y1 - y0)) as usize;
            let mut sc = vec![Rgb888::new(1, 2, 3); n];
            let mut sz = vec![u32::MAX; n];
            frame.render_strip(&bins, s, &mut sc[..], &mut sz[..]).unwrap();
            let mut si = vec![TriangleId(0); n];
            frame.render_strip(&bins, s, &mut si[..], &mut NoDepth).unwrap();
            c.extend(sc);
            z.extend(sz);
            ids.extend(si.into_iter().map(|t| t.0));
        }
        prop_assert!(c == wc && z == wz && ids == wid, "binned strips of {} rows differ", strip_rows);
    }

    /// `StripRenderer` (no setup storage) draws, strip by strip, exactly the
    /// pixels `Frame::render_rows` draws for those rows, with the same
    /// counters.
    #[test]
    fn strip_renderer_equals_frame(
        (w, h, tris) in scene(),
        cuts in prop::collection::vec(1u32..40, 0..5),
        s4 in any::<bool>(),
    ) {
        if s4 {
            check_strip_renderer::<4>(w, h, &tris, &cuts)?;
        } else {
            check_strip_renderer::<8>(w, h, &tris, &cuts)?;
        }
    }

    /// `draw_mesh_cached` (vertices transformed and snapped once) stores
    /// the same triangles, counts the same statistics and renders the same
    /// pixels as `draw_mesh`, and `StripRenderer::draw_mesh` the same
    /// pixels again; for meshes with off-screen, clipped, behind-the-eye and
    /// non-finite vertices, bad indices and colour lists of any length.
    #[test]
    fn draw_mesh_cached_equals_draw_mesh(
        positions in prop::collection::vec(
            prop_oneof![
                10 => (-3.0f32..3.0, -3.0f32..3.0, -3.0f32..3.0).prop_map(|(x, y, z)| Vec3::new(x, y, z)),
                1 => Just(Vec3::new(f32::NAN, 0.0, 0.0)),
                1 => (-1.0e6f32..1.0e6, -1.0e6f32..1.0e6).prop_map(|(x, y)| Vec3::new(x, y, 0.0)),
            ],
            3..12,
        ),
        raw_indices in prop::collection::vec((0u32..13, 0u32..13, 0u32..13), 1..16),
        color_kind in 0u8..3,
        ncolors in 0usize..16,
        angle in 0.0f32..6.3,
        dist in 0.5f32..8.0,
        cull in prop_oneof![Just(CullMode::Back), Just(CullMode::Front), Just(CullMode::None)],
        (w, h) in (1u32..=40, 1u32..=40),
    ) {
        let indices: Vec<[u32; 3]> = raw_indices.iter().map(|&(a, b, c)| [a, b, c]).collect();
        let palette: Vec<Rgb888> = (0..ncolors as u8).map(|i| Rgb888::new(i.wrapping_mul(40), 255u8.wrapping_sub(i.wrapping_mul(13)), i.wrapping_mul(7))).collect();
        let colors = match color_kind {
            0 => MeshColors::Uniform(Rgb888::new(10, 200, 30)),
            1 => MeshColors::PerTriangle(&palette),
            _ => MeshColors::PerVertex(&palette),
        };
        let mesh = Mesh { positions: &positions, indices: &indices, attributes: colors, bounds: None };
        let mvp = Mat4::perspective(1.0, w as f32 / h as f32, 0.5, 20.0)
            * Mat4::translation(Vec3::new(0.0, 0.0, -dist))
            * Mat4::rotation_y(angle)
            * Mat4::rotation_x(angle * 0.7);
        let mut cfg = Config::new(w, h);
        cfg.cull = cull;
        let mut st1 = storage(indices.len());
        let mut st2 = storage(indices.len());
        let mut a: Frame = Frame::new(cfg, &mut st1).unwrap();
        let mut b: Frame = Frame::new(cfg, &mut st2).unwrap();
        a.submit_mesh(&mesh, &mvp, 5).unwrap();
        let mut cache = vec![ProcessedVertex::EMPTY; positions.len()];
        b.submit_mesh_cached(&mesh, &mvp, 5, &mut cache).unwrap();
        // (With a colour list too short for the mesh the two paths count
        // some triangles under different reasons: see the ignored
        // `draw_mesh_cached_counts_missing_colours_like_draw_mesh`.)
        let colours_complete = match colors {
            MeshColors::Uniform(_) => true,
            MeshColors::PerTriangle(c) => c.len() >= indices.len(),
            MeshColors::PerVertex(c) => c.len() >= positions.len(),
        };
        if colours_complete {
            prop_assert_eq!(a.stats(), b.stats());
        } else {
            prop_assert_eq!(a.stats().submitted, b.stats().submitted);
            prop_assert_eq!(a.stats().stored, b.stats().stored);
        }
        prop_assert_eq!(a.triangles(), b.triangles());
        let wa = whole_frame(&a);
        prop_assert!(wa == whole_frame(&b), "images differ");
        // Immediate mode, one strip for the whole frame.
        let n = (w * h) as usize;
        let mut c = vec![Rgb888::new(1, 2, 3); n];
        let mut z = vec![u32::MAX; n];
        let mut r: StripRenderer<'_, Rgb888, [u32]> = StripRenderer::new(cfg, 0, h, &mut c[..], &mut z[..]).unwrap();
        r.submit_mesh(&mesh, &mvp, 5).unwrap();
        prop_assert_eq!(r.stats(), a.stats());
        prop_assert!(c == wa.0 && z == wa.1, "immediate mode differs");
        // A cache shorter than the mesh is refused.
        if !positions.is_empty() {
            let mut short = vec![ProcessedVertex::EMPTY; positions.len() - 1];
            prop_assert_eq!(
                b.submit_mesh_cached(&mesh, &mvp, 5, &mut short),
                Err(Error::VertexCacheSize { expected: positions.len(), actual: positions.len() - 1 })
            );
        }
    }
}

fn check_strip_renderer<const S: u32>(
    w: u32,
    h: u32,
    tris: &[([Vec4; 3], [Rgb888; 3])],
    cuts: &[u32],
) -> Result<(), TestCaseError> {
    let cfg = config_nocull(w, h);
    let mut st = storage(tris.len());
    let mut frame = Frame::<S>::with_subpixel_bits(cfg, &mut st).unwrap();
    for (i, (p, c)) in tris.iter().enumerate() {
        frame.submit_clip_triangle(*p, *c, i as u32).unwrap();
    }
    let mut all = vec![0];
    all.extend(cuts.iter().copied().filter(|&c| c < h));
    all.push(h);
    all.sort_unstable();
    all.dedup();
    for pair in all.windows(2) {
        let (y0, y1) = (pair[0], pair[1]);
        let n = (w * (y1 - y0)) as usize;
        let mut fc = vec![Rgb888::new(1, 2, 3); n];
        let mut fz = vec![0xFFFFu16; n];
        let fw = frame.render_rows(y0, y1, &mut fc[..], &mut fz[..]).unwrap();
        let mut c = vec![Rgb888::new(1, 2, 3); n];
        let mut z = vec![0xFFFFu16; n];
        let mut r: StripRenderer<'_, Rgb888, [u16], S> =
            StripRenderer::with_subpixel_bits(cfg, y0, y1, &mut c[..], &mut z[..]).unwrap();
        for (i, (p, col)) in tris.iter().enumerate() {
            r.submit_clip_triangle(*p, *col, i as u32).unwrap();
        }
        // A strip skips triangles wholly above or below it before setup
        // (`outside_strip`); apart from those it counts what the frame does.
        let (rs, fs) = (r.stats(), frame.stats());
        prop_assert_eq!(rs.submitted, fs.submitted);
        prop_assert!(rs.stored <= fs.stored);
        if rs.outside_strip == 0 {
            prop_assert_eq!(rs, fs);
        }
        prop_assert_eq!(r.render_stats(), fw);
        prop_assert!(c == fc && z == fz, "rows {}..{} differ", y0, y1);
    }
    Ok(())
}

/// `draw_mesh_cached` promises the result of `draw_mesh`; with a colour
/// list too short for the mesh, a triangle that is also off-screen is
/// counted as `rejected_index` by `draw_mesh` but as `culled_frustum` by
/// `draw_mesh_cached` (which tests the frustum before looking the colour
/// up). Images are identical; only `Stats` differ.
#[test]
fn draw_mesh_cached_counts_missing_colours_like_draw_mesh() {
    let positions = [
        Vec3::new(10.0, 0.0, 0.0),
        Vec3::new(11.0, 0.0, 0.0),
        Vec3::new(10.0, 1.0, 0.0),
    ];
    let indices = [[0, 1, 2]];
    let mesh = Mesh {
        positions: &positions,
        indices: &indices,
        attributes: MeshColors::PerTriangle(&[]),
        bounds: None,
    };
    let (mut s1, mut s2) = (storage(1), storage(1));
    let mut a: Frame = Frame::new(Config::new(8, 8), &mut s1).unwrap();
    let mut b: Frame = Frame::new(Config::new(8, 8), &mut s2).unwrap();
    a.submit_mesh(&mesh, &Mat4::IDENTITY, 0).unwrap();
    let mut cache = [ProcessedVertex::EMPTY; 3];
    b.submit_mesh_cached(&mesh, &Mat4::IDENTITY, 0, &mut cache)
        .unwrap();
    assert_eq!(a.stats().rejected_index, 1);
    assert_eq!(b.stats(), a.stats());
}

// ---------------------------------------------------------------------------
// Object culling is conservative
// ---------------------------------------------------------------------------

/// A small mesh anywhere (offsets up to 1e7, sizes from a few ulps to
/// hundreds of units) seen from a camera beside it or far from it.
fn object_scene() -> impl Strategy<Value = (Vec<Vec3>, Vec3, Vec3, f32, f32)> {
    let coord = prop_oneof![-2.0f32..2.0, -1e5f32..1e5, -1e7f32..1e7];
    let scale = prop_oneof![Just(0.0f32), 1e-3f32..1.0, 1.0f32..300.0];
    (
        [coord.clone(), coord.clone(), coord],
        scale,
        proptest::collection::vec([-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0], 3..9),
        [-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0],
        prop_oneof![1e-3f32..1.0, 1.0f32..1e3],
        0.2f32..2.5,
        prop_oneof![Just(0.001f32), 0.01f32..1.0],
    )
        .prop_map(|(c, scale, pts, dir, dist, fov, near)| {
            let c = Vec3::new(c[0], c[1], c[2]);
            let ulps = |v: f32| (f32::from_bits(v.abs().to_bits() + 1) - v.abs()) * 4.0;
            let s = Vec3::new(
                scale.max(ulps(c.x)),
                scale.max(ulps(c.y)),
                scale.max(ulps(c.z)),
            );
            let positions = pts
                .iter()
                .map(|p| Vec3::new(c.x + p[0] * s.x, c.y + p[1] * s.y, c.z + p[2] * s.z))
                .collect::<Vec<_>>();
            let eye = c + Vec3::new(dir[0], dir[1], dir[2] + 0.01) * dist;
            // Look at the mesh, or past it, so it may be on screen or not.
            let target = c + Vec3::new(dir[1], -dir[0], dir[2]) * (dist * 0.5);
            (positions, eye, target, fov, near)
        })
}

proptest! {
    #![proptest_config(cases(2000))]

    /// The image (and every counter but the object's) is the same with and
    /// without a bounding sphere, for every scene.
    #[test]
    fn bounding_sphere_culling_never_changes_the_image(
        (positions, eye, target, fov, near) in object_scene()
    ) {
        let n = positions.len() as u32;
        let indices = (1..n - 1).map(|i| [0, i, i + 1]).collect::<Vec<_>>();
        let mvp = Mat4::perspective(fov, 1.0, near, near * 1e5)
            * Mat4::look_at(eye, target, Vec3::new(0.0, 1.0, 0.0));
        prop_assume!(mvp.is_finite());
        let mut mesh = Mesh {
            positions: &positions,
            indices: &indices,
            attributes: MeshColors::Uniform(Rgb888::new(7, 8, 9)),
            bounds: None,
        };
        let draw = |mesh: &Mesh<'_>| {
            let mut st = storage(indices.len() * 8);
            let mut frame = Frame::new(config_nocull(48, 48), &mut st).unwrap();
            frame.submit_mesh(mesh, &mvp, 0).unwrap();
            (frame_ids(&frame), frame.stats())
        };
        let (without, _) = draw(&mesh);
        mesh.bounds = BoundingSphere::from_points(&positions);
        let (with, stats) = draw(&mesh);
        prop_assert_eq!(&with, &without, "culled_object {}", stats.culled_object);
    }

    /// A strip renderer skips an object whose sphere lies wholly above or
    /// below its strip, and only one of which no triangle would be stored
    /// there: the strip's pixels are the same with and without the sphere.
    #[test]
    fn bounding_sphere_strip_skip_never_changes_a_strip(
        (positions, eye, target, fov, near) in object_scene(),
        y0 in 0u32..48,
        rows in 1u32..12,
    ) {
        let n = positions.len() as u32;
        let y1 = (y0 + rows).min(48);
        let indices = (1..n - 1).map(|i| [0, i, i + 1]).collect::<Vec<_>>();
        let mvp = Mat4::perspective(fov, 1.0, near, near * 1e5)
            * Mat4::look_at(eye, target, Vec3::new(0.0, 1.0, 0.0));
        prop_assume!(mvp.is_finite());
        let mut mesh = Mesh {
            positions: &positions,
            indices: &indices,
            attributes: MeshColors::Uniform(Rgb888::new(7, 8, 9)),
            bounds: None,
        };
        let len = (48 * (y1 - y0)) as usize;
        let draw = |mesh: &Mesh<'_>| {
            let mut ids = vec![TriangleId(0); len];
            let mut nd = NoDepth;
            let mut strip =
                StripRenderer::new(config_nocull(48, 48), y0, y1, &mut ids, &mut nd).unwrap();
            strip.submit_mesh(mesh, &mvp, 0).unwrap();
            let stats = strip.stats();
            (ids, stats)
        };
        let (without, plain) = draw(&mesh);
        mesh.bounds = BoundingSphere::from_points(&positions);
        let (with, stats) = draw(&mesh);
        prop_assert_eq!(&with, &without);
        if stats.outside_strip == indices.len() as u64 && stats.culled_object == 0 {
            prop_assert_eq!(plain.stored, 0, "skipped an object with a triangle in the strip");
        } else {
            prop_assert_eq!(stats.stored, plain.stored);
        }
    }
}

// ---------------------------------------------------------------------------
// The 32-bit edge fast path at its limit
// ---------------------------------------------------------------------------

/// Triangles whose vertex span (in x and y) is at or just around
/// `raster::EDGE32_SPAN` subpixel units, one vertex in or near a 64x64
/// frame: both sides of the switch between `i32` and `i64` edge values,
/// where the `i32` values come closest to overflowing.
fn edge32_limit_tri() -> impl Strategy<Value = [SubPt; 3]> {
    let limit = microraster::raster::EDGE32_SPAN;
    let span = prop_oneof![
        Just(limit),
        Just(limit + 1),
        limit - 300..=limit,
        limit + 1..=limit + 300
    ];
    (
        (-4096i64..(64 << 8) + 4096, -4096i64..(64 << 8) + 4096),
        span.clone(),
        span,
        any::<bool>(),
        any::<bool>(),
        0.0f64..=1.0,
        0.0f64..=1.0,
    )
        .prop_map(|(a, bx, by, fx, fy, t1, t2)| {
            let sx = if fx { 1 } else { -1 };
            let sy = if fy { 1 } else { -1 };
            let b = (a.0 + sx * bx, a.1 + (t1 * by as f64) as i64 * sy);
            let c = (a.0 + (t2 * bx as f64) as i64 * sx, a.1 + sy * by);
            [a, b, c]
        })
}

/// The same triangle drawn with a `u16` and a `u32` depth buffer (which
/// sets up depth from the triangle's area and edge steps, narrowed to
/// `i32` on the fast path: the narrowing's debug assertion and the
/// overflow checks watch it) covers the pixels it covers without one.
fn check_depth_coverage<const S: u32>(config: Config, pos: [Vec4; 3]) -> Result<(), TestCaseError> {
    let n = (config.width * config.height) as usize;
    let plain = coverage::<S>(config, pos);
    // Depths kept off the planes (NDC within 0.999 of them; the same
    // coverage, as nothing is clipped either way): a `u16` depth of 0
    // never passes `Greater` against a clear of 0, nor 0xFFFF `Less`
    // against 0xFFFF, so a triangle at NDC depth below -1 + 3e-5 drew
    // nothing there (found by CI's 100,000-case run). The planes
    // themselves are `unchecked_u16_spans_equal_the_clamped_path`'s and
    // `u16_spans_with_vertices_on_the_planes_at_pixel_centres`'.
    let pos = pos.map(|p| Vec4::new(p.x, p.y, p.z * 0.999, p.w));
    let (ids16, ids32) = with_frame::<S, _>(config, &[pos], |frame| {
        let mut ids16 = vec![TriangleId(0); n];
        let mut z16 = vec![u16::MAX; n];
        frame
            .render_rows(0, config.height, &mut ids16[..], &mut z16[..])
            .expect("valid rows");
        let mut ids32 = vec![TriangleId(0); n];
        let mut z32 = vec![u32::MAX; n];
        frame
            .render_rows(0, config.height, &mut ids32[..], &mut z32[..])
            .expect("valid rows");
        (ids16, ids32)
    });
    // `Greater` into a buffer cleared to 0: the other copy of the `u16`
    // flat rows (`LessEqual`, `Greater` and `GreaterEqual` share it).
    let greater = Config {
        depth_func: DepthFunc::Greater,
        ..config
    };
    let ids16_greater = with_frame::<S, _>(greater, &[pos], |frame| {
        let mut ids = vec![TriangleId(0); n];
        let mut z16 = vec![0u16; n];
        frame
            .render_rows(0, config.height, &mut ids[..], &mut z16[..])
            .expect("valid rows");
        ids
    });
    let covered = |ids: Vec<TriangleId>| ids.into_iter().map(|t| t.0 != 0).collect::<Vec<_>>();
    prop_assert_eq!(covered(ids16), plain.clone(), "u16 depth");
    prop_assert_eq!(covered(ids16_greater), plain.clone(), "u16 depth, Greater");
    prop_assert_eq!(covered(ids32), plain, "u32 depth");
    Ok(())
}

proptest! {
    #![proptest_config(cases(1024))]

    /// At 8 and 4 subpixel bits (at 4, the same units are 16 times as many
    /// pixels, mostly off-screen): coverage equals the `i128` reference on
    /// both sides of the `i32` limit (overflow checks are on in tests).
    #[test]
    fn coverage_matches_reference_at_the_i32_edge_limit(v in edge32_limit_tri()) {
        let (w, h) = (64, 64);
        for s in [8u32, 4] {
            // The same spans in subpixel units; at 4 bits the first vertex
            // is moved to the same place in pixels.
            let shift = |p: SubPt| if s == 8 { p } else { (p.0 - v[0].0 + v[0].0 / 16, p.1 - v[0].1 + v[0].1 / 16) };
            let vs = v.map(shift);
            let pos = grid_to_clip(vs, s, w, h);
            if s == 8 {
                prop_assume!(snap_tri::<8>(&pos, w, h) == Some(vs));
                check_coverage::<8>(config_nocull(w, h), pos)?;
                check_depth_coverage::<8>(config_nocull(w, h), pos)?;
            } else {
                prop_assume!(snap_tri::<4>(&pos, w, h) == Some(vs));
                check_coverage::<4>(config_nocull(w, h), pos)?;
                check_depth_coverage::<4>(config_nocull(w, h), pos)?;
            }
        }
    }
}

/// The strip skip fires: an object in the top rows is skipped whole by a
/// strip at the bottom (counted as outside the strip), and drawn by a
/// strip it reaches.
#[test]
fn an_object_above_the_strip_is_skipped_whole() {
    let positions: Vec<Vec3> = (0..8)
        .map(|i| Vec3::new((i % 4) as f32 * 0.2 - 0.3, 0.7 + (i / 4) as f32 * 0.1, 0.0))
        .collect();
    let indices: Vec<[u32; 3]> = (1..7).map(|i| [0, i, i + 1]).collect();
    let mesh = Mesh {
        positions: &positions,
        indices: &indices,
        attributes: MeshColors::Uniform(Rgb888::new(7, 8, 9)),
        bounds: BoundingSphere::from_points(&positions),
    };
    let mvp = Mat4::translation(Vec3::new(0.0, 0.0, -0.5));
    for (y0, y1, skipped) in [(40u32, 48u32, true), (0, 10, false)] {
        let mut ids = vec![TriangleId(0); (48 * (y1 - y0)) as usize];
        let mut nd = NoDepth;
        let mut strip =
            StripRenderer::new(config_nocull(48, 48), y0, y1, &mut ids, &mut nd).unwrap();
        strip.submit_mesh(&mesh, &mvp, 0).unwrap();
        let s = strip.stats();
        assert_eq!(s.submitted, 6);
        if skipped {
            assert_eq!(s.outside_strip, 6, "{s:?}");
            assert_eq!(s.culled_object, 0);
        } else {
            assert!(s.stored > 0, "{s:?}");
        }
    }
}

/// An NDC depth near a plane, or anywhere: within 3e-5 of -1 or 1 (window
/// depth within about 2^16 `Z32` units of 0 or 1, around the margin of the
/// rasterizer's unclamped span path), a few `f32` steps from them (tens to
/// hundreds of `Z32` units, where a missing margin would show), or uniform
/// in [-1, 1].
fn near_plane_depth() -> impl Strategy<Value = f32> {
    prop_oneof![
        (0.0f32..3e-5).prop_map(|t| -1.0 + t),
        (0.0f32..3e-5).prop_map(|t| 1.0 - t),
        (0u32..64).prop_map(|k| -1.0 + k as f32 * f32::EPSILON),
        (0u32..64).prop_map(|k| 1.0 - k as f32 * f32::EPSILON / 2.0),
        -1.0f32..=1.0,
    ]
}

proptest! {
    #![proptest_config(cases(2048))]

    /// The `u16` span path that skips the per-span range check (`Less`,
    /// writes on, vertex depths clear of the planes: `z_never_clamps` in
    /// `src/raster.rs`) writes the depths the clamped per-pixel path writes
    /// (`Always`, which never takes it), under each ordered test it is
    /// built for, for flat triangles with depths
    /// near both planes and in between. (Debug builds also assert, per
    /// span, that the unchecked spans stay in range.)
    #[test]
    fn unchecked_u16_spans_equal_the_clamped_path(
        (w, h, pos) in clip_case::<8>(),
        z in [near_plane_depth(), near_plane_depth(), near_plane_depth()],
    ) {
        let mut pos = pos;
        for (p, z) in pos.iter_mut().zip(z) {
            p.z = z * p.w;
        }
        prop_assert!(check_unchecked_u16_spans(w, h, pos)?, "rejected");
    }

    /// Named hard case of the same: vertices exactly at pixel centres,
    /// their depths exactly on the planes (NDC -1 and 1: `Z32` 0 and
    /// `2^32 - 1`) or anywhere. A covered pixel centre at a vertex on a
    /// plane has its exact depth on it, where any error of the `f32` span
    /// start or step would leave `[0, 2^32)` and wrap; `z_never_clamps`
    /// must send such triangles to the clamped loop. (With its test
    /// forced true, this fails within a few hundred cases; the property
    /// above, off the pixel centres, did not.)
    #[test]
    fn u16_spans_with_vertices_on_the_planes_at_pixel_centres(
        w in 8u32..=48,
        h in 8u32..=48,
        p in [(0u32..48, 0u32..48), (0u32..48, 0u32..48), (0u32..48, 0u32..48)],
        z in [on_a_plane(), on_a_plane(), on_a_plane()],
    ) {
        let pos: [Vec4; 3] = core::array::from_fn(|k| {
            let (x, y) = ((p[k].0 % w) as f64 + 0.5, (p[k].1 % h) as f64 + 0.5);
            wvzw(x, y, z[k], 1.0, w, h)
        });
        check_unchecked_u16_spans(w, h, pos)?;
    }
}

/// NDC depth -1 or 1 (the planes; mostly), or anywhere between.
fn on_a_plane() -> impl Strategy<Value = f64> {
    prop_oneof![2 => Just(-1.0f64), 2 => Just(1.0f64), 1 => -1.0f64..=1.0]
}

/// [`unchecked_u16_spans_equal_the_clamped_path`]'s check: the flat
/// triangle `pos` drawn into a `u16` buffer under each ordered test (the
/// unchecked span path where `z_never_clamps` holds) writes the depths and
/// colours that `Always` (the clamped per-pixel path) writes. Returns
/// whether the triangle was accepted.
fn check_unchecked_u16_spans(w: u32, h: u32, pos: [Vec4; 3]) -> Result<bool, TestCaseError> {
    let n = (w * h) as usize;
    let mut accepted = true;
    let mut depth = |func, clear| {
        let mut cfg = config_nocull(w, h);
        cfg.depth_func = func;
        let mut st = storage(1);
        let mut frame = Frame::<8>::with_subpixel_bits(cfg, &mut st).unwrap();
        // (Rejected triangles draw nothing on either path.)
        accepted &= frame
            .submit_clip_triangle(pos, [Rgb888::new(9, 8, 7); 3], 0)
            .is_ok();
        let mut c = vec![Rgb888::new(0, 0, 0); n];
        let mut z = vec![clear; n];
        frame.render_rows(0, h, &mut c[..], &mut z[..]).unwrap();
        (c, z)
    };
    // Every ordered test against the clear it passes everywhere but at
    // the clear value itself (`Greater` and `GreaterEqual` as 1/w depth
    // draws them, cleared to 0).
    for (func, clear) in [
        (DepthFunc::Less, u16::MAX),
        (DepthFunc::LessEqual, u16::MAX),
        (DepthFunc::Greater, 0),
        (DepthFunc::GreaterEqual, 0),
    ] {
        let (fast_c, fast_z) = depth(func, clear);
        let (all_c, all_z) = depth(DepthFunc::Always, clear);
        let equal_passes = matches!(func, DepthFunc::LessEqual | DepthFunc::GreaterEqual);
        for k in 0..n {
            if all_z[k] != clear || equal_passes {
                prop_assert_eq!(fast_z[k], all_z[k], "{:?}: depth at pixel {}", func, k);
                prop_assert_eq!(fast_c[k], all_c[k], "{:?}: colour at pixel {}", func, k);
            } else {
                prop_assert_eq!(fast_z[k], clear);
            }
        }
    }
    Ok(accepted)
}

proptest! {
    #![proptest_config(cases(2048))]
}

/// `u16` depth, `u32` depth and the written mask of one flat triangle
/// under `Less` on far-cleared buffers.
fn depth_pair<const S: u32>(w: u32, h: u32, pos: [Vec4; 3]) -> (Vec<u16>, Vec<u32>, Vec<bool>) {
    let n = (w * h) as usize;
    let mut st = storage(1);
    let mut frame = Frame::<S>::with_subpixel_bits(config_nocull(w, h), &mut st).unwrap();
    frame
        .submit_clip_triangle(pos, [Rgb888::new(9, 8, 7); 3], 0)
        .unwrap();
    let (mut c16, mut z16) = (vec![Rgb888::new(0, 0, 0); n], vec![u16::MAX; n]);
    frame.render_rows(0, h, &mut c16[..], &mut z16[..]).unwrap();
    let (mut c32, mut z32) = (vec![Rgb888::new(0, 0, 0); n], vec![u32::MAX; n]);
    frame.render_rows(0, h, &mut c32[..], &mut z32[..]).unwrap();
    let drawn = Rgb888::new(9, 8, 7);
    let both = (0..n).map(|k| c16[k] == drawn && c32[k] == drawn).collect();
    (z16, z32, both)
}

/// Checks every pixel both buffers wrote: the `u16` word is the `u32`
/// word's top half, or one off where the `u32` value lies within 2^13
/// (1/8 of a `u16` LSB, the `u16` path's error bound, plus the `u32`
/// path's one unit) of the boundary it crosses.
fn check_depth_pair(z16: &[u16], z32: &[u32], both: &[bool]) -> Result<(), TestCaseError> {
    for k in 0..z16.len() {
        if !both[k] {
            continue;
        }
        let (hi, frac) = ((z32[k] >> 16) as i64, z32[k] & 0xffff);
        let diff = z16[k] as i64 - hi;
        let ok = diff == 0
            || (diff == 1 && frac >= (1 << 16) - (1 << 13) - 2)
            || (diff == -1 && frac <= (1 << 13) + 1);
        prop_assert!(ok, "pixel {}: u16 {} against u32 {:#x}", k, z16[k], z32[k]);
    }
    Ok(())
}

proptest! {
    #![proptest_config(cases(2048))]

    /// The `u16` path (`f32` span starts, whole `Z32` steps, the unchecked
    /// spans of `z_never_clamps`) stays within 1/8 LSB of the `u32` path
    /// (`f64`, the floor of the exact plane or one off), at both subpixel
    /// precisions, with depths near both planes and in between. (Moving
    /// the unchecked spans' start by 9,000 `Z32` units fails it.)
    #[test]
    fn u16_depth_within_an_eighth_lsb_of_u32_depth_s8(
        (w, h, pos) in clip_case::<8>(),
        z in [near_plane_depth(), near_plane_depth(), near_plane_depth()],
    ) {
        let mut pos = pos;
        for (p, z) in pos.iter_mut().zip(z) {
            p.z = z * p.w;
        }
        let (z16, z32, both) = depth_pair::<8>(w, h, pos);
        check_depth_pair(&z16, &z32, &both)?;
    }

    #[test]
    fn u16_depth_within_an_eighth_lsb_of_u32_depth_s4(
        (w, h, pos) in clip_case::<4>(),
        z in [near_plane_depth(), near_plane_depth(), near_plane_depth()],
    ) {
        let mut pos = pos;
        for (p, z) in pos.iter_mut().zip(z) {
            p.z = z * p.w;
        }
        let (z16, z32, both) = depth_pair::<4>(w, h, pos);
        check_depth_pair(&z16, &z32, &both)?;
    }
}

/// Hard case: horizontal edges exactly through pixel centres, above and
/// below (a top edge's row is drawn, a bottom edge's is not), with the
/// third vertex on either side and at 8 and 4 subpixel bits: coverage,
/// also through the `u16` depth buffer's batched flat rows (which cut a
/// horizontal edge's rows before its spans), equals the reference.
#[test]
fn horizontal_edges_through_pixel_centres_match_the_reference() {
    let (w, h) = (16, 16);
    for s in [8u32, 4] {
        let one = 1i64 << s;
        let half = one / 2;
        let c = |k: i64| k * one + half;
        for (flat_y, apex_y) in [
            (c(3), c(11)),
            (c(11), c(3)),
            (c(5), c(5) + 3),
            (c(9), c(9) - 3),
        ] {
            for apex_x in [c(0), c(4), c(7) + 1, c(13)] {
                for (x0, x1) in [(c(2), c(12)), (c(4) + 5, c(9) - 7)] {
                    let v = [(x0, flat_y), (x1, flat_y), (apex_x, apex_y)];
                    let pos = grid_to_clip(v, s, w, h);
                    let run = || -> Result<(), TestCaseError> {
                        if s == 8 {
                            check_coverage::<8>(config_nocull(w, h), pos)?;
                            check_depth_coverage::<8>(config_nocull(w, h), pos)
                        } else {
                            check_coverage::<4>(config_nocull(w, h), pos)?;
                            check_depth_coverage::<4>(config_nocull(w, h), pos)
                        }
                    };
                    if let Err(e) = run() {
                        panic!("S={s} {v:?}: {e}");
                    }
                }
            }
        }
    }
}

/// The two triangles CI's 100,000-case run found: every depth within
/// 3e-5 of the near plane (a `u16` depth of 0), drawn by
/// `check_depth_coverage` (which keeps depths off the planes since).
#[test]
fn depth_coverage_of_triangles_at_the_near_plane() {
    let v = |x: f32, y: f32, z: f32| Vec4::new(x, y, z, 1.0);
    let a = [
        v(0.0, 0.0, -0.99998105),
        v(0.0, -0.08976485, -0.99998105),
        v(0.08686292, 0.0, -0.99998105),
    ];
    check_depth_coverage::<4>(config_nocull(27, 36), a).unwrap();
    let b = [
        v(0.0, -79514.055, 0.0),
        v(313054.8, 0.0, 0.0),
        v(0.0, 0.0, -0.9999949),
    ];
    check_depth_coverage::<8>(config_nocull(1, 7), b).unwrap();
}
