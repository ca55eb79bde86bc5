//! Frame setup and strip rendering from arbitrary vertices, matrices, frame
//! sizes and row ranges (see `microraster_fuzz::run_frame`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use microraster_fuzz::{run_frame, FrameInput};

fuzz_target!(|input: FrameInput| run_frame(&input));
