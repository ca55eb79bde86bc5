//! Snapping.

use super::*;

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
        frame.submit_clip_triangle(tri, col, 0).unwrap();
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
    frame.submit_clip_triangle(tri, col, 0).unwrap();
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
                let mut f = Frame::<4>::with_subpixel_bits(config_nocull(w, h), &mut st).unwrap();
                f.submit_clip_triangle(tri, col, 0).unwrap();
                f.render_rows(0, 1, &mut img[..], &mut NoDepth).unwrap();
                snap_tri::<4>(&tri, w, h).unwrap()
            } else {
                let mut st = storage(1);
                let mut f = Frame::<8>::new(config_nocull(w, h), &mut st).unwrap();
                f.submit_clip_triangle(tri, col, 0).unwrap();
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
