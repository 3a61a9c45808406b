//! `so3fft-bench s2` (or `--s2`): the spherical-harmonic transforms. Per bandwidth and
//! thread count: real and complex synthesis (inverse) and analysis (forward), medians of
//! the runs, GFLOP/s of the Legendre sums against the FMA peak, and round-trip errors.

use crate::cli::Options;
use crate::workload::{median, random_coeffs};
use so3fft::s2::{s2_coef_index, S2Plan};
use so3fft::{Complex, Complex64};
use std::time::Instant;

/// Flops of one Legendre stage (either direction): per order `m` and degree `l >= m`, the
/// `B` northern rings times 8 columns of multiply-adds (2 flops), as the kernels run them.
fn legendre_flops(b: usize) -> f64 {
    let terms: usize = (0..b).map(|m| b - m).sum();
    (terms * b * 16) as f64
}

/// Coefficients of a real function (Hermitian in `m`, real at `m = 0`).
pub fn hermitian(b: usize, seed: u64) -> Vec<Complex64> {
    let mut c = random_coeffs(b * b, seed);
    for l in 0..b {
        c[s2_coef_index(b, l, 0)].im = 0.0;
        for m in 1..=l as isize {
            let v = c[s2_coef_index(b, l, m)];
            c[s2_coef_index(b, l, -m)] = if m % 2 == 0 { v.conj() } else { -v.conj() };
        }
    }
    c
}

/// Relative L2 error of `got` against `want`.
fn rel_l2(got: &[Complex64], want: &[Complex64]) -> f64 {
    let num: f64 = got.iter().zip(want).map(|(a, b)| (a - b).norm_sqr()).sum();
    let den: f64 = want.iter().map(|b| b.norm_sqr()).sum();
    (num / den).sqrt()
}

/// Median seconds of `runs` calls of `f`.
fn timed<T>(runs: usize, mut f: impl FnMut() -> so3fft::Result<T>) -> so3fft::Result<f64> {
    let mut t = Vec::with_capacity(runs);
    for _ in 0..runs {
        let start = Instant::now();
        f()?;
        t.push(start.elapsed().as_secs_f64());
    }
    Ok(median(&t))
}

/// One precision's medians at one bandwidth and thread count, in seconds: real synthesis,
/// analysis, the same per field of a pair, complex synthesis and analysis; and the real and
/// complex round-trip errors.
struct Row {
    times: [f64; 6],
    err_real: f64,
    err_cx: f64,
    threads: usize,
}

/// `v` in `T`.
fn narrow<T: so3fft::Real>(v: &[Complex64]) -> Vec<Complex<T>> {
    v.iter()
        .map(|z| Complex::new(T::from_f64(z.re), T::from_f64(z.im)))
        .collect()
}

/// `v` in doubles.
fn widen<T: so3fft::Real>(v: &[Complex<T>]) -> Vec<Complex64> {
    v.iter()
        .map(|z| Complex64::new(z.re.to_f64(), z.im.to_f64()))
        .collect()
}

/// The measurements of an S^2 plan in `T` (see [`Row`]).
fn measure<T: so3fft::Real>(b: usize, threads: usize, opts: &Options) -> so3fft::Result<Row> {
    let plan = S2Plan::<T>::new(
        b,
        &so3fft::Options::default()
            .with_threads(threads)
            .with_rigor(opts.rigor),
    )?;
    let runs = opts.runs.unwrap_or(if b >= 1024 { 3 } else { 7 });
    let (ns, nc) = (plan.num_samples(), plan.num_coeffs());
    let zero = Complex::new(T::ZERO, T::ZERO);
    let real_coefs = hermitian(b, 7);
    let coefs = random_coeffs(nc, 11);
    let (real_in, coefs_in) = (narrow::<T>(&real_coefs), narrow::<T>(&coefs));
    let mut real = vec![T::ZERO; ns];
    let mut samples = vec![zero; ns];
    let mut back = vec![zero; nc];
    let re_syn = timed(runs, || plan.inverse_real(&real_in, &mut real))?;
    let re_ana = timed(runs, || plan.forward_real(&real, &mut back))?;
    let err_real = rel_l2(&widen(&back), &widen(&real_in));
    let pair_coefs = narrow::<T>(&[real_coefs.clone(), hermitian(b, 8)].concat());
    let mut pair_real = vec![T::ZERO; 2 * ns];
    let mut pair_back = vec![zero; 2 * nc];
    let re_syn2 = timed(runs, || {
        plan.inverse_real_many(&pair_coefs, &mut pair_real, 2)
    })? / 2.0;
    let re_ana2 = timed(runs, || {
        plan.forward_real_many(&pair_real, &mut pair_back, 2)
    })? / 2.0;
    let cx_syn = timed(runs, || plan.inverse(&coefs_in, &mut samples))?;
    let cx_ana = timed(runs, || plan.forward(&samples, &mut back))?;
    let err_cx = rel_l2(&widen(&back), &widen(&coefs_in));
    Ok(Row {
        times: [re_syn, re_ana, re_syn2, re_ana2, cx_syn, cx_ana],
        err_real,
        err_cx,
        threads: plan.threads(),
    })
}

/// Runs the S^2 measurement for every bandwidth and thread count of `opts`, in double and
/// in single precision (measured one after the other), with the time ratios.
pub fn run(opts: &Options) -> so3fft::Result<()> {
    let peak1 = crate::peak::measure(1).one_core;
    println!("S^2 transforms: medians of the runs in ms; GFLOP/s of the Legendre sums");
    println!("FMA peak of one core: {peak1:.1} GFLOP/s");
    println!(
        "{:>5} {:>3} {:>4} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>8} {:>6} {:>10} {:>10}",
        "B",
        "thr",
        "prec",
        "re syn",
        "re ana",
        "re syn/2",
        "re ana/2",
        "cx syn",
        "cx ana",
        "GFLOP/s",
        "%peak",
        "err real",
        "err cx"
    );
    println!("(re .../2: two real fields per call, time per field; f32/f64: time ratios)");
    for &b in &opts.bandwidths {
        for &threads in &opts.threads {
            let rows = [
                ("f64", measure::<f64>(b, threads, opts)?),
                ("f32", measure::<f32>(b, threads, opts)?),
            ];
            for (name, r) in &rows {
                let [re_syn, re_ana, re_syn2, re_ana2, cx_syn, cx_ana] = r.times;
                let gflops = legendre_flops(b) / cx_ana.min(cx_syn) / 1e9;
                let cores = r.threads.min(2) as f64;
                println!(
                    "{b:>5} {:>3} {name:>4} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {gflops:>8.1} {:>5.0}% {:>10.2e} {:>10.2e}",
                    r.threads,
                    re_syn * 1e3,
                    re_ana * 1e3,
                    re_syn2 * 1e3,
                    re_ana2 * 1e3,
                    cx_syn * 1e3,
                    cx_ana * 1e3,
                    100.0 * gflops / (peak1 * cores),
                    r.err_real,
                    r.err_cx,
                );
            }
            let ratio: Vec<String> = (0..6)
                .map(|k| format!("{:>9.2}", rows[1].1.times[k] / rows[0].1.times[k]))
                .collect();
            println!(
                "{b:>5} {:>3} {:>4} {}",
                rows[0].1.threads,
                "f32/",
                ratio.join(" ")
            );
        }
    }
    Ok(())
}
