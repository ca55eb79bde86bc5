//! Occlusion culling: honest and arbitrary bounds and tile counts,
//! arbitrary matrices, strips and depth tests (see
//! `microraster_fuzz::occlusion`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use microraster_fuzz::{run_occlusion, OcclusionInput};

fuzz_target!(|input: OcclusionInput| run_occlusion(&input));
