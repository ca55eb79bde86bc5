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
use crate::cli::{CullArg, DepthArg, RenderArgs, Source};
use crate::cliptris;
use crate::image_out;
use crate::obj;
use crate::output::{self, Output, Payload};
use crate::render::{self, Counters, DepthKind, RenderOptions, Rendered, Timings};
use crate::scene::{self, Scene, View};
use microraster::CullMode;
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
    /// Rows per strip.
    pub strip_rows: u32,
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
    }
}

/// Builds the scene `args` ask for.
pub fn load_scene(args: &RenderArgs) -> Result<Scene, String> {
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

/// Checks what can be checked before rendering.
fn check_args(args: &RenderArgs) -> Result<(), String> {
    image_out::image_format(&args.out)?;
    if args.depth == DepthArg::None && args.depth_out.is_some() {
        return Err("--depth-out needs a depth buffer, but --depth is none: \
                    use --depth u16 or u32, or drop --depth-out"
            .to_string());
    }
    let mut paths: Vec<(&str, &Path)> = vec![("--out", &args.out)];
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
    check_args(args)?;
    let scene = load_scene(args)?;
    let opts = RenderOptions {
        width: args.width(),
        height: args.height(),
        cull: match args.cull {
            CullArg::Back => CullMode::Back,
            CullArg::Front => CullMode::Front,
            CullArg::None => CullMode::None,
        },
        depth: match args.depth {
            DepthArg::U16 => DepthKind::U16,
            DepthArg::U32 => DepthKind::U32,
            DepthArg::None => DepthKind::None,
        },
        subpixel: args.subpixel,
        threads: args.threads,
        strip_rows: args.strip_rows,
        ids: args.id_out.is_some(),
    };
    let r = render::render(&scene, &opts)?;

    let ids_rgba: Option<Vec<u8>> = r
        .ids
        .as_ref()
        .map(|ids| ids.iter().flat_map(|i| i.to_le_bytes()).collect());
    let depth_bytes = r.depth.to_le_bytes();
    let mut outputs = vec![Output {
        option: "--out",
        path: &args.out,
        payload: Payload::Rgb {
            format: image_out::image_format(&args.out)?,
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

    for w in warnings(&r) {
        eprintln!("microraster: warning: {w}");
    }
    let checksum = format!("{:016x}", r.checksum());
    if args.stats {
        let stats = RenderStats {
            width: r.width,
            height: r.height,
            threads: opts.threads,
            strip_rows: opts.strip_rows,
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
        args.out.display(),
        r.width,
        r.height,
        r.stats.submitted,
        r.pixels_written
    );
    Ok(())
}
