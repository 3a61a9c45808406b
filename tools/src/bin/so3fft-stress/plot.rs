//! The stress suite's charts, log-log: the round-trip error against the bandwidth per way of
//! running, and the run time against the error with SOFT 2.0's and ducc0's figures on this
//! machine as labelled reference points.

use crate::record::{Growth, Row};
use so3fft_tools::chart::{hex, Figure, LegendPlace, Line, Marker, Panel, Rule, Series, XTicks};

/// Colour-blind safe colours (Okabe-Ito) and two greys.
const PALETTE: [&str; 10] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#882255",
    "#777777", "#44AA99",
];

/// One chart with its legend on the right.
fn figure(panel: Panel) -> Result<String, String> {
    Figure {
        panels: vec![panel],
        panel_width: 1020,
        plot_height: 540,
        legend: LegendPlace::Right,
    }
    .svg()
}

/// Round-trip variants drawn, in legend order.
const VARIANTS: [&str; 10] = [
    "complex",
    "real",
    "complex-noskip",
    "complex-tol1e-10",
    "complex-tol1e-6",
    "partial-m8",
    "partial-m8-real",
    "s2-complex",
    "s2-real",
    "reference",
];

/// ` (~B^p)` for a variant whose error follows a power law (not the tolerance variants,
/// whose error saturates at their threshold).
fn growth_label(growths: &[Growth], variant: &str) -> String {
    if variant.contains("tol") {
        return String::new();
    }
    growths
        .iter()
        .find(|g| g.test == "roundtrip" && g.variant == variant)
        .and_then(|g| g.rel_exponent)
        .map_or(String::new(), |p| format!(" (~B^{p:.2})"))
}

/// The error against the bandwidth: round-trip relative L2 error per variant (with the
/// fitted exponent in the legend) and the errors against the exact reference.
pub fn error_svg(rows: &[Row], growths: &[Growth]) -> Result<String, String> {
    let best_isa = crate::reference::isa_name(crate::reference::supported_isas()[0]);
    let mut series = Vec::new();
    for (i, v) in VARIANTS.iter().enumerate() {
        let (label, test, variant) = if *v == "reference" {
            (
                "inverse vs 40-digit reference".to_string(),
                "reference-inverse",
                best_isa,
            )
        } else {
            (format!("{v}{}", growth_label(growths, v)), "roundtrip", *v)
        };
        let dashed = v.contains("tol") || v.contains("noskip") || *v == "reference";
        let line = if dashed { Line::Dashed } else { Line::Solid };
        let mut s = Series::new(label, hex(PALETTE[i % PALETTE.len()]), line, Marker::Circle);
        for r in rows
            .iter()
            .filter(|r| r.test == test && r.variant == variant)
        {
            s.push(r.b as f64, r.rel_l2);
        }
        series.push(s);
    }
    figure(Panel {
        title: "so3fft: relative L2 error of forward(inverse(c)) against B".into(),
        x_label: "bandwidth B".into(),
        y_label: "relative L2 error".into(),
        x_ticks: XTicks::PowersOfTwo,
        series,
        x_rules: vec![Rule {
            at: 1024.0,
            label: "SOFT 2.0's Wigner-d: wrong / Inf from B = 1024".into(),
        }],
        y_rules: vec![
            Rule {
                at: 1e-14,
                label: "target SO(3) 1e-14".into(),
            },
            Rule {
                at: 1e-12,
                label: "target S^2 B=2048: 1e-12".into(),
            },
        ],
    })
}

/// Reference figures measured on this machine (docs/reference-figures.md): seconds for
/// inverse + forward against the error, labelled with the bandwidth.
fn peer_series() -> Vec<Series> {
    let peer = |label: &str, colour: &str, points: &[(f64, f64)], bs: &[usize]| {
        let mut s = Series::new(label, hex(colour), Line::NoLine, Marker::Square);
        for (&(t, e), b) in points.iter().zip(bs) {
            s.push_labelled(t, e, format!("B={b}"));
        }
        s
    };
    vec![
        peer(
            "SOFT 2.0 SO(3), 1 thread (max abs)",
            "#000000",
            &[(1.45 + 1.42, 7e-14), (15.3 + 15.6, 2.2e-13)],
            &[128, 256],
        ),
        peer(
            "SOFT 2.0 S^2 semi-memo (max abs)",
            "#777777",
            &[
                (6.2e-4 + 5.5e-4, 3.7e-13),
                (3.4e-3 + 2.6e-3, 8.3e-13),
                (0.019 + 0.013, 3.1e-12),
                (0.083 + 0.058, 1.8e-11),
            ],
            &[64, 128, 256, 512],
        ),
        peer(
            "ducc0 S^2, 2 threads (max rel)",
            "#AA4499",
            &[
                (0.14e-3 + 0.43e-3, 1.0e-14),
                (0.79e-3 + 1.02e-3, 2.9e-14),
                (3.4e-3 + 4.0e-3, 1.2e-13),
                (13.4e-3 + 20.5e-3, 3.7e-13),
                (57e-3 + 94e-3, 3.4e-12),
            ],
            &[64, 128, 256, 512, 1024],
        ),
    ]
}

/// Run time (inverse + forward) against the round-trip max abs error: one point per
/// bandwidth and way of running, and the peers' published figures as squares.
pub fn time_svg(rows: &[Row]) -> Result<String, String> {
    // (test, variant, legend label, colour index, dashed)
    let mut kinds: Vec<(&str, &str, String, usize, bool)> = VARIANTS
        .iter()
        .filter(|v| **v != "reference")
        .enumerate()
        .map(|(i, v)| {
            let dashed = v.contains("tol") || v.contains("noskip");
            ("roundtrip", *v, v.to_string(), i, dashed)
        })
        .collect();
    // Matching: the angle to the true rotation (rad) against the pipeline's time.
    for (k, v) in ["match-grid", "match-grid-2x", "match-refined"]
        .iter()
        .enumerate()
    {
        let label = format!("{v} (angle error, rad; labels = L)");
        kinds.push(("matching", v, label, VARIANTS.len() + k, true));
    }
    let mut series = Vec::new();
    for (test, variant, label, colour, dashed) in kinds {
        let line = if dashed { Line::Dashed } else { Line::Solid };
        let colour = hex(PALETTE[colour % PALETTE.len()]);
        let mut s = Series::new(label, colour, line, Marker::Circle);
        for r in rows
            .iter()
            .filter(|r| r.test == test && r.variant == variant && r.time_s > 0.0)
        {
            s.push_labelled(r.time_s, r.max_abs, r.b.to_string());
        }
        series.push(s);
    }
    series.extend(peer_series());
    figure(Panel {
        title: "Run time against error: inverse + forward, labels = B".into(),
        x_label: "seconds (inverse + forward; so3fft on all cores of this run)".into(),
        y_label: "round-trip max abs error".into(),
        x_ticks: XTicks::Decades,
        series,
        x_rules: Vec::new(),
        y_rules: Vec::new(),
    })
}
