//! Slivers and edges through pixel centres.

use super::*;

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
