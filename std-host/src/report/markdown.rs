//! The report's Markdown: tables by configuration and scene, the Pareto
//! front, and the unexplained differences, if any.
//!
//! Design note: plain `format!` into a `String`; the text is the report's
//! output, so nothing here measures anything.

use super::*;

pub(crate) fn sci(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else {
        format!("{v:.1e}")
    }
}

/// The report's markdown.
pub fn markdown(info: &RunInfo, summary: &[Summary], rows: &[Row]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Speed against error\n");
    let _ = writeln!(
        s,
        "{}x{} pixels, one thread, median of {} frames per cell; errors against the `f64` \
         reference renderer (`std-host/src/reference.rs`). Written by \
         `microraster report speed-vs-error`.\n",
        info.width, info.height, info.reps
    );
    let _ = writeln!(s, "## By configuration (all scenes together)\n");
    let _ = writeln!(
        s,
        "| configuration | frame time, sum (ms) | pixels differing | coverage only | \
         unexplained | depth max (LSB) | depth beyond bound | depth vs exact, mean | \
         depth vs exact, max | colour max (LSB) | colour beyond bound | matrix error (rel.) | \
         vertex error (px) |"
    );
    let _ = writeln!(s, "|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|");
    let front = pareto_front(
        &summary
            .iter()
            .map(|r| (r.time_ms, r.id_diff_pct))
            .collect::<Vec<_>>(),
    );
    for (i, r) in summary.iter().enumerate() {
        let mark = if front.contains(&i) { " ★" } else { "" };
        let _ = writeln!(
            s,
            "| {}{} | {:.2} | {:.3} % | {:.3} % | {} | {:.0} | {} | {} | {} | {:.0} | {} | {} | {} |",
            r.config.label(),
            mark,
            r.time_ms,
            r.id_diff_pct,
            r.coverage_diff_pct,
            r.unexplained,
            r.depth_max_lsb,
            r.depth_beyond,
            sci(r.depth_mean_abs),
            sci(r.depth_max_abs),
            r.color_max,
            r.color_beyond,
            sci(r.matrix_rel),
            sci(r.vertex_px),
        );
    }
    let _ = writeln!(
        s,
        "\n★ on the Pareto front of frame time against pixels differing.\n"
    );
    let _ = writeln!(s, "## By scene\n");
    let _ = writeln!(
        s,
        "| scene | configuration | time (ms) | covered | differing | coverage only | \
         unexplained | depth max (LSB) | depth mean (LSB) | depth beyond | colour max | \
         colour mean | colour beyond | matrix err | clip err (rel. w) | vertex err (px) | \
         vertex err (z) |"
    );
    let _ = writeln!(
        s,
        "|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"
    );
    for r in rows {
        let e = &r.errors;
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {} | {} | {} | {} | {:.0} | {:.2} | {} | {:.0} | {:.3} | {} | \
             {} | {} | {} | {} |",
            r.scene,
            r.config.label(),
            r.time_ms,
            e.covered,
            e.id_diff,
            e.coverage_diff,
            e.unexplained,
            e.depth_max_lsb,
            e.depth_mean_lsb,
            e.depth_beyond,
            e.color_max,
            e.color_mean,
            e.color_beyond,
            sci(r.vertex.matrix_rel),
            sci(r.vertex.clip_rel),
            sci(r.vertex.window_px),
            sci(r.vertex.window_z),
        );
    }
    let examples: Vec<String> = rows
        .iter()
        .filter(|r| r.errors.unexplained + r.errors.depth_beyond + r.errors.color_beyond > 0)
        .map(|r| {
            format!(
                "- {} {}: {} differing pixels unexplained, e.g. (x, y, core id+1, reference \
                 id+1) {:?}; {} depth and {} colour errors beyond the bound, e.g. (x, y, id+1, \
                 what, stored, exact) {:?}",
                r.scene,
                r.config.label(),
                r.errors.unexplained,
                r.errors.unexplained_examples,
                r.errors.depth_beyond,
                r.errors.color_beyond,
                r.errors.beyond_examples,
            )
        })
        .collect();
    let _ = writeln!(s, "\n## Unexplained differences\n");
    if examples.is_empty() {
        let _ = writeln!(
            s,
            "None: every differing pixel lies within the snapping tolerance of an edge or is a \
             depth tie, and every depth and colour error is within the bound that snapping, the \
             measured vertex error and rounding explain."
        );
    } else {
        for e in examples {
            let _ = writeln!(s, "{e}");
        }
    }
    let _ = writeln!(
        s,
        "\n## Columns\n\n\
         - *differing*: pixels whose triangle (the `TriangleId` image) is not the reference's; \
         *coverage only*: of those, pixels that are background in one image and not in the other.\n\
         - *unexplained*: differing pixels that are neither within the snapping tolerance (half a \
         subpixel per axis plus the measured vertex error) of an edge of either triangle, nor a \
         depth tie within the depth tolerance.\n\
         - *depth (LSB)*: `|stored - floor(z·2^bits)|` at pixels drawn by the same triangle in \
         both, in LSB of the buffer (`u16` or `u32`), where `z` is the exact window depth: the \
         error beyond the buffer's own truncation; *beyond bound*: pixels where it exceeds 2 LSB \
         plus the depth change that moving the vertices by the tolerance causes. *depth vs \
         exact*: `|stored / 2^bits - z|` in window-depth units (`[0, 1]`), truncation included: \
         what a depth test actually compares.\n\
         - *colour*: `|core - round(exact)|` per channel (8-bit LSB); *beyond bound*: pixels where \
         it exceeds 1 LSB plus the colour change that moving the vertices by the tolerance causes.\n\
         - *matrix err*: largest `|m32 - m64|` relative to the matrix's largest entry; *clip err*: \
         largest clip-space component error relative to `w`; *vertex err*: largest window-space \
         error of a vertex in pixels (x, y) and in window depth (z), all against `f64`, before \
         snapping.\n\
         - *time*: the whole frame on one thread: matrices, setup of every triangle, clearing and \
         rendering all rows into `Rgb888` and the depth buffer.\n"
    );
    s
}
