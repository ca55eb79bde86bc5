//! Shared helpers for the integration tests.
//!
//! - An exact reference rasterizer ([`reference_coverage`]), written from the
//!   definition of the top-left rule and independent of the core's code: it
//!   works on snapped vertices in `i128`, normalises neither winding nor
//!   edges, and decides "top" and "left" from where the third vertex lies.
//! - Frame helpers: build a frame, push triangles given in window
//!   coordinates, render to a `Vec` of ids (whole frame or through strips).
//! - ASCII patterns in the style of embedded-graphics' `MockDisplay`: `.`
//!   background, `1`..`9`, `a`..`z` the triangle with that id, `#` a pixel
//!   hit more than once.
//! - An overdraw counter ([`hit_counts`]): each triangle rendered on its own
//!   and the per-pixel hits summed, to find double hits and holes.
//! - A small deterministic RNG for the table-driven tests.

#![allow(dead_code)]

use microraster::fixed::snap;
use microraster::pixelcolor::Rgb888;
use microraster::prelude::*;
use microraster::{
    Config, CullMode, DepthBuffer, DepthFunc, Frame, NoDepth, SetupTriangle, TriangleId, Vec4,
};

// ---------------------------------------------------------------------------
// Exact reference rasterizer
// ---------------------------------------------------------------------------

/// A snapped vertex: window `(x, y)` in `Sub<S>` units (rows from the top).
pub type SubPt = (i64, i64);

/// `(b - a) x (p - a)` (window y down): twice the signed area of `a, b, p`.
pub fn orient(a: SubPt, b: SubPt, p: SubPt) -> i128 {
    let (ax, ay) = (a.0 as i128, a.1 as i128);
    (b.0 as i128 - ax) * (p.1 as i128 - ay) - (b.1 as i128 - ay) * (p.0 as i128 - ax)
}

/// Whether the edge `a -> b` of a triangle whose third vertex is `c` is a
/// top edge (horizontal, interior below: larger y) or a left edge (the
/// interior, where `c` lies, is to the right: larger x at the same row).
/// Derived from the definition, not from the sign of `dy`.
pub fn is_top_or_left(a: SubPt, b: SubPt, c: SubPt) -> bool {
    if a.1 == b.1 {
        // Horizontal: top iff the interior (c) is below, rows counted down.
        c.1 > a.1
    } else {
        // x of the edge's line at c's row, compared with c.x:
        //   c.x > a.x + (b.x - a.x) (c.y - a.y) / (b.y - a.y)
        let dy = b.1 as i128 - a.1 as i128;
        let lhs = (c.0 as i128 - a.0 as i128) * dy;
        let rhs = (b.0 as i128 - a.0 as i128) * (c.1 as i128 - a.1 as i128);
        if dy > 0 {
            lhs > rhs
        } else {
            lhs < rhs
        }
    }
}

/// The centre of pixel column (or row) `i` in `Sub<S>` units.
pub fn centre(i: i64, s: u32) -> i64 {
    (i << s) + (1 << (s - 1))
}

/// Whether the point `p` (in `Sub<S>` units) is covered by the triangle `v`
/// under the top-left rule, for either winding. Zero area covers nothing.
pub fn covers(v: [SubPt; 3], p: SubPt) -> bool {
    let area = orient(v[0], v[1], v[2]);
    if area == 0 {
        return false;
    }
    for k in 0..3 {
        let (a, b, c) = (v[k], v[(k + 1) % 3], v[(k + 2) % 3]);
        let mut e = orient(a, b, p);
        if area < 0 {
            e = -e;
        }
        if e < 0 || (e == 0 && !is_top_or_left(a, b, c)) {
            return false;
        }
    }
    true
}

/// Pixel range `[lo, hi]` (clamped to `0..n`) whose centres may lie in
/// `[min, max]` (Sub<S> units), with one pixel of slack each side.
fn pixel_range(min: i64, max: i64, s: u32, n: u32) -> Option<(i64, i64)> {
    let lo = (min >> s) - 1;
    let hi = (max >> s) + 1;
    let lo = lo.max(0);
    let hi = hi.min(n as i64 - 1);
    (lo <= hi).then_some((lo, hi))
}

/// The exact set of pixels covered by the snapped triangle `v` on a
/// `width x height` frame at `s` subpixel bits, row-major, row 0 on top.
pub fn reference_coverage(v: [SubPt; 3], s: u32, width: u32, height: u32) -> Vec<bool> {
    let mut out = vec![false; (width * height) as usize];
    let xs = [v[0].0, v[1].0, v[2].0];
    let ys = [v[0].1, v[1].1, v[2].1];
    let rx = pixel_range(
        *xs.iter().min().unwrap(),
        *xs.iter().max().unwrap(),
        s,
        width,
    );
    let ry = pixel_range(
        *ys.iter().min().unwrap(),
        *ys.iter().max().unwrap(),
        s,
        height,
    );
    let (Some((x0, x1)), Some((y0, y1))) = (rx, ry) else {
        return out;
    };
    for j in y0..=y1 {
        for i in x0..=x1 {
            if covers(v, (centre(i, s), centre(j, s))) {
                out[(j * width as i64 + i) as usize] = true;
            }
        }
    }
    out
}

/// Snaps three clip-space vertices with the core's public `snap`; `None`
/// if one cannot be snapped.
pub fn snap_tri<const S: u32>(pos: &[Vec4; 3], width: u32, height: u32) -> Option<[SubPt; 3]> {
    let mut out = [(0, 0); 3];
    for k in 0..3 {
        let p = pos[k];
        let s = snap::<S>(p.x, p.y, p.z, p.w, width, height)?;
        out[k] = (s.x as i64, s.y as i64);
    }
    Some(out)
}

/// Winding number of the closed polygon `poly` around `p` (exact), and
/// whether `p` lies on one of its edges.
pub fn winding(poly: &[SubPt], p: SubPt) -> (i32, bool) {
    let mut wn = 0;
    for k in 0..poly.len() {
        let (a, b) = (poly[k], poly[(k + 1) % poly.len()]);
        let o = orient(a, b, p);
        if o == 0
            && p.0 >= a.0.min(b.0)
            && p.0 <= a.0.max(b.0)
            && p.1 >= a.1.min(b.1)
            && p.1 <= a.1.max(b.1)
        {
            return (0, true);
        }
        // Crossings of the horizontal ray to +x (window y down: upward
        // crossing is decreasing y).
        if a.1 <= p.1 {
            if b.1 > p.1 && o > 0 {
                wn += 1;
            }
        } else if b.1 <= p.1 && o < 0 {
            wn -= 1;
        }
    }
    (wn, false)
}

// ---------------------------------------------------------------------------
// Building frames
// ---------------------------------------------------------------------------

/// Clip-space `x, y` (with `w = 1`) of the window point `(px, py)` on a
/// `width x height` frame. Exact in `f32` when `width`, `height` are powers
/// of two and `px`, `py` are multiples of `2^-S` of moderate size.
pub fn win_to_clip(px: f64, py: f64, width: u32, height: u32) -> (f32, f32) {
    let x = 2.0 * px / width as f64 - 1.0;
    let y = 1.0 - 2.0 * py / height as f64;
    (x as f32, y as f32)
}

/// A clip-space vertex at window `(px, py)`, `z = 0`, `w = 1`.
pub fn wv(px: f64, py: f64, width: u32, height: u32) -> Vec4 {
    let (x, y) = win_to_clip(px, py, width, height);
    Vec4::new(x, y, 0.0, 1.0)
}

/// A clip-space vertex at window `(px, py)` with NDC depth `z`, every
/// component scaled by `w` (the same window point, seen through a
/// projection).
pub fn wvzw(px: f64, py: f64, z: f64, w: f64, width: u32, height: u32) -> Vec4 {
    let x = 2.0 * px / width as f64 - 1.0;
    let y = 1.0 - 2.0 * py / height as f64;
    Vec4::new((x * w) as f32, (y * w) as f32, (z * w) as f32, w as f32)
}

/// A triangle in window coordinates (`w = 1`, `z = 0`).
pub fn tri_win(p: [(f64, f64); 3], width: u32, height: u32) -> [Vec4; 3] {
    p.map(|(x, y)| wv(x, y, width, height))
}

/// A config with culling off (and the other defaults).
pub fn config_nocull(width: u32, height: u32) -> Config {
    let mut c = Config::new(width, height);
    c.cull = CullMode::None;
    c
}

/// Storage for `n` submitted triangles (7 pieces each at most).
pub fn storage(n: usize) -> Vec<SetupTriangle> {
    vec![SetupTriangle::EMPTY; n * 7 + 1]
}

const WHITE3: [Rgb888; 3] = [Rgb888::new(255, 255, 255); 3];

/// Builds a frame from `tris`, triangle `i` with id `i` (so `TriangleId`
/// `i + 1`), and hands it to `f`.
pub fn with_frame<const S: u32, R>(
    config: Config,
    tris: &[[Vec4; 3]],
    f: impl FnOnce(&Frame<'_, S>) -> R,
) -> R {
    let mut st = storage(tris.len());
    let mut frame = Frame::<S>::with_subpixel_bits(config, &mut st).expect("valid frame");
    for (i, t) in tris.iter().enumerate() {
        frame
            .submit_clip_triangle(*t, WHITE3, i as u32)
            .expect("storage is large enough");
    }
    f(&frame)
}

/// Renders a frame's triangle ids (0 background), whole frame at once.
pub fn frame_ids<const S: u32>(frame: &Frame<'_, S>) -> Vec<u32> {
    let Config { width, height, .. } = *frame.config();
    let mut ids = vec![TriangleId(0); (width * height) as usize];
    frame
        .render_rows(0, height, &mut ids[..], &mut NoDepth)
        .expect("valid rows");
    ids.into_iter().map(|t| t.0).collect()
}

/// Renders a frame's triangle ids through strips of `strip` rows (the last
/// one shorter), each into its own buffer.
pub fn frame_ids_strips<const S: u32>(frame: &Frame<'_, S>, strip: u32) -> Vec<u32> {
    let Config { width, height, .. } = *frame.config();
    let mut out = Vec::with_capacity((width * height) as usize);
    let mut y0 = 0;
    while y0 < height {
        let y1 = (y0 + strip).min(height);
        let mut ids = vec![TriangleId(0); (width * (y1 - y0)) as usize];
        frame
            .render_rows(y0, y1, &mut ids[..], &mut NoDepth)
            .expect("valid rows");
        out.extend(ids.into_iter().map(|t| t.0));
        y0 = y1;
    }
    out
}

/// Renders `tris` (culling per `config`) and returns the id image.
pub fn render_ids<const S: u32>(config: Config, tris: &[[Vec4; 3]]) -> Vec<u32> {
    with_frame::<S, _>(config, tris, frame_ids)
}

/// A depth buffer that counts every fragment the rasterizer tests at each
/// pixel and lets it pass: an overdraw counter that also sees two pieces
/// of one clipped triangle hitting the same pixel.
#[derive(Debug)]
pub struct HitCounter<'a>(pub &'a mut [u32]);

impl DepthBuffer for HitCounter<'_> {
    const ENABLED: bool = true;
    const WIDE: bool = true;
    const FRAC: u32 = 16;

    fn depth_len(&self) -> Option<usize> {
        Some(self.0.len())
    }

    fn test_and_set(&mut self, index: usize, _: u32, _: DepthFunc, _: bool) -> bool {
        match self.0.get_mut(index) {
            Some(c) => {
                *c += 1;
                true
            }
            None => panic!("fragment at index {index} beyond the strip"),
        }
    }
}

/// Per-pixel hit counts: every triangle of `tris` rendered alone into its
/// own frame (only the rows it may touch), every fragment counted (see
/// [`HitCounter`]), the hits summed. Also checks each triangle's fragment
/// count against the pixels written to a `TriangleId` image.
pub fn hit_counts<const S: u32>(config: Config, tris: &[[Vec4; 3]]) -> Vec<u32> {
    let (width, height) = (config.width, config.height);
    let mut counts = vec![0u32; (width * height) as usize];
    let mut st = storage(1);
    for t in tris {
        let mut frame = Frame::<S>::with_subpixel_bits(config, &mut st).expect("valid frame");
        frame.submit_clip_triangle(*t, WHITE3, 0).expect("room");
        let Some(r0) = frame.triangles().iter().map(|t| t.rows().0).min() else {
            continue;
        };
        let r1 = frame.triangles().iter().map(|t| t.rows().1).max().unwrap();
        let (r0, r1) = (r0 as u32, (r1 as u32 + 1).min(height));
        let n = (width * (r1 - r0)) as usize;
        let mut ids = vec![TriangleId(0); n];
        let mut hits = vec![0u32; n];
        let written = frame
            .render_rows(r0, r1, &mut ids[..], &mut HitCounter(&mut hits))
            .expect("valid rows")
            .pixels_written;
        assert_eq!(written, hits.iter().map(|&h| h as u64).sum::<u64>());
        for k in 0..n {
            assert_eq!(
                ids[k].0 != 0,
                hits[k] != 0,
                "id image and fragments disagree"
            );
        }
        let base = (r0 * width) as usize;
        for (k, h) in hits.iter().enumerate() {
            counts[base + k] += h;
        }
    }
    counts
}

/// Coverage of one triangle alone (whole frame) as booleans.
pub fn coverage<const S: u32>(config: Config, tri: [Vec4; 3]) -> Vec<bool> {
    render_ids::<S>(config, &[tri])
        .into_iter()
        .map(|v| v != 0)
        .collect()
}

// ---------------------------------------------------------------------------
// ASCII patterns
// ---------------------------------------------------------------------------

/// The pattern character for triangle id value `id` (1-based).
pub fn label(id: u32) -> char {
    match id {
        0 => '.',
        1..=9 => char::from(b'0' + id as u8),
        10..=35 => char::from(b'a' + (id - 10) as u8),
        _ => '?',
    }
}

/// The ASCII picture of a scene: `.` no hit, the winner's label for one
/// hit, `#` for more than one. Checks that ids and counts agree.
pub fn pattern(ids: &[u32], counts: &[u32], width: u32) -> Vec<String> {
    assert_eq!(ids.len(), counts.len());
    ids.chunks(width as usize)
        .zip(counts.chunks(width as usize))
        .map(|(ir, cr)| {
            ir.iter()
                .zip(cr)
                .map(|(&id, &n)| match n {
                    0 => {
                        assert_eq!(id, 0, "a pixel with no hit has an id");
                        '.'
                    }
                    1 => {
                        assert_ne!(id, 0, "a pixel with a hit has no id");
                        label(id)
                    }
                    _ => '#',
                })
                .collect()
        })
        .collect()
}

/// Renders `tris` at `S` bits with culling off and returns the pattern.
pub fn scene_pattern<const S: u32>(width: u32, height: u32, tris: &[[Vec4; 3]]) -> Vec<String> {
    let cfg = config_nocull(width, height);
    let ids = render_ids::<S>(cfg, tris);
    let counts = hit_counts::<S>(cfg, tris);
    pattern(&ids, &counts, width)
}

/// The pattern the reference rasterizer predicts for `tris` (ids in
/// submission order, later triangles on top).
pub fn reference_pattern<const S: u32>(width: u32, height: u32, tris: &[[Vec4; 3]]) -> Vec<String> {
    let n = (width * height) as usize;
    let mut ids = vec![0u32; n];
    let mut counts = vec![0u32; n];
    for (i, t) in tris.iter().enumerate() {
        let v = snap_tri::<S>(t, width, height).expect("snappable");
        for (k, c) in reference_coverage(v, S, width, height)
            .into_iter()
            .enumerate()
        {
            if c {
                ids[k] = i as u32 + 1;
                counts[k] += 1;
            }
        }
    }
    pattern(&ids, &counts, width)
}

/// Asserts a pattern, printing both pictures side by side on failure.
#[track_caller]
pub fn assert_pattern(actual: &[String], expected: &[&str]) {
    let ok = actual.len() == expected.len() && actual.iter().zip(expected).all(|(a, e)| a == e);
    if !ok {
        let mut msg = String::from("pattern mismatch\n  actual        | expected\n");
        for k in 0..actual.len().max(expected.len()) {
            let a = actual.get(k).map(String::as_str).unwrap_or("");
            let e = expected.get(k).copied().unwrap_or("");
            let mark = if a == e { ' ' } else { '*' };
            msg.push_str(&format!("{mark} {a:<14}| {e}\n"));
        }
        panic!("{msg}");
    }
}

// ---------------------------------------------------------------------------
// Random numbers (deterministic, for table-driven tests)
// ---------------------------------------------------------------------------

/// SplitMix64.
#[derive(Clone, Debug)]
pub struct SplitMix(pub u64);

impl SplitMix {
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Uniform in `[lo, hi)`.
    pub fn range(&mut self, lo: f64, hi: f64) -> f64 {
        lo + (hi - lo) * self.unit()
    }

    /// Uniform integer in `[lo, hi]`.
    pub fn int(&mut self, lo: i64, hi: i64) -> i64 {
        lo + (self.next_u64() % (hi - lo + 1) as u64) as i64
    }
}

// ---------------------------------------------------------------------------
// Geometry oracles in f64
// ---------------------------------------------------------------------------

/// The visible part of a clip-space triangle whose vertices all have
/// `w > 0`, in f64: the projected triangle intersected with
/// `-1 <= z/w <= 1` (z/w is affine over the projected triangle).
pub struct Visible {
    pts: [(f64, f64); 3],
    zs: [f64; 3],
    area: f64,
    len: [f64; 3],
    zgrad: (f64, f64),
}

impl Visible {
    /// `None` for a (numerically) degenerate or non-finite projection.
    pub fn new(pos: &[[f64; 4]; 3], width: u32, height: u32) -> Option<Visible> {
        let (hw, hh) = (width as f64 / 2.0, height as f64 / 2.0);
        let mut pts = [(0.0, 0.0); 3];
        let mut zs = [0.0; 3];
        for k in 0..3 {
            let v = pos[k];
            assert!(v[3] > 0.0, "Visible needs w > 0");
            pts[k] = ((v[0] / v[3] + 1.0) * hw, (1.0 - v[1] / v[3]) * hh);
            zs[k] = v[2] / v[3];
        }
        let area = cross(pts[0], pts[1], pts[2]);
        let mut len = [0.0; 3];
        for k in 0..3 {
            let (a, b) = (pts[(k + 1) % 3], pts[(k + 2) % 3]);
            len[k] = (b.0 - a.0).hypot(b.1 - a.1);
        }
        let scale = len.iter().copied().fold(0.0, f64::max);
        if !area.is_finite() || area.abs() <= 1e-9 * scale * scale || scale.is_nan() {
            return None;
        }
        let mut t = Visible {
            pts,
            zs,
            area,
            len,
            zgrad: (0.0, 0.0),
        };
        // Gradient of z/w per pixel, from the barycentric gradients.
        let mut g = (0.0, 0.0);
        for k in 0..3 {
            let (a, b) = (pts[(k + 1) % 3], pts[(k + 2) % 3]);
            // d/dp of cross(a, b, p) / area.
            let (dx, dy) = (-(b.1 - a.1) / area, (b.0 - a.0) / area);
            g.0 += dx * zs[k];
            g.1 += dy * zs[k];
        }
        t.zgrad = g;
        Some(t)
    }

    /// Signed distance in pixels from window point `p` to the boundary of
    /// the visible part; positive inside.
    pub fn distance(&self, p: (f64, f64)) -> f64 {
        let sign = self.area.signum();
        let mut d = f64::INFINITY;
        let mut z = 0.0;
        for k in 0..3 {
            let (a, b) = (self.pts[(k + 1) % 3], self.pts[(k + 2) % 3]);
            let e = cross(a, b, p);
            z += e / self.area * self.zs[k];
            d = d.min(e * sign / self.len[k]);
        }
        let g = self.zgrad.0.hypot(self.zgrad.1);
        let dz = if g > 0.0 {
            ((z + 1.0) / g).min((1.0 - z) / g)
        } else if (-1.0..=1.0).contains(&z) {
            f64::INFINITY
        } else {
            f64::NEG_INFINITY
        };
        d.min(dz)
    }
}

fn cross(a: (f64, f64), b: (f64, f64), c: (f64, f64)) -> f64 {
    (b.0 - a.0) * (c.1 - a.1) - (b.1 - a.1) * (c.0 - a.0)
}

/// Checks a rendered coverage against [`Visible`]: pixels more than `eps`
/// px inside must be covered, more than `eps` outside must not. A
/// numerically degenerate triangle is skipped. Returns the first few
/// failures.
pub fn check_against_visible(
    pos: &[[f64; 4]; 3],
    width: u32,
    height: u32,
    covered: &[bool],
    eps: f64,
) -> Result<(), String> {
    let Some(vis) = Visible::new(pos, width, height) else {
        return Ok(());
    };
    let mut errs = Vec::new();
    for j in 0..height {
        for i in 0..width {
            let d = vis.distance((i as f64 + 0.5, j as f64 + 0.5));
            let c = covered[(j * width + i) as usize];
            if d > eps && !c {
                errs.push(format!("({i},{j}) missing, {d:.4} px inside"));
            } else if d < -eps && c {
                errs.push(format!("({i},{j}) drawn, {:.4} px outside", -d));
            }
        }
    }
    if errs.is_empty() {
        Ok(())
    } else {
        let n = errs.len();
        errs.truncate(6);
        Err(format!("{n} bad pixels: {}", errs.join("; ")))
    }
}

/// `[f32; 4]` clip positions as `f64`.
pub fn to_f64(pos: &[Vec4; 3]) -> [[f64; 4]; 3] {
    pos.map(|v| [v.x as f64, v.y as f64, v.z as f64, v.w as f64])
}

/// A proptest config with `default` cases unless `PROPTEST_CASES` is set.
pub fn cases(default: u32) -> proptest::test_runner::Config {
    let mut c = proptest::test_runner::Config::default();
    if std::env::var_os("PROPTEST_CASES").is_none() {
        c.cases = default;
    }
    c
}
