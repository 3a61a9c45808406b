//! Thread scaling on a shared machine: the whole transform and its stages on 1 and on 2
//! threads, with runs disturbed by other processes thrown away.
//!
//! `cargo run --release --example scaling [-- B1,B2,...]` (default 64,128,256). Environment:
//! `SO3FFT_RUNS` (clean measurements per configuration, default 5),
//! `SO3FFT_FFT_THREADING` = `workers` | `fftw` (default: the library's choice).
//!
//! Each measurement is a window of `k` inverse + forward pairs (`k` chosen so the window
//! lasts at least 0.3 s). A window counts only if the CPU time used by other processes
//! during it (from `/proc/stat`, minus this process's own time) stays below 3% of the
//! machine; otherwise it is repeated. The 1- and 2-thread plans alternate, and medians of
//! the clean windows are reported.

use so3fft::{Complex64, FftThreading, Plan, PlanOptions, Rigor, StageTimes};
use std::time::Instant;

/// (busy ticks of the whole machine, all ticks, this process's ticks).
fn ticks() -> (u64, u64, u64) {
    let stat = std::fs::read_to_string("/proc/stat").unwrap_or_default();
    let v: Vec<u64> = stat
        .lines()
        .next()
        .unwrap_or("")
        .split_whitespace()
        .skip(1)
        .filter_map(|x| x.parse().ok())
        .collect();
    let all: u64 = v.iter().sum();
    let idle = v.get(3).copied().unwrap_or(0) + v.get(4).copied().unwrap_or(0);
    let own = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    // Fields after the command name (which may contain spaces), from the state on:
    // utime is the 12th, stime the 13th.
    let rest = own.rsplit(')').next().unwrap_or("");
    let f: Vec<&str> = rest.split_whitespace().collect();
    let field = |i: usize| f.get(i).and_then(|x| x.parse::<u64>().ok()).unwrap_or(0);
    let mine = field(11) + field(12);
    (all - idle, all, mine)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

/// One clean window: mean (inverse, forward) stage times over `k` pairs.
fn clean_window(
    plan: &Plan,
    k: usize,
    c: &[Complex64],
    s: &mut [Complex64],
    back: &mut [Complex64],
) -> (StageTimes, StageTimes) {
    loop {
        let (b0, a0, m0) = ticks();
        let mut ti = StageTimes::default();
        let mut tf = StageTimes::default();
        for _ in 0..k {
            let i = plan.inverse_timed(c, s).unwrap();
            let f = plan.forward_timed(s, back).unwrap();
            for (acc, x) in [(&mut ti, i), (&mut tf, f)] {
                acc.fft += x.fft / k as f64;
                acc.dwt += x.dwt / k as f64;
                acc.total += x.total / k as f64;
            }
        }
        let (b1, a1, m1) = ticks();
        let others = (b1 - b0).saturating_sub(m1 - m0);
        if (others as f64) <= 0.03 * (a1 - a0) as f64 + 1.0 {
            return (ti, tf);
        }
        eprintln!(
            "window disturbed: other processes used {:.0}% of the machine",
            100.0 * others as f64 / (a1 - a0) as f64
        );
        std::thread::sleep(std::time::Duration::from_millis(500));
    }
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let bws: Vec<usize> = match std::env::args().nth(1) {
        Some(s) => s
            .split(',')
            .map(|x| x.trim().parse())
            .collect::<Result<_, _>>()?,
        None => vec![64, 128, 256],
    };
    let runs: usize = std::env::var("SO3FFT_RUNS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(5);
    let fft_threading = match std::env::var("SO3FFT_FFT_THREADING").as_deref() {
        Ok("workers") => FftThreading::SlicesAcrossWorkers,
        Ok("fftw") => FftThreading::FftwThreads,
        _ => FftThreading::Auto,
    };
    println!("medians of {runs} clean windows; seconds per transform");
    println!(
        "{:>5} {:>3} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10}  fft threading",
        "B", "thr", "inv", "inv fft", "inv dwt", "fwd", "fwd fft", "fwd dwt"
    );
    for b in bws {
        let mk = |threads| {
            Plan::new(
                b,
                &PlanOptions {
                    threads,
                    rigor: Rigor::Measure,
                    fft_threading,
                    ..Default::default()
                },
            )
        };
        let plans = [mk(1)?, mk(2)?];
        let mut st = 0x9e37_79b9_7f4a_7c15_u64 ^ b as u64;
        let mut next = move || {
            st ^= st << 13;
            st ^= st >> 7;
            st ^= st << 17;
            (st >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        };
        let c: Vec<Complex64> = (0..plans[0].num_coeffs())
            .map(|_| Complex64::new(next(), next()))
            .collect();
        let mut s = vec![Complex64::new(0.0, 0.0); plans[0].num_samples()];
        let mut back = vec![Complex64::new(0.0, 0.0); plans[0].num_coeffs()];
        // Window length: at least 0.3 s of the 1-thread plan (warm-up run included).
        let t = Instant::now();
        plans[0].inverse(&c, &mut s)?;
        plans[0].forward(&s, &mut back)?;
        let k = ((0.3 / t.elapsed().as_secs_f64()).ceil() as usize).max(1);
        plans[1].inverse(&c, &mut s)?;
        let mut res: [Vec<(StageTimes, StageTimes)>; 2] = [Vec::new(), Vec::new()];
        for r in 0..runs {
            for i in 0..2 {
                let p = (i + r) % 2;
                res[p].push(clean_window(&plans[p], k, &c, &mut s, &mut back));
            }
        }
        let mut tot = [0.0; 2];
        let mut fft = [0.0; 2];
        for (p, plan) in plans.iter().enumerate() {
            let m = |f: &dyn Fn(&(StageTimes, StageTimes)) -> f64| {
                median(res[p].iter().map(f).collect())
            };
            let row = [
                m(&|x| x.0.total),
                m(&|x| x.0.fft),
                m(&|x| x.0.dwt),
                m(&|x| x.1.total),
                m(&|x| x.1.fft),
                m(&|x| x.1.dwt),
            ];
            tot[p] = m(&|x| x.0.total + x.1.total);
            fft[p] = m(&|x| x.0.fft + x.1.fft);
            println!(
                "{:>5} {:>3} {:>10.4e} {:>10.4e} {:>10.4e} {:>10.4e} {:>10.4e} {:>10.4e}  {:?}",
                b,
                plan.threads(),
                row[0],
                row[1],
                row[2],
                row[3],
                row[4],
                row[5],
                plan.fft_threading()
            );
        }
        // Speed-up from the medians of per-window sums (inverse + forward).
        println!(
            "B = {b}: 2 threads over 1: whole transform {:.3}x, FFT stage {:.3}x",
            tot[0] / tot[1],
            fft[0] / fft[1]
        );
    }
    Ok(())
}
