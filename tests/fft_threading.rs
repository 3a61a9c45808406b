//! The FFT stage's threading (`Options::fft_threading`): every value is accepted and gives
//! the plan that spreads slices across its workers, and the host's FFTW thread setting is
//! left as it was. Also sample arrays that FFTW's aligned plans cannot take.
//!
//! Truth is independent of the library: direct summation of the defining formulas
//! (tests/common) at a small bandwidth, and round trips.

mod common;

use common::*;
use so3fft::{Complex64, FftThreading, Options, Plan, Rigor};

const Z: Complex64 = Complex64::new(0.0, 0.0);

const VARIANTS: [FftThreading; 3] = [
    FftThreading::Auto,
    FftThreading::SlicesAcrossWorkers,
    FftThreading::FftwThreads,
];

fn make(b: usize, fft: FftThreading, rigor: Rigor) -> Plan {
    Plan::new(
        b,
        &Options::default()
            .with_threads(2)
            .with_fft_threading(fft)
            .with_rigor(rigor),
    )
    .expect("Plan::new")
}

/// `max |a - b| / max |b|`.
fn rel_diff(a: &[Complex64], b: &[Complex64]) -> f64 {
    max_abs_diff(a, b).0 / max_abs(b)
}

#[test]
fn every_variant_spreads_slices_and_matches_direct_sums() {
    let b = 8;
    let mut rng = Rng::new(5001);
    let coefs = rng.complex_vec(n_coeffs(b));
    let samples = rng.complex_vec(n_samples(b));
    let want_s = direct_inverse(b, &coefs);
    let want_c = direct_forward(b, &samples);
    for v in VARIANTS {
        for rigor in [Rigor::Estimate, Rigor::Measure] {
            let p = make(b, v, rigor);
            assert_eq!(p.fft_threading(), FftThreading::SlicesAcrossWorkers);
            let mut s = vec![Z; n_samples(b)];
            p.inverse(&coefs, &mut s).unwrap();
            let ei = rel_diff(&s, &want_s);
            let mut c = vec![Z; n_coeffs(b)];
            p.forward(&samples, &mut c).unwrap();
            let ef = rel_diff(&c, &want_c);
            assert!(ei < 1e-12 && ef < 1e-12, "{v:?} {rigor:?}: {ei:e} {ef:e}");
        }
    }
}

/// A host that runs FFTW on its own threads keeps its thread count for new plans: the
/// library sets 1 only while it plans (read back where FFTW can report it, 3.3.9 on).
#[test]
fn host_fftw_thread_count_is_kept() {
    // SAFETY: FFTW's thread initialisation and setting, before any plan of this process
    // is made on another thread of the test (the planner lock is not needed for them by
    // FFTW; the library's own planning holds it).
    unsafe {
        assert_ne!(fftw_sys::fftw_init_threads(), 0);
        fftw_sys::fftw_plan_with_nthreads(3);
    }
    let p = make(12, FftThreading::Auto, Rigor::Measure);
    let coefs = Rng::new(7002).complex_vec(n_coeffs(12));
    let mut s = vec![Z; n_samples(12)];
    p.inverse(&coefs, &mut s).unwrap();
    assert!(rel_diff(&s, &direct_inverse(12, &coefs)) < 1e-12);
    // SAFETY: dlsym with a NUL-terminated name in the loaded objects.
    let sym = unsafe { libc::dlsym(libc::RTLD_DEFAULT, c"fftw_planner_nthreads".as_ptr()) };
    if !sym.is_null() {
        // SAFETY: FFTW's `int fftw_planner_nthreads(void)`.
        let f: unsafe extern "C" fn() -> std::ffi::c_int = unsafe { std::mem::transmute(sym) };
        // SAFETY: reads FFTW's setting only.
        assert_eq!(unsafe { f() }, 3);
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
    let p = make(b, FftThreading::Auto, Rigor::Estimate);
    let mut raw = vec![0.0f64; 2 * ns + 2];
    let off = if (raw.as_ptr() as usize).is_multiple_of(16) {
        1
    } else {
        0
    };
    // SAFETY: `raw` holds 2 ns + 2 doubles; Complex64 is two f64 (alignment 8).
    let s =
        unsafe { std::slice::from_raw_parts_mut(raw.as_mut_ptr().add(off) as *mut Complex64, ns) };
    assert!(!(s.as_ptr() as usize).is_multiple_of(16));
    p.inverse(&coefs, s).unwrap();
    let ei = rel_diff(s, &want);
    let mut back = vec![Z; n_coeffs(b)];
    p.forward(s, &mut back).unwrap();
    let ef = rel_diff(&back, &coefs);
    assert!(ei < 1e-12 && ef < 1e-12, "misaligned: {ei:e} {ef:e}");
}
