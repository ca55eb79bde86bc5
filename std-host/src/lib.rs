//! Host-side (std) support code for the `microraster` command-line renderer.
//!
//! Design: everything here is plain data and plain functions that do not
//! depend on the core crate's types, so the modules can be tested on their
//! own: command-line definitions ([`cli`]), Wavefront OBJ loading and camera
//! framing ([`obj`]), the `--clip-tris` text format ([`cliptris`]), image
//! output ([`image_out`]), a small JSON writer for statistics ([`json`]) and
//! the default "cubes" scene ([`cubes`]). Bad input is reported as
//! `Err(String)` with a message meant for the user; nothing here panics on
//! input data.

#![forbid(unsafe_code)]

pub mod bench;
pub mod bench_scenes;
pub mod cli;
pub mod cliptris;
pub mod image_out;
pub mod json;
pub mod obj;
pub mod peers;
pub mod pipeline;
pub mod reference;
pub mod render;
pub mod report;

/// The default scene's data, from the shared no_std scenes crate.
pub use microraster_scenes::cubes;

#[cfg(test)]
pub(crate) mod test_util {
    //! Scratch directories for tests, removed on drop.

    use std::path::{Path, PathBuf};
    use std::sync::atomic::{AtomicU32, Ordering};

    static COUNTER: AtomicU32 = AtomicU32::new(0);

    /// A fresh, uniquely named directory under the system temp dir.
    pub struct TempDir(PathBuf);

    impl TempDir {
        pub fn new(tag: &str) -> Self {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let path = std::env::temp_dir().join(format!(
                "microraster-host-test-{}-{tag}-{n}",
                std::process::id()
            ));
            let _ = std::fs::remove_dir_all(&path);
            std::fs::create_dir_all(&path).expect("create temp dir");
            TempDir(path)
        }

        pub fn path(&self) -> &Path {
            &self.0
        }

        /// Writes `text` to `name` inside the directory and returns its path.
        pub fn write(&self, name: &str, text: &str) -> PathBuf {
            let p = self.0.join(name);
            std::fs::write(&p, text).expect("write temp file");
            p
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }
}
