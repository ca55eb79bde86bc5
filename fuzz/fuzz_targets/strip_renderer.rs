//! `StripRenderer` (whole window and any split) and `StripDrawer` against
//! `Frame::render_rows` on arbitrary input (see
//! `microraster_fuzz::run_strip_renderer`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use microraster_fuzz::{run_strip_renderer, Input};

fuzz_target!(|input: Input| run_strip_renderer(&input));
