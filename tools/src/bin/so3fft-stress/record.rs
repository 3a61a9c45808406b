//! Results: one row per test, bandwidth, variant and precision; error measures; the table,
//! the CSV and the least-squares growth exponents.

use crate::precision::{widen_one, Float, Precision};
use so3fft::Complex;
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
    /// Element type of the transforms.
    pub precision: Precision,
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

/// Errors of complex values, computed in `f64` (`f32` values widened, exactly).
pub fn errors<T: Float, U: Float>(got: &[Complex<T>], want: &[Complex<U>]) -> Errors {
    assert_eq!(got.len(), want.len());
    let (mut diff2, mut norm2, mut max_abs) = (0.0, 0.0, 0.0f64);
    for (&g, &w) in got.iter().zip(want) {
        let (g, w) = (widen_one(g), widen_one(w));
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

/// Errors of real values, computed in `f64`.
pub fn errors_real<T: Float>(got: &[T], want: &[T]) -> Errors {
    assert_eq!(got.len(), want.len());
    let (mut diff2, mut norm2, mut max_abs) = (0.0, 0.0, 0.0f64);
    for (g, w) in got.iter().zip(want) {
        let (g, w) = (g.widened(), w.widened());
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
pub fn bit_differences<T: Float>(a: &[Complex<T>], b: &[Complex<T>]) -> usize {
    a.iter()
        .zip(b)
        .filter(|(x, y)| {
            x.re.bit_pattern() != y.re.bit_pattern() || x.im.bit_pattern() != y.im.bit_pattern()
        })
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
            precision: case.precision,
            rel_l2: e.rel_l2,
            max_abs: e.max_abs,
            time_s,
            note: note.into(),
        });
    }

    /// The table's header line (the rows print as they are measured).
    pub fn header() -> String {
        format!(
            "{:<22} {:>5} {:<22} {:<4} {:>9} {:>9} {:>9}  note",
            "test", "B", "variant", "prec", "rel L2", "max abs", "time s"
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
    /// Element type.
    pub precision: Precision,
}

fn format_row(r: &Row) -> String {
    format!(
        "{:<22} {:>5} {:<22} {:<4} {:>9.2e} {:>9.2e} {:>9.3e}  {}",
        r.test, r.b, r.variant, r.precision, r.rel_l2, r.max_abs, r.time_s, r.note
    )
}

/// Least-squares slope of `log y` against `log x` (points with non-positive or non-finite
/// `y` left out) and the fit's coefficient of determination `r^2` (1: the points lie on a
/// power law; 1 also for two points or a flat series); `None` with fewer than two points.
pub fn growth_fit(points: &[(f64, f64)]) -> Option<(f64, f64)> {
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
    let syy: f64 = logs.iter().map(|p| (p.1 - my).powi(2)).sum();
    if sxx <= 0.0 {
        return None;
    }
    let slope = sxy / sxx;
    let r2 = if syy > 0.0 {
        sxy * sxy / (sxx * syy)
    } else {
        1.0
    };
    Some((slope, r2))
}

/// A fitted growth: `error ~ C B^exponent` for one test, variant and precision.
#[derive(Clone, Debug)]
pub struct Growth {
    /// Test name.
    pub test: String,
    /// Variant.
    pub variant: String,
    /// Element type.
    pub precision: Precision,
    /// Bandwidths fitted.
    pub bandwidths: Vec<usize>,
    /// Exponent of the relative L2 error.
    pub rel_exponent: Option<f64>,
    /// `r^2` of that fit (near 1: a power law; low: the error changes regime, as the f32
    /// plans do where they switch recurrences).
    pub rel_r2: Option<f64>,
    /// Exponent of the max absolute error.
    pub max_exponent: Option<f64>,
}

/// The distinct `(test, variant)` of `rows` in the order they first appear, each followed by
/// its precisions in [`Precision::ALL`] order: so the `f32` line of a series comes right
/// after its `f64` line in the tables.
pub fn series_keys<'a>(rows: impl Iterator<Item = &'a Row>) -> Vec<(String, String, Precision)> {
    let rows: Vec<&Row> = rows.collect();
    let mut pairs: Vec<(&str, &str)> = Vec::new();
    for r in &rows {
        let pair = (r.test.as_str(), r.variant.as_str());
        if !pairs.contains(&pair) {
            pairs.push(pair);
        }
    }
    let mut keys = Vec::new();
    for (test, variant) in pairs {
        for p in Precision::ALL {
            if rows
                .iter()
                .any(|r| r.test == test && r.variant == variant && r.precision == p)
            {
                keys.push((test.to_string(), variant.to_string(), p));
            }
        }
    }
    keys
}

/// Growth exponents of every (test, variant, precision) series of `tests` with at least
/// three bandwidths.
pub fn growths(rows: &[Row], tests: &[&str]) -> Vec<Growth> {
    series_keys(rows.iter().filter(|r| tests.contains(&r.test.as_str())))
        .into_iter()
        .filter_map(|(test, variant, precision)| {
            let series: Vec<&Row> = rows
                .iter()
                .filter(|r| r.test == test && r.variant == variant && r.precision == precision)
                .collect();
            if series.len() < 3 {
                return None;
            }
            let fit = |f: fn(&Row) -> f64| {
                growth_fit(
                    &series
                        .iter()
                        .map(|r| (r.b as f64, f(r)))
                        .collect::<Vec<_>>(),
                )
            };
            let rel = fit(|r| r.rel_l2);
            Some(Growth {
                bandwidths: series.iter().map(|r| r.b).collect(),
                rel_exponent: rel.map(|f| f.0),
                rel_r2: rel.map(|f| f.1),
                max_exponent: fit(|r| r.max_abs).map(|f| f.0),
                test,
                variant,
                precision,
            })
        })
        .collect()
}

/// The growth table as text.
pub fn growth_table(growths: &[Growth]) -> String {
    let mut out = format!(
        "{:<22} {:<22} {:<4} {:>12} {:>5} {:>12}  bandwidths\n",
        "test", "variant", "prec", "rel L2 ~ B^", "r^2", "max abs ~ B^"
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
            "{:<22} {:<22} {:<4} {:>12} {:>5} {:>12}  {}",
            g.test,
            g.variant,
            g.precision,
            show(g.rel_exponent),
            show(g.rel_r2),
            show(g.max_exponent),
            bs.join(",")
        );
    }
    out
}

/// Columns of the CSV file.
const CSV_HEADER: [&str; 8] = [
    "test",
    "B",
    "variant",
    "precision",
    "rel_l2",
    "max_abs",
    "time_s",
    "note",
];

/// Columns of the files of earlier versions, whose rows are all `f64`.
const CSV_HEADER_F64_ONLY: [&str; 7] = [
    "test", "B", "variant", "rel_l2", "max_abs", "time_s", "note",
];

/// Writes the rows as CSV (header line first).
pub fn write_csv(path: &Path, rows: &[Row]) -> csv::Result<()> {
    let records = rows.iter().map(|r| {
        [
            r.test.clone(),
            r.b.to_string(),
            r.variant.clone(),
            r.precision.name().to_string(),
            format!("{:.3e}", r.rel_l2),
            format!("{:.3e}", r.max_abs),
            format!("{:.4e}", r.time_s),
            r.note.clone(),
        ]
    });
    so3fft_tools::csv_out::write(path, &CSV_HEADER, records)
}

/// The rows of a CSV file written by [`write_csv`], or by an earlier version without the
/// precision column (rows `f64`). Files of earlier versions also left a variant holding a
/// comma (`M=B-1,M'=-(B-1)`) unquoted: its pieces are joined again.
pub fn read_csv(path: &Path) -> Result<Vec<Row>, String> {
    let (records, with_precision) = match so3fft_tools::csv_out::read(path, &CSV_HEADER) {
        Ok(records) => (records, true),
        Err(e) => match so3fft_tools::csv_out::read(path, &CSV_HEADER_F64_ONLY) {
            Ok(records) => (records, false),
            Err(_) => return Err(e),
        },
    };
    // Fields after the variant: [precision,] three numbers, the note.
    let after = if with_precision { 5 } else { 4 };
    records
        .iter()
        .enumerate()
        .map(|(i, rec)| {
            // Line i + 2: the header is line 1.
            let bad = |what: &str| format!("{}: line {}: bad {what}", path.display(), i + 2);
            let n = rec.len();
            if n < 2 + 1 + after {
                return Err(bad("record (too few fields)"));
            }
            // The three numbers before the note, counted from the end.
            let number =
                |k: usize, what: &str| rec[n - 4 + k].trim().parse::<f64>().map_err(|_| bad(what));
            let variant: Vec<&str> = rec.iter().skip(2).take(n - 2 - after).collect();
            let precision = if with_precision {
                Precision::parse(&rec[n - 5]).ok_or_else(|| bad("precision"))?
            } else {
                Precision::F64
            };
            Ok(Row {
                test: rec[0].to_string(),
                b: rec[1].trim().parse().map_err(|_| bad("B"))?,
                variant: variant.join(","),
                precision,
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
    use super::{growth_fit, read_csv, series_keys, write_csv, Precision, Row};

    fn row(variant: &str, rel_l2: f64, note: &str) -> Row {
        Row {
            test: "top-order-inverse".into(),
            b: 16,
            variant: variant.into(),
            precision: Precision::F64,
            rel_l2,
            max_abs: 4.578e-16,
            time_s: 3.6345e-4,
            note: note.into(),
        }
    }

    /// Rows come back from the CSV as written (commas in variants and notes, NaN, the
    /// precision), files without the precision column are read as `f64`, and the unquoted
    /// variants of older files are joined again.
    #[test]
    fn csv_round_trip_and_old_files() {
        let dir = std::env::temp_dir();
        let path = dir.join(format!("so3fft-stress-rows-{}.csv", std::process::id()));
        let mut single = row("complex", f64::NAN, "");
        single.precision = Precision::F32;
        let rows = [
            row("M=B-1,M'=-(B-1)", 3.467e-16, "vs closed form, \"quoted\""),
            single,
        ];
        write_csv(&path, &rows).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.starts_with("test,B,variant,precision,rel_l2,"),
            "{text}"
        );
        let back = read_csv(&path).unwrap();
        assert_eq!(back.len(), 2);
        assert_eq!(back[0].variant, rows[0].variant);
        assert_eq!(back[0].note, rows[0].note);
        assert_eq!((back[0].rel_l2, back[0].b), (3.467e-16, 16));
        assert_eq!(
            (back[0].precision, back[1].precision),
            (Precision::F64, Precision::F32)
        );
        assert!(back[1].rel_l2.is_nan());
        std::fs::write(&path, text.replace(",f32,", ",f16,")).unwrap();
        assert!(read_csv(&path).is_err(), "unknown precision accepted");
        let old = "test,B,variant,rel_l2,max_abs,time_s,note\n\
                   top-order-inverse,16,M=B-1,M'=-(B-1),3.467e-16,4.578e-16,3.6345e-4,\"vs x\"\n";
        std::fs::write(&path, old).unwrap();
        let back = read_csv(&path).unwrap();
        assert_eq!(back[0].variant, "M=B-1,M'=-(B-1)");
        assert_eq!(
            (back[0].max_abs, back[0].note.as_str(), back[0].precision),
            (4.578e-16, "vs x", Precision::F64)
        );
        std::fs::write(&path, "test,B\n").unwrap();
        assert!(read_csv(&path).is_err());
        std::fs::remove_file(path).unwrap();
    }

    /// A power law fits exactly; a series that breaks off does not.
    #[test]
    fn fit_quality() {
        let law: Vec<(f64, f64)> = [8.0, 16.0, 32.0].iter().map(|&b| (b, 1e-16 * b)).collect();
        let (slope, r2) = growth_fit(&law).unwrap();
        assert!((slope - 1.0).abs() < 1e-12 && (r2 - 1.0).abs() < 1e-12);
        let broken = [
            (16.0, 3e-7),
            (64.0, 1.2e-6),
            (256.0, 1.2e-7),
            (1024.0, 1.2e-7),
        ];
        assert!(growth_fit(&broken).unwrap().1 < 0.5);
        assert_eq!(growth_fit(&[(8.0, 1.0)]), None);
    }

    /// A series' f32 key follows its f64 key, whatever order the rows came in.
    #[test]
    fn f32_keys_follow_f64_keys() {
        let mut rows = [row("a", 1.0, ""), row("b", 1.0, ""), row("a", 1.0, "")];
        rows[0].precision = Precision::F32;
        let keys: Vec<(String, Precision)> = series_keys(rows.iter())
            .into_iter()
            .map(|k| (k.1, k.2))
            .collect();
        let want = [
            ("a".to_string(), Precision::F64),
            ("a".to_string(), Precision::F32),
            ("b".to_string(), Precision::F64),
        ];
        assert_eq!(keys, want);
    }
}
