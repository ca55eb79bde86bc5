//! The report's plot: error against speed, one point per configuration,
//! the starred front marked. Top row: against the M4F's render
//! instructions (the firmware's, from `docs/embedded.md`); bottom row:
//! against the host's frame time, the median with the fastest and slowest
//! repetition as error bars.
//!
//! Design note: drawn with `plotters` into an RGB8 buffer; its text is drawn
//! afterwards with embedded-graphics' built-in mono font, so no system font
//! is needed, and the PNG is written with the host's own encoder. Point
//! labels are placed with a collision check against the points, the error
//! bars and the labels placed before them ([`place_point_labels`]).

use super::{count_range, significant_front, RunInfo, Summary};
use embedded_graphics::mono_font::{ascii, MonoFont, MonoTextStyle};
use embedded_graphics::pixelcolor::Rgb888 as EgRgb;
use embedded_graphics::prelude::{DrawTarget, OriginDimensions, Point, Size};
use embedded_graphics::text::{Alignment, Baseline, Text, TextStyleBuilder};
use embedded_graphics::Drawable;
use plotters::prelude::*;
use std::path::Path;

const W: u32 = 1200;
const H: u32 = 1100;

/// A text label to draw after plotting, at backend pixel coordinates.
struct Label {
    text: String,
    at: (i32, i32),
    align: Alignment,
    baseline: Baseline,
    big: bool,
}

/// An RGB8 buffer as an embedded-graphics draw target.
struct Canvas<'a> {
    buf: &'a mut [u8],
}

impl OriginDimensions for Canvas<'_> {
    fn size(&self) -> Size {
        Size::new(W, H)
    }
}

impl DrawTarget for Canvas<'_> {
    type Color = EgRgb;
    type Error = core::convert::Infallible;
    fn draw_iter<I>(&mut self, pixels: I) -> Result<(), Self::Error>
    where
        I: IntoIterator<Item = embedded_graphics::Pixel<EgRgb>>,
    {
        use embedded_graphics::pixelcolor::RgbColor as _;
        for embedded_graphics::Pixel(p, c) in pixels {
            if p.x >= 0 && p.y >= 0 && (p.x as u32) < W && (p.y as u32) < H {
                let i = 3 * (p.y as usize * W as usize + p.x as usize);
                self.buf[i] = c.r();
                self.buf[i + 1] = c.g();
                self.buf[i + 2] = c.b();
            }
        }
        Ok(())
    }
}

fn nice_ticks(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    let span = (hi - lo).max(1e-12);
    let raw = span / n as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .iter()
        .map(|m| m * mag)
        .find(|s| span / s <= n as f64)
        .unwrap_or(10.0 * mag);
    let mut t = (lo / step).ceil() * step;
    let mut out = Vec::new();
    while t <= hi + step * 1e-9 {
        out.push(t);
        t += step;
    }
    out
}

fn fmt_tick(v: f64) -> String {
    if v == 0.0 {
        "0".into()
    } else if v.abs() >= 0.01 && v.abs() < 1e4 {
        let s = format!("{v:.3}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{v:.0e}")
    }
}

struct Panel<'a> {
    title: &'a str,
    y_label: &'a str,
    x_label: &'a str,
    log_y: bool,
    /// Speed (lower is faster): the point's x.
    xs: Vec<f64>,
    /// Its range (the noise, or min and max): what starring compares.
    ranges: Vec<(f64, f64)>,
    /// Draw the ranges as error bars.
    bars: bool,
    ys: Vec<f64>,
}

type PResult<T> = Result<T, String>;

fn err<E: std::fmt::Debug>(e: E) -> String {
    format!("plot: {e:?}")
}

#[allow(clippy::too_many_arguments)]
fn draw_panel(
    area: &DrawingArea<BitMapBackend<'_>, plotters::coord::Shift>,
    panel: &Panel<'_>,
    names: &[String],
    labels: &mut Vec<Label>,
) -> PResult<()> {
    let xs = &panel.xs;
    let (x_lo, x_hi) = xs
        .iter()
        .zip(&panel.ranges)
        .filter(|(x, _)| x.is_finite())
        .fold(
            (f64::INFINITY, f64::NEG_INFINITY),
            |(a, b), (&x, &(lo, hi))| {
                if panel.bars {
                    (a.min(lo), b.max(hi))
                } else {
                    (a.min(x), b.max(x))
                }
            },
        );
    let (x_lo, x_hi) = if x_lo.is_finite() {
        (x_lo, x_hi)
    } else {
        (0.0, 1.0)
    };
    let pad = ((x_hi - x_lo) * 0.15).max(x_hi.abs() * 0.02).max(1e-3);
    let (x0, x1) = ((x_lo - pad).max(0.0), x_hi + pad);
    let ys = &panel.ys;
    let (y_lo, y_hi) = ys
        .iter()
        .filter(|v| v.is_finite() && (!panel.log_y || **v > 0.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &y| {
            (a.min(y), b.max(y))
        });
    let (y_lo, y_hi) = if y_lo.is_finite() {
        (y_lo, y_hi)
    } else {
        (1e-9, 1.0)
    };
    let points: Vec<(f64, f64)> = xs.iter().copied().zip(ys.iter().copied()).collect();
    let front = significant_front(
        &panel
            .ranges
            .iter()
            .zip(ys)
            .map(|(&(lo, hi), &y)| (lo, hi, y))
            .collect::<Vec<_>>(),
    );
    let (margin_l, margin_b, margin_t, margin_r) = (80, 64, 50, 20);
    let (aw, ah) = area.dim_in_pixel();
    let (ox, oy) = area.get_base_pixel();
    let plot_area = area.margin(margin_t, margin_b, margin_l, margin_r);
    labels.push(Label {
        text: panel.title.into(),
        at: (ox + aw as i32 / 2, oy + 4),
        align: Alignment::Center,
        baseline: Baseline::Top,
        big: true,
    });
    labels.push(Label {
        text: panel.y_label.into(),
        at: (ox + 8, oy + margin_t - 16),
        align: Alignment::Left,
        baseline: Baseline::Bottom,
        big: false,
    });
    labels.push(Label {
        text: panel.x_label.into(),
        at: (ox + aw as i32 / 2, oy + ah as i32 - 22),
        align: Alignment::Center,
        baseline: Baseline::Bottom,
        big: false,
    });
    let grid = RGBColor(220, 220, 220);
    let axis = RGBColor(60, 60, 60);
    let front_color = RGBColor(213, 94, 0);
    let point_color = RGBColor(0, 114, 178);
    let mut point_px: Vec<((i32, i32), usize)> = Vec::new();
    let mut bar_px: Vec<(i32, i32, i32, i32)> = Vec::new();
    let plot_rect = (
        ox + margin_l,
        oy + margin_t,
        aw as i32 - margin_l - margin_r,
        ah as i32 - margin_t - margin_b,
    );
    macro_rules! body {
        ($chart:expr, $y_ticks:expr, $fy:expr) => {{
            let chart = &mut $chart;
            let x_ticks = nice_ticks(x0, x1, 6);
            let y_ticks: Vec<f64> = $y_ticks;
            let (yb, yt) = ($fy.0, $fy.1);
            for &t in &x_ticks {
                chart
                    .draw_series(LineSeries::new([(t, yb), (t, yt)], grid))
                    .map_err(err)?;
                let (bx, by) = chart.backend_coord(&(t, yb));
                labels.push(Label {
                    text: fmt_tick(t),
                    at: (bx, by + 6),
                    align: Alignment::Center,
                    baseline: Baseline::Top,
                    big: false,
                });
            }
            for &t in &y_ticks {
                chart
                    .draw_series(LineSeries::new([(x0, t), (x1, t)], grid))
                    .map_err(err)?;
                let (bx, by) = chart.backend_coord(&(x0, t));
                labels.push(Label {
                    text: fmt_tick(t),
                    at: (bx - 6, by),
                    align: Alignment::Right,
                    baseline: Baseline::Middle,
                    big: false,
                });
            }
            chart
                .draw_series(LineSeries::new(
                    [(x0, yt), (x0, yb), (x1, yb)],
                    axis.stroke_width(2),
                ))
                .map_err(err)?;
            let fp: Vec<(f64, f64)> = front
                .iter()
                .map(|&i| points[i])
                .filter(|&(_, y)| !panel.log_y || y > 0.0)
                .collect();
            chart
                .draw_series(LineSeries::new(fp, front_color.stroke_width(2)))
                .map_err(err)?;
            for (i, &(x, y)) in points.iter().enumerate() {
                if !x.is_finite() || !y.is_finite() || (panel.log_y && y <= 0.0) {
                    continue;
                }
                if panel.bars {
                    let (lo, hi) = panel.ranges[i];
                    let (l, by) = chart.backend_coord(&(lo, y));
                    let (r, _) = chart.backend_coord(&(hi, y));
                    bar_px.push((l, by - 5, r, by + 5));
                    chart
                        .draw_series(LineSeries::new([(lo, y), (hi, y)], axis))
                        .map_err(err)?;
                    for e in [l, r] {
                        area.draw(&PathElement::new(
                            [(e - ox, by - oy - 4), (e - ox, by - oy + 4)],
                            axis,
                        ))
                        .map_err(err)?;
                    }
                }
                let on = front.contains(&i);
                let style = if on {
                    front_color.filled()
                } else {
                    point_color.stroke_width(2)
                };
                chart
                    .draw_series(std::iter::once(Circle::new((x, y), 5, style)))
                    .map_err(err)?;
                point_px.push((chart.backend_coord(&(x, y)), i));
            }
        }};
    }
    if panel.log_y {
        let lo = 10f64.powf(y_lo.log10().floor());
        let hi = 10f64.powf(y_hi.log10().ceil()).max(lo * 10.0);
        let mut chart = ChartBuilder::on(&plot_area)
            .build_cartesian_2d(x0..x1, (lo..hi).log_scale())
            .map_err(err)?;
        let mut ticks = Vec::new();
        let mut t = lo;
        while t <= hi * 1.0001 {
            ticks.push(t);
            t *= 10.0;
        }
        body!(chart, ticks, (lo, hi));
    } else {
        let hi = if y_hi > 0.0 { y_hi * 1.15 } else { 1.0 };
        let mut chart = ChartBuilder::on(&plot_area)
            .build_cartesian_2d(x0..x1, 0.0..hi)
            .map_err(err)?;
        body!(chart, nice_ticks(0.0, hi, 6), (0.0, hi));
    }
    let placed = place_point_labels(&point_px, &bar_px, names, plot_rect);
    // A label moved away from its point gets a thin leader line to it.
    for (l, &((px, py), _)) in placed.iter().zip(&point_px) {
        let r = label_rect(l);
        let (cx, cy) = (px.clamp(r.0, r.2), py.clamp(r.1, r.3));
        if (cx - px).abs() + (cy - py).abs() > 16 {
            area.draw(&PathElement::new(
                [(px - ox, py - oy), (cx - ox, cy - oy)],
                RGBColor(150, 150, 150),
            ))
            .map_err(err)?;
        }
    }
    labels.extend(placed);
    Ok(())
}

/// A label's box: left, top, right, bottom.
type Rect = (i32, i32, i32, i32);

/// The box of a point label (6x10 font, left-top anchored).
fn label_rect(l: &Label) -> Rect {
    let w = l.text.len() as i32 * 6;
    (l.at.0, l.at.1, l.at.0 + w, l.at.1 + 10)
}

fn overlaps(a: &Rect, b: &Rect) -> bool {
    a.0 < b.2 && b.0 < a.2 && a.1 < b.3 && b.1 < a.3
}

/// Each point's name next to it, overlapping no other name, no point and
/// no error bar (`obstacles`), inside `area` (left, top, width, height):
/// a few positions around the point first, then the first free one
/// straight above or below it (offset a line at a time), then further
/// out to the sides.
fn place_point_labels(
    points: &[((i32, i32), usize)],
    obstacles: &[Rect],
    names: &[String],
    area: (i32, i32, i32, i32),
) -> Vec<Label> {
    let mut labels = Vec::new();
    let mut taken: Vec<Rect> = points
        .iter()
        .map(|&((x, y), _)| (x - 6, y - 6, x + 6, y + 6))
        .chain(obstacles.iter().copied())
        .collect();
    for &((x, y), i) in points {
        let (w, h) = (names[i].len() as i32 * 6, 10);
        let mut candidates = vec![
            (11, -5),
            (11, -16),
            (11, 6),
            (-11 - w, -5),
            (-11 - w, -16),
            (-11 - w, 6),
            (-w / 2, -20),
            (-w / 2, 9),
            (11, -28),
            (11, 18),
            (-11 - w, -28),
            (-11 - w, 18),
            (11, -40),
            (11, 30),
        ];
        for dx in [11, -11 - w, -w / 2, 24, -24 - w] {
            for k in 1..60 {
                candidates.push((dx, -5 - 11 * k));
                candidates.push((dx, -5 + 11 * k));
            }
        }
        let inside = |r: &Rect| {
            r.0 >= area.0 && r.1 >= area.1 && r.2 <= area.0 + area.2 && r.3 <= area.1 + area.3
        };
        let rect_at = |(dx, dy): (i32, i32)| (x + dx, y + dy, x + dx + w, y + dy + h);
        let pick = candidates
            .iter()
            .map(|&c| rect_at(c))
            .find(|r| {
                // A gap of a few pixels between labels, so that two never
                // read as one.
                let padded = (r.0 - 4, r.1 - 1, r.2 + 4, r.3 + 1);
                inside(r) && !taken.iter().any(|t| overlaps(&padded, t))
            })
            .unwrap_or_else(|| rect_at(candidates[0]));
        taken.push(pick);
        labels.push(Label {
            text: names[i].clone(),
            at: (pick.0, pick.1),
            align: Alignment::Left,
            baseline: Baseline::Top,
            big: false,
        });
    }
    labels
}

/// Draws the two panels and writes the PNG.
pub fn write_png(path: &Path, info: &RunInfo, summary: &[Summary]) -> Result<(), String> {
    let mut buf = vec![255u8; (W * H * 3) as usize];
    let mut labels = Vec::new();
    let names: Vec<String> = summary.iter().map(|s| s.config.label()).collect();
    // The M4F's counts in thousands; their ranges are the count noise.
    let kilo = |n: Option<u64>| n.map_or(f64::NAN, |n| n as f64 / 1e3);
    let count_xs: Vec<f64> = summary.iter().map(|s| kilo(s.device.m4f_render)).collect();
    let count_ranges: Vec<(f64, f64)> = summary
        .iter()
        .map(|s| {
            let (lo, hi) = count_range(s.device.m4f_render);
            (lo / 1e3, hi / 1e3)
        })
        .collect();
    let time_xs: Vec<f64> = summary.iter().map(|s| s.time_ms).collect();
    let time_ranges: Vec<(f64, f64)> = summary
        .iter()
        .map(|s| (s.time_min_ms, s.time_max_ms))
        .collect();
    let coverage: Vec<f64> = summary.iter().map(|s| s.id_diff_pct).collect();
    let depth: Vec<f64> = summary.iter().map(|s| s.depth_mean_abs).collect();
    let count_label = "M4F render, thousands of instructions (firmware: cubes, 320x240, QEMU)";
    let time_label = "host frame time, sum over scenes (ms): median, bars min-max";
    {
        let root = BitMapBackend::with_buffer(&mut buf, (W, H)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (top, bottom) = root.split_vertically((H - 20) / 2);
        let bottom = bottom.margin(0, 20, 0, 0);
        for (row, xs, ranges, x_label, bars) in [
            (&top, &count_xs, &count_ranges, count_label, false),
            (&bottom, &time_xs, &time_ranges, time_label, true),
        ] {
            let (left, right) = row.split_horizontally(W / 2);
            draw_panel(
                &left,
                &Panel {
                    title: "Coverage: pixels whose triangle differs from f64",
                    y_label: "% of covered pixels (log scale)",
                    x_label,
                    log_y: true,
                    xs: xs.clone(),
                    ranges: ranges.clone(),
                    bars,
                    ys: coverage.clone(),
                },
                &names,
                &mut labels,
            )?;
            draw_panel(
                &right,
                &Panel {
                    title: "Depth: mean stored-vs-exact error",
                    y_label: "window depth, [0, 1] (log scale)",
                    x_label,
                    log_y: true,
                    xs: xs.clone(),
                    ranges: ranges.clone(),
                    bars,
                    ys: depth.clone(),
                },
                &names,
                &mut labels,
            )?;
        }
        root.present().map_err(err)?;
    }
    labels.push(Label {
        text: format!(
            "host: {}x{}, one thread, {} frames; filled points and line: the front where the lead \
             beats the noise (counts: 1 %; time: the min-max ranges do not overlap)",
            info.width, info.height, info.reps
        ),
        at: (W as i32 / 2, H as i32 - 4),
        align: Alignment::Center,
        baseline: Baseline::Bottom,
        big: false,
    });
    let mut canvas = Canvas { buf: &mut buf };
    for l in &labels {
        let font: &MonoFont<'_> = if l.big {
            &ascii::FONT_8X13_BOLD
        } else {
            &ascii::FONT_6X10
        };
        let style = MonoTextStyle::new(font, EgRgb::new(20, 20, 20));
        let ts = TextStyleBuilder::new()
            .alignment(l.align)
            .baseline(l.baseline)
            .build();
        let _ =
            Text::with_text_style(&l.text, Point::new(l.at.0, l.at.1), style, ts).draw(&mut canvas);
    }
    crate::image_out::write_rgb(path, W, H, &buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn point_labels_do_not_overlap_each_other_points_or_bars() {
        // Eight points in a tight cluster and two on top of each other,
        // with an error bar through the cluster.
        let mut points: Vec<((i32, i32), usize)> = (0..8)
            .map(|i| ((300 + (i % 3) * 4, 300 + (i / 3) * 5), i as usize))
            .collect();
        points.push(((500, 200), 8));
        points.push(((500, 200), 9));
        let names: Vec<String> = (0..10).map(|i| format!("S{i} u16 micromath")).collect();
        let bars = [(250, 305, 400, 315)];
        let area = (100, 100, 600, 400);
        let labels = place_point_labels(&points, &bars, &names, area);
        assert_eq!(labels.len(), points.len());
        let rects: Vec<Rect> = labels.iter().map(label_rect).collect();
        for (i, a) in rects.iter().enumerate() {
            assert!(
                a.0 >= area.0 && a.1 >= area.1 && a.2 <= area.0 + area.2 && a.3 <= area.1 + area.3,
                "{a:?} outside"
            );
            for b in &rects[..i] {
                assert!(!overlaps(a, b), "{a:?} overlaps {b:?}");
            }
            for &((x, y), _) in &points {
                assert!(
                    !overlaps(a, &(x - 6, y - 6, x + 6, y + 6)),
                    "{a:?} on a point"
                );
            }
            assert!(!overlaps(a, &bars[0]), "{a:?} on the bar");
        }
    }
}
