//! The cluster tests' bounds against brute force: whatever a culling
//! volume or a normal cone reports for an eye, every triangle of the set,
//! evaluated exactly in `f64`, agrees. The volume says back-facing only
//! where every triangle's facing value `n . (e - p)` is negative, and
//! front-facing only where every one is positive. The cone says
//! back-facing only where every one is negative. Random sets of up to 16
//! triangles, random local origins, eyes anywhere in a box around them
//! (a geometric eye, `Eye::at`: no size guard).

mod common;

use microraster::cull::{CullVolume, Eye, Facing, NormalCone};
use microraster::Vec3;
use proptest::prelude::*;

fn facing_values(p: &[Vec3], t: &[[u32; 3]], e: [f32; 3]) -> Vec<f64> {
    let f = |v: Vec3| [v.x as f64, v.y as f64, v.z as f64];
    let e = e.map(f64::from);
    t.iter()
        .map(|i| {
            let [a, b, c] = i.map(|k| f(p[k as usize]));
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            n[0] * (e[0] - a[0]) + n[1] * (e[1] - a[1]) + n[2] * (e[2] - a[2])
        })
        .collect()
}

/// A patch of triangles around a random point with normals near a random
/// direction (so that sets are often wholly back- or front-facing).
fn patch() -> impl Strategy<Value = (Vec<Vec3>, Vec<[u32; 3]>)> {
    (
        prop::array::uniform3(-2.0f32..2.0),
        prop::collection::vec(prop::array::uniform3(-1.0f32..1.0), 3..48),
        0.0f32..1.0,
    )
        .prop_map(|(c, pts, flat)| {
            // Squash z to make the patch nearly planar.
            let p: Vec<Vec3> = pts
                .iter()
                .map(|q| Vec3::new(c[0] + q[0], c[1] + q[1], c[2] + q[2] * flat))
                .collect();
            let t = (0..p.len() / 3)
                .map(|k| [3 * k as u32, 3 * k as u32 + 1, 3 * k as u32 + 2])
                .collect();
            (p, t)
        })
}

proptest! {
    #![proptest_config(common::cases(4000))]

    #[test]
    fn volumes_and_cones_never_misreport_a_triangle(
        (p, t) in patch(),
        corner in 0usize..9,
        eye in prop::array::uniform3(-6.0f32..6.0),
    ) {
        let (mut lo, mut hi) = ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]);
        for q in &p {
            for (a, v) in [q.x, q.y, q.z].into_iter().enumerate() {
                lo[a] = lo[a].min(v);
                hi[a] = hi[a].max(v);
            }
        }
        let origin: [f32; 3] = core::array::from_fn(|a| match corner {
            8 => 0.5 * (lo[a] + hi[a]),
            c => if c >> a & 1 == 0 { lo[a] } else { hi[a] },
        });
        let vol = CullVolume::from_triangles(&p, &t, origin);
        let cone = NormalCone::from_triangles(&p, &t);
        let e = Eye::at(eye).unwrap();
        let f = facing_values(&p, &t, eye);
        match vol.facing(&e) {
            Facing::Back => prop_assert!(f.iter().all(|&v| v < 0.0), "{f:?}"),
            Facing::Front => prop_assert!(f.iter().all(|&v| v > 0.0), "{f:?}"),
            Facing::Mixed => {}
        }
        if cone.back_facing(&e) {
            prop_assert!(f.iter().all(|&v| v < 0.0), "{f:?}");
        }
    }
}

/// The property above is not vacuous: over a fixed set of draws both
/// verdicts occur.
#[test]
fn the_bounds_property_sees_both_verdicts() {
    let mut rng = common::SplitMix(7);
    let (mut back, mut front, mut cone) = (0, 0, 0);
    for _ in 0..2000 {
        let mut r = || rng.range(-1.0, 1.0) as f32;
        let c = [r() * 2.0, r() * 2.0, r() * 2.0];
        let p: Vec<Vec3> = (0..12)
            .map(|_| Vec3::new(c[0] + r(), c[1] + r(), c[2] + 0.05 * r()))
            .collect();
        let t: Vec<[u32; 3]> = (0..4).map(|k| [3 * k, 3 * k + 1, 3 * k + 2]).collect();
        let vol = CullVolume::from_triangles(&p, &t, c);
        let e = Eye::at([r() * 6.0, r() * 6.0, r() * 6.0]).unwrap();
        match vol.facing(&e) {
            Facing::Back => back += 1,
            Facing::Front => front += 1,
            Facing::Mixed => {}
        }
        cone += usize::from(NormalCone::from_triangles(&p, &t).back_facing(&e));
    }
    assert!(
        back > 20 && front > 20 && cone > 20,
        "{back} {front} {cone}"
    );
}
