//! The offline step of normal masks: each triangle's normal class and the
//! size bounds of every class, as the core's [`NormalClasses`] reads them.
//!
//! Design note: the normal of a triangle is its edges' cross product in
//! `f64` from the `f32` positions (exact differences), put in its cell of
//! the direction cube by the core's [`classify`]; a zero or non-finite
//! normal gets [`NO_CLASS`] (never skipped). Per class the size guard's
//! bounds come from the core's [`triangle_sizes`] over the class's
//! triangles, and one sphere bounds the whole mesh
//! ([`triangle_sphere`]). The triangles keep their order, so a masked
//! frame is compared with the source mesh's own. The data is 2 bytes a
//! triangle and 8 a class (12 KB at 16 partitions).

use microraster::cull::{triangle_sizes, triangle_sphere};
use microraster::normal_mask::{class_count, classify, NO_CLASS};
use microraster::{BoundingSphere, NormalClasses, Vec3};

/// A mesh's normal classes, owning the arrays a [`NormalClasses`] borrows.
#[derive(Clone, Debug)]
pub struct NormalClassData {
    /// Partitions a side of the direction cube.
    pub partitions: u8,
    /// One class per triangle.
    pub classes: Vec<u16>,
    /// Per class, its triangles' size bounds.
    pub sizes: Vec<[f32; 2]>,
    /// Per class, a sphere around its triangles.
    pub spheres: Vec<BoundingSphere>,
}

impl NormalClassData {
    /// The classes the core reads.
    pub fn set(&self) -> NormalClasses<'_> {
        NormalClasses {
            partitions: self.partitions,
            classes: &self.classes,
            sizes: &self.sizes,
            spheres: &self.spheres,
        }
    }

    /// The bytes of the precomputed data (class ids, sizes and spheres).
    pub fn data_bytes(&self) -> usize {
        std::mem::size_of_val(self.classes.as_slice())
            + std::mem::size_of_val(self.sizes.as_slice())
            + std::mem::size_of_val(self.spheres.as_slice())
    }
}

/// A triangle whose ratio of doubled area to edges is below the class's
/// median by this factor is left out of its class.
pub const EXEMPT_Q: f32 = 3.0;

/// Likewise for its doubled area.
pub const EXEMPT_A: f32 = 9.0;

/// The unit-free normal of a triangle in `f64`, `None` for a bad index.
fn normal(positions: &[Vec3], t: &[u32; 3]) -> Option<[f64; 3]> {
    let p = t.map(|k| positions.get(k as usize).copied());
    let [Some(a), Some(b), Some(c)] = p else {
        return None;
    };
    // Differences of f32 values are exact in f64.
    let d = |q: Vec3| {
        let [x, y, z] = [q.x, q.y, q.z].map(f64::from);
        [x - f64::from(a.x), y - f64::from(a.y), z - f64::from(a.z)]
    };
    let (u, v) = (d(b), d(c));
    Some([
        u[1] * v[2] - u[2] * v[1],
        u[2] * v[0] - u[0] * v[2],
        u[0] * v[1] - u[1] * v[0],
    ])
}

/// Classifies the triangles of a mesh on a direction cube of `partitions`
/// a side (`1..=16`). A triangle with a bad index gets [`NO_CLASS`].
pub fn build(
    positions: &[Vec3],
    indices: &[[u32; 3]],
    partitions: u8,
) -> Result<NormalClassData, String> {
    let n = class_count(partitions);
    if n == 0 {
        return Err(format!(
            "normal masks need 1 to {} partitions a side, not {partitions}",
            microraster::normal_mask::MAX_PARTITIONS
        ));
    }
    let classes: Vec<u16> = indices
        .iter()
        .map(|t| normal(positions, t).map_or(NO_CLASS, |m| classify(m, partitions)))
        .collect();
    let mut classes = classes;
    // Each triangle's own sizes; a class's guard is set by its smallest,
    // so the few far below the class's median are left out of it (never
    // masked, culled per triangle as before).
    let own: Vec<[f32; 2]> = indices
        .iter()
        .map(|t| triangle_sizes(positions, std::slice::from_ref(t)))
        .collect();
    let mut members: Vec<Vec<usize>> = vec![Vec::new(); n];
    for (i, &c) in classes.iter().enumerate() {
        if let Some(m) = members.get_mut(usize::from(c)) {
            m.push(i);
        }
    }
    let median = |v: &mut Vec<f32>| -> f32 {
        v.sort_by(f32::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(0.0)
    };
    let mut sizes = vec![[0.0f32; 2]; n];
    let mut spheres = vec![BoundingSphere::EVERYWHERE; n];
    for (c, m) in members.iter().enumerate() {
        if m.is_empty() {
            continue;
        }
        let q_med = median(&mut m.iter().map(|&i| own[i][0]).collect());
        let a_med = median(&mut m.iter().map(|&i| own[i][1]).collect());
        let mut kept = Vec::with_capacity(m.len());
        for &i in m {
            let [q, a] = own[i];
            if q * EXEMPT_Q < q_med || a * EXEMPT_A < a_med {
                classes[i] = NO_CLASS;
            } else {
                kept.push(indices[i]);
            }
        }
        if !kept.is_empty() {
            sizes[c] = triangle_sizes(positions, &kept);
            spheres[c] = triangle_sphere(positions, &kept);
        }
    }
    let data = NormalClassData {
        partitions,
        classes,
        sizes,
        spheres,
    };
    data.set()
        .validate(indices.len())
        .map_err(|e| e.to_string())?;
    Ok(data)
}

/// Gives every object of `scene` normal classes of `partitions` a side
/// (`render`/`bench --normal-masks N`): each object is then submitted
/// whole through `Submit::submit_masked`, its triangles in their order.
pub fn mask_scene(scene: &mut crate::scene::Scene, partitions: u8) -> Result<(), String> {
    for o in &mut scene.objects {
        let d = build(&o.positions, &o.indices, partitions)?;
        o.normal_classes = Some(std::sync::Arc::new(d));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cube_gets_one_class_a_face() {
        let p: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32))
            .collect();
        // Two faces, outward: -z (0,2,1),(1,2,3) and +z (4,5,6),(5,7,6).
        let t = [[0, 2, 1], [1, 2, 3], [4, 5, 6], [5, 7, 6], [0, 0, 1]];
        let d = build(&p, &t, 2).unwrap();
        assert_eq!(d.classes[0], d.classes[1]);
        assert_eq!(d.classes[2], d.classes[3]);
        assert_eq!(d.classes[4], NO_CLASS);
        assert_eq!(usize::from(d.classes[0]) / 4, 5);
        assert_eq!(usize::from(d.classes[2]) / 4, 4);
        assert!(d.sizes[usize::from(d.classes[0])][1] > 0.99);
        assert_eq!(d.data_bytes(), 5 * 2 + 24 * (8 + 16));
        assert!(build(&p, &t, 0).is_err());
    }
}
