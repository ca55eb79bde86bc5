//! Portal culling: arbitrary cells, portals, boxes, matrices, start cells
//! and rectangle slices (see `microraster_fuzz::portal`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use microraster_fuzz::{run_portal, PortalInput};

fuzz_target!(|input: PortalInput| run_portal(&input));
