//! Results: one row per test, bandwidth and variant; error measures; the table, the CSV
//! and the least-squares growth exponents.

use so3fft::Complex64;
use std::fmt::Write as _;
use std::path::Path;

/// One measured case.
#[derive(Clone, Debug)]
pub struct Row {
    /// Test name (`reference`, `roundtrip`, `parseval`, `adversarial`, ...).
    pub test: String,
    /// Bandwidth.
    pub b: usize,
    /// How it ran (`complex`, `real`, `partial-m8`, `s2-complex`, `avx2`, ...).
    pub variant: String,
    /// Relative L2 error (NaN when it does not apply).
    pub rel_l2: f64,
    /// Max absolute error.
    pub max_abs: f64,
    /// Wall time in seconds of the measured transforms.
    pub time_s: f64,
    /// What else there is to say (bitwise checks, NaN counts).
    pub note: String,
}

/// Relative L2 and max absolute error of a result against the wanted values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Errors {
    /// `||got - want|| / ||want||`.
    pub rel_l2: f64,
    /// `max |got - want|`.
    pub max_abs: f64,
}

/// `max` that keeps a NaN (f64::max would drop it).
fn max_nan(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

/// Errors of complex values.
pub fn errors(got: &[Complex64], want: &[Complex64]) -> Errors {
    assert_eq!(got.len(), want.len());
    let (mut diff2, mut norm2, mut max_abs) = (0.0, 0.0, 0.0f64);
    for (g, w) in got.iter().zip(want) {
        let d = (g - w).norm();
        diff2 += d * d;
        norm2 += w.norm_sqr();
        max_abs = max_nan(max_abs, d);
    }
    Errors {
        rel_l2: (diff2 / norm2).sqrt(),
        max_abs,
    }
}

/// Errors of real values.
pub fn errors_real(got: &[f64], want: &[f64]) -> Errors {
    assert_eq!(got.len(), want.len());
    let (mut diff2, mut norm2, mut max_abs) = (0.0, 0.0, 0.0f64);
    for (g, w) in got.iter().zip(want) {
        let d = (g - w).abs();
        diff2 += d * d;
        norm2 += w * w;
        max_abs = max_nan(max_abs, d);
    }
    Errors {
        rel_l2: (diff2 / norm2).sqrt(),
        max_abs,
    }
}

/// Number of values whose bits differ.
pub fn bit_differences(a: &[Complex64], b: &[Complex64]) -> usize {
    a.iter()
        .zip(b)
        .filter(|(x, y)| x.re.to_bits() != y.re.to_bits() || x.im.to_bits() != y.im.to_bits())
        .count()
}

/// All rows of a run.
#[derive(Default)]
pub struct Report {
    /// Rows in the order they were measured.
    pub rows: Vec<Row>,
    /// Print each row as it comes.
    pub verbose: bool,
}

impl Report {
    /// Adds a row (and prints it when verbose).
    pub fn push(&mut self, row: Row) {
        if self.verbose {
            so3fft_tools::bar_println!("{}", format_row(&row));
            so3fft_tools::progress::message(format!("{} B = {}", row.test, row.b));
        }
        self.rows.push(row);
    }

    /// Adds a row of errors.
    pub fn push_errors(&mut self, case: Case<'_>, e: Errors, time_s: f64, note: &str) {
        self.push(Row {
            test: case.test.into(),
            b: case.b,
            variant: case.variant.into(),
            rel_l2: e.rel_l2,
            max_abs: e.max_abs,
            time_s,
            note: note.into(),
        });
    }

    /// The table's header line (the rows print as they are measured).
    pub fn header() -> String {
        format!(
            "{:<22} {:>5} {:<22} {:>9} {:>9} {:>9}  note",
            "test", "B", "variant", "rel L2", "max abs", "time s"
        )
    }
}

/// Which case a row describes.
#[derive(Clone, Copy)]
pub struct Case<'a> {
    /// Test name.
    pub test: &'a str,
    /// Bandwidth.
    pub b: usize,
    /// Variant.
    pub variant: &'a str,
}

fn format_row(r: &Row) -> String {
    format!(
        "{:<22} {:>5} {:<22} {:>9.2e} {:>9.2e} {:>9.3e}  {}",
        r.test, r.b, r.variant, r.rel_l2, r.max_abs, r.time_s, r.note
    )
}

/// Least-squares slope of `log y` against `log x` (points with non-positive or non-finite
/// `y` left out); `None` with fewer than two points.
pub fn growth_exponent(points: &[(f64, f64)]) -> Option<f64> {
    let logs: Vec<(f64, f64)> = points
        .iter()
        .filter(|(x, y)| *x > 0.0 && y.is_finite() && *y > 0.0)
        .map(|(x, y)| (x.ln(), y.ln()))
        .collect();
    if logs.len() < 2 {
        return None;
    }
    let n = logs.len() as f64;
    let mx = logs.iter().map(|p| p.0).sum::<f64>() / n;
    let my = logs.iter().map(|p| p.1).sum::<f64>() / n;
    let sxx: f64 = logs.iter().map(|p| (p.0 - mx).powi(2)).sum();
    let sxy: f64 = logs.iter().map(|p| (p.0 - mx) * (p.1 - my)).sum();
    (sxx > 0.0).then(|| sxy / sxx)
}

/// A fitted growth: `error ~ C B^exponent` for one test and variant.
#[derive(Clone, Debug)]
pub struct Growth {
    /// Test name.
    pub test: String,
    /// Variant.
    pub variant: String,
    /// Bandwidths fitted.
    pub bandwidths: Vec<usize>,
    /// Exponent of the relative L2 error.
    pub rel_exponent: Option<f64>,
    /// Exponent of the max absolute error.
    pub max_exponent: Option<f64>,
}

/// Growth exponents of every (test, variant) series of `tests` with at least three bandwidths.
pub fn growths(rows: &[Row], tests: &[&str]) -> Vec<Growth> {
    let mut keys: Vec<(String, String)> = Vec::new();
    for r in rows.iter().filter(|r| tests.contains(&r.test.as_str())) {
        let key = (r.test.clone(), r.variant.clone());
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    keys.into_iter()
        .filter_map(|(test, variant)| {
            let series: Vec<&Row> = rows
                .iter()
                .filter(|r| r.test == test && r.variant == variant)
                .collect();
            if series.len() < 3 {
                return None;
            }
            let fit = |f: fn(&Row) -> f64| {
                growth_exponent(
                    &series
                        .iter()
                        .map(|r| (r.b as f64, f(r)))
                        .collect::<Vec<_>>(),
                )
            };
            Some(Growth {
                bandwidths: series.iter().map(|r| r.b).collect(),
                rel_exponent: fit(|r| r.rel_l2),
                max_exponent: fit(|r| r.max_abs),
                test,
                variant,
            })
        })
        .collect()
}

/// The growth table as text.
pub fn growth_table(growths: &[Growth]) -> String {
    let mut out = format!(
        "{:<22} {:<22} {:>12} {:>12}  bandwidths\n",
        "test", "variant", "rel L2 ~ B^", "max abs ~ B^"
    );
    let show = |e: Option<f64>| e.map_or("-".to_string(), |v| format!("{v:.2}"));
    for g in growths {
        let bs = g
            .bandwidths
            .iter()
            .map(|b| b.to_string())
            .collect::<Vec<_>>();
        let _ = writeln!(
            out,
            "{:<22} {:<22} {:>12} {:>12}  {}",
            g.test,
            g.variant,
            show(g.rel_exponent),
            show(g.max_exponent),
            bs.join(",")
        );
    }
    out
}

/// Columns of the CSV file.
const CSV_HEADER: [&str; 7] = [
    "test", "B", "variant", "rel_l2", "max_abs", "time_s", "note",
];

/// Writes the rows as CSV (header line first).
pub fn write_csv(path: &Path, rows: &[Row]) -> csv::Result<()> {
    let records = rows.iter().map(|r| {
        [
            r.test.clone(),
            r.b.to_string(),
            r.variant.clone(),
            format!("{:.3e}", r.rel_l2),
            format!("{:.3e}", r.max_abs),
            format!("{:.4e}", r.time_s),
            r.note.clone(),
        ]
    });
    so3fft_tools::csv_out::write(path, &CSV_HEADER, records)
}

/// The rows of a CSV file written by [`write_csv`]. Files of earlier versions left a variant
/// holding a comma (`M=B-1,M'=-(B-1)`) unquoted: its pieces are joined again.
pub fn read_csv(path: &Path) -> Result<Vec<Row>, String> {
    let records = so3fft_tools::csv_out::read(path, &CSV_HEADER)?;
    records
        .iter()
        .enumerate()
        .map(|(i, rec)| {
            // Line i + 2: the header is line 1.
            let bad = |what: &str| format!("{}: line {}: bad {what}", path.display(), i + 2);
            let n = rec.len();
            if n < CSV_HEADER.len() {
                return Err(bad("record (too few fields)"));
            }
            // The four fields after the variant, counted from the end.
            let number =
                |k: usize, what: &str| rec[n - 4 + k].trim().parse::<f64>().map_err(|_| bad(what));
            let variant: Vec<&str> = rec.iter().skip(2).take(n - 6).collect();
            Ok(Row {
                test: rec[0].to_string(),
                b: rec[1].trim().parse().map_err(|_| bad("B"))?,
                variant: variant.join(","),
                rel_l2: number(0, "rel_l2")?,
                max_abs: number(1, "max_abs")?,
                time_s: number(2, "time_s")?,
                note: rec[n - 1].to_string(),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::{read_csv, write_csv, Row};

    fn row(variant: &str, rel_l2: f64, note: &str) -> Row {
        Row {
            test: "top-order-inverse".into(),
            b: 16,
            variant: variant.into(),
            rel_l2,
            max_abs: 4.578e-16,
            time_s: 3.6345e-4,
            note: note.into(),
        }
    }

    /// Rows come back from the CSV as written (commas in variants and notes, NaN), and the
    /// unquoted variants of older files are joined again.
    #[test]
    fn csv_round_trip_and_old_files() {
        let dir = std::env::temp_dir();
        let path = dir.join(format!("so3fft-stress-rows-{}.csv", std::process::id()));
        let rows = [
            row("M=B-1,M'=-(B-1)", 3.467e-16, "vs closed form, \"quoted\""),
            row("complex", f64::NAN, ""),
        ];
        write_csv(&path, &rows).unwrap();
        let back = read_csv(&path).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[0].variant, rows[0].variant);
        assert_eq!(back[0].note, rows[0].note);
        assert_eq!((back[0].rel_l2, back[0].b), (3.467e-16, 16));
        assert!(back[1].rel_l2.is_nan());
        let old = "test,B,variant,rel_l2,max_abs,time_s,note\n\
                   top-order-inverse,16,M=B-1,M'=-(B-1),3.467e-16,4.578e-16,3.6345e-4,\"vs x\"\n";
        std::fs::write(&path, old).unwrap();
        let back = read_csv(&path).unwrap();
        assert_eq!(back[0].variant, "M=B-1,M'=-(B-1)");
        assert_eq!(
            (back[0].max_abs, back[0].note.as_str()),
            (4.578e-16, "vs x")
        );
        std::fs::write(&path, "test,B\n").unwrap();
        assert!(read_csv(&path).is_err());
        std::fs::remove_file(path).unwrap();
    }
}
