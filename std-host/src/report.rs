//! `microraster report`: not written yet.

use clap::Args;

/// Options of `microraster report`.
#[derive(Args, Debug, Clone, PartialEq)]
pub struct ReportArgs {
    /// Which report.
    pub which: String,
}

/// Writes the report.
pub fn run(_args: &ReportArgs) -> Result<(), String> {
    Err("report is not implemented yet".into())
}
