//! Depth.

use super::*;
#[allow(unused_imports)]
use crate::{frame_sizes::exact_depth, near_far::depth_quad};

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
                    frame.submit_clip_triangle(t, RED3, 0).unwrap();
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
    let mut frame = Frame::<S>::with_subpixel_bits(cfg, &mut st).unwrap();
    frame.submit_clip_triangle(tri, RED3, 0).unwrap();
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
        frame.submit_clip_triangle(tri, col, 0).unwrap();
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
            frame.submit_clip_triangle(*t, RED3, i as u32).unwrap();
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
