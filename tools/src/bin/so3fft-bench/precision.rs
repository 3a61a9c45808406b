//! `so3fft-bench precision`: the SO(3) transforms in single against double precision. Per
//! bandwidth and thread count, both plans are made, then their calls alternate run by run
//! (complex inverse and forward, real inverse and forward): medians, the f32/f64 time
//! ratios, the round-trip errors of both, and the plans' memory; then rotational matching
//! in both precisions (bandwidths up to 128).

use crate::cli::Options;
use crate::workload::{median, random_coeffs};
use so3fft::matching::{rotate_s2_coeffs, Correlation, CorrelationOptions, Peak, Rotation};
use so3fft::s2::S2Plan;
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
            real_coefs: {
                let mut real = vec![Complex64::default(); coefs.len()];
                crate::seeded::fill_real(0x5EED, b, &mut real);
                narrow(&real)
            },
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
    run_matching(opts)
}

/// One precision's correlation plans (complex and real) and inputs at one bandwidth.
struct Matching<T: Real> {
    complex: Correlation<T>,
    real: Correlation<T>,
    sig: Vec<Complex<T>>,
    pat: Vec<Complex<T>>,
    rsig: Vec<T>,
    rpat: Vec<T>,
    grid: Vec<Complex<T>>,
    rgrid: Vec<T>,
    /// Seconds of each pipeline run: complex, real.
    times: [Vec<f64>; 2],
    peaks: [Option<Peak>; 2],
}

impl<T: Real> Matching<T> {
    /// The plans for bandwidth `l`, the signal the pattern rotated by `truth`.
    fn new(
        l: usize,
        options: &so3fft::Options,
        (sig, pat): (&[Complex64], &[Complex64]),
    ) -> so3fft::Result<Matching<T>> {
        let plan = |real: bool| {
            Correlation::<T>::new(
                l,
                &CorrelationOptions::default()
                    .with_real(real)
                    .with_plans(options.clone()),
            )
        };
        let (complex, real) = (plan(false)?, plan(true)?);
        let re = |v: &[Complex64]| v.iter().map(|z| T::from_f64(z.re)).collect::<Vec<T>>();
        Ok(Matching {
            grid: vec![Complex::new(T::ZERO, T::ZERO); complex.num_grid()],
            rgrid: vec![T::ZERO; real.num_grid()],
            sig: narrow(sig),
            pat: narrow(pat),
            rsig: re(sig),
            rpat: re(pat),
            complex,
            real,
            times: Default::default(),
            peaks: [None, None],
        })
    }

    /// One run of both pipelines (correlation and its argmax), timed.
    fn run(&mut self) -> so3fft::Result<()> {
        let t = Instant::now();
        let p = self
            .complex
            .correlate_argmax(&self.sig, &self.pat, &mut self.grid)?;
        self.times[0].push(t.elapsed().as_secs_f64());
        let t = Instant::now();
        let q = self
            .real
            .correlate_real_argmax(&self.rsig, &self.rpat, &mut self.rgrid)?;
        self.times[1].push(t.elapsed().as_secs_f64());
        self.peaks = [Some(p), Some(q)];
        Ok(())
    }

    /// The refined rotation from the complex pipeline's peak (coefficients in f64).
    fn refined(&self) -> so3fft::Result<Rotation> {
        let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(self.complex.b_out())];
        self.complex
            .coefficients(&self.sig, &self.pat, &mut coeffs)?;
        let start = self.peaks[0].expect("run first").rotation();
        Ok(self.complex.refine(&coeffs, &start)?.0)
    }
}

/// Matching pipelines in f64 and f32 (a pattern rotated off the grid, complex and real
/// inputs), alternating run by run: medians, ratios, the grid peaks and the refined
/// rotations of both.
pub fn run_matching(opts: &Options) -> so3fft::Result<()> {
    println!();
    println!("rotational matching in f64 and f32: pipeline medians in ms (two S^2 forwards,");
    println!("combine, inverse, argmax), calls alternating; the refined angle from each peak");
    println!(
        "{:>5} {:>3} {:>4} {:>9} {:>9} {:>12} {:>12} {:>13}",
        "L", "thr", "prec", "complex", "real", "peak cx", "peak re", "refined diff"
    );
    for &l in opts.bandwidths.iter().filter(|&&l| l <= 128) {
        for &threads in &opts.threads {
            let options = so3fft::Options::default()
                .with_threads(threads)
                .with_rigor(opts.rigor);
            let truth = Rotation::new(2.1234567, 1.2345678, 0.3456789);
            let s2 = S2Plan::<f64>::new(l, &options)?;
            let hat = crate::s2::hermitian(l, 3);
            let (mut sig, mut pat) = (
                vec![Complex64::default(); s2.num_samples()],
                vec![Complex64::default(); s2.num_samples()],
            );
            s2.inverse(&rotate_s2_coeffs(l, &hat, &truth)?, &mut sig)?;
            s2.inverse(&hat, &mut pat)?;
            let mut wide = Matching::<f64>::new(l, &options, (&sig, &pat))?;
            let mut narrow = Matching::<f32>::new(l, &options, (&sig, &pat))?;
            wide.run()?;
            narrow.run()?;
            wide.times = Default::default();
            narrow.times = Default::default();
            for _ in 0..opts.runs.unwrap_or(9) {
                wide.run()?;
                narrow.run()?;
            }
            let diff = narrow.refined()?.angle_to(&wide.refined()?);
            let med = |m: &[Vec<f64>; 2]| [median(&m[0]), median(&m[1])];
            let (m64, m32) = (med(&wide.times), med(&narrow.times));
            let index = |p: Option<Peak>| p.map_or(0, |p| p.index);
            for (name, m, peaks) in [("f64", m64, wide.peaks), ("f32", m32, narrow.peaks)] {
                println!(
                    "{l:>5} {threads:>3} {name:>4} {:>9.3} {:>9.3} {:>12} {:>12} {:>13}",
                    m[0] * 1e3,
                    m[1] * 1e3,
                    index(peaks[0]),
                    index(peaks[1]),
                    if name == "f32" {
                        format!("{diff:.1e}")
                    } else {
                        String::new()
                    },
                );
            }
            println!(
                "{l:>5} {threads:>3} {:>4} {:>9.2} {:>9.2}",
                "f32/",
                m32[0] / m64[0],
                m32[1] / m64[1]
            );
        }
    }
    Ok(())
}
