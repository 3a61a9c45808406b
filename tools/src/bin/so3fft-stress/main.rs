//! `so3fft-stress`: the numerical stress suite of so3fft.
//!
//! Tests, each a module:
//! - (a) `reference`: transforms against exact values (40-digit sums in
//!   `tests/data/stress/`), and (e) the same and round trips on every instruction set;
//! - (b) `roundtrip`: `forward(inverse(c))`, `inverse(forward(f))` and Parseval over
//!   doubling bandwidths, full plan complex and real (and with skipping off), order-limited
//!   partial plans, S^2; growth exponents fitted by least squares;
//! - (c) `adversarial`: top-order single coefficients, power-law spectra, exact scaling by
//!   `2^k`, subnormal inputs, NaN and infinite inputs;
//! - (d) `determinism`: bits across 1, 2, 4 threads and repeated executions;
//! - `matching`: rotational matching's angle error and time (points of the time chart).
//!
//! Every test runs in `f64` and in `f32` (`--precision`); each row records its precision.
//!
//! Prints a table (a row per case as it is measured), the fitted exponents and the accuracy
//! targets; `--csv`, `--svg`, `--time-svg` write the results, `--docs DIR` all of them plus
//! the tables in `DIR/stability.md`; `--from-csv` redraws charts and tables from an earlier
//! run's CSV without running a test. See `docs/stability.md`.

mod adversarial;
mod determinism;
mod matching;
mod plot;
mod precision;
mod record;
mod reference;
mod rng;
mod roundtrip;
mod targets;

use clap::{Parser, ValueEnum};
use precision::{Float, Precision};
use record::{Report, Row};
use so3fft_tools::progress::Steps;
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Instant;

/// The numerical stress suite of so3fft: transforms against exact values, round trips over
/// doubling bandwidths, adversarial inputs, determinism across threads, rotational matching
/// and every instruction set, in double and single precision. Prints a row per case as it is measured, the fitted growth
/// exponents and the accuracy targets. See docs/stability.md.
#[derive(Parser, Debug)]
#[command(
    name = "so3fft-stress",
    version,
    args_override_self = true,
    after_help = "Exit status: 0 if every accuracy target that the run covers is met, 1 if one \
                  is missed, 2 on bad arguments, a failed transform or an unwritable output."
)]
struct Options {
    /// Small bandwidths only (SO(3) round trips to 64, partial to 128, S^2 to 256; about
    /// 5 s); without it the full run (SO(3) to 256, partial and S^2 to 2048; a few
    /// minutes, under 6 GB)
    #[arg(long)]
    quick: bool,
    /// Also B = 512 full-grid SO(3) round trips (f64 complex: about 24 GB; f32 complex and
    /// real: about 12 GB)
    #[arg(long)]
    big: bool,
    /// Comma-separated precisions to run [default: f64,f32]
    #[arg(long, value_name = "LIST", value_enum, value_delimiter = ',')]
    precision: Option<Vec<Precision>>,
    /// Worker threads of the transforms (0 = all cores)
    #[arg(long, value_name = "N", default_value_t = 0)]
    threads: usize,
    /// Comma-separated tests to run [default: all]
    #[arg(long, value_name = "LIST", value_enum, value_delimiter = ',')]
    only: Option<Vec<Test>>,
    /// Reference data [default: tests/data/stress of the source tree]
    #[arg(long, value_name = "DIR")]
    data: Option<PathBuf>,
    /// Write every row as CSV
    #[arg(long, value_name = "FILE")]
    csv: Option<PathBuf>,
    /// Write the error-against-bandwidth chart
    #[arg(long, value_name = "FILE")]
    svg: Option<PathBuf>,
    /// Write the time-against-error chart
    #[arg(long, value_name = "FILE")]
    time_svg: Option<PathBuf>,
    /// Write DIR/stability.csv, stability.svg, time-vs-error.svg and the tables of
    /// DIR/stability.md (between its stress-table markers)
    #[arg(long, value_name = "DIR")]
    docs: Option<PathBuf>,
    /// Run no test: read the rows of an earlier run's CSV (as written by --csv or --docs)
    /// and redraw the charts and tables from them (with --docs, the CSV is not rewritten)
    #[arg(
        long,
        value_name = "FILE",
        conflicts_with_all = ["quick", "big", "only", "threads", "precision"]
    )]
    from_csv: Option<PathBuf>,
}

/// The suite's tests, as `--only` names them.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
enum Test {
    Reference,
    Roundtrip,
    Adversarial,
    Determinism,
    Matching,
    Isa,
}

impl Options {
    fn wants(&self, test: Test) -> bool {
        self.only.as_ref().is_none_or(|list| list.contains(&test))
    }

    /// The precisions to run, in [`Precision::ALL`] order.
    fn precisions(&self) -> Vec<Precision> {
        Precision::ALL
            .into_iter()
            .filter(|p| self.precision.as_ref().is_none_or(|list| list.contains(p)))
            .collect()
    }

    /// Number of tests the run makes.
    fn test_count(&self) -> usize {
        Test::value_variants()
            .iter()
            .filter(|&&t| self.wants(t))
            .count()
    }
}

/// Runs the selected tests into `report`, each in every selected precision; returns the
/// wall time of each (test, precision) as text.
fn run_tests(o: &Options, report: &mut Report) -> so3fft::Result<String> {
    let bar = Steps::new(o.test_count() as u64, "tests");
    let mut times = Vec::new();
    for test in Test::value_variants()
        .iter()
        .copied()
        .filter(|&t| o.wants(t))
    {
        let name = format!("{test:?}").to_lowercase();
        bar.message(name.clone());
        let precisions = o.precisions();
        if matches!(test, Test::Roundtrip | Test::Matching) {
            // Timed tests: the precisions alternate inside (one bandwidth at a time).
            let start = Instant::now();
            run_timed(o, test, &precisions, report)?;
            let list: Vec<&str> = precisions.iter().map(|p| p.name()).collect();
            let seconds = start.elapsed().as_secs_f64();
            times.push(format!("{name} {} {seconds:.1}", list.join("+")));
        } else {
            for p in precisions {
                let start = Instant::now();
                match p {
                    Precision::F64 => run_test::<f64>(o, test, report)?,
                    Precision::F32 => run_test::<f32>(o, test, report)?,
                }
                times.push(format!("{name} {p} {:.1}", start.elapsed().as_secs_f64()));
            }
        }
        bar.step();
    }
    Ok(times.join(", "))
}

/// Runs a test whose times the chart compares (round trips, matching) in every precision
/// of `precisions`.
fn run_timed(
    o: &Options,
    test: Test,
    precisions: &[Precision],
    report: &mut Report,
) -> so3fft::Result<()> {
    let t = o.threads;
    if test == Test::Matching {
        let ls: &[usize] = if o.quick {
            &[16, 32]
        } else {
            &[16, 32, 64, 128]
        };
        return matching::run(ls, t, precisions, report);
    }
    let ranges = if o.quick {
        roundtrip::Ranges {
            full_max: 64,
            partial_max: 128,
            s2_max: 256,
            variants: true,
        }
    } else {
        roundtrip::Ranges {
            full_max: 256,
            partial_max: 2048,
            s2_max: 2048,
            variants: true,
        }
    };
    roundtrip::run(ranges, t, precisions, report)?;
    if o.big {
        for &p in precisions {
            match p {
                Precision::F64 => roundtrip::big::<f64>(t, report)?,
                Precision::F32 => roundtrip::big::<f32>(t, report)?,
            }
        }
    }
    Ok(())
}

/// Runs one test in `T` (the untimed ones: see [`run_timed`]).
fn run_test<T: Float>(o: &Options, test: Test, report: &mut Report) -> so3fft::Result<()> {
    let t = o.threads;
    match test {
        Test::Reference => reference::run::<T>(&o.data_dir(), t, report),
        Test::Roundtrip | Test::Matching => run_timed(o, test, &[T::PRECISION], report),
        Test::Adversarial => {
            let bw = if o.quick {
                adversarial::Bandwidths {
                    top: &[16, 64],
                    s2_top: &[64, 256],
                    small: 16,
                }
            } else {
                adversarial::Bandwidths {
                    top: &[16, 64, 256],
                    s2_top: &[64, 256, 1024, 2048],
                    small: 64,
                }
            };
            adversarial::run::<T>(&bw, t, report)
        }
        Test::Determinism => determinism::run::<T>(if o.quick { 32 } else { 64 }, report),
        Test::Isa => {
            let bw = if o.quick {
                reference::IsaBandwidths {
                    so3: 32,
                    partial: 64,
                    s2: 128,
                }
            } else {
                reference::IsaBandwidths {
                    so3: 128,
                    partial: 1024,
                    s2: 1024,
                }
            };
            reference::isa_roundtrips::<T>(bw, t, report)
        }
    }
}

impl Options {
    fn data_dir(&self) -> PathBuf {
        self.data
            .clone()
            .unwrap_or_else(reference::default_data_dir)
    }
}

fn write(path: &Path, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// Writes the files the options ask for (`from_csv`: the rows came from that file, which
/// `--docs` then does not rewrite).
fn write_outputs(o: &Options, rows: &[Row], summary: &targets::Summary) -> Result<(), String> {
    let growths = record::growths(rows, &roundtrip::GROWTH_TESTS);
    let mut csv = o.csv.clone();
    let mut svg = o.svg.clone();
    let mut time_svg = o.time_svg.clone();
    if let Some(dir) = &o.docs {
        if o.from_csv.is_none() || csv.is_some() {
            csv = csv.or(Some(dir.join("stability.csv")));
        }
        svg = Some(dir.join("stability.svg"));
        time_svg = Some(dir.join("time-vs-error.svg"));
        let md = dir.join("stability.md");
        let old = std::fs::read_to_string(&md).map_err(|e| format!("{}: {e}", md.display()))?;
        let tables = targets::markdown(rows, &growths, summary);
        write(&md, &targets::splice(&old, &tables)?)?;
    }
    if let Some(p) = csv {
        record::write_csv(&p, rows).map_err(|e| format!("{}: {e}", p.display()))?;
    }
    if let Some(p) = svg {
        write(&p, &plot::error_svg(rows, &growths)?)?;
    }
    if let Some(p) = time_svg {
        write(&p, &plot::time_svg(rows)?)?;
    }
    Ok(())
}

/// The rows: read from `--from-csv`, or measured now (printed as they come).
fn collect_rows(o: &Options) -> Result<Vec<Row>, String> {
    if let Some(path) = &o.from_csv {
        return record::read_csv(path);
    }
    let mut report = Report {
        verbose: true,
        ..Default::default()
    };
    println!("{}", Report::header());
    let times = run_tests(o, &mut report).map_err(|e| e.to_string())?;
    println!("\nseconds per test: {times}");
    Ok(report.rows)
}

fn main() -> ExitCode {
    // Usage errors exit with status 2, --help and --version with 0 (clap).
    let o = Options::parse();
    let start = Instant::now();
    let rows = match collect_rows(&o) {
        Ok(rows) => rows,
        Err(e) => {
            eprintln!("so3fft-stress: {e}");
            return ExitCode::from(2);
        }
    };
    println!();
    let growths = record::growths(&rows, &roundtrip::GROWTH_TESTS);
    println!(
        "growth of the error with B (least squares on log-log):\n{}",
        record::growth_table(&growths)
    );
    // The rows tell whether the full-grid B = 512 round trips were run, per precision.
    let big = |p: Precision| {
        rows.iter().any(|r| {
            r.precision == p
                && r.test == "roundtrip"
                && r.b == 512
                && (r.variant == "complex" || r.variant == "real")
        })
    };
    let summary = targets::evaluate(&rows, big(Precision::F64), big(Precision::F32));
    println!("accuracy targets:\n{}", summary.text());
    if o.from_csv.is_none() {
        println!("total {:.1} s", start.elapsed().as_secs_f64());
    }
    if let Err(msg) = write_outputs(&o, &rows, &summary) {
        eprintln!("so3fft-stress: {msg}");
        return ExitCode::from(2);
    }
    if summary.all_met() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
