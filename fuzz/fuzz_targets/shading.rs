//! Every shading (`N` = 3, 5, 6, 8; colours, lit colours, textures,
//! Phong) over one mesh with arbitrary normals, uvs, colours, texture and
//! lights: ids, depth and counters independent of shading, strip renderers
//! equal to the frame (see `microraster_fuzz::shading`).
#![no_main]

use libfuzzer_sys::fuzz_target;
use microraster_fuzz::{run_shading, ShadeInput};

fuzz_target!(|input: ShadeInput| run_shading(&input));
