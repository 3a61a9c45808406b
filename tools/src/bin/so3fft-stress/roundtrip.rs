//! (b) Round trips `forward(inverse(c))` and `inverse(forward(f))`, and Parseval, over a
//! range of bandwidths: the full SO(3) plan complex and real (with skipping off as an
//! extra variant), order-limited partial plans, the S^2 transforms; each in `f64` and `f32`.
//! The coefficients are random values rounded to the plan's type, which are then the truth
//! of the round trip.

use crate::precision::{narrow, random, zero, Float, Precision};
use crate::record::{errors, errors_real, Case, Errors, Report};
use crate::rng::SplitMix64;
use so3fft::s2::{s2_coef_index, s2_num_coeffs, s2_num_samples, S2Plan};
use so3fft::{
    coef_index, num_coeffs, num_samples, Complex, Complex64, Options, PartialPlan, Plan, Shape,
};
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

/// The default plan and the plan with skipping off. (Looser skip thresholds, `skip_bits`
/// 24 and 34, buy no measurable time for 3 to 6 orders of magnitude of error, see
/// docs/stability.md: the suite does not run them.)
pub const FULL_VARIANTS: [FullVariant; 2] = [
    FullVariant {
        name: "complex",
        skip_bits: None,
    },
    FullVariant {
        name: "complex-noskip",
        skip_bits: Some(0),
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

/// `|z|^2` in `f64`.
fn norm_sqr<T: Float>(z: &Complex<T>) -> f64 {
    let (re, im) = (z.re.widened(), z.im.widened());
    re * re + im * im
}

fn norm2<T: Float>(c: &[Complex<T>]) -> f64 {
    compensated_sum(c.iter().map(norm_sqr))
}

fn abs2<T: Float>(f: &[Complex<T>]) -> Vec<f64> {
    f.iter().map(norm_sqr).collect()
}

fn squares<T: Float>(f: &[T]) -> Vec<f64> {
    f.iter().map(|x| x.widened() * x.widened()).collect()
}

/// Makes coefficients those of a real signal.
type MakeReal<'a> = &'a dyn Fn(&mut [Complex64]);

/// `n` random coefficients of `SplitMix64(seed)` in `T`; `make_real` (if any) makes them
/// those of a real signal first.
fn coefficients<T: Float>(seed: u64, n: usize, make_real: Option<MakeReal<'_>>) -> Vec<Complex<T>> {
    let mut rng = SplitMix64::new(seed);
    match make_real {
        None => random(&mut rng, n),
        Some(f) => {
            let mut c = rng.complex_vec(n);
            f(&mut c);
            narrow(&c)
        }
    }
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
pub fn full_complex<T: Float>(
    b: usize,
    variant: FullVariant,
    run: RunOptions,
    report: &mut Report,
) -> so3fft::Result<()> {
    let opts = Options::default()
        .with_threads(run.threads)
        .with_skip_bits(variant.skip_bits);
    let plan = Plan::<T>::new(b, &opts)?;
    let coeffs = coefficients::<T>(10 + b as u64, num_coeffs(b), None);
    let mut samples = vec![zero::<T>(); num_samples(b)];
    let mut back = vec![zero::<T>(); num_coeffs(b)];
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
        precision: T::PRECISION,
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
    let mut again = vec![zero::<T>(); num_samples(b)];
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
pub fn full_real<T: Float>(b: usize, run: RunOptions, report: &mut Report) -> so3fft::Result<()> {
    let opts = Options::default().with_threads(run.threads).with_real(true);
    let plan = Plan::<T>::new(b, &opts)?;
    let real =
        |c: &mut [Complex64]| make_real_so3(c, b, b - 1, |l, m, mp| Some(coef_index(b, l, m, mp)));
    let coeffs = coefficients::<T>(20 + b as u64, num_coeffs(b), Some(&real));
    let mut samples = vec![T::narrowed(0.0); num_samples(b)];
    let mut back = vec![zero::<T>(); num_coeffs(b)];
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
        precision: T::PRECISION,
    };
    report.push_errors(case("roundtrip"), errors(&back, &coeffs), time, "");
    if !run.sample_checks {
        return Ok(());
    }
    let dphi2 = (PI / b as f64).powi(2);
    let sample_norm2 =
        quadrature_norm2(&quadrature_weights(b), 4 * b * b, dphi2, &squares(&samples));
    let p = parseval(norm2(&coeffs), sample_norm2);
    report.push_errors(case("parseval"), p, 0.0, "");
    let mut again = vec![T::narrowed(0.0); num_samples(b)];
    let start = Instant::now();
    plan.inverse_real(&back, &mut again)?;
    let time = seconds_since(start);
    report.push_errors(case("inv-fwd"), errors_real(&again, &samples), time, "");
    Ok(())
}

/// Order-limited partial plan (`|M|, |M'| <= 8`, grid `2B x 17 x 17`), complex or real:
/// rows `roundtrip`, `parseval`, `inv-fwd` with variant `partial-m8` / `partial-m8-real`.
pub fn partial<T: Float>(
    b: usize,
    real: bool,
    run: RunOptions,
    report: &mut Report,
) -> so3fft::Result<()> {
    let shape = Shape::new(b).with_orders(ORDER_LIMIT, ORDER_LIMIT);
    let opts = Options::default().with_threads(run.threads).with_real(real);
    let plan = PartialPlan::<T>::new(&shape, &opts)?;
    let variant = if real {
        "partial-m8-real"
    } else {
        "partial-m8"
    };
    let case = |test| Case {
        test,
        b,
        variant,
        precision: T::PRECISION,
    };
    let make_real = |c: &mut [Complex64]| {
        make_real_so3(c, b, ORDER_LIMIT, |l, m, mp| shape.coef_index(l, m, mp))
    };
    let coeffs = coefficients::<T>(
        30 + b as u64,
        plan.num_coeffs(),
        real.then_some(&make_real as MakeReal<'_>),
    );
    let mut back = vec![zero::<T>(); plan.num_coeffs()];
    let weights = quadrature_weights(shape.grid_bandwidth);
    let dphi2 = (2.0 * PI).powi(2) / (shape.n_alpha * shape.n_gamma) as f64;
    let (rt, time, sample_norm2, inv_fwd) = if real {
        let mut samples = vec![T::narrowed(0.0); plan.num_samples()];
        plan.inverse_real(&coeffs, &mut samples)?;
        plan.forward_real(&samples, &mut back)?;
        let time = best_time(|| {
            plan.inverse_real(&coeffs, &mut samples)?;
            plan.forward_real(&samples, &mut back).map(|_| ())
        })?;
        let n2 = quadrature_norm2(&weights, shape.slice_len(), dphi2, &squares(&samples));
        let mut again = vec![T::narrowed(0.0); plan.num_samples()];
        plan.inverse_real(&back, &mut again)?;
        (
            errors(&back, &coeffs),
            time,
            n2,
            errors_real(&again, &samples),
        )
    } else {
        let mut samples = vec![zero::<T>(); plan.num_samples()];
        plan.inverse(&coeffs, &mut samples)?;
        plan.forward(&samples, &mut back)?;
        let time = best_time(|| {
            plan.inverse(&coeffs, &mut samples)?;
            plan.forward(&samples, &mut back).map(|_| ())
        })?;
        let n2 = quadrature_norm2(&weights, shape.slice_len(), dphi2, &abs2(&samples));
        let mut again = vec![zero::<T>(); plan.num_samples()];
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
pub fn sphere<T: Float>(
    b: usize,
    real: bool,
    run: RunOptions,
    report: &mut Report,
) -> so3fft::Result<()> {
    let opts = Options::default().with_threads(run.threads);
    let plan = S2Plan::<T>::new(b, &opts)?;
    let variant = if real { "s2-real" } else { "s2-complex" };
    let case = |test| Case {
        test,
        b,
        variant,
        precision: T::PRECISION,
    };
    let make_real = |c: &mut [Complex64]| make_real_s2(c, b);
    let coeffs = coefficients::<T>(
        40 + b as u64,
        s2_num_coeffs(b),
        real.then_some(&make_real as MakeReal<'_>),
    );
    let mut back = vec![zero::<T>(); s2_num_coeffs(b)];
    let weights = quadrature_weights(b);
    let dphi = PI / b as f64;
    let ns = s2_num_samples(b);
    let (rt, time, sample_norm2, inv_fwd) = if real {
        let mut samples = vec![T::narrowed(0.0); ns];
        plan.inverse_real(&coeffs, &mut samples)?;
        plan.forward_real(&samples, &mut back)?;
        let time = best_time(|| {
            plan.inverse_real(&coeffs, &mut samples)?;
            plan.forward_real(&samples, &mut back).map(|_| ())
        })?;
        let n2 = quadrature_norm2(&weights, 2 * b, dphi, &squares(&samples));
        let mut again = vec![T::narrowed(0.0); ns];
        plan.inverse_real(&back, &mut again)?;
        (
            errors(&back, &coeffs),
            time,
            n2,
            errors_real(&again, &samples),
        )
    } else {
        let mut samples = vec![zero::<T>(); ns];
        plan.inverse(&coeffs, &mut samples)?;
        plan.forward(&samples, &mut back)?;
        let time = best_time(|| {
            plan.inverse(&coeffs, &mut samples)?;
            plan.forward(&samples, &mut back).map(|_| ())
        })?;
        let n2 = quadrature_norm2(&weights, 2 * b, dphi, &abs2(&samples));
        let mut again = vec![zero::<T>(); ns];
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
    /// Run the extra full-plan variant (skipping off).
    pub variants: bool,
}

/// The round trips of one bandwidth and kind in `T`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Kind {
    /// Full plan: complex, the extra variants if asked, real.
    Full,
    /// Order-limited partial plan, complex and real.
    Partial,
    /// S^2, complex and real.
    Sphere,
}

fn one<T: Float>(
    kind: Kind,
    b: usize,
    ranges: Ranges,
    run: RunOptions,
    report: &mut Report,
) -> so3fft::Result<()> {
    match kind {
        Kind::Full => {
            full_complex::<T>(b, FULL_VARIANTS[0], run, report)?;
            if ranges.variants {
                let quick = RunOptions {
                    sample_checks: false,
                    ..run
                };
                for v in &FULL_VARIANTS[1..] {
                    full_complex::<T>(b, *v, quick, report)?;
                }
            }
            full_real::<T>(b, run, report)
        }
        Kind::Partial => {
            partial::<T>(b, false, run, report)?;
            partial::<T>(b, true, run, report)
        }
        Kind::Sphere => {
            sphere::<T>(b, false, run, report)?;
            sphere::<T>(b, true, run, report)
        }
    }
}

/// Every round trip of (b) in each of `precisions`. The precisions of one bandwidth run
/// one after the other, so that their times, compared in the time chart, see the same load
/// of a shared host.
pub fn run(
    ranges: Ranges,
    threads: usize,
    precisions: &[Precision],
    report: &mut Report,
) -> so3fft::Result<()> {
    let run = RunOptions {
        threads,
        sample_checks: true,
    };
    let series = [
        (Kind::Full, doublings(8, ranges.full_max)),
        (Kind::Partial, doublings(16, ranges.partial_max)),
        (Kind::Sphere, doublings(8, ranges.s2_max)),
    ];
    for (kind, bandwidths) in series {
        for b in bandwidths {
            for &p in precisions {
                match p {
                    Precision::F64 => one::<f64>(kind, b, ranges, run, report)?,
                    Precision::F32 => one::<f32>(kind, b, ranges, run, report)?,
                }
            }
        }
    }
    Ok(())
}

/// The full-grid round trips at B = 512 (`--big`), coefficients only (no second sample
/// array): `f64` complex (about 24 GB), `f32` complex and real (about 12 and 7 GB).
pub fn big<T: Float>(threads: usize, report: &mut Report) -> so3fft::Result<()> {
    let run = RunOptions {
        threads,
        sample_checks: false,
    };
    full_complex::<T>(512, FULL_VARIANTS[0], run, report)?;
    if T::PRECISION == Precision::F32 {
        full_real::<T>(512, run, report)?;
    }
    Ok(())
}

/// The tests whose growth with the bandwidth is fitted.
pub const GROWTH_TESTS: [&str; 3] = ["roundtrip", "parseval", "inv-fwd"];
