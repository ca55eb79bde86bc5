//! Fill-rule tests as ASCII patterns (embedded-graphics `MockDisplay`
//! style): `.` is background, `1`..`9` the triangle submitted first..ninth,
//! `#` a pixel hit twice. Each case is also checked against the exact
//! reference rasterizer in `common`.
//!
//! Conventions under test: pixel centres at +0.5, rows counted from the
//! top, a centre on an edge belongs to the triangle for which the edge is a
//! top edge (horizontal, interior below) or a left edge (interior to the
//! right).

mod common;

use common::*;
use microraster::Vec4;

/// All six orders of a triangle's vertices.
fn permutations(t: [Vec4; 3]) -> [[Vec4; 3]; 6] {
    let [a, b, c] = t;
    [
        [a, b, c],
        [b, c, a],
        [c, a, b],
        [a, c, b],
        [c, b, a],
        [b, a, c],
    ]
}

/// Checks `expected` for every vertex order of every triangle, for both
/// submission orders where the triangles do not overlap, at both subpixel
/// precisions, and that the reference rasterizer agrees.
#[track_caller]
fn check_all_orders(width: u32, height: u32, tris: &[[Vec4; 3]], expected: &[&str]) {
    assert_pattern(&reference_pattern::<8>(width, height, tris), expected);
    assert_pattern(&scene_pattern::<8>(width, height, tris), expected);
    assert_pattern(&scene_pattern::<4>(width, height, tris), expected);
    for (k, t) in tris.iter().enumerate() {
        for p in permutations(*t) {
            let mut scene = tris.to_vec();
            scene[k] = p;
            assert_pattern(&scene_pattern::<8>(width, height, &scene), expected);
            assert_pattern(&scene_pattern::<4>(width, height, &scene), expected);
        }
    }
}

// ---------------------------------------------------------------------------
// Shared diagonals (dEQP fill_rules.basic_quad / basic_quad_reverse)
// ---------------------------------------------------------------------------

/// The square (1,1)-(5,5) split along y = x, which passes through the
/// centres (1.5,1.5) .. (4.5,4.5). The diagonal is a left edge of the
/// upper-right triangle (interior to its right), so those centres are 1's.
#[test]
fn basic_quad_main_diagonal_through_centres() {
    let (w, h) = (8, 8);
    let upper_right = tri_win([(1.0, 1.0), (5.0, 1.0), (5.0, 5.0)], w, h);
    let lower_left = tri_win([(1.0, 1.0), (5.0, 5.0), (1.0, 5.0)], w, h);
    let expected = [
        "........", //
        ".1111...", //
        ".2111...", //
        ".2211...", //
        ".2221...", //
        "........", //
        "........", //
        "........", //
    ];
    check_all_orders(w, h, &[upper_right, lower_left], &expected);
}

/// `basic_quad_reverse`: the same square, the second triangle submitted
/// first and its vertices listed the other way round.
#[test]
fn basic_quad_reverse_main_diagonal_through_centres() {
    let (w, h) = (8, 8);
    let lower_left = tri_win([(1.0, 5.0), (5.0, 5.0), (1.0, 1.0)], w, h);
    let upper_right = tri_win([(5.0, 5.0), (1.0, 1.0), (5.0, 1.0)], w, h);
    let expected = [
        "........", //
        ".2222...", //
        ".1222...", //
        ".1122...", //
        ".1112...", //
        "........", //
        "........", //
        "........", //
    ];
    check_all_orders(w, h, &[lower_left, upper_right], &expected);
}

/// The square split along x + y = 6, through the centres with i + j = 5.
/// The anti-diagonal is a right edge of the upper-left triangle and a left
/// edge of the lower-right one: those centres are 2's.
#[test]
fn basic_quad_anti_diagonal_through_centres() {
    let (w, h) = (8, 8);
    let upper_left = tri_win([(1.0, 1.0), (5.0, 1.0), (1.0, 5.0)], w, h);
    let lower_right = tri_win([(5.0, 1.0), (5.0, 5.0), (1.0, 5.0)], w, h);
    let expected = [
        "........", //
        ".1112...", //
        ".1122...", //
        ".1222...", //
        ".2222...", //
        "........", //
        "........", //
        "........", //
    ];
    check_all_orders(w, h, &[upper_left, lower_right], &expected);
}

/// `basic_quad_reverse` for the anti-diagonal.
#[test]
fn basic_quad_reverse_anti_diagonal_through_centres() {
    let (w, h) = (8, 8);
    let lower_right = tri_win([(1.0, 5.0), (5.0, 5.0), (5.0, 1.0)], w, h);
    let upper_left = tri_win([(1.0, 5.0), (1.0, 1.0), (5.0, 1.0)], w, h);
    let expected = [
        "........", //
        ".2221...", //
        ".2211...", //
        ".2111...", //
        ".1111...", //
        "........", //
        "........", //
        "........", //
    ];
    check_all_orders(w, h, &[lower_right, upper_left], &expected);
}

// ---------------------------------------------------------------------------
// Shared horizontal and vertical edges through centres
// ---------------------------------------------------------------------------

/// Two rectangles x in [1, 7], y in [0.75, 2.5] and [2.5, 4.25], each split
/// on its (1,.)-(7,.) diagonal. The shared edge y = 2.5 runs through the
/// centres of row 2; it is a top edge of the lower rectangle, so row 2 is
/// the lower rectangle's (3's), never both, never neither. The diagonals
/// pass through no centre.
#[test]
fn shared_horizontal_edge_through_pixel_centres() {
    let (w, h) = (8, 6);
    let tris = [
        tri_win([(1.0, 0.75), (7.0, 0.75), (7.0, 2.5)], w, h),
        tri_win([(1.0, 0.75), (7.0, 2.5), (1.0, 2.5)], w, h),
        tri_win([(1.0, 2.5), (7.0, 2.5), (7.0, 4.25)], w, h),
        tri_win([(1.0, 2.5), (7.0, 4.25), (1.0, 4.25)], w, h),
    ];
    let expected = [
        "........", //
        ".222111.", //
        ".333333.", //
        ".444333.", //
        "........", //
        "........", //
    ];
    check_all_orders(w, h, &tris, &expected);
}

/// The transpose of [`shared_horizontal_edge_through_pixel_centres`]: the
/// shared edge x = 2.5 runs through the centres of column 2 and is a left
/// edge of the right-hand rectangle, so column 2 is its (3's).
#[test]
fn shared_vertical_edge_through_pixel_centres() {
    let (w, h) = (6, 8);
    let tris = [
        tri_win([(0.75, 1.0), (0.75, 7.0), (2.5, 7.0)], w, h),
        tri_win([(0.75, 1.0), (2.5, 7.0), (2.5, 1.0)], w, h),
        tri_win([(2.5, 1.0), (2.5, 7.0), (4.25, 7.0)], w, h),
        tri_win([(2.5, 1.0), (4.25, 7.0), (4.25, 1.0)], w, h),
    ];
    let expected = [
        "......", //
        ".234..", //
        ".234..", //
        ".234..", //
        ".133..", //
        ".133..", //
        ".133..", //
        "......", //
    ];
    check_all_orders(w, h, &tris, &expected);
}

/// A rectangle (1.5,1.5)-(5.5,4.5) whose four sides all run through pixel
/// centres: the top row and left column are drawn, the bottom row (4) and
/// right column (5) are not. The diagonal touches a centre only at the
/// top-left corner, which belongs to the triangle for which both edges
/// through it are top or left: the upper-right one.
#[test]
fn rectangle_edges_through_pixel_centres_top_left_included() {
    let (w, h) = (8, 6);
    let tris = [
        tri_win([(1.5, 1.5), (5.5, 1.5), (5.5, 4.5)], w, h),
        tri_win([(1.5, 1.5), (5.5, 4.5), (1.5, 4.5)], w, h),
    ];
    let expected = [
        "........", //
        ".1111...", //
        ".2211...", //
        ".2221...", //
        "........", //
        "........", //
    ];
    check_all_orders(w, h, &tris, &expected);
}

/// Four right triangles meeting at the centre of pixel (1,1) (a
/// pinwheel): exactly one covers it, the one extending right and down (its
/// horizontal leg is a top edge and its vertical leg a left edge).
#[test]
fn four_triangles_meeting_at_a_pixel_centre_cover_it_once() {
    let (w, h) = (4, 4);
    let c = (1.5, 1.5);
    let d = 2.0;
    let corner = |sx: f64, sy: f64| tri_win([c, (c.0 + sx * d, c.1), (c.0, c.1 + sy * d)], w, h);
    // 1: right-down, 2: left-down, 3: left-up, 4: right-up.
    let tris = [
        corner(1.0, 1.0),
        corner(-1.0, 1.0),
        corner(-1.0, -1.0),
        corner(1.0, -1.0),
    ];
    // Pixel (1,1) is the corner: 1's. (1,0) lies on the vertical leg
    // x = 1.5 of 3 and 4 (a left edge of 4); (0,1) on the horizontal leg
    // y = 1.5 of 2 and 3 (a top edge of 2); (2,1) on 1's top leg; (1,2) on
    // 1's left leg. (0,0) is on 3's hypotenuse x + y = 1, a left edge of 3;
    // (0,2) on 2's hypotenuse y = x + 2, a left edge of 2. (2,0) on 4's
    // hypotenuse and (3,1), (2,2) on 1's are right edges: empty.
    let expected = [
        "34..", //
        "211.", //
        "21..", //
        "....", //
    ];
    check_all_orders(w, h, &tris, &expected);
}

// ---------------------------------------------------------------------------
// §1: 3/16-px triangles with a corner on a pixel centre
// ---------------------------------------------------------------------------

/// Whether the centre of pixel (1,1) is covered by the right triangle with
/// its corner at (1.5 + dx, 1.5 + dy) and legs of 3/16 px along sx, sy
/// (window y down). From the definition: the vertical leg is a left edge
/// iff the interior is to its right (sx > 0); the horizontal leg is a top
/// edge iff the interior is below it (sy > 0); the hypotenuse is always
/// more than 1/16 px away.
fn corner_case_expected(sx: i32, sy: i32, dx: i32, dy: i32) -> bool {
    // Centre relative to the corner, in units of the shift, along the legs.
    let a = -dx * sx;
    let b = -dy * sy;
    (a > 0 || (a == 0 && sx > 0)) && (b > 0 || (b == 0 && sy > 0))
}

fn corner_cases<const S: u32>(shift: f64) {
    let (w, h) = (4, 4);
    let leg = 3.0 / 16.0;
    let mut checked = 0;
    for (sx, sy) in [(1, 1), (-1, 1), (-1, -1), (1, -1)] {
        for dx in -1..=1 {
            for dy in -1..=1 {
                let c = (1.5 + dx as f64 * shift, 1.5 + dy as f64 * shift);
                let t = tri_win(
                    [
                        c,
                        (c.0 + sx as f64 * leg, c.1),
                        (c.0, c.1 + sy as f64 * leg),
                    ],
                    w,
                    h,
                );
                let want = corner_case_expected(sx, sy, dx, dy);
                for p in permutations(t) {
                    let cov = coverage::<S>(config_nocull(w, h), p);
                    let expected: Vec<bool> = (0..16).map(|k| want && k == 5).collect();
                    assert_eq!(
                        cov,
                        expected,
                        "S={S} legs ({sx},{sy}) shift ({dx},{dy})*{shift}: expected pixel (1,1) {}",
                        if want { "covered" } else { "empty" }
                    );
                    let v = snap_tri::<S>(&p, w, h).unwrap();
                    assert_eq!(reference_coverage(v, S, w, h), expected);
                }
                checked += 1;
            }
        }
    }
    assert_eq!(checked, 36);
}

/// §1 at 4 subpixel bits: the 36 cases, shifts of -1/16, 0, +1/16 px (one
/// subpixel), all vertex orders.
#[test]
fn vertex_on_pixel_centre_3_16_px_triangles_s4() {
    corner_cases::<4>(1.0 / 16.0);
}

/// §1 at 8 subpixel bits with the same 1/16-px shifts.
#[test]
fn vertex_on_pixel_centre_3_16_px_triangles_s8() {
    corner_cases::<8>(1.0 / 16.0);
}

/// §1 at 8 subpixel bits with shifts of one subpixel (1/256 px).
#[test]
fn vertex_on_pixel_centre_3_16_px_triangles_s8_one_subpixel_shift() {
    corner_cases::<8>(1.0 / 256.0);
}

// ---------------------------------------------------------------------------
// §10: sampling at pixel centres
// ---------------------------------------------------------------------------

/// Draws the 10x10 rectangle at (2 + ox, 2 + oy) on a 16x16 frame and
/// checks it covers exactly the 10x10 block starting at (c0, r0), with a
/// background border and background everywhere else.
fn fragment_centre_case<const S: u32>(ox: f64, oy: f64, c0: u32, r0: u32) {
    let (w, h) = (16, 16);
    let (x0, y0) = (2.0 + ox, 2.0 + oy);
    let (x1, y1) = (x0 + 10.0, y0 + 10.0);
    let tris = [
        tri_win([(x0, y0), (x1, y0), (x1, y1)], w, h),
        tri_win([(x0, y0), (x1, y1), (x0, y1)], w, h),
    ];
    let cfg = config_nocull(w, h);
    let counts = hit_counts::<S>(cfg, &tris);
    for j in 0..h {
        for i in 0..w {
            let inside = (c0..c0 + 10).contains(&i) && (r0..r0 + 10).contains(&j);
            assert_eq!(
                counts[(j * w + i) as usize],
                inside as u32,
                "S={S} offset ({ox},{oy}): pixel ({i},{j})"
            );
        }
    }
}

/// §10: offsets 0, 0.2, ..., 1.0 px in each axis (36 rectangles). The
/// covered block moves by exactly one pixel once the offset passes 0.5.
#[test]
fn fragment_centre_rectangles_offsets_0_to_1() {
    let offs = [0.0, 0.2, 0.4, 0.6, 0.8, 1.0];
    for &ox in &offs {
        for &oy in &offs {
            let c0 = 2 + (ox > 0.5) as u32;
            let r0 = 2 + (oy > 0.5) as u32;
            fragment_centre_case::<8>(ox, oy, c0, r0);
            fragment_centre_case::<4>(ox, oy, c0, r0);
        }
    }
}

/// §10 at exactly 0.5: the left side x = 2.5 and top side y = 2.5 run
/// through centres and are included (left / top edges), the right side
/// x = 12.5 and bottom y = 12.5 are excluded. So the block does NOT move
/// yet: columns 2..=11 and rows 2..=11, as at offset 0.
#[test]
fn fragment_centre_rectangle_offset_exactly_half() {
    for (ox, oy) in [(0.5, 0.0), (0.0, 0.5), (0.5, 0.5)] {
        fragment_centre_case::<8>(ox, oy, 2, 2);
        fragment_centre_case::<4>(ox, oy, 2, 2);
    }
}

// ---------------------------------------------------------------------------
// §3: rotated split squares (basic_quad, basic_quad_reverse, projected,
// clipped_partly, clipped_full)
// ---------------------------------------------------------------------------

/// The two triangles of the quad `q` split on diagonal `diag` (0: q0-q2,
/// 1: q1-q3); `reverse` lists the second one's vertices the other way
/// round (and starting elsewhere).
fn split_quad(q: [Vec4; 4], diag: usize, reverse: bool) -> [[Vec4; 3]; 2] {
    let [a, b, c, d] = if diag == 0 {
        q
    } else {
        [q[1], q[2], q[3], q[0]]
    };
    let first = [a, b, c];
    let second = if reverse { [c, a, d] } else { [a, c, d] };
    [first, second]
}

/// Hit counts of the split quad vs its snapped outline: pixels strictly
/// inside are hit once (no holes, no double hits on the diagonal), pixels
/// strictly outside never, pixels on the outline at most once. Returns
/// (double hits, holes, strays).
fn split_quad_errors<const S: u32>(
    width: u32,
    height: u32,
    q: [Vec4; 4],
    diag: usize,
    reverse: bool,
) -> (usize, usize, usize) {
    let tris = split_quad(q, diag, reverse);
    let counts = hit_counts::<S>(config_nocull(width, height), &tris);
    let snapped: Vec<SubPt> = q
        .iter()
        .map(|v| {
            let s = microraster::fixed::snap::<S>(v.x, v.y, v.z, v.w, width, height).unwrap();
            (s.x as i64, s.y as i64)
        })
        .collect();
    let sigma = orient(snapped[0], snapped[1], snapped[2]).signum();
    for k in 0..4 {
        assert_eq!(
            orient(snapped[k], snapped[(k + 1) % 4], snapped[(k + 2) % 4]).signum(),
            sigma,
            "test quad must stay convex after snapping"
        );
    }
    let (mut double, mut holes, mut strays) = (0, 0, 0);
    for j in 0..height as i64 {
        for i in 0..width as i64 {
            let p = (centre(i, S), centre(j, S));
            let e: Vec<i128> = (0..4)
                .map(|k| sigma * orient(snapped[k], snapped[(k + 1) % 4], p))
                .collect();
            let n = counts[(j * width as i64 + i) as usize];
            if n > 1 {
                double += 1;
            }
            if e.iter().all(|&v| v > 0) && n != 1 {
                holes += 1;
            }
            if e.iter().any(|&v| v < 0) && n != 0 {
                strays += 1;
            }
        }
    }
    (double, holes, strays)
}

/// A square centred at window (cx, cy), half-side r px, rotated by `a`;
/// vertex k scaled by `ws[k]` (all components).
fn square(cx: f64, cy: f64, r: f64, a: f64, ws: [f64; 4], width: u32, height: u32) -> [Vec4; 4] {
    let (s, c) = a.sin_cos();
    let corners = [(-r, -r), (r, -r), (r, r), (-r, r)];
    let mut out = [Vec4::new(0.0, 0.0, 0.0, 1.0); 4];
    for k in 0..4 {
        let (u, v) = corners[k];
        let px = cx + u * c - v * s;
        let py = cy + u * s + v * c;
        out[k] = wvzw(px, py, 0.0, ws[k], width, height);
    }
    out
}

/// Runs split squares over `angles` angles in [0, 90] degrees, centred on
/// a 4x4 grid (jittered), both diagonals, both vertex orders, at S = 4 and
/// S = 8, with per-vertex w from `wgen`.
fn rotated_squares(
    angles: usize,
    reverse: bool,
    seed: u64,
    mut wgen: impl FnMut(&mut SplitMix) -> [f64; 4],
) {
    let (w, h) = (128, 128);
    let mut rng = SplitMix(seed);
    let mut cases = 0;
    for k in 0..angles {
        let a = (k as f64 / (angles - 1) as f64) * std::f64::consts::FRAC_PI_2;
        let cell = k % 16;
        let cx = 16.0 + 32.0 * (cell % 4) as f64 + rng.range(-2.0, 2.0);
        let cy = 16.0 + 32.0 * (cell / 4) as f64 + rng.range(-2.0, 2.0);
        // Half-side 0.15 NDC on 128 px: 9.6 px.
        let r = 9.6 + rng.range(-0.5, 0.5);
        let ws = wgen(&mut rng);
        let q = square(cx, cy, r, a, ws, w, h);
        for diag in 0..2 {
            let e8 = split_quad_errors::<8>(w, h, q, diag, reverse);
            let e4 = split_quad_errors::<4>(w, h, q, diag, reverse);
            assert_eq!(
                (e8, e4),
                ((0, 0, 0), (0, 0, 0)),
                "angle {:.3} deg, diag {diag}, reverse {reverse}, w {ws:?}: (double hits, holes, strays) at S=8, S=4",
                a.to_degrees()
            );
            cases += 1;
        }
    }
    assert_eq!(cases, angles * 2);
}

/// §3 `basic_quad`: rotated split squares, 0 double hits and 0 holes.
#[test]
fn rotated_split_squares_basic_quad() {
    rotated_squares(91, false, 1, |_| [1.0; 4]);
}

/// §3 `basic_quad_reverse`: the second triangle's vertex order reversed.
#[test]
fn rotated_split_squares_basic_quad_reverse() {
    rotated_squares(91, true, 2, |_| [1.0; 4]);
}

/// §3 `projected`: every vertex scaled by a random w in [0.1, 4].
#[test]
fn rotated_split_squares_projected_random_w() {
    let wg = |r: &mut SplitMix| [0; 4].map(|_| r.range(0.1, 4.0));
    rotated_squares(91, false, 3, wg);
    rotated_squares(91, true, 4, wg);
}

/// §3 `clipped_partly`: a square of side 2 NDC centred at (0.5, 0.5),
/// rotated over many steps on a 64x64 frame; part of it lies outside.
#[test]
fn rotated_split_square_clipped_partly() {
    let (w, h) = (64, 64);
    let mut rng = SplitMix(5);
    for k in 0..30 {
        let a = k as f64 * std::f64::consts::FRAC_PI_2 / 29.0;
        let ws = [0; 4].map(|_| rng.range(0.5, 2.0));
        // Centre (0.5, 0.5) NDC is window (48, 16); side 2 NDC = 64 px.
        let q = square(48.0, 16.0, 32.0, a, ws, w, h);
        for diag in 0..2 {
            for reverse in [false, true] {
                let e8 = split_quad_errors::<8>(w, h, q, diag, reverse);
                let e4 = split_quad_errors::<4>(w, h, q, diag, reverse);
                assert_eq!((e8, e4), ((0, 0, 0), (0, 0, 0)), "step {k}");
            }
        }
    }
}

/// §3 `clipped_full`: a square of side 4 NDC centred at the origin covers
/// the whole frame: every pixel exactly once, at any rotation. Also with
/// a square far beyond the guard band (half-side 1e5 NDC), which the core
/// clips against the guard band.
#[test]
fn rotated_split_square_clipped_full() {
    let (w, h) = (64, 64);
    let mut rng = SplitMix(6);
    for half_ndc in [2.0, 1.0e5] {
        for k in 0..30 {
            let a = k as f64 * std::f64::consts::FRAC_PI_2 / 29.0;
            let ws = [0; 4].map(|_| rng.range(0.5, 2.0));
            let q = square(32.0, 32.0, half_ndc * 32.0, a, ws, w, h);
            for diag in 0..2 {
                for reverse in [false, true] {
                    let tris = split_quad(q, diag, reverse);
                    for counts in [
                        hit_counts::<8>(config_nocull(w, h), &tris),
                        hit_counts::<4>(config_nocull(w, h), &tris),
                    ] {
                        let bad = counts.iter().filter(|&&n| n != 1).count();
                        assert_eq!(
                            bad, 0,
                            "half-side {half_ndc} NDC, step {k}, diag {diag}, reverse {reverse}"
                        );
                    }
                }
            }
        }
    }
}
