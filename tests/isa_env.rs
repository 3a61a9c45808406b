//! `SO3FFT_ISA`: the instruction set of plans whose options name none. One test in its own
//! binary (its own process), since it sets the environment variable.

use so3fft::{Complex64, Error, Isa, Options, Plan, ISA_VARIABLE};

/// The inverse of a plan made with `isa`, and the instruction set the plan took.
fn inverse(
    b: usize,
    isa: Option<Isa>,
    coeffs: &[Complex64],
) -> so3fft::Result<(Vec<Complex64>, Isa)> {
    let plan = Plan::new(b, &Options::default().with_isa(isa).with_threads(1))?;
    let mut out = vec![Complex64::default(); plan.num_samples()];
    plan.inverse(coeffs, &mut out)?;
    Ok((out, plan.isa()))
}

#[test]
fn isa_variable_selects_the_kernels() {
    let b = 12;
    let coeffs: Vec<Complex64> = (0..so3fft::num_coeffs(b))
        .map(|i| Complex64::new((i as f64 * 0.61).sin(), (i as f64 * 0.29).cos()))
        .collect();
    std::env::remove_var(ISA_VARIABLE);
    assert_eq!(Isa::selected().unwrap(), Isa::detect());
    let (want, _) = inverse(b, None, &coeffs).unwrap();
    for name in ["avx512", "AVX2", " scalar "] {
        std::env::set_var(ISA_VARIABLE, name);
        let isa = match name.trim().to_ascii_lowercase().as_str() {
            "avx512" => Isa::Avx512,
            "avx2" => Isa::Avx2,
            _ => Isa::Scalar,
        };
        if !isa.is_supported() {
            // A set this CPU lacks: planning refuses, naming the variable.
            let err = Plan::<f64>::new(b, &Options::default()).err().unwrap();
            assert!(matches!(&err, Error::InvalidArgument(m) if m.contains(ISA_VARIABLE)));
            continue;
        }
        assert_eq!(Isa::selected().unwrap(), isa, "{name}");
        // The kernels of that set: the same transform to rounding.
        let (got, taken) = inverse(b, None, &coeffs).unwrap();
        assert_eq!(taken, isa, "{name}: the plan's kernels");
        let scale = want.iter().map(|z| z.norm()).fold(0.0, f64::max);
        // Every value within rounding (a NaN fails the comparison).
        let close = got
            .iter()
            .zip(&want)
            .all(|(a, b)| (a - b).norm() < 1e-13 * scale);
        assert!(close, "{name}: not the transform to rounding");
        // An explicit option wins over the variable.
        let (explicit, taken) = inverse(b, Some(Isa::detect()), &coeffs).unwrap();
        assert_eq!(taken, Isa::detect(), "{name}: explicit option");
        assert!(explicit == want, "{name}: explicit option");
    }
    // Not an instruction set: an error, not a guess.
    std::env::set_var(ISA_VARIABLE, "sse9");
    assert!(matches!(Isa::selected(), Err(Error::InvalidArgument(_))));
    let err = Plan::<f64>::new(b, &Options::default()).err().unwrap();
    assert!(matches!(&err, Error::InvalidArgument(m) if m.contains("sse9")));
    // Empty: as if unset.
    std::env::set_var(ISA_VARIABLE, "");
    assert_eq!(Isa::selected().unwrap(), Isa::detect());
    std::env::remove_var(ISA_VARIABLE);
}
