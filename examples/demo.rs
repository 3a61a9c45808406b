//! The main job: round trips (inverse then forward) of random band-limited signals at a
//! few bandwidths, printing the time of each stage and the error.
//!
//! `cargo run --release --example demo [-- B1,B2,...]`

use so3fft::{Complex64, Plan, PlanOptions};
use std::time::Instant;

fn random_coeffs(n: usize, seed: u64) -> Vec<Complex64> {
    let mut s = seed;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..n).map(|_| Complex64::new(next(), next())).collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let bws: Vec<usize> = match std::env::args().nth(1) {
        Some(s) => s
            .split(',')
            .map(|x| x.trim().parse())
            .collect::<Result<_, _>>()?,
        None => vec![8, 16, 32, 64, 128],
    };
    let opts = PlanOptions {
        rigor: so3fft::Rigor::Measure,
        threads: std::env::var("SO3FFT_THREADS")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(0),
        max_workspace_bytes: std::env::var("SO3FFT_WORKSPACE_MB")
            .ok()
            .and_then(|s| s.parse::<usize>().ok())
            .map(|mb| mb << 20),
        skip_bits: std::env::var("SO3FFT_SKIP_BITS")
            .ok()
            .and_then(|s| s.parse().ok()),
        fft_threading: match std::env::var("SO3FFT_FFT_THREADING").as_deref() {
            Ok("workers") => so3fft::FftThreading::SlicesAcrossWorkers,
            Ok("fftw") => so3fft::FftThreading::FftwThreads,
            _ => so3fft::FftThreading::Auto,
        },
        ..Default::default()
    };
    println!("so3fft demo: random coefficients -> inverse -> forward, all cores");
    println!(
        "{:>5} {:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>11} {:>11}",
        "B",
        "threads",
        "plan s",
        "inv s",
        "inv FFT",
        "inv DWT",
        "fwd s",
        "fwd FFT",
        "fwd DWT",
        "max abs err",
        "rel L2 err"
    );
    for b in bws {
        let t = Instant::now();
        let plan = Plan::new(b, &opts)?;
        let t_plan = t.elapsed().as_secs_f64();
        let coeffs = random_coeffs(plan.num_coeffs(), 0x5eed + b as u64);
        let mut samples = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
        let mut back = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
        let ti = plan.inverse_timed(&coeffs, &mut samples)?;
        let tf = plan.forward_timed(&samples, &mut back)?;
        let (mut emax, mut num, mut den) = (0.0f64, 0.0, 0.0);
        for (a, c) in back.iter().zip(&coeffs) {
            emax = emax.max((a - c).norm());
            num += (a - c).norm_sqr();
            den += c.norm_sqr();
        }
        println!(
            "{:>5} {:>7} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>11.3e} {:>11.3e}",
            b,
            plan.threads(),
            t_plan,
            ti.total,
            ti.fft,
            ti.dwt,
            tf.total,
            tf.fft,
            tf.dwt,
            emax,
            (num / den).sqrt()
        );
    }
    Ok(())
}
