//! `so3fft-stress`: the numerical stress suite of so3fft.
//!
//! Tests, each a module:
//! - (a) `reference`: transforms against exact values (40-digit sums in
//!   `tests/data/stress/`), and (e) the same and round trips on every instruction set;
//! - (b) `roundtrip`: `forward(inverse(c))`, `inverse(forward(f))` and Parseval over
//!   doubling bandwidths, full plan complex and real, skipping variants, order-limited
//!   partial plans, S^2; growth exponents fitted by least squares;
//! - (c) `adversarial`: top-order single coefficients, power-law spectra, exact scaling by
//!   `2^k`, subnormal inputs, NaN and infinite inputs;
//! - (d) `determinism`: bits across 1, 2, 4 threads and repeated executions;
//! - `matching`: rotational matching's angle error and time (points of the time chart).
//!
//! Prints a table (a row per case as it is measured), the fitted exponents and the issue's
//! targets; `--csv`, `--svg`,
//! `--time-svg` write the results, `--docs DIR` all of them plus the tables in
//! `DIR/stability.md`. See `docs/stability.md`.

mod adversarial;
mod determinism;
mod matching;
mod plot;
mod record;
mod reference;
mod rng;
mod roundtrip;
mod targets;

use record::Report;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Instant;

const USAGE: &str = "\
usage: so3fft-stress [--quick] [--big] [--threads N] [--only LIST] [--data DIR]
                     [--csv FILE] [--svg FILE] [--time-svg FILE] [--docs DIR]

  --quick      small bandwidths only (SO(3) round trips to 64, partial to 128, S^2 to 256;
               about 5 s); default: the full run (SO(3) to 256, partial and S^2 to 2048;
               a few minutes, under 6 GB)
  --big        also B = 512 full-grid SO(3) round trips (needs about 24 GB)
  --threads N  worker threads of the transforms (default 0 = all cores)
  --only LIST  comma-separated tests among reference,roundtrip,adversarial,determinism,isa,
               matching
  --data DIR   reference data (default tests/data/stress of the source tree)
  --csv FILE   write every row as CSV
  --svg FILE   write the error-against-bandwidth plot
  --time-svg FILE  write the time-against-error plot
  --docs DIR   write DIR/stability.csv, stability.svg, time-vs-error.svg and the tables of
               DIR/stability.md (between its stress-table markers)
exit status: 0 if every accuracy target that the run covers is met, 1 if one is missed,
2 on bad arguments or a failed transform";

/// Command-line options.
struct Options {
    quick: bool,
    big: bool,
    threads: usize,
    only: Option<Vec<String>>,
    data: PathBuf,
    csv: Option<PathBuf>,
    svg: Option<PathBuf>,
    time_svg: Option<PathBuf>,
    docs: Option<PathBuf>,
}

fn parse(args: impl Iterator<Item = String>) -> Result<Option<Options>, String> {
    let mut o = Options {
        quick: false,
        big: false,
        threads: 0,
        only: None,
        data: reference::default_data_dir(),
        csv: None,
        svg: None,
        time_svg: None,
        docs: None,
    };
    let mut args = args.peekable();
    while let Some(arg) = args.next() {
        let mut value = || args.next().ok_or(format!("{arg} needs a value"));
        match arg.as_str() {
            "-h" | "--help" => return Ok(None),
            "--quick" => o.quick = true,
            "--big" => o.big = true,
            "--threads" => {
                o.threads = value()?
                    .parse()
                    .map_err(|_| "--threads needs a number".to_string())?
            }
            "--only" => o.only = Some(value()?.split(',').map(str::to_string).collect()),
            "--data" => o.data = value()?.into(),
            "--csv" => o.csv = Some(value()?.into()),
            "--svg" => o.svg = Some(value()?.into()),
            "--time-svg" => o.time_svg = Some(value()?.into()),
            "--docs" => o.docs = Some(value()?.into()),
            other => return Err(format!("unknown argument {other:?}")),
        }
    }
    Ok(Some(o))
}

impl Options {
    fn wants(&self, test: &str) -> bool {
        self.only
            .as_ref()
            .is_none_or(|list| list.iter().any(|t| t == test))
    }
}

/// Runs the selected tests into `report`.
fn run_tests(o: &Options, report: &mut Report) -> so3fft::Result<()> {
    let t = o.threads;
    if o.wants("reference") {
        reference::run(&o.data, t, report)?;
    }
    if o.wants("roundtrip") {
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
        roundtrip::run(ranges, t, report)?;
        if o.big {
            // Only the coefficient round trip: f (17 GB) and two coefficient arrays.
            let run = roundtrip::RunOptions {
                threads: t,
                sample_checks: false,
            };
            roundtrip::full_complex(512, roundtrip::FULL_VARIANTS[0], run, report)?;
        }
    }
    if o.wants("adversarial") {
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
        adversarial::run(&bw, t, report)?;
    }
    if o.wants("determinism") {
        determinism::run(if o.quick { 32 } else { 64 }, report)?;
    }
    if o.wants("matching") {
        let ls: &[usize] = if o.quick {
            &[16, 32]
        } else {
            &[16, 32, 64, 128]
        };
        matching::run(ls, t, report)?;
    }
    if o.wants("isa") {
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
        reference::isa_roundtrips(bw, t, report)?;
    }
    Ok(())
}

fn write(path: &PathBuf, text: &str) -> Result<(), String> {
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// Writes the files the options ask for.
fn write_outputs(o: &Options, report: &Report, summary: &targets::Summary) -> Result<(), String> {
    let growths = record::growths(&report.rows, &roundtrip::GROWTH_TESTS);
    let mut csv = o.csv.clone();
    let mut svg = o.svg.clone();
    let mut time_svg = o.time_svg.clone();
    if let Some(dir) = &o.docs {
        csv = Some(dir.join("stability.csv"));
        svg = Some(dir.join("stability.svg"));
        time_svg = Some(dir.join("time-vs-error.svg"));
        let md = dir.join("stability.md");
        let old = std::fs::read_to_string(&md).map_err(|e| format!("{}: {e}", md.display()))?;
        let tables = targets::markdown(report, &growths, summary);
        write(&md, &targets::splice(&old, &tables)?)?;
    }
    if let Some(p) = csv {
        write(&p, &report.csv())?;
    }
    if let Some(p) = svg {
        write(&p, &plot::error_svg(&report.rows, &growths))?;
    }
    if let Some(p) = time_svg {
        write(&p, &plot::time_svg(&report.rows))?;
    }
    Ok(())
}

fn main() -> ExitCode {
    let o = match parse(std::env::args().skip(1)) {
        Ok(Some(o)) => o,
        Ok(None) => {
            println!("{USAGE}");
            return ExitCode::SUCCESS;
        }
        Err(msg) => {
            eprintln!("so3fft-stress: {msg}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let mut report = Report {
        verbose: true,
        ..Default::default()
    };
    let start = Instant::now();
    println!("{}", Report::header());
    if let Err(e) = run_tests(&o, &mut report) {
        eprintln!("so3fft-stress: {e}");
        return ExitCode::from(2);
    }
    println!();
    let growths = record::growths(&report.rows, &roundtrip::GROWTH_TESTS);
    println!(
        "growth of the error with B (least squares on log-log):\n{}",
        record::growth_table(&growths)
    );
    let summary = targets::evaluate(&report.rows, o.big);
    println!("accuracy targets:\n{}", summary.text());
    println!("total {:.1} s", start.elapsed().as_secs_f64());
    if let Err(msg) = write_outputs(&o, &report, &summary) {
        eprintln!("so3fft-stress: {msg}");
        return ExitCode::from(2);
    }
    if summary.all_met() {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}
