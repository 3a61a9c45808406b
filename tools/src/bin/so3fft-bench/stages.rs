//! `so3fft-bench stages`: stage times of repeated transforms, for profiling (`perf record`)
//! and for comparing two builds run alternately. Each transform prints the seconds of its
//! FFT and DWT stages on stderr (the forwards also the whole transform).
//!
//! Take the best or the median of the printed times: the first repetition includes page
//! faults and cold caches.

use crate::cli::{Options, StageMode};
use crate::workload::{dwt_flops_exact, dwt_flops_real, random_coeffs, XorShift64Star};
use so3fft::{Complex64, Direction, Plan};

/// Stage times of the repetitions of one plan, per transform kind.
#[derive(Default)]
struct Times {
    /// `(kind, fft seconds, dwt seconds)` in the order run.
    runs: Vec<(&'static str, f64, f64)>,
}

impl Times {
    fn push(&mut self, kind: &'static str, t: &so3fft::StageTimes) {
        eprintln!("{kind} fft {:.4} dwt {:.4}", t.fft, t.dwt);
        self.runs.push((kind, t.fft, t.dwt));
    }

    /// One line per kind: median stage times and the DWT stage's nominal GFLOP/s against
    /// `peak` (the FMA peak of the threads used).
    fn summary(&self, flops: u64, peak: f64) {
        let mut kinds: Vec<&str> = self.runs.iter().map(|r| r.0).collect();
        kinds.dedup();
        kinds.sort();
        kinds.dedup();
        for kind in kinds {
            let pick = |f: fn(&(&str, f64, f64)) -> f64| {
                let mut v: Vec<f64> = self.runs.iter().filter(|r| r.0 == kind).map(f).collect();
                v.sort_by(f64::total_cmp);
                v[v.len() / 2]
            };
            let (fft, dwt) = (pick(|r| r.1), pick(|r| r.2));
            let gflops = flops as f64 / dwt / 1e9;
            eprintln!(
                "median {kind}: fft {fft:.4} dwt {dwt:.4} s, DWT {gflops:.1} GFLOP/s = {:.0}% of the FMA peak {peak:.1}",
                100.0 * gflops / peak
            );
        }
    }
}

/// Runs `opts.stage_mode` `opts.runs` times for every bandwidth and thread count.
pub fn run(opts: &Options) -> Result<(), so3fft::Error> {
    let repetitions = opts.runs.unwrap_or(1);
    let peak1 = crate::peak::measure(1);
    eprintln!(
        "FMA peak of one core: {:.1} GFLOP/s ({})",
        peak1.one_core,
        peak1.isa.name()
    );
    for &b in &opts.bandwidths {
        for &threads in &opts.threads {
            let plan = Plan::new(
                b,
                &so3fft::Options::default()
                    .with_threads(threads)
                    .with_rigor(opts.rigor)
                    .with_max_workspace_bytes(opts.workspace_bytes)
                    .with_direction(Direction::Both)
                    .with_real(opts.stage_mode.real()),
            )?;
            eprintln!("B = {b}, threads {}", plan.threads(),);
            let (times, flops) = if opts.stage_mode.real() {
                (
                    repeat_real(&plan, opts.stage_mode, repetitions)?,
                    dwt_flops_real(b),
                )
            } else {
                (
                    repeat_complex(&plan, opts.stage_mode, repetitions)?,
                    dwt_flops_exact(b),
                )
            };
            eprintln!("workspace {} MiB", plan.workspace_bytes() >> 20);
            times.summary(flops, peak1.one_core * plan.threads() as f64);
        }
    }
    Ok(())
}

/// The complex transforms of `mode`, `repetitions` times, on random coefficients.
fn repeat_complex(
    plan: &Plan,
    mode: StageMode,
    repetitions: usize,
) -> Result<Times, so3fft::Error> {
    let mut times = Times::default();
    let coeffs = random_coeffs(plan.num_coeffs(), 0x1234567);
    let mut result = coeffs.clone();
    let mut samples = vec![Complex64::default(); plan.num_samples()];
    plan.inverse(&coeffs, &mut samples)?;
    for _ in 0..repetitions {
        if mode.inverse() {
            times.push("inv", &plan.inverse(&coeffs, &mut samples)?);
        }
        if mode == StageMode::ForwardDestroying {
            let mut input = samples.clone();
            times.push(
                "dfwd",
                &plan.forward_destroying_input(&mut input, &mut result)?,
            );
        } else if mode.forward() {
            times.push("fwd", &plan.forward(&samples, &mut result)?);
        }
    }
    Ok(times)
}

/// The real-signal transforms of `mode`, `repetitions` times, on the coefficients of random
/// real samples.
fn repeat_real(plan: &Plan, mode: StageMode, repetitions: usize) -> Result<Times, so3fft::Error> {
    let mut times = Times::default();
    let mut rng = XorShift64Star::new(0x1234567);
    let mut samples: Vec<f64> = (0..plan.num_samples())
        .map(|_| rng.next_signed_unit())
        .collect();
    let mut coeffs = vec![Complex64::default(); plan.num_coeffs()];
    plan.forward_real(&samples, &mut coeffs)?;
    let mut result = coeffs.clone();
    for _ in 0..repetitions {
        if mode.inverse() {
            times.push("rinv", &plan.inverse_real(&coeffs, &mut samples)?);
        }
        if mode.forward() {
            times.push("rfwd", &plan.forward_real(&samples, &mut result)?);
        }
    }
    Ok(times)
}
