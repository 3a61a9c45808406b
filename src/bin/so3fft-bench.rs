//! `so3fft-bench`: timing, accuracy and efficiency of the SO(3) FFT.
//!
//! For each bandwidth B and thread count it times the inverse and forward transforms (median of
//! several runs, with the FFT and DWT stages separately), checks the round trip on random
//! coefficients, and relates the DWT stage's flop rate to the machine's FMA peak measured in the
//! same run. Prints a table and writes a CSV file.
//!
//! `cargo run --release --bin so3fft-bench -- --help` lists the options.

#[path = "so3fft_bench/cli.rs"]
mod cli;
#[path = "so3fft_bench/peak.rs"]
mod peak;
#[path = "so3fft_bench/report.rs"]
mod report;
#[path = "so3fft_bench/soft_cmp.rs"]
mod soft_cmp;
#[path = "so3fft_bench/workload.rs"]
mod workload;

use cli::{Command, Options};
use report::{Row, Stages};
use so3fft::{Complex64, Direction, Plan, PlanOptions, StageTimes};
use std::process::ExitCode;
use std::time::Instant;
use workload::RoundTripError;

/// Share of `MemAvailable` a configuration may use before it is skipped: the machine has no
/// swap, so running out of memory kills the process instead of slowing it down.
const MEMORY_FRACTION: f64 = 0.8;

fn main() -> ExitCode {
    match cli::parse(std::env::args().skip(1)) {
        Ok(Command::Help) => {
            println!("{}", cli::USAGE);
            ExitCode::SUCCESS
        }
        Ok(Command::Run(opts)) => run(&opts),
        Err(msg) => {
            eprintln!("so3fft-bench: {msg}\n{}", cli::USAGE);
            ExitCode::from(2)
        }
    }
}

/// Runs the whole benchmark; fails if no configuration could be measured or the CSV not written.
fn run(opts: &Options) -> ExitCode {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let peak = peak::measure(cores);
    print_header(opts, &peak);

    let mut rows = Vec::new();
    for &b in &opts.bandwidths {
        rows.extend(bench_bandwidth(b, opts, &peak));
    }

    let speedups = report::speedups(&rows);
    if !speedups.is_empty() {
        println!("\nSpeed-up (median wall time, 1 thread / N threads):\n{speedups}");
    }
    if opts.soft {
        let mut soft_rows = Vec::new();
        for &b in &opts.bandwidths {
            match soft_cmp::compare(b, opts.runs_for(b)) {
                Ok(r) => soft_rows.extend(r),
                Err(e) => eprintln!("so3fft-bench: SOFT comparison at B = {b}: {e}"),
            }
        }
        print!("{}", soft_cmp::table(&soft_rows));
    }
    if let Err(e) = report::write_csv(&opts.csv, &rows) {
        eprintln!("so3fft-bench: cannot write {}: {e}", opts.csv.display());
        return ExitCode::FAILURE;
    }
    println!("CSV written to {}", opts.csv.display());
    if rows.is_empty() {
        eprintln!("so3fft-bench: no configuration was measured");
        return ExitCode::FAILURE;
    }
    ExitCode::SUCCESS
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

/// All thread counts at one bandwidth. The random coefficients are shared between them.
fn bench_bandwidth(b: usize, opts: &Options, peak: &peak::Peak) -> Vec<Row> {
    if !fits_in_memory(b) {
        return Vec::new();
    }
    let coeffs = workload::random_coeffs(so3fft::num_coeffs(b), 0x5EED_0000 + b as u64);
    let mut rows = Vec::new();
    for &threads in &opts.threads {
        match bench_config(b, threads, opts, &coeffs, peak.one_core) {
            Ok(row) => {
                println!("{}", report::table_line(&row));
                rows.push(row);
            }
            Err(e) => eprintln!("so3fft-bench: B = {b}, threads = {threads}: skipped: {e}"),
        }
    }
    rows
}

/// Whether bandwidth `b` fits in [`MEMORY_FRACTION`] of the available memory (warns if not).
fn fits_in_memory(b: usize) -> bool {
    let need = workload::estimated_bytes(b);
    let Some(available) = workload::mem_available_bytes() else {
        eprintln!("so3fft-bench: cannot read MemAvailable; running B = {b} unchecked");
        return true;
    };
    let fits = (need as f64) <= MEMORY_FRACTION * available as f64;
    if !fits {
        eprintln!(
            "so3fft-bench: warning: skipping B = {b}: needs about {:.2} GiB, more than {:.0}% of \
             MemAvailable ({:.2} GiB)",
            gib(need),
            100.0 * MEMORY_FRACTION,
            gib(available)
        );
    }
    fits
}

fn gib(bytes: usize) -> f64 {
    bytes as f64 / (1u64 << 30) as f64
}

/// Times of every run of one configuration.
#[derive(Default)]
struct RunTimes {
    fwd_wall: Vec<f64>,
    inv_wall: Vec<f64>,
    fwd: Vec<StageTimes>,
    inv: Vec<StageTimes>,
}

/// Plans and measures one (bandwidth, threads) configuration.
fn bench_config(
    b: usize,
    threads: usize,
    opts: &Options,
    coeffs: &[Complex64],
    peak_1core: f64,
) -> Result<Row, so3fft::Error> {
    let plan_start = Instant::now();
    let plan = Plan::new(
        b,
        &PlanOptions {
            direction: Direction::Both,
            threads,
            rigor: opts.rigor,
            ..PlanOptions::default()
        },
    )?;
    eprintln!(
        "  (B = {b}, threads = {}: plan created in {:.3} s)",
        plan.threads(),
        plan_start.elapsed().as_secs_f64()
    );
    let mut samples = vec![Complex64::default(); plan.num_samples()];
    let mut result = vec![Complex64::default(); plan.num_coeffs()];
    let runs = opts.runs_for(b);

    // One untimed round trip faults in the output pages and warms caches and the thread pool,
    // except at B >= 512 where it would cost as much as the measurement itself.
    if b < 512 {
        plan.inverse(coeffs, &mut samples)?;
        plan.forward(&samples, &mut result)?;
    }
    let mut times = RunTimes::default();
    let mut error = RoundTripError::default();
    for _ in 0..runs {
        error = error.worst(round_trip(
            &plan,
            coeffs,
            &mut samples,
            &mut result,
            &mut times,
        )?);
    }
    Ok(summarise(
        b,
        plan.threads(),
        runs,
        &times,
        error,
        peak_1core,
    ))
}

/// One timed inverse-then-forward round trip; returns its error against `coeffs`.
fn round_trip(
    plan: &Plan,
    coeffs: &[Complex64],
    samples: &mut [Complex64],
    result: &mut [Complex64],
    times: &mut RunTimes,
) -> Result<RoundTripError, so3fft::Error> {
    let start = Instant::now();
    times.inv.push(plan.inverse_timed(coeffs, samples)?);
    times.inv_wall.push(start.elapsed().as_secs_f64());

    let start = Instant::now();
    times.fwd.push(plan.forward_timed(samples, result)?);
    times.fwd_wall.push(start.elapsed().as_secs_f64());
    Ok(workload::roundtrip_error(coeffs, result))
}

/// Medians of the runs, as a table row. The whole-transform times are the bench's own wall
/// clock around each call; the stage times are the library's.
fn summarise(
    b: usize,
    threads: usize,
    runs: usize,
    times: &RunTimes,
    error: RoundTripError,
    peak_1core: f64,
) -> Row {
    let stages = |t: &[StageTimes]| Stages {
        fft: workload::median(&t.iter().map(|s| s.fft).collect::<Vec<_>>()),
        dwt: workload::median(&t.iter().map(|s| s.dwt).collect::<Vec<_>>()),
    };
    Row {
        bandwidth: b,
        threads,
        runs,
        fwd_median: workload::median(&times.fwd_wall),
        inv_median: workload::median(&times.inv_wall),
        fwd: stages(&times.fwd),
        inv: stages(&times.inv),
        dwt_flops: workload::dwt_flops_exact(b),
        peak_1core,
        max_abs_err: error.max_abs,
        rel_l2_err: error.rel_l2,
    }
}
