//! How often `FftThreading::Auto` keeps FFTW's threads: makes plans with two threads and
//! `Rigor::Measure` and counts the choice (a check of the plan-time measurement's
//! robustness; run it with and without load on the other core).
//!
//! `cargo bench --bench tune_count -- [B] [PLANS]` (defaults 128 and 20).

use so3fft::{FftThreading, Options, Plan, Rigor};

fn main() {
    // `cargo bench` adds flags such as `--bench`: only the plain arguments count.
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let arg = |i: usize, default: usize| -> usize {
        match args.get(i).cloned() {
            None => default,
            Some(s) => s.parse().unwrap_or_else(|_| {
                eprintln!("usage: tune_count [B] [PLANS]  (got {s:?})");
                std::process::exit(2)
            }),
        }
    };
    let (b, n) = (arg(0, 128), arg(1, 20));
    let options = Options::default()
        .with_threads(2)
        .with_rigor(Rigor::Measure);
    let mut fftw = 0;
    let t = std::time::Instant::now();
    for _ in 0..n {
        let plan = Plan::new(b, &options).unwrap_or_else(|e| {
            eprintln!("tune_count: {e}");
            std::process::exit(1)
        });
        if plan.fft_threading() == FftThreading::FftwThreads {
            fftw += 1;
        }
    }
    println!(
        "B={b}: {fftw} of {n} plans kept FFTW's threads ({:.3} s per plan)",
        t.elapsed().as_secs_f64() / n.max(1) as f64
    );
}
