//! Huge coordinates, clipping, guard band (§7, §8).

use super::*;

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
