//! `so3fft-bench`: timing, accuracy and efficiency of the SO(3) FFT.
//!
//! For each bandwidth B and thread count it times the inverse and forward transforms (median of
//! several runs, with the FFT and DWT stages separately), checks the round trip on random
//! coefficients, relates the DWT stage's flop rate to the machine's FMA peak measured in the
//! same run, and records the peak resident memory. Per bandwidth it also runs the transforms
//! without skipping negligible Wigner-d prefixes, the real-signal transforms against the
//! complex ones and, at small B, a plain one-thread DWT (`naive.rs`) as a yardstick. `--big`
//! adds B = 512 in a memory-lean procedure (`big.rs`).
//! Prints tables, writes a CSV file and an SVG plot.
//!
//! `cargo run --release --bin so3fft-bench -- --help` lists the options; `notes/bench.md`
//! describes the columns and how each number is measured.

mod big;
mod cli;
mod memory;
mod naive;
mod peak;
mod plot;
mod report;
mod scaling;
mod seeded;
mod soft_cmp;
mod stages;
mod workload;

use cli::{Command, Options, Tool};
use report::{Memory, Row, Stages, Variant};
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
        Ok(Command::Run(opts)) => match opts.tool {
            Tool::Full => run(&opts),
            Tool::Stages => report_failure("stages", stages::run(&opts)),
            Tool::Scaling => report_failure("scaling", scaling::run(&opts)),
            Tool::Real => report_failure("real", run_real(&opts)),
        },
        Err(msg) => {
            eprintln!("so3fft-bench: {msg}\n{}", cli::USAGE);
            ExitCode::from(2)
        }
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
        rows.push(bench_real(b, threads, opts, f64::NAN)?);
    }
    println!(
        "Real-signal transforms against the complex ones (same B, threads):\n{}",
        report::real_table(&rows)
    );
    Ok(())
}

/// Runs the whole benchmark; fails if no configuration could be measured or the CSV not written.
fn run(opts: &Options) -> ExitCode {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let peak = peak::measure(cores);
    print_header(opts, &peak);

    let mut rows = Vec::new();
    let mut noskip_missing = Vec::new();
    for &b in &opts.bandwidths {
        if b > cli::MAX_REGULAR_BANDWIDTH {
            let threads = big_threads(opts, cores);
            let out = big::run(b, threads, opts, peak.one_core);
            rows.extend(out.rows);
            noskip_missing.extend(out.noskip_missing.map(|why| (b, why)));
        } else {
            bench_bandwidth(b, opts, &peak, &mut rows, &mut noskip_missing);
        }
    }

    let speedups = report::speedups(&rows);
    if !speedups.is_empty() {
        println!("\nSpeed-up (median wall time, 1 thread / N threads):\n{speedups}");
    }
    if rows.iter().any(|r| r.variant == Variant::NoSkip) || !noskip_missing.is_empty() {
        println!(
            "Skipping of negligible Wigner-d prefixes: default (skip below 2^-64) against \
             skip_bits = Some(0) (every degree of every beta); DWT stage times, ratio = no-skip / skip:\n{}",
            report::skip_table(&rows, &noskip_missing)
        );
    }
    if rows.iter().any(|r| r.variant == Variant::Naive) {
        println!(
            "Plain DWT (naive.rs: one thread, scalar loops, textbook recurrence) against the \
             library's one-thread DWT stage; round trip errors of the plain DWT:\n{}",
            report::naive_table(&rows)
        );
    }
    if rows.iter().any(|r| r.variant == Variant::Real) {
        println!(
            "Real-signal transforms against the complex ones (same B, threads):\n{}",
            report::real_table(&rows)
        );
    }
    if rows.iter().any(|r| r.memory.is_some()) {
        println!(
            "Peak resident memory of the timed phase (VmHWM after a reset; B > 256: the forward \
             alone); growth = peak - resident at the start of the phase; in+out = samples + \
             coefficients:\n{}",
            report::memory_table(&rows)
        );
    }
    if opts.soft {
        let mut soft_rows = Vec::new();
        // Not above 256: the SOFT entry points need several grid-sized workspaces.
        for &b in opts
            .bandwidths
            .iter()
            .filter(|&&b| b <= cli::MAX_REGULAR_BANDWIDTH)
        {
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
    if !rows.is_empty() {
        match std::fs::write(&opts.plot, plot::svg(&rows)) {
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

/// All measurements at one bandwidth B <= 256: every thread count, the no-skip run (first
/// thread count), the real-signal run (last thread count) and the plain DWT. The random
/// coefficients are shared between the complex runs and the plain DWT.
fn bench_bandwidth(
    b: usize,
    opts: &Options,
    peak: &peak::Peak,
    rows: &mut Vec<Row>,
    noskip_missing: &mut Vec<(usize, String)>,
) {
    if !fits_in_memory(b) {
        return;
    }
    let coeffs = workload::random_coeffs(so3fft::num_coeffs(b), 0x5EED_0000 + b as u64);
    for &threads in &opts.threads {
        match bench_config(b, threads, opts, &coeffs, peak.one_core) {
            Ok(row) => {
                println!("{}", report::table_line(&row));
                rows.push(row);
            }
            Err(e) => eprintln!("so3fft-bench: B = {b}, threads = {threads}: skipped: {e}"),
        }
    }

    match bench_noskip(b, opts.threads[0], opts, &coeffs, peak.one_core) {
        Ok(row) => rows.push(row),
        Err(e) => {
            eprintln!("  (B = {b}: no-skip run n/a: {e})");
            noskip_missing.push((b, e.to_string()));
        }
    }

    let real_threads = *opts.threads.last().expect("at least one thread count");
    match bench_real(b, real_threads, opts, peak.one_core) {
        Ok(row) => rows.push(row),
        Err(e) => eprintln!("so3fft-bench: B = {b}: real-signal run skipped: {e}"),
    }

    if b <= opts.naive_max {
        let mut row = bench_naive(b, opts, &coeffs, peak.one_core);
        let lib = match report::find(rows, Variant::Complex, b, 1) {
            Some(r) => Ok(r.clone()),
            None => {
                eprintln!("  (B = {b}: library one-thread DWT measured for the plain-DWT ratio)");
                bench_config(b, 1, opts, &coeffs, peak.one_core)
            }
        };
        match lib {
            Ok(lib) => row.ratio = Some((lib.fwd.dwt / row.fwd.dwt, lib.inv.dwt / row.inv.dwt)),
            Err(e) => eprintln!("so3fft-bench: B = {b}: one-thread plan failed: {e}"),
        }
        rows.push(row);
    }
}

/// Timed runs of the plain DWT at bandwidth `b` (inverse of `coeffs` to the slice spectra,
/// forward back): one run from B = 128 on (about 1 s per direction), else up to 3.
fn bench_naive(b: usize, opts: &Options, coeffs: &[Complex64], peak_1core: f64) -> Row {
    let runs = if b >= 128 { 1 } else { opts.runs_for(b).min(3) };
    let n = 2 * b;
    let betas = naive::Betas::new(b);
    let mut g = vec![Complex64::default(); n * n * n];
    let mut result = vec![Complex64::default(); coeffs.len()];
    let mut times = RunTimes::default();
    let (error, phase) = memory::measure(|| {
        let mut error = RoundTripError::default();
        for _ in 0..runs {
            let (cpu, t) = (cpu_seconds(), Instant::now());
            naive::inverse(b, &betas, coeffs, &mut g);
            times.inv_wall.push(t.elapsed().as_secs_f64());
            times.inv_cpu.push(cpu_seconds() - cpu);
            let (cpu, t) = (cpu_seconds(), Instant::now());
            naive::forward(b, &betas, &g, &mut result);
            times.fwd_wall.push(t.elapsed().as_secs_f64());
            times.fwd_cpu.push(cpu_seconds() - cpu);
            error = error.worst(workload::roundtrip_error(coeffs, &result));
        }
        error
    });
    let median = workload::median;
    let (fwd, inv) = (median(&times.fwd_wall), median(&times.inv_wall));
    eprintln!("  (B = {b}: plain DWT, {runs} run(s): forward {fwd:.3e} s, inverse {inv:.3e} s)");
    let na = Stages {
        fft: f64::NAN,
        dwt: f64::NAN,
    };
    Row {
        variant: Variant::Naive,
        bandwidth: b,
        threads: 1,
        runs,
        fwd_median: f64::NAN,
        inv_median: f64::NAN,
        fwd: Stages { dwt: fwd, ..na },
        inv: Stages { dwt: inv, ..na },
        dwt_flops: workload::dwt_flops_exact(b),
        peak_1core,
        max_abs_err: error.max_abs,
        rel_l2_err: error.rel_l2,
        memory: phase.map(|p| Memory {
            peak: p.peak,
            start: p.start,
            plan: 0,
            arrays: workload::array_bytes(b, false),
        }),
        ratio: None,
        cpu: Some((median(&times.fwd_cpu), median(&times.inv_cpu))),
    }
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
    fwd_cpu: Vec<f64>,
    inv_cpu: Vec<f64>,
    fwd: Vec<StageTimes>,
    inv: Vec<StageTimes>,
}

impl RunTimes {
    /// Times one inverse `f` (wall and process CPU time, and the library's stages).
    fn inverse(&mut self, f: impl FnOnce() -> so3fft::Result<StageTimes>) -> so3fft::Result<()> {
        timed_call(&mut self.inv, &mut self.inv_wall, &mut self.inv_cpu, f)
    }

    /// Times one forward `f`, as [`RunTimes::inverse`].
    fn forward(&mut self, f: impl FnOnce() -> so3fft::Result<StageTimes>) -> so3fft::Result<()> {
        timed_call(&mut self.fwd, &mut self.fwd_wall, &mut self.fwd_cpu, f)
    }
}

/// Runs `f` and records its stage times, wall time and process CPU time.
fn timed_call(
    stages: &mut Vec<StageTimes>,
    wall: &mut Vec<f64>,
    cpu: &mut Vec<f64>,
    f: impl FnOnce() -> so3fft::Result<StageTimes>,
) -> so3fft::Result<()> {
    let (c, start) = (cpu_seconds(), Instant::now());
    stages.push(f()?);
    wall.push(start.elapsed().as_secs_f64());
    cpu.push(cpu_seconds() - c);
    Ok(())
}

/// A `Direction::Both` plan for `variant` (`Complex`: default options; `NoSkip`:
/// `skip_bits: Some(0)`; `Real`: the real-signal transforms) with the bench's rigour; the
/// planning time goes to stderr.
fn bench_plan(
    b: usize,
    threads: usize,
    variant: Variant,
    opts: &Options,
) -> Result<Plan, so3fft::Error> {
    let plan_start = Instant::now();
    let plan = Plan::new(
        b,
        &PlanOptions {
            direction: Direction::Both,
            threads,
            rigor: opts.rigor,
            skip_bits: (variant == Variant::NoSkip).then_some(0),
            real: variant == Variant::Real,
            fft_threading: opts.fft_threading,
            ..PlanOptions::default()
        },
    )?;
    let what = match variant {
        Variant::NoSkip => ", no skipping",
        Variant::Real => ", real signal",
        _ => "",
    };
    eprintln!(
        "  (B = {b}, threads = {}{what}: plan created in {:.3} s, FFT stage {:?})",
        plan.threads(),
        plan_start.elapsed().as_secs_f64(),
        plan.fft_threading()
    );
    Ok(plan)
}

/// A plan being measured: its times and worst error so far.
struct Config {
    plan: Plan,
    variant: Variant,
    times: RunTimes,
    error: RoundTripError,
}

impl Config {
    /// Plans one (bandwidth, threads) configuration of the library: `Complex` (default
    /// options) or `NoSkip` (`skip_bits: Some(0)`, every degree computed).
    fn new(
        b: usize,
        threads: usize,
        variant: Variant,
        opts: &Options,
    ) -> Result<Config, so3fft::Error> {
        let plan = bench_plan(b, threads, variant, opts)?;
        Ok(Config {
            plan,
            variant,
            times: RunTimes::default(),
            error: RoundTripError::default(),
        })
    }

    /// One untimed round trip: faults in the output pages, warms caches and the thread pool.
    fn warm_up(&self, coeffs: &[Complex64], arrays: &mut Arrays) -> Result<(), so3fft::Error> {
        self.plan.inverse(coeffs, &mut arrays.samples)?;
        self.plan.forward(&arrays.samples, &mut arrays.result)
    }

    /// One timed inverse-then-forward round trip, checked against `coeffs`.
    fn run(&mut self, coeffs: &[Complex64], arrays: &mut Arrays) -> Result<(), so3fft::Error> {
        let plan = &self.plan;
        self.times
            .inverse(|| plan.inverse_timed(coeffs, &mut arrays.samples))?;
        self.times
            .forward(|| plan.forward_timed(&arrays.samples, &mut arrays.result))?;
        let error = workload::roundtrip_error(coeffs, &arrays.result);
        self.error = self.error.worst(error);
        Ok(())
    }

    fn row(&self, b: usize, peak_1core: f64) -> Row {
        let mut row = summarise(b, self.plan.threads(), &self.times, self.error, peak_1core);
        row.variant = self.variant;
        row
    }
}

/// The sample and result arrays of the library's round trips at one bandwidth.
struct Arrays {
    samples: Vec<Complex64>,
    result: Vec<Complex64>,
}

impl Arrays {
    fn new(b: usize) -> Arrays {
        Arrays {
            samples: vec![Complex64::default(); so3fft::num_samples(b)],
            result: vec![Complex64::default(); so3fft::num_coeffs(b)],
        }
    }
}

/// CPU time of the whole process (all threads) in seconds; NaN where unavailable. Against
/// the wall time it shows whether the run had its cores (the machine is shared).
pub fn cpu_seconds() -> f64 {
    let mut ts = libc::timespec {
        tv_sec: 0,
        tv_nsec: 0,
    };
    // SAFETY: `ts` is a valid, writable timespec.
    if unsafe { libc::clock_gettime(libc::CLOCK_PROCESS_CPUTIME_ID, &mut ts) } != 0 {
        return f64::NAN;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// Measures one configuration: warm-up, then the timed runs with the peak memory of the runs.
fn bench_config(
    b: usize,
    threads: usize,
    opts: &Options,
    coeffs: &[Complex64],
    peak_1core: f64,
) -> Result<Row, so3fft::Error> {
    let mut config = Config::new(b, threads, Variant::Complex, opts)?;
    let mut arrays = Arrays::new(b);
    config.warm_up(coeffs, &mut arrays)?;
    let (result, phase) =
        memory::measure(|| (0..opts.runs_for(b)).try_for_each(|_| config.run(coeffs, &mut arrays)));
    result?;
    let mut row = config.row(b, peak_1core);
    row.memory = phase.map(|p| Memory {
        peak: p.peak,
        start: p.start,
        plan: config.plan.memory_bytes() as u64,
        arrays: workload::array_bytes(b, false),
    });
    Ok(row)
}

/// Skipping against no skipping, interleaved run by run (alternating which goes first) so
/// that the load of the shared machine hits both alike; returns the no-skip row with
/// `ratio` = (no-skip / skip) DWT stage medians of these runs. No memory figure: two plans
/// are held (and skipping does not change the allocation).
fn bench_noskip(
    b: usize,
    threads: usize,
    opts: &Options,
    coeffs: &[Complex64],
    peak_1core: f64,
) -> Result<Row, so3fft::Error> {
    let mut noskip = Config::new(b, threads, Variant::NoSkip, opts)?;
    let mut skip = Config::new(b, threads, Variant::Complex, opts)?;
    let mut arrays = Arrays::new(b);
    noskip.warm_up(coeffs, &mut arrays)?;
    skip.warm_up(coeffs, &mut arrays)?;
    for run in 0..opts.runs_for(b) {
        if run % 2 == 0 {
            skip.run(coeffs, &mut arrays)?;
            noskip.run(coeffs, &mut arrays)?;
        } else {
            noskip.run(coeffs, &mut arrays)?;
            skip.run(coeffs, &mut arrays)?;
        }
    }
    let sk = skip.row(b, peak_1core);
    let mut row = noskip.row(b, peak_1core);
    row.ratio = Some((row.fwd.dwt / sk.fwd.dwt, row.inv.dwt / sk.inv.dwt));
    Ok(row)
}

/// The real-signal transforms (`inverse_real` / `forward_real`) against the complex ones at
/// bandwidth `b` on `threads` threads, on coefficients with the real symmetry
/// ([`seeded::fill_real`]). First a phase with only the real plan and arrays alive (one
/// untimed and one timed round trip) gives the peak memory; then `runs` round trips of each
/// path, interleaved (alternating which goes first) so that the load of the shared machine
/// hits both alike. The row has the medians of the interleaved real runs and `ratio` =
/// (real / complex) whole-transform medians of these same runs.
fn bench_real(
    b: usize,
    threads: usize,
    opts: &Options,
    peak_1core: f64,
) -> Result<Row, so3fft::Error> {
    let seed = 0x5EA1_0000 + b as u64;
    let (ns, nc) = (so3fft::num_samples(b), so3fft::num_coeffs(b));
    let mut coeffs = vec![Complex64::default(); nc];
    seeded::fill_real(seed, b, &mut coeffs);
    let real = bench_plan(b, threads, Variant::Real, opts)?;
    let mut samples = vec![0.0f64; ns];
    let mut result = vec![Complex64::default(); nc];
    real.inverse_real(&coeffs, &mut samples)?;
    real.forward_real(&samples, &mut result)?;
    let (measured, phase) = memory::measure(|| {
        real.inverse_real(&coeffs, &mut samples)?;
        real.forward_real(&samples, &mut result)
    });
    measured?;

    let mut complex = Config::new(b, threads, Variant::Complex, opts)?;
    let mut arrays = Arrays::new(b);
    complex.warm_up(&coeffs, &mut arrays)?;
    let mut times = RunTimes::default();
    let mut error = RoundTripError::default();
    let mut real_run = |times: &mut RunTimes| -> Result<(), so3fft::Error> {
        times.inverse(|| real.inverse_real_timed(&coeffs, &mut samples))?;
        times.forward(|| real.forward_real_timed(&samples, &mut result))?;
        error = error.worst(seeded::compare_real(seed, b, &result));
        Ok(())
    };
    for run in 0..opts.runs_for(b) {
        if run % 2 == 0 {
            real_run(&mut times)?;
            complex.run(&coeffs, &mut arrays)?;
        } else {
            complex.run(&coeffs, &mut arrays)?;
            real_run(&mut times)?;
        }
    }
    let c = complex.row(b, peak_1core);
    let mut row = summarise(b, real.threads(), &times, error, peak_1core);
    row.variant = Variant::Real;
    row.dwt_flops = workload::dwt_flops_real(b);
    row.ratio = Some((row.fwd_median / c.fwd_median, row.inv_median / c.inv_median));
    row.memory = phase.map(|p| Memory {
        peak: p.peak,
        start: p.start,
        plan: real.memory_bytes() as u64,
        arrays: workload::array_bytes(b, true),
    });
    Ok(row)
}

/// Medians of the runs, as a table row. The whole-transform times are the bench's own wall
/// clock around each call; the stage times are the library's.
fn summarise(
    b: usize,
    threads: usize,
    times: &RunTimes,
    error: RoundTripError,
    peak_1core: f64,
) -> Row {
    let stages = |t: &[StageTimes]| Stages {
        fft: workload::median(&t.iter().map(|s| s.fft).collect::<Vec<_>>()),
        dwt: workload::median(&t.iter().map(|s| s.dwt).collect::<Vec<_>>()),
    };
    Row {
        variant: Variant::Complex,
        bandwidth: b,
        threads,
        runs: times.fwd_wall.len(),
        fwd_median: workload::median(&times.fwd_wall),
        inv_median: workload::median(&times.inv_wall),
        fwd: stages(&times.fwd),
        inv: stages(&times.inv),
        dwt_flops: workload::dwt_flops_exact(b),
        peak_1core,
        max_abs_err: error.max_abs,
        rel_l2_err: error.rel_l2,
        memory: None,
        ratio: None,
        cpu: Some((
            workload::median(&times.fwd_cpu),
            workload::median(&times.inv_cpu),
        )),
    }
}
