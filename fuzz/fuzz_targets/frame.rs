//! Frame setup and rendering from arbitrary input: submissions through
//! every `Submit` path, `Frame::clear`, strip splits, bins, wrong calls,
//! every pixel format (see `microraster_fuzz::run_frame`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use microraster_fuzz::{run_frame, Input};

fuzz_target!(|input: Input| run_frame(&input));
