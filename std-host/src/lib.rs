//! Host-side (std) support code for the `microraster` command-line renderer.
//!
//! Design: data flows one way. [`cli`] parses and validates the command
//! line; the command modules consume what it made and never reach back:
//! [`render_cmd`] (`render`), [`bench`](mod@bench) (`bench`), [`bake`]
//! (`bake`) and, with the `report` feature, `report` (`report
//! speed-vs-error`). Below them:
//!
//! | module | what |
//! |---|---|
//! | [`scene`] | scenes as plain data, cameras (up-vector choice) |
//! | [`bench_scenes`] | the built-in scenes (cubes, sphere, bunny, quad) |
//! | [`obj`] | Wavefront OBJ loading (errors with file and line), framing |
//! | [`bake`] | `bake`: a model as Rust source for firmware |
//! | [`cliptris`] | the `--clip-tris` text format |
//! | [`pipeline`] | setup into binned core frames, threaded strip drawing |
//! | [`render`] | one image from a scene, counters, checksum |
//! | [`shaded`] | one lit, textured model (`render --obj`): the core's shading types |
//! | [`output`] | every output staged in a temporary file, then renamed |
//! | [`image_out`] | PNG / PPM / raw encoders |
//!
//! `scene` sits below `pipeline`, which sits below `render`; `cli` depends
//! only on `image_out` (for path checks). The peers of `bench --peers`
//! (`peers` feature) and the report (`report` feature) are out of the
//! default build. Bad input is reported as `Err(String)` with a message
//! meant for the user; nothing here panics on input data.

#![forbid(unsafe_code)]

pub mod bake;
pub mod bench;
pub mod bench_scenes;
pub mod cli;
pub mod cliptris;
pub mod cluster;
pub mod normal_mask;
pub mod cull_cmd;
pub mod image_out;
pub mod obj;
pub mod occlusion;
pub mod output;
pub mod pipeline;
pub mod portal;
pub mod render;
pub mod render_cmd;
#[cfg(feature = "report")]
pub mod report;
pub mod scene;
pub mod shaded;

/// The default scene's data, from the shared no_std scenes crate.
pub use microraster_scenes::cubes;

/// The error for `report` in a build without the `report` feature.
pub const NO_REPORT: &str = "the report needs the `report` feature, which this binary was \
     built without: rebuild with `--features report` (e.g. `cargo run --release -p \
     microraster-host --features report -- report speed-vs-error OUT_DIR`)";
