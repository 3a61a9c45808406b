//! (a) Errors against exact values: inverse and forward transforms compared with 40-digit
//! sums from `tests/data/stress/gen_stress_reference.py`, on every instruction set the CPU
//! has (e). In `f32` the inputs are rounded to `f32` first and the truth stays that of the
//! `f64` inputs: the error includes the inputs' rounding (about `3e-8` relative).

use crate::precision::{narrow, random, zero, Float};
use crate::record::{errors, Case, Report};
use crate::rng::SplitMix64;
use so3fft::{coef_index, num_samples, sample_index, Complex64, Isa, Options, Plan};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Bandwidths of the inverse reference files.
pub const INVERSE_BANDWIDTHS: [usize; 4] = [4, 8, 16, 32];
/// Bandwidths of the forward reference files (`forward_B*`; `poles_B*` stop at 16).
pub const FORWARD_BANDWIDTHS: [usize; 4] = [4, 8, 16, 32];
/// Bandwidths of the pole-only forward reference files.
pub const POLES_BANDWIDTHS: [usize; 3] = [4, 8, 16];

/// The reference data directory of the source tree.
pub fn default_data_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../tests/data/stress")
}

/// Every instruction set this CPU runs, best first.
pub fn supported_isas() -> Vec<Isa> {
    [Isa::Avx512, Isa::Avx2, Isa::Scalar]
        .into_iter()
        .filter(|i| i.is_supported())
        .collect()
}

/// Lower-case name of an instruction set.
pub fn isa_name(isa: Isa) -> &'static str {
    match isa {
        Isa::Avx512 => "avx512",
        Isa::Avx2 => "avx2",
        Isa::Scalar => "scalar",
    }
}

/// The numeric lines of a reference file: three integers and a complex value each.
pub fn read_reference(path: &Path) -> std::io::Result<Vec<([i64; 3], Complex64)>> {
    let text = std::fs::read_to_string(path)?;
    let bad = |line: &str| {
        std::io::Error::new(
            std::io::ErrorKind::InvalidData,
            format!("{}: bad line {line:?}", path.display()),
        )
    };
    let mut out = Vec::new();
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
    {
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.len() != 5 {
            return Err(bad(line));
        }
        let int = |s: &str| s.parse::<i64>().map_err(|_| bad(line));
        let real = |s: &str| s.parse::<f64>().map_err(|_| bad(line));
        out.push((
            [int(f[0])?, int(f[1])?, int(f[2])?],
            Complex64::new(real(f[3])?, real(f[4])?),
        ));
    }
    Ok(out)
}

/// The coefficients the generator's inverse reference transforms: SplitMix64(1000 + B),
/// re then im, for l, then M, then M' ascending.
pub fn inverse_input(b: usize) -> Vec<Complex64> {
    let mut rng = SplitMix64::new(1000 + b as u64);
    let mut coeffs = vec![Complex64::new(0.0, 0.0); so3fft::num_coeffs(b)];
    for l in 0..b {
        let li = l as isize;
        for m in -li..=li {
            for mp in -li..=li {
                coeffs[coef_index(b, l, m, mp)] = rng.complex();
            }
        }
    }
    coeffs
}

/// The samples of a forward reference: SplitMix64(seed) in flat sample order over the
/// given beta slices, zero elsewhere.
pub fn forward_input(b: usize, seed: u64, slices: &[usize]) -> Vec<Complex64> {
    let mut rng = SplitMix64::new(seed);
    let slice = 4 * b * b;
    let mut samples = vec![Complex64::new(0.0, 0.0); num_samples(b)];
    for &k in slices {
        for v in &mut samples[k * slice..(k + 1) * slice] {
            *v = rng.complex();
        }
    }
    samples
}

/// Which forward reference: random samples everywhere or on the pole slices only.
#[derive(Clone, Copy, PartialEq, Eq)]
pub enum ForwardKind {
    /// `forward_B*.txt`: every beta.
    Everywhere,
    /// `poles_B*.txt`: `beta_0` and `beta_{2B-1}` only.
    Poles,
}

impl ForwardKind {
    fn file_stem(self) -> &'static str {
        match self {
            ForwardKind::Everywhere => "forward",
            ForwardKind::Poles => "poles",
        }
    }

    fn seed(self, b: usize) -> u64 {
        b as u64
            + match self {
                ForwardKind::Everywhere => 2000,
                ForwardKind::Poles => 3000,
            }
    }

    fn slices(self, b: usize) -> Vec<usize> {
        match self {
            ForwardKind::Everywhere => (0..2 * b).collect(),
            ForwardKind::Poles => vec![0, 2 * b - 1],
        }
    }
}

fn plan_on<T: Float>(b: usize, isa: Isa, threads: usize) -> so3fft::Result<Plan<T>> {
    Plan::new(
        b,
        &Options::default().with_isa(Some(isa)).with_threads(threads),
    )
}

fn io_error(e: std::io::Error) -> so3fft::Error {
    so3fft::Error::InvalidArgument(e.to_string())
}

/// The inverse at the reference points in `T`: (errors, seconds of the transform).
pub fn check_inverse<T: Float>(
    dir: &Path,
    b: usize,
    isa: Isa,
    threads: usize,
) -> so3fft::Result<(crate::record::Errors, f64)> {
    let refs = read_reference(&dir.join(format!("inverse_B{b}.txt"))).map_err(io_error)?;
    let plan = plan_on::<T>(b, isa, threads)?;
    let coeffs = narrow::<T>(&inverse_input(b));
    let mut samples = vec![zero::<T>(); num_samples(b)];
    let start = Instant::now();
    plan.inverse(&coeffs, &mut samples)?;
    let time = start.elapsed().as_secs_f64();
    let got: Vec<_> = refs
        .iter()
        .map(|([k, j1, j2], _)| samples[sample_index(b, *j1 as usize, *k as usize, *j2 as usize)])
        .collect();
    let want: Vec<Complex64> = refs.iter().map(|r| r.1).collect();
    Ok((errors(&got, &want), time))
}

/// The forward at the reference coefficients in `T`: (errors, seconds of the transform).
pub fn check_forward<T: Float>(
    dir: &Path,
    b: usize,
    kind: ForwardKind,
    isa: Isa,
    threads: usize,
) -> so3fft::Result<(crate::record::Errors, f64)> {
    let path = dir.join(format!("{}_B{b}.txt", kind.file_stem()));
    let refs = read_reference(&path).map_err(io_error)?;
    let plan = plan_on::<T>(b, isa, threads)?;
    let samples = narrow::<T>(&forward_input(b, kind.seed(b), &kind.slices(b)));
    let mut coeffs = vec![zero::<T>(); so3fft::num_coeffs(b)];
    let start = Instant::now();
    plan.forward(&samples, &mut coeffs)?;
    let time = start.elapsed().as_secs_f64();
    let got: Vec<_> = refs
        .iter()
        .map(|([l, m, mp], _)| coeffs[coef_index(b, *l as usize, *m as isize, *mp as isize)])
        .collect();
    let want: Vec<Complex64> = refs.iter().map(|r| r.1).collect();
    Ok((errors(&got, &want), time))
}

/// Every reference file on every instruction set, in `T`: rows `reference-inverse`,
/// `reference-forward`, `reference-poles` with the ISA as variant.
pub fn run<T: Float>(dir: &Path, threads: usize, report: &mut Report) -> so3fft::Result<()> {
    for isa in supported_isas() {
        let variant = isa_name(isa);
        for b in INVERSE_BANDWIDTHS {
            let (e, t) = check_inverse::<T>(dir, b, isa, threads)?;
            let case = Case {
                test: "reference-inverse",
                b,
                variant,
                precision: T::PRECISION,
            };
            report.push_errors(case, e, t, "vs 40-digit direct sum, 7-8 betas x 8 points");
        }
        for b in FORWARD_BANDWIDTHS {
            let (e, t) = check_forward::<T>(dir, b, ForwardKind::Everywhere, isa, threads)?;
            let case = Case {
                test: "reference-forward",
                b,
                variant,
                precision: T::PRECISION,
            };
            report.push_errors(case, e, t, "random samples, vs 40-digit quadrature");
        }
        for b in POLES_BANDWIDTHS {
            let (e, t) = check_forward::<T>(dir, b, ForwardKind::Poles, isa, threads)?;
            let case = Case {
                test: "reference-poles",
                b,
                variant,
                precision: T::PRECISION,
            };
            report.push_errors(case, e, t, "mass on beta_0, beta_2B-1 only");
        }
    }
    Ok(())
}

/// Bandwidths of the per-instruction-set round trips.
#[derive(Clone, Copy)]
pub struct IsaBandwidths {
    /// Full SO(3) plan.
    pub so3: usize,
    /// Order-limited partial plan.
    pub partial: usize,
    /// S^2 plan.
    pub s2: usize,
}

/// Round trips on every instruction set, in `T`: rows `isa-roundtrip` with variants
/// `so3-<isa>`, `partial-m8-<isa>`, `s2-<isa>`.
pub fn isa_roundtrips<T: Float>(
    bw: IsaBandwidths,
    threads: usize,
    report: &mut Report,
) -> so3fft::Result<()> {
    use so3fft::s2::{s2_num_coeffs, s2_num_samples, S2Plan};
    use so3fft::{PartialPlan, Shape};
    for isa in supported_isas() {
        let name = isa_name(isa);
        let mut push = |b: usize, kind: &str, e, time| {
            let variant = format!("{kind}-{name}");
            let case = Case {
                test: "isa-roundtrip",
                b,
                variant: &variant,
                precision: T::PRECISION,
            };
            report.push_errors(case, e, time, "");
        };
        let b = bw.so3;
        let plan = plan_on::<T>(b, isa, threads)?;
        let c = random::<T>(&mut SplitMix64::new(10 + b as u64), so3fft::num_coeffs(b));
        let (mut f, mut back) = (vec![zero::<T>(); num_samples(b)], vec![zero(); c.len()]);
        let start = Instant::now();
        plan.inverse(&c, &mut f)?;
        plan.forward(&f, &mut back)?;
        push(b, "so3", errors(&back, &c), start.elapsed().as_secs_f64());

        let b = bw.partial;
        let m = crate::roundtrip::ORDER_LIMIT;
        let opts = Options::default().with_isa(Some(isa)).with_threads(threads);
        let plan = PartialPlan::<T>::new(&Shape::new(b).with_orders(m, m), &opts)?;
        let c = random::<T>(&mut SplitMix64::new(30 + b as u64), plan.num_coeffs());
        let (mut f, mut back) = (vec![zero::<T>(); plan.num_samples()], vec![zero(); c.len()]);
        let start = Instant::now();
        plan.inverse(&c, &mut f)?;
        plan.forward(&f, &mut back)?;
        push(
            b,
            "partial-m8",
            errors(&back, &c),
            start.elapsed().as_secs_f64(),
        );

        let b = bw.s2;
        let opts = Options::default().with_isa(Some(isa)).with_threads(threads);
        let plan = S2Plan::<T>::new(b, &opts)?;
        let c = random::<T>(&mut SplitMix64::new(40 + b as u64), s2_num_coeffs(b));
        let (mut f, mut back) = (vec![zero::<T>(); s2_num_samples(b)], vec![zero(); c.len()]);
        let start = Instant::now();
        plan.inverse(&c, &mut f)?;
        plan.forward(&f, &mut back)?;
        push(b, "s2", errors(&back, &c), start.elapsed().as_secs_f64());
    }
    Ok(())
}
