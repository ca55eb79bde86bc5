//! `microraster bake`: a model as Rust source for firmware to `include!`.
//!
//! Design: the model is loaded with [`obj::load_obj_shaded`], optionally
//! decimated, and written as one file `DIR/<model>.rs` of `pub` constants and
//! statics (the texture inline too, so one `include!` brings everything; no
//! `include_bytes!` and no alignment worries). `<model>` is the OBJ's file
//! stem in lower case with every character outside `[a-z0-9_]` made `_`.
//! The file holds, with `N` vertices, `M` triangles and `K` materials:
//!
//! | item | type | what |
//! |---|---|---|
//! | `VERTEX_COUNT`, `TRIANGLE_COUNT`, `MATERIAL_COUNT` | `usize` | `N`, `M`, `K` |
//! | `POSITIONS` (`--positions f32`) | `[microraster::Vec3; N]` | exact: `{:?}` of an `f32` round-trips |
//! | `POSITIONS_I16` (`--positions i16`) | `[[i16; 3]; N]` | position = `q * POSITION_SCALE + POSITION_OFFSET` per axis |
//! | `POSITION_SCALE`, `POSITION_OFFSET` (i16 only) | `[f32; 3]` | offset = box centre, scale = box size / 65534 (1 for a flat axis) |
//! | `INDICES` | `[[u32; 3]; M]` | triangles, file winding |
//! | `NORMALS` | `[microraster::Vec3; N]` | unit |
//! | `UVS` (if the model has UVs) | `[[f32; 2]; N]` | `(u, 1 - v)`: v flipped from the file's, so v = 0 is the texture's row 0 (top) |
//! | `TEXTURE_WIDTH`, `TEXTURE_HEIGHT` (if textured) | `u32` | `--texture-size` |
//! | `TEXTURE` (if textured) | `[u16; W * H]` | Rgb565 (r5 g6 b5, red in the top bits), row 0 = top of the image |
//! | `MATERIAL_TEXTURED` (if textured) | `[bool; K]` | which materials sample `TEXTURE` |
//! | `MATERIAL_DIFFUSE`, `MATERIAL_SPECULAR` | `[[u8; 3]; K]` | `Kd`, `Ks` in 0..=255 |
//! | `MATERIAL_SHININESS` | `[f32; K]` | `Ns` |
//! | `TRIANGLE_MATERIAL` | `[u8; M]` | index into the material arrays |
//!
//! UVs are baked in the core's convention (`microraster::shade::Texture`:
//! texel `(u * W, v * H)`, row 0 first), so the file's v, which points up,
//! is flipped: a baked `[u, v]` addresses column `u * W`, row `v * H` of
//! `TEXTURE` directly (clamp or wrap: Spot's UVs leave [0, 1] slightly).
//! The flip is exact for v in [0.5, 1] and within half an f32 ulp of 1
//! below. The texture is resampled to `W x H`
//! with an area-weighted box filter (each target texel is the mean of the
//! source pixels it covers, fractions weighted; no gamma correction), then
//! rounded to Rgb565 as `(c * 31 + 127) / 255` (`* 63` for green). A model
//! may have one texture (every textured material the same image); a
//! texture without UVs is left out with a note.
//!
//! `--max-triangles N` decimates by vertex clustering: the bounding box is
//! cut into cubic cells, every vertex in a cell becomes one (mean position,
//! normalised mean normal, the UV of the cell's first vertex), triangles
//! that lose a corner and exact duplicates are dropped. The grid is the
//! finest (found by bisection over cells along the longest side, 1..=4096)
//! that leaves at most `N` triangles. Deterministic, fast, crude: it does
//! not preserve the silhouette as edge collapse would, and UVs smear at
//! texture seams. A mesh that cannot reach `N` triangles without vanishing
//! is an error.
//!
//! `--clusters` also writes `DIR/<model>_clusters.rs` ([`cluster_source`]):
//! the same triangles in cluster order (meshoptimizer's meshlets, as
//! `microraster cull` builds them) over the same vertices, and the arrays
//! of a [`microraster::ClusterSet`], so that firmware can cull clusters
//! before transforming them (`examples/firmware`, feature `clusters`).
//! Floats are written so that they read back bit for bit.
//!
//! Positions must be finite (no literal for NaN; a NaN has no place in
//! firmware data), at most 256 materials (`u8`). The output is staged in a
//! temporary file and renamed ([`output::write_all`]), so a failed bake
//! leaves nothing in `DIR`. The command prints the flash bytes of both
//! position formats, the i16 error against f32 (maximum and RMS over
//! vertices, relative to the bounding box diagonal) and the total.

use crate::cli::{BakeArgs, PositionsArg};
use crate::cluster::{self, ClusterOptions};
use crate::obj::{self, ShadedMesh, TextureImage};
use crate::output::{self, Output, Payload};
use std::collections::HashMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// Largest `--texture-size`.
pub const MAX_BAKE_TEXTURE: u32 = 1024;

/// Checks a texture side: a power of two in 1..=[`MAX_BAKE_TEXTURE`].
pub fn check_texture_size(n: u32) -> Result<u32, String> {
    if n == 0 || n > MAX_BAKE_TEXTURE || !n.is_power_of_two() {
        return Err(format!(
            "texture size must be a power of two from 1 to {MAX_BAKE_TEXTURE}, got {n}"
        ));
    }
    Ok(n)
}

/// i16 positions for a bounding box, and how to get them back.
#[derive(Clone, Debug, PartialEq)]
pub struct Quantized {
    /// One `[x, y, z]` per vertex, each in -32767..=32767.
    pub q: Vec<[i16; 3]>,
    /// Per-axis step: position = q * scale + offset.
    pub scale: [f32; 3],
    /// Per-axis centre of the bounding box.
    pub offset: [f32; 3],
}

impl Quantized {
    /// Vertex `i` back in model space, as firmware computes it (f32).
    pub fn dequantize(&self, i: usize) -> [f32; 3] {
        [0, 1, 2].map(|k| self.q[i][k] as f32 * self.scale[k] + self.offset[k])
    }
}

/// Quantizes finite `positions` to i16 over their bounding box.
pub fn quantize_i16(positions: &[[f32; 3]]) -> Quantized {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if positions.is_empty() {
        (lo, hi) = ([0.0; 3], [0.0; 3]);
    }
    let offset = [0, 1, 2].map(|k| ((lo[k] as f64 + hi[k] as f64) * 0.5) as f32);
    let scale = [0, 1, 2].map(|k| {
        let s = ((hi[k] as f64 - lo[k] as f64) / 65534.0) as f32;
        if s > 0.0 && s.is_finite() {
            s
        } else {
            1.0
        }
    });
    let q = positions
        .iter()
        .map(|p| {
            [0, 1, 2].map(|k| {
                let t = (p[k] as f64 - offset[k] as f64) / scale[k] as f64;
                t.round().clamp(-32767.0, 32767.0) as i16
            })
        })
        .collect();
    Quantized { q, scale, offset }
}

/// Error of `quant` against `positions`: (max, RMS) of the per-vertex
/// distance, divided by the bounding box diagonal (absolute if it is zero).
pub fn quantization_error(positions: &[[f32; 3]], quant: &Quantized) -> (f64, f64) {
    let diag = bbox_diagonal(positions);
    let diag = if diag > 0.0 { diag } else { 1.0 };
    let (mut max, mut sum2) = (0.0f64, 0.0f64);
    for (i, p) in positions.iter().enumerate() {
        let d = quant.dequantize(i);
        let e2: f64 = (0..3).map(|k| (d[k] as f64 - p[k] as f64).powi(2)).sum();
        max = max.max(e2.sqrt());
        sum2 += e2;
    }
    let rms = (sum2 / positions.len().max(1) as f64).sqrt();
    (max / diag, rms / diag)
}

fn bbox_diagonal(positions: &[[f32; 3]]) -> f64 {
    let (lo, hi) = bounds(positions);
    (0..3)
        .map(|k| (hi[k] as f64 - lo[k] as f64).powi(2))
        .sum::<f64>()
        .sqrt()
}

fn bounds(positions: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for p in positions {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if positions.is_empty() {
        return ([0.0; 3], [0.0; 3]);
    }
    (lo, hi)
}

/// `tex` resampled to `w x h` with an area-weighted box filter (row 0 on top).
pub fn resample_box(tex: &TextureImage, w: u32, h: u32) -> Vec<[u8; 3]> {
    let (sw, sh) = (tex.width as f64, tex.height as f64);
    let spans = |n: u32, src: f64| -> Vec<Vec<(usize, f64)>> {
        (0..n)
            .map(|d| {
                let a = d as f64 * src / n as f64;
                let b = (d + 1) as f64 * src / n as f64;
                let mut v = Vec::new();
                let mut s = a.floor();
                while s < b {
                    let wgt = (b.min(s + 1.0) - a.max(s)).max(0.0);
                    if wgt > 0.0 {
                        v.push(((s as usize).min(src as usize - 1), wgt));
                    }
                    s += 1.0;
                }
                v
            })
            .collect()
    };
    let (xs, ys) = (spans(w, sw), spans(h, sh));
    let mut out = Vec::with_capacity((w * h) as usize);
    for yspan in &ys {
        for xspan in &xs {
            let mut acc = [0.0f64; 3];
            let mut total = 0.0;
            for &(sy, wy) in yspan {
                for &(sx, wx) in xspan {
                    let px = tex.rgb[sy * tex.width as usize + sx];
                    let wgt = wx * wy;
                    for k in 0..3 {
                        acc[k] += px[k] as f64 * wgt;
                    }
                    total += wgt;
                }
            }
            out.push(acc.map(|c| (c / total).round().clamp(0.0, 255.0) as u8));
        }
    }
    out
}

/// An 8-bit colour as an Rgb565 word, rounded to nearest.
pub fn rgb565(c: [u8; 3]) -> u16 {
    let r = (c[0] as u32 * 31 + 127) / 255;
    let g = (c[1] as u32 * 63 + 127) / 255;
    let b = (c[2] as u32 * 31 + 127) / 255;
    ((r << 11) | (g << 5) | b) as u16
}

/// Cluster ids of every vertex for a grid of `cells` along the longest
/// side of the bounding box.
fn cluster_ids(positions: &[[f32; 3]], cells: u32) -> Vec<u64> {
    let (lo, hi) = bounds(positions);
    let ext = [0, 1, 2].map(|k| hi[k] as f64 - lo[k] as f64);
    let longest = ext.iter().cloned().fold(0.0, f64::max);
    let size = if longest > 0.0 {
        longest / cells as f64
    } else {
        1.0
    };
    let dims = ext.map(|e| ((e / size).ceil() as u64).clamp(1, cells as u64));
    positions
        .iter()
        .map(|p| {
            let c = [0, 1, 2]
                .map(|k| (((p[k] as f64 - lo[k] as f64) / size).floor() as u64).min(dims[k] - 1));
            (c[2] * dims[1] + c[1]) * dims[0] + c[0]
        })
        .collect()
}

/// The triangles (as cluster-id triples, with their index) that survive
/// clustering: no collapsed corner, no exact duplicate.
fn surviving(mesh: &ShadedMesh, ids: &[u64]) -> Vec<(usize, [u64; 3])> {
    let mut seen = std::collections::HashSet::new();
    let mut out = Vec::new();
    for (t, tri) in mesh.indices.iter().enumerate() {
        let c = tri.map(|i| ids[i as usize]);
        if c[0] == c[1] || c[1] == c[2] || c[0] == c[2] {
            continue;
        }
        // Same triangle, same winding, whatever the starting corner.
        let r = (0..3).min_by_key(|&s| c[s]).unwrap_or(0);
        let key = [c[r], c[(r + 1) % 3], c[(r + 2) % 3]];
        if seen.insert((key, mesh.triangle_material[t])) {
            out.push((t, c));
        }
    }
    out
}

/// `mesh` decimated by vertex clustering to at most `max_triangles`
/// triangles (unchanged if it has no more). See the module notes.
pub fn decimate(mesh: &ShadedMesh, max_triangles: usize) -> Result<ShadedMesh, String> {
    if mesh.indices.len() <= max_triangles {
        return Ok(mesh.clone());
    }
    let count = |cells: u32| surviving(mesh, &cluster_ids(&mesh.positions, cells)).len();
    let (mut lo, mut hi) = (1u32, 4096u32);
    while lo < hi {
        let mid = lo + (hi - lo).div_ceil(2);
        if count(mid) <= max_triangles {
            lo = mid;
        } else {
            hi = mid - 1;
        }
    }
    let ids = cluster_ids(&mesh.positions, lo);
    let kept = surviving(mesh, &ids);
    if kept.is_empty() || kept.len() > max_triangles {
        return Err(format!(
            "cannot decimate {} triangles to at most {max_triangles} without losing the whole \
             mesh: ask for more triangles",
            mesh.indices.len()
        ));
    }
    // One new vertex per cluster used, in order of first use.
    let mut slot: HashMap<u64, u32> = HashMap::new();
    for (_, c) in &kept {
        for &id in c {
            let next = slot.len() as u32;
            slot.entry(id).or_insert(next);
        }
    }
    let n = slot.len();
    let mut pos_sum = vec![[0.0f64; 3]; n];
    let mut nrm_sum = vec![[0.0f64; 3]; n];
    let mut members = vec![0u32; n];
    let mut first: Vec<Option<usize>> = vec![None; n];
    for (v, id) in ids.iter().enumerate() {
        let Some(&s) = slot.get(id) else { continue };
        let s = s as usize;
        for k in 0..3 {
            pos_sum[s][k] += mesh.positions[v][k] as f64;
            nrm_sum[s][k] += mesh.normals[v][k] as f64;
        }
        members[s] += 1;
        first[s].get_or_insert(v);
    }
    let positions = (0..n)
        .map(|s| pos_sum[s].map(|c| (c / members[s] as f64) as f32))
        .collect();
    let normals = (0..n)
        .map(|s| {
            let m = nrm_sum[s];
            let len = (m[0] * m[0] + m[1] * m[1] + m[2] * m[2]).sqrt();
            if len > 0.0 && len.is_finite() {
                m.map(|c| (c / len) as f32)
            } else {
                mesh.normals[first[s].unwrap_or(0)]
            }
        })
        .collect();
    let uvs = mesh.uvs.as_ref().map(|uv| {
        (0..n)
            .map(|s| uv[first[s].unwrap_or(0)])
            .collect::<Vec<_>>()
    });
    let indices = kept.iter().map(|(_, c)| c.map(|id| slot[&id])).collect();
    let triangle_material = kept
        .iter()
        .map(|&(t, _)| mesh.triangle_material[t])
        .collect();
    let mut out = ShadedMesh {
        positions,
        indices,
        normals,
        uvs,
        triangle_material,
        ..mesh.clone()
    };
    (out.bounds_min, out.bounds_max) = bounds(&out.positions);
    Ok(out)
}

/// What to bake.
#[derive(Clone, Debug)]
pub struct BakeOptions {
    /// The OBJ file.
    pub model: PathBuf,
    /// A PNG to use as every material's texture (see [`obj::load_obj_shaded`]).
    pub texture: Option<PathBuf>,
    /// Texture side after resampling (see [`check_texture_size`]).
    pub texture_size: u32,
    /// Position format written.
    pub positions: PositionsArg,
    /// Decimate to at most this many triangles.
    pub max_triangles: Option<u32>,
}

/// Sizes and errors of a bake, for the summary.
#[derive(Clone, Debug, PartialEq)]
pub struct BakeReport {
    /// Rust module name (the file is `<name>.rs`).
    pub name: String,
    /// Vertices and triangles baked.
    pub vertices: usize,
    /// Triangles baked.
    pub triangles: usize,
    /// Triangles in the file before decimation.
    pub source_triangles: usize,
    /// Flash bytes of `POSITIONS` as f32.
    pub f32_position_bytes: usize,
    /// Flash bytes of `POSITIONS_I16` plus scale and offset.
    pub i16_position_bytes: usize,
    /// i16 against f32: largest per-vertex distance / bbox diagonal.
    pub i16_max_error: f64,
    /// i16 against f32: RMS per-vertex distance / bbox diagonal.
    pub i16_rms_error: f64,
    /// Bytes of `TEXTURE` (0 without one).
    pub texture_bytes: usize,
    /// Bytes of every array in the file, with the chosen position format.
    pub total_bytes: usize,
    /// Notes for stderr (the loader's repairs, a texture left out).
    pub notes: Vec<String>,
}

/// Module name for `model`: its stem, lower case, `[a-z0-9_]` only.
pub fn module_name(model: &Path) -> String {
    let stem = model
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    let mut name: String = stem
        .chars()
        .map(|c| {
            let c = c.to_ascii_lowercase();
            if c.is_ascii_alphanumeric() || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect();
    if name.is_empty() || name.starts_with(|c: char| c.is_ascii_digit()) {
        name.insert(0, 'm');
    }
    name
}

fn vec3_array(src: &mut String, name: &str, items: &[[f32; 3]]) {
    let _ = writeln!(
        src,
        "#[allow(clippy::approx_constant)]\npub static {name}: [microraster::Vec3; VERTEX_COUNT] = ["
    );
    for p in items {
        let _ = writeln!(
            src,
            "    microraster::Vec3::new({:?}, {:?}, {:?}),",
            p[0], p[1], p[2]
        );
    }
    src.push_str("];\n\n");
}

/// The baked source of `mesh` and its report (nothing is written).
pub fn bake_source(
    mesh: &ShadedMesh,
    name: &str,
    source_label: &str,
    opts: &BakeOptions,
) -> Result<(String, BakeReport), String> {
    let label = source_label;
    check_bakeable(mesh, label, opts)?;
    let decimated = decimated_as_asked(mesh, opts).map_err(|e| format!("{label}: {e}"))?;
    bake_decimated(
        decimated.as_ref().unwrap_or(mesh),
        mesh.indices.len(),
        name,
        label,
        opts,
    )
}

/// What [`bake_source`] refuses before it decimates: a texture size that
/// is not a power of two in range, and non-finite positions.
fn check_bakeable(mesh: &ShadedMesh, label: &str, opts: &BakeOptions) -> Result<(), String> {
    check_texture_size(opts.texture_size)?;
    let bad = mesh
        .positions
        .iter()
        .filter(|p| !p.iter().all(|c| c.is_finite()))
        .count();
    if bad > 0 {
        return Err(format!(
            "{label}: {bad} vertex positions are NaN or infinite; firmware data must be finite"
        ));
    }
    Ok(())
}

/// `mesh` decimated to `opts.max_triangles`, or `None` without a limit.
fn decimated_as_asked(mesh: &ShadedMesh, opts: &BakeOptions) -> Result<Option<ShadedMesh>, String> {
    opts.max_triangles
        .map(|n| decimate(mesh, n as usize))
        .transpose()
}

/// [`bake_source`] of a mesh already decimated (from `source_triangles`).
fn bake_decimated(
    mesh: &ShadedMesh,
    source_triangles: usize,
    name: &str,
    label: &str,
    opts: &BakeOptions,
) -> Result<(String, BakeReport), String> {
    if mesh.materials.len() > 256 {
        return Err(format!(
            "{label}: {} materials; a bake holds at most 256 (TRIANGLE_MATERIAL is u8)",
            mesh.materials.len()
        ));
    }
    let mut notes: Vec<String> = mesh.warnings.clone();

    // The one texture, if any.
    let mut textures: Vec<&TextureImage> = Vec::new();
    for m in &mesh.materials {
        if let Some(t) = &m.texture {
            if !textures.contains(&t) {
                textures.push(t);
            }
        }
    }
    if textures.len() > 1 {
        return Err(format!(
            "{label}: {} different textures; a bake holds one (use --texture to choose)",
            textures.len()
        ));
    }
    let texture = match (textures.first(), &mesh.uvs) {
        (Some(_), None) => {
            notes.push(format!(
                "{label}: has a texture but no texture coordinates (vt): texture left out"
            ));
            None
        }
        (t, _) => t.copied(),
    };

    let (n, m, k) = (
        mesh.positions.len(),
        mesh.indices.len(),
        mesh.materials.len(),
    );
    let quant = quantize_i16(&mesh.positions);
    let (i16_max_error, i16_rms_error) = quantization_error(&mesh.positions, &quant);
    let f32_position_bytes = n * 12;
    let i16_position_bytes = n * 6 + 24;
    let mut src = String::new();
    let _ = writeln!(
        src,
        "// Generated by `microraster bake` from {}: do not edit.\n\
         // {n} vertices, {m} triangles{}, {k} materials; positions {}.\n",
        opts.model
            .file_name()
            .map(|f| f.to_string_lossy())
            .unwrap_or_default(),
        if m < source_triangles {
            format!(" (decimated from {source_triangles})")
        } else {
            String::new()
        },
        match opts.positions {
            PositionsArg::F32 => "f32",
            PositionsArg::I16 => "i16",
        }
    );
    let _ = writeln!(
        src,
        "pub const VERTEX_COUNT: usize = {n};\npub const TRIANGLE_COUNT: usize = {m};\n\
         pub const MATERIAL_COUNT: usize = {k};\n"
    );
    let mut total = 0usize;
    match opts.positions {
        PositionsArg::F32 => {
            vec3_array(&mut src, "POSITIONS", &mesh.positions);
            total += f32_position_bytes;
        }
        PositionsArg::I16 => {
            let f3 = |v: [f32; 3]| format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2]);
            let _ = writeln!(
                src,
                "/// Dequantized position = q * POSITION_SCALE + POSITION_OFFSET, per axis.\n\
                 pub const POSITION_SCALE: [f32; 3] = {};\npub const POSITION_OFFSET: [f32; 3] = {};\n\n\
                 pub static POSITIONS_I16: [[i16; 3]; VERTEX_COUNT] = [",
                f3(quant.scale),
                f3(quant.offset)
            );
            for q in &quant.q {
                let _ = writeln!(src, "    [{}, {}, {}],", q[0], q[1], q[2]);
            }
            src.push_str("];\n\n");
            total += i16_position_bytes;
        }
    }
    src.push_str("pub static INDICES: [[u32; 3]; TRIANGLE_COUNT] = [\n");
    for t in &mesh.indices {
        let _ = writeln!(src, "    [{}, {}, {}],", t[0], t[1], t[2]);
    }
    src.push_str("];\n\n");
    total += m * 12;
    vec3_array(&mut src, "NORMALS", &mesh.normals);
    total += n * 12;
    if let Some(uvs) = &mesh.uvs {
        src.push_str(
            "/// (u, 1 - v) of the file's: texel (u * W, v * H), row 0 = top of the image.\n\
             #[allow(clippy::approx_constant)]\npub static UVS: [[f32; 2]; VERTEX_COUNT] = [\n",
        );
        for t in uvs {
            let _ = writeln!(src, "    [{:?}, {:?}],", t[0], 1.0 - t[1]);
        }
        src.push_str("];\n\n");
        total += n * 8;
    }
    let mut texture_bytes = 0;
    if let Some(tex) = texture {
        let s = opts.texture_size;
        let texels = resample_box(tex, s, s);
        let _ = writeln!(
            src,
            "/// Resampled from {}x{} (box filter); Rgb565, row 0 = top.\n\
             pub const TEXTURE_WIDTH: u32 = {s};\npub const TEXTURE_HEIGHT: u32 = {s};\n\
             pub static TEXTURE: [u16; {}] = [",
            tex.width,
            tex.height,
            s * s
        );
        for row in texels.chunks(16) {
            let words: Vec<String> = row
                .iter()
                .map(|&c| format!("0x{:04x}", rgb565(c)))
                .collect();
            let _ = writeln!(src, "    {},", words.join(", "));
        }
        src.push_str("];\n\n");
        texture_bytes = texels.len() * 2;
        total += texture_bytes;
        let flags: Vec<&str> = mesh
            .materials
            .iter()
            .map(|m| if m.texture.is_some() { "true" } else { "false" })
            .collect();
        let _ = writeln!(
            src,
            "/// Which materials sample TEXTURE (the others use MATERIAL_DIFFUSE alone).\n\
             pub static MATERIAL_TEXTURED: [bool; MATERIAL_COUNT] = [{}];\n",
            flags.join(", ")
        );
        total += k;
    }
    let u8c = |c: [f32; 3]| c.map(|x| (x.clamp(0.0, 1.0) * 255.0).round() as u8);
    src.push_str("/// Material names, in order:");
    for mat in &mesh.materials {
        let _ = write!(src, " {:?}", mat.name);
    }
    src.push_str(".\npub static MATERIAL_DIFFUSE: [[u8; 3]; MATERIAL_COUNT] = [\n");
    for mat in &mesh.materials {
        let c = u8c(mat.diffuse);
        let _ = writeln!(src, "    [{}, {}, {}],", c[0], c[1], c[2]);
    }
    src.push_str("];\n\npub static MATERIAL_SPECULAR: [[u8; 3]; MATERIAL_COUNT] = [\n");
    for mat in &mesh.materials {
        let c = u8c(mat.specular);
        let _ = writeln!(src, "    [{}, {}, {}],", c[0], c[1], c[2]);
    }
    src.push_str("];\n\npub static MATERIAL_SHININESS: [f32; MATERIAL_COUNT] = [");
    let sh: Vec<String> = mesh
        .materials
        .iter()
        .map(|m| format!("{:?}", m.shininess))
        .collect();
    src.push_str(&sh.join(", "));
    src.push_str("];\n\npub static TRIANGLE_MATERIAL: [u8; TRIANGLE_COUNT] = [\n");
    for row in mesh.triangle_material.chunks(32) {
        let ids: Vec<String> = row.iter().map(|i| i.to_string()).collect();
        let _ = writeln!(src, "    {},", ids.join(", "));
    }
    src.push_str("];\n");
    total += k * 10 + m;
    Ok((
        src,
        BakeReport {
            name: name.to_string(),
            vertices: n,
            triangles: m,
            source_triangles,
            f32_position_bytes,
            i16_position_bytes,
            i16_max_error,
            i16_rms_error,
            texture_bytes,
            total_bytes: total,
            notes,
        },
    ))
}

/// What `bake --clusters` wrote into `<model>_clusters.rs`.
#[derive(Clone, Debug, PartialEq)]
pub struct ClusterBakeReport {
    /// Clusters (meshlets).
    pub clusters: usize,
    /// Nodes of the tree, and how many of them are inner nodes.
    pub nodes: usize,
    /// Inner nodes.
    pub inner_nodes: usize,
    /// Entries of the vertex list.
    pub list_entries: usize,
    /// Bytes of the arrays: the reordered indices, clusters, nodes, list.
    pub bytes: usize,
}

/// An `f32` as a Rust expression that gives it back exactly (`{:?}`
/// round-trips finite values; the others are named).
pub fn f32_literal(x: f32) -> String {
    if x.is_finite() {
        format!("{x:?}")
    } else if x.is_nan() {
        "f32::NAN".to_string()
    } else if x > 0.0 {
        "f32::INFINITY".to_string()
    } else {
        "f32::NEG_INFINITY".to_string()
    }
}

/// The source of `<name>_clusters.rs` for `mesh` (decimated first as
/// `opts` says, like [`bake_source`], so it fits the model file): the
/// triangles in the order of [`cluster::build`] with the default
/// options (meshlets of at most 64 vertices and 12 triangles, the cost
/// model's tree with `t/r = 1`, shared vertices), over the model file's
/// own vertex numbering, and the [`ClusterSet`](microraster::ClusterSet)
/// arrays:
///
/// | item | type | what |
/// |---|---|---|
/// | `CLUSTER_INDICES` | `[[u32; 3]; TRIANGLE_COUNT]` | the model's triangles (same vertices) in cluster order |
/// | `CLUSTERS` | `[microraster::Cluster; K]` | runs of `CLUSTER_INDICES`, ranges of `CLUSTER_VERTICES` |
/// | `CLUSTER_NODES` | `[microraster::ClusterNode; L]` | the tree in pre-order |
/// | `CLUSTER_VERTICES` | `[u32; V]` | the vertex list (indices into the model's vertices) |
pub fn cluster_source(
    mesh: &ShadedMesh,
    name: &str,
    opts: &BakeOptions,
) -> Result<(String, ClusterBakeReport), String> {
    let decimated = decimated_as_asked(mesh, opts)?;
    cluster_decimated(decimated.as_ref().unwrap_or(mesh), name, opts)
}

/// [`cluster_source`] of a mesh already decimated.
fn cluster_decimated(
    mesh: &ShadedMesh,
    name: &str,
    opts: &BakeOptions,
) -> Result<(String, ClusterBakeReport), String> {
    let positions: Vec<microraster::Vec3> = mesh
        .positions
        .iter()
        .map(|p| microraster::Vec3::new(p[0], p[1], p[2]))
        .collect();
    let co = ClusterOptions::default();
    let c = cluster::build(&positions, &mesh.indices, &co)?;
    if c.indices.len() != mesh.indices.len() || c.source_vertex.len() != positions.len() {
        return Err(format!(
            "{name}: the clusters cover {} of {} triangles and {} of {} vertices",
            c.indices.len(),
            mesh.indices.len(),
            c.source_vertex.len(),
            positions.len()
        ));
    }
    // The build renumbers shared vertices by first use; the file keeps
    // the model's numbering, so map every index back.
    let back = |v: u32| c.source_vertex[v as usize];
    let (k, l, m, v) = (
        c.clusters.len(),
        c.nodes.len(),
        c.indices.len(),
        c.vertex_list.len(),
    );
    let mut src = String::new();
    let _ = writeln!(
        src,
        "// Generated by `microraster bake --clusters` from {}: do not edit.\n\
         // {m} triangles in {k} clusters (meshoptimizer meshlets of at most {} vertices and\n\
         // {} triangles), {l} nodes ({} inner, t/r = {}), {v} vertex list entries; the\n\
         // vertices are those of {name}.rs.\n",
        opts.model
            .file_name()
            .map(|f| f.to_string_lossy())
            .unwrap_or_default(),
        co.max_vertices,
        co.max_triangles,
        c.inner_nodes(),
        co.t_over_r,
    );
    let _ = writeln!(
        src,
        "pub const CLUSTER_COUNT: usize = {k};\npub const CLUSTER_NODE_COUNT: usize = {l};\n"
    );
    let _ = writeln!(
        src,
        "/// The model's triangles in cluster order (the same vertices).\n\
         pub static CLUSTER_INDICES: [[u32; 3]; {m}] = ["
    );
    for t in &c.indices {
        let t = t.map(back);
        let _ = writeln!(src, "    [{}, {}, {}],", t[0], t[1], t[2]);
    }
    src.push_str("];\n\n");
    let _ = writeln!(
        src,
        "/// Runs of `CLUSTER_INDICES` and their ranges of `CLUSTER_VERTICES`.\n\
         pub static CLUSTERS: [microraster::Cluster; CLUSTER_COUNT] = ["
    );
    for cl in &c.clusters {
        let _ = writeln!(
            src,
            "    microraster::Cluster {{ triangles: [{}, {}], vertices: [{}, {}] }},",
            cl.triangles[0], cl.triangles[1], cl.vertices[0], cl.vertices[1]
        );
    }
    src.push_str("];\n\n");
    let f = |x: f32| f32_literal(x);
    let f3 = |a: [f32; 3]| format!("[{}, {}, {}]", f(a[0]), f(a[1]), f(a[2]));
    let _ = writeln!(
        src,
        "/// The tree over `CLUSTERS`, in pre-order.\n\
         pub static CLUSTER_NODES: [microraster::ClusterNode; CLUSTER_NODE_COUNT] = ["
    );
    for n in &c.nodes {
        let (vol, cone, s) = (&n.volume, &n.cone, &n.sphere);
        let _ = writeln!(
            src,
            "    microraster::ClusterNode {{\n        clusters: [{}, {}],\n        skip: {},\n        \
             volume: microraster::cull::CullVolume {{ origin: {}, n_min: {}, n_max: {}, d_min: {}, d_max: {}, radius: {} }},\n        \
             cone: microraster::cull::NormalCone {{ apex: {}, axis: {}, cutoff: {} }},\n        \
             size: [{}, {}],\n        \
             sphere: microraster::BoundingSphere {{ center: microraster::Vec3::new({}, {}, {}), radius: {} }},\n    }},",
            n.clusters[0],
            n.clusters[1],
            n.skip,
            f3(vol.origin),
            f3(vol.n_min),
            f3(vol.n_max),
            f(vol.d_min),
            f(vol.d_max),
            f(vol.radius),
            f3(cone.apex),
            f3(cone.axis),
            f(cone.cutoff),
            f(n.size[0]),
            f(n.size[1]),
            f(s.center.x),
            f(s.center.y),
            f(s.center.z),
            f(s.radius),
        );
    }
    src.push_str("];\n\n");
    let _ = writeln!(
        src,
        "/// The vertices each cluster uses (indices into the model's vertices).\n\
         pub static CLUSTER_VERTICES: [u32; {v}] = ["
    );
    for row in c.vertex_list.chunks(16) {
        let ids: Vec<String> = row.iter().map(|&i| back(i).to_string()).collect();
        let _ = writeln!(src, "    {},", ids.join(", "));
    }
    src.push_str("];\n");
    let bytes = m * 12 + c.data_bytes() + v * 4;
    Ok((
        src,
        ClusterBakeReport {
            clusters: k,
            nodes: l,
            inner_nodes: c.inner_nodes(),
            list_entries: v,
            bytes,
        },
    ))
}

/// The source of `<name>_classes.rs` for `mesh` (already decimated as
/// the model file is): the normal classes of
/// [`normal_mask::build`](crate::normal_mask::build) with `partitions` a
/// side, over the model file's triangles in their order, as the arrays of
/// a [`microraster::NormalClasses`]:
///
/// | item | type | what |
/// |---|---|---|
/// | `PARTITIONS` | `u8` | partitions a side of the direction cube |
/// | `CLASSES` | `[u16; TRIANGLE_COUNT]` | each triangle's class (or `NO_CLASS`) |
/// | `CLASS_SIZES` | `[[f32; 2]; 6 N^2]` | per class, its triangles' size bounds |
/// | `CLASS_SPHERES` | `[microraster::BoundingSphere; 6 N^2]` | per class, a sphere around its triangles |
///
/// Firmware that reorders the triangles reorders `CLASSES` with them.
pub fn classes_source(
    mesh: &ShadedMesh,
    name: &str,
    opts: &BakeOptions,
    partitions: u8,
) -> Result<String, String> {
    let positions: Vec<microraster::Vec3> = mesh
        .positions
        .iter()
        .map(|p| microraster::Vec3::new(p[0], p[1], p[2]))
        .collect();
    let data = crate::normal_mask::build(&positions, &mesh.indices, partitions)?;
    let (m, k) = (data.classes.len(), data.sizes.len());
    let mut src = String::new();
    let _ = writeln!(
        src,
        "// Generated by `microraster bake --normal-masks {partitions}` from {}: do not edit.\n\
         // The normal classes of the {m} triangles of {name}.rs, in their order, on a direction\n\
         // cube of {partitions} partitions a side ({k} classes).\n",
        opts.model
            .file_name()
            .map(|f| f.to_string_lossy())
            .unwrap_or_default(),
    );
    let _ = writeln!(
        src,
        "pub const PARTITIONS: u8 = {partitions};\npub const CLASS_COUNT: usize = {k};\n"
    );
    let _ = writeln!(
        src,
        "/// Each triangle's class.\npub static CLASSES: [u16; {m}] = ["
    );
    for line in data.classes.chunks(16) {
        let items: Vec<String> = line.iter().map(u16::to_string).collect();
        let _ = writeln!(src, "    {},", items.join(", "));
    }
    src.push_str("];\n\n");
    let f = |x: f32| f32_literal(x);
    let _ = writeln!(
        src,
        "/// Per class, its triangles' size bounds.\n\
         pub static CLASS_SIZES: [[f32; 2]; CLASS_COUNT] = ["
    );
    for z in &data.sizes {
        let _ = writeln!(src, "    [{}, {}],", f(z[0]), f(z[1]));
    }
    src.push_str("];\n\n");
    let _ = writeln!(
        src,
        "/// Per class, a sphere around its triangles.\n\
         pub static CLASS_SPHERES: [microraster::BoundingSphere; CLASS_COUNT] = ["
    );
    for b in &data.spheres {
        let c = b.center;
        let _ = writeln!(
            src,
            "    microraster::BoundingSphere {{ center: microraster::Vec3::new({}, {}, {}), radius: {} }},",
            f(c.x),
            f(c.y),
            f(c.z),
            f(b.radius)
        );
    }
    src.push_str("];\n");
    Ok(src)
}

/// Bakes `opts.model` into `out_dir/<model>.rs` (the folder is created if
/// missing), all or nothing. Returns the report and the file written.
pub fn bake(opts: &BakeOptions, out_dir: &Path) -> Result<(BakeReport, PathBuf), String> {
    let (report, _, mut paths) = bake_files(opts, false, None, out_dir)?;
    Ok((report, paths.remove(0)))
}

/// [`bake`], and with `clusters` also `out_dir/<model>_clusters.rs`
/// ([`cluster_source`]), with `masks` (partitions a side) also
/// `out_dir/<model>_classes.rs` ([`classes_source`]): every file or
/// none. Returns the reports and the files written, the model's first.
pub fn bake_files(
    opts: &BakeOptions,
    clusters: bool,
    masks: Option<u8>,
    out_dir: &Path,
) -> Result<(BakeReport, Option<ClusterBakeReport>, Vec<PathBuf>), String> {
    check_texture_size(opts.texture_size)?;
    let mesh = obj::load_obj_shaded(&opts.model, opts.texture.as_deref())?;
    let name = module_name(&opts.model);
    let label = opts.model.display().to_string();
    // Checked and decimated once for both files.
    check_bakeable(&mesh, &label, opts)?;
    let decimated = decimated_as_asked(&mesh, opts).map_err(|e| format!("{label}: {e}"))?;
    let baked = decimated.as_ref().unwrap_or(&mesh);
    let (src, report) = bake_decimated(baked, mesh.indices.len(), &name, &label, opts)?;
    let clustered = if clusters {
        Some(cluster_decimated(baked, &name, opts).map_err(|e| format!("{label}: {e}"))?)
    } else {
        None
    };
    let classes = match masks {
        Some(n) => {
            Some(classes_source(baked, &name, opts, n).map_err(|e| format!("{label}: {e}"))?)
        }
        None => None,
    };
    std::fs::create_dir_all(out_dir).map_err(|e| {
        format!(
            "{}: cannot create the output folder: {e}",
            out_dir.display()
        )
    })?;
    let path = out_dir.join(format!("{name}.rs"));
    let cluster_path = out_dir.join(format!("{name}_clusters.rs"));
    let classes_path = out_dir.join(format!("{name}_classes.rs"));
    let mut outputs = vec![Output {
        option: "--out",
        path: &path,
        payload: Payload::Raw(src.as_bytes()),
    }];
    if let Some((csrc, _)) = &clustered {
        outputs.push(Output {
            option: "--out",
            path: &cluster_path,
            payload: Payload::Raw(csrc.as_bytes()),
        });
    }
    if let Some(csrc) = &classes {
        outputs.push(Output {
            option: "--out",
            path: &classes_path,
            payload: Payload::Raw(csrc.as_bytes()),
        });
    }
    output::write_all(&outputs)?;
    let mut paths = vec![path.clone()];
    if clustered.is_some() {
        paths.push(cluster_path.clone());
    }
    if classes.is_some() {
        paths.push(classes_path.clone());
    }
    Ok((report, clustered.map(|(_, r)| r), paths))
}

/// `microraster bake`: bakes and prints the summary.
pub fn run(args: &BakeArgs) -> Result<(), String> {
    let opts = BakeOptions {
        model: args.model.clone(),
        texture: args.texture.clone(),
        texture_size: args.texture_size,
        positions: args.positions,
        max_triangles: args.max_triangles,
    };
    let (r, clusters, paths) = bake_files(&opts, args.clusters, args.normal_masks, &args.out)?;
    for note in &r.notes {
        eprintln!("microraster: warning: {note}");
    }
    for path in &paths {
        println!("wrote {}", path.display());
    }
    if r.triangles < r.source_triangles {
        println!(
            "{} vertices, {} triangles (decimated from {})",
            r.vertices, r.triangles, r.source_triangles
        );
    } else {
        println!("{} vertices, {} triangles", r.vertices, r.triangles);
    }
    println!("positions f32: {} bytes (exact)", r.f32_position_bytes);
    println!(
        "positions i16: {} bytes; error vs f32: max {:.3e}, RMS {:.3e} of the bounding box diagonal",
        r.i16_position_bytes, r.i16_max_error, r.i16_rms_error
    );
    if r.texture_bytes > 0 {
        println!(
            "texture {0}x{0} Rgb565: {1} bytes",
            args.texture_size, r.texture_bytes
        );
    }
    let chosen = match args.positions {
        PositionsArg::F32 => "f32",
        PositionsArg::I16 => "i16",
    };
    println!("total baked: {} bytes (positions {chosen})", r.total_bytes);
    if let Some(c) = clusters {
        println!(
            "clusters: {} clusters, {} nodes ({} inner), {} vertex list entries: {} bytes with the reordered indices",
            c.clusters, c.nodes, c.inner_nodes, c.list_entries, c.bytes
        );
    }
    Ok(())
}
