//! Measuring tools for the FFT stage (they assert nothing; `harness = false`).
//!
//! ```text
//! cargo bench --features internals --bench fft_stage -- copies   # block copies (G=pairs)
//! cargo bench --features internals --bench fft_stage -- timing   # stage per threading
//! cargo bench --features internals --bench fft_stage -- loop     # repeated stages
//! ```
//!
//! Environment: `SO3FFT_B` (bandwidths, comma-separated; `loop` takes the first),
//! `SO3FFT_ROUNDS` (timing), `SO3FFT_THREADS` and `SO3FFT_FWD=1` (loop), `G` (copies).
//! With no argument all three run.

use so3fft::internals::{fft_stage_alone, BlockCopies};
use so3fft::{Complex64, FftThreading, Options, Plan, Rigor};
use std::time::Instant;

fn env<T: std::str::FromStr>(name: &str) -> Option<T> {
    std::env::var(name).ok().and_then(|s| s.parse().ok())
}

fn bandwidths(default: &str) -> Vec<usize> {
    std::env::var("SO3FFT_B")
        .unwrap_or(default.into())
        .split(',')
        .map(|x| x.trim().parse().expect("SO3FFT_B: bandwidths"))
        .collect()
}

/// Time of the block copies of one group of pairs over all clusters: scatter and gather,
/// against a plain copy of as many bytes.
fn copies() {
    for b in bandwidths("64,128,256") {
        let n = 2 * b;
        let nn = n * n;
        let g = env("G").unwrap_or(BlockCopies::default_pairs(b));
        let copies = BlockCopies::new(b, g).expect("buffers");
        let reps = 20;
        let time = |f: &dyn Fn()| {
            (0..5)
                .map(|_| {
                    let t0 = Instant::now();
                    for _ in 0..reps {
                        f();
                    }
                    t0.elapsed().as_secs_f64() / reps as f64
                })
                .fold(f64::INFINITY, f64::min)
        };
        let ts = time(&|| copies.scatter());
        let tg = time(&|| copies.gather());
        let bytes = 2 * g * nn * 16;
        let src = vec![0u8; bytes];
        let mut dst = vec![1u8; bytes];
        let dst_ptr = dst.as_mut_ptr();
        let tc = time(&|| {
            // SAFETY: `src` and `dst` are distinct vectors of `bytes` bytes each.
            unsafe { std::ptr::copy_nonoverlapping(src.as_ptr(), dst_ptr, bytes) }
        });
        std::hint::black_box(&dst);
        println!(
            "B={b} g={g}: scatter {:.2} ms, gather {:.2} ms per pair, memcpy of the same bytes {:.2} ms ({:.1} GB/s)",
            ts * 1e3 / g as f64,
            tg * 1e3 / g as f64,
            tc * 1e3 / g as f64,
            bytes as f64 / tc / 1e9
        );
    }
}

/// Wait (up to a minute) until both cores have been idle for 300 ms, so that timings are
/// not taken while another process runs.
fn wait_idle() {
    fn idle_total() -> (u64, u64) {
        let s = std::fs::read_to_string("/proc/stat").unwrap_or_default();
        let v: Vec<u64> = s
            .lines()
            .next()
            .unwrap_or("")
            .split_whitespace()
            .skip(1)
            .filter_map(|x| x.parse().ok())
            .collect();
        if v.len() < 5 {
            return (0, 0);
        }
        (v[3] + v[4], v.iter().sum())
    }
    let t0 = Instant::now();
    while t0.elapsed().as_secs() < 60 {
        let (i0, a0) = idle_total();
        std::thread::sleep(std::time::Duration::from_millis(300));
        let (i1, a1) = idle_total();
        if a1 == a0 || (i1 - i0) as f64 >= 0.95 * (a1 - a0) as f64 {
            return;
        }
    }
}

/// Whole FFT stage (every chunk) of one direction on `grid`, in seconds.
fn fft_stage(plan: &Plan, forward: bool, grid: &mut [Complex64]) -> f64 {
    let t = Instant::now();
    fft_stage_alone(plan, forward, grid).expect("FFT stage");
    t.elapsed().as_secs_f64()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// FFT stage alone: one thread, two threads with each variant, two threads with Auto.
fn timing() {
    let rounds: usize = env("SO3FFT_ROUNDS").unwrap_or(5);
    for b in bandwidths("64,128,256") {
        let mk = |threads, fft_threading| {
            let t = Instant::now();
            let p = Plan::new(
                b,
                &Options::default()
                    .with_threads(threads)
                    .with_rigor(Rigor::Measure)
                    .with_fft_threading(fft_threading),
            )
            .unwrap();
            (p, t.elapsed().as_secs_f64())
        };
        let plans = [
            ("1 thread", mk(1, FftThreading::Auto)),
            ("2 workers", mk(2, FftThreading::SlicesAcrossWorkers)),
            ("2 fftw", mk(2, FftThreading::FftwThreads)),
            ("2 auto", mk(2, FftThreading::Auto)),
        ];
        let n = 2 * b;
        let mut grid: Vec<Complex64> = (0..n * n * n)
            .map(|i| Complex64::new((i % 7) as f64 - 3.0, (i % 5) as f64))
            .collect();
        let mut times = vec![[Vec::new(), Vec::new()]; plans.len()];
        for _ in 0..rounds {
            for (i, (_, (p, _))) in plans.iter().enumerate() {
                wait_idle();
                times[i][0].push(fft_stage(p, true, &mut grid));
                times[i][1].push(fft_stage(p, false, &mut grid));
            }
        }
        let one = median(times[0][0].clone()) + median(times[0][1].clone());
        for ((name, (p, tp)), t) in plans.iter().zip(&times) {
            let (f, i) = (median(t[0].clone()), median(t[1].clone()));
            println!(
                "B={b:4} {name:10} ({:?}, plan {tp:.3} s): fwd {f:.4e} inv {i:.4e} (min {:.4e} {:.4e}) speed-up over 1 thread {:.2}x",
                p.fft_threading(),
                t[0].iter().cloned().fold(f64::INFINITY, f64::min),
                t[1].iter().cloned().fold(f64::INFINITY, f64::min),
                one / (f + i)
            );
        }
    }
}

/// Repeated inverse (or forward, `SO3FFT_FWD=1`) FFT stages for 5 s, for profiling.
fn stage_loop() {
    let b = bandwidths("128")[0];
    let threads: usize = env("SO3FFT_THREADS").unwrap_or(2);
    let fwd = std::env::var("SO3FFT_FWD").is_ok();
    let plan = Plan::new(
        b,
        &Options::default()
            .with_threads(threads)
            .with_rigor(Rigor::Measure)
            .with_fft_threading(FftThreading::SlicesAcrossWorkers),
    )
    .unwrap();
    let n = 2 * b;
    let mut grid = vec![Complex64::new(1.0, 0.5); n * n * n];
    let t = Instant::now();
    let mut k = 0;
    while t.elapsed().as_secs_f64() < 5.0 {
        fft_stage(&plan, fwd, &mut grid);
        k += 1;
    }
    println!(
        "{k} stages, {:.4} s each",
        t.elapsed().as_secs_f64() / k as f64
    );
}

fn main() {
    // `cargo bench` passes `--bench`; the first other argument picks the tool.
    let which: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let all = which.is_empty();
    let wants = |name: &str| all || which.iter().any(|w| w == name);
    if wants("copies") {
        copies();
    }
    if wants("timing") {
        timing();
    }
    if wants("loop") {
        stage_loop();
    }
}
