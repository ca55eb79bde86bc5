//! Wavefront OBJ loading and automatic camera framing.
//!
//! Design: [`load_obj`] is for the rasterizer alone, which needs only vertex
//! positions, so the file is read with `tobj` (faces fan-triangulated,
//! positions indexed on their own, MTL files never opened) and every model
//! in it is merged into one indexed mesh. Triangle order is file order after triangulation, model by model, so
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
//! [`load_obj_shaded`] is the loader for shading: it keeps normals, texture
//! coordinates and materials. With `vt` or `vn` in the file it asks tobj for
//! one index per (v, vt, vn) corner (`single_index`), so normals and UVs are
//! indexed like positions and a position is duplicated at seams. Without
//! `vn` it computes smooth normals (area-weighted face normals summed per
//! position *value*, so UV seams do not crease, with a [`CREASE_ANGLE_DEG`]
//! limit, so a box keeps its edges). UVs are kept as in the file,
//! v = 0 at the bottom; textures ([`TextureImage`]) keep the file's row order,
//! row 0 at the top, so the texel row of v is `(1 - v) * height`. MTL files
//! are opened relative to the OBJ's folder, textures beside their MTL file
//! (`map_Kd` options such as `-s` are skipped); textures are PNG only, decoded to 8-bit RGB, at most [`MAX_TEXTURE_SIDE`] pixels a side.
//! Triangles without a material get [`Material::default_material`] (light
//! grey, [`DEFAULT_DIFFUSE`]). What the loader can repair (NaN normals or
//! UVs, a missing MTL file, degenerate faces) it repairs, counts in
//! [`ShadedCounts`] and names in a warning; what it cannot (index out of
//! range, a broken MTL, a missing or bad texture) is an error naming the
//! file and, where known, the line. Texture and normal indices are checked
//! before tobj sees them, by both loaders: tobj reports them without a line,
//! and a too-negative one overflows inside it (a panic where overflow checks
//! are on). A file without any `vt` (`vn`) may still name them in faces:
//! tobj ignores those, and so do the checks.
//!
//! [`frame_camera`] places the eye on the `(0, 0.3, 1)` side of the mesh's
//! bounding sphere at the distance where the sphere (plus a 10% margin) fits
//! both the vertical and the horizontal field of view (the benchmarks'
//! camera); [`frame_camera_front`], `render --obj`'s, on the model's front
//! ([`front_direction`]: -z, unless the model opens towards +z).

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
    let bytes = std::fs::read(path)
        .map_err(|e| format!("{}: cannot open OBJ file: {e}", path.display()))?;
    // Texture and normal indices are unused here, but a bad one can overflow
    // inside tobj (a panic with overflow checks): refuse it with its line.
    scan_corners(&String::from_utf8_lossy(&bytes))
        .map_err(|(line, what)| format!("{}: line {line}: {what}", path.display()))?;
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
    let (models, _materials) = tobj::load_obj_buf(&mut &bytes[..], &options, |_| {
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
    frame_camera_from(mesh, FRAME_DIRECTION, fov_y_deg, aspect)
}

/// The side a model is seen from by `render --obj`: its front.
///
/// Many OBJ models face -z (Spot does), so the eye goes on the `(0, 0.3,
/// -1)` side, looking towards +z, unless the model is open towards +z: a
/// room or a box seen from inside, like the Cornell box, whose inward
/// walls face away from an eye at -z. That is decided by the projected
/// area of the faces an eye on each side sees (the sum over triangles of
/// the area-weighted normal's `-z` or `+z` part): for a closed mesh the two
/// are equal (the normals of a closed surface sum to zero), and the
/// convention holds; +z is taken only where it sees over 10 % more.
pub fn front_direction(mesh: &LoadedMesh) -> [f32; 3] {
    let (mut towards_minus, mut towards_plus) = (0.0f64, 0.0f64);
    for t in &mesh.indices {
        let p = |k: usize| {
            mesh.positions
                .get(t[k] as usize)
                .map(|v| v.map(f64::from))
                .filter(|v| v.iter().all(|c| c.is_finite()))
        };
        let (Some(a), Some(b), Some(c)) = (p(0), p(1), p(2)) else {
            continue;
        };
        let (u, v) = ([b[0] - a[0], b[1] - a[1]], [c[0] - a[0], c[1] - a[1]]);
        let nz = u[0] * v[1] - u[1] * v[0];
        if nz < 0.0 {
            towards_minus -= nz;
        } else {
            towards_plus += nz;
        }
    }
    if towards_plus > 1.1 * towards_minus {
        [0.0, 0.3, 1.0]
    } else {
        [0.0, 0.3, -1.0]
    }
}

/// [`frame_camera`] from the model's front ([`front_direction`]): the
/// camera of `render --obj`.
pub fn frame_camera_front(mesh: &LoadedMesh, fov_y_deg: f32, aspect: f32) -> ([f32; 3], [f32; 3]) {
    frame_camera_from(mesh, front_direction(mesh), fov_y_deg, aspect)
}

/// [`frame_camera`] with the eye towards `direction` from the centre.
fn frame_camera_from(
    mesh: &LoadedMesh,
    direction: [f32; 3],
    fov_y_deg: f32,
    aspect: f32,
) -> ([f32; 3], [f32; 3]) {
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
    let dir = direction.map(f64::from);
    let len = dir.iter().map(|c| c * c).sum::<f64>().sqrt();
    let eye = [0, 1, 2].map(|k| (centre[k] + dir[k] / len * distance) as f32);
    let target = centre.map(|c| c as f32);
    (eye, target)
}

// ---------------------------------------------------------------------------
// Shaded loading: normals, UVs, materials and textures.
// ---------------------------------------------------------------------------

/// Largest texture side accepted by [`load_png_rgb`], in pixels (a 4096 x
/// 4096 RGB texture is 48 MiB in memory).
pub const MAX_TEXTURE_SIDE: u32 = 4096;

/// `Kd` of [`Material::default_material`] and of a material without `Kd`:
/// light grey, as most viewers use.
pub const DEFAULT_DIFFUSE: [f32; 3] = [0.8, 0.8, 0.8];

/// Name of the material given to triangles without one.
pub const DEFAULT_MATERIAL_NAME: &str = "(default)";

/// An 8-bit RGB image; row 0 is the top row of the image file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TextureImage {
    /// Width in pixels (1..=[`MAX_TEXTURE_SIDE`]).
    pub width: u32,
    /// Height in pixels (1..=[`MAX_TEXTURE_SIDE`]).
    pub height: u32,
    /// `width * height` pixels, row by row from the top.
    pub rgb: Vec<[u8; 3]>,
}

/// A surface description from an MTL file (or the default one).
#[derive(Clone, Debug, PartialEq)]
pub struct Material {
    /// `newmtl` name ([`DEFAULT_MATERIAL_NAME`] for the default material).
    pub name: String,
    /// `Kd`, each component clamped to 0..=1 ([`DEFAULT_DIFFUSE`] if absent).
    pub diffuse: [f32; 3],
    /// `Ks`, clamped to 0..=1 (black if absent).
    pub specular: [f32; 3],
    /// `Ns`, the specular exponent, clamped to 0..=1000 (0 if absent).
    pub shininess: f32,
    /// `map_Kd` loaded as RGB, or the texture given to [`load_obj_shaded`].
    pub texture: Option<TextureImage>,
}

impl Material {
    /// The material of triangles without `usemtl` (or naming an unknown
    /// material, or when the MTL file is missing): [`DEFAULT_DIFFUSE`], no
    /// specular, no texture.
    pub fn default_material() -> Self {
        Material {
            name: DEFAULT_MATERIAL_NAME.to_string(),
            diffuse: DEFAULT_DIFFUSE,
            specular: [0.0; 3],
            shininess: 0.0,
            texture: None,
        }
    }
}

/// What [`load_obj_shaded`] repaired instead of failing; all zero for a
/// clean file. [`ShadedMesh::warnings`] says which file and what.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ShadedCounts {
    /// Vertices whose computed smooth normal was zero or non-finite (a
    /// degenerate neighbourhood): given their face's normal, or (0, 0, 1).
    pub normal_fallbacks: usize,
    /// Vertices whose `vn` in the file was NaN, infinite or zero: given the
    /// computed smooth normal instead.
    pub bad_file_normals: usize,
    /// Vertices of models whose faces give `vn` for some vertices and not
    /// others: given the computed smooth normal.
    pub missing_file_normals: usize,
    /// Vertices without a texture coordinate in a mesh that has some: given
    /// (0, 0).
    pub missing_uvs: usize,
    /// Texture coordinates that are NaN or infinite: replaced by (0, 0).
    pub bad_uvs: usize,
    /// `mtllib` files that could not be opened: their materials fall back to
    /// the default material.
    pub missing_mtl_files: usize,
    /// Triangles drawn with the default material.
    pub default_material_triangles: usize,
}

/// A triangle mesh with what shading needs, merged from all models of an OBJ
/// file. Every per-vertex array has `positions.len()` entries.
#[derive(Clone, Debug, PartialEq)]
pub struct ShadedMesh {
    /// Vertex positions (model space, as in the file). With `vt` or `vn` in
    /// the file a position appears once per distinct (v, vt, vn) corner.
    pub positions: Vec<[f32; 3]>,
    /// Triangles as indices into the per-vertex arrays, in file order.
    pub indices: Vec<[u32; 3]>,
    /// Unit normal per vertex: the file's `vn` (normalised) or a computed
    /// smooth normal.
    pub normals: Vec<[f32; 3]>,
    /// `true` if every normal came from the file's `vn`.
    pub normals_from_file: bool,
    /// Texture coordinates per vertex, as in the file (v = 0 is the bottom of
    /// the image, so texel row = (1 - v) * height; the core's textures are
    /// addressed row 0 first, so pass it `(u, 1 - v)`, as `bake` writes
    /// them); `None` without `vt`.
    pub uvs: Option<Vec<[f32; 2]>>,
    /// Materials: the MTL files' in file order, then the default material if
    /// any triangle uses it.
    pub materials: Vec<Material>,
    /// One index into `materials` per triangle.
    pub triangle_material: Vec<u32>,
    /// Component-wise minimum over the finite positions (all zero if none).
    pub bounds_min: [f32; 3],
    /// Component-wise maximum over the finite positions (all zero if none).
    pub bounds_max: [f32; 3],
    /// What was repaired, counted.
    pub counts: ShadedCounts,
    /// One line per kind of repair, naming the file (for stderr).
    pub warnings: Vec<String>,
}

impl ShadedMesh {
    /// Positions and indices only, as [`load_obj`] would give them (for
    /// [`frame_camera`]).
    pub fn to_loaded(&self) -> LoadedMesh {
        LoadedMesh {
            positions: self.positions.clone(),
            indices: self.indices.clone(),
            bounds_min: self.bounds_min,
            bounds_max: self.bounds_max,
        }
    }
}

/// Loads `path` (PNG) as 8-bit RGB, row 0 at the top. Grey, palette, alpha
/// and 16-bit images are converted (alpha dropped, 16 bits truncated to 8).
/// Errors name the file: missing, not a PNG, zero size or a side over
/// [`MAX_TEXTURE_SIDE`] (checked from the header, before decoding).
pub fn load_png_rgb(path: &Path) -> Result<TextureImage, String> {
    let what = |e: &dyn std::fmt::Display| format!("{}: cannot load texture: {e}", path.display());
    let file = File::open(path).map_err(|e| what(&e))?;
    let mut decoder = png::Decoder::new(BufReader::new(file));
    decoder.set_transformations(png::Transformations::normalize_to_color8());
    let mut reader = decoder
        .read_info()
        .map_err(|e| what(&format!("not a readable PNG ({e})")))?;
    let (width, height) = reader.info().size();
    if width == 0 || height == 0 {
        return Err(what(&format!("the image is {width}x{height} pixels")));
    }
    if width > MAX_TEXTURE_SIDE || height > MAX_TEXTURE_SIDE {
        return Err(what(&format!(
            "the image is {width}x{height} pixels; textures may be at most \
             {MAX_TEXTURE_SIDE}x{MAX_TEXTURE_SIDE}"
        )));
    }
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| what(&"image too large"))?;
    let mut buf = vec![0u8; size];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| what(&format!("PNG data is damaged ({e})")))?;
    let channels = match info.color_type {
        png::ColorType::Grayscale => 1,
        png::ColorType::GrayscaleAlpha => 2,
        png::ColorType::Rgb => 3,
        png::ColorType::Rgba => 4,
        png::ColorType::Indexed => return Err(what(&"palette was not expanded")),
    };
    if info.bit_depth != png::BitDepth::Eight {
        return Err(what(&format!("unexpected bit depth {:?}", info.bit_depth)));
    }
    let (w, h) = (width as usize, height as usize);
    let mut rgb = Vec::with_capacity(w * h);
    for row in buf[..info.buffer_size()]
        .chunks_exact(info.line_size)
        .take(h)
    {
        for px in row[..w * channels].chunks_exact(channels) {
            rgb.push(if channels < 3 {
                [px[0]; 3]
            } else {
                [px[0], px[1], px[2]]
            });
        }
    }
    if rgb.len() != w * h {
        return Err(what(&"PNG data is short"));
    }
    Ok(TextureImage { width, height, rgb })
}

/// Which indices a file's faces use, from [`scan_corners`].
struct CornerScan {
    has_vt: bool,
    has_vn: bool,
}

/// Checks every face's texture and normal indices (tobj does not give a line,
/// and some out-of-range ones overflow inside it), and says whether the file
/// has `vt` or `vn` at all. Positions are left to tobj and [`locate_error`].
fn scan_corners(text: &str) -> Result<CornerScan, (usize, String)> {
    let count = |kind: &str| {
        text.lines()
            .filter(|l| l.split_whitespace().next() == Some(kind))
            .count() as i64
    };
    let (total_vt, total_vn) = (count("vt"), count("vn"));
    let (mut seen_vt, mut seen_vn) = (0i64, 0i64);
    for (n, line) in text.lines().enumerate() {
        let mut toks = line.split_whitespace();
        match toks.next() {
            Some("vt") => seen_vt += 1,
            Some("vn") => seen_vn += 1,
            Some("f") => {
                for corner in toks {
                    let parts: Vec<&str> = corner.split('/').collect();
                    let checks = [
                        (1, "texture coordinate", seen_vt, total_vt),
                        (2, "normal", seen_vn, total_vn),
                    ];
                    for (slot, name, seen, total) in checks {
                        // With no `vt` (`vn`) at all tobj ignores those indices.
                        let Some(&s) = parts.get(slot).filter(|s| !s.is_empty() && total > 0)
                        else {
                            continue;
                        };
                        let quoted = format!("`{}`", line.trim());
                        let bad = match s.parse::<i64>() {
                            Err(_) => Some(format!("{s:?} is not a {name} index: {quoted}")),
                            Ok(0) => Some(format!("{name} indices start at 1, not 0: {quoted}")),
                            Ok(i) if i < 0 && -i > seen => Some(format!(
                                "{name} index {i} reaches back past the {seen} before this \
                                 line: {quoted}"
                            )),
                            Ok(i) if i > total => Some(format!(
                                "{name} index {i} is past the file's {total}: {quoted}"
                            )),
                            Ok(_) => None,
                        };
                        if let Some(b) = bad {
                            return Err((n + 1, b));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(CornerScan {
        has_vt: total_vt > 0,
        has_vn: total_vn > 0,
    })
}

/// The first line of MTL `text` that tobj would refuse, and why.
fn locate_mtl_error(text: &str) -> Option<(usize, String)> {
    for (n, line) in text.lines().enumerate() {
        let toks: Vec<&str> = line.split_whitespace().collect();
        let Some((&kind, args)) = toks.split_first() else {
            continue;
        };
        let floats =
            |k: usize| args.len() >= k && args[..k].iter().all(|t| t.parse::<f32>().is_ok());
        let quoted = format!("`{}`", line.trim());
        let bad = match kind {
            "Ka" | "Kd" | "Ks" | "Ke" if !floats(3) => {
                Some(format!("{kind} needs three numbers r g b: {quoted}"))
            }
            "Ns" | "Ni" | "d" if !floats(1) => Some(format!("{kind} needs a number: {quoted}")),
            "newmtl" | "map_Ka" | "map_Kd" | "map_Ks" | "map_Bump" | "map_bump" | "bump"
            | "map_Ns" | "map_d"
                if args.is_empty() =>
            {
                Some(format!("{kind} needs a name: {quoted}"))
            }
            "illum" if args.first().and_then(|a| a.parse::<u8>().ok()).is_none() => {
                Some(format!("illum needs a whole number: {quoted}"))
            }
            _ => None,
        };
        if bad.is_some() {
            return bad.map(|b| (n + 1, b));
        }
    }
    None
}

/// Faces meeting at a larger angle than this keep a hard edge in
/// [`smooth_normals`] (a box stays a box; a UV seam on a smooth surface,
/// where the angle is near zero, is smoothed over).
pub const CREASE_ANGLE_DEG: f32 = 60.0;

/// Area-weighted smooth normals, and how many vertices needed a fallback.
///
/// Face normals are accumulated per position *value*, so vertices duplicated
/// at UV seams get the same normal. Around a position, faces whose normals
/// are within [`CREASE_ANGLE_DEG`] of each other are linked, transitively,
/// into smooth sheets; a vertex sums the sheets its own faces are in (so
/// every copy of a seam vertex on a smooth surface gets the same normal,
/// and each wall of a box stays flat). A vertex whose sum is zero or non-finite (only
/// degenerate faces) gets its first non-degenerate face's normal, else
/// (0, 0, 1), and is counted.
pub fn smooth_normals(positions: &[[f32; 3]], indices: &[[u32; 3]]) -> (Vec<[f32; 3]>, usize) {
    use std::collections::HashMap;
    let key = |p: [f32; 3]| p.map(|c| if c == 0.0 { 0u32 } else { c.to_bits() });
    let mut slot_of: HashMap<[u32; 3], usize> = HashMap::new();
    let slots: Vec<usize> = positions
        .iter()
        .map(|&p| {
            let next = slot_of.len();
            *slot_of.entry(key(p)).or_insert(next)
        })
        .collect();
    let unit = |n: [f64; 3]| {
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        (len.is_finite() && len > 0.0).then(|| n.map(|c| c / len))
    };
    // Twice the area times the unit normal (area weighting for free), and
    // the unit normal; `None` for a degenerate or non-finite face.
    let faces: Vec<Option<([f64; 3], [f64; 3])>> = indices
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| positions[i as usize].map(f64::from));
            let u = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
            let v = [c[0] - a[0], c[1] - a[1], c[2] - a[2]];
            let n = [
                u[1] * v[2] - u[2] * v[1],
                u[2] * v[0] - u[0] * v[2],
                u[0] * v[1] - u[1] * v[0],
            ];
            unit(n).map(|nu| (n, nu))
        })
        .collect();
    // Faces around each position value, and each vertex's own faces.
    let mut at_slot: Vec<Vec<usize>> = vec![Vec::new(); slot_of.len()];
    let mut own: Vec<Vec<usize>> = vec![Vec::new(); positions.len()];
    for (f, t) in indices.iter().enumerate() {
        if faces[f].is_none() {
            continue;
        }
        for &i in t {
            let s = &mut at_slot[slots[i as usize]];
            if s.last() != Some(&f) {
                s.push(f);
            }
            own[i as usize].push(f);
        }
    }
    // Around each position, faces whose normals are within the crease angle
    // are linked, transitively: each group is one smooth sheet.
    let cos_crease = f64::from(CREASE_ANGLE_DEG).to_radians().cos();
    let groups: Vec<Vec<usize>> = at_slot
        .iter()
        .map(|fs| {
            let mut parent: Vec<usize> = (0..fs.len()).collect();
            fn root(p: &mut [usize], mut a: usize) -> usize {
                while p[a] != a {
                    p[a] = p[p[a]];
                    a = p[a];
                }
                a
            }
            for a in 0..fs.len() {
                for b in a + 1..fs.len() {
                    let (_, na) = faces[fs[a]].unwrap_or_default();
                    let (_, nb) = faces[fs[b]].unwrap_or_default();
                    if na[0] * nb[0] + na[1] * nb[1] + na[2] * nb[2] >= cos_crease {
                        let (ra, rb) = (root(&mut parent, a), root(&mut parent, b));
                        parent[ra.max(rb)] = ra.min(rb);
                    }
                }
            }
            (0..fs.len()).map(|a| root(&mut parent, a)).collect()
        })
        .collect();
    let mut fallbacks = 0;
    let normals = (0..positions.len())
        .map(|i| {
            let (fs, gs) = (&at_slot[slots[i]], &groups[slots[i]]);
            // The sheets this vertex's own faces belong to.
            let mine: Vec<usize> = own[i]
                .iter()
                .filter_map(|f| fs.iter().position(|g| g == f).map(|k| gs[k]))
                .collect();
            let mut sum = [0.0f64; 3];
            for (&f, g) in fs.iter().zip(gs) {
                if mine.contains(g) {
                    let (n, _) = faces[f].unwrap_or_default();
                    (0..3).for_each(|k| sum[k] += n[k]);
                }
            }
            unit(sum).map(|n| n.map(|c| c as f32)).unwrap_or_else(|| {
                fallbacks += 1;
                own[i]
                    .first()
                    .and_then(|&f| faces[f])
                    .map_or([0.0, 0.0, 1.0], |(_, nu)| nu.map(|c| c as f32))
            })
        })
        .collect();
    (normals, fallbacks)
}

fn clamp01(c: [f32; 3], default: [f32; 3]) -> [f32; 3] {
    [0, 1, 2].map(|k| {
        if c[k].is_finite() {
            c[k].clamp(0.0, 1.0)
        } else {
            default[k]
        }
    })
}

/// Where `map_Kd NAME` points: options before the file name (`-s 1 1 1
/// a.png`, `-clamp on a.png`) are skipped by taking the last word when NAME
/// starts with `-`; the file is looked for beside its MTL file, then beside
/// the OBJ (the same folder unless `mtllib` names a subfolder).
fn texture_path(name: &str, mtl_dir: &Path, obj_dir: &Path) -> std::path::PathBuf {
    let file = if name.starts_with('-') {
        name.split_whitespace().last().unwrap_or(name)
    } else {
        name
    };
    let beside_mtl = mtl_dir.join(file);
    if beside_mtl.exists() || mtl_dir == obj_dir {
        beside_mtl
    } else {
        obj_dir.join(file)
    }
}

/// Loads `path` as a Wavefront OBJ file with normals, texture coordinates and
/// materials; all models are merged into one mesh (see [`ShadedMesh`]).
///
/// MTL files (`mtllib`) are opened relative to the OBJ's folder, textures
/// (`map_Kd`) beside their MTL file (the same folder, unless `mtllib` names a
/// subfolder; then the OBJ's folder is tried too). A missing MTL file is a warning (its materials become the
/// default material, counted in [`ShadedCounts::missing_mtl_files`]); a
/// malformed MTL file, a missing or unreadable texture, a non-PNG texture and
/// one of zero size or over [`MAX_TEXTURE_SIDE`] are errors. With
/// `texture_override`, that PNG becomes the texture of every material (the
/// default one included), replacing any `map_Kd`: for OBJ files with UVs and
/// no MTL, such as Spot. Face indices out of range (positions, texture
/// coordinates, normals) are errors with the line; NaN normals and UVs are
/// replaced and counted. Every message names the file.
pub fn load_obj_shaded(path: &Path, texture_override: Option<&Path>) -> Result<ShadedMesh, String> {
    use std::cell::RefCell;
    use std::collections::HashMap;
    let bytes = std::fs::read(path)
        .map_err(|e| format!("{}: cannot open OBJ file: {e}", path.display()))?;
    let text = String::from_utf8_lossy(&bytes);
    let scan = scan_corners(&text)
        .map_err(|(line, what)| format!("{}: line {line}: {what}", path.display()))?;
    let dir = path.parent().unwrap_or(Path::new("")).to_path_buf();
    #[allow(clippy::needless_update)]
    let options = tobj::LoadOptions {
        triangulate: true,
        single_index: scan.has_vt || scan.has_vn,
        ignore_points: true,
        ignore_lines: true,
        ..Default::default()
    };
    // tobj swallows MTL errors; the loader records them here.
    let mtl_missing: RefCell<Vec<String>> = RefCell::new(Vec::new());
    let mtl_error: RefCell<Option<String>> = RefCell::new(None);
    // Where each MTL file's materials start, to find their textures' folder.
    let mtl_files: RefCell<Vec<(usize, std::path::PathBuf)>> = RefCell::new(Vec::new());
    let (models, materials) =
        tobj::load_obj_buf(&mut std::io::Cursor::new(&bytes[..]), &options, |p| {
            let full = dir.join(p);
            match std::fs::read(&full) {
                Err(e) => {
                    mtl_missing
                        .borrow_mut()
                        .push(format!("{}: {e}", full.display()));
                    Err(tobj::LoadError::OpenFileFailed)
                }
                Ok(mtl) => {
                    let r = tobj::load_mtl_buf(&mut std::io::Cursor::new(&mtl[..]));
                    match &r {
                        Err(e) => {
                            let t = String::from_utf8_lossy(&mtl);
                            let msg = match locate_mtl_error(&t) {
                                Some((line, what)) => {
                                    format!("{}: line {line}: {what} ({e})", full.display())
                                }
                                None => format!("{}: cannot load MTL file: {e}", full.display()),
                            };
                            mtl_error.borrow_mut().get_or_insert(msg);
                        }
                        Ok((mats, _)) => mtl_files.borrow_mut().push((mats.len(), full)),
                    }
                    r
                }
            }
        })
        .map_err(|e| describe_load_error(path, &e))?;
    if let Some(e) = mtl_error.into_inner() {
        return Err(e);
    }
    // A missing MTL makes tobj return Err here when no MTL loaded at all.
    let tobj_materials = materials.unwrap_or_default();

    let mut counts = ShadedCounts::default();
    let mut warnings = Vec::new();
    let missing = mtl_missing.into_inner();
    counts.missing_mtl_files = missing.len();
    for m in &missing {
        warnings.push(format!(
            "{}: material file missing, using the default material: {m}",
            path.display()
        ));
    }

    // Materials, with their textures opened beside their MTL file.
    let override_tex = texture_override.map(load_png_rgb).transpose()?;
    let mut mtl_dirs: Vec<std::path::PathBuf> = Vec::new();
    for (n, file) in mtl_files.into_inner() {
        let d = file.parent().unwrap_or(Path::new("")).to_path_buf();
        mtl_dirs.extend(std::iter::repeat_n(d, n));
    }
    let mut materials: Vec<Material> = Vec::with_capacity(tobj_materials.len() + 1);
    // Materials sharing a texture file share one decoding.
    let mut decoded: HashMap<std::path::PathBuf, TextureImage> = HashMap::new();
    for (i, m) in tobj_materials.iter().enumerate() {
        let texture = match (&override_tex, &m.diffuse_texture) {
            (Some(t), _) => Some(t.clone()),
            (None, Some(name)) => {
                let tex_path = texture_path(name, mtl_dirs.get(i).unwrap_or(&dir), &dir);
                if !decoded.contains_key(&tex_path) {
                    let t = load_png_rgb(&tex_path).map_err(|e| {
                        format!("{}: material {:?}: map_Kd: {e}", path.display(), m.name)
                    })?;
                    decoded.insert(tex_path.clone(), t);
                }
                decoded.get(&tex_path).cloned()
            }
            (None, None) => None,
        };
        materials.push(Material {
            name: m.name.clone(),
            diffuse: clamp01(m.diffuse.unwrap_or(DEFAULT_DIFFUSE), DEFAULT_DIFFUSE),
            specular: clamp01(m.specular.unwrap_or([0.0; 3]), [0.0; 3]),
            shininess: m
                .shininess
                .filter(|s| s.is_finite())
                .map_or(0.0, |s| s.clamp(0.0, 1000.0)),
            texture,
        });
    }

    // Merge the models.
    let mut positions: Vec<[f32; 3]> = Vec::new();
    let mut indices: Vec<[u32; 3]> = Vec::new();
    let mut file_normals: Vec<Option<[f32; 3]>> = Vec::new();
    let mut uvs: Vec<Option<[f32; 2]>> = Vec::new();
    let mut tri_mat: Vec<Option<u32>> = Vec::new();
    for model in &models {
        let m = &model.mesh;
        let base = positions.len();
        let count = m.positions.len() / 3;
        if m.positions.len() % 3 != 0 || m.indices.len() % 3 != 0 {
            return Err(format!(
                "{}: model {:?}: malformed mesh data",
                path.display(),
                model.name
            ));
        }
        let offset = u32::try_from(base + count)
            .map(|_| base as u32)
            .map_err(|_| format!("{}: too many vertices (more than 2^32)", path.display()))?;
        positions.extend(m.positions.chunks_exact(3).map(|p| [p[0], p[1], p[2]]));
        if m.normals.len() == 3 * count {
            file_normals.extend(m.normals.chunks_exact(3).map(|n| Some([n[0], n[1], n[2]])));
        } else {
            counts.missing_file_normals += if m.normals.is_empty() && !scan.has_vn {
                0
            } else {
                count
            };
            file_normals.extend(std::iter::repeat_n(None, count));
        }
        if m.texcoords.len() == 2 * count {
            uvs.extend(m.texcoords.chunks_exact(2).map(|t| Some([t[0], t[1]])));
        } else {
            uvs.extend(std::iter::repeat_n(None, count));
        }
        let mat = m
            .material_id
            .filter(|&i| i < materials.len())
            .map(|i| i as u32);
        for t in m.indices.chunks_exact(3) {
            let mut tri = [0u32; 3];
            for (dst, &i) in tri.iter_mut().zip(t) {
                if i as usize >= count {
                    return Err(format!(
                        "{}: model {:?}: vertex index {i} out of range",
                        path.display(),
                        model.name
                    ));
                }
                *dst = i + offset;
            }
            indices.push(tri);
            tri_mat.push(mat);
        }
    }
    if indices.is_empty() {
        return Err(format!("{}: no triangles (faces) found", path.display()));
    }

    // Normals: the file's where usable, else smooth ones.
    let (smooth, fallbacks) = smooth_normals(&positions, &indices);
    let mut normals_from_file = true;
    let normals: Vec<[f32; 3]> = file_normals
        .iter()
        .zip(&smooth)
        .map(|(f, s)| {
            let unit = f.and_then(|n| {
                let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                (len.is_finite() && len > 0.0).then(|| n.map(|c| c / len))
            });
            if f.is_some() && unit.is_none() {
                counts.bad_file_normals += 1;
            }
            unit.unwrap_or_else(|| {
                normals_from_file = false;
                *s
            })
        })
        .collect();
    // Fallbacks matter only where the computed normal is used.
    if !normals_from_file {
        counts.normal_fallbacks = fallbacks;
    }

    let uvs = if uvs.iter().any(Option::is_some) {
        Some(
            uvs.iter()
                .map(|t| match t {
                    None => {
                        counts.missing_uvs += 1;
                        [0.0, 0.0]
                    }
                    Some(t) if !t.iter().all(|c| c.is_finite()) => {
                        counts.bad_uvs += 1;
                        [0.0, 0.0]
                    }
                    Some(t) => *t,
                })
                .collect(),
        )
    } else {
        None
    };

    counts.default_material_triangles = tri_mat.iter().filter(|m| m.is_none()).count();
    let default_index = materials.len() as u32;
    if counts.default_material_triangles > 0 {
        let mut d = Material::default_material();
        d.texture = override_tex.clone();
        materials.push(d);
    }
    let triangle_material = tri_mat.iter().map(|m| m.unwrap_or(default_index)).collect();

    let p = path.display();
    let c = counts;
    for (n, what) in [
        (
            c.normal_fallbacks,
            "vertices had no usable smooth normal (degenerate faces) and got a fallback",
        ),
        (
            c.bad_file_normals,
            "normals in the file were NaN, infinite or zero and were recomputed",
        ),
        (
            c.missing_file_normals,
            "vertices had no normal in the file (faces mix v and v//vn) and got a computed one",
        ),
        (
            c.missing_uvs,
            "vertices had no texture coordinate and got (0, 0)",
        ),
        (
            c.bad_uvs,
            "texture coordinates were NaN or infinite and became (0, 0)",
        ),
    ] {
        if n > 0 {
            warnings.push(format!("{p}: {n} {what}"));
        }
    }
    // Without any material file, the default material is no surprise.
    if c.default_material_triangles > 0 && !tobj_materials.is_empty() {
        warnings.push(format!(
            "{p}: {} triangles have no `usemtl`, or name a material no MTL file defines: \
             default material",
            c.default_material_triangles
        ));
    }

    let (bounds_min, bounds_max) = finite_bounds(&positions);
    Ok(ShadedMesh {
        positions,
        indices,
        normals,
        normals_from_file,
        uvs,
        materials,
        triangle_material,
        bounds_min,
        bounds_max,
        counts,
        warnings,
    })
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
