//! Writing a command's outputs all or nothing.
//!
//! Design note: a render can have up to three outputs (`--out`, `--id-out`,
//! `--depth-out`). [`check_paths`] runs before any work: every output must
//! have an existing directory, and no two may name the same file. Paths are
//! compared by identity, not by spelling: the directory is canonicalized
//! (symlinks, `.` and `..` resolved) and joined with the file name, and an
//! existing file is canonicalized itself, so `./a.png`, `dir/../a.png` and
//! a symlink to `a.png` all collide with `a.png`. (A case-insensitive file
//! system is not detected.) [`write_all`] encodes every output into a
//! temporary file beside its target (`.NAME.PID.N.tmp`, so the rename stays
//! on one file system and is atomic), and renames them only once every one
//! of them was written; on any failure the temporary files are removed and
//! no target is touched. The `tempfile` crate would give random names but
//! add `rustix` and three more crates to the default build; a name made of
//! the process id is unique enough for files that live a few milliseconds.

use crate::image_out::{self, ImageFormat};
use std::path::{Path, PathBuf};

/// What one output holds.
#[derive(Clone, Copy, Debug)]
pub enum Payload<'a> {
    /// An RGB8 image in `format`.
    Rgb {
        /// PNG or PPM.
        format: ImageFormat,
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// `width * height * 3` bytes.
        data: &'a [u8],
    },
    /// An RGBA8 PNG.
    RgbaPng {
        /// Width in pixels.
        width: u32,
        /// Height in pixels.
        height: u32,
        /// `width * height * 4` bytes.
        data: &'a [u8],
    },
    /// Bytes written unchanged.
    Raw(&'a [u8]),
}

/// One file to write.
#[derive(Clone, Copy, Debug)]
pub struct Output<'a> {
    /// The option that named it, for messages (`--out`).
    pub option: &'static str,
    /// Where it goes.
    pub path: &'a Path,
    /// What goes there.
    pub payload: Payload<'a>,
}

/// The file `path` names: its canonical directory joined with its name, or
/// the canonical path itself if it exists. Errors if the directory does not
/// exist or `path` is a directory.
pub fn identity(path: &Path) -> Result<PathBuf, String> {
    let name = path
        .file_name()
        .ok_or_else(|| format!("{}: not a file name", path.display()))?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let dir = dir.canonicalize().map_err(|e| {
        format!(
            "{}: cannot write there: directory {}: {e}",
            path.display(),
            dir.display()
        )
    })?;
    let full = dir.join(name);
    if full.is_dir() {
        return Err(format!("{}: is a directory", path.display()));
    }
    Ok(full.canonicalize().unwrap_or(full))
}

/// Checks that every `(option, path)` can be written and that no two name
/// the same file.
pub fn check_paths(paths: &[(&str, &Path)]) -> Result<(), String> {
    let mut seen: Vec<(&str, &Path, PathBuf)> = Vec::new();
    for &(option, path) in paths {
        let id = identity(path)?;
        if let Some((other, other_path, _)) = seen.iter().find(|(_, _, i)| *i == id) {
            return Err(format!(
                "{option} {} and {other} {} are the same file: give each output its own path",
                path.display(),
                other_path.display()
            ));
        }
        seen.push((option, path, id));
    }
    Ok(())
}

fn temp_path(path: &Path, n: usize) -> PathBuf {
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy())
        .unwrap_or_default();
    let tmp = format!(".{name}.{}.{n}.tmp", std::process::id());
    match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.join(tmp),
        _ => PathBuf::from(tmp),
    }
}

fn write_one(path: &Path, payload: &Payload<'_>) -> Result<(), String> {
    match *payload {
        Payload::Rgb {
            format,
            width,
            height,
            data,
        } => image_out::write_rgb_as(path, format, width, height, data),
        Payload::RgbaPng {
            width,
            height,
            data,
        } => image_out::write_rgba_png(path, width, height, data),
        Payload::Raw(data) => image_out::write_raw(path, data),
    }
}

/// Writes every output, or none: each to a temporary file first, then all
/// renamed into place. Errors name the target path.
pub fn write_all(outputs: &[Output<'_>]) -> Result<(), String> {
    let paths: Vec<(&str, &Path)> = outputs.iter().map(|o| (o.option, o.path)).collect();
    check_paths(&paths)?;
    let mut staged: Vec<PathBuf> = Vec::new();
    let remove = |staged: &[PathBuf]| {
        for t in staged {
            let _ = std::fs::remove_file(t);
        }
    };
    for (n, o) in outputs.iter().enumerate() {
        let tmp = temp_path(o.path, n);
        if let Err(e) = write_one(&tmp, &o.payload) {
            let _ = std::fs::remove_file(&tmp);
            remove(&staged);
            // Name the target, not the temporary file.
            let e = e.replace(&tmp.display().to_string(), &o.path.display().to_string());
            return Err(format!("{e} (no output was written)"));
        }
        staged.push(tmp);
    }
    for (n, (o, tmp)) in outputs.iter().zip(&staged).enumerate() {
        if let Err(e) = std::fs::rename(tmp, o.path) {
            remove(&staged[n..]);
            return Err(format!(
                "{}: cannot move the finished file into place: {e}",
                o.path.display()
            ));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn same_file_by_other_spellings_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.png");
        let sub = dir.path().join("sub");
        std::fs::create_dir(&sub).unwrap();
        let b = sub.join("..").join("a.png");
        let e = check_paths(&[("--out", &a), ("--id-out", &b)]).unwrap_err();
        assert!(e.contains("same file"), "{e}");
        assert!(check_paths(&[("--out", &a), ("--id-out", &sub.join("a.png"))]).is_ok());
        // An existing file and a symlink to it.
        std::fs::write(&a, b"x").unwrap();
        #[cfg(unix)]
        {
            let link = dir.path().join("link.png");
            std::os::unix::fs::symlink(&a, &link).unwrap();
            assert!(check_paths(&[("--out", &a), ("--id-out", &link)]).is_err());
        }
        assert!(check_paths(&[("--out", &sub)]).is_err());
        assert!(check_paths(&[("--out", &dir.path().join("no/x.png"))]).is_err());
    }

    #[test]
    fn nothing_is_written_unless_everything_is() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.raw");
        let b = dir.path().join("b.png");
        let bad = Payload::RgbaPng {
            width: 2,
            height: 2,
            data: &[0; 3],
        };
        let outs = [
            Output {
                option: "--out",
                path: &a,
                payload: Payload::Raw(b"abc"),
            },
            Output {
                option: "--id-out",
                path: &b,
                payload: bad,
            },
        ];
        assert!(write_all(&outs).is_err());
        let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
        assert!(left.is_empty(), "{left:?}");
        write_all(&outs[..1]).unwrap();
        assert_eq!(std::fs::read(&a).unwrap(), b"abc");
    }
}
