//! Occlusion culling from arbitrary input (`fuzz_targets/occlusion.rs`):
//! a few small objects, each with an arbitrary matrix and bounds that are
//! honest (`BoundingSphere::from_points`, `Aabb::from_points`) or arbitrary
//! (NaN, infinite, inverted, huge), drawn into an arbitrary strip through
//! an occluder with an honest or arbitrary number of hi-z tiles, under any
//! depth test.
//!
//! Checks: no panic; too few tiles is exactly `Error::HiZSize`; every
//! object is counted once (`check_accounting`); and with honest bounds the
//! strip's colour and depth are the plain strip's, byte for byte.

use crate::{check_accounting, MatIn, F};
use libfuzzer_sys::arbitrary::{self, Arbitrary};
use microraster::occlusion::{tiles_for, Aabb, HiZTile};
use microraster::pixelcolor::Rgb888;
use microraster::prelude::Submit;
use microraster::{
    BoundingSphere, Config, CullMode, DepthFunc, Error, Mesh, MeshColors, ProcessedVertex,
    StripRenderer, Vec3,
};

/// One object.
#[derive(Arbitrary, Clone, Debug)]
pub struct ObjectIn {
    positions: Vec<[i8; 3]>,
    indices: Vec<[u8; 3]>,
    mvp: MatIn,
    honest: bool,
    sphere: [F; 4],
    aabb: [F; 6],
    use_box: bool,
}

/// The input.
#[derive(Arbitrary, Clone, Debug)]
pub struct OcclusionInput {
    objects: Vec<ObjectIn>,
    size: [u8; 2],
    rows: [u8; 2],
    tiles: u8,
    honest_tiles: bool,
    depth_func: u8,
    cull: u8,
}

/// Runs one input.
pub fn run_occlusion(input: &OcclusionInput) {
    let (w, h) = (
        u32::from(input.size[0] % 64) + 1,
        u32::from(input.size[1] % 48) + 1,
    );
    let y0 = u32::from(input.rows[0]) % h;
    let y1 = (y0 + u32::from(input.rows[1]) % h + 1).min(h);
    let mut config = Config::new(w, h);
    config.depth_func = [
        DepthFunc::Less,
        DepthFunc::LessEqual,
        DepthFunc::Greater,
        DepthFunc::Always,
        DepthFunc::Equal,
    ][usize::from(input.depth_func % 5)];
    config.cull = [CullMode::Back, CullMode::None][usize::from(input.cull % 2)];
    let objects: Vec<_> = input
        .objects
        .iter()
        .take(6)
        .map(|o| {
            let p: Vec<Vec3> = o
                .positions
                .iter()
                .take(32)
                .map(|c| Vec3::new(c[0] as f32 / 16.0, c[1] as f32 / 16.0, c[2] as f32 / 16.0))
                .collect();
            let t: Vec<[u32; 3]> = o
                .indices
                .iter()
                .take(32)
                .map(|t| t.map(|i| u32::from(i) % (p.len().max(1) as u32)))
                .collect();
            let (sphere, aabb) = if o.honest {
                (BoundingSphere::from_points(&p), Aabb::from_points(&p))
            } else {
                let s = o.sphere.map(|f| f.0);
                let b = o.aabb.map(|f| f.0);
                (
                    Some(BoundingSphere {
                        center: Vec3::new(s[0], s[1], s[2]),
                        radius: s[3],
                    }),
                    Some(Aabb::new(
                        Vec3::new(b[0], b[1], b[2]),
                        Vec3::new(b[3], b[4], b[5]),
                    )),
                )
            };
            (p, t, o.mvp.matrix(), sphere, aabb.filter(|_| o.use_box))
        })
        .collect();
    let honest = input.objects.iter().take(6).all(|o| o.honest);
    let n = (w * (y1 - y0)) as usize;
    let draw = |occlude: bool| -> Option<(Vec<Rgb888>, Vec<u16>)> {
        let mut color = vec![Rgb888::new(1, 2, 3); n];
        let mut depth = vec![u16::MAX; n];
        let mut r = StripRenderer::new(config, y0, y1, &mut color, &mut depth[..]).ok()?;
        let need = tiles_for(w, y1 - y0);
        let count = if input.honest_tiles {
            need
        } else {
            usize::from(input.tiles)
        };
        let mut tiles = vec![HiZTile::default(); count];
        let mut cache = vec![ProcessedVertex::EMPTY; 32];
        if occlude {
            let mut o = match r.occluder(&mut tiles) {
                Ok(o) => o,
                Err(e) => {
                    assert!(count < need);
                    assert_eq!(
                        e,
                        Error::HiZSize {
                            expected: need,
                            actual: count
                        }
                    );
                    return None;
                }
            };
            assert!(count >= need);
            for (k, (p, t, mvp, sphere, aabb)) in objects.iter().enumerate() {
                let mesh = Mesh {
                    positions: p,
                    indices: t,
                    attributes: MeshColors::Uniform(Rgb888::new(k as u8 * 40, 9, 9)),
                    bounds: None,
                };
                let before = o.stats();
                let c = &mut cache[..p.len()];
                let res =
                    o.submit_bounded(sphere.as_ref(), aabb.as_ref(), mvp, t.len() as u64, |r| {
                        r.submit_mesh_cached(&mesh, mvp, 0, c)
                    });
                assert!(res.is_ok(), "{res:?}");
                check_accounting(&before, &o.stats(), t.len() as u64);
            }
        } else {
            for (k, (p, t, mvp, _, _)) in objects.iter().enumerate() {
                let mesh = Mesh {
                    positions: p,
                    indices: t,
                    attributes: MeshColors::Uniform(Rgb888::new(k as u8 * 40, 9, 9)),
                    bounds: None,
                };
                r.submit_mesh_cached(&mesh, mvp, 0, &mut cache[..p.len()])
                    .ok()?;
            }
        }
        Some((color, depth))
    };
    let culled = draw(true);
    if honest {
        if let (Some(a), Some(b)) = (culled, draw(false)) {
            assert!(a == b, "occlusion changed the strip");
        }
    }
}
