//! Culling (§5).

use super::*;

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
            let culled = 2 - keep(ccw_front) as u64 - keep(!ccw_front) as u64;
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
