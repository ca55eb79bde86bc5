//! `microraster`: render scenes with the microraster core on all cores.
//!
//! `microraster render` draws the default four-cubes scene to `cubes.png`;
//! see `microraster render --help` for meshes, clip-space triangles,
//! threads, strips, depth formats and debug outputs. Errors print one line
//! and exit with status 1 (2 for bad arguments, from clap). This file only
//! dispatches: [`microraster_host::cli`] parses, the command modules run.

use clap::Parser;
use microraster_host::cli::{Cli, Command};
use std::process::ExitCode;

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Render(args) => microraster_host::render_cmd::run(&args),
        Command::Bench(args) => microraster_host::bench::run(&args),
        #[cfg(feature = "report")]
        Command::Report(args) => microraster_host::report::run(&args),
        #[cfg(not(feature = "report"))]
        Command::Report(_) => Err(microraster_host::NO_REPORT.to_string()),
        Command::Bake(args) => microraster_host::bake::run(&args),
        Command::Cull(args) => microraster_host::cull_cmd::run(&args),
        Command::BakeHouse(args) => microraster_host::portal::bake_run(&args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("microraster: error: {e}");
            ExitCode::FAILURE
        }
    }
}
