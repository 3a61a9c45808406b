//! Bandwidths up to 256: every thread count, the no-skip run, the real-signal run and the
//! plain DWT, each timed over several runs with the round trip checked.

use crate::cli::Options;
use crate::memory;
use crate::naive;
use crate::report::{self, Memory, Row, Stages, Variant};
use crate::seeded;
use crate::timing::{median_of, RunTimes};
use crate::workload::{self, RoundTripError};
use so3fft::{Complex64, Direction, Plan};
use so3fft_tools::{bar_eprintln, bar_println};
use std::time::Instant;

/// Share of `MemAvailable` a configuration may use before it is skipped: the machine has no
/// swap, so running out of memory kills the process instead of slowing it down.
const MEMORY_FRACTION: f64 = 0.8;

/// What every measurement at one bandwidth shares.
#[derive(Clone, Copy)]
pub struct Setup<'a> {
    /// The bandwidth B.
    pub b: usize,
    pub opts: &'a Options,
    /// Measured single-core FMA peak, GFLOP/s (NaN: not measured).
    pub peak_1core: f64,
}

/// Rows of one bandwidth and the reasons of missing no-skip runs, as they accumulate.
pub struct Results {
    pub rows: Vec<Row>,
    /// (bandwidth, reason) where the no-skip run could not be made.
    pub noskip_missing: Vec<(usize, String)>,
}

/// All measurements at one bandwidth B <= 256: every thread count, the no-skip run (first
/// thread count), the real-signal run (last thread count) and the plain DWT. The random
/// coefficients are shared between the complex runs and the plain DWT.
pub fn bench_bandwidth(setup: Setup, results: &mut Results) {
    let (b, opts) = (setup.b, setup.opts);
    if !fits_in_memory(b) {
        return;
    }
    let coeffs = workload::random_coeffs(so3fft::num_coeffs(b), 0x5EED_0000 + b as u64);
    for &threads in &opts.threads {
        match complex_row(setup, threads, &coeffs) {
            Ok(row) => {
                bar_println!("{}", report::table_line(&row));
                results.rows.push(row);
            }
            Err(e) => bar_eprintln!("so3fft-bench: B = {b}, threads = {threads}: skipped: {e}"),
        }
    }

    match noskip_row(setup, opts.threads[0], &coeffs) {
        Ok(row) => results.rows.push(row),
        Err(e) => {
            bar_eprintln!("  (B = {b}: no-skip run n/a: {e})");
            results.noskip_missing.push((b, e.to_string()));
        }
    }

    let real_threads = *opts.threads.last().expect("at least one thread count");
    match real_row(setup, real_threads) {
        Ok(row) => results.rows.push(row),
        Err(e) => bar_eprintln!("so3fft-bench: B = {b}: real-signal run skipped: {e}"),
    }

    if b <= opts.naive_max {
        let mut row = naive_row(setup, &coeffs);
        let library = match report::find(&results.rows, Variant::Complex, b, 1) {
            Some(r) => Ok(r.clone()),
            None => {
                bar_eprintln!(
                    "  (B = {b}: library one-thread DWT measured for the plain-DWT ratio)"
                );
                complex_row(setup, 1, &coeffs)
            }
        };
        match library {
            Ok(lib) => row.ratio = Some((lib.fwd.dwt / row.fwd.dwt, lib.inv.dwt / row.inv.dwt)),
            Err(e) => bar_eprintln!("so3fft-bench: B = {b}: one-thread plan failed: {e}"),
        }
        results.rows.push(row);
    }
}

/// Timed runs of the plain DWT (inverse of `coeffs` to the slice spectra, forward back):
/// one run from B = 128 on (about 1 s per direction), else up to 3.
fn naive_row(setup: Setup, coeffs: &[Complex64]) -> Row {
    let b = setup.b;
    let runs = if b >= 128 {
        1
    } else {
        setup.opts.runs_for(b).min(3)
    };
    let n = 2 * b;
    let betas = naive::Betas::new(b);
    let mut spectra = vec![Complex64::default(); n * n * n];
    let mut result = vec![Complex64::default(); coeffs.len()];
    let mut times = RunTimes::default();
    let (error, phase) = memory::measure(|| {
        let mut error = RoundTripError::default();
        for _ in 0..runs {
            // The plain DWT has no stage times: the whole call is its DWT.
            let _ = times.inverse(|| {
                naive::inverse(b, &betas, coeffs, &mut spectra);
                Ok(Default::default())
            });
            let _ = times.forward(|| {
                naive::forward(b, &betas, &spectra, &mut result);
                Ok(Default::default())
            });
            error = error.worst(workload::roundtrip_error(coeffs, &result));
        }
        error
    });
    let forward = median_of(&times.forward, |t| t.wall);
    let inverse = median_of(&times.inverse, |t| t.wall);
    bar_eprintln!(
        "  (B = {b}: plain DWT, {runs} run(s): forward {forward:.3e} s, inverse {inverse:.3e} s)"
    );
    let not_applicable = Stages {
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
        fwd: Stages {
            dwt: forward,
            ..not_applicable
        },
        inv: Stages {
            dwt: inverse,
            ..not_applicable
        },
        dwt_flops: workload::dwt_flops_exact(b),
        peak_1core: setup.peak_1core,
        max_abs_err: error.max_abs,
        rel_l2_err: error.rel_l2,
        memory: phase.map(|p| Memory::of_phase(p, 0, workload::array_bytes(b, false))),
        ratio: None,
        cpu: Some((
            median_of(&times.forward, |t| t.cpu),
            median_of(&times.inverse, |t| t.cpu),
        )),
    }
}

/// Whether bandwidth `b` fits in [`MEMORY_FRACTION`] of the available memory (warns if not).
fn fits_in_memory(b: usize) -> bool {
    let need = workload::estimated_bytes(b);
    let Some(available) = workload::mem_available_bytes() else {
        bar_eprintln!("so3fft-bench: cannot read MemAvailable; running B = {b} unchecked");
        return true;
    };
    let fits = (need as f64) <= MEMORY_FRACTION * available as f64;
    if !fits {
        bar_eprintln!(
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

/// A `Direction::Both` plan for `variant` (`Complex`: default options; `NoSkip`:
/// `skip_bits: Some(0)`; `Real`: the real-signal transforms) with the bench's rigour and FFT
/// threading; the planning time goes to stderr.
fn bench_plan(setup: Setup, threads: usize, variant: Variant) -> Result<Plan, so3fft::Error> {
    let (b, opts) = (setup.b, setup.opts);
    let plan_start = Instant::now();
    let plan = Plan::new(
        b,
        &so3fft::Options::default()
            .with_direction(Direction::Both)
            .with_threads(threads)
            .with_rigor(opts.rigor)
            .with_skip_bits((variant == Variant::NoSkip).then_some(0))
            .with_real(variant == Variant::Real),
    )?;
    let what = match variant {
        Variant::NoSkip => ", no skipping",
        Variant::Real => ", real signal",
        _ => "",
    };
    bar_eprintln!(
        "  (B = {b}, threads = {}{what}: plan created in {:.3} s)",
        plan.threads(),
        plan_start.elapsed().as_secs_f64(),
    );
    Ok(plan)
}

/// A complex-transform plan being measured: its times and worst error so far.
struct Config<'a> {
    setup: Setup<'a>,
    plan: Plan,
    variant: Variant,
    times: RunTimes,
    error: RoundTripError,
}

impl<'a> Config<'a> {
    /// Plans one (bandwidth, threads) configuration of the library: `Complex` (default
    /// options) or `NoSkip` (`skip_bits: Some(0)`, every degree computed).
    fn new(setup: Setup<'a>, threads: usize, variant: Variant) -> Result<Self, so3fft::Error> {
        Ok(Config {
            setup,
            plan: bench_plan(setup, threads, variant)?,
            variant,
            times: RunTimes::default(),
            error: RoundTripError::default(),
        })
    }

    /// One untimed round trip: faults in the output pages, warms caches and the thread pool.
    fn warm_up(&self, coeffs: &[Complex64], arrays: &mut Arrays) -> Result<(), so3fft::Error> {
        self.plan.inverse(coeffs, &mut arrays.samples)?;
        self.plan.forward(&arrays.samples, &mut arrays.result)?;
        Ok(())
    }

    /// One timed inverse-then-forward round trip, checked against `coeffs`.
    fn run(&mut self, coeffs: &[Complex64], arrays: &mut Arrays) -> Result<(), so3fft::Error> {
        let plan = &self.plan;
        self.times
            .inverse(|| plan.inverse(coeffs, &mut arrays.samples))?;
        self.times
            .forward(|| plan.forward(&arrays.samples, &mut arrays.result))?;
        let error = workload::roundtrip_error(coeffs, &arrays.result);
        self.error = self.error.worst(error);
        Ok(())
    }

    fn row(&self) -> Row {
        let mut row = summarise(self.setup, self.plan.threads(), &self.times, self.error);
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

/// Measures the complex transforms on `threads` threads: warm-up, then the timed runs with
/// the peak memory of the runs.
fn complex_row(setup: Setup, threads: usize, coeffs: &[Complex64]) -> Result<Row, so3fft::Error> {
    let b = setup.b;
    let mut config = Config::new(setup, threads, Variant::Complex)?;
    let mut arrays = Arrays::new(b);
    config.warm_up(coeffs, &mut arrays)?;
    let (result, phase) = memory::measure(|| {
        (0..setup.opts.runs_for(b)).try_for_each(|_| config.run(coeffs, &mut arrays))
    });
    result?;
    let mut row = config.row();
    let plan_bytes = config.plan.memory_bytes() as u64;
    row.memory = phase.map(|p| Memory::of_phase(p, plan_bytes, workload::array_bytes(b, false)));
    Ok(row)
}

/// Skipping against no skipping, interleaved run by run (alternating which goes first) so
/// that the load of the shared machine hits both alike; returns the no-skip row with
/// `ratio` = (no-skip / skip) DWT stage medians of these runs. No memory figure: two plans
/// are held (and skipping does not change the allocation).
fn noskip_row(setup: Setup, threads: usize, coeffs: &[Complex64]) -> Result<Row, so3fft::Error> {
    let mut noskip = Config::new(setup, threads, Variant::NoSkip)?;
    let mut skip = Config::new(setup, threads, Variant::Complex)?;
    let mut arrays = Arrays::new(setup.b);
    noskip.warm_up(coeffs, &mut arrays)?;
    skip.warm_up(coeffs, &mut arrays)?;
    for run in 0..setup.opts.runs_for(setup.b) {
        if run % 2 == 0 {
            skip.run(coeffs, &mut arrays)?;
            noskip.run(coeffs, &mut arrays)?;
        } else {
            noskip.run(coeffs, &mut arrays)?;
            skip.run(coeffs, &mut arrays)?;
        }
    }
    let skip_row = skip.row();
    let mut row = noskip.row();
    row.ratio = Some((
        row.fwd.dwt / skip_row.fwd.dwt,
        row.inv.dwt / skip_row.inv.dwt,
    ));
    Ok(row)
}

/// The real-signal transforms (`inverse_real` / `forward_real`) against the complex ones on
/// `threads` threads, on coefficients with the real symmetry ([`seeded::fill_real`]). First
/// a phase with only the real plan and arrays alive (one untimed and one timed round trip)
/// gives the peak memory; then the round trips of each path, interleaved (alternating which
/// goes first) so that the load of the shared machine hits both alike. The row has the
/// medians of the interleaved real runs and `ratio` = (real / complex) whole-transform
/// medians of these same runs.
pub fn real_row(setup: Setup, threads: usize) -> Result<Row, so3fft::Error> {
    let b = setup.b;
    let seed = 0x5EA1_0000 + b as u64;
    let (num_samples, num_coeffs) = (so3fft::num_samples(b), so3fft::num_coeffs(b));
    let mut coeffs = vec![Complex64::default(); num_coeffs];
    seeded::fill_real(seed, b, &mut coeffs);
    let real = bench_plan(setup, threads, Variant::Real)?;
    let mut samples = vec![0.0f64; num_samples];
    let mut result = vec![Complex64::default(); num_coeffs];
    real.inverse_real(&coeffs, &mut samples)?;
    real.forward_real(&samples, &mut result)?;
    let (measured, phase) = memory::measure(|| {
        real.inverse_real(&coeffs, &mut samples)?;
        real.forward_real(&samples, &mut result)
    });
    measured?;

    let mut complex = Config::new(setup, threads, Variant::Complex)?;
    let mut arrays = Arrays::new(b);
    complex.warm_up(&coeffs, &mut arrays)?;
    let mut times = RunTimes::default();
    let mut error = RoundTripError::default();
    let mut real_run = |times: &mut RunTimes| -> Result<(), so3fft::Error> {
        times.inverse(|| real.inverse_real(&coeffs, &mut samples))?;
        times.forward(|| real.forward_real(&samples, &mut result))?;
        error = error.worst(seeded::compare_real(seed, b, &result));
        Ok(())
    };
    for run in 0..setup.opts.runs_for(b) {
        if run % 2 == 0 {
            real_run(&mut times)?;
            complex.run(&coeffs, &mut arrays)?;
        } else {
            complex.run(&coeffs, &mut arrays)?;
            real_run(&mut times)?;
        }
    }
    let complex_row = complex.row();
    let mut row = summarise(setup, real.threads(), &times, error);
    row.variant = Variant::Real;
    row.dwt_flops = workload::dwt_flops_real(b);
    row.ratio = Some((
        row.fwd_median / complex_row.fwd_median,
        row.inv_median / complex_row.inv_median,
    ));
    let plan_bytes = real.memory_bytes() as u64;
    row.memory = phase.map(|p| Memory::of_phase(p, plan_bytes, workload::array_bytes(b, true)));
    Ok(row)
}

/// Medians of the runs, as a table row. The whole-transform times are the bench's own wall
/// clock around each call; the stage times are the library's.
fn summarise(setup: Setup, threads: usize, times: &RunTimes, error: RoundTripError) -> Row {
    let b = setup.b;
    let (fwd, inv) = (&times.forward, &times.inverse);
    Row {
        variant: Variant::Complex,
        bandwidth: b,
        threads,
        runs: fwd.len(),
        fwd_median: median_of(fwd, |t| t.wall),
        inv_median: median_of(inv, |t| t.wall),
        fwd: Stages {
            fft: median_of(fwd, |t| t.stages.fft),
            dwt: median_of(fwd, |t| t.stages.dwt),
        },
        inv: Stages {
            fft: median_of(inv, |t| t.stages.fft),
            dwt: median_of(inv, |t| t.stages.dwt),
        },
        dwt_flops: workload::dwt_flops_exact(b),
        peak_1core: setup.peak_1core,
        max_abs_err: error.max_abs,
        rel_l2_err: error.rel_l2,
        memory: None,
        ratio: None,
        cpu: Some((median_of(fwd, |t| t.cpu), median_of(inv, |t| t.cpu))),
    }
}
