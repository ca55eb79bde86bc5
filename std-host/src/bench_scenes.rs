//! The built-in scenes of `microraster bench` (also `render --scene NAME`).
//!
//! Design: every scene is a plain [`Scene`] plus an optional
//! [`Spin`], the per-frame model rotation about the y axis that the
//! benchmark applies before frame `k` (angle `k * step`). Meshes are built
//! or loaded once, outside any timed region. The scenes of issue 4:
//!
//! | name | what | default size |
//! |---|---|---|
//! | `cubes` | the default four cubes, flat | 800x600 |
//! | `sphere` | tgx's scene: UV sphere 100 stacks x 100 slices = 20,000 triangles, radius 1, at z = -3.2, 45° vertical fov, near 1, far 100, Gouraud (colour from the normal), spinning 1° per frame about y | 240x320 |
//! | `bunny` | the Stanford bunny (69,451 triangles), Gouraud (head-light Lambert on vertex normals) | 1920x1080 |
//! | `bunny-subdiv` | the bunny with every triangle split 1→4 at its edge midpoints, twice (1,111,216 triangles) | 1920x1080 |
//! | `quad` | two flat triangles covering the whole frame at depth 0.5 | 1920x1080 |
//! | `spots` | a 10x10 grid of Spot (5,856 triangles each, 585,600 in all), Gouraud, seen from eye height outside the grid, drawn front to back (the occlusion-culling scene, `docs/culling.md`) | 320x240 |
//! | `house` | an 8x8 house of rooms joined by doors, each with two crates and a ball (54,744 triangles), seen from camera 0 of `portal::house_camera`; with `View::portals`, only the rooms seen through doors (the portal-culling scene, `docs/culling.md`) | 320x240 |
//!
//! The sphere has exactly `2 * stacks * slices` triangles like tgx's: each
//! (stack, slice) cell is a quad split into two triangles, including the
//! cells at the poles, where the quad has two coincident corners and one of
//! its triangles is degenerate (zero area; the core counts it as
//! `culled_degenerate`). So 100 x 100 gives 20,000 triangles, 200 of them
//! degenerate.
//!
//! The bunny is read from `assets/models/stanford-bunny.obj` in the
//! repository (path fixed at compile time, see [`BUNNY_OBJ`]).

use crate::obj;
use crate::scene::{self, Object, ObjectColors, Scene, View};
use microraster::pixelcolor::Rgb888;
use microraster::{BoundingSphere, Mat4, Vec3};
use std::collections::HashMap;
use std::path::Path;

/// Names of the built-in scenes.
pub const NAMES: [&str; 7] = [
    "cubes",
    "sphere",
    "bunny",
    "bunny-subdiv",
    "quad",
    "spots",
    "house",
];

/// The bunny mesh shipped in the repository.
pub const BUNNY_OBJ: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../assets/models/stanford-bunny.obj"
);

/// Triangles of the Stanford bunny as stored.
pub const BUNNY_TRIANGLES: usize = 69_451;

/// tgx's sphere: stacks and slices.
pub const SPHERE_STACKS: u32 = 100;
/// tgx's sphere: stacks and slices.
pub const SPHERE_SLICES: u32 = 100;
/// Distance of the sphere's centre in front of the eye.
pub const SPHERE_Z: f32 = -3.2;

/// Per-frame rotation of every object about the y axis through its pivot.
#[derive(Clone, Debug, PartialEq)]
pub struct Spin {
    /// Radians per frame.
    pub step: f32,
    /// One entry per object of the scene.
    pub objects: Vec<SpinObject>,
}

/// How one object is placed while it spins:
/// `mvp(k) = view_proj * T(position) * Ry(k * step) * T(-pivot)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpinObject {
    /// Projection times view.
    pub view_proj: Mat4,
    /// Where the pivot ends up in world space.
    pub position: Vec3,
    /// The point (object space) the object turns about.
    pub pivot: Vec3,
}

impl Spin {
    /// Sets the objects' matrices for frame `frame`.
    pub fn apply(&self, scene: &mut Scene, frame: u32) {
        let angle = self.step * frame as f32;
        for (o, s) in scene.objects.iter_mut().zip(&self.objects) {
            o.mvp = s.view_proj
                * Mat4::translation(s.position)
                * Mat4::rotation_y(angle)
                * Mat4::translation(-s.pivot);
        }
    }

    /// Spins every object of `scene` in place (about its bounding sphere's
    /// centre) by `step_deg` degrees a frame, keeping its current matrix as
    /// the view-projection.
    pub fn in_place(scene: &Scene, step_deg: f32) -> Spin {
        Spin {
            step: step_deg.to_radians(),
            objects: scene
                .objects
                .iter()
                .map(|o| {
                    let c = o.bounds.map(|b| b.center).unwrap_or(Vec3::ZERO);
                    SpinObject {
                        view_proj: o.mvp,
                        position: c,
                        pivot: c,
                    }
                })
                .collect(),
        }
    }
}

/// A scene ready to benchmark.
#[derive(Clone, Debug)]
pub struct BenchScene {
    /// The name it is reported under.
    pub name: String,
    /// Triangles in drawing order.
    pub scene: Scene,
    /// The per-frame rotation, if the scene spins.
    pub spin: Option<Spin>,
}

impl BenchScene {
    /// The scene as drawn in frame `frame` (the spin applied).
    pub fn set_frame(&mut self, frame: u32) {
        if let Some(spin) = &self.spin {
            spin.apply(&mut self.scene, frame);
        }
    }
}

/// Why `--eye`, `--target` and `--fov` are refused for the quad.
pub const NO_CAMERA_QUAD: &str = "the quad scene is two triangles given in clip space and has \
     no camera: --eye, --target and --fov do not apply to it";

/// Default frame size of a built-in scene.
pub fn default_size(name: &str) -> (u32, u32) {
    match name {
        "cubes" => (800, 600),
        "sphere" => (240, 320),
        "spots" | "house" => (320, 240),
        _ => (1920, 1080),
    }
}

/// Builds the built-in scene `name` for `view`. The quad has no camera, so
/// a camera setting in `view` is an error there.
pub fn builtin(name: &str, view: &View) -> Result<BenchScene, String> {
    let (scene, spin) = match name {
        "cubes" => (scene::cubes_scene(view)?, None),
        "sphere" => {
            let (scene, spin) = sphere_scene(view, SPHERE_STACKS, SPHERE_SLICES)?;
            (scene, Some(spin))
        }
        "bunny" => (bunny_scene(view, 0)?, None),
        "bunny-subdiv" => (bunny_scene(view, 2)?, None),
        "spots" => (spots_scene(view)?, None),
        "house" => (crate::portal::house_scene(view)?.0, None),
        "quad" if view.has_camera() => return Err(NO_CAMERA_QUAD.to_string()),
        "quad" => (quad_scene(), None),
        other => {
            return Err(format!(
                "unknown scene {other:?} (known: {})",
                NAMES.join(", ")
            ))
        }
    };
    Ok(BenchScene {
        name: name.to_string(),
        scene,
        spin,
    })
}

/// A UV sphere of radius `radius` centred at the origin with
/// `2 * stacks * slices` triangles, counter-clockwise seen from outside.
///
/// Vertex `(i, j)` (`i` in `0..=stacks` from the north pole, `j` in
/// `0..slices`) is at index `i * slices + j`; the pole rows hold `slices`
/// coincident vertices each, so that every cell is a quad of two triangles
/// (the pole cells' second triangle has zero area).
pub fn uv_sphere(stacks: u32, slices: u32, radius: f32) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let (stacks, slices) = (stacks.max(2), slices.max(3));
    let mut positions = Vec::with_capacity(((stacks + 1) * slices) as usize);
    for i in 0..=stacks {
        let theta = std::f32::consts::PI * i as f32 / stacks as f32;
        let (st, ct) = theta.sin_cos();
        for j in 0..slices {
            let phi = std::f32::consts::TAU * j as f32 / slices as f32;
            let (sp, cp) = phi.sin_cos();
            // Exact poles, so the degenerate triangles really have zero area.
            let (st, ct) = if i == 0 {
                (0.0, 1.0)
            } else if i == stacks {
                (0.0, -1.0)
            } else {
                (st, ct)
            };
            positions.push(Vec3::new(radius * st * cp, radius * ct, -radius * st * sp));
        }
    }
    let idx = |i: u32, j: u32| i * slices + (j % slices);
    let mut indices = Vec::with_capacity((2 * stacks * slices) as usize);
    for i in 0..stacks {
        for j in 0..slices {
            let (a, b) = (idx(i, j), idx(i + 1, j));
            let (c, d) = (idx(i + 1, j + 1), idx(i, j + 1));
            // a-b-c and a-c-d are counter-clockwise seen from outside.
            indices.push([a, b, c]);
            indices.push([a, c, d]);
        }
    }
    (positions, indices)
}

/// Vertex colours from unit normals: `(n + 1) / 2` as RGB.
pub fn normal_colors(normals: &[Vec3]) -> Vec<Rgb888> {
    let ch = |v: f32| ((v * 0.5 + 0.5).clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
    normals
        .iter()
        .map(|n| Rgb888::new(ch(n.x), ch(n.y), ch(n.z)))
        .collect()
}

/// tgx's sphere scene for `view` (eye at the origin looking down -z unless
/// the view says otherwise), with its spin of 1° per frame.
pub fn sphere_scene(view: &View, stacks: u32, slices: u32) -> Result<(Scene, Spin), String> {
    let (positions, indices) = uv_sphere(stacks, slices, 1.0);
    // On a unit sphere the position is the normal.
    let colors = normal_colors(&positions);
    let fov = view.fov.unwrap_or(45.0);
    let proj = view.projection(fov.to_radians(), 1.0, 100.0);
    let view_m = match (view.eye, view.target) {
        (None, None) => Mat4::IDENTITY,
        (eye, target) => scene::look_at(
            eye.unwrap_or([0.0; 3]),
            target.unwrap_or([0.0, 0.0, SPHERE_Z]),
        )?,
    };
    let bounds = BoundingSphere::from_points(&positions);
    let spin = Spin {
        step: 1f32.to_radians(),
        objects: vec![SpinObject {
            view_proj: proj * view_m,
            position: Vec3::new(0.0, 0.0, SPHERE_Z),
            pivot: Vec3::ZERO,
        }],
    };
    let mut scene = Scene {
        objects: vec![Object {
            positions,
            indices,
            colors: ObjectColors::PerVertex(colors),
            bounds,
            mvp: Mat4::IDENTITY,
            clusters: None,
            normal_classes: None,
            aabb: None,
            parts: None,
            detail_fill: None,
        }],
        clip_tris: Vec::new(),
    };
    spin.apply(&mut scene, 0);
    Ok((scene, spin))
}

/// Area-weighted vertex normals (unit length; zero for unused vertices).
pub fn vertex_normals(positions: &[Vec3], indices: &[[u32; 3]]) -> Vec<Vec3> {
    let mut n = vec![Vec3::ZERO; positions.len()];
    for t in indices {
        let p = |k: usize| positions.get(t[k] as usize).copied();
        let (Some(a), Some(b), Some(c)) = (p(0), p(1), p(2)) else {
            continue;
        };
        let f = (b - a).cross(c - a);
        for &v in t {
            n[v as usize] = n[v as usize] + f;
        }
    }
    n.into_iter().map(Vec3::normalize).collect()
}

/// Splits every triangle into four at its edge midpoints; midpoints are
/// shared between the two triangles of an edge, so a closed mesh stays
/// closed. Triangles with an index out of range are dropped.
pub fn subdivide(positions: &[Vec3], indices: &[[u32; 3]]) -> (Vec<Vec3>, Vec<[u32; 3]>) {
    let mut pos = positions.to_vec();
    let mut mid: HashMap<(u32, u32), u32> = HashMap::with_capacity(indices.len() * 3 / 2);
    let mut out = Vec::with_capacity(indices.len() * 4);
    let n = positions.len() as u32;
    for &[a, b, c] in indices {
        if a >= n || b >= n || c >= n {
            continue;
        }
        let mut m = |u: u32, v: u32| -> u32 {
            let key = (u.min(v), u.max(v));
            *mid.entry(key).or_insert_with(|| {
                let p = (pos[u as usize] + pos[v as usize]) * 0.5;
                pos.push(p);
                (pos.len() - 1) as u32
            })
        };
        let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
        out.push([a, ab, ca]);
        out.push([ab, b, bc]);
        out.push([ca, bc, c]);
        out.push([ab, bc, ca]);
    }
    (pos, out)
}

/// Loads the repository's Stanford bunny.
pub fn load_bunny() -> Result<obj::LoadedMesh, String> {
    obj::load_obj(Path::new(BUNNY_OBJ))
}

/// The bunny (`subdivisions` times split 1→4), framed like `render --obj`
/// (or seen as `view` says), Gouraud-shaded by a head light.
pub fn bunny_scene(view: &View, subdivisions: u32) -> Result<Scene, String> {
    let mesh = load_bunny()?;
    gouraud_mesh_scene(&mesh, view, subdivisions)
}

/// A mesh framed like `render --obj` (or seen as `view` says), split
/// `subdivisions` times, with per-vertex head-light Lambert colours.
pub fn gouraud_mesh_scene(
    mesh: &obj::LoadedMesh,
    view: &View,
    subdivisions: u32,
) -> Result<Scene, String> {
    let fov = view.fov.unwrap_or(60.0);
    let (fe, ft) = obj::frame_camera(mesh, fov, view.aspect());
    let (eye, target) = (view.eye.unwrap_or(fe), view.target.unwrap_or(ft));
    let mut positions: Vec<Vec3> = mesh
        .positions
        .iter()
        .map(|&p| Vec3::from_array(p))
        .collect();
    let mut indices = mesh.indices.clone();
    for _ in 0..subdivisions {
        (positions, indices) = subdivide(&positions, &indices);
    }
    // The camera, near and far planes and bounds as `render --obj` has them
    // (only the colours differ), from the original mesh.
    let mut scene = scene::mesh_scene(
        &mesh.positions,
        &mesh.indices,
        eye,
        target,
        fov,
        view.aspect(),
        view.inv_w,
    )?;
    let light = (Vec3::from_array(eye) - Vec3::from_array(target)).normalize();
    let colors = vertex_normals(&positions, &indices)
        .iter()
        .map(|n| {
            let lambert = n.dot(light).max(0.0);
            let shade = |base: f32| ((0.15 + 0.85 * lambert) * base) as u8;
            Rgb888::new(shade(235.0), shade(215.0), shade(190.0))
        })
        .collect();
    if let Some(o) = scene.objects.first_mut() {
        o.positions = positions;
        o.indices = indices;
        o.colors = ObjectColors::PerVertex(colors);
    }
    Ok(scene)
}

/// Two flat triangles covering the whole frame at NDC depth 0 (window
/// depth 0.5), counter-clockwise, drawn with the identity matrix.
pub fn quad_scene() -> Scene {
    let positions = vec![
        Vec3::new(-1.0, -1.0, 0.0),
        Vec3::new(1.0, -1.0, 0.0),
        Vec3::new(1.0, 1.0, 0.0),
        Vec3::new(-1.0, 1.0, 0.0),
    ];
    let bounds = BoundingSphere::from_points(&positions);
    let color = Rgb888::new(40, 120, 200);
    Scene {
        objects: vec![Object {
            positions,
            indices: vec![[0, 1, 2], [0, 2, 3]],
            colors: ObjectColors::PerTriangle(vec![color; 2]),
            bounds,
            mvp: Mat4::IDENTITY,
            clusters: None,
            normal_classes: None,
            aabb: None,
            parts: None,
            detail_fill: None,
        }],
        clip_tris: Vec::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::{render, DepthKind, RenderOptions};
    use microraster::CullMode;

    fn opts(width: u32, height: u32, depth: DepthKind) -> RenderOptions {
        RenderOptions {
            width,
            height,
            cull: CullMode::Back,
            detail: 0,
            depth,
            subpixel: 8,
            threads: 1,
            strip_rows: 16,
            tile_width: 0,
            ids: false,
            mode: microraster::RasterMode::Clipping,
            inv_w: false,
            occlusion: crate::render::Occlusion::Off,
        }
    }

    #[test]
    fn names_match_the_cli() {
        assert_eq!(NAMES, crate::cli::SCENES);
        for name in NAMES {
            let (w, h) = default_size(name);
            assert!(w > 0 && h > 0);
        }
        assert!(builtin("teapot", &View::new(8, 8)).is_err());
    }

    #[test]
    fn sphere_has_tgx_triangle_count() {
        let (p, t) = uv_sphere(100, 100, 1.0);
        assert_eq!(t.len(), 20_000);
        assert_eq!(p.len(), 101 * 100);
        assert!(t.iter().flatten().all(|&i| (i as usize) < p.len()));
        for v in &p {
            assert!((v.length() - 1.0).abs() < 1e-5, "{v:?}");
        }
        // Exactly one degenerate triangle per pole cell.
        let degenerate = t
            .iter()
            .filter(|t| {
                t[0] == t[1] || t[1] == t[2] || t[0] == t[2] || {
                    let (a, b, c) = (p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
                    (b - a).cross(c - a).length() == 0.0
                }
            })
            .count();
        assert_eq!(degenerate, 200);
    }

    #[test]
    fn sphere_faces_outward() {
        let (p, t) = uv_sphere(8, 12, 1.0);
        for tri in &t {
            let (a, b, c) = (p[tri[0] as usize], p[tri[1] as usize], p[tri[2] as usize]);
            let n = (b - a).cross(c - a);
            let centroid = (a + b + c) * (1.0 / 3.0);
            assert!(n.dot(centroid) >= 0.0, "{tri:?}");
        }
    }

    #[test]
    fn sphere_scene_renders_a_disc_of_front_faces() {
        let view = View::new(240, 320);
        let (mut scene, spin) = sphere_scene(&view, 100, 100).unwrap();
        let r = render(&scene, &opts(240, 320, DepthKind::U16)).unwrap();
        let s = r.stats;
        assert_eq!(s.submitted, 20_000);
        assert_eq!(s.rejected_index + s.rejected_nonfinite + s.clipped, 0);
        // A bit more than half the faces point away (the eye sees 34% of
        // the surface); the sphere is slightly wider than the 240-pixel
        // frame, so some triangles leave it at the sides.
        assert!(
            s.culled_backface > 10_000 && s.culled_backface < 15_000,
            "{s:?}"
        );
        assert!(s.culled_frustum < 1_000, "{s:?}");
        // The silhouette: a disc of angular radius asin(1/3.2) over a 22.5°
        // half-fov (160 pixels), cut by the frame's sides.
        let r_px = (1.0f64 / 3.2).asin().tan() / 22.5f64.to_radians().tan() * 160.0;
        let mut area = 0.0;
        for y in 0..320 {
            for x in 0..240 {
                let (dx, dy) = (x as f64 + 0.5 - 120.0, y as f64 + 0.5 - 160.0);
                if dx * dx + dy * dy <= r_px * r_px {
                    area += 1.0;
                }
            }
        }
        let px = r.pixels_written as f64;
        assert!((px - area).abs() < 0.01 * area, "{px} vs {area}");
        // Frame 10 turns the sphere: same coverage, other colours.
        spin.apply(&mut scene, 10);
        let r10 = render(&scene, &opts(240, 320, DepthKind::U16)).unwrap();
        assert!((r10.pixels_written as f64 - px).abs() < 0.01 * px);
        assert_ne!(r10.rgb, r.rgb);
    }

    #[test]
    fn subdivision_multiplies_by_four_and_shares_midpoints() {
        let (p, t) = uv_sphere(6, 8, 1.0);
        let (p1, t1) = subdivide(&p, &t);
        assert_eq!(t1.len(), 4 * t.len());
        let (p2, t2) = subdivide(&p1, &t1);
        assert_eq!(t2.len(), 16 * t.len());
        assert_eq!(BUNNY_TRIANGLES * 16, 1_111_216);
        // A closed triangle mesh (a tetrahedron): V - E + F = 2 after splits,
        // i.e. new vertices = edges (shared midpoints).
        let tp = vec![
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::new(-1.0, -1.0, 1.0),
            Vec3::new(-1.0, 1.0, -1.0),
            Vec3::new(1.0, -1.0, -1.0),
        ];
        let tt = vec![[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]];
        let (sp, st) = subdivide(&tp, &tt);
        assert_eq!((sp.len(), st.len()), (4 + 6, 16));
        let (sp, st) = subdivide(&sp, &st);
        // E = 3F/2 = 96 edges before the second split: 10 + 24 vertices.
        assert_eq!((sp.len(), st.len()), (34, 64));
        // Total area is unchanged by midpoint splits.
        let area = |p: &[Vec3], t: &[[u32; 3]]| -> f32 {
            t.iter()
                .map(|t| {
                    let (a, b, c) = (p[t[0] as usize], p[t[1] as usize], p[t[2] as usize]);
                    (b - a).cross(c - a).length() * 0.5
                })
                .sum()
        };
        assert!((area(&p, &t) - area(&p2, &t2)).abs() < 1e-4);
        // Out-of-range triangles are dropped.
        let (_, bad) = subdivide(&tp, &[[0, 1, 9]]);
        assert!(bad.is_empty());
    }

    #[test]
    fn quad_covers_every_pixel_once() {
        let scene = quad_scene();
        for depth in [DepthKind::U16, DepthKind::U32, DepthKind::None] {
            let r = render(&scene, &opts(64, 48, depth)).unwrap();
            assert_eq!(r.stats.stored, 2);
            assert_eq!(r.pixels_written, 64 * 48);
        }
    }

    #[test]
    fn vertex_normals_of_a_sphere_point_outward() {
        let (p, t) = uv_sphere(12, 16, 1.0);
        let n = vertex_normals(&p, &t);
        // Away from the poles the vertex normal is the position.
        for (i, (p, n)) in p.iter().zip(&n).enumerate() {
            if (16..11 * 16).contains(&i) {
                assert!((*p - *n).length() < 0.05, "{p:?} {n:?}");
            }
        }
        assert_eq!(vertex_normals(&[Vec3::ZERO], &[])[0], Vec3::ZERO);
    }

    #[test]
    fn bunny_scene_loads() {
        let view = View::new(192, 108);
        let b = builtin("bunny", &view).unwrap();
        assert_eq!(b.scene.triangle_count(), BUNNY_TRIANGLES);
        let o = &b.scene.objects[0];
        match &o.colors {
            ObjectColors::PerVertex(c) => assert_eq!(c.len(), o.positions.len()),
            other => panic!("{other:?}"),
        }
        let r = render(&b.scene, &opts(192, 108, DepthKind::U32)).unwrap();
        assert!(r.pixels_written > 2_000, "{}", r.pixels_written);
    }

    #[test]
    fn bunny_subdiv_has_1_111_216_triangles() {
        let b = builtin("bunny-subdiv", &View::new(192, 108)).unwrap();
        assert_eq!(b.scene.triangle_count(), 1_111_216);
    }
}

/// Spot shipped in the repository.
pub const SPOT_OBJ: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../assets/models/spot.obj");

/// Spots a side of the `spots` scene's grid.
pub const SPOTS_GRID: usize = 10;

/// The grid's spacing between Spots' centres (Spot is 0.94 wide and 1.72
/// long, 1.69 high).
pub const SPOTS_SPACING: f32 = 2.0;

/// The camera's height above the grid's floor level (Spot's feet at
/// y = -0.74, its back at about 0.5, its head at 0.95): a grown-up's eye
/// among cows.
pub const SPOTS_EYE_Y: f32 = 0.45;

/// Camera `k` of `count` on a circle around the grid's centre, at eye
/// height, outside the grid by one spacing, looking at the centre: eye and
/// target.
pub fn spots_camera(k: usize, count: usize, n: usize) -> ([f32; 3], [f32; 3]) {
    let half = (n as f32 - 1.0) * 0.5 * SPOTS_SPACING;
    let radius = half * std::f32::consts::SQRT_2 * 0.75 + SPOTS_SPACING;
    let a = std::f32::consts::TAU * (k as f32 + 0.5) / count.max(1) as f32;
    (
        [radius * a.cos(), SPOTS_EYE_Y, radius * a.sin()],
        [0.0, 0.1, 0.0],
    )
}

/// Spot's mesh, centred on the grid's cells and coloured per vertex (a
/// fixed light, Lambert) in each instance's own tint.
#[derive(Clone, Debug)]
pub struct SpotGrid {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    shade: Vec<f32>,
    bounds: Option<BoundingSphere>,
    aabb: Option<microraster::occlusion::Aabb>,
    parts: std::sync::Arc<Vec<crate::occlusion::Part>>,
}

impl SpotGrid {
    /// Loads Spot.
    pub fn load() -> Result<SpotGrid, String> {
        let mesh = obj::load_obj(Path::new(SPOT_OBJ))?;
        let positions: Vec<Vec3> = mesh
            .positions
            .iter()
            .map(|&p| Vec3::from_array(p))
            .collect();
        let light = Vec3::new(0.4, 0.8, 0.45).normalize();
        let (indices, parts) =
            crate::occlusion::split(&positions, &mesh.indices, crate::occlusion::PART_TRIANGLES);
        let shade = vertex_normals(&positions, &indices)
            .iter()
            .map(|n| 0.2 + 0.8 * n.dot(light).max(0.0))
            .collect();
        Ok(SpotGrid {
            bounds: BoundingSphere::from_points(&positions),
            aabb: microraster::occlusion::Aabb::from_points(&positions),
            positions,
            indices,
            shade,
            parts: std::sync::Arc::new(parts),
        })
    }

    /// `n x n` Spots seen from `eye` towards `target` (`fov` degrees,
    /// `aspect`), drawn front to back: sorted by the distance from the eye
    /// to each bounding sphere's centre.
    pub fn scene(
        &self,
        n: usize,
        eye: [f32; 3],
        target: [f32; 3],
        fov: f32,
        aspect: f32,
        inv_w: bool,
    ) -> Result<Scene, String> {
        let extent = n as f32 * SPOTS_SPACING * 2.0 + 10.0;
        let proj = scene::projection(inv_w, microraster::math::radians(fov), aspect, 0.05, extent);
        let view_proj = proj * scene::look_at(eye, target)?;
        let spacing = SPOTS_SPACING;
        let half = (n as f32 - 1.0) * 0.5 * spacing;
        let mut objects = Vec::with_capacity(n * n);
        let mut order = Vec::with_capacity(n * n);
        for i in 0..n {
            for j in 0..n {
                let k = (i * n + j) as u32;
                let h = k.wrapping_mul(2_654_435_761);
                let yaw = (h >> 8) as f32 / 16_777_216.0 * std::f32::consts::TAU;
                let (x, z) = (i as f32 * spacing - half, j as f32 * spacing - half);
                let model = Mat4::translation(Vec3::new(x, 0.0, z)) * Mat4::rotation_y(yaw);
                let tint = [
                    150.0 + (h >> 24 & 63) as f32 * 1.5,
                    150.0 + (h >> 16 & 63) as f32 * 1.5,
                    150.0 + (h >> 10 & 63) as f32 * 1.5,
                ];
                let colors = self
                    .shade
                    .iter()
                    .map(|s| {
                        Rgb888::new(
                            (s * tint[0]) as u8,
                            (s * tint[1]) as u8,
                            (s * tint[2]) as u8,
                        )
                    })
                    .collect();
                let c = self.bounds.map_or(Vec3::new(0.0, 0.0, 0.0), |b| b.center);
                let world = model.transform_point(c);
                let d = [world.x - eye[0], world.y - eye[1], world.z - eye[2]];
                order.push(d.iter().map(|v| v * v).sum::<f32>());
                objects.push(Object {
                    positions: self.positions.clone(),
                    indices: self.indices.clone(),
                    colors: ObjectColors::PerVertex(colors),
                    bounds: self.bounds,
                    mvp: view_proj * model,
                    clusters: None,
                    normal_classes: None,
                    aabb: self.aabb,
                    parts: Some(self.parts.clone()),
                    detail_fill: None,
                });
            }
        }
        let mut idx: Vec<usize> = (0..objects.len()).collect();
        idx.sort_by(|&a, &b| order[a].total_cmp(&order[b]));
        let mut slots: Vec<Option<Object>> = objects.into_iter().map(Some).collect();
        let objects = idx.into_iter().filter_map(|i| slots[i].take()).collect();
        Ok(Scene {
            objects,
            clip_tris: Vec::new(),
        })
    }
}

/// The `spots` scene: [`SPOTS_GRID`]² Spots from camera 0 of
/// [`spots_camera`] (or as `view` says), 60° vertical field of view.
pub fn spots_scene(view: &View) -> Result<Scene, String> {
    let (e, t) = spots_camera(0, 64, SPOTS_GRID);
    SpotGrid::load()?.scene(
        SPOTS_GRID,
        view.eye.unwrap_or(e),
        view.target.unwrap_or(t),
        view.fov.unwrap_or(60.0),
        view.aspect(),
        view.inv_w,
    )
}
