//! Parser for the `--clip-tris` text format.
//!
//! Design: one triangle per line, given directly in clip space so that the
//! rasterizer's clipping and rejection paths can be driven without a camera.
//! A line holds 12 numbers (`x y z w` of each of the three vertices) and
//! optionally 3 more, an `r g b` colour as integers 0–255. `#` starts a comment
//! anywhere on a line; blank and comment-only lines are skipped. Coordinates
//! are parsed with Rust's `f32` parser, so `nan`, `inf`, `-inf`, `infinity`
//! and huge values such as `1e38` (or `1e39`, which rounds to infinity) are
//! accepted on purpose: deciding what to do with them is the renderer's job
//! (it counts them as rejected). Errors name the 1-based line number and say
//! what is wrong.

use std::path::Path;

/// One clip-space triangle from a `--clip-tris` file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClipTri {
    /// Clip-space `[x, y, z, w]` of the three vertices, in file order.
    pub v: [[f32; 4]; 3],
    /// Optional flat colour.
    pub color: Option<[u8; 3]>,
}

/// Parses the text of a `--clip-tris` file.
pub fn parse_clip_tris(text: &str) -> Result<Vec<ClipTri>, String> {
    let mut tris = Vec::new();
    for (index, raw_line) in text.lines().enumerate() {
        let line_no = index + 1;
        if let Some(tri) = parse_line(raw_line).map_err(|e| format!("line {line_no}: {e}"))? {
            tris.push(tri);
        }
    }
    Ok(tris)
}

/// Reads and parses a `--clip-tris` file; errors name the path.
pub fn load_clip_tris(path: &Path) -> Result<Vec<ClipTri>, String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read clip-space triangles: {e}", path.display()))?;
    parse_clip_tris(&text).map_err(|e| format!("{}: {e}", path.display()))
}

/// Parses one line; `Ok(None)` for a blank or comment-only line.
fn parse_line(line: &str) -> Result<Option<ClipTri>, String> {
    let content = match line.find('#') {
        Some(pos) => &line[..pos],
        None => line,
    };
    let tokens: Vec<&str> = content.split_whitespace().collect();
    if tokens.is_empty() {
        return Ok(None);
    }
    if tokens.len() != 12 && tokens.len() != 15 {
        return Err(format!(
            "expected 12 numbers (x y z w of 3 vertices) or 15 (followed by r g b), found {}",
            tokens.len()
        ));
    }
    let mut v = [[0.0f32; 4]; 3];
    for (i, token) in tokens[..12].iter().enumerate() {
        v[i / 4][i % 4] = token.parse::<f32>().map_err(|_| {
            format!(
                "cannot parse {token:?} as a number (vertex {}, component {})",
                i / 4,
                ["x", "y", "z", "w"][i % 4]
            )
        })?;
    }
    let color = if tokens.len() == 15 {
        let mut rgb = [0u8; 3];
        for (i, token) in tokens[12..].iter().enumerate() {
            let name = ["r", "g", "b"][i];
            let value: i64 = token.parse().map_err(|_| {
                format!("colour component {name} = {token:?} is not an integer in 0..=255")
            })?;
            rgb[i] = u8::try_from(value).map_err(|_| {
                format!("colour component {name} = {value} is out of range 0..=255")
            })?;
        }
        Some(rgb)
    } else {
        None
    };
    Ok(Some(ClipTri { v, color }))
}

#[cfg(test)]
mod tests {
    use super::*;
    use tempfile::TempDir;

    fn write_file(dir: &TempDir, name: &str, text: &str) -> std::path::PathBuf {
        let p = dir.path().join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    const TRI: &str = "0 0 0 1  1 0 0 1  0 1 0 1";

    #[test]
    fn plain_and_coloured_lines() {
        let text = format!("{TRI}\n{TRI} 255 0 17\n");
        let tris = parse_clip_tris(&text).unwrap();
        assert_eq!(tris.len(), 2);
        assert_eq!(
            tris[0].v,
            [
                [0.0, 0.0, 0.0, 1.0],
                [1.0, 0.0, 0.0, 1.0],
                [0.0, 1.0, 0.0, 1.0]
            ]
        );
        assert_eq!(tris[0].color, None);
        assert_eq!(tris[1].color, Some([255, 0, 17]));
    }

    #[test]
    fn comments_blank_lines_and_crlf() {
        let text = format!(
            "# header comment\n\n   \t\n{TRI} # trailing comment 1 2 3\r\n{TRI} 1 2 3#tight\n#{TRI}\n"
        );
        let tris = parse_clip_tris(&text).unwrap();
        assert_eq!(tris.len(), 2);
        assert_eq!(tris[0].color, None);
        assert_eq!(tris[1].color, Some([1, 2, 3]));
        assert!(parse_clip_tris("").unwrap().is_empty());
        assert!(parse_clip_tris("# only\n\n").unwrap().is_empty());
    }

    #[test]
    fn special_floats_parse() {
        let text = "nan inf -inf 1e38  NaN +inf infinity -1e39  -0 1.5e-45 .5 5.\n";
        let t = parse_clip_tris(text).unwrap()[0];
        assert!(t.v[0][0].is_nan());
        assert_eq!(t.v[0][1], f32::INFINITY);
        assert_eq!(t.v[0][2], f32::NEG_INFINITY);
        assert_eq!(t.v[0][3], 1e38);
        assert!(t.v[1][0].is_nan());
        assert_eq!(t.v[1][1], f32::INFINITY);
        assert_eq!(t.v[1][2], f32::INFINITY);
        assert_eq!(t.v[1][3], f32::NEG_INFINITY);
        assert!(t.v[2][0] == 0.0 && t.v[2][0].is_sign_negative());
        assert!(t.v[2][1] > 0.0);
        assert_eq!(t.v[2][2], 0.5);
        assert_eq!(t.v[2][3], 5.0);
    }

    #[test]
    fn wrong_count_names_the_line() {
        let text = format!("{TRI}\n\n1 2 3\n");
        let e = parse_clip_tris(&text).unwrap_err();
        assert!(e.starts_with("line 3:"), "{e}");
        assert!(
            e.contains("12") && e.contains("15") && e.contains("found 3"),
            "{e}"
        );
        for n in [11, 13, 14, 16] {
            let line = vec!["1"; n].join(" ");
            let e = parse_clip_tris(&line).unwrap_err();
            assert!(
                e.starts_with("line 1:") && e.contains(&format!("found {n}")),
                "{e}"
            );
        }
    }

    #[test]
    fn bad_tokens_are_errors() {
        let e = parse_clip_tris(&format!("{TRI}\n0 0 0 1 1 0 zero 1 0 1 0 1\n")).unwrap_err();
        assert!(e.starts_with("line 2:") && e.contains("\"zero\""), "{e}");
        let e = parse_clip_tris("0,0 0 0 1 1 0 0 1 0 1 0 1").unwrap_err();
        assert!(e.contains("\"0,0\""), "{e}");
    }

    #[test]
    fn colour_range_is_checked() {
        let e = parse_clip_tris(&format!("{TRI} 0 256 0")).unwrap_err();
        assert!(
            e.starts_with("line 1:") && e.contains("256") && e.contains("range"),
            "{e}"
        );
        let e = parse_clip_tris(&format!("{TRI} -1 0 0")).unwrap_err();
        assert!(e.contains("-1") && e.contains("range"), "{e}");
        let e = parse_clip_tris(&format!("{TRI} 1.5 0 0")).unwrap_err();
        assert!(e.contains("1.5") && e.contains("integer"), "{e}");
        let e = parse_clip_tris(&format!("{TRI} 99999999999999999999999 0 0")).unwrap_err();
        assert!(e.contains("integer"), "{e}");
    }

    #[test]
    fn load_from_file() {
        let dir = TempDir::new().unwrap();
        let ok = write_file(&dir, "ok.txt", &format!("{TRI} 10 20 30\n"));
        assert_eq!(load_clip_tris(&ok).unwrap()[0].color, Some([10, 20, 30]));
        let bad = write_file(&dir, "bad.txt", "1 2\n");
        let e = load_clip_tris(&bad).unwrap_err();
        assert!(e.contains("bad.txt") && e.contains("line 1"), "{e}");
        let e = load_clip_tris(&dir.path().join("missing.txt")).unwrap_err();
        assert!(e.contains("missing.txt"), "{e}");
    }
}
