//! Wavefront OBJ loading and automatic camera framing.
//!
//! Design: only vertex positions matter to the rasterizer, so the file is read
//! with `tobj` (faces fan-triangulated, positions indexed on their own, MTL
//! files never opened) and every model in it is merged into one indexed
//! mesh. Triangle order is file order after triangulation, model by model, so
//! triangle ids in the id image can be traced back to the file. Point and line
//! elements are dropped rather than turned into degenerate triangles. A file
//! that yields no triangle at all is an error. Bounds are taken over finite
//! positions only, so one `nan` vertex does not poison the automatic camera;
//! such vertices stay in the mesh for the renderer to reject.
//!
//! tobj's errors carry no line number, so when it fails the file is
//! scanned again by [`locate_error`], a light check of the same statements
//! (`v`, `vt`, `vn`, `f`, `l`): the first line that tobj's error matches is
//! reported with its number and text, so the message says what to fix and
//! where ("teapot.obj: line 12: ... `f 1 2 x`"). The scan runs only on the
//! error path and never decides whether a file loads.
//!
//! [`frame_camera`] places the eye on the `(0, 0.3, 1)` side of the mesh's
//! bounding sphere at the distance where the sphere (plus a 10% margin) fits
//! both the vertical and the horizontal field of view.

use std::fs::File;
use std::io::BufReader;
use std::path::Path;

/// A triangle mesh merged from all models in an OBJ file.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedMesh {
    /// Vertex positions (model space, as in the file).
    pub positions: Vec<[f32; 3]>,
    /// Triangles as indices into `positions`, in file order.
    pub indices: Vec<[u32; 3]>,
    /// Component-wise minimum over the finite positions (all zero if none).
    pub bounds_min: [f32; 3],
    /// Component-wise maximum over the finite positions (all zero if none).
    pub bounds_max: [f32; 3],
}

/// Loads `path` as a Wavefront OBJ file; all models are merged into one mesh.
pub fn load_obj(path: &Path) -> Result<LoadedMesh, String> {
    let file =
        File::open(path).map_err(|e| format!("{}: cannot open OBJ file: {e}", path.display()))?;
    // `..Default::default()` keeps this compiling if a tobj feature adds fields.
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: false,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // Materials are not needed: never open the MTL files the OBJ names.
    let (models, _materials) = tobj::load_obj_buf(&mut BufReader::new(file), &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| describe_load_error(path, &e))?;
    let meshes: Vec<(&[f32], &[u32])> = models
        .iter()
        .map(|m| (m.mesh.positions.as_slice(), m.mesh.indices.as_slice()))
        .collect();
    merge_meshes(&meshes).map_err(|e| format!("{}: {e}", path.display()))
}

/// tobj's error `e` for `path`, with the line it most likely comes from.
fn describe_load_error(path: &Path, e: &tobj::LoadError) -> String {
    let text = std::fs::read(path)
        .map(|b| String::from_utf8_lossy(&b).into_owned())
        .unwrap_or_default();
    match locate_error(&text, e) {
        Some((line, what)) => format!("{}: line {line}: {what} ({e})", path.display()),
        None => format!("{}: cannot load OBJ file: {e}", path.display()),
    }
}

/// The first line (1-based) of the OBJ `text` showing the problem tobj
/// reported as `e`, and what is wrong there.
pub fn locate_error(text: &str, e: &tobj::LoadError) -> Option<(usize, String)> {
    use tobj::LoadError as E;
    let floats = |toks: &[&str]| toks.iter().all(|t| t.parse::<f32>().is_ok());
    let total_v = text
        .lines()
        .filter(|l| l.split_whitespace().next() == Some("v"))
        .count() as i64;
    let mut seen_v = 0i64;
    for (n, line) in text.lines().enumerate() {
        let toks: Vec<&str> = line.split_whitespace().collect();
        let Some((&kind, args)) = toks.split_first() else {
            continue;
        };
        let quoted = format!("`{}`", line.trim());
        let problem = match (kind, e) {
            ("v", E::PositionParseError) if args.len() < 3 || !floats(&args[..3]) => {
                Some(format!("a vertex needs three numbers x y z: {quoted}"))
            }
            ("v", E::PositionParseError) if args.len() == 4 && !floats(&args[3..]) => {
                Some(format!("the vertex weight w is not a number: {quoted}"))
            }
            ("v", E::ScalingByZeroError) if args.len() == 4 && args[3].parse() == Ok(0.0f32) => {
                Some(format!("the vertex weight w is zero: {quoted}"))
            }
            ("v", E::ColorParseError) if args.len() == 5 || args.len() > 6 => Some(format!(
                "a vertex has x y z, then nothing, a weight w or a colour r g b: {quoted}"
            )),
            ("vt", E::TexcoordParseError) if args.len() < 2 || !floats(&args[..2]) => {
                Some(format!("a texture coordinate needs two numbers: {quoted}"))
            }
            ("vn", E::NormalParseError) if args.len() < 3 || !floats(&args[..3]) => {
                Some(format!("a normal needs three numbers: {quoted}"))
            }
            ("f" | "l", E::FaceParseError | E::FaceVertexOutOfBounds) => {
                args.iter().find_map(|a| {
                    let first = a.split('/').next().unwrap_or("");
                    match first.parse::<i64>() {
                        Err(_) => Some(format!(
                            "{first:?} is not a vertex index (whole numbers from 1, or \
                             negative to count back): {quoted}"
                        )),
                        Ok(0) => Some(format!("vertex indices start at 1, not 0: {quoted}")),
                        Ok(i) if i < 0 && -i > seen_v => Some(format!(
                            "vertex index {i} reaches back past the {seen_v} vertices \
                             before this line: {quoted}"
                        )),
                        Ok(i) if i > total_v => Some(format!(
                            "vertex index {i} is past the file's {total_v} vertices: {quoted}"
                        )),
                        Ok(_) => None,
                    }
                })
            }
            _ => None,
        };
        if kind == "v" {
            seen_v += 1;
        }
        if let Some(p) = problem {
            return Some((n + 1, p));
        }
    }
    None
}

/// Merges flat `(positions, indices)` pairs (as `tobj` returns them) into one
/// mesh, offsetting each part's indices by the vertices before it.
fn merge_meshes(parts: &[(&[f32], &[u32])]) -> Result<LoadedMesh, String> {
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut indices: Vec<[u32; 3]> = Vec::new();
    for (part, &(flat_pos, flat_idx)) in parts.iter().enumerate() {
        if flat_pos.len() % 3 != 0 || flat_idx.len() % 3 != 0 {
            return Err(format!("model {part}: malformed mesh data"));
        }
        let base = positions.len();
        let count = flat_pos.len() / 3;
        let offset = u32::try_from(base)
            .ok()
            .filter(|b| u32::try_from(count).is_ok_and(|c| b.checked_add(c).is_some()))
            .ok_or_else(|| "too many vertices (more than 2^32)".to_string())?;
        positions.extend(flat_pos.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        for t in flat_idx.chunks_exact(3) {
            let mut tri = [0u32; 3];
            for (dst, &i) in tri.iter_mut().zip(t) {
                if usize::try_from(i).map_or(true, |i| i >= count) {
                    return Err(format!("model {part}: vertex index {i} out of range"));
                }
                *dst = i + offset;
            }
            indices.push(tri);
        }
    }
    if indices.is_empty() {
        return Err("no triangles (faces) found".to_string());
    }
    let (bounds_min, bounds_max) = finite_bounds(&positions);
    Ok(LoadedMesh {
        positions,
        indices,
        bounds_min,
        bounds_max,
    })
}

/// Component-wise min/max over the positions whose coordinates are all
/// finite; `([0; 3], [0; 3])` if there is none.
fn finite_bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut finite = positions.iter().filter(|p| p.iter().all(|c| c.is_finite()));
    let Some(first) = finite.next() else {
        return ([0.0; 3], [0.0; 3]);
    };
    let (mut lo, mut hi) = (*first, *first);
    for p in finite {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    (lo, hi)
}

/// Direction (before normalising) from the model centre towards the eye.
pub const FRAME_DIRECTION: [f32; 3] = [0.0, 0.3, 1.0];

/// Extra room around the bounding sphere: the sphere's radius is grown by
/// this factor before fitting it into the field of view.
pub const FRAME_MARGIN: f32 = 1.1;

/// Returns `(eye, target)` for a camera that frames the mesh.
///
/// The target is the centre of the bounding box; the bounding sphere is centred
/// there with the radius of the farthest finite vertex. The eye looks at it
/// from direction [`FRAME_DIRECTION`] (in front, slightly above; use up = +y)
/// at the distance where the sphere, grown by [`FRAME_MARGIN`], fits both the
/// vertical field of view `fov_y_deg` and the horizontal one implied by
/// `aspect` (width / height). Out-of-range inputs are clamped rather than
/// rejected: the field of view to 1°..=179°, a non-finite or non-positive
/// aspect to 1, a zero-size mesh to radius 1.
pub fn frame_camera(mesh: &LoadedMesh, fov_y_deg: f32, aspect: f32) -> ([f32; 3], [f32; 3]) {
    let fov = if fov_y_deg.is_finite() {
        fov_y_deg.clamp(1.0, 179.0)
    } else {
        60.0
    };
    let aspect = if aspect.is_finite() && aspect > 0.0 {
        aspect
    } else {
        1.0
    };
    let (lo, hi) = (mesh.bounds_min, mesh.bounds_max);
    let centre = [
        (lo[0] as f64 + hi[0] as f64) * 0.5,
        (lo[1] as f64 + hi[1] as f64) * 0.5,
        (lo[2] as f64 + hi[2] as f64) * 0.5,
    ];
    let mut radius = 0.0f64;
    for p in &mesh.positions {
        if p.iter().all(|c| c.is_finite()) {
            let d2: f64 = (0..3).map(|k| (p[k] as f64 - centre[k]).powi(2)).sum();
            radius = radius.max(d2.sqrt());
        }
    }
    if !(radius.is_finite() && radius > 0.0) {
        radius = 1.0;
    }
    let half_v = (fov as f64).to_radians() * 0.5;
    let half_h = (half_v.tan() * aspect as f64).atan();
    let distance = radius * FRAME_MARGIN as f64 / half_v.min(half_h).sin();
    let dir = FRAME_DIRECTION.map(f64::from);
    let len = dir.iter().map(|c| c * c).sum::<f64>().sqrt();
    let eye = [0, 1, 2].map(|k| (centre[k] + dir[k] / len * distance) as f32);
    let target = centre.map(|c| c as f32);
    (eye, target)
}

#[cfg(test)]
mod tests {
    use super::*;
    use tempfile::TempDir;

    fn write_file(dir: &TempDir, name: &str, text: &str) -> std::path::PathBuf {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    fn load_text(text: &str) -> Result<LoadedMesh, String> {
        let dir = TempDir::new().unwrap();
        let path = write_file(&dir, "mesh.obj", text);
        load_obj(&path)
    }

    fn pos(m: &LoadedMesh, t: usize) -> [[f32; 3]; 3] {
        m.indices[t].map(|i| m.positions[i as usize])
    }

    #[test]
    fn quad_triangulates_into_two_triangles() {
        let m = load_text("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n").unwrap();
        assert_eq!(m.indices.len(), 2);
        // Fan triangulation keeps the winding: (0,1,2) and (0,2,3).
        assert_eq!(pos(&m, 0), [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.]]);
        assert_eq!(pos(&m, 1), [[0., 0., 0.], [1., 1., 0.], [0., 1., 0.]]);
        assert_eq!(m.bounds_min, [0.0, 0.0, 0.0]);
        assert_eq!(m.bounds_max, [1.0, 1.0, 0.0]);
    }

    #[test]
    fn negative_indices_groups_and_merge_order() {
        // Cornell-box style: relative indices, several groups, a missing MTL.
        let text = "mtllib missing.mtl\n\
            g first\nusemtl a\n\
            v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf -4 -3 -2 -1\n\
            g second\nusemtl b\n\
            v 5 5 5\nv 6 5 5\nv 5 6 5\nf -3 -2 -1\n\
            o third\nv -1 -2 -3\nv -1 -2 -4\nv -2 -2 -3\nv 0 0 9\nf -4/1 -3 -2\np 1\nl 1 2\n";
        let m = load_text(text).unwrap();
        assert_eq!(m.indices.len(), 4);
        assert_eq!(pos(&m, 0), [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.]]);
        assert_eq!(pos(&m, 1), [[0., 0., 0.], [1., 1., 0.], [0., 1., 0.]]);
        assert_eq!(pos(&m, 2), [[5., 5., 5.], [6., 5., 5.], [5., 6., 5.]]);
        assert_eq!(
            pos(&m, 3),
            [[-1., -2., -3.], [-1., -2., -4.], [-2., -2., -3.]]
        );
        for t in &m.indices {
            assert!(t.iter().all(|&i| (i as usize) < m.positions.len()));
        }
        // Bounds cover the referenced vertices; the unused (0,0,9) is not kept.
        assert_eq!(m.bounds_min, [-2.0, -2.0, -4.0]);
        assert_eq!(m.bounds_max, [6.0, 6.0, 5.0]);
    }

    #[test]
    fn non_finite_vertices_are_kept_but_not_bounded() {
        let m = load_text("v 0 0 0\nv 2 0 0\nv 0 2 0\nv nan 0 0\nf 1 2 3\nf 1 2 4\n").unwrap();
        assert_eq!(m.indices.len(), 2);
        assert!(m.positions.iter().any(|p| p[0].is_nan()));
        assert_eq!(m.bounds_min, [0.0, 0.0, 0.0]);
        assert_eq!(m.bounds_max, [2.0, 2.0, 0.0]);
    }

    #[test]
    fn bad_files_are_errors_naming_the_path() {
        let cases = [
            ("no faces", "v 0 0 0\nv 1 0 0\nv 0 1 0\n"),
            ("empty", ""),
            ("index too big", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n"),
            ("index zero", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n"),
            (
                "negative too far",
                "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -1 -2 -4\n",
            ),
            ("garbage index", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 x 3\n"),
            ("garbage coord", "v 0 zero 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n"),
            ("points only", "v 0 0 0\np 1\n"),
        ];
        for (what, text) in cases {
            let e = load_text(text).expect_err(what);
            assert!(e.contains("mesh.obj"), "{what}: {e}");
        }
        let e = load_obj(Path::new("/nonexistent/dir/thing.obj")).unwrap_err();
        assert!(e.contains("thing.obj"), "{e}");
    }

    #[test]
    fn load_errors_name_the_line() {
        let cases = [
            ("v 0 0 0\nv 1 zero 0\nv 0 1 0\nf 1 2 3\n", "line 2:"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\n\nf 1 2 x\n", "line 5:"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n", "line 5:"),
            ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "line 4:"),
            ("v 0 0 0\nv 1 0 0\nf -1 -2 -3\nv 0 1 0\n", "line 3:"),
            ("v 0 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n", "line 1:"),
            ("vn 0 1\nv 0 0 0\n", "line 1:"),
        ];
        for (text, want) in cases {
            let e = load_text(text).unwrap_err();
            assert!(e.contains("mesh.obj") && e.contains(want), "{text:?}: {e}");
        }
        // The scan finds nothing where tobj's error does not match a line.
        assert_eq!(
            locate_error("v 0 0 0\n", &tobj::LoadError::GenericFailure),
            None
        );
    }

    #[test]
    fn missing_file_names_the_path() {
        let e = load_obj(Path::new("/nonexistent/dir/thing.obj")).unwrap_err();
        assert!(e.contains("thing.obj"), "{e}");
    }

    #[test]
    fn merge_checks_indices() {
        let p = [0.0f32; 9];
        assert!(merge_meshes(&[(&p, &[0, 1, 3])]).is_err());
        assert!(merge_meshes(&[(&p[..8], &[0, 1, 2])]).is_err());
        let m = merge_meshes(&[(&p, &[0, 1, 2]), (&p, &[2, 1, 0])]).unwrap();
        assert_eq!(m.indices, vec![[0, 1, 2], [5, 4, 3]]);
    }

    fn check_framing(m: &LoadedMesh, fov_y: f32, aspect: f32) {
        let (eye, target) = frame_camera(m, fov_y, aspect);
        assert!(eye.iter().chain(&target).all(|c| c.is_finite()));
        let centre: [f32; 3] = [0, 1, 2].map(|k| (m.bounds_min[k] + m.bounds_max[k]) * 0.5);
        for k in 0..3 {
            assert!((target[k] - centre[k]).abs() <= 1e-5 * (1.0 + centre[k].abs()));
        }
        // View basis (right-handed, up = +y).
        let sub = |a: [f32; 3], b: [f32; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
        let dot = |a: [f32; 3], b: [f32; 3]| a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
        let cross = |a: [f32; 3], b: [f32; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let norm = |a: [f32; 3]| {
            let l = dot(a, a).sqrt();
            a.map(|c| c / l)
        };
        let fwd = norm(sub(target, eye));
        // Eye is in front (+z) and above (+y) the target.
        assert!(fwd[2] < 0.0 && fwd[1] < 0.0 && fwd[0].abs() < 1e-6);
        let right = norm(cross(fwd, [0.0, 1.0, 0.0]));
        let up = cross(right, fwd);
        let tan_v = (fov_y.to_radians() * 0.5).tan();
        let tan_h = tan_v * aspect;
        for p in &m.positions {
            let d = sub(*p, eye);
            let z = dot(d, fwd);
            assert!(z > 0.0, "vertex behind the camera");
            let x = dot(d, right) / z;
            let y = dot(d, up) / z;
            // Inside the frustum with some of the margin left over.
            assert!(x.abs() <= tan_h * 0.97, "x {x} vs {tan_h}");
            assert!(y.abs() <= tan_v * 0.97, "y {y} vs {tan_v}");
        }
    }

    #[test]
    fn framing_fits_generated_meshes() {
        let m = load_text(
            "v -3 0 -2\nv 3.4 0 -2\nv 3.4 3.15 2\nv -3 3.15 2\nv 0 10 0\nf 1 2 3 4\nf 1 2 5\n",
        )
        .unwrap();
        for (fov, aspect) in [(60.0, 4.0 / 3.0), (60.0, 0.25), (90.0, 1.0), (20.0, 3.0)] {
            check_framing(&m, fov, aspect);
        }
        // A degenerate (single-point) mesh still gets a usable camera.
        let dot = load_text("v 1 2 3\nf 1 1 1\n").unwrap();
        let (eye, target) = frame_camera(&dot, 60.0, 1.0);
        assert_eq!(target, [1.0, 2.0, 3.0]);
        assert!(eye[2] > 3.0 && eye[1] > 2.0);
        // Nonsense parameters are clamped, not propagated.
        for (fov, aspect) in [
            (f32::NAN, 1.0),
            (0.0, 1.0),
            (500.0, -1.0),
            (60.0, f32::INFINITY),
        ] {
            let (e, t) = frame_camera(&m, fov, aspect);
            assert!(e.iter().chain(&t).all(|c| c.is_finite()));
        }
    }

    #[test]
    fn framing_fits_shared_models_when_present() {
        let root = Path::new("/work/shared/models");
        for rel in [
            "cornell-box/CornellBox-Original.obj",
            "teapot/teapot.obj",
            "spot/spot_triangulated.obj",
            "stanford-bunny/stanford-bunny.obj",
        ] {
            let path = root.join(rel);
            if !path.exists() {
                eprintln!("skipping {}: not present", path.display());
                continue;
            }
            let m = load_obj(&path).unwrap();
            if rel.starts_with("cornell") {
                assert_eq!(m.indices.len(), 36);
            }
            if rel.starts_with("teapot") {
                assert_eq!(m.indices.len(), 6320);
            }
            check_framing(&m, 60.0, 800.0 / 600.0);
            check_framing(&m, 45.0, 0.5);
        }
    }
}
