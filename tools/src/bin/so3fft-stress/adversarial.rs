//! (c) Adversarial inputs: a single coefficient at the highest degree and orders (against
//! the closed form of `d^l_{l,+-l}`), coefficients that decay or grow in the degree, exact
//! scaling by `2^k`, subnormal inputs, NaN and infinite inputs; each in `f64` and `f32`
//! (the same inputs rounded to `f32`; the exponents of the scaling and subnormal tests
//! follow the type's range, see [`crate::precision::Precision`]).

use crate::precision::{narrow, narrow_one, pow2, random, widen, zero, Float};
use crate::record::{bit_differences, errors, Case, Report, Row};
use crate::rng::SplitMix64;
use crate::roundtrip::{compensated_sum, ORDER_LIMIT};
use so3fft::s2::{s2_coef_index, s2_num_coeffs, s2_num_samples, S2Plan};
use so3fft::{
    coef_index, num_coeffs, num_samples, sample_index, Complex, Complex64, Options, PartialPlan,
    Plan, Shape,
};
use std::f64::consts::PI;
use std::sync::{mpsc, Arc};
use std::time::{Duration, Instant};

const ZERO: Complex64 = Complex64::new(0.0, 0.0);

fn plan<T: Float>(b: usize, threads: usize, real: bool) -> so3fft::Result<Plan<T>> {
    Plan::new(b, &Options::default().with_threads(threads).with_real(real))
}

/// `exp(-i pi t / B)` for `t = 0 .. 2B-1`: [`Phases::at`] reduces `t` mod `2B` first
/// (accurate for large `M j`) and looks the value up.
struct Phases {
    table: Vec<Complex64>,
}

impl Phases {
    fn new(b: usize) -> Phases {
        let table = (0..2 * b)
            .map(|t| {
                let angle = -PI * t as f64 / b as f64;
                Complex64::new(angle.cos(), angle.sin())
            })
            .collect();
        Phases { table }
    }

    fn at(&self, t: isize) -> Complex64 {
        self.table[t.rem_euclid(self.table.len() as isize) as usize]
    }
}

/// `cos^(2l)(x)` for `x = pi t / q` in `[0, pi/2]`, as `exp(l ln1p(-sin^2 x))`: accurate to
/// a few ulps wherever the value is not negligible (a plain power would carry `2l` times
/// the rounding of `cos x`).
fn cos_power(l: usize, t: f64, q: f64) -> f64 {
    let s = (PI * t / q).sin();
    (l as f64 * (-s * s).ln_1p()).exp()
}

/// The inverse of the single coefficient `fhat(l, m, mp) = c` with `l = |m| = |mp|`, from
/// `d^l_{l,l} = cos^{2l}(beta/2)` and `d^l_{l,-l} = d^l_{-l,l} = sin^{2l}(beta/2)`.
fn top_order_samples(b: usize, m: isize, mp: isize, c: Complex64) -> Vec<Complex64> {
    let l = m.unsigned_abs();
    let n = 2 * b;
    let phases = Phases::new(b);
    let mut out = vec![ZERO; num_samples(b)];
    for k in 0..n {
        // beta / 2 = pi (2k+1) / (8B); sin(beta/2) = cos(pi (4B-2k-1) / (8B)).
        let q = (8 * b) as f64;
        let d = if m == mp {
            cos_power(l, (2 * k + 1) as f64, q)
        } else {
            cos_power(l, (4 * b - 2 * k - 1) as f64, q)
        };
        let dt = ((2 * l + 1) as f64 / 2.0).sqrt() * d / (2.0 * PI);
        for j1 in 0..n {
            for j2 in 0..n {
                let e = phases.at(m * j1 as isize + mp * j2 as isize);
                out[sample_index(b, j1, k, j2)] = c * dt * e;
            }
        }
    }
    out
}

/// The S^2 synthesis of `fhat(l, m) = c`, `l = |m|`: `Y_l^l = (-1)^l sqrt((2l+1)/2)
/// sqrt(prod_{i<=l} (2i-1)/(2i)) sin^l(theta) e^{i l phi} / sqrt(2 pi)` and
/// `Y_l^{-l} = (-1)^l conj(Y_l^l)`.
fn s2_top_order_samples(b: usize, m: isize, c: Complex64) -> Vec<Complex64> {
    let l = m.unsigned_abs();
    let n = 2 * b;
    // Compensated: a plain sum of 2047 terms would carry about 5e-15 of rounding.
    let log_ratio = compensated_sum((1..=l).map(|i| (-1.0 / (2 * i) as f64).ln_1p()));
    let sign = if l.is_multiple_of(2) { 1.0 } else { -1.0 };
    let norm = sign * ((2 * l + 1) as f64 / 2.0).sqrt() / (2.0 * PI).sqrt();
    let phases = Phases::new(b);
    let mut out = vec![ZERO; s2_num_samples(b)];
    for j in 0..n {
        // sin^l(theta) = cos^l(pi/2 - theta), pi/2 - theta_j = pi (2B-2j-1) / (4B); the
        // power is taken as exp(l/2 ln1p(-sin^2)) with the half in the log of the ratio.
        let x = PI * (2 * b as isize - 2 * j as isize - 1).unsigned_abs() as f64 / (4 * b) as f64;
        let s = x.sin();
        let p = (0.5 * log_ratio + 0.5 * l as f64 * (-s * s).ln_1p()).exp();
        for k in 0..n {
            // e^{i m phi_k}, phi_k = pi k / B: the table holds e^{-i pi t / B}.
            let y = norm * p * phases.at(-m * k as isize);
            let y = if m < 0 { y * sign } else { y };
            out[j * n + k] = c * y;
        }
    }
    out
}

/// S^2 single coefficients at `l = |m| = B-1`: the synthesis against the closed form
/// (`s2-top-order-inverse`) and the round trip (`s2-top-order-roundtrip`).
pub fn s2_top_order<T: Float>(b: usize, threads: usize, report: &mut Report) -> so3fft::Result<()> {
    let plan = S2Plan::<T>::new(b, &Options::default().with_threads(threads))?;
    // Exact in both precisions.
    let c = Complex64::new(0.75, -0.5);
    let top = b as isize - 1;
    for (m, variant) in [(top, "m=B-1"), (-top, "m=-(B-1)")] {
        let mut coeffs = vec![zero::<T>(); s2_num_coeffs(b)];
        coeffs[s2_coef_index(b, b - 1, m)] = narrow_one(c);
        let mut samples = vec![zero::<T>(); s2_num_samples(b)];
        let start = Instant::now();
        plan.inverse(&coeffs, &mut samples)?;
        let t_inv = start.elapsed().as_secs_f64();
        let want = s2_top_order_samples(b, m, c);
        let case = |test| Case {
            test,
            b,
            variant,
            precision: T::PRECISION,
        };
        let note = "vs closed form sin^l(theta)";
        report.push_errors(
            case("s2-top-order-inverse"),
            errors(&samples, &want),
            t_inv,
            note,
        );
        let mut back = vec![zero::<T>(); s2_num_coeffs(b)];
        let start = Instant::now();
        plan.forward(&samples, &mut back)?;
        let t_fwd = start.elapsed().as_secs_f64();
        report.push_errors(
            case("s2-top-order-roundtrip"),
            errors(&back, &coeffs),
            t_fwd,
            "",
        );
    }
    Ok(())
}

/// Single coefficients at `l = B-1`, `|M| = |M'| = B-1`: the inverse against the closed
/// form (`top-order-inverse`) and the round trip (`top-order-roundtrip`).
pub fn top_order<T: Float>(b: usize, threads: usize, report: &mut Report) -> so3fft::Result<()> {
    let plan = plan::<T>(b, threads, false)?;
    let top = b as isize - 1;
    let c = Complex64::new(0.75, -0.5);
    for (m, mp, variant) in [
        (top, -top, "M=B-1,M'=-(B-1)"),
        (-top, top, "M=-(B-1),M'=B-1"),
        (top, top, "M=M'=B-1"),
    ] {
        let mut coeffs = vec![zero::<T>(); num_coeffs(b)];
        coeffs[coef_index(b, b - 1, m, mp)] = narrow_one(c);
        let mut samples = vec![zero::<T>(); num_samples(b)];
        let start = Instant::now();
        plan.inverse(&coeffs, &mut samples)?;
        let t_inv = start.elapsed().as_secs_f64();
        let want = top_order_samples(b, m, mp, c);
        let case = |test| Case {
            test,
            b,
            variant,
            precision: T::PRECISION,
        };
        let note = "vs closed form cos/sin^(2l)(beta/2)";
        report.push_errors(
            case("top-order-inverse"),
            errors(&samples, &want),
            t_inv,
            note,
        );
        let mut back = vec![zero::<T>(); num_coeffs(b)];
        let start = Instant::now();
        plan.forward(&samples, &mut back)?;
        let t_fwd = start.elapsed().as_secs_f64();
        report.push_errors(
            case("top-order-roundtrip"),
            errors(&back, &coeffs),
            t_fwd,
            "",
        );
    }
    Ok(())
}

/// Coefficients `(l+1)^-p` times random values (p > 0 decays, p < 0 grows): the round
/// trip, with the worst per-degree relative error in the note.
pub fn power_law<T: Float>(
    b: usize,
    p: f64,
    threads: usize,
    report: &mut Report,
) -> so3fft::Result<()> {
    let plan = plan::<T>(b, threads, false)?;
    let mut coeffs = SplitMix64::new(50 + b as u64).complex_vec(num_coeffs(b));
    for l in 0..b {
        let scale = ((l + 1) as f64).powf(-p);
        let li = l as isize;
        for m in -li..=li {
            for mp in -li..=li {
                coeffs[coef_index(b, l, m, mp)] *= scale;
            }
        }
    }
    let input = narrow::<T>(&coeffs);
    // The truth: the coefficients as the plan's type holds them.
    let coeffs = widen(&input);
    let mut samples = vec![zero::<T>(); num_samples(b)];
    let mut out = vec![zero::<T>(); num_coeffs(b)];
    let start = Instant::now();
    plan.inverse(&input, &mut samples)?;
    plan.forward(&samples, &mut out)?;
    let time = start.elapsed().as_secs_f64();
    let back = widen(&out);
    // Per degree: ||error|| / ||fhat|| over the degree's coefficients.
    let mut worst = (0.0f64, 0usize);
    for l in 0..b {
        let (mut d2, mut n2) = (0.0, 0.0);
        let li = l as isize;
        for m in -li..=li {
            for mp in -li..=li {
                let i = coef_index(b, l, m, mp);
                d2 += (back[i] - coeffs[i]).norm_sqr();
                n2 += coeffs[i].norm_sqr();
            }
        }
        let rel = (d2 / n2).sqrt();
        if rel > worst.0 || rel.is_nan() {
            worst = (rel, l);
        }
    }
    let variant = format!("(l+1)^{}", -p);
    let note = format!("worst degree l={}: rel {:.2e}", worst.1, worst.0);
    let case = Case {
        test: "power-law",
        b,
        variant: &variant,
        precision: T::PRECISION,
    };
    report.push_errors(case, errors(&back, &coeffs), time, &note);
    Ok(())
}

/// A transform from one complex array to a new one, in `T`.
pub type TransformFn<T> =
    Box<dyn Fn(&[Complex<T>]) -> so3fft::Result<Vec<Complex<T>>> + Send + Sync>;

/// The transforms whose scaling and special values are checked, each as
/// `f(input) -> output` on complex arrays of `T`.
pub struct Transform<T: Float> {
    /// Row label.
    pub name: &'static str,
    /// Runs the transform.
    pub run: TransformFn<T>,
    /// Input length.
    pub input_len: usize,
    /// The input whose contributions are skipped most: the top-order coefficient
    /// `(B-1, -(B-1), B-1)` of an inverse (`(B-1, -8, 8)` partial, `(B-1, B-1)` on S^2), the
    /// sample at `beta_0`, `alpha = gamma = 0` of a forward.
    pub top: usize,
}

fn real_parts<T: Float>(x: &[Complex<T>]) -> Vec<T> {
    x.iter().map(|z| z.re).collect()
}

fn as_complex<T: Float>(x: &[T]) -> Vec<Complex<T>> {
    x.iter()
        .map(|&r| Complex::new(r, T::narrowed(0.0)))
        .collect()
}

/// The ten transforms of the scaling and special-value tests: full plan with skipping
/// off, full plan complex and real, partial order-limited, S^2 complex; inverse and forward
/// of each. Real inverses read the
/// representatives only; real forwards read the real parts.
pub fn transforms<T: Float>(b: usize, threads: usize) -> so3fft::Result<Vec<Transform<T>>> {
    let full = std::sync::Arc::new(plan::<T>(b, threads, true)?);
    let shape = Shape::new(b).with_orders(ORDER_LIMIT.min(b - 1), ORDER_LIMIT.min(b - 1));
    let part = std::sync::Arc::new(PartialPlan::<T>::new(
        &shape,
        &Options::default().with_threads(threads),
    )?);
    let s2 = std::sync::Arc::new(S2Plan::<T>::new(
        b,
        &Options::default().with_threads(threads),
    )?);
    let (nc, ns) = (num_coeffs(b), num_samples(b));
    let (pc, ps) = (part.num_coeffs(), part.num_samples());
    let (sc, ss) = (s2_num_coeffs(b), s2_num_samples(b));
    let top = b as isize - 1;
    let m = ORDER_LIMIT.min(b - 1) as isize;
    let top_so3 = coef_index(b, b - 1, -top, top);
    let top_partial = shape.coef_index(b - 1, -m, m).unwrap_or(0);
    let top_s2 = s2_coef_index(b, b - 1, top);
    let noskip = std::sync::Arc::new(Plan::<T>::new(
        b,
        &Options::default()
            .with_threads(threads)
            .with_skip_bits(Some(0)),
    )?);
    let mut out: Vec<Transform<T>> = Vec::new();
    let p = noskip.clone();
    out.push(Transform {
        name: "so3-inverse-noskip",
        input_len: nc,
        top: top_so3,
        run: Box::new(move |c| {
            let mut f = vec![zero(); ns];
            p.inverse(c, &mut f).map(|_| f)
        }),
    });
    let p = noskip;
    out.push(Transform {
        name: "so3-forward-noskip",
        input_len: ns,
        top: 0,
        run: Box::new(move |f| {
            let mut c = vec![zero(); nc];
            p.forward(f, &mut c).map(|_| c)
        }),
    });
    let p = full.clone();
    out.push(Transform {
        name: "so3-inverse",
        input_len: nc,
        top: top_so3,
        run: Box::new(move |c| {
            let mut f = vec![zero(); ns];
            p.inverse(c, &mut f).map(|_| f)
        }),
    });
    let p = full.clone();
    out.push(Transform {
        name: "so3-forward",
        input_len: ns,
        top: 0,
        run: Box::new(move |f| {
            let mut c = vec![zero(); nc];
            p.forward(f, &mut c).map(|_| c)
        }),
    });
    let p = full.clone();
    out.push(Transform {
        name: "so3-real-inverse",
        input_len: nc,
        top: top_so3,
        run: Box::new(move |c| {
            let mut f = vec![T::narrowed(0.0); ns];
            p.inverse_real(c, &mut f).map(|_| as_complex(&f))
        }),
    });
    let p = full;
    out.push(Transform {
        name: "so3-real-forward",
        input_len: ns,
        top: 0,
        run: Box::new(move |f| {
            let mut c = vec![zero(); nc];
            p.forward_real(&real_parts(f), &mut c).map(|_| c)
        }),
    });
    let p = part.clone();
    out.push(Transform {
        name: "partial-m8-inverse",
        input_len: pc,
        top: top_partial,
        run: Box::new(move |c| {
            let mut f = vec![zero(); ps];
            p.inverse(c, &mut f).map(|_| f)
        }),
    });
    let p = part;
    out.push(Transform {
        name: "partial-m8-forward",
        input_len: ps,
        top: 0,
        run: Box::new(move |f| {
            let mut c = vec![zero(); pc];
            p.forward(f, &mut c).map(|_| c)
        }),
    });
    let p = s2.clone();
    out.push(Transform {
        name: "s2-inverse",
        input_len: sc,
        top: top_s2,
        run: Box::new(move |c| {
            let mut f = vec![zero(); ss];
            p.inverse(c, &mut f).map(|_| f)
        }),
    });
    let p = s2;
    out.push(Transform {
        name: "s2-forward",
        input_len: ss,
        top: 0,
        run: Box::new(move |f| {
            let mut c = vec![zero(); sc];
            p.forward(f, &mut c).map(|_| c)
        }),
    });
    Ok(out)
}

/// The outcome of `T(2^k x)` against `2^k T(x)`.
#[derive(Clone, Copy, Debug)]
pub struct Scaling {
    /// Values whose bits differ.
    pub differing: usize,
    /// Values compared.
    pub total: usize,
    /// Values of `2^k T(x)` that overflow the type (`k` out of range: they cannot differ
    /// from an overflowing `T(2^k x)`, so they are not counted as exact).
    pub overflowing: usize,
    /// `max |T(2^k x) - 2^k T(x)| / (2^k max |T(x)|)`.
    pub max_rel: f64,
}

impl Scaling {
    /// The row's note: `bit-exact`, or what differs.
    pub fn verdict(&self) -> String {
        match (self.differing, self.overflowing) {
            (0, 0) => "bit-exact".to_string(),
            (d, 0) => format!("{d}/{} values differ", self.total),
            (d, o) => format!("{d}/{} values differ, {o} overflow", self.total),
        }
    }
}

/// `v` times `2^k`, computed in `f64` (exact for every `k` of the tests) and rounded to
/// `T`: exact where the product is a normal number of `T`.
fn scaled<T: Float>(v: &[Complex<T>], k: i32) -> Vec<Complex<T>> {
    let factor = pow2(k);
    narrow(&widen(v).iter().map(|z| z * factor).collect::<Vec<_>>())
}

/// `T(2^k x)` against `2^k T(x)` for one transform and a random `x` (values of `T`).
pub fn scaling<T: Float>(t: &Transform<T>, k: i32) -> so3fft::Result<Scaling> {
    let x = random::<T>(&mut SplitMix64::new(60), t.input_len);
    let base = (t.run)(&x)?;
    let got = (t.run)(&scaled(&x, k))?;
    // 2^k T(x) rounded to T: where it is not normal, T(2^k x) cannot be exact either.
    let want = scaled(&base, k);
    let (got64, base64) = (widen(&got), widen(&base));
    let top = base64.iter().map(|z| z.norm()).fold(0.0, f64::max);
    let overflowing = widen(&want)
        .iter()
        .filter(|z| z.re.is_infinite() || z.im.is_infinite())
        .count();
    let unscale = pow2(-k);
    let max_rel = got64
        .iter()
        .zip(&base64)
        .map(|(g, w)| (g * unscale - w).norm() / top)
        .fold(0.0, f64::max);
    Ok(Scaling {
        differing: bit_differences(&got, &want),
        total: got.len(),
        overflowing,
        max_rel,
    })
}

/// Rows `scale-2^k`: every transform, every exponent of `T`.
pub fn scaling_rows<T: Float>(b: usize, threads: usize, report: &mut Report) -> so3fft::Result<()> {
    for t in transforms::<T>(b, threads)? {
        for k in T::PRECISION.scale_exponents() {
            let s = scaling(&t, k)?;
            let verdict = s.verdict();
            report.push(Row {
                test: format!("scale-2^{k}"),
                b,
                variant: t.name.into(),
                precision: T::PRECISION,
                rel_l2: s.max_rel,
                max_abs: f64::NAN,
                time_s: 0.0,
                note: verdict,
            });
        }
    }
    Ok(())
}

/// Subnormal inputs: `T(2^e x) 2^-e` against `T(x)` (`e` of [`crate::precision::Precision::subnormal_exponent`]),
/// and the time against `T(x)`'s.
pub fn subnormal_rows<T: Float>(
    b: usize,
    threads: usize,
    report: &mut Report,
) -> so3fft::Result<()> {
    let e = T::PRECISION.subnormal_exponent();
    for t in transforms::<T>(b, threads)? {
        let x = random::<T>(&mut SplitMix64::new(70), t.input_len);
        let start = Instant::now();
        let base = (t.run)(&x)?;
        let t_normal = start.elapsed().as_secs_f64();
        let tiny = scaled(&x, e);
        let start = Instant::now();
        let got = (t.run)(&tiny)?;
        let t_tiny = start.elapsed().as_secs_f64();
        // Two steps: 2^1040 itself is not a double.
        let half = pow2(-e / 2);
        let up: Vec<Complex64> = widen(&got).iter().map(|z| z * half * half).collect();
        let finite = got
            .iter()
            .all(|z| z.re.widened().is_finite() && z.im.widened().is_finite());
        let note = format!(
            "inputs x 2^{e}, error of result x 2^{}; time {:.1}x normal; {}",
            -e,
            t_tiny / t_normal.max(1e-9),
            if finite { "finite" } else { "NOT finite" }
        );
        let case = Case {
            test: "subnormal",
            b,
            variant: t.name,
            precision: T::PRECISION,
        };
        report.push_errors(case, errors(&up, &base), t_tiny, &note);
    }
    Ok(())
}

/// Counts of NaN, infinite and finite values.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SpecialCounts {
    /// Values with a NaN part.
    pub nan: usize,
    /// Values with an infinite part and no NaN.
    pub inf: usize,
    /// Finite values.
    pub finite: usize,
}

/// Classifies every value.
pub fn special_counts<T: Float>(values: &[Complex<T>]) -> SpecialCounts {
    let mut c = SpecialCounts::default();
    for &z in values {
        let z = crate::precision::widen_one(z);
        if z.re.is_nan() || z.im.is_nan() {
            c.nan += 1;
        } else if z.re.is_infinite() || z.im.is_infinite() {
            c.inf += 1;
        } else {
            c.finite += 1;
        }
    }
    c
}

/// A special value placed in one input.
#[derive(Clone, Copy, Debug)]
pub struct Poison {
    /// Row label.
    pub name: &'static str,
    /// The value (rounded to the plan's type: the same special value).
    pub value: Complex64,
    /// Where (index into the input).
    pub at: PoisonSite,
}

/// Where a poison value goes.
#[derive(Clone, Copy, Debug)]
pub enum PoisonSite {
    /// Input index 1 (a low-degree coefficient `(1, 0, 0)` / a sample on the first slice).
    Low,
    /// The last input (the top order pair's last degree / a sample on the last slice).
    Last,
    /// [`Transform::top`].
    Top,
}

/// The poisons of the NaN / Inf test.
pub const POISONS: [Poison; 5] = [
    Poison {
        name: "NaN@top",
        value: Complex64::new(f64::NAN, 0.0),
        at: PoisonSite::Top,
    },
    Poison {
        name: "NaN@low",
        value: Complex64::new(f64::NAN, 0.0),
        at: PoisonSite::Low,
    },
    Poison {
        name: "NaN@last",
        value: Complex64::new(f64::NAN, 0.0),
        at: PoisonSite::Last,
    },
    Poison {
        name: "+Inf@low",
        value: Complex64::new(f64::INFINITY, 0.0),
        at: PoisonSite::Low,
    },
    Poison {
        name: "-Inf@last",
        value: Complex64::new(f64::NEG_INFINITY, 0.0),
        at: PoisonSite::Last,
    },
];

/// Runs transform `t` on a random input with one poisoned value in a separate thread;
/// `None` if it has not returned after `timeout` (it is left running).
pub fn poisoned<T: Float>(
    t: Arc<Transform<T>>,
    poison: Poison,
    timeout: Duration,
) -> Option<so3fft::Result<(SpecialCounts, f64)>> {
    let (send, recv) = mpsc::channel();
    std::thread::spawn(move || {
        let mut x = random::<T>(&mut SplitMix64::new(80), t.input_len);
        let i = match poison.at {
            PoisonSite::Low => 1,
            PoisonSite::Last => t.input_len - 1,
            PoisonSite::Top => t.top,
        };
        x[i] = narrow_one(poison.value);
        let start = Instant::now();
        let result = (t.run)(&x).map(|y| (special_counts(&y), start.elapsed().as_secs_f64()));
        let _ = send.send(result);
    });
    recv.recv_timeout(timeout).ok()
}

/// Rows `nan-inf`: every transform, every poison; the note counts NaN / Inf / finite outputs.
pub fn special_rows<T: Float>(b: usize, threads: usize, report: &mut Report) -> so3fft::Result<()> {
    for t in transforms::<T>(b, threads)? {
        let name = t.name;
        // One plan for every poison: NaN left behind in a plan's buffers would show in the
        // rows that follow.
        let t = Arc::new(t);
        for poison in POISONS {
            let timeout = Duration::from_secs(60);
            let (note, time) = match poisoned::<T>(t.clone(), poison, timeout) {
                None => ("HANG: no result after 60 s".to_string(), f64::NAN),
                Some(Err(e)) => (format!("error: {e}"), f64::NAN),
                Some(Ok((c, t))) => (
                    format!(
                        "{}: out NaN {} Inf {} finite {} of {}",
                        poison.name,
                        c.nan,
                        c.inf,
                        c.finite,
                        c.nan + c.inf + c.finite
                    ),
                    t,
                ),
            };
            report.push(Row {
                test: "nan-inf".into(),
                b,
                variant: format!("{name}/{}", poison.name),
                precision: T::PRECISION,
                rel_l2: f64::NAN,
                max_abs: f64::NAN,
                time_s: time,
                note,
            });
        }
    }
    Ok(())
}

/// The bandwidths of the adversarial tests.
pub struct Bandwidths<'a> {
    /// SO(3) top-order single coefficients.
    pub top: &'a [usize],
    /// S^2 top-order single coefficients.
    pub s2_top: &'a [usize],
    /// Power laws, scaling, subnormal and special values.
    pub small: usize,
}

/// Every adversarial test in `T`.
pub fn run<T: Float>(
    bw: &Bandwidths<'_>,
    threads: usize,
    report: &mut Report,
) -> so3fft::Result<()> {
    for &b in bw.top {
        top_order::<T>(b, threads, report)?;
    }
    for &b in bw.s2_top {
        s2_top_order::<T>(b, threads, report)?;
    }
    for p in [2.0, 4.0, -2.0] {
        power_law::<T>(bw.small, p, threads, report)?;
    }
    scaling_rows::<T>(bw.small, threads, report)?;
    subnormal_rows::<T>(bw.small, threads, report)?;
    special_rows::<T>(bw.small, threads, report)?;
    Ok(())
}
