//! The two ways of threading the FFT stage (Options::fft_threading) and the plan-time
//! choice between them (FftThreading::Auto).
//!
//! Truth is independent of the library: direct summation of the defining formulas
//! (tests/common) at a small bandwidth, round trips (the forward transform inverts the
//! inverse on band-limited data), and agreement between the two variants, which share no
//! FFT plan and split the work differently.

mod common;

use common::*;
use so3fft::{Complex64, FftThreading, Options, Plan, Rigor};

const Z: Complex64 = Complex64::new(0.0, 0.0);

fn make(b: usize, threads: usize, fft: FftThreading, rigor: Rigor, ws: Option<usize>) -> Plan {
    Plan::new(
        b,
        &Options::default()
            .with_threads(threads)
            .with_fft_threading(fft)
            .with_rigor(rigor)
            .with_max_workspace_bytes(ws),
    )
    .expect("Plan::new")
}

/// A chunk cap giving `h` low beta slices per chunk (`2h` slots: with `h` odd the FFT
/// groups do not start on cache lines, which takes the general copy loops).
fn ws_for_chunk(b: usize, h: usize) -> Option<usize> {
    Some(2 * h * (2 * b) * (2 * b) * 16)
}

/// `max |a - b| / max |b|`.
fn rel_diff(a: &[Complex64], b: &[Complex64]) -> f64 {
    max_abs_diff(a, b).0 / max_abs(b)
}

const VARIANTS: [FftThreading; 2] = [FftThreading::SlicesAcrossWorkers, FftThreading::FftwThreads];

#[test]
fn explicit_variants_match_direct_sums() {
    let b = 8;
    let mut rng = Rng::new(5001);
    let coefs = rng.complex_vec(n_coeffs(b));
    let samples = rng.complex_vec(n_samples(b));
    let want_s = direct_inverse(b, &coefs);
    let want_c = direct_forward(b, &samples);
    // Default chunking (one chunk), and 3 slices per chunk (chunks of 3, 3, 2).
    for ws in [None, ws_for_chunk(b, 3)] {
        for v in VARIANTS {
            let p = make(b, 2, v, Rigor::Estimate, ws);
            assert_eq!(p.fft_threading(), v);
            let mut s = vec![Z; n_samples(b)];
            p.inverse(&coefs, &mut s).unwrap();
            let ei = rel_diff(&s, &want_s);
            let mut c = vec![Z; n_coeffs(b)];
            p.forward(&samples, &mut c).unwrap();
            let ef = rel_diff(&c, &want_c);
            println!(
                "B={b} {v:?} ws={ws:?}: inverse vs direct {ei:.2e}, forward vs direct {ef:.2e}"
            );
            assert!(
                ei < 1e-12,
                "{v:?} ws={ws:?}: inverse differs from direct sum by {ei:e}"
            );
            assert!(
                ef < 1e-12,
                "{v:?} ws={ws:?}: forward differs from direct sum by {ef:e}"
            );
        }
    }
}

#[test]
fn explicit_variants_round_trip_and_agree() {
    // Chunks of 5 (10 slots: groups not on cache lines), 6 (a group of 8 and one of 4)
    // and 2 slices (one group of 4).
    for (b, ws) in [
        (32, None),
        (24, ws_for_chunk(24, 5)),
        (20, ws_for_chunk(20, 6)),
        (17, ws_for_chunk(17, 2)),
    ] {
        let coefs = Rng::new(6000 + b as u64).complex_vec(n_coeffs(b));
        let mut out = Vec::new();
        for v in VARIANTS {
            let p = make(b, 2, v, Rigor::Measure, ws);
            assert_eq!(p.fft_threading(), v);
            let mut s = vec![Z; n_samples(b)];
            p.inverse(&coefs, &mut s).unwrap();
            let mut back = vec![Z; n_coeffs(b)];
            p.forward(&s, &mut back).unwrap();
            let e = rel_diff(&back, &coefs);
            println!("B={b} {v:?} ws={ws:?}: round trip {e:.2e}");
            assert!(e < 1e-12, "B={b} {v:?}: round-trip error {e:e}");
            out.push((s, back));
        }
        let es = rel_diff(&out[0].0, &out[1].0);
        let ec = rel_diff(&out[0].1, &out[1].1);
        println!("B={b}: variants differ by {es:.2e} (samples), {ec:.2e} (coefficients)");
        assert!(es < 1e-13, "B={b}: inverse variants differ by {es:e}");
        assert!(ec < 1e-13, "B={b}: forward variants differ by {ec:e}");
    }
}

/// Sample arrays that are 8 but not 16 bytes aligned (valid for `Complex64`) take FFTW's
/// unaligned plans and direct FFT output; results must be those of aligned arrays.
#[test]
fn misaligned_sample_arrays() {
    let b = 12;
    let ns = n_samples(b);
    let coefs = Rng::new(7001).complex_vec(n_coeffs(b));
    let want = direct_inverse(b, &coefs);
    for v in VARIANTS {
        let p = make(b, 2, v, Rigor::Estimate, None);
        let mut raw = vec![0.0f64; 2 * ns + 2];
        let off = if (raw.as_ptr() as usize).is_multiple_of(16) {
            1
        } else {
            0
        };
        // SAFETY: `raw` holds 2 ns + 2 doubles; Complex64 is two f64 (alignment 8).
        let s = unsafe {
            std::slice::from_raw_parts_mut(raw.as_mut_ptr().add(off) as *mut Complex64, ns)
        };
        assert!(!(s.as_ptr() as usize).is_multiple_of(16));
        p.inverse(&coefs, s).unwrap();
        let ei = rel_diff(s, &want);
        let mut back = vec![Z; n_coeffs(b)];
        p.forward(s, &mut back).unwrap();
        let ef = rel_diff(&back, &coefs);
        println!("{v:?}: misaligned samples: inverse vs direct {ei:.2e}, round trip {ef:.2e}");
        assert!(ei < 1e-12 && ef < 1e-12, "{v:?}: {ei:e} {ef:e}");
    }
}

#[test]
fn auto_resolves_to_a_concrete_variant() {
    let b = 32;
    let coefs = Rng::new(8001).complex_vec(n_coeffs(b));
    for rigor in [Rigor::Measure, Rigor::Patient] {
        let p = make(b, 2, FftThreading::Auto, rigor, None);
        let got = p.fft_threading();
        println!("B={b}, 2 threads, {rigor:?}: Auto resolved to {got:?}");
        assert!(VARIANTS.contains(&got), "{rigor:?}: {got:?}");
        // The chosen variant computes correctly.
        let mut s = vec![Z; n_samples(b)];
        p.inverse(&coefs, &mut s).unwrap();
        let mut back = vec![Z; n_coeffs(b)];
        p.forward(&s, &mut back).unwrap();
        let e = rel_diff(&back, &coefs);
        assert!(e < 1e-12, "{rigor:?} ({got:?}): round-trip error {e:e}");
    }
    // One-direction plans are measured on the direction they have.
    for direction in [so3fft::Direction::Forward, so3fft::Direction::Inverse] {
        let p = Plan::new(
            b,
            &Options::default()
                .with_threads(2)
                .with_rigor(Rigor::Measure)
                .with_direction(direction),
        )
        .unwrap();
        assert!(VARIANTS.contains(&p.fft_threading()));
    }
}

#[test]
fn estimate_keeps_slices_across_workers() {
    for b in [8, 32] {
        let p = make(b, 2, FftThreading::Auto, Rigor::Estimate, None);
        assert_eq!(p.fft_threading(), FftThreading::SlicesAcrossWorkers);
    }
}

#[test]
fn one_thread_never_uses_fftw_threads() {
    let b = 16;
    for fft in [
        FftThreading::Auto,
        FftThreading::SlicesAcrossWorkers,
        FftThreading::FftwThreads,
    ] {
        for rigor in [Rigor::Estimate, Rigor::Measure] {
            let p = make(b, 1, fft, rigor, None);
            assert_eq!(
                p.fft_threading(),
                FftThreading::SlicesAcrossWorkers,
                "threads = 1, {fft:?}, {rigor:?}"
            );
        }
    }
}

/// Explicit choices are kept as they are, with or without measuring.
#[test]
fn explicit_choice_is_kept() {
    for v in VARIANTS {
        for rigor in [Rigor::Estimate, Rigor::Measure] {
            assert_eq!(make(16, 2, v, rigor, None).fft_threading(), v);
        }
    }
}
