//! The stress suite's charts, log-log: the round-trip error against the bandwidth per way of
//! running and precision, and the run time against the error in three panels (SO(3), S^2,
//! matching), `f64` and `f32` in each, with SOFT 2.0's and ducc0's figures on this machine
//! as labelled reference points.

use crate::precision::Precision;
use crate::record::{Growth, Row};
use so3fft_tools::chart::{hex, Figure, LegendPlace, Line, Marker, Panel, Rule, Series, XTicks};

/// Colour-blind safe colours (Okabe-Ito) and two greys.
const PALETTE: [&str; 10] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#882255",
    "#777777", "#44AA99",
];

/// Panels stacked, each with its legend on the right.
fn figure(panels: Vec<Panel>, plot_height: u32) -> Result<String, String> {
    Figure {
        panels,
        panel_width: 1020,
        plot_height,
        legend: LegendPlace::Right,
        columns: 1,
    }
    .svg()
}

/// How a precision is drawn: `f64` solid lines and circles, `f32` dashed lines and
/// triangles, in the colour of the way of running.
fn style(p: Precision) -> (Line, Marker) {
    match p {
        Precision::F64 => (Line::Solid, Marker::Circle),
        Precision::F32 => (Line::Dashed, Marker::Triangle),
    }
}

/// A series of one way of running in one precision.
fn series(label: String, colour: &str, p: Precision) -> Series {
    let (line, marker) = style(p);
    Series::new(label, hex(colour), line, marker)
}

/// Round-trip variants of the error chart, in legend order (skipping off is left out: its
/// errors are those of `complex`, see the time chart).
const VARIANTS: [&str; 6] = [
    "complex",
    "real",
    "partial-m8",
    "partial-m8-real",
    "s2-complex",
    "s2-real",
];

/// ` (~B^p)`: the fitted exponent of a round trip's relative error, where the points
/// follow a power law (`r^2 >= 0.9`; not where an f32 plan switches to double-precision
/// recurrences part of the way).
fn growth_label(growths: &[Growth], variant: &str, p: Precision) -> String {
    growths
        .iter()
        .find(|g| g.test == "roundtrip" && g.variant == variant && g.precision == p)
        .filter(|g| g.rel_r2.is_some_and(|r2| r2 >= 0.9))
        .and_then(|g| g.rel_exponent)
        .map_or(String::new(), |e| format!(" (~B^{e:.2})"))
}

/// The error against the bandwidth: round-trip relative L2 error per variant and precision
/// (with the fitted exponent in the legend) and the errors against the exact reference.
pub fn error_svg(rows: &[Row], growths: &[Growth]) -> Result<String, String> {
    let best_isa = crate::reference::isa_name(crate::reference::supported_isas()[0]);
    let mut all = Vec::new();
    for (i, v) in VARIANTS.iter().enumerate() {
        for p in Precision::ALL {
            let mut s = series(format!("{v} {p}"), PALETTE[i], p);
            for r in rows
                .iter()
                .filter(|r| r.test == "roundtrip" && r.variant == *v && r.precision == p)
            {
                s.push(r.b as f64, r.rel_l2);
            }
            s.label += &growth_label(growths, v, p);
            all.push(s);
        }
    }
    for p in Precision::ALL {
        let label = format!("inverse vs 40-digit reference {p}");
        let mut s = series(label, PALETTE[6], p);
        s.line = Line::Dotted;
        for r in rows
            .iter()
            .filter(|r| r.test == "reference-inverse" && r.variant == best_isa && r.precision == p)
        {
            s.push(r.b as f64, r.rel_l2);
        }
        all.push(s);
    }
    figure(
        vec![Panel {
            title: "so3fft: relative L2 error of forward(inverse(c)) against B, f64 and f32".into(),
            x_label: "bandwidth B".into(),
            y_label: "relative L2 error".into(),
            x_ticks: XTicks::PowersOfTwo,
            series: all,
            x_rules: vec![Rule {
                at: 1024.0,
                label: "SOFT 2.0's Wigner-d: wrong / Inf from B = 1024".into(),
            }],
            y_rules: vec![
                Rule {
                    at: 1e-14,
                    label: "target SO(3) f64: 1e-14".into(),
                },
                Rule {
                    at: 1e-12,
                    label: "target S^2 f64 B=2048: 1e-12".into(),
                },
                Rule {
                    at: crate::targets::F32_ROUND_TRIP,
                    label: "target f32 up to B=512: 1e-5".into(),
                },
            ],
        }],
        600,
    )
}

/// A peer's figures measured on this machine (docs/reference-figures.md): seconds for
/// inverse + forward against the error, labelled with the bandwidth.
fn peer(label: &str, colour: &str, points: &[(f64, f64)], bs: &[usize]) -> Series {
    let mut s = Series::new(label, hex(colour), Line::NoLine, Marker::Square);
    for (&(t, e), b) in points.iter().zip(bs) {
        s.push_labelled(t, e, format!("B={b}"));
    }
    s
}

/// SOFT 2.0's SO(3) transforms (one thread; the round trip's max abs error).
fn soft_so3() -> Series {
    peer(
        "SOFT 2.0 SO(3), 1 thread (max abs)",
        "#000000",
        &[(1.45 + 1.42, 7e-14), (15.3 + 15.6, 2.2e-13)],
        &[128, 256],
    )
}

/// SOFT 2.0's and ducc0's S^2 transforms.
fn s2_peers() -> Vec<Series> {
    vec![
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

/// One way of running in a time panel: (test, variant, colour, the precisions whose points
/// are labelled).
type TimeVariant = (
    &'static str,
    &'static str,
    &'static str,
    &'static [Precision],
);

const BOTH: &[Precision] = &Precision::ALL;
const F64_ONLY: &[Precision] = &[Precision::F64];
const NONE: &[Precision] = &[];

/// The series of `variants` in both precisions: time against the max abs error (the
/// angle error for matching), labelled with B where asked.
fn time_series(rows: &[Row], variants: &[TimeVariant]) -> Vec<Series> {
    let mut out = Vec::new();
    for &(test, variant, colour, labelled) in variants {
        for p in Precision::ALL {
            let mut s = series(format!("{variant} {p}"), colour, p);
            for r in rows.iter().filter(|r| {
                r.test == test && r.variant == variant && r.precision == p && r.time_s > 0.0
            }) {
                if labelled.contains(&p) {
                    s.push_labelled(r.time_s, r.max_abs, r.b.to_string());
                } else {
                    s.push(r.time_s, r.max_abs);
                }
            }
            out.push(s);
        }
    }
    out
}

/// A time panel.
fn time_panel(title: &str, y_label: &str, series: Vec<Series>) -> Panel {
    Panel {
        title: title.into(),
        x_label: "seconds (so3fft on all cores of this run)".into(),
        y_label: y_label.into(),
        x_ticks: XTicks::Decades,
        series,
        x_rules: Vec::new(),
        y_rules: Vec::new(),
    }
}

/// Run time against error, one panel per kind: SO(3) and S^2 round trips (inverse +
/// forward against the max abs error; the peers' figures as squares), and matching (the
/// pipeline against the angle to the true rotation). `f64` solid with circles, `f32`
/// dashed with triangles; labels = B (L for matching).
pub fn time_svg(rows: &[Row]) -> Result<String, String> {
    let so3: [TimeVariant; 5] = [
        ("roundtrip", "complex", PALETTE[0], BOTH),
        ("roundtrip", "real", PALETTE[1], NONE),
        ("roundtrip", "complex-noskip", PALETTE[8], NONE),
        ("roundtrip", "partial-m8", PALETTE[2], BOTH),
        ("roundtrip", "partial-m8-real", PALETTE[3], NONE),
    ];
    let mut so3_series = time_series(rows, &so3);
    so3_series.push(soft_so3());
    let s2: [TimeVariant; 2] = [
        ("roundtrip", "s2-complex", PALETTE[4], BOTH),
        ("roundtrip", "s2-real", PALETTE[5], NONE),
    ];
    let mut s2_series = time_series(rows, &s2);
    s2_series.extend(s2_peers());
    // The grid peaks of f32 are those of f64 (same angles): their labels would overlap.
    let matching: [TimeVariant; 3] = [
        ("matching", "match-grid", PALETTE[0], F64_ONLY),
        ("matching", "match-grid-2x", PALETTE[1], NONE),
        ("matching", "match-refined", PALETTE[2], BOTH),
    ];
    let match_series = time_series(rows, &matching);
    figure(
        vec![
            time_panel(
                "SO(3) round trips: inverse + forward, labels = B",
                "round-trip max abs error",
                so3_series,
            ),
            time_panel(
                "S^2 round trips: inverse + forward, labels = B",
                "round-trip max abs error",
                s2_series,
            ),
            time_panel(
                "Rotational matching: correlation grid + argmax (+ refinement), labels = L",
                "angle to the true rotation (rad)",
                match_series,
            ),
        ],
        440,
    )
}
