//! The normal masks' frustum test against brute force: for any camera,
//! from near to far and from a near plane at 1e-3 to one at 1 with the
//! eye up to 1,000 units from the origin (where a mask built from the
//! eye's position in `f32` went wrong), every normal of a class in the
//! lecture's mask (`BackMask::geometric`, no size guard: a superset of
//! the exact mask), at any visible point, makes a small triangle that the
//! projection, evaluated in `f64`, shows with the culled winding.

use microraster::normal_mask::{class_count, classify, MAX_PARTITIONS};
use microraster::{
    BackMask, BoundingSphere, Config, CullMode, FrontFace, Mat4, NormalClasses, Vec3,
};
use proptest::prelude::*;

/// `A^-1` of a 4x4 matrix (rows), by Gauss-Jordan with pivoting.
fn inverse(a: [[f64; 4]; 4]) -> Option<[[f64; 4]; 4]> {
    let mut m = [[0.0; 8]; 4];
    for i in 0..4 {
        m[i][..4].copy_from_slice(&a[i]);
        m[i][4 + i] = 1.0;
    }
    for col in 0..4 {
        let piv = (col..4).max_by(|&i, &j| m[i][col].abs().total_cmp(&m[j][col].abs()))?;
        if m[piv][col].abs() < 1e-300 {
            return None;
        }
        m.swap(col, piv);
        let d = m[col][col];
        for v in m[col].iter_mut() {
            *v /= d;
        }
        for r in 0..4 {
            if r != col {
                let f = m[r][col];
                let pivot_row = m[col];
                for (v, p) in m[r].iter_mut().zip(pivot_row) {
                    *v -= f * p;
                }
            }
        }
    }
    Some(core::array::from_fn(|i| {
        core::array::from_fn(|j| m[i][4 + j])
    }))
}

/// A unit normal of cell `(face, i, j)` at `(fu, fv)` within it (0..1).
fn cell_normal(face: usize, i: usize, j: usize, n: usize, fu: f64, fv: f64) -> [f64; 3] {
    let (a, s) = (face / 2, if face.is_multiple_of(2) { 1.0 } else { -1.0 });
    let step = 2.0 / n as f64;
    let mut m = [0.0; 3];
    m[a] = s;
    m[(a + 1) % 3] = -1.0 + step * (i as f64 + fu);
    m[(a + 2) % 3] = -1.0 + step * (j as f64 + fv);
    let l = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
    m.map(|v| v / l)
}

/// Checks every class of the lecture's mask for one camera (see the
/// module note); `samples` are `(fu, fv, x, y, z)`: the place in the cell
/// and a clip point, besides every cell corner at every viewport corner.
#[allow(clippy::too_many_arguments)]
fn check(
    dist: f32,
    dir: [f32; 3],
    target: [f32; 3],
    near: f32,
    far: f32,
    fov: f32,
    aspect: f32,
    partitions: u8,
    front: bool,
    cull_front: bool,
    samples: &[(f64, f64, f64, f64, f64)],
) -> Result<(), TestCaseError> {
    let l = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
    if l <= 0.1 {
        return Ok(());
    }
    let eye = Vec3::new(dir[0] / l * dist, dir[1] / l * dist, dir[2] / l * dist);
    let up = if dir[1].abs() / l > 0.9 {
        Vec3::new(1.0, 0.0, 0.0)
    } else {
        Vec3::new(0.0, 1.0, 0.0)
    };
    let view = Mat4::look_at(eye, Vec3::from_array(target), up);
    let mvp = Mat4::perspective(fov, aspect, near, far) * view;
    let mut config = Config::new(64, 48);
    config.cull = if cull_front {
        CullMode::Front
    } else {
        CullMode::Back
    };
    config.front_face = if front { FrontFace::Cw } else { FrontFace::Ccw };
    let n = class_count(partitions);
    let sizes = vec![[1.0f32; 2]; n];
    let spheres = vec![BoundingSphere::EVERYWHERE; n];
    let set = NormalClasses {
        partitions,
        classes: &[],
        sizes: &sizes,
        spheres: &spheres,
    };
    let mask = BackMask::geometric::<8>(&mvp, &config, None, &set);
    let c = &mvp.cols;
    let a: [[f64; 4]; 4] = core::array::from_fn(|i| core::array::from_fn(|j| f64::from(c[j][i])));
    let inv = inverse(a).unwrap();
    let p = usize::from(partitions);
    // The lecture's mask is never empty for these cameras (a good
    // share of the cube faces away from the whole frustum).
    prop_assert!(
        !mask.is_empty() || fov > 1.2 || partitions < 4,
        "an empty mask"
    );
    for class in 0..n {
        if !mask.contains(class as u16) {
            continue;
        }
        let (face, i, j) = (class / (p * p), (class / p) % p, class % p);
        // The extremes (every cell corner at every corner of the sector:
        // the viewport with a pixel's margin, which the mask promises)
        // and random points.
        let (mx, my) = (1.0 + 2.0 / 64.0, 1.0 + 2.0 / 48.0);
        let corners = (0..16).map(|k| {
            let b = |bit: usize| if k >> bit & 1 == 1 { 1.0 } else { 0.0 };
            (
                b(0),
                b(1),
                mx * (2.0 * b(2) - 1.0),
                my * (2.0 * b(3) - 1.0),
                0.0,
            )
        });
        for (fu, fv, x, y, z) in corners.chain(samples.iter().copied()) {
            let nrm = cell_normal(face, i, j, p, fu, fv);
            if fu > 0.0 && fu < 1.0 && fv > 0.0 && fv < 1.0 {
                assert_eq!(usize::from(classify(nrm, partitions)), class, "{nrm:?}");
            }
            // A visible point: clip (x, y, z, 1) to object space.
            let q = [x, y, z, 1.0];
            let h: [f64; 4] = core::array::from_fn(|r| (0..4).map(|k| inv[r][k] * q[k]).sum());
            let pt = [h[0] / h[3], h[1] / h[3], h[2] / h[3]];
            // A small triangle at it with normal `nrm`.
            let t1 = if nrm[0].abs() < 0.9 {
                [1.0, 0.0, 0.0]
            } else {
                [0.0, 1.0, 0.0]
            };
            let u = [
                nrm[1] * t1[2] - nrm[2] * t1[1],
                nrm[2] * t1[0] - nrm[0] * t1[2],
                nrm[0] * t1[1] - nrm[1] * t1[0],
            ];
            let v = [
                nrm[1] * u[2] - nrm[2] * u[1],
                nrm[2] * u[0] - nrm[0] * u[2],
                nrm[0] * u[1] - nrm[1] * u[0],
            ];
            // u x v = nrm (|u| |v| scaled): counter-clockwise about nrm.
            let eps = 1e-4 * (near as f64);
            let verts = [
                pt,
                core::array::from_fn::<f64, 3, _>(|k| pt[k] + eps * u[k]),
                core::array::from_fn::<f64, 3, _>(|k| pt[k] + eps * v[k]),
            ];
            let ndc: Vec<[f64; 2]> = verts
                .iter()
                .map(|w| {
                    let r = |i: usize| (0..3).map(|k| a[i][k] * w[k]).sum::<f64>() + a[i][3];
                    [r(0) / r(3), r(1) / r(3)]
                })
                .collect();
            let area = (ndc[1][0] - ndc[0][0]) * (ndc[2][1] - ndc[0][1])
                - (ndc[2][0] - ndc[0][0]) * (ndc[1][1] - ndc[0][1]);
            // Counter-clockwise in NDC is a positive area.
            let front_facing = if front { area < 0.0 } else { area > 0.0 };
            let culled = if cull_front {
                front_facing
            } else {
                !front_facing
            };
            prop_assert!(
                culled,
                "class {class} masked, but a normal {nrm:?} at {pt:?} shows area {area:e}"
            );
        }
    }
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

    #[test]
    fn masked_normals_face_away_from_every_visible_point(
        dist in prop::sample::select(vec![1.0f32, 10.0, 100.0, 1000.0]),
        dir in prop::array::uniform3(-1.0f32..1.0),
        target in prop::array::uniform3(-1.0f32..1.0),
        near in prop::sample::select(vec![1e-3f32, 1e-2, 0.1, 1.0]),
        fov in 0.2f32..2.6,
        aspect in 0.5f32..2.0,
        partitions in 1u8..=MAX_PARTITIONS,
        front in any::<bool>(),
        cull_front in any::<bool>(),
        samples in prop::collection::vec((0.0f64..1.0, 0.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0, -0.99f64..0.99), 24),
    ) {
        check(dist, dir, target, near, dist * 4.0 + 10.0, fov, aspect, partitions, front, cull_front, &samples)?;
    }
}

/// A far eye and a near plane: the eye 1,000 units out, the near plane at
/// 1e-3. Built from the eye's position rounded to `f32`, the corner
/// directions were off by 1.6e-2 here and 8 front-facing classes went
/// into the mask (found in review).
#[test]
fn a_far_eye_with_a_near_plane_masks_no_front_face() {
    for partitions in [4, 8, 16] {
        check(
            1000.0,
            [1.0, 0.3, 0.2],
            [0.0; 3],
            1e-3,
            1e4,
            0.9,
            4.0 / 3.0,
            partitions,
            false,
            false,
            &[],
        )
        .unwrap();
    }
}
