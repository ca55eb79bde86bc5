//! `microraster cull`: cluster culling measured against per-triangle
//! culling on real meshes, from many cameras (the table of
//! `docs/culling.md`).
//!
//! Design note: every model is clustered once ([`crate::cluster`]) and seen
//! from `--cameras` directions (a Fibonacci sphere, `--distance` bounding
//! radii from its centre, looking at it). For each camera every method
//! draws the same frame, checked byte for byte against per-triangle
//! culling of the clustered mesh. Timing rounds are interleaved: each
//! round times every method over all cameras in turn (A B C ..., A B C
//! ...), so drift on a shared machine spreads over all of them; the table
//! quotes the median per-frame time over the rounds with its range. The
//! geometry stage is the submission alone (object cull, cluster tests,
//! transform, clip, setup into a frame); the frame adds drawing the whole
//! frame on one thread with a `u16` depth buffer. Three rows bound what
//! any such culling can gain: per camera, the clustered mesh cut (outside
//! the timing) to the triangles of the clusters that culling volumes over
//! the tree draw, to all but those per-triangle culling culls by winding,
//! and to those it sets up, each cut submitted per triangle with only its
//! vertices: the tree's cut with its tests free, a free and perfect
//! culling by facing, and a free and perfect culler (each cut, a copy of
//! the mesh for one camera, is submitted once untimed before it is timed,
//! so that it is in cache as the shared mesh is). `t/r` is measured: one
//! node test (over the leaves and the sample eyes) against the
//! geometry-stage time per triangle of per-triangle culling.

use crate::cli::CullArgs;
use crate::cluster::{self, ClusterOptions, ClusteredMesh};
use crate::normal_mask::{self, NormalClassData};
use microraster::cull::{Detail, Eye, Visit};
use microraster::normal_mask::NO_CLASS;
use microraster::prelude::*;
use microraster::{BackMask, DetailFill};
use microraster::{
    BoundingSphere, ClusterCull, ClusterTest, Config, Frame, Mat4, Mesh, MeshColors,
    ProcessedVertex, SetupTriangle, Stats, Vec3,
};
use serde::Serialize;
use std::time::Instant;

/// The methods compared, in table order.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Method {
    /// The source mesh (shared vertices), per-triangle culling.
    Source,
    /// The clustered mesh, per-triangle culling.
    Clustered,
    /// Culling volumes at the leaves.
    Volumes,
    /// Culling volumes, tree top-down.
    VolumesTree,
    /// Normal cones at the leaves.
    Cones,
    /// Normal cones, tree top-down.
    ConesTree,
    /// Culling volumes, tree top-down, with detail culling (lossy; only
    /// with `--detail`).
    Detail,
    /// [`Method::Detail`], with what it drops drawn as boxes in the
    /// mesh's colour (`DetailFill`; only with `--detail`).
    DetailBoxes,
    /// Normal masks of this many partitions a side, on the clustered
    /// mesh's triangle order (`--normal-masks`).
    Mask(u8),
    /// The floor of every culling before transform: per camera, the
    /// clustered mesh cut to the triangles that per-triangle culling sets
    /// up, with only their vertices, submitted per triangle. A
    /// perfect culler that cost nothing would submit that; its cut is made
    /// outside the timing.
    Floor,
    /// What culling volumes over the tree would cost if their tests and
    /// bookkeeping were free: like [`Method::Floor`], the triangles of the
    /// clusters [`Method::VolumesTree`] draws.
    FloorVolumes,
    /// The floor of culling by facing (every test here): like
    /// [`Method::Floor`], the triangles that per-triangle culling does not
    /// cull by winding (back faces left out, all else submitted).
    FloorFacing,
}

impl Method {
    /// All, in order.
    pub const ALL: [Method; 9] = [
        Method::Source,
        Method::Clustered,
        Method::Volumes,
        Method::VolumesTree,
        Method::Cones,
        Method::ConesTree,
        Method::FloorVolumes,
        Method::FloorFacing,
        Method::Floor,
    ];

    /// The setting (detail culling for [`Method::Detail`] is in the
    /// frame's `Config::detail`).
    fn cull(self) -> Option<ClusterCull> {
        let (test, hierarchy) = match self {
            Method::Source
            | Method::Clustered
            | Method::Mask(_)
            | Method::Floor
            | Method::FloorVolumes
            | Method::FloorFacing => return None,
            Method::Volumes => (ClusterTest::Volumes, false),
            Method::VolumesTree | Method::Detail | Method::DetailBoxes => {
                (ClusterTest::Volumes, true)
            }
            Method::Cones => (ClusterTest::Cones, false),
            Method::ConesTree => (ClusterTest::Cones, true),
        };
        Some(ClusterCull { test, hierarchy })
    }

    fn label(self) -> String {
        let s = match self {
            Method::Source => "per triangle, source mesh",
            Method::Clustered => "per triangle, clustered mesh",
            Method::Volumes => "culling volumes, leaves",
            Method::VolumesTree => "culling volumes, tree",
            Method::Cones => "normal cones, leaves",
            Method::ConesTree => "normal cones, tree",
            Method::Detail => "culling volumes, tree, detail",
            Method::DetailBoxes => "culling volumes, tree, boxes for detail",
            Method::Mask(n) => return format!("normal masks, N = {n}"),
            Method::Floor => "floor: only the triangles set up (a free, perfect culler)",
            Method::FloorVolumes => "culling volumes, tree, free: their cut, no test",
            Method::FloorFacing => "floor of culling by facing: all but the back faces, free",
        };
        s.to_string()
    }
}

/// One row of the table.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The method.
    pub method: Method,
    /// Triangles that reached the vertex and triangle stages, per frame
    /// (mean over the cameras).
    pub triangles_to_transform: f64,
    /// Share of the submitted triangles removed before transform.
    pub removed_before_transform: f64,
    /// Vertices transformed per frame (mean).
    pub vertices_transformed: f64,
    /// Triangles set up per frame (mean).
    pub triangles_set_up: f64,
    /// Geometry stage, ms per frame: median over the rounds, min, max.
    pub geometry_ms: [f64; 3],
    /// Whole frame, ms per frame: median, min, max.
    pub frame_ms: [f64; 3],
    /// Cameras whose frame differed from per-triangle culling (must be 0
    /// but for detail culling).
    pub frames_differing: usize,
    /// Pixels whose colour differed from per-triangle culling, per frame
    /// (mean; 0 but for detail culling).
    pub pixels_differing: f64,
}

/// What one model measured.
#[derive(Clone, Debug, Serialize)]
pub struct ModelReport {
    /// File name.
    pub model: String,
    /// Triangles of the source mesh.
    pub triangles: usize,
    /// Vertices of the source mesh, of the clustered one, and entries of
    /// its vertex list.
    pub vertices: [usize; 3],
    /// Clusters, inner tree nodes.
    pub clusters: [usize; 2],
    /// Bytes of the precomputed data (clusters and nodes).
    pub data_bytes: usize,
    /// The measured `t/r`.
    pub t_over_r: f64,
    /// The rows.
    pub rows: Vec<Row>,
    /// Normal masks: per partitions, the bytes of the data, and the mean
    /// share of the triangles masked per sector for each of
    /// `--sector-rows`, exact and without the size guard.
    pub masks: Vec<MaskReport>,
}

/// Normal masks of one partition count, by sector height.
#[derive(Clone, Debug, Serialize)]
pub struct MaskReport {
    /// Partitions a side.
    pub partitions: u8,
    /// Bytes of the precomputed data (class ids, sizes, spheres).
    pub data_bytes: usize,
    /// Triangles left out of every class (never masked).
    pub exempt: usize,
    /// Per `--sector-rows`: the sectors, and the share of triangles
    /// masked per sector (mean), exact and without the size guard.
    pub sectors: Vec<(u32, f64, f64)>,
}

/// Runs the command.
pub fn run(args: &CullArgs) -> Result<(), String> {
    if args.portals {
        let row = crate::portal::measure(args.rooms, args.cameras, args.size, args.rounds)?;
        if let Some(path) = &args.json {
            let text = serde_json::to_string_pretty(&row).map_err(|e| e.to_string())?;
            crate::output::write_all(&[crate::output::Output {
                option: "--json",
                path,
                payload: crate::output::Payload::Raw(text.as_bytes()),
            }])?;
        }
        print!(
            "{}",
            crate::portal::markdown(&row, args.rooms, args.cameras, args.size)
        );
        return Ok(());
    }
    if args.occlusion {
        let rows = crate::occlusion::measure(
            args.grid,
            args.cameras,
            args.size,
            &args.occlusion_rows,
            args.rounds,
        )?;
        if let Some(path) = &args.json {
            let text = serde_json::to_string_pretty(&rows).map_err(|e| e.to_string())?;
            crate::output::write_all(&[crate::output::Output {
                option: "--json",
                path,
                payload: crate::output::Payload::Raw(text.as_bytes()),
            }])?;
        }
        print!(
            "{}",
            crate::occlusion::markdown(&rows, args.grid, args.cameras, args.size)
        );
        return Ok(());
    }
    let opts = ClusterOptions {
        max_vertices: args.max_vertices,
        max_triangles: args.max_triangles,
        cone_weight: args.cone_weight,
        t_over_r: args.t_over_r,
        shared: !args.copies,
    };
    let mut reports = Vec::new();
    for path in &args.models {
        let m = crate::obj::load_obj(path)?;
        let positions: Vec<Vec3> = m.positions.iter().map(|&p| Vec3::from_array(p)).collect();
        let clustered = cluster::build(&positions, &m.indices, &opts)?;
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        eprintln!(
            "{name}: {} triangles, {} clusters, {} inner nodes",
            m.indices.len(),
            clustered.clusters.len(),
            clustered.inner_nodes()
        );
        reports.push(measure(&name, &positions, &m.indices, &clustered, args)?);
    }
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&reports).map_err(|e| e.to_string())?;
        crate::output::write_all(&[crate::output::Output {
            option: "--json",
            path,
            payload: crate::output::Payload::Raw(text.as_bytes()),
        }])?;
    }
    print!("{}", markdown(&reports, args));
    Ok(())
}

/// The cameras: `n` directions on a Fibonacci sphere, `dist` radii out.
pub fn cameras(positions: &[Vec3], n: usize, dist: f32, aspect: f32) -> Result<Vec<Mat4>, String> {
    let b = BoundingSphere::from_points(positions).ok_or("the model has no finite vertex")?;
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = i as f32 * 2.399_963;
            let eye = b.center + Vec3::new(r * phi.cos(), y, r * phi.sin()) * (dist * b.radius);
            let view =
                crate::scene::look_at([eye.x, eye.y, eye.z], [b.center.x, b.center.y, b.center.z])?;
            let near = (dist - 1.0).max(0.05) * b.radius * 0.5;
            Ok(Mat4::perspective(0.9, aspect, near, (dist + 2.0) * b.radius) * view)
        })
        .collect()
}

/// A mesh to submit and how.
struct Case<'a> {
    mesh: Mesh<'a>,
    set: Option<(&'a ClusteredMesh, ClusterCull)>,
    classes: Option<&'a NormalClassData>,
    /// The frame's settings (with detail culling for [`Method::Detail`]).
    config: Config,
    /// The varyings of detail culling's boxes ([`Method::DetailBoxes`]).
    fill: Option<[f32; 3]>,
    /// Per camera, the cut mesh a floor row submits in place of `mesh`
    /// ([`Method::FloorVolumes`], [`Method::FloorFacing`],
    /// [`Method::Floor`]).
    kept: Option<&'a [Kept]>,
}

/// The triangles of a mesh that one camera keeps by some rule ([`Cut`]),
/// in their order and colours, with only the vertices they use.
struct Kept {
    positions: Vec<Vec3>,
    indices: Vec<[u32; 3]>,
    colors: Vec<Rgb888>,
}

/// Which triangles a floor row keeps.
#[derive(Clone, Copy)]
enum Cut {
    /// Those per-triangle culling sets up (stores a piece of).
    SetUp,
    /// Those per-triangle culling does not cull by winding.
    NotBack,
    /// Those of the clusters that culling volumes over the tree draw.
    Volumes,
}

impl Kept {
    /// Cuts `mesh` (colours per triangle, clustered as `clustered`) to
    /// what `cut` keeps from `mvp`. For [`Cut::SetUp`] and
    /// [`Cut::NotBack`] each triangle alone is submitted, in clip space as
    /// [`Mesh::triangle`] gives it (the same `f32` operations as the
    /// cached path's vertex stage), and its counts decide.
    fn cut(
        mesh: &Mesh<'_, MeshColors<'_>>,
        colors: &[Rgb888],
        clustered: &ClusteredMesh,
        mvp: &Mat4,
        config: Config,
        cut: Cut,
        storage: &mut [SetupTriangle],
    ) -> Result<Kept, String> {
        let mut keep = vec![false; mesh.indices.len()];
        if let Cut::Volumes = cut {
            let eye = Eye::for_frame::<8>(mvp, &config);
            let eye = eye.map(|e| mesh.bounds.map_or(e, |b| e.within(&b)));
            let cull = Method::VolumesTree.cull().ok_or("no cluster test")?;
            clustered.set().visit(eye.as_ref(), None, cull, |v| {
                if let Visit::Draw(a, b) = v {
                    for k in &clustered.clusters[a..b] {
                        let [t0, t1] = k.triangles.map(|t| t as usize);
                        keep[t0..t1].fill(true);
                    }
                }
            });
        } else {
            let mut frame = Frame::new(config, storage).map_err(|e| e.to_string())?;
            for (i, k) in keep.iter_mut().enumerate() {
                let Some(tri) = mesh.triangle::<3>(i, mvp) else {
                    return Err(format!("triangle {i} indexes past the mesh"));
                };
                frame.clear();
                frame
                    .submit_triangle(tri, i as u32)
                    .map_err(|e| e.to_string())?;
                let s = frame.stats();
                *k = match cut {
                    Cut::NotBack => s.culled_backface == 0,
                    _ => s.stored > 0,
                };
            }
        }
        let mut remap = vec![u32::MAX; mesh.positions.len()];
        let mut kept = Kept {
            positions: Vec::new(),
            indices: Vec::new(),
            colors: Vec::new(),
        };
        for ((t, &c), _) in mesh
            .indices
            .iter()
            .zip(colors)
            .zip(&keep)
            .filter(|(_, &k)| k)
        {
            let mut k = [0u32; 3];
            for (slot, &v) in k.iter_mut().zip(t) {
                let r = &mut remap[v as usize];
                if *r == u32::MAX {
                    *r = kept.positions.len() as u32;
                    kept.positions.push(mesh.positions[v as usize]);
                }
                *slot = *r;
            }
            kept.indices.push(k);
            kept.colors.push(c);
        }
        Ok(kept)
    }
}

impl Method {
    /// Whether the method drops by detail (lossy): its frames are set
    /// against the clustered mesh drawn in one colour, and so is it.
    fn lossy(self) -> bool {
        matches!(self, Method::Detail | Method::DetailBoxes)
    }
}

/// Submits one frame; returns its stats.
fn submit(
    frame: &mut Frame<'_>,
    case: &Case<'_>,
    camera: usize,
    mvp: &Mat4,
    cache: &mut [ProcessedVertex],
) -> Result<Stats, String> {
    if let Some(kept) = case.kept {
        let k = kept.get(camera).ok_or("no cut mesh for the camera")?;
        let mesh = Mesh {
            positions: &k.positions,
            indices: &k.indices,
            attributes: MeshColors::PerTriangle(&k.colors),
            bounds: case.mesh.bounds,
        };
        frame
            .submit_mesh_cached(&mesh, mvp, 0, cache)
            .map_err(|e| e.to_string())?;
        return Ok(frame.stats());
    }
    match (case.set, case.classes) {
        (Some((c, cull)), _) if case.fill.is_some() => {
            let mesh = Mesh {
                positions: case.mesh.positions,
                indices: case.mesh.indices,
                attributes: DetailFill {
                    attributes: case.mesh.attributes,
                    fill: case.fill.unwrap_or_default(),
                },
                bounds: case.mesh.bounds,
            };
            frame.submit_clusters(&mesh, mvp, &c.set(), cull, 0, cache)
        }
        (Some((c, cull)), _) => frame.submit_clusters(&case.mesh, mvp, &c.set(), cull, 0, cache),
        (None, Some(c)) => frame.submit_masked(&case.mesh, mvp, &c.set(), 0, cache),
        (None, None) => frame.submit_mesh_cached(&case.mesh, mvp, 0, cache),
    }
    .map_err(|e| e.to_string())?;
    Ok(frame.stats())
}

/// Vertices a frame transforms.
fn vertices_transformed(case: &Case<'_>, camera: usize, mvp: &Mat4) -> usize {
    if let Some(kept) = case.kept {
        return kept.get(camera).map_or(0, |k| k.positions.len());
    }
    if let Some(c) = case.classes {
        let mask = BackMask::for_frame::<8>(mvp, &case.config, None, &c.set());
        let mut seen = vec![false; case.mesh.positions.len()];
        for (t, &k) in case.mesh.indices.iter().zip(&c.classes) {
            if !mask.contains(k) {
                for &v in t {
                    if let Some(s) = seen.get_mut(v as usize) {
                        *s = true;
                    }
                }
            }
        }
        return seen.iter().filter(|&&s| s).count();
    }
    let Some((c, cull)) = case.set else {
        return case.mesh.positions.len();
    };
    let eye = Eye::for_frame::<8>(mvp, &case.config);
    let eye = eye.map(|e| case.mesh.bounds.map_or(e, |b| e.within(&b)));
    let detail = Detail::for_frame(mvp, &case.config);
    let mut seen = vec![false; c.positions.len()];
    let mut n = 0;
    c.set().visit(eye.as_ref(), detail.as_ref(), cull, |v| {
        if let Visit::Draw(a, b) = v {
            for k in &c.clusters[a..b] {
                let r = k.vertices[0] as usize..k.vertices[1] as usize;
                if c.vertex_list.is_empty() {
                    n += r.len();
                    continue;
                }
                for &id in &c.vertex_list[r] {
                    if !std::mem::replace(&mut seen[id as usize], true) {
                        n += 1;
                    }
                }
            }
        }
    });
    n
}

fn measure(
    name: &str,
    positions: &[Vec3],
    indices: &[[u32; 3]],
    clustered: &ClusteredMesh,
    args: &CullArgs,
) -> Result<ModelReport, String> {
    let (w, h) = args.size;
    let config = Config::new(w, h);
    let mvps = cameras(positions, args.cameras, args.distance, w as f32 / h as f32)?;
    let white = Rgb888::new(255, 255, 255);
    let src_colors = vec![white; indices.len()];
    let colors: Vec<Rgb888> = clustered
        .source_triangle
        .iter()
        .map(|&t| {
            let t = t as usize;
            Rgb888::new((t * 37) as u8, (t * 91) as u8, (t * 13) as u8)
        })
        .collect();
    let source = Mesh {
        positions,
        indices,
        attributes: MeshColors::PerTriangle(&src_colors),
        bounds: BoundingSphere::from_points(positions),
    };
    let cmesh = Mesh {
        positions: &clustered.positions,
        indices: &clustered.indices,
        attributes: MeshColors::PerTriangle(&colors),
        bounds: BoundingSphere::from_points(&clustered.positions),
    };
    // Lossy rows are set against this mesh (in one colour, so a box in
    // that colour is right where it covers the mesh).
    let white_colors = vec![white; clustered.indices.len()];
    let cmesh_white = Mesh {
        attributes: MeshColors::PerTriangle(&white_colors),
        ..cmesh
    };
    let reference_white = Case {
        mesh: cmesh_white,
        set: None,
        classes: None,
        config,
        fill: None,
        kept: None,
    };
    let mut methods = Method::ALL.to_vec();
    if args.detail > 0 {
        methods.extend([Method::Detail, Method::DetailBoxes]);
    }
    let class_data: Vec<NormalClassData> = args
        .normal_masks
        .iter()
        .map(|&n| normal_mask::build(&clustered.positions, &clustered.indices, n))
        .collect::<Result<_, _>>()?;
    methods.extend(args.normal_masks.iter().map(|&n| Method::Mask(n)));
    // The floor's meshes, cut per camera before any timing (a triangle
    // makes at most `MAX_PIECES` pieces, and the frame is emptied after
    // each that stores one).
    let mut one = vec![SetupTriangle::EMPTY; 2 * microraster::MAX_PIECES];
    let mut cut = |cut| -> Result<Vec<Kept>, String> {
        mvps.iter()
            .map(|mvp| Kept::cut(&cmesh, &colors, clustered, mvp, config, cut, &mut one))
            .collect()
    };
    let kept = [cut(Cut::Volumes)?, cut(Cut::NotBack)?, cut(Cut::SetUp)?];
    let cases: Vec<Case<'_>> = methods
        .iter()
        .map(|m| Case {
            mesh: match m {
                Method::Source => source,
                _ if m.lossy() => cmesh_white,
                _ => cmesh,
            },
            set: m.cull().map(|c| (clustered, c)),
            classes: match m {
                Method::Mask(n) => args
                    .normal_masks
                    .iter()
                    .position(|k| k == n)
                    .map(|i| &class_data[i]),
                _ => None,
            },
            config: Config {
                detail: if m.lossy() { args.detail } else { 0 },
                ..config
            },
            fill: (*m == Method::DetailBoxes).then_some([255.0; 3]),
            kept: match m {
                Method::FloorVolumes => Some(&kept[0][..]),
                Method::FloorFacing => Some(&kept[1][..]),
                Method::Floor => Some(&kept[2][..]),
                _ => None,
            },
        })
        .collect();
    // Room for two pieces a triangle, and boxes' pieces.
    let cap = clustered.indices.len().max(indices.len()) * 7
        + clustered.nodes.len() * 2 * microraster::MAX_PIECES
        + 64;
    let mut storage = vec![SetupTriangle::EMPTY; cap];
    let mut cache =
        vec![ProcessedVertex::default(); clustered.positions.len().max(positions.len())];
    let n = (w * h) as usize;
    let (mut color, mut depth) = (vec![Rgb888::BLACK; n], vec![u16::MAX; n]);

    // Counts and the identical-frame check, once per camera.
    let mut rows: Vec<Row> = methods
        .iter()
        .map(|&method| Row {
            method,
            triangles_to_transform: 0.0,
            removed_before_transform: 0.0,
            vertices_transformed: 0.0,
            triangles_set_up: 0.0,
            geometry_ms: [0.0; 3],
            frame_ms: [0.0; 3],
            frames_differing: 0,
            pixels_differing: 0.0,
        })
        .collect();
    let cams = mvps.len().max(1) as f64;
    for (camera, mvp) in mvps.iter().enumerate() {
        let mut want: Option<(Vec<u8>, Vec<Rgb888>)> = None;
        let mut want_white: Option<(Vec<u8>, Vec<Rgb888>)> = None;
        if methods.iter().any(|m| m.lossy()) {
            let mut frame = Frame::new(config, &mut storage).map_err(|e| e.to_string())?;
            submit(&mut frame, &reference_white, camera, mvp, &mut cache)?;
            color.fill(Rgb888::BLACK);
            depth.fill(u16::MAX);
            frame
                .render_rows(0, h, &mut color, &mut depth[..])
                .map_err(|e| e.to_string())?;
            let mut bytes: Vec<u8> = color.iter().flat_map(|c| [c.r(), c.g(), c.b()]).collect();
            bytes.extend(depth.iter().flat_map(|d| d.to_le_bytes()));
            want_white = Some((bytes, color.clone()));
        }
        for (row, case) in rows.iter_mut().zip(&cases) {
            let mut frame = Frame::new(case.config, &mut storage).map_err(|e| e.to_string())?;
            let s = submit(&mut frame, case, camera, mvp, &mut cache)?;
            color.fill(Rgb888::BLACK);
            depth.fill(u16::MAX);
            frame
                .render_rows(0, h, &mut color, &mut depth[..])
                .map_err(|e| e.to_string())?;
            let mut skipped =
                s.culled_cluster + s.culled_hierarchy + s.culled_detail + s.culled_mask;
            let mut submitted = s.submitted;
            if case.kept.is_some() {
                // What the perfect culler left out was never submitted.
                submitted = cmesh.indices.len() as u64;
                skipped = submitted.saturating_sub(s.submitted);
            }
            row.triangles_to_transform += (submitted - skipped) as f64 / cams;
            row.removed_before_transform += skipped as f64 / submitted.max(1) as f64 / cams;
            row.vertices_transformed += vertices_transformed(case, camera, mvp) as f64 / cams;
            row.triangles_set_up += s.stored as f64 / cams;
            if row.method != Method::Source {
                let mut bytes: Vec<u8> = color.iter().flat_map(|c| [c.r(), c.g(), c.b()]).collect();
                bytes.extend(depth.iter().flat_map(|d| d.to_le_bytes()));
                let want = if row.method.lossy() {
                    &mut want_white
                } else {
                    &mut want
                };
                match want {
                    None => *want = Some((bytes, color.clone())),
                    Some((w, c)) if *w != bytes => {
                        row.frames_differing += 1;
                        let n = c.iter().zip(&color).filter(|(a, b)| a != b).count();
                        row.pixels_differing += n as f64 / cams;
                    }
                    Some(_) => {}
                }
            }
        }
    }

    // Timing, interleaved rounds.
    let rounds = args.rounds.max(1);
    let mut geo = vec![Vec::with_capacity(rounds); cases.len()];
    let mut full = vec![Vec::with_capacity(rounds); cases.len()];
    for _ in 0..rounds {
        for (k, case) in cases.iter().enumerate() {
            let (mut g, mut f) = (0.0f64, 0.0f64);
            for (camera, mvp) in mvps.iter().enumerate() {
                if case.kept.is_some() {
                    // A cut is a copy of the mesh for this camera alone:
                    // submitted once untimed, it is in cache as the mesh
                    // every other row shares over the cameras is.
                    let mut frame =
                        Frame::new(case.config, &mut storage).map_err(|e| e.to_string())?;
                    submit(&mut frame, case, camera, mvp, &mut cache)?;
                }
                let t0 = Instant::now();
                let mut frame = Frame::new(case.config, &mut storage).map_err(|e| e.to_string())?;
                submit(&mut frame, case, camera, mvp, &mut cache)?;
                let t1 = Instant::now();
                color.fill(Rgb888::BLACK);
                depth.fill(u16::MAX);
                frame
                    .render_rows(0, h, &mut color, &mut depth[..])
                    .map_err(|e| e.to_string())?;
                let t2 = Instant::now();
                g += (t1 - t0).as_secs_f64();
                f += (t2 - t0).as_secs_f64();
            }
            geo[k].push(g * 1e3 / cams);
            full[k].push(f * 1e3 / cams);
        }
    }
    for (k, row) in rows.iter_mut().enumerate() {
        row.geometry_ms = spread(&mut geo[k]);
        row.frame_ms = spread(&mut full[k]);
    }

    // t/r: a node test against the per-triangle geometry time.
    let eyes = cluster::sample_eyes(&clustered.positions);
    let leaves = &clustered.nodes;
    let t0 = Instant::now();
    let mut backs = 0usize;
    for e in &eyes {
        for node in leaves {
            backs += usize::from(node.volume.facing(e) == microraster::cull::Facing::Back);
        }
    }
    let tests = (eyes.len() * leaves.len()).max(1) as f64;
    let t = t0.elapsed().as_secs_f64() / tests;
    std::hint::black_box(backs);
    let r = rows[1].geometry_ms[0] * 1e-3 / clustered.indices.len().max(1) as f64;
    let masks = class_data
        .iter()
        .map(|d| mask_sectors(d, &mvps, config, &args.sector_rows))
        .collect();
    Ok(ModelReport {
        model: name.to_string(),
        triangles: indices.len(),
        vertices: [
            positions.len(),
            clustered.positions.len(),
            clustered.vertex_list.len(),
        ],
        clusters: [clustered.clusters.len(), clustered.inner_nodes()],
        data_bytes: clustered.data_bytes(),
        t_over_r: t / r,
        rows,
        masks,
    })
}

/// The share of triangles the masks of `d` skip per sector, for each
/// sector height, over the cameras (sectors are the rows of a strip
/// renderer, with its slab).
fn mask_sectors(d: &NormalClassData, mvps: &[Mat4], config: Config, heights: &[u32]) -> MaskReport {
    let n = d.classes.len().max(1) as f64;
    let h = config.height;
    let sectors = heights
        .iter()
        .map(|&rows| {
            let rows = rows.clamp(1, h);
            let (mut exact, mut geometric, mut count) = (0.0, 0.0, 0usize);
            for mvp in mvps {
                for y0 in (0..h).step_by(rows as usize) {
                    let y1 = (y0 + rows).min(h);
                    let slab = (rows < h).then(|| {
                        (
                            1.0 - 2.0 * (y0 as f32 + 0.25) / h as f32,
                            1.0 - 2.0 * (y1 as f32 - 0.25) / h as f32,
                        )
                    });
                    let share = |m: BackMask| {
                        d.classes.iter().filter(|&&k| m.contains(k)).count() as f64 / n
                    };
                    exact += share(BackMask::for_frame::<8>(mvp, &config, slab, &d.set()));
                    geometric += share(BackMask::geometric::<8>(mvp, &config, slab, &d.set()));
                    count += 1;
                }
            }
            let c = count.max(1) as f64;
            (h.div_ceil(rows), exact / c, geometric / c)
        })
        .collect();
    MaskReport {
        partitions: d.partitions,
        data_bytes: d.data_bytes(),
        exempt: d.classes.iter().filter(|&&k| k == NO_CLASS).count(),
        sectors,
    }
}

/// `[median, min, max]`.
fn spread(v: &mut [f64]) -> [f64; 3] {
    v.sort_by(f64::total_cmp);
    let Some((&lo, &hi)) = v.first().zip(v.last()) else {
        return [0.0; 3];
    };
    [v[v.len() / 2], lo, hi]
}

/// The tables, one per model.
pub fn markdown(reports: &[ModelReport], args: &CullArgs) -> String {
    let (w, h) = args.size;
    let mut s = format!(
        "{} cameras at {} radii, {w}x{h}, {} interleaved rounds, 1 thread; meshlets of at most {} vertices and {} triangles, cone weight {}, tree t/r {}, vertices {}\n",
        args.cameras,
        args.distance,
        args.rounds,
        args.max_vertices,
        args.max_triangles,
        args.cone_weight,
        args.t_over_r,
        if args.copies { "copied per cluster" } else { "shared (a vertex list)" }
    );
    for r in reports {
        s += &format!(
            "\n### {}: {} triangles, {} -> {} vertices ({} list entries), {} clusters, {} inner nodes, {} B of culling data, measured t/r {:.3}\n\n",
            r.model,
            r.triangles,
            r.vertices[0],
            r.vertices[1],
            r.vertices[2],
            r.clusters[0],
            r.clusters[1],
            r.data_bytes,
            r.t_over_r
        );
        s += "| method | triangles to transform | removed before transform | vertices transformed | set up | geometry ms (median, range) | frame ms (median, range) | frames differing |\n";
        s += "|---|---:|---:|---:|---:|---:|---:|---:|\n";
        for row in &r.rows {
            s += &format!(
                "| {} | {:.0} | {:.1} % | {:.0} | {:.0} | {:.3} ({:.3}-{:.3}) | {:.3} ({:.3}-{:.3}) | {} |\n",
                if row.method.lossy() {
                    format!("{} {} px", row.method.label(), args.detail)
                } else {
                    row.method.label()
                },
                row.triangles_to_transform,
                row.removed_before_transform * 100.0,
                row.vertices_transformed,
                row.triangles_set_up,
                row.geometry_ms[0],
                row.geometry_ms[1],
                row.geometry_ms[2],
                row.frame_ms[0],
                row.frame_ms[1],
                row.frame_ms[2],
                match row.method {
                    Method::Source => "-".to_string(),
                    Method::Detail | Method::DetailBoxes => format!(
                        "{} ({:.1} pixels a frame)",
                        row.frames_differing, row.pixels_differing
                    ),
                    _ => row.frames_differing.to_string(),
                },
            );
        }
        if !r.masks.is_empty() {
            s += "\nNormal masks by sector (each sector a strip with its own mask): share of the triangles masked per sector, exact (with the size guard) / the lecture's mask alone (no size guard, not exact)\n\n| N | data | exempt triangles |";
            for &(k, _, _) in &r.masks[0].sectors {
                s += &format!(" {k} sector{} |", if k == 1 { "" } else { "s" });
            }
            s += "\n|---:|---:|---:|";
            s += &"---:|".repeat(r.masks[0].sectors.len());
            s += "\n";
            for m in &r.masks {
                s += &format!("| {} | {} B | {} |", m.partitions, m.data_bytes, m.exempt);
                for &(_, e, g) in &m.sectors {
                    s += &format!(" {:.1} % / {:.1} % |", e * 100.0, g * 100.0);
                }
                s += "\n";
            }
        }
    }
    s
}
