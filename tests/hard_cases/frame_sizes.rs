//! Extreme frame sizes.

use super::*;

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
    let mut frame: Frame<'_, 4> = Frame::with_subpixel_bits(config_nocull(1, 1), &mut st).unwrap();
    frame.submit_clip_triangle(ur, RED3, 0).unwrap();
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
pub(crate) fn exact_depth(t: &SetupTriangle, s: u32, i: i64, j: i64) -> i128 {
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
    let mut frame = Frame::<S>::with_subpixel_bits(cfg, &mut st).unwrap();
    for (i, t) in quad.iter().enumerate() {
        frame.submit_clip_triangle(*t, RED3, i as u32).unwrap();
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
