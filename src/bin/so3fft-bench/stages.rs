//! `so3fft-bench stages`: stage times of repeated transforms, for profiling (`perf record`)
//! and for comparing two builds run alternately. Each transform prints the seconds of its
//! FFT and DWT stages on stderr (the forwards also the whole transform).
//!
//! Take the best or the median of the printed times: the first repetition includes page
//! faults and cold caches.

use crate::cli::{Options, StageMode};
use crate::workload::{random_coeffs, XorShift64Star};
use so3fft::{Complex64, Direction, Plan, PlanOptions};

/// Runs `opts.stage_mode` `opts.runs` times for every bandwidth and thread count.
pub fn run(opts: &Options) -> Result<(), so3fft::Error> {
    let repetitions = opts.runs.unwrap_or(1);
    for &b in &opts.bandwidths {
        for &threads in &opts.threads {
            let plan = Plan::new(
                b,
                &PlanOptions {
                    threads,
                    rigor: opts.rigor,
                    max_workspace_bytes: opts.workspace_bytes,
                    direction: Direction::Both,
                    real: opts.stage_mode.real(),
                    fft_threading: opts.fft_threading,
                    ..Default::default()
                },
            )?;
            eprintln!(
                "B = {b}, threads {}, fft threading {:?}",
                plan.threads(),
                plan.fft_threading()
            );
            if opts.stage_mode.real() {
                repeat_real(&plan, opts.stage_mode, repetitions)?;
            } else {
                repeat_complex(&plan, opts.stage_mode, repetitions)?;
            }
            eprintln!("workspace {} MiB", plan.workspace_bytes() >> 20);
        }
    }
    Ok(())
}

/// The complex transforms of `mode`, `repetitions` times, on random coefficients.
fn repeat_complex(plan: &Plan, mode: StageMode, repetitions: usize) -> Result<(), so3fft::Error> {
    let coeffs = random_coeffs(plan.num_coeffs(), 0x1234567);
    let mut result = coeffs.clone();
    let mut samples = vec![Complex64::default(); plan.num_samples()];
    plan.inverse(&coeffs, &mut samples)?;
    for _ in 0..repetitions {
        if mode.inverse() {
            let t = plan.inverse_timed(&coeffs, &mut samples)?;
            eprintln!("inv fft {:.4} dwt {:.4}", t.fft, t.dwt);
        }
        if mode == StageMode::ForwardDestroying {
            let mut input = samples.clone();
            let t = plan.forward_destroying_input_timed(&mut input, &mut result)?;
            eprintln!("dfwd fft {:.4} dwt {:.4}", t.fft, t.dwt);
        } else if mode.forward() {
            let t = plan.forward_timed(&samples, &mut result)?;
            eprintln!("fwd fft {:.4} dwt {:.4} total {:.4}", t.fft, t.dwt, t.total);
        }
    }
    Ok(())
}

/// The real-signal transforms of `mode`, `repetitions` times, on the coefficients of random
/// real samples.
fn repeat_real(plan: &Plan, mode: StageMode, repetitions: usize) -> Result<(), so3fft::Error> {
    let mut rng = XorShift64Star::new(0x1234567);
    let mut samples: Vec<f64> = (0..plan.num_samples())
        .map(|_| rng.next_signed_unit())
        .collect();
    let mut coeffs = vec![Complex64::default(); plan.num_coeffs()];
    plan.forward_real(&samples, &mut coeffs)?;
    let mut result = coeffs.clone();
    for _ in 0..repetitions {
        if mode.inverse() {
            let t = plan.inverse_real_timed(&coeffs, &mut samples)?;
            eprintln!("rinv fft {:.4} dwt {:.4}", t.fft, t.dwt);
        }
        if mode.forward() {
            let t = plan.forward_real_timed(&samples, &mut result)?;
            eprintln!(
                "rfwd fft {:.4} dwt {:.4} total {:.4}",
                t.fft, t.dwt, t.total
            );
        }
    }
    Ok(())
}
