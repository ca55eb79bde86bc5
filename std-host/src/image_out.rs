//! Image and raw-buffer output for the host binary.
//!
//! Design: the renderer hands us tightly packed 8-bit buffers (RGB for the
//! colour image, RGBA for the triangle-id image). The file format of the colour
//! image is chosen from the path's extension (`.png` or `.ppm`, case
//! insensitive); anything else is refused up front so that a long render does
//! not end in an unwritable file. PNG goes through the `png` crate; PPM is the
//! binary `P6` variant written by hand. Every failure is reported as a
//! `String` naming the path; buffer sizes are checked (with overflow-checked
//! arithmetic) before anything is written, so a mismatch never leaves a
//! truncated file behind.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

/// Largest width or height accepted for an output image (matches `--size`).
pub const MAX_DIMENSION: u32 = 16384;

/// File format of a colour image, chosen by extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// Portable Network Graphics, 8-bit RGB.
    Png,
    /// Binary portable pixmap (`P6`), 8-bit RGB.
    Ppm,
}

/// Picks the image format from the extension of `path` (case-insensitive).
///
/// Returns an error naming the allowed extensions for anything other than
/// `.png` or `.ppm`.
pub fn image_format(path: &Path) -> Result<ImageFormat, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    match ext.as_deref() {
        Some("png") => Ok(ImageFormat::Png),
        Some("ppm") => Ok(ImageFormat::Ppm),
        _ => Err(format!(
            "{}: unsupported image file extension (allowed: .png, .ppm)",
            path.display()
        )),
    }
}

/// Checks dimensions and that `len == width * height * channels`.
fn check_buffer(
    path: &Path,
    width: u32,
    height: u32,
    channels: u64,
    len: usize,
) -> Result<(), String> {
    if width == 0 || height == 0 || width > MAX_DIMENSION || height > MAX_DIMENSION {
        return Err(format!(
            "{}: image size {width}x{height} is invalid (each side must be 1..={MAX_DIMENSION})",
            path.display()
        ));
    }
    let expected = u64::from(width)
        .checked_mul(u64::from(height))
        .and_then(|n| n.checked_mul(channels));
    match expected {
        Some(n) if u64::try_from(len).ok() == Some(n) => Ok(()),
        Some(n) => Err(format!(
            "{}: buffer holds {len} bytes but a {width}x{height} image with {channels} \
             channels needs {n}",
            path.display()
        )),
        None => Err(format!(
            "{}: image size {width}x{height} overflows",
            path.display()
        )),
    }
}

fn create(path: &Path) -> Result<BufWriter<File>, String> {
    File::create(path)
        .map(BufWriter::new)
        .map_err(|e| format!("{}: cannot create file: {e}", path.display()))
}

fn write_png(
    path: &Path,
    width: u32,
    height: u32,
    color: png::ColorType,
    data: &[u8],
) -> Result<(), String> {
    let err = |e: png::EncodingError| format!("{}: PNG encoding failed: {e}", path.display());
    let file = create(path)?;
    let mut encoder = png::Encoder::new(file, width, height);
    encoder.set_color(color);
    encoder.set_depth(png::BitDepth::Eight);
    let mut writer = encoder.write_header().map_err(err)?;
    writer.write_image_data(data).map_err(err)?;
    writer.finish().map_err(err)
}

fn write_ppm(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), String> {
    let err = |e: std::io::Error| format!("{}: write failed: {e}", path.display());
    let mut file = create(path)?;
    write!(file, "P6\n{width} {height}\n255\n").map_err(err)?;
    file.write_all(rgb).map_err(err)?;
    file.flush().map_err(err)
}

/// Writes a tightly packed 8-bit RGB image (`width * height * 3` bytes, rows
/// top to bottom) as PNG or binary PPM, chosen by the extension of `path`.
pub fn write_rgb(path: &Path, width: u32, height: u32, rgb: &[u8]) -> Result<(), String> {
    write_rgb_as(path, image_format(path)?, width, height, rgb)
}

/// [`write_rgb`] in `format`, whatever the extension of `path` (for a
/// temporary file that is renamed afterwards).
pub fn write_rgb_as(
    path: &Path,
    format: ImageFormat,
    width: u32,
    height: u32,
    rgb: &[u8],
) -> Result<(), String> {
    check_buffer(path, width, height, 3, rgb.len())?;
    match format {
        ImageFormat::Png => write_png(path, width, height, png::ColorType::Rgb, rgb),
        ImageFormat::Ppm => write_ppm(path, width, height, rgb),
    }
}

/// Writes a tightly packed 8-bit RGBA image (`width * height * 4` bytes) as
/// PNG, whatever the extension of `path` (used for the triangle-id image).
pub fn write_rgba_png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<(), String> {
    check_buffer(path, width, height, 4, rgba.len())?;
    write_png(path, width, height, png::ColorType::Rgba, rgba)
}

/// Writes `bytes` to `path` unchanged (used for the raw depth buffer).
pub fn write_raw(path: &Path, bytes: &[u8]) -> Result<(), String> {
    std::fs::write(path, bytes).map_err(|e| format!("{}: write failed: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use tempfile::TempDir;

    fn read_png(path: &Path) -> (png::OutputInfo, Vec<u8>) {
        let bytes = std::fs::read(path).unwrap();
        let decoder = png::Decoder::new(std::io::Cursor::new(bytes));
        let mut reader = decoder.read_info().unwrap();
        let mut buf = vec![0; reader.output_buffer_size().unwrap()];
        let info = reader.next_frame(&mut buf).unwrap();
        buf.truncate(info.buffer_size());
        (info, buf)
    }

    fn pattern(len: usize) -> Vec<u8> {
        (0..len).map(|i| (i * 37 % 251) as u8).collect()
    }

    #[test]
    fn format_by_extension() {
        assert_eq!(image_format(Path::new("a.png")), Ok(ImageFormat::Png));
        assert_eq!(image_format(Path::new("dir/a.PNG")), Ok(ImageFormat::Png));
        assert_eq!(image_format(Path::new("a.Ppm")), Ok(ImageFormat::Ppm));
        for bad in ["a.jpg", "a", "png", "a.png.gz", ".png"] {
            let e = image_format(Path::new(bad)).unwrap_err();
            assert!(e.contains(".png") && e.contains(".ppm"), "{bad}: {e}");
        }
    }

    #[test]
    fn png_rgb_round_trip() {
        let dir = TempDir::new().unwrap();
        let path = dir.path().join("out.png");
        let data = pattern(5 * 3 * 3);
        write_rgb(&path, 5, 3, &data).unwrap();
        let (info, back) = read_png(&path);
        assert_eq!((info.width, info.height), (5, 3));
        assert_eq!(info.color_type, png::ColorType::Rgb);
        assert_eq!(info.bit_depth, png::BitDepth::Eight);
        assert_eq!(back, data);
    }

    #[test]
    fn png_rgba_round_trip() {
        let dir = TempDir::new().unwrap();
        let path = dir.path().join("ids.png");
        let data = pattern(4 * 7 * 4);
        write_rgba_png(&path, 4, 7, &data).unwrap();
        let (info, back) = read_png(&path);
        assert_eq!((info.width, info.height), (4, 7));
        assert_eq!(info.color_type, png::ColorType::Rgba);
        assert_eq!(back, data);
    }

    #[test]
    fn ppm_header_and_body() {
        let dir = TempDir::new().unwrap();
        let path = dir.path().join("out.PPM");
        let data = pattern(2 * 3 * 3);
        write_rgb(&path, 2, 3, &data).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let header = b"P6\n2 3\n255\n";
        assert_eq!(&bytes[..header.len()], header);
        assert_eq!(&bytes[header.len()..], &data[..]);
    }

    #[test]
    fn raw_round_trip() {
        let dir = TempDir::new().unwrap();
        let path = dir.path().join("depth.bin");
        let data = pattern(100);
        write_raw(&path, &data).unwrap();
        assert_eq!(std::fs::read(&path).unwrap(), data);
    }

    #[test]
    fn size_mismatch_is_an_error_and_writes_nothing() {
        let dir = TempDir::new().unwrap();
        let path = dir.path().join("bad.png");
        let e = write_rgb(&path, 4, 4, &[0; 47]).unwrap_err();
        assert!(e.contains("47") && e.contains("48"), "{e}");
        assert!(!path.exists());
        let e = write_rgba_png(&path, 4, 4, &[0; 48]).unwrap_err();
        assert!(e.contains("64"), "{e}");
        let ppm = dir.path().join("bad.ppm");
        assert!(write_rgb(&ppm, 2, 2, &[0; 13]).is_err());
        assert!(!ppm.exists());
    }

    #[test]
    fn bad_dimensions_and_extension_are_errors() {
        let dir = TempDir::new().unwrap();
        assert!(write_rgb(&dir.path().join("a.png"), 0, 4, &[]).is_err());
        assert!(write_rgb(&dir.path().join("a.png"), 4, 0, &[]).is_err());
        assert!(write_rgb(&dir.path().join("a.ppm"), MAX_DIMENSION + 1, 1, &[]).is_err());
        assert!(write_rgba_png(&dir.path().join("a.png"), u32::MAX, u32::MAX, &[]).is_err());
        let e = write_rgb(&dir.path().join("a.bmp"), 1, 1, &[0; 3]).unwrap_err();
        assert!(e.contains("a.bmp"), "{e}");
    }

    #[test]
    fn unwritable_path_is_an_error() {
        let dir = TempDir::new().unwrap();
        let path = dir.path().join("no/such/dir/x.png");
        let e = write_rgb(&path, 1, 1, &[1, 2, 3]).unwrap_err();
        assert!(e.contains("x.png"), "{e}");
        assert!(write_raw(&dir.path().join("no/such/raw.bin"), &[1]).is_err());
    }
}
