//! `microraster bench`: not written yet.

use clap::Args;

/// Options of `microraster bench`.
#[derive(Args, Debug, Clone, PartialEq)]
pub struct BenchArgs {
    /// Frames to render.
    #[arg(long, default_value_t = 10)]
    pub frames: u32,
}

/// Runs the benchmark.
pub fn run(_args: &BenchArgs) -> Result<(), String> {
    Err("bench is not implemented yet".into())
}
