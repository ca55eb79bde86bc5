//! `microraster`: render scenes with the microraster core on all cores.
//!
//! `microraster render` draws the default four-cubes scene to `cubes.png`;
//! see `microraster render --help` for meshes, clip-space triangle files,
//! threads, strips, depth formats and debug outputs. Errors print one line
//! and exit with status 1 (2 for bad arguments, from clap).

use clap::Parser;
use microraster::CullMode;
use microraster_host::cli::{Cli, Command, CullArg, DepthArg, RenderArgs, Source};
use microraster_host::json::JsonObject;
use microraster_host::render::{self, DepthKind, RenderOptions, Scene};
use microraster_host::{bench_scenes, cliptris, cubes, image_out, obj};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => run_render(&args),
        Command::Bench(args) => microraster_host::bench::run(&args),
        Command::Report(args) => microraster_host::report::run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("microraster: error: {e}");
            ExitCode::FAILURE
        }
    }
}

fn load_scene(args: &RenderArgs) -> Result<Scene, String> {
    match args.source() {
        Source::Scene(name) => {
            // Built-in scenes keep their own camera (and, for the sphere, its
            // 45° field of view) unless --eye or --target is given.
            let custom = args.eye.is_some() || args.target.is_some();
            let view = bench_scenes::View {
                width: args.width(),
                height: args.height(),
                eye: args.eye,
                target: args.target,
                fov: custom.then_some(args.fov),
            };
            Ok(bench_scenes::builtin(&name, &view)?.scene)
        }
        Source::Obj(path) => {
            let mesh = obj::load_obj(&path)?;
            let (eye, target) = match (args.eye, args.target) {
                (Some(e), Some(t)) => (e, t),
                (e, t) => {
                    let (fe, ft) = obj::frame_camera(&mesh, args.fov, args.aspect());
                    (e.unwrap_or(fe), t.unwrap_or(ft))
                }
            };
            Ok(render::mesh_scene(
                &mesh.positions,
                &mesh.indices,
                eye,
                target,
                args.fov,
                args.aspect(),
            ))
        }
        Source::ClipTris(path) => Ok(render::clip_tris_scene(cliptris::load_clip_tris(&path)?)),
    }
}

fn run_render(args: &RenderArgs) -> Result<(), String> {
    // Validate output paths before doing any work.
    image_out::image_format(&args.out)?;
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
    image_out::write_rgb(&args.out, r.width, r.height, &r.rgb)?;
    if let (Some(path), Some(ids)) = (&args.id_out, &r.ids) {
        let rgba: Vec<u8> = ids.iter().flat_map(|i| i.to_le_bytes()).collect();
        image_out::write_rgba_png(path, r.width, r.height, &rgba)?;
    }
    if let Some(path) = &args.depth_out {
        image_out::write_raw(path, &r.depth.to_le_bytes())?;
    }
    if args.checksum {
        println!("{:016x}", r.checksum());
    }
    if args.stats {
        let s = r.stats;
        let mut counters = microraster_host::bench::counters(&s);
        counters.field_u64("pixels_written", r.pixels_written);
        let mut timings = JsonObject::new();
        timings
            .field_f64("setup_ms", r.timings.setup_ms)
            .field_f64("raster_ms", r.timings.raster_ms)
            .field_f64("ids_ms", r.timings.ids_ms);
        let mut top = JsonObject::new();
        top.field_u64("width", r.width as u64)
            .field_u64("height", r.height as u64)
            .field_u64("threads", opts.threads as u64)
            .field_u64("strip_rows", opts.strip_rows as u64)
            .field_u64("subpixel_bits", opts.subpixel as u64)
            .field_str("checksum", &format!("{:016x}", r.checksum()))
            .field_obj("counters", &counters)
            .field_obj("timings", &timings);
        println!("{}", top.to_pretty_string());
    } else if !args.checksum {
        eprintln!(
            "microraster: wrote {} ({}x{}, {} triangles, {} pixels)",
            args.out.display(),
            r.width,
            r.height,
            r.stats.submitted,
            r.pixels_written
        );
    }
    let _ = cubes::CUBES_EYE;
    Ok(())
}
