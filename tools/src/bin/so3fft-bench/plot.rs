//! The benchmark's chart (`bench.svg`): time per transform against the bandwidth and
//! round-trip error against the bandwidth, log-log, side by side, each with its legend.

use crate::report::{Row, Variant};
use so3fft_tools::chart::{hex, Figure, LegendPlace, Line, Marker, Panel, Series, XTicks};

/// Colours of successive thread counts (colour-blind safe, Okabe-Ito).
const PALETTE: [&str; 6] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9",
];
const GREY: &str = "#555555";
const REAL_COLOUR: &str = "#8B008B";

/// The SVG document for `rows`.
pub fn svg(rows: &[Row]) -> Result<String, String> {
    Figure {
        panels: vec![time_panel(rows), error_panel(rows)],
        panel_width: 560,
        plot_height: 440,
        legend: LegendPlace::Below,
        columns: 2,
    }
    .svg()
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

fn panel(title: &str, y_label: &str, series: Vec<Series>) -> Panel {
    Panel {
        title: title.into(),
        x_label: "bandwidth B (log scale)".into(),
        y_label: format!("{y_label} (log scale)"),
        x_ticks: XTicks::DataValues,
        series,
        x_rules: Vec::new(),
        y_rules: Vec::new(),
    }
}

fn time_panel(rows: &[Row]) -> Panel {
    let mut series = Vec::new();
    for (i, &t) in thread_counts(rows).iter().enumerate() {
        let colour = hex(PALETTE[i % PALETTE.len()]);
        let mut forward = Series::new(
            format!("forward, {t} thr"),
            colour,
            Line::Solid,
            Marker::Circle,
        );
        let mut inverse = Series::new(
            format!("inverse, {t} thr"),
            colour,
            Line::Dashed,
            Marker::Square,
        );
        for r in rows
            .iter()
            .filter(|r| r.variant == Variant::Complex && r.threads == t)
        {
            forward.push(r.bandwidth as f64, r.fwd_median);
            inverse.push(r.bandwidth as f64, r.inv_median);
        }
        series.extend([forward, inverse]);
    }
    let mut variants = [
        (
            Variant::NoSkip,
            Series::new(
                "forward, no skipping",
                hex(GREY),
                Line::Dotted,
                Marker::Diamond,
            ),
            Series::new(
                "inverse, no skipping",
                hex(GREY),
                Line::Dashed,
                Marker::Diamond,
            ),
        ),
        (
            Variant::Naive,
            Series::new(
                "plain DWT forward, 1 thr",
                hex("#000000"),
                Line::Solid,
                Marker::Triangle,
            ),
            Series::new(
                "plain DWT inverse, 1 thr",
                hex("#000000"),
                Line::Dashed,
                Marker::Triangle,
            ),
        ),
        (
            Variant::Real,
            Series::new(
                "real forward",
                hex(REAL_COLOUR),
                Line::Solid,
                Marker::Diamond,
            ),
            Series::new(
                "real inverse",
                hex(REAL_COLOUR),
                Line::Dashed,
                Marker::Diamond,
            ),
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
        forward.push(r.bandwidth as f64, forward_time);
        inverse.push(r.bandwidth as f64, inverse_time);
    }
    series.extend(
        variants
            .into_iter()
            .flat_map(|(_, forward, inverse)| [forward, inverse]),
    );
    panel(
        "Time per transform (medians; plain DWT: DWT stage only)",
        "time [s]",
        series,
    )
}

fn error_panel(rows: &[Row]) -> Panel {
    let mut bandwidths: Vec<usize> = rows.iter().map(|r| r.bandwidth).collect();
    bandwidths.sort_unstable();
    bandwidths.dedup();
    let kinds = [
        (Variant::Complex, "complex", PALETTE[0], Marker::Circle),
        (Variant::NoSkip, "no skipping", GREY, Marker::Diamond),
        (Variant::Naive, "plain DWT", "#000000", Marker::Triangle),
        (Variant::Real, "real signal", REAL_COLOUR, Marker::Square),
    ];
    let mut series = Vec::new();
    for (variant, name, colour, marker) in kinds {
        let mut rel = Series::new(
            format!("{name}: relative L2"),
            hex(colour),
            Line::Solid,
            marker,
        );
        let mut max = Series::new(
            format!("{name}: max abs"),
            hex(colour),
            Line::Dashed,
            marker,
        );
        for &b in &bandwidths {
            // One row per bandwidth: the fewest threads (errors barely depend on them).
            let row = rows
                .iter()
                .filter(|r| r.variant == variant && r.bandwidth == b)
                .min_by_key(|r| r.threads);
            if let Some(r) = row {
                rel.push(b as f64, r.rel_l2_err);
                max.push(b as f64, r.max_abs_err);
            }
        }
        series.extend([rel, max]);
    }
    panel("Round-trip error (inverse then forward)", "error", series)
}
