//! (d) Determinism: every plan kind gives the same bits on 1, 2 and 4 threads (4 is
//! oversubscribed on a two-core machine) and across repeated executions of one plan, in
//! `f64` and `f32`.

use crate::precision::{random, zero, Float};
use crate::record::{Report, Row};
use crate::rng::SplitMix64;
use crate::roundtrip::ORDER_LIMIT;
use so3fft::s2::S2Plan;
use so3fft::{Complex, Options, PartialPlan, Plan, Shape};
use std::time::Instant;

/// The plan kinds checked.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// [`Plan`], complex, default options.
    PlanComplex,
    /// [`Plan`], complex, a 1 MiB chunk buffer (many chunks).
    PlanChunked,
    /// [`Plan`], real signals.
    PlanReal,
    /// [`PartialPlan`], `|M|, |M'| <= 8`, complex.
    PartialComplex,
    /// [`PartialPlan`], `|M|, |M'| <= 8`, real.
    PartialReal,
    /// [`S2Plan`], complex.
    S2Complex,
    /// [`S2Plan`], real.
    S2Real,
}

/// Every kind.
pub const KINDS: [Kind; 7] = [
    Kind::PlanComplex,
    Kind::PlanChunked,
    Kind::PlanReal,
    Kind::PartialComplex,
    Kind::PartialReal,
    Kind::S2Complex,
    Kind::S2Real,
];

impl Kind {
    /// Row label.
    pub fn name(self) -> &'static str {
        match self {
            Kind::PlanComplex => "plan-complex",
            Kind::PlanChunked => "plan-complex-chunked",
            Kind::PlanReal => "plan-real",
            Kind::PartialComplex => "partial-m8",
            Kind::PartialReal => "partial-m8-real",
            Kind::S2Complex => "s2-complex",
            Kind::S2Real => "s2-real",
        }
    }
}

/// Runs the inverse of fixed random coefficients, then the forward of the result, and
/// returns the bits of both outputs.
pub type Runner = Box<dyn Fn() -> so3fft::Result<Vec<u64>>>;

fn bits<T: Float>(values: &[Complex<T>], out: &mut Vec<u64>) {
    out.extend(
        values
            .iter()
            .flat_map(|z| [z.re.bit_pattern(), z.im.bit_pattern()]),
    );
}

fn bits_real<T: Float>(values: &[T], out: &mut Vec<u64>) {
    out.extend(values.iter().map(|x| x.bit_pattern()));
}

/// The transforms a runner needs of a plan kind.
trait RoundTrip<T: Float> {
    fn sizes(&self) -> (usize, usize);
    fn inverse(&self, c: &[Complex<T>], f: &mut [Complex<T>]) -> so3fft::Result<()>;
    fn forward(&self, f: &[Complex<T>], c: &mut [Complex<T>]) -> so3fft::Result<()>;
    fn inverse_real(&self, c: &[Complex<T>], f: &mut [T]) -> so3fft::Result<()>;
    fn forward_real(&self, f: &[T], c: &mut [Complex<T>]) -> so3fft::Result<()>;
}

macro_rules! round_trip_of {
    ($plan:ident) => {
        impl<T: Float> RoundTrip<T> for $plan<T> {
            fn sizes(&self) -> (usize, usize) {
                (self.num_coeffs(), self.num_samples())
            }
            fn inverse(&self, c: &[Complex<T>], f: &mut [Complex<T>]) -> so3fft::Result<()> {
                $plan::inverse(self, c, f).map(|_| ())
            }
            fn forward(&self, f: &[Complex<T>], c: &mut [Complex<T>]) -> so3fft::Result<()> {
                $plan::forward(self, f, c).map(|_| ())
            }
            fn inverse_real(&self, c: &[Complex<T>], f: &mut [T]) -> so3fft::Result<()> {
                $plan::inverse_real(self, c, f).map(|_| ())
            }
            fn forward_real(&self, f: &[T], c: &mut [Complex<T>]) -> so3fft::Result<()> {
                $plan::forward_real(self, f, c).map(|_| ())
            }
        }
    };
}

round_trip_of!(Plan);
round_trip_of!(PartialPlan);
round_trip_of!(S2Plan);

/// The runner of `plan` on random coefficients of `seed` (complex, or the real transforms
/// on the same coefficients: a real inverse reads one block of each conjugate pair).
fn runner_of<T: Float, P: RoundTrip<T> + 'static>(plan: P, real: bool, seed: u64) -> Runner {
    let (nc, ns) = plan.sizes();
    let coeffs = random::<T>(&mut SplitMix64::new(seed), nc);
    Box::new(move || {
        let mut out = Vec::new();
        let mut back = vec![zero::<T>(); nc];
        if real {
            let mut f = vec![T::narrowed(0.0); ns];
            plan.inverse_real(&coeffs, &mut f)?;
            plan.forward_real(&f, &mut back)?;
            bits_real(&f, &mut out);
        } else {
            let mut f = vec![zero::<T>(); ns];
            plan.inverse(&coeffs, &mut f)?;
            plan.forward(&f, &mut back)?;
            bits(&f, &mut out);
        }
        bits(&back, &mut out);
        Ok(out)
    })
}

/// The runner of `kind` at bandwidth `b` on `threads` threads, in `T`.
pub fn runner<T: Float>(kind: Kind, b: usize, threads: usize) -> so3fft::Result<Runner> {
    let opts = Options::default().with_threads(threads);
    let m = ORDER_LIMIT.min(b - 1);
    let shape = Shape::new(b).with_orders(m, m);
    let seed = 100 + b as u64;
    Ok(match kind {
        Kind::PlanComplex => runner_of(Plan::<T>::new(b, &opts)?, false, seed),
        Kind::PlanChunked => {
            let opts = opts.with_max_workspace_bytes(Some(1 << 20));
            runner_of(Plan::<T>::new(b, &opts)?, false, seed)
        }
        Kind::PlanReal => runner_of(Plan::<T>::new(b, &opts.with_real(true))?, true, seed),
        Kind::PartialComplex => runner_of(PartialPlan::<T>::new(&shape, &opts)?, false, 200),
        Kind::PartialReal => {
            let plan = PartialPlan::<T>::new(&shape, &opts.with_real(true))?;
            runner_of(plan, true, 200)
        }
        Kind::S2Complex => runner_of(S2Plan::<T>::new(b, &opts)?, false, 300),
        Kind::S2Real => runner_of(S2Plan::<T>::new(b, &opts)?, true, 300),
    })
}

/// Thread counts compared.
pub const THREADS: [usize; 3] = [1, 2, 4];

/// The result of one kind: values that differ from the 1-thread run, per thread count,
/// and across three repeated executions of each plan.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Outcome {
    /// `(threads, differing values)` against the 1-thread result.
    pub across_threads: Vec<(usize, usize)>,
    /// Differing values between repeats (summed over thread counts).
    pub across_repeats: usize,
    /// Values compared per run.
    pub values: usize,
}

impl Outcome {
    /// Whether every comparison was bit-identical.
    pub fn identical(&self) -> bool {
        self.across_repeats == 0 && self.across_threads.iter().all(|t| t.1 == 0)
    }
}

fn differing(a: &[u64], b: &[u64]) -> usize {
    a.iter().zip(b).filter(|(x, y)| x != y).count() + a.len().abs_diff(b.len())
}

/// Checks one kind in `T`: (outcome, seconds of one 1-thread run).
pub fn check<T: Float>(kind: Kind, b: usize) -> so3fft::Result<(Outcome, f64)> {
    let mut reference: Option<Vec<u64>> = None;
    let mut outcome = Outcome {
        across_threads: Vec::new(),
        across_repeats: 0,
        values: 0,
    };
    let mut time = 0.0;
    for threads in THREADS {
        let run = runner::<T>(kind, b, threads)?;
        let start = Instant::now();
        let first = run()?;
        if threads == 1 {
            time = start.elapsed().as_secs_f64();
        }
        for _ in 0..2 {
            outcome.across_repeats += differing(&first, &run()?);
        }
        match &reference {
            None => {
                outcome.values = first.len();
                reference = Some(first);
            }
            Some(r) => outcome.across_threads.push((threads, differing(r, &first))),
        }
    }
    Ok((outcome, time))
}

/// Rows `determinism`: one per kind, in `T`.
pub fn run<T: Float>(b: usize, report: &mut Report) -> so3fft::Result<()> {
    for kind in KINDS {
        let (o, time) = check::<T>(kind, b)?;
        let note = if o.identical() {
            format!(
                "bit-identical: threads 1/2/4, 3 executes each ({} values)",
                o.values
            )
        } else {
            let t: Vec<String> = o
                .across_threads
                .iter()
                .map(|(t, d)| format!("{t} threads: {d} differ"))
                .collect();
            format!("{}; repeats: {} differ", t.join(", "), o.across_repeats)
        };
        report.push(Row {
            test: "determinism".into(),
            b,
            variant: kind.name().into(),
            precision: T::PRECISION,
            rel_l2: f64::NAN,
            max_abs: f64::NAN,
            time_s: time,
            note,
        });
    }
    Ok(())
}
