//! `StripRenderer` against `Frame::render_rows` on arbitrary input (see
//! `microraster_fuzz::run_strip_renderer`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use microraster_fuzz::{run_strip_renderer, FrameInput};

fuzz_target!(|input: FrameInput| run_strip_renderer(&input));
