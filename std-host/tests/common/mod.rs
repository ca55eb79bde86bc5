//! What the cluster and detail culling tests share: the case count, the
//! three closed meshes of `assets/models` built into cluster trees once,
//! and a camera about a mesh.

#![allow(dead_code)] // each test file uses its own part

use microraster::{BoundingSphere, Mat4, Vec3};
use microraster_host::cluster::{self, ClusterOptions, ClusteredMesh};
use std::sync::OnceLock;

/// `PROPTEST_CASES`, or `default`.
pub fn cases(default: u32) -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// A mesh of `assets/models` with its cluster tree (default options).
pub fn model(name: &str) -> ClusteredMesh {
    let path = format!("{}/../assets/models/{name}", env!("CARGO_MANIFEST_DIR"));
    let m = microraster_host::obj::load_obj(std::path::Path::new(&path)).unwrap();
    let p: Vec<Vec3> = m.positions.iter().map(|&a| Vec3::from_array(a)).collect();
    cluster::build(&p, &m.indices, &ClusterOptions::default()).unwrap()
}

/// The bunny, the teapot and Spot, built once per test binary.
pub fn models() -> &'static [ClusteredMesh; 3] {
    static M: OnceLock<[ClusteredMesh; 3]> = OnceLock::new();
    M.get_or_init(|| ["stanford-bunny.obj", "teapot.obj", "spot.obj"].map(model))
}

/// A camera at `dir * dist` bounding radii from the mesh's centre, looking
/// at a point `jitter` radii off it, with a 0.9 rad field of view, the
/// aspect `aspect`, the near plane at 0.05 radii and the far at `far`
/// radii. `None` for a direction of (almost) zero length.
pub fn camera(
    m: &ClusteredMesh,
    dir: [f32; 3],
    dist: f32,
    jitter: [f32; 3],
    far: f32,
    aspect: f32,
) -> Option<Mat4> {
    let b = BoundingSphere::from_points(&m.positions)?;
    let len = (dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]).sqrt();
    if len < 1e-3 {
        return None;
    }
    let eye = b.center + Vec3::from_array(dir.map(|c| c / len)) * (dist * b.radius);
    let target = b.center + Vec3::from_array(jitter) * b.radius;
    let view =
        microraster_host::scene::look_at([eye.x, eye.y, eye.z], [target.x, target.y, target.z])
            .ok()?;
    Some(Mat4::perspective(0.9, aspect, 0.05 * b.radius, far * b.radius) * view)
}
