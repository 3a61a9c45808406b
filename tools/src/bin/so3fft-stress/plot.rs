//! Hand-written SVG charts (no plotting crate), log-log: the round-trip error against the
//! bandwidth per way of running, and the run time against the error with SOFT 2.0's and
//! ducc0's figures on this machine as labelled reference points.

use crate::record::{Growth, Row};
use std::fmt::Write as _;

const WIDTH: f64 = 900.0;
const PLOT_H: f64 = 430.0;
const LEFT: f64 = 80.0;
const RIGHT: f64 = 250.0;
const TOP: f64 = 50.0;
const BOTTOM: f64 = 55.0;
/// Colour-blind safe colours (Okabe-Ito) and two greys.
const PALETTE: [&str; 10] = [
    "#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#882255",
    "#777777", "#44AA99",
];

/// One line of points.
struct Series {
    label: String,
    color: &'static str,
    dashed: bool,
    /// Points only (reference figures), no line.
    scatter: bool,
    points: Vec<(f64, f64)>,
    /// A text beside each point (bandwidths), or none.
    point_labels: Vec<String>,
}

/// A log-log chart.
struct Chart {
    title: String,
    x_label: String,
    y_label: String,
    series: Vec<Series>,
    /// Vertical marker lines: (x, label).
    vlines: Vec<(f64, String)>,
    /// Horizontal marker lines: (y, label).
    hlines: Vec<(f64, String)>,
    /// x ticks at powers of two (bandwidths) instead of decades.
    x_powers_of_two: bool,
}

fn decade_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let (a, b) = (lo.log10().floor(), hi.log10().ceil());
    (a, if b > a { b } else { a + 1.0 })
}

impl Chart {
    fn svg(&self) -> String {
        let xs = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.0));
        let xs = xs.chain(self.vlines.iter().map(|v| v.0));
        let (x0, x1) = if self.x_powers_of_two {
            octave_range(xs)
        } else {
            decade_range(xs)
        };
        let ys = self
            .series
            .iter()
            .flat_map(|s| s.points.iter().map(|p| p.1));
        let (y0, y1) = decade_range(ys.chain(self.hlines.iter().map(|h| h.0)));
        let plot_w = WIDTH - LEFT - RIGHT;
        let px = |x: f64| LEFT + (x.log10() - x0) / (x1 - x0) * plot_w;
        let py = |y: f64| TOP + (y1 - y.log10()) / (y1 - y0) * PLOT_H;
        let height = TOP + PLOT_H + BOTTOM;
        let mut out = String::new();
        let _ = writeln!(
            out,
            r#"<svg xmlns="http://www.w3.org/2000/svg" width="{WIDTH}" height="{height}" viewBox="0 0 {WIDTH} {height}" font-family="sans-serif" font-size="12">"#
        );
        let _ = writeln!(out, r#"<rect width="100%" height="100%" fill="white"/>"#);
        let _ = writeln!(
            out,
            r#"<text x="{}" y="24" font-size="15" text-anchor="middle">{}</text>"#,
            LEFT + plot_w / 2.0,
            escape(&self.title)
        );
        // Grid and ticks, one per decade (or per power of two).
        let x_ticks: Vec<(f64, String)> = if self.x_powers_of_two {
            let (a, b) = (10f64.powf(x0).log2().round(), 10f64.powf(x1).log2().round());
            (a as i32..=b as i32)
                .map(|k| (2f64.powi(k), format!("{}", 1u64 << k.max(0))))
                .collect()
        } else {
            (x0 as i32..=x1 as i32)
                .map(|d| (10f64.powi(d), format!("1e{d}")))
                .collect()
        };
        for (value, label) in x_ticks {
            let x = px(value);
            let _ = writeln!(
                out,
                "<line x1=\"{x:.1}\" y1=\"{TOP}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"#ddd\"/>\n<text x=\"{x:.1}\" y=\"{:.1}\" text-anchor=\"middle\">{label}</text>",
                TOP + PLOT_H,
                TOP + PLOT_H + 18.0
            );
        }
        for d in y0 as i32..=y1 as i32 {
            let y = py(10f64.powi(d));
            let _ = writeln!(
                out,
                "<line x1=\"{LEFT}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#ddd\"/>\n<text x=\"{:.1}\" y=\"{:.1}\" text-anchor=\"end\">1e{d}</text>",
                LEFT + plot_w,
                LEFT - 6.0,
                y + 4.0
            );
        }
        let _ = writeln!(
            out,
            r#"<rect x="{LEFT}" y="{TOP}" width="{plot_w}" height="{PLOT_H}" fill="none" stroke="black"/>"#
        );
        let _ = writeln!(
            out,
            r#"<text x="{:.1}" y="{:.1}" text-anchor="middle">{}</text>"#,
            LEFT + plot_w / 2.0,
            TOP + PLOT_H + 42.0,
            escape(&self.x_label)
        );
        let _ = writeln!(
            out,
            r#"<text transform="translate(20 {:.1}) rotate(-90)" text-anchor="middle">{}</text>"#,
            TOP + PLOT_H / 2.0,
            escape(&self.y_label)
        );
        for (x, label) in &self.vlines {
            let x = px(*x);
            let _ = writeln!(
                out,
                "<line x1=\"{x:.1}\" y1=\"{TOP}\" x2=\"{x:.1}\" y2=\"{:.1}\" stroke=\"#b00\" stroke-dasharray=\"6 4\"/>\n<text x=\"{:.1}\" y=\"{:.1}\" fill=\"#b00\" font-size=\"11\" text-anchor=\"end\">{}</text>",
                TOP + PLOT_H,
                x - 4.0,
                TOP + 14.0,
                escape(label)
            );
        }
        for (y, label) in &self.hlines {
            let y = py(*y);
            let _ = writeln!(
                out,
                "<line x1=\"{LEFT}\" y1=\"{y:.1}\" x2=\"{:.1}\" y2=\"{y:.1}\" stroke=\"#b00\" stroke-dasharray=\"2 3\"/>\n<text x=\"{:.1}\" y=\"{:.1}\" fill=\"#b00\" font-size=\"11\">{}</text>",
                LEFT + plot_w,
                LEFT + 4.0,
                y - 3.0,
                escape(label)
            );
        }
        for s in self.series.iter().filter(|s| !s.points.is_empty()) {
            let path: Vec<String> = s
                .points
                .iter()
                .map(|&(x, y)| format!("{:.1},{:.1}", px(x), py(y)))
                .collect();
            if !s.scatter {
                let dash = if s.dashed {
                    r#" stroke-dasharray="5 3""#
                } else {
                    ""
                };
                let _ = writeln!(
                    out,
                    r#"<polyline points="{}" fill="none" stroke="{}" stroke-width="1.6"{dash}/>"#,
                    path.join(" "),
                    s.color
                );
            }
            for (i, &(x, y)) in s.points.iter().enumerate() {
                let (cx, cy) = (px(x), py(y));
                if s.scatter {
                    let _ = writeln!(
                        out,
                        r#"<rect x="{:.1}" y="{:.1}" width="8" height="8" fill="none" stroke="{}" stroke-width="1.6"/>"#,
                        cx - 4.0,
                        cy - 4.0,
                        s.color
                    );
                } else {
                    let _ = writeln!(
                        out,
                        r#"<circle cx="{cx:.1}" cy="{cy:.1}" r="3" fill="{}"/>"#,
                        s.color
                    );
                }
                if let Some(label) = s.point_labels.get(i) {
                    let _ = writeln!(
                        out,
                        r#"<text x="{:.1}" y="{:.1}" font-size="9" fill="{}">{}</text>"#,
                        cx + 5.0,
                        cy - 4.0,
                        s.color,
                        escape(label)
                    );
                }
            }
        }
        // Legend on the right.
        let lx = LEFT + plot_w + 14.0;
        for (i, s) in self
            .series
            .iter()
            .filter(|s| !s.points.is_empty())
            .enumerate()
        {
            let y = TOP + 8.0 + 17.0 * i as f64;
            if s.scatter {
                let _ = writeln!(
                    out,
                    r#"<rect x="{:.1}" y="{:.1}" width="8" height="8" fill="none" stroke="{}" stroke-width="1.6"/>"#,
                    lx + 6.0,
                    y - 4.0,
                    s.color
                );
            } else {
                let dash = if s.dashed {
                    r#" stroke-dasharray="5 3""#
                } else {
                    ""
                };
                let _ = writeln!(
                    out,
                    r#"<line x1="{lx:.1}" y1="{y:.1}" x2="{:.1}" y2="{y:.1}" stroke="{}" stroke-width="1.6"{dash}/>"#,
                    lx + 20.0,
                    s.color
                );
            }
            let _ = writeln!(
                out,
                r#"<text x="{:.1}" y="{:.1}" font-size="11">{}</text>"#,
                lx + 26.0,
                y + 4.0,
                escape(&s.label)
            );
        }
        out.push_str("</svg>\n");
        out
    }
}

/// `log10` of the powers of two around the positive values (the x range of a bandwidth axis).
fn octave_range(values: impl Iterator<Item = f64>) -> (f64, f64) {
    let (lo, hi) = values
        .filter(|v| v.is_finite() && *v > 0.0)
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| {
            (a.min(v), b.max(v))
        });
    if !lo.is_finite() {
        return (0.0, 1.0);
    }
    let (a, b) = (
        lo.log2().floor(),
        hi.log2().ceil().max(lo.log2().floor() + 1.0),
    );
    (2f64.powf(a).log10(), 2f64.powf(b).log10())
}

fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
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
pub fn error_svg(rows: &[Row], growths: &[Growth]) -> String {
    let best_isa = crate::reference::isa_name(crate::reference::supported_isas()[0]);
    let mut series = Vec::new();
    for (i, v) in VARIANTS.iter().enumerate() {
        let (label, points): (String, Vec<(f64, f64)>) = if *v == "reference" {
            let pts = rows
                .iter()
                .filter(|r| r.test == "reference-inverse" && r.variant == best_isa)
                .map(|r| (r.b as f64, r.rel_l2))
                .collect();
            ("inverse vs 40-digit reference".into(), pts)
        } else {
            let pts = rows
                .iter()
                .filter(|r| r.test == "roundtrip" && r.variant == *v)
                .map(|r| (r.b as f64, r.rel_l2))
                .collect();
            (format!("{v}{}", growth_label(growths, v)), pts)
        };
        series.push(Series {
            label,
            color: PALETTE[i % PALETTE.len()],
            dashed: v.contains("tol") || v.contains("noskip") || *v == "reference",
            scatter: false,
            points,
            point_labels: Vec::new(),
        });
    }
    Chart {
        title: "so3fft: relative L2 error of forward(inverse(c)) against B".into(),
        x_label: "bandwidth B".into(),
        y_label: "relative L2 error".into(),
        series,
        vlines: vec![(
            1024.0,
            "SOFT 2.0's Wigner-d: wrong / Inf from B = 1024".into(),
        )],
        hlines: vec![
            (1e-14, "target SO(3) 1e-14".into()),
            (1e-12, "target S^2 B=2048: 1e-12".into()),
        ],
        x_powers_of_two: true,
    }
    .svg()
}

/// Reference figures measured on this machine (docs/reference-figures.md): (label, colour,
/// points (seconds for inverse + forward, error), point labels).
fn peer_series() -> Vec<Series> {
    let peer = |label: &str, color, points: Vec<(f64, f64)>, bs: &[usize]| Series {
        label: label.into(),
        color,
        dashed: false,
        scatter: true,
        points,
        point_labels: bs.iter().map(|b| format!("B={b}")).collect(),
    };
    vec![
        peer(
            "SOFT 2.0 SO(3), 1 thread (max abs)",
            "#000000",
            vec![(1.45 + 1.42, 7e-14), (15.3 + 15.6, 2.2e-13)],
            &[128, 256],
        ),
        peer(
            "SOFT 2.0 S^2 semi-memo (max abs)",
            "#777777",
            vec![
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
            vec![
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
pub fn time_svg(rows: &[Row]) -> String {
    let mut series = Vec::new();
    for (i, v) in VARIANTS.iter().filter(|v| **v != "reference").enumerate() {
        let picked: Vec<&Row> = rows
            .iter()
            .filter(|r| r.test == "roundtrip" && r.variant == *v && r.time_s > 0.0)
            .collect();
        series.push(Series {
            label: (*v).to_string(),
            color: PALETTE[i % PALETTE.len()],
            dashed: v.contains("tol") || v.contains("noskip"),
            scatter: false,
            points: picked.iter().map(|r| (r.time_s, r.max_abs)).collect(),
            point_labels: picked.iter().map(|r| r.b.to_string()).collect(),
        });
    }
    // Matching: the angle to the true rotation (rad) against the pipeline's time.
    for (k, v) in ["match-grid", "match-grid-2x", "match-refined"]
        .iter()
        .enumerate()
    {
        let picked: Vec<&Row> = rows
            .iter()
            .filter(|r| r.test == "matching" && r.variant == *v && r.time_s > 0.0)
            .collect();
        series.push(Series {
            label: format!("{v} (angle error, rad; labels = L)"),
            color: PALETTE[(VARIANTS.len() + k) % PALETTE.len()],
            dashed: true,
            scatter: false,
            points: picked.iter().map(|r| (r.time_s, r.max_abs)).collect(),
            point_labels: picked.iter().map(|r| r.b.to_string()).collect(),
        });
    }
    series.extend(peer_series());
    Chart {
        title: "Run time against error: inverse + forward, labels = B".into(),
        x_label: "seconds (inverse + forward; so3fft on all cores of this run)".into(),
        y_label: "round-trip max abs error".into(),
        series,
        vlines: Vec::new(),
        hlines: Vec::new(),
        x_powers_of_two: false,
    }
    .svg()
}
