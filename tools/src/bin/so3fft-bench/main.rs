//! `so3fft-bench`: timing, accuracy and efficiency of the SO(3) FFT.
//!
//! For each bandwidth B and thread count it times the inverse and forward transforms (median of
//! several runs, with the FFT and DWT stages separately), checks the round trip on random
//! coefficients, relates the DWT stage's flop rate to the machine's FMA peak measured in the
//! same run, and records the peak resident memory. Per bandwidth it also runs the transforms
//! without skipping negligible Wigner-d prefixes, the real-signal transforms against the
//! complex ones and, at small B, a plain one-thread DWT (`naive.rs`) as a yardstick
//! (`regular.rs`). `--big` adds B = 512 in a memory-lean procedure (`big.rs`).
//! Prints tables, writes a CSV file and an SVG plot.
//!
//! Three narrower tools share the options: `stages` (stage times of repeated transforms, for
//! profiling), `scaling` (thread scaling in windows undisturbed by other processes) and
//! `real` (the real-signal against the complex transforms only).
//!
//! `cargo run --release --bin so3fft-bench -- --help` lists the options; `notes/bench.md`
//! describes the columns and how each number is measured.

#![warn(unsafe_op_in_unsafe_fn)]
#![warn(clippy::undocumented_unsafe_blocks)]

mod big;
mod cli;
mod floor;
mod matching;
mod memory;
mod mpi_model;
mod naive;
mod noise;
mod partial;
mod peak;
mod plot;
mod precision;
mod regular;
mod report;
mod s2;
mod scaling;
mod seeded;
mod soft_cmp;
mod stages;
mod timing;
mod workload;

use clap::Parser;
use cli::{Options, Tool};
use regular::{Results, Setup};
use report::{Row, Variant};
use so3fft_tools::progress::Steps;
use std::process::ExitCode;

fn main() -> ExitCode {
    // Usage errors exit with status 2, --help and --version with 0 (clap).
    let opts = match cli::Cli::parse().into_options() {
        Ok(opts) => opts,
        Err(e) => e.exit(),
    };
    if let Some(isa) = &opts.isa {
        // Before any thread exists: every plan, SOFT call and the peak follow it.
        std::env::set_var(so3fft::ISA_VARIABLE, isa);
    }
    if let Err(e) = so3fft::Isa::selected() {
        eprintln!("so3fft-bench: {e}");
        return ExitCode::from(2);
    }
    run_tool(&opts)
}

/// Runs the tool `opts` names.
fn run_tool(opts: &Options) -> ExitCode {
    match opts.tool {
        Tool::Full => run_full(opts),
        Tool::Stages => report_failure("stages", stages::run(opts)),
        Tool::Scaling => report_failure("scaling", scaling::run(opts)),
        Tool::Real => report_failure("real", run_real(opts)),
        Tool::S2 => report_failure("s2", s2::run(opts)),
        Tool::Precision => report_failure("precision", precision::run(opts)),
        Tool::Match => report_failure("match", matching::run(opts)),
        Tool::Noise => report_failure("noise", noise::run(opts)),
        Tool::Partial => report_failure("partial", partial::run(opts)),
        Tool::MpiModel => report_failure("mpi-model", mpi_model::run(opts)),
    }
}

/// Exit code of a tool's result, with the error on stderr.
fn report_failure(tool: &str, result: Result<(), so3fft::Error>) -> ExitCode {
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("so3fft-bench {tool}: {e}");
            ExitCode::FAILURE
        }
    }
}

/// The `real` tool: the real-signal transforms against the complex ones at every bandwidth,
/// on the last thread count (as in the full benchmark), as one table.
fn run_real(opts: &Options) -> Result<(), so3fft::Error> {
    let threads = *opts.threads.last().expect("at least one thread count");
    let mut rows = Vec::new();
    for &b in &opts.bandwidths {
        let setup = Setup {
            b,
            opts,
            peak_1core: f64::NAN,
        };
        rows.push(regular::real_row(setup, threads)?);
    }
    println!(
        "Real-signal transforms against the complex ones (same B, threads):\n{}",
        report::real_table(&rows)
    );
    Ok(())
}

/// Runs the whole benchmark; fails if no configuration could be measured or the CSV not written.
fn run_full(opts: &Options) -> ExitCode {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let peak = peak::measure(cores);
    print_header(opts, &peak);

    let mut results = Results {
        rows: Vec::new(),
        noskip_missing: Vec::new(),
    };
    let bar = Steps::new(opts.bandwidths.len() as u64, "bandwidths");
    for &b in &opts.bandwidths {
        bar.message(format!("(B = {b})"));
        if b > cli::MAX_REGULAR_BANDWIDTH {
            let threads = big_threads(opts, cores);
            let out = big::run(b, threads, opts, peak.one_core);
            results.rows.extend(out.rows);
            results
                .noskip_missing
                .extend(out.noskip_missing.map(|why| (b, why)));
        } else {
            let setup = Setup {
                b,
                opts,
                peak_1core: peak.one_core,
            };
            regular::bench_bandwidth(setup, &mut results);
        }
        bar.step();
    }
    drop(bar);
    let rows = results.rows;
    print_summaries(&rows, &results.noskip_missing);
    if opts.soft {
        print_soft_comparison(opts);
    }
    if let Err(e) = report::write_csv(&opts.csv, &rows) {
        eprintln!("so3fft-bench: cannot write {}: {e}", opts.csv.display());
        return ExitCode::FAILURE;
    }
    println!("CSV written to {}", opts.csv.display());
    if !rows.is_empty() {
        let written = plot::svg(&rows)
            .and_then(|svg| std::fs::write(&opts.plot, svg).map_err(|e| e.to_string()));
        match written {
            Ok(()) => println!("Plot written to {}", opts.plot.display()),
            Err(e) => eprintln!("so3fft-bench: cannot write {}: {e}", opts.plot.display()),
        }
    }
    if rows.is_empty() {
        eprintln!("so3fft-bench: no configuration was measured");
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
}

/// Threads of the one run at B > 256: the largest requested count (0 = all cores).
fn big_threads(opts: &Options, cores: usize) -> usize {
    opts.threads
        .iter()
        .map(|&t| if t == 0 { cores } else { t })
        .max()
        .unwrap_or(1)
}

/// Prints the measured peak, the flop-count convention and the table header.
fn print_header(opts: &Options, peak: &peak::Peak) {
    println!("so3fft-bench: FFT on SO(3), inverse then forward on random coefficients");
    println!(
        "FMA peak (measured now, {}): {:.1} GFLOP/s on 1 core, {:.1} GFLOP/s on {} threads",
        peak.isa.name(),
        peak.one_core,
        peak.all_threads,
        peak.threads
    );
    println!(
        "DWT flops per direction: exact 8B(4B^3-B)/3 = 8B * sum_(m,m') (B - max(|m|,|m'|)) \
         [used]; leading order 32B^4/3 [not used]; both count two FMAs = 4 flops per (l, m, m', beta)"
    );
    let counts: Vec<String> = opts
        .bandwidths
        .iter()
        .map(|&b| {
            format!(
                "B={b}: {:.3e} (32B^4/3: {:.3e})",
                workload::dwt_flops_exact(b) as f64,
                workload::dwt_flops_approx(b)
            )
        })
        .collect();
    println!("  {}", counts.join(", "));
    println!(
        "fraction of peak = DWT GFLOP/s / (1-core peak x threads); times in seconds, medians; \
         rigor = {}",
        cli::rigor_name(opts.rigor)
    );
    println!();
    println!("{}", report::table_header());
}

/// The tables after the main one: speed-ups, skipping, plain DWT, real signals, memory.
fn print_summaries(rows: &[Row], noskip_missing: &[(usize, String)]) {
    let speedups = report::speedups(rows);
    if !speedups.is_empty() {
        println!("\nSpeed-up (median wall time, 1 thread / N threads):\n{speedups}");
    }
    if rows.iter().any(|r| r.variant == Variant::NoSkip) || !noskip_missing.is_empty() {
        println!(
            "Skipping of negligible Wigner-d prefixes: default (skip below 2^-64) against \
             skip_bits = Some(0) (every degree of every beta); DWT stage times, ratio = no-skip / skip:\n{}",
            report::skip_table(rows, noskip_missing)
        );
    }
    if rows.iter().any(|r| r.variant == Variant::Naive) {
        println!(
            "Plain DWT (naive.rs: one thread, scalar loops, textbook recurrence) against the \
             library's one-thread DWT stage; round trip errors of the plain DWT:\n{}",
            report::naive_table(rows)
        );
    }
    if rows.iter().any(|r| r.variant == Variant::Real) {
        println!(
            "Real-signal transforms against the complex ones (same B, threads):\n{}",
            report::real_table(rows)
        );
    }
    if rows.iter().any(|r| r.memory.is_some()) {
        println!(
            "Peak resident memory of the timed phase (VmHWM after a reset; B > 256: the forward \
             alone); growth = peak - resident at the start of the phase; in+out = samples + \
             coefficients:\n{}",
            report::memory_table(rows)
        );
    }
}

/// `--soft`: the SOFT 2.0 entry points against the native plan at every B <= 256.
fn print_soft_comparison(opts: &Options) {
    let mut soft_rows = Vec::new();
    // Not above 256: the SOFT entry points need several grid-sized workspaces.
    let bandwidths: Vec<usize> = opts
        .bandwidths
        .iter()
        .copied()
        .filter(|&b| b <= cli::MAX_REGULAR_BANDWIDTH)
        .collect();
    let bar = Steps::new(bandwidths.len() as u64, "bandwidths (SOFT)");
    for b in bandwidths {
        bar.message(format!("(B = {b})"));
        match soft_cmp::compare(b, opts.runs_for(b)) {
            Ok(r) => soft_rows.extend(r),
            Err(e) => so3fft_tools::bar_eprintln!("so3fft-bench: SOFT comparison at B = {b}: {e}"),
        }
        bar.step();
    }
    drop(bar);
    print!("{}", soft_cmp::table(&soft_rows));
}
