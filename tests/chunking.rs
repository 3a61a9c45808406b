//! Chunked transforms (several chunks, a partial last chunk with padding lanes) and every
//! instruction set against direct summation, for the complex and the real-signal paths. (The direct sums use explicit factorial formulas, good to
//! about 1e-14 relative up to B = 13 or so; at B = 20 their own error is 1e-12.)

mod common;

use common::*;
use so3fft::{Complex64, Isa, Options, Plan};

/// Doubles per beta of the complex lane rows, unpadded (see `Plan::workspace_bytes`).
fn lane_doubles(b: usize) -> usize {
    8 * b * b - 8 * b + 8
}

/// Plan options whose chunk buffer holds chunks of `h` low betas (a multiple of 8; smaller
/// caps give 8).
fn opts(b: usize, h: usize, isa: Isa, real: bool) -> Options {
    Options::default()
        .with_max_workspace_bytes(Some(2 * h.next_multiple_of(8) * lane_doubles(b) * 8))
        .with_isa(Some(isa))
        .with_real(real)
}

fn isas() -> Vec<Isa> {
    [Isa::Avx512, Isa::Avx2, Isa::Scalar]
        .into_iter()
        .filter(|i| i.is_supported())
        .collect()
}

#[test]
fn chunks_and_isas_match_direct_sums() {
    for b in [12usize, 13] {
        let mut rng = Rng::new(4242 + b as u64);
        let coefs = rng.complex_vec(n_coeffs(b));
        let want_f = direct_inverse(b, &coefs);
        let samples = rng.complex_vec(n_samples(b));
        let want_c = direct_forward(b, &samples);
        let scale_f = max_abs(&want_f);
        let scale_c = max_abs(&want_c);
        for h in [8usize, 16] {
            for isa in isas() {
                let plan = Plan::new(b, &opts(b, h, isa, false)).unwrap();
                assert!(plan.workspace_bytes() <= 2 * 16 * lane_doubles(b) * 8 * h.div_ceil(8));
                let mut f = vec![Complex64::new(0.0, 0.0); n_samples(b)];
                plan.inverse(&coefs, &mut f).unwrap();
                let (ei, _) = max_abs_diff(&f, &want_f);
                let mut c = vec![Complex64::new(0.0, 0.0); n_coeffs(b)];
                plan.forward(&samples, &mut c).unwrap();
                let (ef, _) = max_abs_diff(&c, &want_c);
                assert!(
                    ei <= 5e-13 * scale_f && ef <= 5e-13 * scale_c,
                    "B={b} h={h} {isa:?}: inverse {ei:.2e}, forward {ef:.2e}"
                );
            }
        }
    }
}

/// The real path with chunks of its own (about twice the betas of the complex ones in the
/// same buffer): the inverse against the direct sum, and the forward of those samples back.
#[test]
fn real_chunks_match_direct_sums() {
    for b in [12usize, 13] {
        let mut rng = Rng::new(99 + b as u64);
        let coefs = random_real_signal_coefs(b, &mut rng);
        let want = direct_inverse(b, &coefs);
        let scale = max_abs(&want);
        for h in [8usize, 16] {
            for isa in isas() {
                let plan = Plan::new(b, &opts(b, h, isa, true)).unwrap();
                let mut f = vec![0.0; n_samples(b)];
                plan.inverse_real(&coefs, &mut f).unwrap();
                let ei = f
                    .iter()
                    .zip(&want)
                    .fold(0.0f64, |e, (x, z)| e.max((x - z.re).abs().max(z.im.abs())));
                let mut c = vec![Complex64::new(0.0, 0.0); n_coeffs(b)];
                plan.forward_real(&f, &mut c).unwrap();
                let (er, _) = max_abs_diff(&c, &coefs);
                assert!(
                    ei <= 1e-13 * scale && er <= 1e-13,
                    "B={b} h={h} {isa:?}: real inverse {ei:.2e}, round trip {er:.2e}"
                );
            }
        }
    }
}

/// Round trips (inverse then forward) with 8-beta chunks at B = 64 on every instruction
/// set, complex and real: the coefficients must come back. With `destroy` the forwards
/// may overwrite their samples (`forward_destroying_input`, `forward_real_destroying_input`).
fn round_trips_with_small_chunks(seed: u64, destroy: bool) {
    let b = 64;
    let mut rng = Rng::new(seed);
    let coefs = rng.complex_vec(n_coeffs(b));
    let real_coefs = random_real_signal_coefs(b, &mut rng);
    for isa in isas() {
        let plan = Plan::new(b, &opts(b, 8, isa, false)).unwrap();
        let mut f = vec![Complex64::new(0.0, 0.0); n_samples(b)];
        plan.inverse(&coefs, &mut f).unwrap();
        let mut c = vec![Complex64::new(f64::NAN, 0.0); n_coeffs(b)];
        if destroy {
            plan.forward_destroying_input(&mut f, &mut c).unwrap();
        } else {
            plan.forward(&f, &mut c).unwrap();
        }
        let (e, _) = max_abs_diff(&c, &coefs);
        assert!(e <= 1e-12, "B={b} {isa:?}: complex round trip {e:.2e}");

        let plan = Plan::new(b, &opts(b, 8, isa, true)).unwrap();
        let mut f = vec![0.0; n_samples(b)];
        plan.inverse_real(&real_coefs, &mut f).unwrap();
        let mut c = vec![Complex64::new(f64::NAN, 0.0); n_coeffs(b)];
        if destroy {
            plan.forward_real_destroying_input(&mut f, &mut c).unwrap();
        } else {
            plan.forward_real(&f, &mut c).unwrap();
        }
        let (e, _) = max_abs_diff(&c, &real_coefs);
        assert!(e <= 1e-12, "B={b} {isa:?}: real round trip {e:.2e}");
    }
}

/// Many chunks at a bandwidth where the chunks near the poles need no degrees at all of
/// most clusters, and few of the others: the forward adds and the inverse reads only the
/// degrees some beta of the chunk needs.
#[test]
fn chunks_near_the_poles_round_trip() {
    round_trips_with_small_chunks(640, false);
}

/// The forward that may overwrite its input gives the forward's coefficients.
#[test]
fn forward_destroying_input_round_trips() {
    round_trips_with_small_chunks(641, true);
}
