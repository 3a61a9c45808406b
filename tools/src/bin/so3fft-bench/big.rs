//! Bandwidths above 256 (`--big`, B = 512): one memory-lean run of each transform.
//!
//! At B = 512 the sample grid alone is `(2B)^3` complex values, 17.2 GB, and the
//! coefficients 2.9 GB, on a machine with 24 GiB and no swap. So no array is ever held twice:
//!
//! 1. Complex round trip. Coefficients are a hash of (seed, index) (`seeded.rs`); the inverse
//!    writes the grid, the forward writes its result over the coefficient array, and the
//!    result is compared with coefficients generated again. The peak resident memory of the
//!    forward (reset just before it) is compared with input + output = grid + coefficients:
//!    the target is at most 5% more.
//! 2. The same without skipping negligible Wigner-d prefixes (`skip_bits: Some(0)`), on the
//!    same arrays (n/a while the library refuses that option).
//! 3. Real-signal round trip (`forward_real` / `inverse_real`, real grid of 8.6 GB) on
//!    coefficients with the real-signal symmetry, also regenerated for the comparison; its
//!    times are related to the complex ones of step 1.
//!
//! Steps 1 and 3 are each followed by the forward that may overwrite its input
//! (`forward_destroying_input`, `forward_real_destroying_input`) on the inverse's samples,
//! with its time, error and peak memory printed (not in the CSV).
//!
//! Each plan is dropped before the next is made (a plan holds a chunk buffer of about 1 GB
//! at B = 512). Before each step the memory it needs is checked against `MemAvailable`; a step
//! that does not fit is skipped with a message. Everything runs once (a run takes minutes).

use crate::cli::Options;
use crate::memory;
use crate::report::{self, Memory, Row, Stages, Variant};
use crate::seeded;
use crate::timing::{self, Timed};
use crate::workload::{self, RoundTripError};
use rayon::prelude::*;
use so3fft::{Complex64, Direction, Plan, StageTimes};
use so3fft_tools::{bar_eprintln, bar_println};
use std::time::Instant;

/// Memory left over for everything else when a step is admitted.
const MARGIN_BYTES: usize = 512 << 20;
/// Bandwidth of the check of the real-signal symmetry with the complex inverse.
const SYMMETRY_CHECK_B: usize = 16;

/// What one lean run produced: its rows, and the reason the no-skip step was not run.
pub struct Outcome {
    pub rows: Vec<Row>,
    pub noskip_missing: Option<String>,
}

/// Runs the three steps at bandwidth `b` with `threads` workers.
pub fn run(b: usize, threads: usize, opts: &Options, peak_1core: f64) -> Outcome {
    bar_eprintln!(
        "  (B = {b}: memory-lean run, {threads} threads, each transform once; grid {:.2} GB, \
         coefficients {:.2} GB)",
        gb(16 * so3fft::num_samples(b)),
        gb(16 * so3fft::num_coeffs(b))
    );
    let mut lean = Lean {
        b,
        threads,
        opts,
        peak_1core,
        coeffs: None,
        destroy_complex: None,
        rows: Vec::new(),
    };
    let noskip_missing = lean.complex_steps();
    lean.real_step();
    Outcome {
        rows: lean.rows,
        noskip_missing,
    }
}

/// The state of the lean run at one bandwidth.
struct Lean<'a> {
    b: usize,
    threads: usize,
    opts: &'a Options,
    peak_1core: f64,
    /// The coefficient array, shared by all steps once allocated.
    coeffs: Option<Vec<Complex64>>,
    /// Time of the complex forward that may overwrite its input (step 1).
    destroy_complex: Option<f64>,
    rows: Vec<Row>,
}

impl Lean<'_> {
    fn seed(&self) -> u64 {
        0x5EED_0000 + self.b as u64
    }

    fn real_seed(&self) -> u64 {
        0x5EED_1000 + self.b as u64
    }

    /// A plan with default options except those given. `workspace`: cap on the chunk buffer
    /// (`None`: the library's default, which depends on `MemAvailable` at planning time).
    fn plan(
        &self,
        skip_bits: Option<u32>,
        real: bool,
        workspace: Option<usize>,
    ) -> Result<Plan, so3fft::Error> {
        Plan::new(
            self.b,
            &so3fft::Options::default()
                .with_direction(Direction::Both)
                .with_threads(self.threads)
                .with_rigor(self.opts.rigor)
                .with_skip_bits(skip_bits)
                .with_real(real)
                .with_max_workspace_bytes(workspace),
        )
    }

    /// Bytes still to allocate for a grid of `grid_bytes` plus the coefficients (if not held).
    fn fits(&self, what: &str, grid_bytes: usize, plan: &Plan) -> bool {
        let coef_bytes = if self.coeffs.is_some() {
            0
        } else {
            16 * so3fft::num_coeffs(self.b)
        };
        let need = grid_bytes + coef_bytes + plan.memory_bytes();
        match workload::mem_available_bytes() {
            Some(avail) if need + MARGIN_BYTES > avail => {
                bar_eprintln!(
                    "so3fft-bench: B = {}: skipping the {what}: it needs {:.2} GB more \
                     (arrays and plan) plus {:.1} GB margin, MemAvailable is {:.2} GB",
                    self.b,
                    gb(need),
                    gb(MARGIN_BYTES),
                    gb(avail)
                );
                false
            }
            Some(_) => true,
            None => {
                bar_eprintln!(
                    "so3fft-bench: cannot read MemAvailable; running B = {} unchecked",
                    self.b
                );
                true
            }
        }
    }

    fn take_coeffs(&mut self) -> Vec<Complex64> {
        self.coeffs
            .take()
            .unwrap_or_else(|| filled(so3fft::num_coeffs(self.b), Complex64::new(0.0, 0.0)))
    }

    /// Steps 1 and 2; returns why the no-skip step was not run, if it was not.
    fn complex_steps(&mut self) -> Option<String> {
        let b = self.b;
        let plan = match self.plan(None, false, None) {
            Ok(p) => p,
            Err(e) => {
                bar_eprintln!("so3fft-bench: B = {b}: complex plan failed: {e}");
                return Some(format!("complex plan failed: {e}"));
            }
        };
        if !self.fits("complex round trip", 16 * so3fft::num_samples(b), &plan) {
            return Some("complex round trip skipped (memory)".into());
        }
        let mut coeffs = self.take_coeffs();
        let t = Instant::now();
        let mut grid = filled(so3fft::num_samples(b), Complex64::new(0.0, 0.0));
        bar_eprintln!(
            "  (grid allocated and faulted in: {:.1} s)",
            t.elapsed().as_secs_f64()
        );

        let skip = self.complex_round_trip(&plan, Variant::Complex, &mut coeffs, &mut grid);
        if let Ok(row) = &skip {
            // The grid still holds the inverse's samples: the forward that may overwrite
            // them, on the same plan (the grid is rewritten by the next step's inverse).
            let arrays = workload::array_bytes(b, false);
            match timed_phase(|| plan.forward_destroying_input(&mut grid, &mut coeffs)) {
                Ok(destroying) => {
                    let error = seeded::compare_complex(self.seed(), &coeffs);
                    self.destroy_complex = Some(destroying.timed.wall);
                    print_destroying("complex", &destroying, error, row.fwd_median, arrays);
                }
                Err(e) => bar_eprintln!("so3fft-bench: B = {b}: destroying forward failed: {e}"),
            }
        }
        // The no-skip plan gets the same chunk buffer: the default depends on MemAvailable,
        // which the grid has just used up, and a smaller chunk makes the DWT stage slower.
        let workspace = plan.workspace_bytes();
        drop(plan);
        let missing = match (&skip, self.plan(Some(0), false, Some(workspace))) {
            (Err(e), _) => Some(format!("complex round trip failed: {e}")),
            (Ok(_), Err(e)) => Some(format!("Plan::new with skip_bits Some(0): {e}")),
            (Ok(_), Ok(plan)) => {
                match self.complex_round_trip(&plan, Variant::NoSkip, &mut coeffs, &mut grid) {
                    Ok(mut row) => {
                        let skip_row = skip.as_ref().expect("checked above");
                        row.ratio = Some((
                            row.fwd.dwt / skip_row.fwd.dwt,
                            row.inv.dwt / skip_row.inv.dwt,
                        ));
                        self.rows.push(row);
                        None
                    }
                    Err(e) => Some(format!("no-skip round trip failed: {e}")),
                }
            }
        };
        match skip {
            Ok(row) => self.rows.insert(0, row),
            Err(e) => bar_eprintln!("so3fft-bench: B = {b}: complex round trip failed: {e}"),
        }
        if let Some(why) = &missing {
            bar_eprintln!("  (B = {b}: no-skip step n/a: {why})");
        }
        drop(grid);
        self.coeffs = Some(coeffs);
        missing
    }

    /// Inverse of seeded coefficients into `grid`, forward back into `coeffs`, comparison
    /// with the regenerated coefficients.
    fn complex_round_trip(
        &self,
        plan: &Plan,
        variant: Variant,
        coeffs: &mut [Complex64],
        grid: &mut [Complex64],
    ) -> Result<Row, so3fft::Error> {
        let b = self.b;
        let t = Instant::now();
        seeded::fill_complex(self.seed(), coeffs);
        bar_eprintln!(
            "  ({}: coefficients generated in {:.1} s)",
            variant.name(),
            t.elapsed().as_secs_f64()
        );
        let inverse = timed_phase(|| plan.inverse(coeffs, grid))?;
        let forward = timed_phase(|| plan.forward(grid, coeffs))?;
        let t = Instant::now();
        let error = seeded::compare_complex(self.seed(), coeffs);
        let row = self.row(variant, plan, RoundTrip { inverse, forward }, error);
        bar_eprintln!(
            "  ({}: compared in {:.1} s; {}; target 1.05)",
            variant.name(),
            t.elapsed().as_secs_f64(),
            memory_summary(
                inverse.phase,
                forward.phase,
                workload::array_bytes(b, false),
                plan
            ),
        );
        if variant == Variant::Complex {
            bar_println!("{}", report::table_line(&row));
        }
        Ok(row)
    }

    /// Step 3.
    fn real_step(&mut self) {
        let b = self.b;
        match seeded::real_symmetry_check(SYMMETRY_CHECK_B, self.real_seed()) {
            Ok((im, abs)) => bar_eprintln!(
                "  (real-signal coefficients fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M')): \
                 complex inverse at B = {SYMMETRY_CHECK_B} gives max |Im f| = {im:.2e}, max |f| = {abs:.2e})"
            ),
            Err(e) => bar_eprintln!("so3fft-bench: real symmetry check failed: {e}"),
        }
        let plan = match self.plan(None, true, None) {
            Ok(p) => p,
            Err(e) => {
                bar_eprintln!("so3fft-bench: B = {b}: real plan failed: {e}");
                return;
            }
        };
        if !self.fits("real round trip", 8 * so3fft::num_samples(b), &plan) {
            return;
        }
        let mut coeffs = self.take_coeffs();
        let t = Instant::now();
        let mut grid = filled(so3fft::num_samples(b), 0.0f64);
        bar_eprintln!(
            "  (real grid allocated and faulted in: {:.1} s)",
            t.elapsed().as_secs_f64()
        );
        match self.real_round_trip(&plan, &mut coeffs, &mut grid) {
            Ok(row) => {
                let arrays = workload::array_bytes(b, true);
                let destroying =
                    timed_phase(|| plan.forward_real_destroying_input(&mut grid, &mut coeffs));
                match destroying {
                    Ok(destroying) => {
                        let error = seeded::compare_real(self.real_seed(), b, &coeffs);
                        print_destroying("real", &destroying, error, row.fwd_median, arrays);
                        if let Some(complex) = self.destroy_complex {
                            bar_println!(
                                "  destroying forwards, real over complex: {:.3}",
                                destroying.timed.wall / complex
                            );
                        }
                    }
                    Err(e) => {
                        bar_eprintln!("so3fft-bench: B = {b}: destroying forward failed: {e}")
                    }
                }
                self.rows.push(row)
            }
            Err(e) => bar_eprintln!("so3fft-bench: B = {b}: real round trip failed: {e}"),
        }
        self.coeffs = Some(coeffs);
    }

    fn real_round_trip(
        &self,
        plan: &Plan,
        coeffs: &mut [Complex64],
        grid: &mut [f64],
    ) -> Result<Row, so3fft::Error> {
        let b = self.b;
        seeded::fill_real(self.real_seed(), b, coeffs);
        let inverse = timed_phase(|| plan.inverse_real(coeffs, grid))?;
        let forward = timed_phase(|| plan.forward_real(grid, coeffs))?;
        let error = seeded::compare_real(self.real_seed(), b, coeffs);
        let arrays = workload::array_bytes(b, true);
        let mut row = self.row(Variant::Real, plan, RoundTrip { inverse, forward }, error);
        row.ratio = self
            .rows
            .iter()
            .find(|r| r.variant == Variant::Complex)
            .map(|c| (row.fwd_median / c.fwd_median, row.inv_median / c.inv_median));
        bar_eprintln!(
            "  (real: {})",
            memory_summary(inverse.phase, forward.phase, arrays, plan)
        );
        Ok(row)
    }

    /// The row of one round trip of `plan` (`variant`: complex, no-skip or real), with the
    /// peak memory of its forward.
    fn row(&self, variant: Variant, plan: &Plan, trip: RoundTrip, error: RoundTripError) -> Row {
        let real = variant == Variant::Real;
        let stages = |t: StageTimes| Stages {
            fft: t.fft,
            dwt: t.dwt,
        };
        let (inv, fwd) = (trip.inverse.timed, trip.forward.timed);
        let arrays = workload::array_bytes(self.b, real);
        let plan_bytes = plan.memory_bytes() as u64;
        Row {
            variant,
            bandwidth: self.b,
            threads: self.threads,
            runs: 1,
            fwd_median: fwd.wall,
            inv_median: inv.wall,
            fwd: stages(fwd.stages),
            inv: stages(inv.stages),
            dwt_flops: if real {
                workload::dwt_flops_real(self.b)
            } else {
                workload::dwt_flops_exact(self.b)
            },
            peak_1core: self.peak_1core,
            max_abs_err: error.max_abs,
            rel_l2_err: error.rel_l2,
            memory: trip
                .forward
                .phase
                .map(|p| Memory::of_phase(p, plan_bytes, arrays)),
            ratio: None,
            cpu: Some((fwd.cpu, inv.cpu)),
        }
    }
}

/// Prints the result of a forward that may overwrite its input (`what`: complex or real):
/// time, stages, error against the seeded coefficients, ratio to the preserving forward
/// (`preserving` seconds) of the same plan, and its peak memory against input + output
/// (`arrays` bytes).
fn print_destroying(
    what: &str,
    destroying: &Measured,
    error: RoundTripError,
    preserving: f64,
    arrays: u64,
) {
    let peak = destroying.phase.map_or("n/a".into(), |p| {
        format!("{:.4}", p.peak as f64 / arrays as f64)
    });
    let Timed { wall, stages, .. } = destroying.timed;
    bar_println!(
        "  {what} forward destroying its input: {wall:.3e} s (FFT {:.3e} / DWT {:.3e}), \
         {:.3} x the preserving forward; errors {:.2e} / {:.2e}; peak {peak} x (input + output)",
        stages.fft,
        stages.dwt,
        wall / preserving,
        error.max_abs,
        error.rel_l2,
    );
}

/// One transform timed in a phase of its own: its times and the phase's peak memory.
#[derive(Clone, Copy)]
struct Measured {
    timed: Timed,
    phase: Option<memory::Phase>,
}

/// The inverse and the forward of one round trip.
struct RoundTrip {
    inverse: Measured,
    forward: Measured,
}

/// Runs `transform` with the peak-memory counter reset first: its times and the peak of the
/// phase.
fn timed_phase(transform: impl FnOnce() -> so3fft::Result<StageTimes>) -> so3fft::Result<Measured> {
    let (timed, phase) = memory::measure(|| timing::time(transform));
    Ok(Measured {
        timed: timed?,
        phase,
    })
}

/// A vector of `n` copies of `value`, written in parallel (which also faults the pages in, so
/// the first transform's time does not include that).
pub fn filled<T: Copy + Send + Sync>(n: usize, value: T) -> Vec<T> {
    let mut v: Vec<T> = Vec::with_capacity(n);
    v.spare_capacity_mut()
        .par_chunks_mut(1 << 16)
        .for_each(|c| {
            c.iter_mut().for_each(|x| {
                x.write(value);
            })
        });
    // SAFETY: the first `n` elements were initialised just above.
    unsafe { v.set_len(n) };
    v
}

fn gb(bytes: usize) -> f64 {
    bytes as f64 / 1e9
}

/// Peaks of both phases, the forward's against `arrays` bytes, and the plan's memory.
fn memory_summary(
    inv: Option<memory::Phase>,
    fwd: Option<memory::Phase>,
    arrays: u64,
    plan: &Plan,
) -> String {
    format!(
        "peak RSS during the inverse {}, during the forward {} = {} x (input + output = {:.3} GB); \
         plan memory_bytes {:.3} GB, of which chunk buffer {:.3} GB",
        phase_gb(inv),
        phase_gb(fwd),
        fwd.map_or("n/a".into(), |p| format!("{:.4}", p.peak as f64 / arrays as f64)),
        arrays as f64 / 1e9,
        gb(plan.memory_bytes()),
        gb(plan.workspace_bytes()),
    )
}

fn phase_gb(p: Option<memory::Phase>) -> String {
    p.map_or("n/a".into(), |p| format!("{:.3} GB", p.peak as f64 / 1e9))
}

#[cfg(test)]
mod tests {
    use super::{run, Variant};

    /// The whole lean procedure at a small bandwidth: three rows, exact round trips.
    #[test]
    fn lean_run_at_small_bandwidth() {
        let opts = crate::cli::Options {
            rigor: so3fft::Rigor::Estimate,
            ..Default::default()
        };
        let out = run(24, 2, &opts, 100.0);
        assert!(out.noskip_missing.is_none(), "{:?}", out.noskip_missing);
        let variants: Vec<Variant> = out.rows.iter().map(|r| r.variant).collect();
        assert_eq!(variants, [Variant::Complex, Variant::NoSkip, Variant::Real]);
        for r in &out.rows {
            assert!(r.max_abs_err < 1e-13 && r.rel_l2_err < 1e-14, "{r:?}");
            assert!(
                r.fwd.dwt > 0.0 && r.inv.fft > 0.0 && r.fwd_median > 0.0,
                "{r:?}"
            );
            assert!(r.ratio.is_some() || r.variant == Variant::Complex, "{r:?}");
        }
        assert!(out.rows[0].memory.is_some());
    }
}
