//! The clipless mode on arbitrary input: no panic, no write outside the
//! rows, any split the same (see `microraster_fuzz::clipless`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use microraster_fuzz::{clipless::run_clipless, Input};

fuzz_target!(|input: Input| run_clipless(&input));
