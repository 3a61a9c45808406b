//! (d) Determinism: every plan kind gives the same bits on 1, 2 and 4 threads (4 is
//! oversubscribed on a two-core machine) and across repeated executions of one plan.

use crate::record::{Report, Row};
use crate::rng::SplitMix64;
use crate::roundtrip::ORDER_LIMIT;
use so3fft::s2::{s2_num_coeffs, S2Plan};
use so3fft::{num_coeffs, Complex64, Options, PartialPlan, Plan, Shape};
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

fn bits(values: &[Complex64], out: &mut Vec<u64>) {
    out.extend(values.iter().flat_map(|z| [z.re.to_bits(), z.im.to_bits()]));
}

fn bits_real(values: &[f64], out: &mut Vec<u64>) {
    out.extend(values.iter().map(|x| x.to_bits()));
}

fn plan_runner(b: usize, opts: Options) -> so3fft::Result<Runner> {
    let real = opts.real;
    let plan = Plan::new(b, &opts)?;
    let coeffs = SplitMix64::new(100 + b as u64).complex_vec(num_coeffs(b));
    Ok(Box::new(move || {
        let mut out = Vec::new();
        let mut back = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
        if real {
            let mut f = vec![0.0; plan.num_samples()];
            plan.inverse_real(&coeffs, &mut f)?;
            plan.forward_real(&f, &mut back)?;
            bits_real(&f, &mut out);
        } else {
            let mut f = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
            plan.inverse(&coeffs, &mut f)?;
            plan.forward(&f, &mut back)?;
            bits(&f, &mut out);
        }
        bits(&back, &mut out);
        Ok(out)
    }))
}

fn partial_runner(shape: Shape, opts: Options) -> so3fft::Result<Runner> {
    let real = opts.real;
    let plan = PartialPlan::new(&shape, &opts)?;
    let coeffs = SplitMix64::new(200).complex_vec(plan.num_coeffs());
    Ok(Box::new(move || {
        let mut out = Vec::new();
        let mut back = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
        if real {
            let mut f = vec![0.0; plan.num_samples()];
            plan.inverse_real(&coeffs, &mut f)?;
            plan.forward_real(&f, &mut back)?;
            bits_real(&f, &mut out);
        } else {
            let mut f = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
            plan.inverse(&coeffs, &mut f)?;
            plan.forward(&f, &mut back)?;
            bits(&f, &mut out);
        }
        bits(&back, &mut out);
        Ok(out)
    }))
}

fn s2_runner(b: usize, threads: usize, real: bool) -> so3fft::Result<Runner> {
    let plan = S2Plan::new(b, &Options::default().with_threads(threads))?;
    let coeffs = SplitMix64::new(300).complex_vec(s2_num_coeffs(b));
    Ok(Box::new(move || {
        let mut out = Vec::new();
        let mut back = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
        if real {
            let mut f = vec![0.0; plan.num_samples()];
            plan.inverse_real(&coeffs, &mut f)?;
            plan.forward_real(&f, &mut back)?;
            bits_real(&f, &mut out);
        } else {
            let mut f = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
            plan.inverse(&coeffs, &mut f)?;
            plan.forward(&f, &mut back)?;
            bits(&f, &mut out);
        }
        bits(&back, &mut out);
        Ok(out)
    }))
}

/// The runner of `kind` at bandwidth `b` on `threads` threads.
pub fn runner(kind: Kind, b: usize, threads: usize) -> so3fft::Result<Runner> {
    let plan_opts = Options::default().with_threads(threads);
    let m = ORDER_LIMIT.min(b - 1);
    let partial_opts = Options::default().with_threads(threads);
    match kind {
        Kind::PlanComplex => plan_runner(b, plan_opts),
        Kind::PlanChunked => plan_runner(b, plan_opts.with_max_workspace_bytes(Some(1 << 20))),
        Kind::PlanReal => plan_runner(b, plan_opts.with_real(true)),
        Kind::PartialComplex => partial_runner(Shape::new(b).with_orders(m, m), partial_opts),
        Kind::PartialReal => partial_runner(
            Shape::new(b).with_orders(m, m),
            partial_opts.with_real(true),
        ),
        Kind::S2Complex => s2_runner(b, threads, false),
        Kind::S2Real => s2_runner(b, threads, true),
    }
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

/// Checks one kind: (outcome, seconds of one 1-thread run).
pub fn check(kind: Kind, b: usize) -> so3fft::Result<(Outcome, f64)> {
    let mut reference: Option<Vec<u64>> = None;
    let mut outcome = Outcome {
        across_threads: Vec::new(),
        across_repeats: 0,
        values: 0,
    };
    let mut time = 0.0;
    for threads in THREADS {
        let run = runner(kind, b, threads)?;
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

/// Rows `determinism`: one per kind.
pub fn run(b: usize, report: &mut Report) -> so3fft::Result<()> {
    for kind in KINDS {
        let (o, time) = check(kind, b)?;
        let note = if o.identical() {
            format!(
                "bit-identical: threads 1/2/4, 3 executes each ({} doubles)",
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
            rel_l2: f64::NAN,
            max_abs: f64::NAN,
            time_s: time,
            note,
        });
    }
    Ok(())
}
