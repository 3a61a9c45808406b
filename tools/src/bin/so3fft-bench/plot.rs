//! SVG plot of the results, written by hand (no plotting crate): time per transform against
//! bandwidth (log-log) and round-trip error against bandwidth (log-log), side by side, each
//! with axes, ticks, labels and a legend.

use crate::report::{Row, Variant};
use std::fmt::Write as _;

const PANEL_W: f64 = 560.0;
const PLOT_H: f64 = 330.0;
const MARGIN_L: f64 = 78.0;
const MARGIN_R: f64 = 20.0;
const MARGIN_T: f64 = 48.0;
/// Space under the plot area for the x label.
const AXIS_SPACE: f64 = 52.0;
const LEGEND_ROW: f64 = 17.0;
/// Colours of successive thread counts (colour-blind safe, Okabe-Ito).
const PALETTE: [&str; 6] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9",
];

#[derive(Clone, Copy)]
enum Marker {
    Circle,
    Square,
    Triangle,
    Diamond,
}

struct Series {
    label: String,
    color: &'static str,
    dash: Option<&'static str>,
    marker: Marker,
    points: Vec<(f64, f64)>,
}

impl Series {
    fn new(
        label: impl Into<String>,
        color: &'static str,
        dash: Option<&'static str>,
        marker: Marker,
    ) -> Self {
        Series {
            label: label.into(),
            color,
            dash,
            marker,
            points: Vec::new(),
        }
    }
}

struct Panel {
    title: &'static str,
    y_label: &'static str,
    series: Vec<Series>,
}

/// The whole SVG document for `rows`.
pub fn svg(rows: &[Row]) -> String {
    let panels = [time_panel(rows), error_panel(rows)];
    let legend_rows = panels
        .iter()
        .map(|p| {
            p.series
                .iter()
                .filter(|s| !s.points.is_empty())
                .count()
                .div_ceil(2)
        })
        .max()
        .unwrap_or(0);
    let height = MARGIN_T + PLOT_H + AXIS_SPACE + legend_rows as f64 * LEGEND_ROW + 16.0;
    let width = 2.0 * PANEL_W;
    let mut out = String::new();
    let _ = writeln!(
        out,
        r#"<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height:.0}" viewBox="0 0 {width} {height:.0}" font-family="sans-serif" font-size="12">"#
    );
    let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
    let x_values = bandwidths(rows);
    for (i, p) in panels.iter().enumerate() {
        draw_panel(&mut out, i as f64 * PANEL_W, p, &x_values);
    }
    out.push_str("</svg>\n");
    out
}

/// Distinct bandwidths of the rows, ascending.
fn bandwidths(rows: &[Row]) -> Vec<f64> {
    let mut bandwidths: Vec<usize> = rows.iter().map(|r| r.bandwidth).collect();
    bandwidths.sort_unstable();
    bandwidths.dedup();
    bandwidths.into_iter().map(|b| b as f64).collect()
}

/// Distinct thread counts of the complex rows, ascending.
fn thread_counts(rows: &[Row]) -> Vec<usize> {
    let mut counts: Vec<usize> = rows
        .iter()
        .filter(|r| r.variant == Variant::Complex)
        .map(|r| r.threads)
        .collect();
    counts.sort_unstable();
    counts.dedup();
    counts
}

/// Adds the point (`b`, `y`) to `series` where it can be drawn on log axes.
fn push(series: &mut Series, b: usize, y: f64) {
    if y.is_finite() && y > 0.0 {
        series.points.push((b as f64, y));
    }
}

fn time_panel(rows: &[Row]) -> Panel {
    let mut series = Vec::new();
    for (i, &t) in thread_counts(rows).iter().enumerate() {
        let color = PALETTE[i % PALETTE.len()];
        let mut forward = Series::new(format!("forward, {t} thr"), color, None, Marker::Circle);
        let mut inverse = Series::new(
            format!("inverse, {t} thr"),
            color,
            Some("6,4"),
            Marker::Square,
        );
        for r in rows
            .iter()
            .filter(|r| r.variant == Variant::Complex && r.threads == t)
        {
            push(&mut forward, r.bandwidth, r.fwd_median);
            push(&mut inverse, r.bandwidth, r.inv_median);
        }
        series.extend([forward, inverse]);
    }
    let grey = "#555555";
    let real_colour = "#8B008B";
    let mut variants = [
        (
            Variant::NoSkip,
            Series::new("forward, no skipping", grey, Some("2,3"), Marker::Diamond),
            Series::new(
                "inverse, no skipping",
                grey,
                Some("8,3,2,3"),
                Marker::Diamond,
            ),
        ),
        (
            Variant::Naive,
            Series::new("plain DWT forward, 1 thr", "black", None, Marker::Triangle),
            Series::new(
                "plain DWT inverse, 1 thr",
                "black",
                Some("6,4"),
                Marker::Triangle,
            ),
        ),
        (
            Variant::Real,
            Series::new("real forward", real_colour, None, Marker::Diamond),
            Series::new("real inverse", real_colour, Some("6,4"), Marker::Diamond),
        ),
    ];
    for r in rows {
        let Some((_, forward, inverse)) = variants.iter_mut().find(|v| v.0 == r.variant) else {
            continue;
        };
        // The plain DWT has no whole-transform time: its DWT stage is the transform.
        let (forward_time, inverse_time) = if r.variant == Variant::Naive {
            (r.fwd.dwt, r.inv.dwt)
        } else {
            (r.fwd_median, r.inv_median)
        };
        push(forward, r.bandwidth, forward_time);
        push(inverse, r.bandwidth, inverse_time);
    }
    series.extend(
        variants
            .into_iter()
            .flat_map(|(_, forward, inverse)| [forward, inverse]),
    );
    Panel {
        title: "Time per transform (medians; plain DWT: DWT stage only)",
        y_label: "time [s]",
        series,
    }
}

fn error_panel(rows: &[Row]) -> Panel {
    let mut series = Vec::new();
    let kinds = [
        (Variant::Complex, "complex", PALETTE[0], Marker::Circle),
        (Variant::NoSkip, "no skipping", "#555555", Marker::Diamond),
        (Variant::Naive, "plain DWT", "black", Marker::Triangle),
        (Variant::Real, "real signal", "#8B008B", Marker::Square),
    ];
    for (variant, name, color, marker) in kinds {
        let mut rel = Series::new(format!("{name}: relative L2"), color, None, marker);
        let mut max = Series::new(format!("{name}: max abs"), color, Some("6,4"), marker);
        for b in bandwidths(rows) {
            // One row per bandwidth: the fewest threads (errors barely depend on them).
            let row = rows
                .iter()
                .filter(|r| r.variant == variant && r.bandwidth as f64 == b)
                .min_by_key(|r| r.threads);
            if let Some(r) = row {
                push(&mut rel, r.bandwidth, r.rel_l2_err);
                push(&mut max, r.bandwidth, r.max_abs_err);
            }
        }
        series.extend([rel, max]);
    }
    Panel {
        title: "Round-trip error (inverse then forward)",
        y_label: "error",
        series,
    }
}

/// Maps data to pixels in one panel (log10 on both axes).
struct Axes {
    /// Left and top edge of the plot area, pixels.
    x0: f64,
    y0: f64,
    /// Width and height of the plot area, pixels.
    w: f64,
    h: f64,
    /// log10 range of each axis.
    log_x: (f64, f64),
    log_y: (f64, f64),
}

impl Axes {
    fn pixel_x(&self, x: f64) -> f64 {
        self.x0 + (x.log10() - self.log_x.0) / (self.log_x.1 - self.log_x.0) * self.w
    }

    fn pixel_y(&self, y: f64) -> f64 {
        self.y0 + self.h - (y.log10() - self.log_y.0) / (self.log_y.1 - self.log_y.0) * self.h
    }
}

fn draw_panel(out: &mut String, left: f64, panel: &Panel, x_values: &[f64]) {
    let series: Vec<&Series> = panel
        .series
        .iter()
        .filter(|s| !s.points.is_empty())
        .collect();
    let x0 = left + MARGIN_L;
    let w = PANEL_W - MARGIN_L - MARGIN_R;
    let _ = writeln!(
        out,
        r#"<text x="{:.1}" y="22" text-anchor="middle" font-size="14" font-weight="bold">{}</text>"#,
        x0 + w / 2.0,
        panel.title
    );
    if series.is_empty() || x_values.is_empty() {
        let _ = writeln!(
            out,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">no data</text>"#,
            x0 + w / 2.0,
            MARGIN_T + PLOT_H / 2.0
        );
        return;
    }
    let (xmin, xmax) = (x_values[0], x_values[x_values.len() - 1]);
    let log_x = (xmin.log10() - 0.08, xmax.log10() + 0.08);
    let ys = series.iter().flat_map(|s| s.points.iter().map(|p| p.1));
    let (ymin, ymax) = ys.fold((f64::INFINITY, 0.0f64), |(a, b), y| (a.min(y), b.max(y)));
    let mut log_y = (ymin.log10().floor(), ymax.log10().ceil());
    if log_y.1 - log_y.0 < 1.0 {
        log_y.1 = log_y.0 + 1.0;
    }
    let axes = Axes {
        x0,
        y0: MARGIN_T,
        w,
        h: PLOT_H,
        log_x,
        log_y,
    };
    draw_axes(out, &axes, x_values, panel.y_label);
    // Reverse order: the first legend entries end up on top where lines coincide (the
    // errors with and without skipping are usually identical).
    for s in series.iter().rev() {
        draw_series(out, &axes, s);
    }
    draw_legend(out, left, &series);
}

fn draw_axes(out: &mut String, axes: &Axes, x_values: &[f64], y_label: &str) {
    let (x1, y1) = (axes.x0 + axes.w, axes.y0 + axes.h);
    // Decades: grid line, major tick, label; 2..9: minor tick.
    let decades = (axes.log_y.1 - axes.log_y.0).round() as i32;
    let label_every = (decades + 7) / 8;
    for (i, e) in (axes.log_y.0 as i32..=axes.log_y.1 as i32).enumerate() {
        let y = axes.pixel_y(10f64.powi(e));
        let _ = writeln!(
            out,
            "<line x1=\"{:.1}\" y1=\"{y:.1}\" x2=\"{x1:.1}\" y2=\"{y:.1}\" stroke=\"#e4e4e4\"/>\n\
             <line x1=\"{:.1}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"black\"/>",
            axes.x0,
            axes.x0 - 6.0,
            axes.x0
        );
        if i as i32 % label_every == 0 {
            let _ = writeln!(
                out,
                r#"<text x="{:.1}" y="{:.1}" text-anchor="end">1e{e}</text>"#,
                axes.x0 - 9.0,
                y + 4.0
            );
        }
        if e < axes.log_y.1 as i32 && decades <= 12 {
            for k in 2..10 {
                let y = axes.pixel_y(k as f64 * 10f64.powi(e));
                let _ = writeln!(
                    out,
                    r#"<line x1="{:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="black"/>"#,
                    axes.x0 - 3.0,
                    axes.x0
                );
                // With few decades, label 2 and 5 too (else a panel may show two labels).
                if decades <= 2 && (k == 2 || k == 5) {
                    let _ = writeln!(
                        out,
                        r##"<text x="{:.1}" y="{:.1}" text-anchor="end" fill="#555555">{k}e{e}</text>"##,
                        axes.x0 - 9.0,
                        y + 4.0
                    );
                }
            }
        }
    }
    // Bandwidths: one tick each, labels where there is room.
    let mut last_label = f64::NEG_INFINITY;
    for &b in x_values {
        let x = axes.pixel_x(b);
        let _ = writeln!(
            out,
            "<line x1=\"{x:.1}\" y1=\"{:.1}\" x2=\"{x:.1}\" y2=\"{y1:.1}\" stroke=\"#e4e4e4\"/>\n\
             <line x1=\"{x:.1}\" y1=\"{y1:.1}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"black\"/>",
            axes.y0,
            y1 + 6.0
        );
        if x - last_label >= 28.0 {
            let _ = writeln!(
                out,
                r#"<text x="{x:.1}" y="{:.1}" text-anchor="middle">{b}</text>"#,
                y1 + 20.0
            );
            last_label = x;
        }
    }
    let _ = writeln!(
        out,
        "<rect x=\"{:.1}\" y=\"{:.1}\" width=\"{:.1}\" height=\"{:.1}\" fill=\"none\" stroke=\"black\"/>\n\
         <text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"middle\">bandwidth B (log scale)</text>\n\
         <text transform=\"translate({:.1},{:.1}) rotate(-90)\" text-anchor=\"middle\">{y_label} (log scale)</text>",
        axes.x0,
        axes.y0,
        axes.w,
        axes.h,
        axes.x0 + axes.w / 2.0,
        y1 + 40.0,
        axes.x0 - 58.0,
        axes.y0 + axes.h / 2.0
    );
}

fn dash_attr(dash: Option<&str>) -> String {
    dash.map_or(String::new(), |d| format!(r#" stroke-dasharray="{d}""#))
}

fn marker(out: &mut String, m: Marker, x: f64, y: f64, color: &str) {
    let _ = match m {
        Marker::Circle => writeln!(
            out,
            r#"<circle cx="{x:.1}" cy="{y:.1}" r="3.5" fill="{color}"/>"#
        ),
        Marker::Square => writeln!(
            out,
            r#"<rect x="{:.1}" y="{:.1}" width="7" height="7" fill="white" stroke="{color}" stroke-width="1.5"/>"#,
            x - 3.5,
            y - 3.5
        ),
        Marker::Triangle => writeln!(
            out,
            r#"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" fill="{color}"/>"#,
            x,
            y - 4.5,
            x - 4.0,
            y + 3.0,
            x + 4.0,
            y + 3.0
        ),
        // Larger than the others and hollow, so a marker drawn on top stays visible inside.
        Marker::Diamond => writeln!(
            out,
            r#"<polygon points="{:.1},{:.1} {:.1},{:.1} {:.1},{:.1} {:.1},{:.1}" fill="white" stroke="{color}" stroke-width="1.5"/>"#,
            x,
            y - 6.5,
            x + 6.5,
            y,
            x,
            y + 6.5,
            x - 6.5,
            y
        ),
    };
}

fn draw_series(out: &mut String, axes: &Axes, s: &Series) {
    let pts: Vec<String> = s
        .points
        .iter()
        .map(|&(x, y)| format!("{:.1},{:.1}", axes.pixel_x(x), axes.pixel_y(y)))
        .collect();
    let _ = writeln!(
        out,
        r#"<polyline points="{}" fill="none" stroke="{}" stroke-width="1.6"{}/>"#,
        pts.join(" "),
        s.color,
        dash_attr(s.dash)
    );
    for &(x, y) in &s.points {
        marker(out, s.marker, axes.pixel_x(x), axes.pixel_y(y), s.color);
    }
}

/// Two columns of entries under the x-axis label.
fn draw_legend(out: &mut String, left: f64, series: &[&Series]) {
    let top = MARGIN_T + PLOT_H + AXIS_SPACE + 4.0;
    let col_w = (PANEL_W - MARGIN_L) / 2.0;
    for (i, s) in series.iter().enumerate() {
        let x = left + MARGIN_L + (i % 2) as f64 * col_w;
        let y = top + (i / 2) as f64 * LEGEND_ROW;
        let _ = writeln!(
            out,
            r#"<line x1="{x:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{}" stroke-width="1.6"{}/>"#,
            x + 30.0,
            s.color,
            dash_attr(s.dash)
        );
        marker(out, s.marker, x + 15.0, y, s.color);
        let _ = writeln!(
            out,
            r#"<text x="{:.1}" y="{:.1}">{}</text>"#,
            x + 38.0,
            y + 4.0,
            s.label
        );
    }
}
