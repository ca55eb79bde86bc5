//! Named hard cases: w <= 0, slivers, edges through centres, huge
//! coordinates and guard-band clipping (RASTER_TEST_CASES §7, §8), near/far
//! planes (§9), bad input, culling (§5), buffer and frame-size errors,
//! storage limits, extreme frame sizes, depth exactness, perspective-correct
//! colour (§6) and depth functions.

mod common;

use common::*;
use microraster::fixed::{snap, MAX_DIMENSION};
use microraster::pixelcolor::Rgb888;
use microraster::{
    BoundingSphere, Config, CullMode, DepthFunc, Error, Frame, FrontFace, Mat4, Mesh, MeshColors,
    NoDepth, ProcessedVertex, SetupTriangle, Stats, TriangleId, Vec3, Vec4,
};

const RED3: [Rgb888; 3] = [Rgb888::new(255, 0, 0); 3];

fn v(x: f32, y: f32, z: f32, w: f32) -> Vec4 {
    Vec4::new(x, y, z, w)
}

/// Pushes `tris` (ids 0..) into a frame at `S` bits and returns its stats
/// and id image.
fn run<const S: u32>(cfg: Config, tris: &[[Vec4; 3]]) -> (Stats, Vec<u32>) {
    with_frame::<S, _>(cfg, tris, |f| (f.stats(), frame_ids(f)))
}

fn count(ids: &[u32]) -> usize {
    ids.iter().filter(|&&i| i != 0).count()
}

// ---------------------------------------------------------------------------
// w <= 0
// ---------------------------------------------------------------------------

/// (-0.5,-0.5,0,1), (0.5,-0.5,0,1), (0,-0.5,0,-1) on 64x64, culling off:
/// the part with w > 0 is the wedge below NDC y = -0.5 (window row 48),
/// widening downwards: row j covers the columns whose centre is within
/// (j - 15.5) / 2 px of x = 32, i.e. 32, 34, 34, ..., 46, 46, 48 pixels:
/// 640 in all, nothing above row 48 (not an upright mirrored triangle).
#[test]
fn w_le_0_wedge_covers_640_pixels() {
    let tri = [
        v(-0.5, -0.5, 0.0, 1.0),
        v(0.5, -0.5, 0.0, 1.0),
        v(0.0, -0.5, 0.0, -1.0),
    ];
    let expected: Vec<u32> = (0..64 * 64)
        .map(|k| {
            let (i, j) = ((k % 64) as f64, (k / 64) as f64);
            (j >= 48.0 && (i + 0.5 - 32.0).abs() <= (j - 15.5) / 2.0) as u32
        })
        .collect();
    assert_eq!(expected.iter().sum::<u32>(), 640);
    for order in [tri, [tri[2], tri[0], tri[1]], [tri[1], tri[0], tri[2]]] {
        let (_, ids8) = run::<8>(config_nocull(64, 64), &[order]);
        let (_, ids4) = run::<4>(config_nocull(64, 64), &[order]);
        for ids in [ids8, ids4] {
            assert_eq!(count(&ids), 640);
            assert_eq!(count(&ids[..48 * 64]), 0, "nothing above row 48");
            assert_eq!(ids, expected);
        }
        let counts = hit_counts::<8>(config_nocull(64, 64), &[order]);
        assert!(counts.iter().all(|&n| n <= 1), "clipped pieces overlap");
    }
}

/// A triangle with all three vertices behind the eye (w < 0) draws
/// nothing, whatever x, y, z are, and stores nothing.
#[test]
fn all_vertices_behind_the_eye_draw_nothing() {
    let mut rng = SplitMix(11);
    for _ in 0..2000 {
        let mut tri = [v(0.0, 0.0, 0.0, 1.0); 3];
        for t in tri.iter_mut() {
            let w = -rng.range(0.05, 4.0) as f32;
            let r = |rng: &mut SplitMix| rng.range(-3.0, 3.0) as f32 * w.abs();
            *t = v(r(&mut rng), r(&mut rng), r(&mut rng), w);
        }
        // Also the mirror image of a visible triangle.
        let mirror = [
            v(0.5, 0.5, 0.0, -1.0),
            v(-0.5, 0.5, 0.0, -1.0),
            v(0.0, -0.5, 0.0, -1.0),
        ];
        for t in [tri, mirror] {
            let (s8, ids8) = run::<8>(config_nocull(32, 32), &[t]);
            let (s4, ids4) = run::<4>(config_nocull(32, 32), &[t]);
            assert_eq!((count(&ids8), count(&ids4)), (0, 0), "{t:?}");
            assert_eq!((s8.stored, s4.stored), (0, 0), "{t:?}");
        }
    }
}

// ---------------------------------------------------------------------------
// Slivers and edges through pixel centres
// ---------------------------------------------------------------------------

/// §4's near-collinear slivers: the square [-0.9, 0.9]^2 tiled by 8
/// triangles around two slivers whose tips are x = -0.499 and x = -0.501
/// (one each side of x = -0.5); rotated and projected (shared vertices
/// share w). Every pixel strictly inside the snapped square is hit exactly
/// once, nothing outside, nothing twice.
#[test]
fn slivers_never_double_hit_neighbours() {
    let (w, h) = (64u32, 64u32);
    let mut rng = SplitMix(12);
    let base = [
        (-0.5, -0.9),  // 0: P0
        (-0.499, 0.0), // 1: P1
        (-0.5, 0.9),   // 2: P2
        (-0.501, 0.0), // 3: P3
        (-0.9, -0.9),  // 4: BL
        (0.9, -0.9),   // 5: BR
        (0.9, 0.9),    // 6: TR
        (-0.9, 0.9),   // 7: TL
    ];
    let idx = [
        [0, 1, 2], // sliver right of x = -0.5
        [0, 2, 3], // sliver left of it
        [0, 3, 4],
        [3, 7, 4],
        [3, 2, 7],
        [0, 5, 1],
        [1, 5, 6],
        [1, 6, 2],
    ];
    for step in 0..60 {
        let a = step as f64 * std::f64::consts::TAU / 60.0 * if step % 2 == 0 { 1.0 } else { 0.01 };
        let (s, c) = a.sin_cos();
        let projected = step >= 20;
        let verts: Vec<Vec4> = base
            .iter()
            .map(|&(x, y)| {
                let (xr, yr) = (x * c - y * s, x * s + y * c);
                let ww = if projected { rng.range(0.1, 4.0) } else { 1.0 };
                Vec4::new((xr * ww) as f32, (yr * ww) as f32, 0.0, ww as f32)
            })
            .collect();
        let tris: Vec<[Vec4; 3]> = idx.iter().map(|t| t.map(|k| verts[k])).collect();
        // The outline, with P0 and P2 on the bottom and top sides (after
        // snapping they need not lie exactly on the corner-to-corner lines).
        let outline: Vec<SubPt> = [4usize, 0, 5, 6, 2, 7]
            .iter()
            .map(|&k| {
                let p = verts[k];
                let s = snap::<8>(p.x, p.y, p.z, p.w, w, h).unwrap();
                (s.x as i64, s.y as i64)
            })
            .collect();
        let counts = hit_counts::<8>(config_nocull(w, h), &tris);
        for j in 0..h as i64 {
            for i in 0..w as i64 {
                let (wn, on) = winding(&outline, (centre(i, 8), centre(j, 8)));
                let n = counts[(j * w as i64 + i) as usize];
                assert!(n <= 1, "step {step}: pixel ({i},{j}) hit {n} times");
                if !on {
                    assert_eq!(
                        n,
                        wn.unsigned_abs(),
                        "step {step}: pixel ({i},{j}), winding {wn}"
                    );
                }
            }
        }
    }
}

/// Pairs of triangles sharing an edge between two pixel centres, at slopes
/// dy/dx with small integers (so the edge passes through many centres), the
/// third vertices on either side: each centre on the shared edge is
/// covered exactly once, and each triangle matches the reference.
#[test]
fn edges_through_pixel_centres_are_covered_once() {
    let (w, h) = (32u32, 32u32);
    let mut rng = SplitMix(13);
    let mut on_edge_checked = 0;
    for _ in 0..400 {
        let (dx, dy) = (rng.int(-4, 4), rng.int(-4, 4));
        if dx == 0 && dy == 0 {
            continue;
        }
        let k = rng.int(2, 6);
        let (ax, ay) = (rng.int(4, 12), rng.int(4, 12));
        let a = (ax as f64 + 0.5, ay as f64 + 0.5);
        let b = (a.0 + (dx * k) as f64, a.1 + (dy * k) as f64);
        let mid = ((a.0 + b.0) / 2.0, (a.1 + b.1) / 2.0);
        let n = (-(dy as f64), dx as f64);
        let off = |s: f64, rng: &mut SplitMix| {
            let t = rng.range(1.0, 6.0) * s;
            let u = rng.range(-3.0, 3.0);
            (mid.0 + n.0 * t + u, mid.1 + n.1 * t + u * 0.3)
        };
        let c = off(1.0, &mut rng);
        let d = off(-1.0, &mut rng);
        let t1 = tri_win([a, b, c], w, h);
        let t2 = if rng.unit() < 0.5 {
            tri_win([b, a, d], w, h)
        } else {
            tri_win([a, b, d], w, h)
        };
        for s4 in [false, true] {
            let counts = if s4 {
                hit_counts::<4>(config_nocull(w, h), &[t1, t2])
            } else {
                hit_counts::<8>(config_nocull(w, h), &[t1, t2])
            };
            for m in 0..=k {
                let (i, j) = (ax + dx * m, ay + dy * m);
                if m == 0 || m == k || i < 0 || j < 0 || i >= w as i64 || j >= h as i64 {
                    continue;
                }
                assert_eq!(
                    counts[(j * w as i64 + i) as usize],
                    1,
                    "centre ({i},{j}) on shared edge"
                );
                on_edge_checked += 1;
            }
            assert!(counts.iter().all(|&n| n <= 1));
        }
        for t in [t1, t2] {
            let cov = coverage::<8>(config_nocull(w, h), t);
            assert_eq!(
                cov,
                reference_coverage(snap_tri::<8>(&t, w, h).unwrap(), 8, w, h)
            );
        }
    }
    assert!(on_edge_checked > 1000);
}

// ---------------------------------------------------------------------------
// Huge coordinates, clipping, guard band (§7, §8)
// ---------------------------------------------------------------------------

/// Checks one clip-space triangle (all w > 0) at both precisions against
/// the f64 geometry of its visible part, with a band of 2 subpixels.
/// Returns the geometry errors and, separately, the number of pixels hit
/// twice by the triangle's own clipped pieces.
fn check_geometry(tri: [Vec4; 3], width: u32, height: u32) -> (Result<(), String>, usize) {
    let pos = to_f64(&tri);
    let mut doubles = 0;
    for s4 in [false, true] {
        let cfg = config_nocull(width, height);
        let (ids, counts) = if s4 {
            (render_ids::<4>(cfg, &[tri]), hit_counts::<4>(cfg, &[tri]))
        } else {
            (render_ids::<8>(cfg, &[tri]), hit_counts::<8>(cfg, &[tri]))
        };
        doubles += counts.iter().filter(|&&n| n > 1).count();
        let cov: Vec<bool> = ids.iter().map(|&i| i != 0).collect();
        let eps = if s4 { 2.0 / 16.0 } else { 2.0 / 256.0 };
        if let Err(e) = check_against_visible(&pos, width, height, &cov, eps) {
            return (Err(format!("S4={s4}: {e}")), doubles);
        }
    }
    (Ok(()), doubles)
}

/// The §7 cases: one, two or three vertices at 30,000 x w along the 26
/// directions, the others near the centre, each with its own w.
fn clip_cases_30000() -> Vec<[Vec4; 3]> {
    let dirs = directions();
    let mut rng = SplitMix(21);
    let near = |rng: &mut SplitMix| {
        let w = rng.range(0.2, 16.0);
        let c = |rng: &mut SplitMix| rng.range(-0.5, 0.5) * w;
        Vec4::new(c(rng) as f32, c(rng) as f32, c(rng) as f32, w as f32)
    };
    let far = |d: [f32; 3], rng: &mut SplitMix| {
        let w = rng.range(0.2, 16.0) as f32;
        Vec4::new(
            30000.0 * d[0] * w,
            30000.0 * d[1] * w,
            30000.0 * d[2] * w,
            w,
        )
    };
    let mut cases = vec![];
    for d in &dirs {
        cases.push([far(*d, &mut rng), near(&mut rng), near(&mut rng)]);
    }
    for (a, d1) in dirs.iter().enumerate() {
        for d2 in &dirs[a + 1..] {
            cases.push([far(*d1, &mut rng), far(*d2, &mut rng), near(&mut rng)]);
        }
    }
    for _ in 0..300 {
        let pick = |rng: &mut SplitMix| dirs[rng.int(0, 25) as usize];
        let (d1, d2, d3) = (pick(&mut rng), pick(&mut rng), pick(&mut rng));
        cases.push([far(d1, &mut rng), far(d2, &mut rng), far(d3, &mut rng)]);
    }
    let mut out = vec![];
    for t in cases {
        out.extend([t, [t[1], t[2], t[0]], [t[0], t[2], t[1]]]);
    }
    out
}

/// Random triangles with vertices in [-3, 3]^3 NDC (every third one with
/// a vertex just 0.01 past x, y or z = ±1), each vertex with its own w.
fn random_clip_cases() -> Vec<[Vec4; 3]> {
    let mut rng = SplitMix(22);
    (0..1500)
        .map(|n| {
            let mut tri = [v(0.0, 0.0, 0.0, 1.0); 3];
            for t in tri.iter_mut() {
                let w = rng.range(0.2, 16.0);
                let mut c = [
                    rng.range(-3.0, 3.0),
                    rng.range(-3.0, 3.0),
                    rng.range(-3.0, 3.0),
                ];
                if n % 3 == 0 {
                    let axis = rng.int(0, 2) as usize;
                    c[axis] = if rng.unit() < 0.5 { 1.01 } else { -1.01 };
                }
                *t = Vec4::new(
                    (c[0] * w) as f32,
                    (c[1] * w) as f32,
                    (c[2] * w) as f32,
                    w as f32,
                );
            }
            tri
        })
        .collect()
}

/// The 26 directions of {-1, 0, 1}^3 \ {0}.
fn directions() -> Vec<[f32; 3]> {
    let mut out = vec![];
    for x in -1..=1 {
        for y in -1..=1 {
            for z in -1..=1 {
                if (x, y, z) != (0, 0, 0) {
                    out.push([x as f32, y as f32, z as f32]);
                }
            }
        }
    }
    out
}

/// §7 `triangle_vertex.clip_one/two/three`: one, two or three vertices at
/// 30,000 along the 26 directions (so outside one, two or three clip
/// planes and far beyond the guard band), the others near the centre,
/// every vertex scaled by a random w in [0.2, 16], three vertex orders. No
/// panic, and the image is the visible part of the geometric triangle
/// (within 2 subpixels). (Overdraw between the clipped pieces is checked by
/// `clipped_pieces_never_overlap`.)
#[test]
fn clip_one_two_three_vertices_at_30000_w_26_directions() {
    let cases = clip_cases_30000();
    let fails: Vec<String> = cases
        .iter()
        .filter_map(|t| {
            check_geometry(*t, 64, 64)
                .0
                .err()
                .map(|e| format!("{t:?}: {e}"))
        })
        .collect();
    assert!(
        fails.is_empty(),
        "{} of {} failed, e.g.\n{}",
        fails.len(),
        cases.len(),
        fails[..fails.len().min(5)].join("\n")
    );
}

/// §7 `clip_pos_z` / `clip_neg_z`, `polygon` cases beyond ±1 and edges
/// 0.01 beyond a plane: random triangles with vertices in [-3, 3]^3 NDC,
/// a few pushed just past x, y or z = ±1, every vertex with its own w.
#[test]
fn random_clipped_triangles_match_geometry() {
    let cases = random_clip_cases();
    let fails: Vec<String> = cases
        .iter()
        .filter_map(|t| {
            check_geometry(*t, 32, 32)
                .0
                .err()
                .map(|e| format!("{t:?}: {e}"))
        })
        .collect();
    assert!(
        fails.is_empty(),
        "{} failed, e.g.\n{}",
        fails.len(),
        fails[..fails.len().min(5)].join("\n")
    );
}

/// The pieces a clipped triangle is cut into never cover a pixel twice
/// (§7's polygon-edge overdraw check), over the §7 and random clip cases.
#[test]
fn clipped_pieces_never_overlap() {
    let mut bad = vec![];
    for (t, (w, h)) in clip_cases_30000()
        .into_iter()
        .map(|t| (t, (64, 64)))
        .chain(random_clip_cases().into_iter().map(|t| (t, (32, 32))))
    {
        let doubles = check_geometry(t, w, h).1;
        if doubles > 0 {
            bad.push(format!("{t:?}: {doubles} pixels hit twice"));
        }
    }
    assert!(
        bad.is_empty(),
        "{} triangles, e.g.\n{}",
        bad.len(),
        bad[..bad.len().min(5)].join("\n")
    );
}

/// Minimal repro: one triangle crossing the near and far planes on a 32x32
/// frame at S = 4 is clipped into two pieces with opposite windings after
/// snapping; pixels (21, 11) and (19, 12) are drawn twice.
#[test]
fn clipped_piece_with_flipped_winding_double_hits() {
    let tri = [
        v(-14.132449, -6.184573, -19.484907, 9.548645),
        v(32.9435, 18.312862, -27.085337, 14.905867),
        v(-12.194808, -4.7609706, 16.46872, 13.41653),
    ];
    let counts = hit_counts::<4>(config_nocull(32, 32), &[tri]);
    let doubles: Vec<usize> = (0..counts.len()).filter(|&k| counts[k] > 1).collect();
    assert!(
        doubles.is_empty(),
        "pixels hit twice: {:?}",
        doubles.iter().map(|k| (k % 32, k / 32)).collect::<Vec<_>>()
    );
}

/// The quadrant x >= -0.5, y >= -0.5 (NDC) drawn as a right triangle whose
/// other vertices are at x = X and y = X: for every X from 3 (already
/// off-screen) to 1e5, 1e30 and f32::MAX the image is the same, columns
/// 16.. and rows ..48 of 64x64 (2304 pixels); mirrored too, and with all
/// components scaled by w where that stays finite.
#[test]
fn huge_coordinates_give_the_same_image_as_small_off_screen_ones() {
    let mut rng = SplitMix(23);
    let quadrant: Vec<u32> = (0..64 * 64)
        .map(|k| ((k % 64) >= 16 && (k / 64) < 48) as u32)
        .collect();
    let mirrored: Vec<u32> = (0..64 * 64)
        .map(|k| ((k % 64) < 48 && (k / 64) >= 16) as u32)
        .collect();
    for x in [3.0f32, 100.0, 1.0e5, 1.0e6, 1.0e30, f32::MAX] {
        for (sign, expected) in [(1.0f32, &quadrant), (-1.0, &mirrored)] {
            let a = -0.5 * sign;
            let mut scales = vec![1.0f32];
            if x <= 1.0e30 {
                scales.extend([rng.range(0.2, 16.0) as f32, 1.0e-3, 1.0e4]);
            }
            for ws in scales {
                let tri = [
                    v(a * ws, a * ws, 0.0, ws),
                    v(sign * x * ws, a * ws, 0.0, ws),
                    v(a * ws, sign * x * ws, 0.0, ws),
                ];
                for (s4, ids) in [
                    (false, render_ids::<8>(config_nocull(64, 64), &[tri])),
                    (true, render_ids::<4>(config_nocull(64, 64), &[tri])),
                ] {
                    assert_eq!(
                        &ids,
                        expected,
                        "X = {x}, sign {sign}, w {ws}, S4 = {s4}: {} pixels",
                        count(&ids)
                    );
                }
            }
        }
    }
}

/// Coordinates of opposite sign near ±f32::MAX (whose difference overflows
/// f32): the band -0.5 <= y < 0.5 NDC between (-X, -0.5), (X, -0.5) and
/// (0, 0.5) is rows 16..48 of 64x64 for every X.
#[test]
fn opposite_huge_coordinates_draw_the_band() {
    for x in [1.0e30f32, 1.0e38, f32::MAX] {
        let tri = [
            v(-x, -0.5, 0.0, 1.0),
            v(x, -0.5, 0.0, 1.0),
            v(0.0, 0.5, 0.0, 1.0),
        ];
        let (s, ids) = run::<8>(config_nocull(64, 64), &[tri]);
        assert_eq!(count(&ids), 32 * 64, "X = {x}: {s:?}");
        assert!(ids[..16 * 64]
            .iter()
            .chain(&ids[48 * 64..])
            .all(|&i| i == 0));
        check_geometry(tri, 64, 64).0.unwrap();
    }
}

/// Two clip-space triangles whose vertices carry very different
/// homogeneous scales `scale` and 1: NDC (0,0), (1e5,-0.5) beyond the guard
/// band, (0,0.5); and NDC (0,0) on the far plane, (0.5,0) behind the near
/// plane, (0,0.5). Returns the scales that fail, with the reason.
fn huge_w_failures(scales: &[f32]) -> Vec<String> {
    let mut bad = vec![];
    for &scale in scales {
        let guard = [
            v(0.0, 0.0, 0.0, scale),
            v(1.0e5, -0.5, 0.0, 1.0),
            v(0.0, 0.5 * scale, 0.0, scale),
        ];
        let far = [
            v(0.0, 0.0, scale, scale),
            v(0.5, 0.0, -3.0, 1.0),
            v(0.0, 0.5, 0.0, 1.0),
        ];
        for (name, tri, min_px) in [("guard", guard, 300), ("far/near", far, 10)] {
            let (s, ids) = run::<8>(config_nocull(64, 64), &[tri]);
            if count(&ids) < min_px {
                bad.push(format!(
                    "{name} scale {scale:e}: {} pixels, {s:?}",
                    count(&ids)
                ));
            } else if let Err(e) = check_geometry(tri, 64, 64).0 {
                bad.push(format!("{name} scale {scale:e}: {e}"));
            }
        }
    }
    bad
}

/// Vertices of one triangle at homogeneous scales differing by up to 1e7
/// (one of them beyond the guard band or behind the near plane): the image
/// is the geometric one.
#[test]
fn vertices_with_w_ratio_up_to_1e7_match_geometry() {
    let bad = huge_w_failures(&[1.0, 0.01, 1.0e3, 1.0e5, 1.0e7]);
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// The same with ratios from 1e9 up to 1e38.
#[test]
fn vertices_with_w_ratio_beyond_1e8_match_geometry() {
    let bad = huge_w_failures(&[1.0e9, 1.0e12, 1.0e20, 1.0e30, 1.0e35, 1.0e38]);
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// §8 viewport vs guard band: a rectangle spanning NDC x from -1 to 3
/// draws exactly what the rectangle ending on the frame's own right edge
/// (x = 1) draws: rows 16..48, every column, nothing else; a rectangle
/// lying entirely right of the frame (x from 1 to 3) draws nothing. Also
/// rendered through strips, so no row outside a strip is touched.
#[test]
fn guard_band_does_not_leak_outside_the_frame() {
    let rect = |x0: f32, x1: f32| {
        [
            [
                v(x0, -0.5, 0.0, 1.0),
                v(x1, -0.5, 0.0, 1.0),
                v(x1, 0.5, 0.0, 1.0),
            ],
            [
                v(x0, -0.5, 0.0, 1.0),
                v(x1, 0.5, 0.0, 1.0),
                v(x0, 0.5, 0.0, 1.0),
            ],
        ]
    };
    let expected: Vec<bool> = (0..64 * 64).map(|k| (16..48).contains(&(k / 64))).collect();
    for x1 in [1.0f32, 3.0, 1.0e4, 1.0e7] {
        for s4 in [false, true] {
            let cfg = config_nocull(64, 64);
            let tris = rect(-1.0, x1);
            let (ids, strips, counts) = if s4 {
                (
                    render_ids::<4>(cfg, &tris),
                    with_frame::<4, _>(cfg, &tris, |f| frame_ids_strips(f, 5)),
                    hit_counts::<4>(cfg, &tris),
                )
            } else {
                (
                    render_ids::<8>(cfg, &tris),
                    with_frame::<8, _>(cfg, &tris, |f| frame_ids_strips(f, 5)),
                    hit_counts::<8>(cfg, &tris),
                )
            };
            let cov: Vec<bool> = ids.iter().map(|&i| i != 0).collect();
            assert_eq!(cov, expected, "x1 = {x1}");
            assert_eq!(ids, strips);
            assert!(counts.iter().all(|&n| n <= 1));
        }
    }
    for x0 in [1.0f32, 1.0001] {
        let (_, ids) = run::<8>(config_nocull(64, 64), &rect(x0, 3.0));
        assert_eq!(count(&ids), 0);
    }
    // One column: x from 1 - 1/64 (column 63's centre is at 1 - 1/64, on
    // the left edge, included) to 3.
    let (_, ids) = run::<8>(config_nocull(64, 64), &rect(1.0 - 1.0 / 64.0, 3.0));
    assert_eq!(count(&ids), 32);
    assert!((16..48).all(|j| ids[j * 64 + 63] != 0));
}

// ---------------------------------------------------------------------------
// Near and far planes (§9)
// ---------------------------------------------------------------------------

/// A full-frame quad (two triangles) with NDC depth z(x); every vertex
/// scaled by its own w.
fn depth_quad(z: impl Fn(f32) -> f32, ws: [f32; 4]) -> [[Vec4; 3]; 2] {
    let c = [(-1.0f32, -1.0f32), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let p: Vec<Vec4> = (0..4)
        .map(|k| {
            let (x, y) = c[k];
            let w = ws[k];
            v(x * w, y * w, z(x) * w, w)
        })
        .collect();
    [[p[0], p[1], p[2]], [p[0], p[2], p[3]]]
}

/// A quad crossing the near plane (z = x - 1.25 NDC) is drawn only where
/// z >= -w: x >= 0.25, columns 40..64 of 64x64, 24 x 64 = 1536 pixels.
/// One crossing the far plane (z = x + 0.75) only where z <= w: columns
/// 0..40, 2560 pixels. With and without per-vertex w; pieces never overlap.
#[test]
fn near_far_crossing_drawn_only_inside_the_depth_range() {
    let mut rng = SplitMix(31);
    for k in 0..20 {
        let ws = if k == 0 {
            [1.0; 4]
        } else {
            [0; 4].map(|_| rng.range(0.2, 8.0) as f32)
        };
        for (quad, cols) in [
            (depth_quad(|x| x - 1.25, ws), 40..64),
            (depth_quad(|x| x + 0.75, ws), 0..40),
        ] {
            for s4 in [false, true] {
                let cfg = config_nocull(64, 64);
                let counts = if s4 {
                    hit_counts::<4>(cfg, &quad)
                } else {
                    hit_counts::<8>(cfg, &quad)
                };
                for (p, &n) in counts.iter().enumerate() {
                    assert_eq!(n, cols.contains(&(p % 64)) as u32, "w {ws:?}, pixel {p}");
                }
            }
        }
    }
}

/// Vulkan `clip_volume`: primitives at z/w = -1, 0, 1 exactly are drawn
/// (the whole frame); at -1.5 and 1.5 nothing is drawn and they are
/// counted as culled by the frustum.
#[test]
fn clip_volume_depth_planes_exactly() {
    for (z, drawn) in [
        (-1.0f32, true),
        (0.0, true),
        (1.0, true),
        (-1.5, false),
        (1.5, false),
        (-1.0001, false),
        (1.0001, false),
    ] {
        for ws in [[1.0f32; 4], [0.5, 2.0, 3.0, 7.0]] {
            let quad = depth_quad(|_| z, ws);
            let (s, ids) = run::<8>(config_nocull(16, 16), &quad);
            assert_eq!(count(&ids), if drawn { 256 } else { 0 }, "z/w = {z}");
            if !drawn {
                assert_eq!(s.culled_frustum, 2, "z/w = {z}: {s:?}");
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Bad input
// ---------------------------------------------------------------------------

/// NaN or an infinity in any coordinate of any vertex: nothing drawn,
/// nothing stored, counted once in `rejected_nonfinite`.
#[test]
fn non_finite_coordinates_are_rejected() {
    let good = [
        v(-1.0, -1.0, 0.0, 1.0),
        v(1.0, -1.0, 0.0, 1.0),
        v(0.0, 1.0, 0.0, 1.0),
    ];
    for k in 0..3 {
        for c in 0..4 {
            for bad in [f32::NAN, f32::INFINITY, f32::NEG_INFINITY] {
                let mut t = good;
                match c {
                    0 => t[k].x = bad,
                    1 => t[k].y = bad,
                    2 => t[k].z = bad,
                    _ => t[k].w = bad,
                }
                for (s, ids) in [
                    run::<8>(config_nocull(8, 8), &[t]),
                    run::<4>(config_nocull(8, 8), &[t]),
                ] {
                    assert_eq!(count(&ids), 0);
                    assert_eq!(
                        s,
                        Stats {
                            submitted: 1,
                            rejected_nonfinite: 1,
                            ..Stats::default()
                        },
                        "vertex {k} component {c} = {bad}"
                    );
                }
            }
        }
    }
}

/// Zero area after snapping (collinear, all three equal, two equal,
/// collinear only after snapping): culled as degenerate.
#[test]
fn zero_area_triangles_are_culled_degenerate() {
    let cases = [
        [
            v(-0.5, -0.5, 0.0, 1.0),
            v(0.0, 0.0, 0.0, 1.0),
            v(0.5, 0.5, 0.0, 1.0),
        ],
        [v(0.1, 0.2, 0.0, 1.0); 3],
        [
            v(0.1, 0.2, 0.0, 1.0),
            v(0.1, 0.2, 0.0, 1.0),
            v(0.7, -0.3, 0.0, 1.0),
        ],
        [
            v(-0.9, 0.3, 0.0, 1.0),
            v(0.9, 0.3, 0.0, 1.0),
            v(0.0, 0.3, 0.0, 1.0),
        ],
        // Collinear only after snapping: 1e-6 NDC is far below 1/256 px.
        [
            v(-0.5, -0.5, 0.0, 1.0),
            v(0.0, 1.0e-6, 0.0, 1.0),
            v(0.5, 0.5, 0.0, 1.0),
        ],
        // Collinear in NDC, given at different w.
        [
            v(-1.0, -1.0, 0.0, 2.0),
            v(0.0, 0.0, 0.0, 1.0),
            v(2.0, 2.0, 0.0, 4.0),
        ],
    ];
    for t in cases {
        for (s, ids) in [
            run::<8>(config_nocull(32, 32), &[t]),
            run::<4>(config_nocull(32, 32), &[t]),
        ] {
            assert_eq!(count(&ids), 0);
            assert_eq!(
                s,
                Stats {
                    submitted: 1,
                    culled_degenerate: 1,
                    ..Stats::default()
                },
                "{t:?}"
            );
        }
    }
}

/// A small triangle whose bounding box holds no pixel centre: culled as
/// degenerate (setup rejects it before any rasterization).
#[test]
fn no_pixel_centre_in_bounding_box_is_culled_degenerate() {
    let (w, h) = (16, 16);
    let cases = [
        [(3.6, 3.6), (4.4, 3.6), (3.6, 4.4)],
        [(3.6, 3.1), (4.4, 3.2), (4.0, 3.45)],
        [(0.55, 0.55), (0.95, 0.6), (0.7, 0.99)],
    ];
    for p in cases {
        let t = tri_win(p, w, h);
        for (s, ids) in [
            run::<8>(config_nocull(w, h), &[t]),
            run::<4>(config_nocull(w, h), &[t]),
        ] {
            assert_eq!(count(&ids), 0);
            assert_eq!(
                s,
                Stats {
                    submitted: 1,
                    culled_degenerate: 1,
                    ..Stats::default()
                },
                "{p:?}"
            );
        }
    }
}

// ---------------------------------------------------------------------------
// Culling (§5)
// ---------------------------------------------------------------------------

/// CullMode::{Back, Front, None} x FrontFace::{Ccw, Cw} on one
/// counter-clockwise (NDC) and one clockwise triangle.
#[test]
fn backface_culling_modes_and_front_faces() {
    let ccw = [
        v(-0.9, -0.9, 0.0, 1.0),
        v(0.9, -0.9, 0.0, 1.0),
        v(-0.9, 0.9, 0.0, 1.0),
    ];
    let cw = [
        v(0.9, 0.9, 0.0, 1.0),
        v(0.9, -0.8, 0.0, 1.0),
        v(-0.8, 0.9, 0.0, 1.0),
    ];
    for cull in [CullMode::Back, CullMode::Front, CullMode::None] {
        for front in [FrontFace::Ccw, FrontFace::Cw] {
            let mut cfg = Config::new(32, 32);
            cfg.cull = cull;
            cfg.front_face = front;
            let ccw_front = front == FrontFace::Ccw;
            let keep = |is_front: bool| match cull {
                CullMode::Back => is_front,
                CullMode::Front => !is_front,
                CullMode::None => true,
            };
            let (s, ids) = run::<8>(cfg, &[ccw, cw]);
            let has = |id: u32| ids.contains(&id);
            assert_eq!(has(1), keep(ccw_front), "{cull:?} {front:?}: ccw");
            assert_eq!(has(2), keep(!ccw_front), "{cull:?} {front:?}: cw");
            let culled = 2 - keep(ccw_front) as u32 - keep(!ccw_front) as u32;
            assert_eq!(s.culled_backface, culled);
            assert_eq!(s.stored, 2 - culled);
        }
    }
}

/// §5 with random vertices drawn as a list, a strip (alternating winding)
/// and a fan, for every cull mode and front face: the image is the
/// reference image of exactly the triangles that should survive.
#[test]
fn culling_lists_strips_and_fans_match_reference() {
    let (w, h) = (64u32, 64u32);
    let mut rng = SplitMix(41);
    for _ in 0..60 {
        let vs: Vec<Vec4> = (0..6)
            .map(|_| {
                v(
                    rng.range(-0.9, 0.9) as f32,
                    rng.range(-0.9, 0.9) as f32,
                    0.0,
                    1.0,
                )
            })
            .collect();
        let list = vec![[vs[0], vs[1], vs[2]], [vs[3], vs[4], vs[5]]];
        let strip: Vec<[Vec4; 3]> = (0..4)
            .map(|i| {
                if i % 2 == 0 {
                    [vs[i], vs[i + 1], vs[i + 2]]
                } else {
                    [vs[i + 1], vs[i], vs[i + 2]]
                }
            })
            .collect();
        let fan: Vec<[Vec4; 3]> = (1..5).map(|i| [vs[0], vs[i], vs[i + 1]]).collect();
        for tris in [list, strip, fan] {
            for cull in [CullMode::Back, CullMode::Front, CullMode::None] {
                for front in [FrontFace::Ccw, FrontFace::Cw] {
                    let mut cfg = Config::new(w, h);
                    cfg.cull = cull;
                    cfg.front_face = front;
                    let mut expected = vec![0u32; (w * h) as usize];
                    for (i, t) in tris.iter().enumerate() {
                        let sv = snap_tri::<8>(t, w, h).unwrap();
                        let area = orient(sv[0], sv[1], sv[2]);
                        let is_front = (area < 0) == (front == FrontFace::Ccw);
                        let keep = match cull {
                            CullMode::Back => is_front,
                            CullMode::Front => !is_front,
                            CullMode::None => true,
                        };
                        if keep && area != 0 {
                            for (k, c) in reference_coverage(sv, 8, w, h).into_iter().enumerate() {
                                if c {
                                    expected[k] = i as u32 + 1;
                                }
                            }
                        }
                    }
                    assert_eq!(run::<8>(cfg, &tris).1, expected, "{cull:?} {front:?}");
                }
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Errors
// ---------------------------------------------------------------------------

/// Wrong row ranges and buffer sizes return the typed error and leave both
/// buffers untouched.
#[test]
fn render_rows_errors_leave_buffers_untouched() {
    let (w, h) = (8u32, 6u32);
    let mut st = storage(2);
    let mut frame: Frame = Frame::new(config_nocull(w, h), &mut st).unwrap();
    frame
        .push_clip_triangle(
            [
                v(-1.0, -1.0, 0.0, 1.0),
                v(3.0, -1.0, 0.0, 1.0),
                v(-1.0, 3.0, 0.0, 1.0),
            ],
            RED3,
            0,
        )
        .unwrap();
    let sentinel_c = Rgb888::new(1, 2, 3);
    let sentinel_z = 0x5A5A_5A5Au32;
    // (y0, y1, colour len, depth len, expected error)
    let rows_err = |y0, y1| Error::InvalidRows { y0, y1, height: h };
    let cases: Vec<(u32, u32, usize, usize, Error)> = vec![
        (3, 3, 0, 0, rows_err(3, 3)),
        (4, 3, 8, 8, rows_err(4, 3)),
        (0, 7, 56, 56, rows_err(0, 7)),
        (6, 7, 8, 8, rows_err(6, 7)),
        (
            0,
            6,
            47,
            48,
            Error::ColorBufferSize {
                expected: 48,
                actual: 47,
            },
        ),
        (
            0,
            6,
            49,
            48,
            Error::ColorBufferSize {
                expected: 48,
                actual: 49,
            },
        ),
        (
            2,
            3,
            0,
            8,
            Error::ColorBufferSize {
                expected: 8,
                actual: 0,
            },
        ),
        (
            0,
            6,
            48,
            47,
            Error::DepthBufferSize {
                expected: 48,
                actual: 47,
            },
        ),
        (
            0,
            6,
            48,
            49,
            Error::DepthBufferSize {
                expected: 48,
                actual: 49,
            },
        ),
        (
            1,
            3,
            16,
            0,
            Error::DepthBufferSize {
                expected: 16,
                actual: 0,
            },
        ),
        (
            0,
            6,
            47,
            49,
            Error::ColorBufferSize {
                expected: 48,
                actual: 47,
            },
        ),
    ];
    for (y0, y1, nc, nz, err) in cases {
        let mut c = vec![sentinel_c; nc];
        let mut z = vec![sentinel_z; nz];
        assert_eq!(
            frame.render_rows(y0, y1, &mut c[..], &mut z[..]),
            Err(err),
            "rows {y0}..{y1}, {nc}, {nz}"
        );
        assert!(c.iter().all(|&p| p == sentinel_c) && z.iter().all(|&d| d == sentinel_z));
        let mut z16 = vec![0x5A5Au16; nz];
        let mut ids = vec![TriangleId(77); nc];
        assert_eq!(
            frame.render_rows(y0, y1, &mut ids[..], &mut z16[..]),
            Err(err)
        );
        assert!(ids.iter().all(|&p| p == TriangleId(77)) && z16.iter().all(|&d| d == 0x5A5A));
    }
    // Without a depth buffer only the colour size matters.
    let mut c = [sentinel_c; 9];
    assert_eq!(
        frame.render_rows(0, 1, &mut c[..], &mut NoDepth),
        Err(Error::ColorBufferSize {
            expected: 8,
            actual: 9
        })
    );
    assert!(c.iter().all(|&p| p == sentinel_c));
    // And the right sizes work.
    let mut c = [sentinel_c; 16];
    let mut z = [u32::MAX; 16];
    assert!(frame.render_rows(4, 6, &mut c[..], &mut z[..]).is_ok());
}

/// Zero or oversized frame sizes: `Error::InvalidFrameSize` carrying them.
#[test]
fn invalid_frame_sizes_are_rejected() {
    for (w, h) in [
        (0, 1),
        (1, 0),
        (0, 0),
        (MAX_DIMENSION + 1, 1),
        (1, MAX_DIMENSION + 1),
        (u32::MAX, u32::MAX),
        (65536, 1),
    ] {
        let mut st = storage(1);
        let r8 = Frame::<8>::new(Config::new(w, h), &mut st).err();
        assert_eq!(
            r8,
            Some(Error::InvalidFrameSize {
                width: w,
                height: h
            })
        );
        let r4 = Frame::<4>::new(Config::new(w, h), &mut st).err();
        assert_eq!(
            r4,
            Some(Error::InvalidFrameSize {
                width: w,
                height: h
            })
        );
    }
    let mut st = storage(1);
    assert!(Frame::<8>::new(Config::new(MAX_DIMENSION, MAX_DIMENSION), &mut st).is_ok());
    assert!(Frame::<8>::new(Config::new(1, 1), &mut st).is_ok());
}

/// Full storage: `StorageFull`, and nothing of the triangle is stored or
/// counted, even when only some of its clipped pieces would fit.
#[test]
fn storage_full_stores_nothing() {
    let mut st = vec![SetupTriangle::EMPTY; 2];
    let mut frame: Frame = Frame::new(config_nocull(16, 16), &mut st).unwrap();
    let small = [
        v(-0.5, -0.5, 0.0, 1.0),
        v(0.5, -0.5, 0.0, 1.0),
        v(0.0, 0.5, 0.0, 1.0),
    ];
    // One vertex behind the near plane: the clipped quad needs 2 pieces.
    let two_pieces = [
        v(-0.5, -0.5, 0.0, 1.0),
        v(0.5, -0.5, 0.0, 1.0),
        v(0.0, 0.5, -3.0, 1.0),
    ];
    frame.push_clip_triangle(small, RED3, 0).unwrap();
    let before = (frame.stats(), frame.triangles().to_vec());
    assert_eq!(
        frame.push_clip_triangle(two_pieces, RED3, 1),
        Err(Error::StorageFull {
            capacity: 2,
            needed: 1
        })
    );
    assert_eq!((frame.stats(), frame.triangles().to_vec()), before);
    frame.push_clip_triangle(small, RED3, 2).unwrap();
    let before = (frame.stats(), frame.triangles().to_vec());
    assert_eq!(
        frame.push_clip_triangle(small, RED3, 3),
        Err(Error::StorageFull {
            capacity: 2,
            needed: 1
        })
    );
    assert_eq!((frame.stats(), frame.triangles().to_vec()), before);
    // Triangles that store nothing are still accepted and counted.
    let culled = [
        v(5.0, 5.0, 0.0, 1.0),
        v(6.0, 5.0, 0.0, 1.0),
        v(5.0, 6.0, 0.0, 1.0),
    ];
    frame.push_clip_triangle(culled, RED3, 4).unwrap();
    assert_eq!(frame.stats().culled_frustum, 1);
    // The two pieces fit into an empty frame of capacity 2.
    frame.clear();
    frame.push_clip_triangle(two_pieces, RED3, 1).unwrap();
    assert_eq!(frame.stats().stored, 2);
    assert_eq!(frame.stats().clipped, 1);
}

/// `draw_mesh` is all-or-nothing: a mesh that does not fit leaves the
/// frame exactly as it was; index errors and object culling are counted.
#[test]
fn draw_mesh_is_all_or_nothing() {
    let positions = [
        Vec3::new(-0.5, -0.5, 0.0),
        Vec3::new(0.5, -0.5, 0.0),
        Vec3::new(0.5, 0.5, 0.0),
        Vec3::new(-0.5, 0.5, 0.0),
    ];
    let indices = [[0, 1, 2], [0, 2, 3], [0, 3, 2], [1, 0, 3]];
    let mesh = Mesh {
        positions: &positions,
        indices: &indices,
        colors: MeshColors::Uniform(Rgb888::new(1, 2, 3)),
        bounds: None,
    };
    let mut st = vec![SetupTriangle::EMPTY; 5];
    let mut frame: Frame = Frame::new(config_nocull(16, 16), &mut st).unwrap();
    frame
        .push_clip_triangle(
            [
                v(-0.5, -0.5, 0.0, 1.0),
                v(0.5, -0.5, 0.0, 1.0),
                v(0.0, 0.5, 0.0, 1.0),
            ],
            RED3,
            99,
        )
        .unwrap();
    frame
        .push_clip_triangle(
            [
                v(-0.5, -0.5, 0.0, 1.0),
                v(0.5, -0.5, 0.0, 1.0),
                v(0.0, 0.5, 0.0, 1.0),
            ],
            RED3,
            98,
        )
        .unwrap();
    let before = (frame.stats(), frame.triangles().to_vec(), frame_ids(&frame));
    let err = frame.draw_mesh(&mesh, &Mat4::IDENTITY, 0).unwrap_err();
    assert!(
        matches!(err, Error::StorageFull { capacity: 5, .. }),
        "{err:?}"
    );
    assert_eq!(
        (frame.stats(), frame.triangles().to_vec(), frame_ids(&frame)),
        before
    );
    // The cached path too.
    let mut cache = [ProcessedVertex::EMPTY; 4];
    let err = frame
        .draw_mesh_cached(&mesh, &Mat4::IDENTITY, 0, &mut cache)
        .unwrap_err();
    assert!(
        matches!(err, Error::StorageFull { capacity: 5, .. }),
        "{err:?}"
    );
    assert_eq!(
        (frame.stats(), frame.triangles().to_vec(), frame_ids(&frame)),
        before
    );
    // It fits after a clear.
    frame.clear();
    frame.draw_mesh(&mesh, &Mat4::IDENTITY, 10).unwrap();
    assert_eq!(frame.stats().stored, 4);
    assert_eq!(
        frame.triangles().iter().map(|t| t.id()).collect::<Vec<_>>(),
        vec![10, 11, 12, 13]
    );
    // A bad index is counted, not stored.
    frame.clear();
    let bad = [[0, 1, 2], [0, 1, 9]];
    let m = Mesh {
        indices: &bad,
        ..mesh
    };
    frame.draw_mesh(&m, &Mat4::IDENTITY, 0).unwrap();
    assert_eq!(
        (
            frame.stats().submitted,
            frame.stats().rejected_index,
            frame.stats().stored
        ),
        (2, 1, 1)
    );
    // An object outside the frustum is culled whole, even with full storage.
    frame.clear();
    for i in 0..5 {
        frame
            .push_clip_triangle(
                [
                    v(-0.5, -0.5, 0.0, 1.0),
                    v(0.5, -0.5, 0.0, 1.0),
                    v(0.0, 0.5, 0.0, 1.0),
                ],
                RED3,
                i,
            )
            .unwrap();
    }
    let far = Mesh {
        bounds: BoundingSphere::from_points(&positions),
        ..mesh
    };
    frame
        .draw_mesh(&far, &Mat4::translation(Vec3::new(10.0, 0.0, 0.0)), 0)
        .unwrap();
    assert_eq!(frame.stats().culled_object, 4);
    assert_eq!(frame.stats().submitted, 9);
}

// ---------------------------------------------------------------------------
// Extreme frame sizes
// ---------------------------------------------------------------------------

/// A 1x1 frame: the pixel centre on the diagonal of the split frame goes
/// to the upper-right triangle (left edge), in either submission order.
#[test]
fn one_by_one_frame() {
    let ur = tri_win([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0)], 1, 1);
    let ll = tri_win([(0.0, 0.0), (1.0, 1.0), (0.0, 1.0)], 1, 1);
    for s4 in [false, true] {
        let r = |t: &[[Vec4; 3]]| {
            if s4 {
                render_ids::<4>(config_nocull(1, 1), t)
            } else {
                render_ids::<8>(config_nocull(1, 1), t)
            }
        };
        assert_eq!(r(&[ur, ll]), vec![1]);
        assert_eq!(r(&[ll, ur]), vec![2]);
        assert_eq!(r(&[ll]), vec![0]);
        assert_eq!(r(&[ur]), vec![1]);
        // A big triangle covers it; a small one next to the centre does not.
        assert_eq!(
            r(&[[
                v(-1.0, -1.0, 0.0, 1.0),
                v(3.0, -1.0, 0.0, 1.0),
                v(-1.0, 3.0, 0.0, 1.0)
            ]]),
            vec![1]
        );
        assert_eq!(
            r(&[tri_win([(0.0, 0.0), (0.4, 0.0), (0.0, 0.4)], 1, 1)]),
            vec![0]
        );
    }
    let mut st = storage(1);
    let mut frame: Frame<'_, 4> = Frame::new(config_nocull(1, 1), &mut st).unwrap();
    frame.push_clip_triangle(ur, RED3, 0).unwrap();
    let mut c = [Rgb888::new(0, 0, 0)];
    let mut z = [u16::MAX];
    assert_eq!(
        frame
            .render_rows(0, 1, &mut c, &mut z[..])
            .unwrap()
            .pixels_written,
        1
    );
    assert_eq!(c[0], Rgb888::new(255, 0, 0));
    assert_eq!(z[0], 0x8000);
}

/// The exact floor of the plane through the stored triangle's (x, y, Z32)
/// at pixel (i, j): sum of E_k Z_k / area, E_k the edge opposite k.
fn exact_depth(t: &SetupTriangle, s: u32, i: i64, j: i64) -> i128 {
    let v = t.vertices().map(|(x, y)| (x as i64, y as i64));
    let z = t.depths();
    let p = (centre(i, s), centre(j, s));
    let area = orient(v[0], v[1], v[2]);
    assert!(area > 0, "stored triangles are wound to positive area");
    let mut num = 0i128;
    for k in 0..3 {
        num += orient(v[(k + 1) % 3], v[(k + 2) % 3], p) * z[k] as i128;
    }
    num.div_euclid(area)
}

fn largest_frame<const S: u32>(w: u32, h: u32) {
    let cfg = {
        let mut c = config_nocull(w, h);
        c.depth_func = DepthFunc::Always;
        c
    };
    // Full-frame quad with depth z = x (or y): a ramp over 16384 pixels.
    let horizontal = w > h;
    let z = |x: f32, y: f32| if horizontal { x } else { y };
    let c = [(-1.0f32, -1.0f32), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)];
    let p: Vec<Vec4> = c.iter().map(|&(x, y)| v(x, y, z(x, y), 1.0)).collect();
    let quad = [[p[0], p[1], p[2]], [p[0], p[2], p[3]]];
    let mut st = storage(2);
    let mut frame = Frame::<S>::new(cfg, &mut st).unwrap();
    for (i, t) in quad.iter().enumerate() {
        frame.push_clip_triangle(*t, RED3, i as u32).unwrap();
    }
    let n = (w * h) as usize;
    let mut ids = vec![TriangleId(0); n];
    let mut depth = vec![u32::MAX; n];
    frame
        .render_rows(0, h, &mut ids[..], &mut depth[..])
        .unwrap();
    assert!(
        ids.iter().all(|t| t.0 != 0),
        "{w}x{h} S={S}: not fully covered"
    );
    assert_eq!(
        hit_counts::<S>(cfg, &quad)
            .iter()
            .filter(|&&c| c != 1)
            .count(),
        0
    );
    let tris = frame.triangles();
    for k in 0..n {
        let (i, j) = ((k as u32 % w) as i64, (k as u32 / w) as i64);
        let t = &tris[(ids[k].0 - 1) as usize];
        let exact = exact_depth(t, S, i, j);
        assert!(
            (depth[k] as i128 - exact).abs() <= 1,
            "{w}x{h} S={S}: pixel {k} depth {} vs exact {exact}",
            depth[k]
        );
    }
    // The last column / row: a right (bottom) edge through its centre is
    // excluded, a left (top) edge through it included.
    let last = (if horizontal { w } else { h }) as f64 - 0.5;
    let (wf, hf) = (w as f64, h as f64);
    let t_right = if horizontal {
        tri_win([(last - 4.0, -1.0), (last, -1.0), (last, hf + 1.0)], w, h)
    } else {
        tri_win([(-1.0, last - 4.0), (wf + 1.0, last), (-1.0, last)], w, h)
    };
    let ids = render_ids::<S>(config_nocull(w, h), &[t_right]);
    assert_eq!(
        ids[n - 1],
        0,
        "right/bottom edge through the last centre is excluded"
    );
    assert_eq!(ids[n - 2], 1);
    let t_left = if horizontal {
        tri_win([(last, -1.0), (last + 4.0, -1.0), (last, hf + 1.0)], w, h)
    } else {
        tri_win([(-1.0, last), (wf + 1.0, last), (-1.0, last + 4.0)], w, h)
    };
    let ids = render_ids::<S>(config_nocull(w, h), &[t_left]);
    assert_eq!(count(&ids), 1);
    assert_eq!(
        ids[n - 1],
        1,
        "left/top edge through the last centre is included"
    );
}

/// A frame of MAX_DIMENSION pixels along one axis (16384x1 and 1x16384),
/// at both precisions: fully covered once by a quad, depth ramp across the
/// whole frame within 1 LSB of the exact plane (the longest span the
/// stepping error bound allows), last-centre fill rule.
#[test]
fn largest_frame_16384_along_one_axis() {
    assert_eq!(MAX_DIMENSION, 16384);
    largest_frame::<8>(MAX_DIMENSION, 1);
    largest_frame::<4>(MAX_DIMENSION, 1);
    largest_frame::<8>(1, MAX_DIMENSION);
    largest_frame::<4>(1, MAX_DIMENSION);
}

// ---------------------------------------------------------------------------
// Depth
// ---------------------------------------------------------------------------

/// z/w = -1 gives Z32 0; z/w = 1 gives u32::MAX (u16::MAX), which passes
/// LessEqual (not Less) against a buffer cleared to the far plane.
#[test]
fn depth_at_near_and_far_planes_exactly() {
    for (z, z32) in [(-1.0f32, 0u32), (1.0, u32::MAX)] {
        for ws in [[1.0f32; 4], [0.3, 2.0, 5.0, 11.0]] {
            let quad = depth_quad(|_| z, ws);
            for func in [DepthFunc::LessEqual, DepthFunc::Less] {
                let mut cfg = config_nocull(8, 8);
                cfg.depth_func = func;
                let mut st = storage(2);
                let mut frame: Frame = Frame::new(cfg, &mut st).unwrap();
                for t in quad {
                    frame.push_clip_triangle(t, RED3, 0).unwrap();
                }
                assert!(frame.triangles().iter().all(|t| t.depths() == [z32; 3]));
                let mut c = vec![Rgb888::new(0, 0, 0); 64];
                let mut d32 = vec![u32::MAX; 64];
                let passes = func == DepthFunc::LessEqual || z32 < u32::MAX;
                let n = frame
                    .render_rows(0, 8, &mut c[..], &mut d32[..])
                    .unwrap()
                    .pixels_written;
                assert_eq!(n, if passes { 64 } else { 0 }, "z {z} {func:?}");
                assert!(d32
                    .iter()
                    .all(|&d| d == if passes { z32 } else { u32::MAX }));
                let mut d16 = [u16::MAX; 64];
                let n = frame
                    .render_rows(0, 8, &mut c[..], &mut d16[..])
                    .unwrap()
                    .pixels_written;
                assert_eq!(n, if passes { 64 } else { 0 });
                let z16 = (z32 >> 16) as u16;
                assert!(d16
                    .iter()
                    .all(|&d| d == if passes { z16 } else { u16::MAX }));
                let n = frame
                    .render_rows(0, 8, &mut c[..], &mut NoDepth)
                    .unwrap()
                    .pixels_written;
                assert_eq!(n, 64);
            }
        }
    }
}

/// Random triangles (general, small, slivers with huge depth gradients,
/// off-grid, per-vertex w): the written u32 depth at every covered pixel
/// is within 1 LSB of the exact plane through the stored triangle's
/// vertices and Z32 depths; the u16 depth is its top 16 bits (within 1).
#[test]
fn depth_is_the_exact_plane_within_1_lsb() {
    let mut rng = SplitMix(51);
    let (w, h) = (48u32, 40u32);
    let mut pixels = 0u64;
    for n in 0..600 {
        let mut tri = [v(0.0, 0.0, 0.0, 1.0); 3];
        let sliver = n % 3 == 0;
        for k in 0..3 {
            let ww = rng.range(0.2, 5.0);
            let (mut x, mut y) = (rng.range(-1.2, 1.2), rng.range(-1.2, 1.2));
            if sliver && k == 2 {
                // Near the line through the first two vertices.
                let a = (tri_ndc(&tri, 0), tri_ndc(&tri, 1));
                let s = rng.range(-0.5, 1.5);
                x = a.0 .0 + (a.1 .0 - a.0 .0) * s + rng.range(-0.003, 0.003);
                y = a.0 .1 + (a.1 .1 - a.0 .1) * s + rng.range(-0.003, 0.003);
            }
            let z = rng.range(-1.0, 1.0);
            tri[k] = Vec4::new((x * ww) as f32, (y * ww) as f32, (z * ww) as f32, ww as f32);
        }
        for s4 in [false, true] {
            pixels += if s4 {
                check_depth::<4>(w, h, tri)
            } else {
                check_depth::<8>(w, h, tri)
            };
        }
    }
    assert!(pixels > 100_000, "only {pixels} pixels checked");
}

fn tri_ndc(t: &[Vec4; 3], k: usize) -> (f64, f64) {
    (t[k].x as f64 / t[k].w as f64, t[k].y as f64 / t[k].w as f64)
}

fn check_depth<const S: u32>(w: u32, h: u32, tri: [Vec4; 3]) -> u64 {
    let mut cfg = config_nocull(w, h);
    cfg.depth_func = DepthFunc::Always;
    let mut st = storage(1);
    let mut frame = Frame::<S>::new(cfg, &mut st).unwrap();
    frame.push_clip_triangle(tri, RED3, 0).unwrap();
    let Some(t) = frame.triangles().first().copied() else {
        return 0;
    };
    if frame.triangles().len() != 1 {
        return 0; // clipped into pieces: checked elsewhere
    }
    let n = (w * h) as usize;
    let mut ids = vec![TriangleId(0); n];
    let mut d32 = vec![u32::MAX; n];
    frame.render_rows(0, h, &mut ids[..], &mut d32[..]).unwrap();
    let mut c = vec![Rgb888::new(0, 0, 0); n];
    let mut d16 = vec![u16::MAX; n];
    frame.render_rows(0, h, &mut c[..], &mut d16[..]).unwrap();
    let mut checked = 0;
    for k in 0..n {
        if ids[k].0 == 0 {
            assert_eq!((d32[k], d16[k]), (u32::MAX, u16::MAX));
            continue;
        }
        let (i, j) = ((k as u32 % w) as i64, (k as u32 / w) as i64);
        let exact = exact_depth(&t, S, i, j);
        assert!(
            (d32[k] as i128 - exact).abs() <= 1,
            "S={S} {tri:?} pixel ({i},{j}): depth {} vs exact {exact}",
            d32[k]
        );
        assert!((d16[k] as i128 - (exact >> 16)).abs() <= 1);
        checked += 1;
    }
    checked
}

/// §6 `interpolation.projected`: Gouraud colour is perspective-correct:
/// at every covered pixel each channel is within 1 LSB of the f64
/// perspective-correct interpolation at the pixel centre, computed from the
/// snapped vertices and the clip w.
#[test]
fn gouraud_colour_is_perspective_correct_within_1_lsb() {
    let mut rng = SplitMix(61);
    let (w, h) = (64u32, 48u32);
    let mut checked = 0u64;
    let mut worst = 0.0f64;
    for n in 0..400 {
        let mut tri = [v(0.0, 0.0, 0.0, 1.0); 3];
        let mut col = [Rgb888::new(0, 0, 0); 3];
        for k in 0..3 {
            let ww = if n % 4 == 0 { 1.0 } else { rng.range(0.2, 4.0) };
            let (x, y, z) = (
                rng.range(-1.1, 1.1),
                rng.range(-1.1, 1.1),
                rng.range(-0.9, 0.9),
            );
            tri[k] = Vec4::new((x * ww) as f32, (y * ww) as f32, (z * ww) as f32, ww as f32);
            col[k] = Rgb888::new(
                rng.int(0, 255) as u8,
                rng.int(0, 255) as u8,
                rng.int(0, 255) as u8,
            );
        }
        let Some(sv) = snap_tri::<8>(&tri, w, h) else {
            continue;
        };
        let area = orient(sv[0], sv[1], sv[2]);
        if area == 0 {
            continue;
        }
        let mut st = storage(1);
        let mut frame: Frame = Frame::new(config_nocull(w, h), &mut st).unwrap();
        frame.push_clip_triangle(tri, col, 0).unwrap();
        let mut img = vec![Rgb888::new(1, 2, 3); (w * h) as usize];
        frame.render_rows(0, h, &mut img[..], &mut NoDepth).unwrap();
        let cov = reference_coverage(sv, 8, w, h);
        for (k, &c) in cov.iter().enumerate() {
            if !c {
                assert_eq!(img[k], Rgb888::new(1, 2, 3));
                continue;
            }
            let p = (
                centre((k as u32 % w) as i64, 8),
                centre((k as u32 / w) as i64, 8),
            );
            let mut b = [0.0f64; 3];
            for m in 0..3 {
                b[m] = orient(sv[(m + 1) % 3], sv[(m + 2) % 3], p) as f64
                    / area as f64
                    / tri[m].w as f64;
            }
            let den: f64 = b.iter().sum();
            let chan = |c: Rgb888, ch: usize| {
                use microraster::pixelcolor::RgbColor;
                [c.r(), c.g(), c.b()][ch] as f64
            };
            for ch in 0..3 {
                let want = (0..3).map(|m| b[m] * chan(col[m], ch)).sum::<f64>() / den;
                let got = chan(img[k], ch);
                let err = (got - want).abs();
                worst = worst.max(err);
                assert!(
                    err <= 1.0,
                    "{tri:?} {col:?}: pixel {k} channel {ch}: {got} vs {want:.3}"
                );
            }
            checked += 1;
        }
    }
    assert!(checked > 50_000, "only {checked} pixels");
    assert!(worst <= 0.51, "worst error {worst}: not rounded to nearest");
}

/// Depth functions: the same triangle drawn twice ties (Less keeps the
/// first, LessEqual takes the second), Always / Never, Equal / NotEqual /
/// Greater / GreaterEqual, and `depth_write = false` leaves the buffer as
/// cleared; a near triangle beats a far one in either order under Less.
#[test]
fn depth_func_variants() {
    let (w, h) = (16u32, 16u32);
    let t = [
        v(-0.8, -0.8, 0.1, 1.0),
        v(0.9, -0.7, -0.2, 1.0),
        v(-0.6, 0.9, 0.3, 1.0),
    ];
    let covered: Vec<bool> = coverage::<8>(config_nocull(w, h), t);
    let npx = covered.iter().filter(|&&c| c).count();
    assert!(npx > 50);
    let draw = |func: DepthFunc, write: bool, clear: u32, tris: &[[Vec4; 3]]| {
        let mut cfg = config_nocull(w, h);
        cfg.depth_func = func;
        cfg.depth_write = write;
        let mut st = storage(tris.len());
        let mut frame: Frame = Frame::new(cfg, &mut st).unwrap();
        for (i, t) in tris.iter().enumerate() {
            frame.push_clip_triangle(*t, RED3, i as u32).unwrap();
        }
        let mut ids = vec![TriangleId(0); (w * h) as usize];
        let mut z = vec![clear; (w * h) as usize];
        frame.render_rows(0, h, &mut ids[..], &mut z[..]).unwrap();
        (ids.iter().map(|t| t.0).collect::<Vec<_>>(), z)
    };
    let only = |id: u32| -> Vec<u32> { covered.iter().map(|&c| if c { id } else { 0 }).collect() };
    let far = u32::MAX;
    // (func, write, clear, expected winner)
    let cases = [
        (DepthFunc::Less, true, far, 1),
        (DepthFunc::LessEqual, true, far, 2),
        (DepthFunc::Always, true, far, 2),
        (DepthFunc::Always, true, 0, 2),
        (DepthFunc::Never, true, far, 0),
        (DepthFunc::Equal, true, far, 0),
        (DepthFunc::NotEqual, true, far, 1),
        (DepthFunc::Greater, true, 0, 1),
        (DepthFunc::GreaterEqual, true, 0, 2),
        (DepthFunc::Greater, true, far, 0),
        (DepthFunc::Less, false, far, 2),
        (DepthFunc::Never, false, far, 0),
    ];
    for (func, write, clear, winner) in cases {
        let (ids, z) = draw(func, write, clear, &[t, t]);
        assert_eq!(ids, only(winner), "{func:?} write={write} clear={clear:#x}");
        let untouched = !write || winner == 0;
        for k in 0..z.len() {
            if untouched || !covered[k] {
                assert_eq!(z[k], clear, "{func:?} write={write}: depth written at {k}");
            } else {
                assert_ne!(z[k], clear);
            }
        }
    }
    // Near beats far in either order under Less; far wins under Greater.
    let near = [
        v(-1.0, -1.0, -0.5, 1.0),
        v(3.0, -1.0, -0.5, 1.0),
        v(-1.0, 3.0, -0.5, 1.0),
    ];
    let farq = [
        v(-1.0, -1.0, 0.5, 1.0),
        v(3.0, -1.0, 0.5, 1.0),
        v(-1.0, 3.0, 0.5, 1.0),
    ];
    assert!(draw(DepthFunc::Less, true, far, &[near, farq])
        .0
        .iter()
        .all(|&i| i == 1));
    assert!(draw(DepthFunc::Less, true, far, &[farq, near])
        .0
        .iter()
        .all(|&i| i == 2));
    assert!(draw(DepthFunc::Greater, true, 0, &[near, farq])
        .0
        .iter()
        .all(|&i| i == 2));
    assert!(draw(DepthFunc::Greater, true, 0, &[farq, near])
        .0
        .iter()
        .all(|&i| i == 1));
}

// ---------------------------------------------------------------------------
// Snapping
// ---------------------------------------------------------------------------

/// `fixed::snap` rounds to the nearest subpixel with halves up at every
/// magnitude up to COORD_LIMIT: window x = 2^23 + 1 (an odd integer in
/// [2^23, 2^24), where f32 has no fraction bits) must stay 2^23 + 1.
#[test]
fn snap_rounds_to_nearest_beyond_2_pow_23() {
    // (x * 32 + 32) * 256 = 2^23 + 1 exactly in f32.
    let x = 1023.0f32 + 1.0 / 8192.0;
    assert_eq!((x * 32.0 + 32.0) * 256.0, 8_388_609.0);
    assert_eq!(snap::<8>(x, 0.0, 0.0, 1.0, 64, 64).unwrap().x, 8_388_609);
    assert_eq!(
        snap::<8>(-x - 2.0, 0.0, 0.0, 1.0, 64, 64).unwrap().x,
        -8_388_609
    );
    for k in [1i64, 3, 5, 1001, (1 << 23) - 1] {
        let target = (1i64 << 23) + k;
        let x = ((target as f64 / 256.0) - 32.0) / 32.0;
        let s = snap::<8>(x as f32, 0.0, 0.0, 1.0, 64, 64).unwrap();
        assert_eq!(s.x as i64, target, "window x {target} units");
    }
}

/// Snapping below 2^23 is exact round-half-up: values exactly half-way
/// between two subpixels (on the 1/512 grid) go up, in both axes and
/// signs.
#[test]
fn snap_rounds_halves_up() {
    for (px, want) in [
        (10.0f64 + 1.0 / 512.0, 2561i32),
        (10.0 - 1.0 / 512.0, 2560),
        (-10.0 + 1.0 / 512.0, -2559),
        (-10.0 - 1.0 / 512.0, -2560),
        (10.0 + 3.0 / 1024.0, 2561),
        (10.0 + 1.0 / 1024.0, 2560),
    ] {
        let (x, y) = win_to_clip(px, px, 64, 64);
        let s = snap::<8>(x, y, 0.0, 1.0, 64, 64).unwrap();
        assert_eq!((s.x, s.y), (want, want), "window {px}");
    }
    let (x, _) = win_to_clip(5.0 + 1.0 / 32.0, 0.0, 64, 64);
    assert_eq!(snap::<4>(x, 0.0, 0.0, 1.0, 64, 64).unwrap().x, 81);
}

/// §6 on slivers (near-collinear triangles, small and wide boxes, random
/// w): Gouraud colour stays within 1 LSB of the f64 perspective-correct
/// value at every covered pixel.
#[test]
fn gouraud_colour_on_slivers_within_1_lsb() {
    let mut rng = SplitMix(62);
    let (w, h) = (64u32, 64u32);
    let mut checked = 0u64;
    let mut bad = vec![];
    for n in 0..3000 {
        let reach = if n % 2 == 0 { 20.0 } else { 60.0 };
        let a = (rng.range(2.0, 62.0), rng.range(2.0, 62.0));
        let b = (
            (a.0 + rng.range(-reach, reach)).clamp(0.0, 64.0),
            (a.1 + rng.range(-reach, reach)).clamp(0.0, 64.0),
        );
        let s = rng.range(-0.2, 1.2);
        let off = rng.range(-0.7, 0.7);
        let c = (a.0 + (b.0 - a.0) * s + off, a.1 + (b.1 - a.1) * s - off);
        let pts = [a, b, c];
        let mut tri = [v(0.0, 0.0, 0.0, 1.0); 3];
        let mut col = [Rgb888::new(0, 0, 0); 3];
        for k in 0..3 {
            let ww = rng.range(0.2, 4.0);
            tri[k] = wvzw(pts[k].0, pts[k].1, 0.0, ww, w, h);
            col[k] = Rgb888::new(
                rng.int(0, 255) as u8,
                rng.int(0, 255) as u8,
                rng.int(0, 255) as u8,
            );
        }
        let Some(sv) = snap_tri::<8>(&tri, w, h) else {
            continue;
        };
        let area = orient(sv[0], sv[1], sv[2]);
        if area == 0 {
            continue;
        }
        let mut st = storage(1);
        let mut frame: Frame = Frame::new(config_nocull(w, h), &mut st).unwrap();
        frame.push_clip_triangle(tri, col, 0).unwrap();
        let mut img = vec![Rgb888::new(1, 2, 3); (w * h) as usize];
        frame.render_rows(0, h, &mut img[..], &mut NoDepth).unwrap();
        let cov = reference_coverage(sv, 8, w, h);
        for (k, &covered) in cov.iter().enumerate() {
            if !covered {
                continue;
            }
            let p = (
                centre((k as u32 % w) as i64, 8),
                centre((k as u32 / w) as i64, 8),
            );
            let mut bw = [0.0f64; 3];
            for m in 0..3 {
                bw[m] = orient(sv[(m + 1) % 3], sv[(m + 2) % 3], p) as f64
                    / area as f64
                    / tri[m].w as f64;
            }
            let den: f64 = bw.iter().sum();
            use microraster::pixelcolor::RgbColor;
            let ch = |c: Rgb888, i: usize| [c.r(), c.g(), c.b()][i] as f64;
            for i in 0..3 {
                let want = (0..3).map(|m| bw[m] * ch(col[m], i)).sum::<f64>() / den;
                let got = ch(img[k], i);
                if (got - want).abs() > 1.0 {
                    bad.push(format!(
                        "{pts:?} w {:?} area {area}: pixel ({}, {}) channel {i}: {got} vs {want:.2}",
                        tri.map(|t| t.w),
                        k as u32 % w,
                        k as u32 / w
                    ));
                }
            }
            checked += 1;
        }
    }
    assert!(checked > 8_000, "only {checked} pixels");
    assert!(
        bad.is_empty(),
        "{} channel values off by more than 1 LSB, e.g.\n{}",
        bad.len(),
        bad[..bad.len().min(6)].join("\n")
    );
}

/// Minimal repro for the sliver colour error: a thin triangle whose box
/// is under 24 px wide (the small-box path steps the colour sums in f32
/// from the box's left end); pixel (16, 36) gets blue 180 where the f64
/// perspective-correct value is 181.13.
#[test]
fn gouraud_sliver_small_box_within_1_lsb() {
    let tri = [
        v(-0.7607876, 0.11132787, 0.0, 2.0690444),
        v(-0.41330773, -0.41330773, 0.0, 0.41330773),
        v(-3.5952766, -3.7410781, 0.0, 3.375821),
    ];
    let col = [
        Rgb888::new(76, 210, 177),
        Rgb888::new(163, 248, 174),
        Rgb888::new(133, 138, 255),
    ];
    let (w, h) = (64u32, 64u32);
    let mut st = storage(1);
    let mut frame: Frame = Frame::new(config_nocull(w, h), &mut st).unwrap();
    frame.push_clip_triangle(tri, col, 0).unwrap();
    let mut img = vec![Rgb888::new(1, 2, 3); (w * h) as usize];
    frame.render_rows(0, h, &mut img[..], &mut NoDepth).unwrap();
    let sv = snap_tri::<8>(&tri, w, h).unwrap();
    let area = orient(sv[0], sv[1], sv[2]) as f64;
    let p = (centre(16, 8), centre(36, 8));
    let bw: Vec<f64> = (0..3)
        .map(|m| orient(sv[(m + 1) % 3], sv[(m + 2) % 3], p) as f64 / area / tri[m].w as f64)
        .collect();
    let want = (0..3).map(|m| bw[m] * col[m].b() as f64).sum::<f64>() / bw.iter().sum::<f64>();
    use microraster::pixelcolor::RgbColor;
    let got = img[(36 * w + 16) as usize].b() as f64;
    assert!((got - want).abs() <= 1.0, "blue {got} vs {want:.3}");
}

/// Gouraud colour along the longest span a frame can have (16384 pixels,
/// one row) with per-vertex w: within 1 LSB of the f64 perspective-correct
/// value at every pixel, at both precisions (the float stepping along a
/// span must not drift).
#[test]
fn gouraud_across_a_16384_px_span_within_1_lsb() {
    use microraster::pixelcolor::RgbColor;
    let (w, h) = (MAX_DIMENSION, 1u32);
    let ndc = [(-1.0f32, -1.0f32), (3.0, -1.0), (-1.0, 3.0)];
    let col = [
        Rgb888::new(255, 0, 30),
        Rgb888::new(0, 255, 0),
        Rgb888::new(10, 0, 255),
    ];
    for ws in [[1.0f32, 1.0, 1.0], [1.0, 4.0, 0.5], [0.3, 2.0, 7.0]] {
        let tri: [Vec4; 3] =
            std::array::from_fn(|k| v(ndc[k].0 * ws[k], ndc[k].1 * ws[k], 0.0, ws[k]));
        for s4 in [false, true] {
            let mut img = vec![Rgb888::new(1, 2, 3); w as usize];
            let sv = if s4 {
                let mut st = storage(1);
                let mut f = Frame::<4>::new(config_nocull(w, h), &mut st).unwrap();
                f.push_clip_triangle(tri, col, 0).unwrap();
                f.render_rows(0, 1, &mut img[..], &mut NoDepth).unwrap();
                snap_tri::<4>(&tri, w, h).unwrap()
            } else {
                let mut st = storage(1);
                let mut f = Frame::<8>::new(config_nocull(w, h), &mut st).unwrap();
                f.push_clip_triangle(tri, col, 0).unwrap();
                f.render_rows(0, 1, &mut img[..], &mut NoDepth).unwrap();
                snap_tri::<8>(&tri, w, h).unwrap()
            };
            let s = if s4 { 4 } else { 8 };
            let area = orient(sv[0], sv[1], sv[2]) as f64;
            let mut worst = 0.0f64;
            for i in 0..w as i64 {
                let p = (centre(i, s), centre(0, s));
                let bw: Vec<f64> = (0..3)
                    .map(|m| {
                        orient(sv[(m + 1) % 3], sv[(m + 2) % 3], p) as f64 / area / ws[m] as f64
                    })
                    .collect();
                let den: f64 = bw.iter().sum();
                let ch = |c: Rgb888, n: usize| [c.r(), c.g(), c.b()][n] as f64;
                for n in 0..3 {
                    let want = (0..3).map(|m| bw[m] * ch(col[m], n)).sum::<f64>() / den;
                    worst = worst.max((ch(img[i as usize], n) - want).abs());
                }
            }
            assert!(worst <= 1.0, "w {ws:?} S4={s4}: worst error {worst:.3} LSB");
        }
    }
}
