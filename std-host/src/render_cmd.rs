//! `microraster render`: one image from a scene, an OBJ mesh or clip-space
//! triangles, and what the user should know about it.
//!
//! Design note: the command never lies. Everything that can be refused is
//! refused before any work: camera options for a source with no camera (the
//! quad and `--clip-tris`), `--depth-out` without a depth buffer, two
//! outputs naming the same file, an output in a missing directory, an empty
//! `--clip-tris` file (as an empty `--obj` is). After the render, an image
//! with no pixel written, or triangles dropped as non-finite or out of
//! range, is reported on stderr with the core's counters. All outputs are
//! written together or not at all ([`crate::output`]). Stdout holds only
//! what was asked for: one JSON document with `--stats` (the checksum inside
//! it), else the checksum line with `--checksum`; the "wrote ..." line goes
//! to stderr.

use crate::bench_scenes;
use crate::cli::{CullArg, DepthArg, FilterArg, RenderArgs, ShadingArg, Source};
use crate::cliptris;
use crate::image_out;
use crate::obj;
use crate::output::{self, Output, Payload};
use crate::render::{self, Counters, DepthKind, RenderOptions, Rendered, Timings};
use crate::scene::{self, Scene, View};
use crate::shaded::{self, Camera, ShadedModel, ShadingMode, ShadingOptions, TextureData};
use microraster::pixelcolor::Rgb888;
use microraster::shade::Material;
use microraster::{CullMode, Vec3};
use serde::Serialize;
use std::path::Path;

/// Why camera options are refused for `--clip-tris`.
pub const NO_CAMERA_CLIP_TRIS: &str = "--clip-tris triangles are given in clip space and have \
     no camera: --eye, --target and --fov do not apply to them";

/// The JSON of `render --stats`.
#[derive(Debug, Serialize)]
pub struct RenderStats {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Worker threads.
    pub threads: usize,
    /// Rows per strip (or tile).
    pub strip_rows: u32,
    /// Tile width, or `null` for strips.
    pub tile_width: Option<u32>,
    /// Sub-pixel bits.
    pub subpixel_bits: u32,
    /// FNV-1a of the RGB8 bytes, as `--checksum` prints it.
    pub checksum: String,
    /// The core's counters and the pixels written.
    pub counters: RenderCounters,
    /// Stage times.
    pub timings: Timings,
}

/// [`Counters`] plus the pixels written.
#[derive(Debug, Serialize)]
pub struct RenderCounters {
    /// The core's counters.
    #[serde(flatten)]
    pub core: Counters,
    /// Pixels written into the colour image.
    pub pixels_written: u64,
}

fn view_of(args: &RenderArgs) -> View {
    View {
        width: args.width(),
        height: args.height(),
        eye: args.eye,
        target: args.target,
        fov: args.fov,
        inv_w: args.depth_kind == crate::cli::DepthKindArg::InvW,
        portals: args.portals,
    }
}

/// Builds the scene `args` ask for.
pub fn load_scene(args: &RenderArgs) -> Result<Scene, String> {
    let mut scene = load_source(args)?;
    if let Some(c) = args.cull_clusters {
        let opts = crate::cluster::ClusterOptions::default();
        crate::cluster::cluster_scene(&mut scene, c.cull(), &opts)?;
    }
    if let Some(n) = args.normal_masks {
        crate::normal_mask::mask_scene(&mut scene, n)?;
    }
    if args.cull_detail_boxes {
        crate::scene::detail_boxes(&mut scene);
    }
    Ok(scene)
}

fn load_source(args: &RenderArgs) -> Result<Scene, String> {
    let view = view_of(args);
    match args.source() {
        Source::Scene(name) => Ok(bench_scenes::builtin(&name, &view)?.scene),
        Source::Obj(path) => {
            let mesh = obj::load_obj(&path)?;
            let fov = args.fov.unwrap_or(60.0);
            let (eye, target) = match (args.eye, args.target) {
                (Some(e), Some(t)) => (e, t),
                (e, t) => {
                    let (fe, ft) = obj::frame_camera(&mesh, fov, args.aspect());
                    (e.unwrap_or(fe), t.unwrap_or(ft))
                }
            };
            scene::mesh_scene(
                &mesh.positions,
                &mesh.indices,
                eye,
                target,
                fov,
                args.aspect(),
                view.inv_w,
            )
        }
        Source::ClipTris(path) => {
            if view.has_camera() {
                return Err(NO_CAMERA_CLIP_TRIS.to_string());
            }
            let tris = cliptris::load_clip_tris(&path)?;
            if tris.is_empty() {
                return Err(format!(
                    "{}: no triangles (only blank or comment lines)",
                    path.display()
                ));
            }
            Ok(scene::clip_tris_scene(tris))
        }
    }
}

/// The OBJ model at `path`, lit and textured as its file says (see
/// [`shaded`]), with the loader's warnings.
pub fn load_model(
    path: &Path,
    texture: Option<&Path>,
) -> Result<(ShadedModel, obj::ShadedMesh, Vec<String>), String> {
    let mesh = obj::load_obj_shaded(path, texture)?;
    let mut notes = Vec::new();
    // A model with UVs and no texture named anywhere: a PNG beside it
    // named after it (`spot.obj`: `spot.png` or `spot_texture.png`).
    let mut beside = None;
    if texture.is_none() && mesh.uvs.is_some() && mesh.materials.iter().all(|m| m.texture.is_none())
    {
        if let Some(t) = beside_texture(path) {
            let image = obj::load_png_rgb(&t)?;
            notes.push(format!(
                "{}: its material names no texture; using {} (found beside it by name)",
                path.display(),
                t.display()
            ));
            beside = Some(image);
        }
    }
    let v = Vec3::from_array;
    let to_rgb = |c: [f32; 3]| {
        let q = |x: f32| (x.clamp(0.0, 1.0) * 255.0 + 0.5) as u8;
        Rgb888::new(q(c[0]), q(c[1]), q(c[2]))
    };
    let material_of = |t: usize| {
        mesh.triangle_material
            .get(t)
            .and_then(|&m| mesh.materials.get(m as usize))
    };
    // A texture: the first material's that has one (one texture per
    // model; textured triangles of other materials use it too).
    let texture = mesh
        .materials
        .iter()
        .find_map(|m| m.texture.as_ref())
        .or(beside.as_ref())
        .map(|t| TextureData {
            width: t.width,
            height: t.height,
            texels: t
                .rgb
                .iter()
                .map(|c| Rgb888::new(c[0], c[1], c[2]))
                .collect(),
        });
    // Textured materials show the texture as it is (Kd is a tint).
    let diffuse = (0..mesh.indices.len())
        .map(|t| material_of(t).map_or(Rgb888::new(204, 204, 204), |m| to_rgb(m.diffuse)))
        .collect();
    // One highlight for the model: the strongest material's, or a soft
    // default for files without an MTL.
    let material = match mesh
        .materials
        .iter()
        .filter(|m| m.specular.iter().any(|&c| c > 0.0))
        .max_by(|a, b| a.specular[0].total_cmp(&b.specular[0]))
    {
        Some(m) => Material {
            specular: m.specular,
            shininess: m.shininess.round().clamp(1.0, 1024.0) as u16,
        },
        None if mesh
            .materials
            .iter()
            .all(|m| m.name == obj::DEFAULT_MATERIAL_NAME) =>
        {
            Material {
                specular: DEFAULT_SPECULAR,
                shininess: DEFAULT_SHININESS,
            }
        }
        None => Material::MATTE,
    };
    let model = ShadedModel {
        positions: mesh.positions.iter().map(|&p| v(p)).collect(),
        indices: mesh.indices.clone(),
        normals: mesh.normals.iter().map(|&n| v(n)).collect(),
        // The file's v points up; the core's row 0 is the texture's top.
        uvs: mesh
            .uvs
            .as_ref()
            .map(|uv| uv.iter().map(|t| [t[0], 1.0 - t[1]]).collect()),
        diffuse,
        texture,
        material,
    };
    Ok((model, mesh, notes))
}

/// `DIR/STEM.png` or `DIR/STEM_texture.png` beside the OBJ file, if one
/// exists.
fn beside_texture(obj: &Path) -> Option<std::path::PathBuf> {
    let stem = obj.file_stem()?.to_string_lossy().into_owned();
    let dir = obj.parent().unwrap_or(Path::new(""));
    [format!("{stem}.png"), format!("{stem}_texture.png")]
        .into_iter()
        .map(|n| dir.join(n))
        .find(|p| p.is_file())
}

/// The highlight of a model without an MTL file.
pub const DEFAULT_SPECULAR: [f32; 3] = [0.25; 3];

/// Its exponent.
pub const DEFAULT_SHININESS: u16 = 32;

/// Renders the OBJ model at `path`; returns the render and the loader's
/// warnings.
fn render_obj(
    args: &RenderArgs,
    path: &Path,
    opts: &RenderOptions,
) -> Result<(Rendered, Vec<String>), String> {
    let (model, mesh, notes) = load_model(path, args.texture.as_deref())?;
    for n in &notes {
        eprintln!("microraster: {n}");
    }
    let fov = args.fov.unwrap_or(60.0);
    let (eye, target) = match (args.eye, args.target) {
        (Some(e), Some(t)) => (e, t),
        (e, t) => {
            let (fe, ft) = obj::frame_camera_front(&mesh.to_loaded(), fov, args.aspect());
            (e.unwrap_or(fe), t.unwrap_or(ft))
        }
    };
    let camera = Camera {
        eye,
        target,
        fov_y_deg: fov,
    };
    let shading = ShadingOptions {
        mode: match args.shading {
            ShadingArg::Flat => ShadingMode::Flat,
            ShadingArg::Gouraud => ShadingMode::Gouraud,
            ShadingArg::Phong => ShadingMode::Phong,
        },
        light: args.light.unwrap_or(shaded::DEFAULT_LIGHT),
        texture: !args.no_texture,
        bilinear: args.texture_filter == FilterArg::Bilinear,
    };
    let r = shaded::render_shaded(&model, &camera, opts, &shading)?;
    Ok((r, mesh.warnings))
}

/// Checks what can be checked before rendering.
fn check_args(args: &RenderArgs, out: &Path) -> Result<(), String> {
    image_out::image_format(out)?;
    if args.has_shading_options() && !matches!(args.source(), Source::Obj(_)) {
        return Err(
            "--shading, --light, --texture, --no-texture and --texture-filter apply to \
                    --obj models only (the built-in scenes and --clip-tris carry \
                    their own colours)"
                .to_string(),
        );
    }
    if args.depth == DepthArg::None && args.depth_out.is_some() {
        return Err("--depth-out needs a depth buffer, but --depth is none: \
                    use --depth u16 or u32, or drop --depth-out"
            .to_string());
    }
    let mut paths: Vec<(&str, &Path)> = vec![("--out", out)];
    if let Some(p) = &args.id_out {
        paths.push(("--id-out", p));
    }
    if let Some(p) = &args.depth_out {
        paths.push(("--depth-out", p));
    }
    output::check_paths(&paths)
}

/// The counters that are not zero, as `name N, ...`.
fn nonzero(c: &Counters) -> String {
    let all = [
        ("outside the view (whole object culled)", c.culled_object),
        ("outside the view", c.culled_frustum),
        (
            "back-facing (or front-facing with --cull front)",
            c.culled_backface,
        ),
        ("back-facing cluster (before transform)", c.culled_cluster),
        (
            "back-facing cluster tree node (before transform)",
            c.culled_hierarchy,
        ),
        (
            "object or cluster below --cull-detail pixels (before transform)",
            c.culled_detail,
        ),
        (
            "box pieces drawn for them (--cull-detail-boxes)",
            c.detail_boxes,
        ),
        ("back-facing normal class (before transform)", c.culled_mask),
        (
            "hidden behind the strip's hi-z (before transform, per strip)",
            c.culled_occlusion,
        ),
        (
            "in rooms no door shows (portals, never submitted)",
            c.culled_portal,
        ),
        ("degenerate", c.culled_degenerate),
        ("non-finite", c.rejected_nonfinite),
        ("index out of range", c.rejected_index),
        ("clipped", c.clipped),
        ("stored", c.stored),
    ];
    let parts: Vec<String> = all
        .iter()
        .filter(|(_, n)| *n > 0)
        .map(|(what, n)| format!("{n} {what}"))
        .collect();
    if parts.is_empty() {
        "none".to_string()
    } else {
        parts.join(", ")
    }
}

/// Warnings about the render `r`: no pixel written, triangles dropped.
pub fn warnings(r: &Rendered) -> Vec<String> {
    let c = Counters::from(&r.stats);
    let mut out = Vec::new();
    let dropped = c.rejected_nonfinite + c.rejected_index;
    if dropped > 0 {
        out.push(format!(
            "{dropped} of {} triangles dropped: {} with a non-finite or out-of-range \
             coordinate (rejected_nonfinite), {} with a vertex index out of range \
             (rejected_index)",
            c.submitted, c.rejected_nonfinite, c.rejected_index
        ));
    }
    if r.pixels_written == 0 {
        out.push(format!(
            "the image is empty: no triangle wrote a pixel ({} submitted; {})",
            c.submitted,
            nonzero(&c)
        ));
    }
    out
}

/// Runs `microraster render`.
pub fn run(args: &RenderArgs) -> Result<(), String> {
    let out = args.out_path();
    check_args(args, &out)?;
    let opts = RenderOptions {
        width: args.width(),
        height: args.height(),
        cull: match args.cull {
            CullArg::Back => CullMode::Back,
            CullArg::Front => CullMode::Front,
            CullArg::None => CullMode::None,
        },
        detail: args.cull_detail,
        depth: match args.depth {
            DepthArg::U16 => DepthKind::U16,
            DepthArg::U32 => DepthKind::U32,
            DepthArg::F32 => DepthKind::F32,
            DepthArg::None => DepthKind::None,
        },
        subpixel: args.subpixel,
        threads: args.threads,
        strip_rows: args.tile.map_or(args.strip_rows, |t| t.1),
        tile_width: args.tile.map_or(0, |t| t.0),
        ids: args.id_out.is_some(),
        mode: match args.mode {
            crate::cli::ModeArg::Clipping => microraster::RasterMode::Clipping,
            crate::cli::ModeArg::Clipless => microraster::RasterMode::Clipless,
        },
        inv_w: args.depth_kind == crate::cli::DepthKindArg::InvW,
        occlusion: if args.occlusion {
            crate::render::Occlusion::On
        } else {
            crate::render::Occlusion::Off
        },
    };
    if opts.inv_w {
        if args.depth == DepthArg::None {
            return Err(
                "--depth-kind inv-w needs a depth buffer (--depth u16, u32 or f32)".to_string(),
            );
        }
        match args.source() {
            Source::Scene(_) => {}
            Source::Obj(_) => {}
            Source::ClipTris(_) => {
                return Err(
                    "--depth-kind inv-w needs a camera: --clip-tris gives its own clip-space z"
                        .to_string(),
                )
            }
        }
    }
    if args.portals && !matches!(args.source(), Source::Scene(ref n) if n == "house") {
        return Err("--portals needs a scene with rooms and doors: --scene house".to_string());
    }
    if args.portals && args.id_out.is_some() {
        return Err(
            "--id-out with --portals would number only the rooms drawn; render the ids without --portals"
                .to_string(),
        );
    }
    let (r, load_warnings) = match args.source() {
        Source::Obj(_) if args.normal_masks.is_some() => {
            return Err(
                "--normal-masks is not yet supported with --obj (lit models); \
                 use --scene, or `microraster bench --obj FILE --normal-masks N`"
                    .into(),
            )
        }
        Source::Obj(_) if args.cull_clusters.is_some() => {
            return Err(
                "--cull-clusters is not yet supported with --obj (lit models); \
                 use --scene, or `microraster bench --obj FILE --cull-clusters TEST`"
                    .to_string(),
            )
        }
        Source::Obj(path) => render_obj(args, &path, &opts)?,
        _ => {
            let mut r = render::render(&load_scene(args)?, &opts)?;
            // Rooms skipped by portal culling were never submitted: counted
            // as submitted and culled, as the core counts its own skips.
            if let (true, Source::Scene(name)) = (args.portals, args.source()) {
                if name == "house" {
                    let (_, report) = crate::portal::house_scene(&view_of(args))?;
                    r.stats.submitted += report.triangles;
                    r.stats.culled_portal += report.triangles;
                }
            }
            (r, Vec::new())
        }
    };

    let ids_rgba: Option<Vec<u8>> = r
        .ids
        .as_ref()
        .map(|ids| ids.iter().flat_map(|i| i.to_le_bytes()).collect());
    let depth_bytes = r.depth.to_le_bytes();
    let mut outputs = vec![Output {
        option: "--out",
        path: &out,
        payload: Payload::Rgb {
            format: image_out::image_format(&out)?,
            width: r.width,
            height: r.height,
            data: &r.rgb,
        },
    }];
    if let (Some(path), Some(rgba)) = (&args.id_out, &ids_rgba) {
        outputs.push(Output {
            option: "--id-out",
            path,
            payload: Payload::RgbaPng {
                width: r.width,
                height: r.height,
                data: rgba,
            },
        });
    }
    if let Some(path) = &args.depth_out {
        outputs.push(Output {
            option: "--depth-out",
            path,
            payload: Payload::Raw(&depth_bytes),
        });
    }
    output::write_all(&outputs)?;

    for w in load_warnings.iter().chain(&warnings(&r)) {
        eprintln!("microraster: warning: {w}");
    }
    let checksum = format!("{:016x}", r.checksum());
    if args.stats {
        let stats = RenderStats {
            width: r.width,
            height: r.height,
            threads: opts.threads,
            strip_rows: opts.strip_rows,
            tile_width: (opts.tile_width > 0 && opts.tile_width < r.width)
                .then_some(opts.tile_width),
            subpixel_bits: opts.subpixel,
            checksum,
            counters: RenderCounters {
                core: Counters::from(&r.stats),
                pixels_written: r.pixels_written,
            },
            timings: r.timings,
        };
        let text = serde_json::to_string_pretty(&stats).map_err(|e| e.to_string())?;
        println!("{text}");
    } else if args.checksum {
        println!("{checksum}");
    }
    let also: String = outputs[1..]
        .iter()
        .map(|o| format!(", {} {}", o.option, o.path.display()))
        .collect();
    eprintln!(
        "microraster: wrote {} ({}x{}, {} triangles, {} pixels{also})",
        out.display(),
        r.width,
        r.height,
        r.stats.submitted,
        r.pixels_written
    );
    Ok(())
}
