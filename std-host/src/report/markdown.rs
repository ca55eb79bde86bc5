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

/// A count as `798,080`, or `-` where there is none.
pub(crate) fn thousands(n: Option<u64>) -> String {
    let Some(n) = n else { return "-".into() };
    let d = n.to_string();
    let mut out = String::new();
    for (i, c) in d.chars().enumerate() {
        if i > 0 && (d.len() - i) % 3 == 0 {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// The starred configurations by M4F render count and by host time (see
/// [`significant_front`]), indices into `summary`.
pub fn stars(summary: &[Summary]) -> (Vec<usize>, Vec<usize>) {
    let by_count: Vec<(f64, f64, f64)> = summary
        .iter()
        .map(|r| {
            let (lo, hi) = count_range(r.device.m4f_render);
            (lo, hi, r.id_diff_pct)
        })
        .collect();
    let by_time: Vec<(f64, f64, f64)> = summary
        .iter()
        .map(|r| (r.time_min_ms, r.time_max_ms, r.id_diff_pct))
        .collect();
    (significant_front(&by_count), significant_front(&by_time))
}

/// The report's markdown.
pub fn markdown(
    info: &RunInfo,
    summary: &[Summary],
    rows: &[Row],
    device: &[firmware::FirmwareRow],
) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# Speed against error\n");
    let _ = writeln!(
        s,
        "{}x{} pixels, one thread, median of {} frames per cell (with the fastest and the \
         slowest); errors against the `f64` reference renderer (`std-host/src/reference.rs`). \
         Speed of record: the firmware's instructions for the four cubes at 320x240 in the same \
         configuration on the Cortex-M4F and the Cortex-M0 under QEMU (`docs/embedded.md`, \
         *Configurations*, measured by `.ci/firmware.sh`). *Pixels differing* pools every scene \
         but `layers` (close parallel surfaces), which counts in *depth flips* only: pixels both \
         triangles cover away from their edges where the depth test chose the other one. \
         Written by `microraster report speed-vs-error`.\n",
        info.width, info.height, info.reps
    );
    let _ = writeln!(s, "## By configuration (all scenes together)\n");
    let _ = writeln!(
        s,
        "| configuration | ★ M4F | ★ host | M4F render (instr.) | M4F rasterization | \
         M0 render | M0 rasterization | host frame time, sum (ms): median [min, max] | \
         pixels differing | coverage only | \
         unexplained | depth flips | depth max (LSB) | depth beyond bound | depth vs exact, mean | \
         depth vs exact, max | colour max (LSB) | colour beyond bound | matrix error (rel.) | \
         vertex error (px) |"
    );
    let _ = writeln!(
        s,
        "|---|:-:|:-:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"
    );
    let (by_count, by_time) = stars(summary);
    let star = |front: &[usize], i: usize| if front.contains(&i) { "★" } else { "" };
    for (i, r) in summary.iter().enumerate() {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} | {} | {:.2} [{:.2}, {:.2}] | {:.3} % | {:.3} % | {} | \
             {} | {:.0} | {} | {} | {} | {:.0} | {} | {} | {} |",
            r.config.label(),
            star(&by_count, i),
            star(&by_time, i),
            thousands(r.device.m4f_render),
            thousands(r.device.m4f_raster),
            thousands(r.device.m0_render),
            thousands(r.device.m0_raster),
            r.time_ms,
            r.time_min_ms,
            r.time_max_ms,
            r.id_diff_pct,
            r.coverage_diff_pct,
            r.unexplained,
            r.depth_flips,
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
        "\n★ on the Pareto front of speed against pixels differing, where the lead is larger \
         than the noise: a configuration is starred only if it is faster, beyond the noise, than \
         every configuration at least as accurate (the errors are deterministic). *★ M4F*: by the \
         M4F's render instructions, noise taken as {:.0} % (the SysTick granularity is 40 \
         instructions a tick on the M4F and 62.5 on the micro:bit, times the strips for the \
         clears: a few thousand instructions, well under 1 %); *★ host*: by the host time, where \
         the ranges [min, max] over the repetitions must not overlap.\n",
        firmware::COUNT_NOISE * 100.0
    );
    let _ = writeln!(s, "## The firmware's configurations (`docs/embedded.md`)\n");
    let _ = writeln!(
        s,
        "The four cubes, 320x240 `Rgb565`, set up once, under QEMU `-icount shift=0`; \
         instructions, and RAM in bytes. `none`: no depth buffer; `no-i32-edges`: every triangle \
         on the `i64` edge path (the core's measurement feature; the same pixels).\n"
    );
    let _ = writeln!(
        s,
        "| board | configuration | frame | render | rasterization | RAM B |"
    );
    let _ = writeln!(s, "|---|---|--:|--:|--:|--:|");
    for d in device {
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {} | {} |",
            d.board,
            d.config,
            thousands(Some(d.frame)),
            thousands(Some(d.render)),
            thousands(Some(d.raster)),
            d.ram
        );
    }
    let _ = writeln!(s);
    let _ = writeln!(s, "## By scene\n");
    let _ = writeln!(
        s,
        "| scene | configuration | time (ms): median [min, max] | covered | differing | coverage only | \
         unexplained | depth flips | depth max (LSB) | depth mean (LSB) | depth beyond | colour max | \
         colour mean | colour beyond | matrix err | clip err (rel. w) | vertex err (px) | \
         vertex err (z) |"
    );
    let _ = writeln!(
        s,
        "|---|---|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|--:|"
    );
    for r in rows {
        let e = &r.errors;
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} [{:.3}, {:.3}] | {} | {} | {} | {} | {} | {:.0} | {:.2} | {} | {:.0} | {:.3} | {} | \
             {} | {} | {} | {} |",
            r.scene,
            r.config.label(),
            r.time_ms,
            r.time_min_ms,
            r.time_max_ms,
            e.covered,
            e.id_diff,
            e.coverage_diff,
            e.unexplained,
            e.depth_flips,
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
         - *M4F render*, *M0 render*: the firmware's instructions for the frame less the display \
         push, on the Cortex-M4F (`mps2-an386`) and the Cortex-M0 (`microbit`), the four cubes at \
         320x240 in this configuration; *rasterization*: the render less the strip clears and the \
         geometry.\n\
         - *time*: the whole frame on one thread: matrices, setup of every triangle, clearing and \
         rendering all rows into `Rgb888` and the depth buffer.\n"
    );
    s
}
