//! (b) Round trips `forward(inverse(c))` and `inverse(forward(f))`, and Parseval, over a
//! range of bandwidths: the full SO(3) plan complex and real (with skipping off and loose
//! tolerances as extra variants), order-limited partial plans, the S^2 transforms.

use crate::record::{errors, errors_real, Case, Errors, Report};
use crate::rng::SplitMix64;
use so3fft::s2::{s2_coef_index, s2_num_coeffs, s2_num_samples, S2Plan};
use so3fft::{coef_index, num_coeffs, num_samples, Complex64, Options, PartialPlan, Plan, Shape};
use std::f64::consts::PI;
use std::time::Instant;

/// Order limit of the order-limited partial plans.
pub const ORDER_LIMIT: usize = 8;

/// A way of running the full plan.
#[derive(Clone, Copy, Debug)]
pub struct FullVariant {
    /// Row label.
    pub name: &'static str,
    /// `Options::skip_bits`.
    pub skip_bits: Option<u32>,
}

/// The default plan, skipping off, and the skip thresholds of tolerances 1e-10 and 1e-6
/// (`ceil(-log2 tol)` bits, at least 24).
pub const FULL_VARIANTS: [FullVariant; 4] = [
    FullVariant {
        name: "complex",
        skip_bits: None,
    },
    FullVariant {
        name: "complex-noskip",
        skip_bits: Some(0),
    },
    FullVariant {
        name: "complex-tol1e-10",
        skip_bits: Some(34),
    },
    FullVariant {
        name: "complex-tol1e-6",
        skip_bits: Some(24),
    },
];

/// Quadrature weights `w_B(k)` of docs/conventions.md, from the formula (not the library's).
pub fn quadrature_weights(b: usize) -> Vec<f64> {
    (0..2 * b)
        .map(|k| {
            let beta = PI * (2 * k + 1) as f64 / (4 * b) as f64;
            let sum: f64 = (0..b)
                .map(|i| ((2 * i + 1) as f64 * beta).sin() / (2 * i + 1) as f64)
                .sum();
            2.0 / b as f64 * beta.sin() * sum
        })
        .collect()
}

/// `int |f|^2` by the exact quadrature: `(2 pi / n_alpha)(2 pi / n_gamma) sum_k w(k) sum |f|^2`
/// over slices of `slice_len` samples, for any per-sample `|f|^2`.
pub fn quadrature_norm2(weights: &[f64], slice_len: usize, dphi2: f64, abs2: &[f64]) -> f64 {
    let slices: Vec<f64> = abs2
        .chunks_exact(slice_len)
        .zip(weights)
        .map(|(slice, w)| w * compensated_sum(slice.iter().copied()))
        .collect();
    compensated_sum(slices.into_iter()) * dphi2
}

/// Neumaier's compensated sum: this check's own rounding stays near one ulp of the total,
/// well below the transform errors it measures.
pub fn compensated_sum(values: impl Iterator<Item = f64>) -> f64 {
    let (mut sum, mut carry) = (0.0f64, 0.0f64);
    for v in values {
        let t = sum + v;
        carry += if sum.abs() >= v.abs() {
            (sum - t) + v
        } else {
            (v - t) + sum
        };
        sum = t;
    }
    sum + carry
}

/// Parseval's relative defect `|int |f|^2 - sum |c|^2| / sum |c|^2`, as an [`Errors`] whose
/// max is NaN.
fn parseval(coeff_norm2: f64, sample_norm2: f64) -> Errors {
    Errors {
        rel_l2: (sample_norm2 - coeff_norm2).abs() / coeff_norm2,
        max_abs: f64::NAN,
    }
}

/// Sets the partner `fhat(l, -M, -M') = (-1)^(M-M') conj(fhat(l, M, M'))` of every
/// representative (`M' > 0`, or `M' = 0` and `M > 0`) and makes `fhat(l, 0, 0)` real: the
/// coefficients of a real signal. `index` gives the position of `(l, M, M')` if stored.
pub fn make_real_so3(
    coeffs: &mut [Complex64],
    b: usize,
    order_limit: usize,
    index: impl Fn(usize, isize, isize) -> Option<usize>,
) {
    let lim = order_limit as isize;
    for l in 0..b {
        let li = (l as isize).min(lim);
        for m in -li..=li {
            for mp in 0..=li {
                if mp == 0 && m < 0 {
                    continue;
                }
                let Some(i) = index(l, m, mp) else { continue };
                if m == 0 && mp == 0 {
                    coeffs[i].im = 0.0;
                    continue;
                }
                let sign = if (m - mp).rem_euclid(2) == 0 {
                    1.0
                } else {
                    -1.0
                };
                if let Some(j) = index(l, -m, -mp) {
                    coeffs[j] = coeffs[i].conj() * sign;
                }
            }
        }
    }
}

/// Sets `fhat(l, -m) = (-1)^m conj(fhat(l, m))` and makes `fhat(l, 0)` real.
pub fn make_real_s2(coeffs: &mut [Complex64], b: usize) {
    for l in 0..b {
        coeffs[s2_coef_index(b, l, 0)].im = 0.0;
        for m in 1..=l as isize {
            let sign = if m % 2 == 0 { 1.0 } else { -1.0 };
            coeffs[s2_coef_index(b, l, -m)] = coeffs[s2_coef_index(b, l, m)].conj() * sign;
        }
    }
}

fn norm2(c: &[Complex64]) -> f64 {
    compensated_sum(c.iter().map(|z| z.norm_sqr()))
}

fn abs2(f: &[Complex64]) -> Vec<f64> {
    f.iter().map(|z| z.norm_sqr()).collect()
}

fn seconds_since(start: Instant) -> f64 {
    start.elapsed().as_secs_f64()
}

/// The shortest wall time of `run` over repeated warm calls (at least one, more while
/// they add up to under 0.3 s, at most 50): the caller has run it once already, so pages
/// are touched and caches warm.
pub fn best_time(mut run: impl FnMut() -> so3fft::Result<()>) -> so3fft::Result<f64> {
    let (mut best, mut total) = (f64::INFINITY, 0.0);
    for _ in 0..50 {
        let start = Instant::now();
        run()?;
        let t = seconds_since(start);
        best = best.min(t);
        total += t;
        if total >= 0.3 {
            break;
        }
    }
    Ok(best)
}

/// Options of one round-trip run.
#[derive(Clone, Copy)]
pub struct RunOptions {
    /// Worker threads (0: all).
    pub threads: usize,
    /// Also check `inverse(forward(f))` and Parseval (needs a second sample array).
    pub sample_checks: bool,
}

/// Full plan, complex: rows `roundtrip` (and, with `sample_checks`, `parseval`, `inv-fwd`).
pub fn full_complex(
    b: usize,
    variant: FullVariant,
    run: RunOptions,
    report: &mut Report,
) -> so3fft::Result<()> {
    let opts = Options::default()
        .with_threads(run.threads)
        .with_skip_bits(variant.skip_bits);
    let plan = Plan::new(b, &opts)?;
    let coeffs = SplitMix64::new(10 + b as u64).complex_vec(num_coeffs(b));
    let mut samples = vec![Complex64::new(0.0, 0.0); num_samples(b)];
    let mut back = vec![Complex64::new(0.0, 0.0); num_coeffs(b)];
    plan.inverse(&coeffs, &mut samples)?;
    plan.forward(&samples, &mut back)?;
    let time = best_time(|| {
        plan.inverse(&coeffs, &mut samples)?;
        plan.forward(&samples, &mut back)?;
        Ok(())
    })?;
    let case = |test| Case {
        test,
        b,
        variant: variant.name,
    };
    report.push_errors(case("roundtrip"), errors(&back, &coeffs), time, "");
    if !run.sample_checks {
        return Ok(());
    }
    let sample_norm2 = quadrature_norm2(
        &quadrature_weights(b),
        4 * b * b,
        (PI / b as f64).powi(2),
        &abs2(&samples),
    );
    let p = parseval(norm2(&coeffs), sample_norm2);
    report.push_errors(
        case("parseval"),
        p,
        0.0,
        "|quad |f|^2 - sum |c|^2| / sum |c|^2",
    );
    let mut again = vec![Complex64::new(0.0, 0.0); num_samples(b)];
    let start = Instant::now();
    plan.inverse(&back, &mut again)?;
    let time = seconds_since(start);
    report.push_errors(
        case("inv-fwd"),
        errors(&again, &samples),
        time,
        "f band-limited",
    );
    Ok(())
}

/// Full plan, real signals: rows `roundtrip`, `parseval`, `inv-fwd` with variant `real`.
pub fn full_real(b: usize, run: RunOptions, report: &mut Report) -> so3fft::Result<()> {
    let opts = Options::default().with_threads(run.threads).with_real(true);
    let plan = Plan::new(b, &opts)?;
    let mut coeffs = SplitMix64::new(20 + b as u64).complex_vec(num_coeffs(b));
    make_real_so3(&mut coeffs, b, b - 1, |l, m, mp| {
        Some(coef_index(b, l, m, mp))
    });
    let mut samples = vec![0.0; num_samples(b)];
    let mut back = vec![Complex64::new(0.0, 0.0); num_coeffs(b)];
    plan.inverse_real(&coeffs, &mut samples)?;
    plan.forward_real(&samples, &mut back)?;
    let time = best_time(|| {
        plan.inverse_real(&coeffs, &mut samples)?;
        plan.forward_real(&samples, &mut back)?;
        Ok(())
    })?;
    let case = |test| Case {
        test,
        b,
        variant: "real",
    };
    report.push_errors(case("roundtrip"), errors(&back, &coeffs), time, "");
    if !run.sample_checks {
        return Ok(());
    }
    let squares: Vec<f64> = samples.iter().map(|x| x * x).collect();
    let dphi2 = (PI / b as f64).powi(2);
    let sample_norm2 = quadrature_norm2(&quadrature_weights(b), 4 * b * b, dphi2, &squares);
    let p = parseval(norm2(&coeffs), sample_norm2);
    report.push_errors(case("parseval"), p, 0.0, "");
    let mut again = vec![0.0; num_samples(b)];
    let start = Instant::now();
    plan.inverse_real(&back, &mut again)?;
    let time = seconds_since(start);
    report.push_errors(case("inv-fwd"), errors_real(&again, &samples), time, "");
    Ok(())
}

/// Order-limited partial plan (`|M|, |M'| <= 8`, grid `2B x 17 x 17`), complex or real:
/// rows `roundtrip`, `parseval`, `inv-fwd` with variant `partial-m8` / `partial-m8-real`.
pub fn partial(b: usize, real: bool, run: RunOptions, report: &mut Report) -> so3fft::Result<()> {
    let shape = Shape::new(b).with_orders(ORDER_LIMIT, ORDER_LIMIT);
    let opts = Options::default().with_threads(run.threads).with_real(real);
    let plan = PartialPlan::new(&shape, &opts)?;
    let variant = if real {
        "partial-m8-real"
    } else {
        "partial-m8"
    };
    let case = |test| Case { test, b, variant };
    let mut coeffs = SplitMix64::new(30 + b as u64).complex_vec(plan.num_coeffs());
    let mut back = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
    let weights = quadrature_weights(shape.grid_bandwidth);
    let dphi2 = (2.0 * PI).powi(2) / (shape.n_alpha * shape.n_gamma) as f64;
    let (rt, time, sample_norm2, inv_fwd) = if real {
        make_real_so3(&mut coeffs, b, ORDER_LIMIT, |l, m, mp| {
            shape.coef_index(l, m, mp)
        });
        let mut samples = vec![0.0; plan.num_samples()];
        plan.inverse_real(&coeffs, &mut samples)?;
        plan.forward_real(&samples, &mut back)?;
        let time = best_time(|| {
            plan.inverse_real(&coeffs, &mut samples)?;
            plan.forward_real(&samples, &mut back).map(|_| ())
        })?;
        let squares: Vec<f64> = samples.iter().map(|x| x * x).collect();
        let n2 = quadrature_norm2(&weights, shape.slice_len(), dphi2, &squares);
        let mut again = vec![0.0; plan.num_samples()];
        plan.inverse_real(&back, &mut again)?;
        (
            errors(&back, &coeffs),
            time,
            n2,
            errors_real(&again, &samples),
        )
    } else {
        let mut samples = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
        plan.inverse(&coeffs, &mut samples)?;
        plan.forward(&samples, &mut back)?;
        let time = best_time(|| {
            plan.inverse(&coeffs, &mut samples)?;
            plan.forward(&samples, &mut back).map(|_| ())
        })?;
        let n2 = quadrature_norm2(&weights, shape.slice_len(), dphi2, &abs2(&samples));
        let mut again = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
        plan.inverse(&back, &mut again)?;
        (errors(&back, &coeffs), time, n2, errors(&again, &samples))
    };
    report.push_errors(case("roundtrip"), rt, time, "grid 2B x 17 x 17");
    if run.sample_checks {
        let p = parseval(norm2(&coeffs), sample_norm2);
        report.push_errors(case("parseval"), p, 0.0, "");
        report.push_errors(case("inv-fwd"), inv_fwd, 0.0, "");
    }
    Ok(())
}

/// S^2 transforms, complex or real: rows `roundtrip`, `parseval`, `inv-fwd` with variant
/// `s2-complex` / `s2-real`.
pub fn sphere(b: usize, real: bool, run: RunOptions, report: &mut Report) -> so3fft::Result<()> {
    let opts = Options::default().with_threads(run.threads);
    let plan = S2Plan::new(b, &opts)?;
    let variant = if real { "s2-real" } else { "s2-complex" };
    let case = |test| Case { test, b, variant };
    let mut coeffs = SplitMix64::new(40 + b as u64).complex_vec(s2_num_coeffs(b));
    let mut back = vec![Complex64::new(0.0, 0.0); s2_num_coeffs(b)];
    let weights = quadrature_weights(b);
    let dphi = PI / b as f64;
    let ns = s2_num_samples(b);
    let (rt, time, sample_norm2, inv_fwd) = if real {
        make_real_s2(&mut coeffs, b);
        let mut samples = vec![0.0; ns];
        plan.inverse_real(&coeffs, &mut samples)?;
        plan.forward_real(&samples, &mut back)?;
        let time = best_time(|| {
            plan.inverse_real(&coeffs, &mut samples)?;
            plan.forward_real(&samples, &mut back).map(|_| ())
        })?;
        let squares: Vec<f64> = samples.iter().map(|x| x * x).collect();
        let n2 = quadrature_norm2(&weights, 2 * b, dphi, &squares);
        let mut again = vec![0.0; ns];
        plan.inverse_real(&back, &mut again)?;
        (
            errors(&back, &coeffs),
            time,
            n2,
            errors_real(&again, &samples),
        )
    } else {
        let mut samples = vec![Complex64::new(0.0, 0.0); ns];
        plan.inverse(&coeffs, &mut samples)?;
        plan.forward(&samples, &mut back)?;
        let time = best_time(|| {
            plan.inverse(&coeffs, &mut samples)?;
            plan.forward(&samples, &mut back).map(|_| ())
        })?;
        let n2 = quadrature_norm2(&weights, 2 * b, dphi, &abs2(&samples));
        let mut again = vec![Complex64::new(0.0, 0.0); ns];
        plan.inverse(&back, &mut again)?;
        (errors(&back, &coeffs), time, n2, errors(&again, &samples))
    };
    report.push_errors(case("roundtrip"), rt, time, "");
    if run.sample_checks {
        let p = parseval(norm2(&coeffs), sample_norm2);
        report.push_errors(case("parseval"), p, 0.0, "");
        report.push_errors(case("inv-fwd"), inv_fwd, 0.0, "");
    }
    Ok(())
}

/// Bandwidths `from, 2 from, ..., <= to`.
pub fn doublings(from: usize, to: usize) -> Vec<usize> {
    std::iter::successors(Some(from), |b| Some(b * 2))
        .take_while(|b| *b <= to)
        .collect()
}

/// The bandwidth ranges of a run.
#[derive(Clone, Copy)]
pub struct Ranges {
    /// Largest full-grid SO(3) bandwidth.
    pub full_max: usize,
    /// Largest order-limited partial bandwidth.
    pub partial_max: usize,
    /// Largest S^2 bandwidth.
    pub s2_max: usize,
    /// Run the extra full-plan variants (skipping off, tolerances).
    pub variants: bool,
}

/// Every round trip of (b).
pub fn run(ranges: Ranges, threads: usize, report: &mut Report) -> so3fft::Result<()> {
    let run = RunOptions {
        threads,
        sample_checks: true,
    };
    for b in doublings(8, ranges.full_max) {
        full_complex(b, FULL_VARIANTS[0], run, report)?;
        if ranges.variants {
            let quick = RunOptions {
                sample_checks: false,
                ..run
            };
            for v in &FULL_VARIANTS[1..] {
                full_complex(b, *v, quick, report)?;
            }
        }
        full_real(b, run, report)?;
    }
    for b in doublings(16, ranges.partial_max) {
        partial(b, false, run, report)?;
        partial(b, true, run, report)?;
    }
    for b in doublings(8, ranges.s2_max) {
        sphere(b, false, run, report)?;
        sphere(b, true, run, report)?;
    }
    Ok(())
}

/// The tests whose growth with the bandwidth is fitted.
pub const GROWTH_TESTS: [&str; 3] = ["roundtrip", "parseval", "inv-fwd"];
