//! The one set of transforms of every SO(3) plan (`so3fft::Transform`): the calls in the
//! caller's scratch give the plain calls' results bit for bit, on every instruction set and
//! shape, and those are right (direct summation for the full plan, the exact round trip
//! for the others); a scratch too small is an error, not a write past it.

mod common;

use common::{direct_inverse, Rng};
use so3fft::s2::S2Plan;
use so3fft::{
    Complex64, DistributedPlan, Error, Exchange, Isa, Options, PartialPlan, Plan, Scratch, Shape,
    ThreadExchange, Transform,
};

fn isas() -> impl Iterator<Item = Isa> {
    [Isa::Avx512, Isa::Avx2, Isa::Scalar]
        .into_iter()
        .filter(|i| i.is_supported())
}

fn bits(v: &[Complex64]) -> Vec<(u64, u64)> {
    v.iter().map(|z| (z.re.to_bits(), z.im.to_bits())).collect()
}

fn max_diff(a: &[Complex64], b: &[Complex64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}

/// Every transform of `plan` in `scratch` against the plain call: identical bits; the real
/// round trip on the samples' side. Returns the complex inverse of `coeffs` and the
/// forward of that (for the caller's truth).
fn same_with_scratch(
    plan: &dyn Transform,
    coeffs: &[Complex64],
    real_coeffs: &[Complex64],
    scratch: &mut Scratch,
) -> (Vec<Complex64>, Vec<Complex64>) {
    let (ns, nc) = (plan.num_samples(), plan.num_coeffs());
    let mut x = vec![Complex64::default(); ns];
    let mut xs = vec![Complex64::default(); ns];
    plan.inverse(coeffs, &mut x).unwrap();
    plan.inverse_with_scratch(coeffs, &mut xs, scratch).unwrap();
    assert_eq!(bits(&x), bits(&xs), "inverse");
    let mut c = vec![Complex64::default(); nc];
    let mut cs = vec![Complex64::default(); nc];
    plan.forward(&x, &mut c).unwrap();
    plan.forward_with_scratch(&x, &mut cs, scratch).unwrap();
    assert_eq!(bits(&c), bits(&cs), "forward");
    // Real signals.
    let mut r = vec![0.0; ns];
    let mut rs = vec![0.0; ns];
    plan.inverse_real(real_coeffs, &mut r).unwrap();
    plan.inverse_real_with_scratch(real_coeffs, &mut rs, scratch)
        .unwrap();
    assert!(r.iter().zip(&rs).all(|(a, b)| a.to_bits() == b.to_bits()));
    let mut rc = vec![Complex64::default(); nc];
    let mut rcs = vec![Complex64::default(); nc];
    plan.forward_real(&r, &mut rc).unwrap();
    plan.forward_real_with_scratch(&r, &mut rcs, scratch)
        .unwrap();
    assert_eq!(bits(&rc), bits(&rcs), "real forward");
    // The real samples of any coefficients are band-limited: their transform gives them
    // back.
    let mut r2 = vec![0.0; ns];
    plan.inverse_real(&rc, &mut r2).unwrap();
    let err = r
        .iter()
        .zip(&r2)
        .map(|(a, b)| (a - b).abs())
        .fold(0.0, f64::max);
    assert!(err < 1e-12, "real round trip {err:e}");
    (x, c)
}

/// The full plan: results in the caller's scratch equal the plain ones and direct sums.
#[test]
fn plan_with_scratch() {
    let b = 6;
    let mut rng = Rng::new(7);
    let coeffs = rng.complex_vec(so3fft::num_coeffs(b));
    let other = rng.complex_vec(so3fft::num_coeffs(b));
    let direct = direct_inverse(b, &coeffs);
    for isa in isas() {
        let opts = Options::default()
            .with_threads(2)
            .with_real(true)
            .with_isa(Some(isa));
        let plan = Plan::new(b, &opts).unwrap();
        let mut scratch = Scratch::for_plan(&plan).unwrap();
        assert!(scratch.bytes() >= plan.scratch_bytes());
        // Twice: a scratch left dirty by earlier calls changes nothing.
        for _ in 0..2 {
            let (x, c) = same_with_scratch(&plan, &coeffs, &other, &mut scratch);
            assert!(
                max_diff(&x, &direct) < 1e-12,
                "{isa:?}: against direct sums"
            );
            assert!(max_diff(&c, &coeffs) < 1e-12, "{isa:?}: round trip");
        }
    }
}

/// Partial shapes (band- and order-limited, oversampled, a lower degree limit) and the
/// full shape: results in the scratch equal the plain ones, and
/// the round trip is exact.
#[test]
fn partial_plans_with_scratch() {
    let shapes = [
        Shape::new(8),
        Shape::new(6).with_grid(8, 16, 16),
        Shape::new(7).with_orders(4, 3).with_grid(9, 11, 10),
        Shape::new(6).with_degree_min(2).with_grid(7, 14, 15),
    ];
    for s in shapes {
        let mut rng = Rng::new(11);
        let coeffs = rng.complex_vec(s.num_coeffs());
        let other = rng.complex_vec(s.num_coeffs());
        for isa in isas() {
            let opts = Options::default()
                .with_threads(2)
                .with_real(true)
                .with_isa(Some(isa));
            let plan = PartialPlan::new(&s, &opts).unwrap();
            let mut scratch = Scratch::new(plan.scratch_bytes()).unwrap();
            let (_, c) = same_with_scratch(&plan, &coeffs, &other, &mut scratch);
            assert!(max_diff(&c, &coeffs) < 1e-12, "{s:?} {isa:?}: round trip");
        }
    }
}

/// S^2 plans: the same in their ring scratch; the round trip is exact.
#[test]
fn s2_plans_with_scratch() {
    for b in [1, 5, 16] {
        let mut rng = Rng::new(13);
        for isa in isas() {
            let plan =
                S2Plan::new(b, &Options::default().with_threads(2).with_isa(Some(isa))).unwrap();
            let coeffs = rng.complex_vec(plan.num_coeffs());
            let other = rng.complex_vec(plan.num_coeffs());
            let mut scratch = Scratch::for_plan(&plan).unwrap();
            let (_, c) = same_with_scratch(&plan, &coeffs, &other, &mut scratch);
            assert!(max_diff(&c, &coeffs) < 1e-12, "B {b} {isa:?}: round trip");
        }
    }
}

/// Distributed plans (two ranks on threads): the same on each rank's share, in each rank's
/// scratch; a scratch too small on one rank fails both (collectively, none waits).
#[test]
fn distributed_plans_with_scratch() {
    let s = Shape::new(7).with_grid(8, 16, 16);
    let group = ThreadExchange::group(2);
    std::thread::scope(|scope| {
        for comm in &group {
            scope.spawn(move || {
                let opts = Options::default().with_threads(1).with_real(true);
                let plan = DistributedPlan::new(comm, &s, &opts).unwrap();
                let mut rng = Rng::new(17 + comm.rank() as u64);
                let coeffs = rng.complex_vec(plan.local_num_coeffs());
                let other = rng.complex_vec(plan.local_num_coeffs());
                let mut scratch = Scratch::for_plan(&plan).unwrap();
                let (_, c) = same_with_scratch(&plan, &coeffs, &other, &mut scratch);
                assert!(max_diff(&c, &coeffs) < 1e-12, "round trip");
                // Rank 1's scratch is too small: both ranks get an error.
                let bytes = if comm.rank() == 1 { 8 } else { scratch.bytes() };
                let mut small = Scratch::new(bytes).unwrap();
                let mut x = vec![Complex64::default(); plan.local_num_samples()];
                assert!(plan
                    .inverse_with_scratch(&coeffs, &mut x, &mut small)
                    .is_err());
            });
        }
    });
}

/// A scratch smaller than the plan needs is refused before anything runs; a larger one
/// serves.
#[test]
fn scratch_too_small_is_an_error() {
    let plan = Plan::new(8, &Options::default().with_threads(1)).unwrap();
    let partial = PartialPlan::new(
        &Shape::new(6).with_grid(8, 16, 16),
        &Options::default().with_threads(1),
    )
    .unwrap();
    let s2 = S2Plan::new(8, &Options::default().with_threads(1)).unwrap();
    let plans: [&dyn Transform; 3] = [&plan, &partial, &s2];
    for p in plans {
        let mut small = Scratch::new(p.scratch_bytes() / 2).unwrap();
        let c = vec![Complex64::new(1.0, 0.0); p.num_coeffs()];
        let mut x = vec![Complex64::new(f64::NAN, 0.0); p.num_samples()];
        let r = p.inverse_with_scratch(&c, &mut x, &mut small);
        assert!(
            matches!(r, Err(Error::LengthMismatch { what, .. }) if what == "scratch bytes"),
            "{r:?}"
        );
        assert!(x.iter().all(|v| v.re.is_nan()), "nothing written");
    }
    // A scratch made for another plan, larger than this one needs.
    let mut big = Scratch::new(2 * partial.scratch_bytes()).unwrap();
    let c = vec![Complex64::new(0.5, 0.0); partial.num_coeffs()];
    let mut x = vec![Complex64::default(); partial.num_samples()];
    let mut y = x.clone();
    partial.inverse(&c, &mut x).unwrap();
    partial.inverse_with_scratch(&c, &mut y, &mut big).unwrap();
    assert_eq!(bits(&x), bits(&y));
}
