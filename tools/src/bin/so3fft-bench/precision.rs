//! `so3fft-bench precision`: the SO(3) transforms in single against double precision. Per
//! bandwidth and thread count, both plans are made, then their calls alternate run by run
//! (complex inverse and forward, real inverse and forward): medians, the f32/f64 time
//! ratios, the round-trip errors of both, and the plans' memory.

use crate::cli::Options;
use crate::workload::{median, random_coeffs};
use so3fft::{Complex, Complex64, Plan, Real};
use std::time::Instant;

/// `v` rounded to `T`.
fn narrow<T: Real>(v: &[Complex64]) -> Vec<Complex<T>> {
    v.iter()
        .map(|z| Complex::new(T::from_f64(z.re), T::from_f64(z.im)))
        .collect()
}

/// Relative L2 error of `got` against `want`.
fn rel_l2<T: Real>(got: &[Complex<T>], want: &[Complex<T>]) -> f64 {
    let d = |a: Complex<T>, b: Complex<T>| {
        (a.re.to_f64() - b.re.to_f64()).powi(2) + (a.im.to_f64() - b.im.to_f64()).powi(2)
    };
    let zero = Complex::new(T::ZERO, T::ZERO);
    let num: f64 = got.iter().zip(want).map(|(&a, &b)| d(a, b)).sum();
    let den: f64 = want.iter().map(|&b| d(b, zero)).sum();
    (num / den).sqrt()
}

/// Coefficients of a real signal: `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`.
fn real_signal(b: usize, c: &[Complex64]) -> Vec<Complex64> {
    let mut c = c.to_vec();
    for l in 0..b {
        let top = l as isize;
        for m in -top..=top {
            for mp in -top..=top {
                if (m, mp) < (-m, -mp) {
                    let v = c[so3fft::coef_index(b, l, m, mp)];
                    let w = if (m - mp) % 2 == 0 {
                        v.conj()
                    } else {
                        -v.conj()
                    };
                    c[so3fft::coef_index(b, l, -m, -mp)] = w;
                } else if m == 0 && mp == 0 {
                    c[so3fft::coef_index(b, l, 0, 0)].im = 0.0;
                }
            }
        }
    }
    c
}

/// One precision's plan and arrays at one bandwidth.
struct Case<T: Real> {
    plan: Plan<T>,
    coefs: Vec<Complex<T>>,
    real_coefs: Vec<Complex<T>>,
    samples: Vec<Complex<T>>,
    reals: Vec<T>,
    back: Vec<Complex<T>>,
    /// Seconds of each run: complex inverse, forward, real inverse, forward.
    times: [Vec<f64>; 4],
    /// Seconds of their DWT and FFT stages.
    stages: [Vec<(f64, f64)>; 4],
    errors: [f64; 2],
}

impl<T: Real> Case<T> {
    fn new(b: usize, options: &so3fft::Options, coefs: &[Complex64]) -> so3fft::Result<Case<T>> {
        let plan = Plan::<T>::new(b, options)?;
        let zero = Complex::new(T::ZERO, T::ZERO);
        Ok(Case {
            samples: vec![zero; plan.num_samples()],
            reals: vec![T::ZERO; plan.num_samples()],
            back: vec![zero; plan.num_coeffs()],
            coefs: narrow(coefs),
            real_coefs: narrow(&real_signal(b, coefs)),
            plan,
            times: Default::default(),
            stages: Default::default(),
            errors: [0.0; 2],
        })
    }

    /// One run of the four calls, timed; the round-trip errors of the last one.
    fn run(&mut self) -> so3fft::Result<()> {
        let mut time = |k: usize, f: &mut dyn FnMut() -> so3fft::Result<so3fft::StageTimes>| {
            let start = Instant::now();
            let st = f()?;
            self.times[k].push(start.elapsed().as_secs_f64());
            self.stages[k].push((st.dwt, st.fft));
            Ok::<(), so3fft::Error>(())
        };
        let (p, c, rc) = (&self.plan, &self.coefs, &self.real_coefs);
        let (s, r, back) = (&mut self.samples, &mut self.reals, &mut self.back);
        time(0, &mut || p.inverse(c, s))?;
        time(1, &mut || p.forward(s, back))?;
        self.errors[0] = rel_l2(back, c);
        time(2, &mut || p.inverse_real(rc, r))?;
        time(3, &mut || p.forward_real(r, back))?;
        self.errors[1] = rel_l2(back, rc);
        Ok(())
    }

    fn medians(&self) -> [f64; 4] {
        std::array::from_fn(|k| median(&self.times[k]))
    }

    /// Medians of the DWT and the FFT stage of each call.
    fn stage_medians(&self) -> [(f64, f64); 4] {
        std::array::from_fn(|k| {
            let dwt: Vec<f64> = self.stages[k].iter().map(|s| s.0).collect();
            let fft: Vec<f64> = self.stages[k].iter().map(|s| s.1).collect();
            (median(&dwt), median(&fft))
        })
    }

    fn clear(&mut self) {
        self.times.iter_mut().for_each(Vec::clear);
        self.stages.iter_mut().for_each(Vec::clear);
    }
}

/// Runs the comparison for every bandwidth and thread count of `opts`.
pub fn run(opts: &Options) -> so3fft::Result<()> {
    println!("SO(3) transforms in f64 and f32: medians in ms, calls alternating run by run");
    println!("(f32/: time ratios; dwt, fft: the f64 stage in ms / the f32 stage's ratio)");
    println!(
        "{:>5} {:>3} {:>4} {:>9} {:>9} {:>9} {:>9} {:>10} {:>10} {:>9}",
        "B", "thr", "prec", "cx inv", "cx fwd", "re inv", "re fwd", "err cx", "err re", "MiB plan"
    );
    for &b in &opts.bandwidths {
        for &threads in &opts.threads {
            let options = so3fft::Options::default()
                .with_threads(threads)
                .with_rigor(opts.rigor)
                .with_real(true);
            let coefs = random_coeffs(so3fft::num_coeffs(b), 0x5EED + b as u64);
            let mut wide = Case::<f64>::new(b, &options, &coefs)?;
            let mut narrow = Case::<f32>::new(b, &options, &coefs)?;
            drop(coefs);
            let runs = opts.runs.unwrap_or(if b >= 256 { 5 } else { 9 });
            // One untimed run each (first touches), then alternating.
            wide.run()?;
            narrow.run()?;
            wide.clear();
            narrow.clear();
            for _ in 0..runs {
                wide.run()?;
                narrow.run()?;
            }
            let (m64, m32) = (wide.medians(), narrow.medians());
            let mib = |bytes: usize| bytes as f64 / (1 << 20) as f64;
            for (name, m, errors, memory) in [
                ("f64", m64, wide.errors, wide.plan.memory_bytes()),
                ("f32", m32, narrow.errors, narrow.plan.memory_bytes()),
            ] {
                println!(
                    "{b:>5} {threads:>3} {name:>4} {:>9.3} {:>9.3} {:>9.3} {:>9.3} {:>10.2e} {:>10.2e} {:>9.1}",
                    m[0] * 1e3,
                    m[1] * 1e3,
                    m[2] * 1e3,
                    m[3] * 1e3,
                    errors[0],
                    errors[1],
                    mib(memory),
                );
            }
            let ratio: Vec<String> = (0..4)
                .map(|k| format!("{:>9.2}", m32[k] / m64[k]))
                .collect();
            println!(
                "{b:>5} {threads:>3} {:>4} {} {:>10} {:>10} {:>9.2}",
                "f32/",
                ratio.join(" "),
                "",
                "",
                narrow.plan.memory_bytes() as f64 / wide.plan.memory_bytes() as f64
            );
            let (s64, s32) = (wide.stage_medians(), narrow.stage_medians());
            for (name, pick) in [("dwt", 0), ("fft", 1)] {
                let stage = |s: &[(f64, f64); 4], k: usize| if pick == 0 { s[k].0 } else { s[k].1 };
                let cells: Vec<String> = (0..4)
                    .map(|k| {
                        let (a, b) = (stage(&s64, k), stage(&s32, k));
                        format!("{:>9}", format!("{:.1}/{:.2}", a * 1e3, b / a))
                    })
                    .collect();
                println!("{b:>5} {threads:>3} {name:>4} {}", cells.join(" "));
            }
        }
    }
    Ok(())
}
