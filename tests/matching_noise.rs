//! Matching on noisy data: degree weights, the noise estimate and the uncertainty of a
//! refined peak, against exact properties (a band-limited rotated copy, whose optimum no
//! non-negative weighting moves), the expected noise power of white noise on the grid, and
//! scenes with a known rotation.

mod common;

use num_complex::Complex64;
use so3fft::matching::scene::vmf_scene;
use so3fft::matching::{
    rotate_s2_coeffs, Correlation, CorrelationOptions, DegreeWeights, Rotation,
};
use so3fft::s2::S2Plan;
use so3fft::Options;

fn plan(b: usize, real: bool, weights: DegreeWeights) -> so3fft::Result<Correlation> {
    Correlation::new(
        b,
        &CorrelationOptions::default()
            .with_real(real)
            .with_weights(weights)
            .with_threads(2),
    )
}

/// Samples of random complex coefficients of bandwidth `b`, zero in the top quarter of the
/// degrees (where the noise floor is fitted: a spectrum flat to the last degree would read
/// as noise), and of the same function rotated by `g` (exactly, through the coefficients).
fn rotated_pair(b: usize, g: &Rotation, seed: u64) -> (Vec<Complex64>, Vec<Complex64>) {
    let mut rng = common::Rng::new(seed);
    let mut hat = rng.complex_vec(b * b);
    for l in b - (b / 4).max(4)..b {
        for m in -(l as isize)..=l as isize {
            hat[so3fft::s2::s2_coef_index(b, l, m)] = Complex64::default();
        }
    }
    let s2 = S2Plan::<f64>::new(b, &Options::default()).unwrap();
    let mut pattern = vec![Complex64::default(); 4 * b * b];
    let mut signal = pattern.clone();
    s2.inverse(&hat, &mut pattern).unwrap();
    s2.inverse(&rotate_s2_coeffs(b, &hat, g).unwrap(), &mut signal)
        .unwrap();
    (signal, pattern)
}

/// On a band-limited, exactly rotated copy the refined peak is the rotation with uniform,
/// given and automatic weights alike: `|sum_l w_l <f_l, g h_l>|` is largest at the
/// rotation for any `w_l >= 0` (Cauchy-Schwarz in each degree).
#[test]
fn weights_do_not_move_an_exact_optimum() {
    let b = 12;
    let truth = Rotation::new(0.91, 1.37, 4.02);
    let (signal, pattern) = rotated_pair(b, &truth, 5);
    let band_pass: Vec<f64> = (0..b).map(|l| (l as f64 * 0.4).sin().abs() + 0.1).collect();
    for weights in [
        DegreeWeights::Uniform,
        DegreeWeights::Given(band_pass),
        DegreeWeights::Automatic,
    ] {
        let p = plan(b, false, weights.clone()).unwrap();
        let mut grid = vec![Complex64::default(); p.num_grid()];
        let m = p.find(&signal, &pattern, &mut grid).unwrap();
        let err = m.rotation.angle_to(&truth);
        assert!(err < 1e-8, "{weights:?}: {err:e} rad from the rotation");
        // Noise-free: the uncertainty is at the level of rounding.
        assert!(
            m.uncertainty.sigma < 1e-10,
            "{weights:?}: {:?}",
            m.uncertainty
        );
        assert!(m.peak_ratio > 1.0, "{weights:?}: ratio {}", m.peak_ratio);
    }
}

/// Normalised with weights, `|C| <= 1` everywhere and 1 at the rotation of a scaled,
/// shifted copy (Cauchy-Schwarz with the weighted norms).
#[test]
fn weighted_normalized_correlation_peaks_at_one() {
    let b = 10;
    let truth = Rotation::new(2.2, 0.6, 0.3);
    let (mut signal, pattern) = rotated_pair(b, &truth, 9);
    for x in signal.iter_mut() {
        *x = *x * 1.7 + Complex64::new(0.4, -2.0);
    }
    let w: Vec<f64> = (0..b).map(|l| 1.0 / (1.0 + l as f64)).collect();
    let p = Correlation::new(
        b,
        &CorrelationOptions::default()
            .with_normalized(true)
            .with_weights(DegreeWeights::Given(w))
            .with_threads(2),
    )
    .unwrap();
    let mut grid = vec![Complex64::default(); p.num_grid()];
    let m = p.find(&signal, &pattern, &mut grid).unwrap();
    let top = grid.iter().map(|z| z.norm()).fold(0.0, f64::max);
    assert!(top <= 1.0 + 1e-12, "largest |C| on the grid {top}");
    assert!(
        (m.value.sqrt() - 1.0).abs() < 1e-12,
        "|C| at the peak {}",
        m.value.sqrt()
    );
    assert!(m.rotation.angle_to(&truth) < 1e-8);
}

/// White noise of standard deviation `sigma` at the samples has, averaged over a degree's
/// orders, the power `sigma^2 pi sum_j w(j)^2 / (2B)` per coefficient at every degree
/// (the quadrature `fhat = (pi/B) sum w(j) f conj(Y)` and `sum_m |Y_lm|^2 = (2l+1)/4pi`);
/// the fitted floor finds it.
#[test]
fn noise_floor_of_white_noise() {
    let b = 32;
    let sigma = 0.7;
    let w = common::weights_formula(b);
    let expected = sigma * sigma * std::f64::consts::PI * w.iter().map(|x| x * x).sum::<f64>()
        / (2 * b) as f64;
    let p = plan(b, true, DegreeWeights::Automatic).unwrap();
    let mut rng = common::Rng::new(77);
    let mut normal = || {
        // Box-Muller from the test generator.
        let (u, v) = (1.0 - rng.unit(), rng.unit());
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    };
    let noise: Vec<f64> = (0..4 * b * b).map(|_| sigma * normal()).collect();
    let other: Vec<f64> = (0..4 * b * b).map(|_| sigma * normal()).collect();
    let sp = p.spectra_real(&noise, &other).unwrap();
    for floor in [sp.signal_noise, sp.pattern_noise] {
        assert!(
            (floor / expected - 1.0).abs() < 0.15,
            "floor {floor:e}, expected {expected:e}"
        );
    }
    // Noise alone: no degree stands out of the noise, and weights without signal are
    // uniform by convention.
    assert_eq!(sp.weights, vec![1.0; b]);
    // A smooth scene under the same noise: the low degrees keep their clean power.
    let noisy = vmf_scene(b, 3, 1.0);
    let clean = vmf_scene(b, 3, 0.0);
    let a = p.spectra_real(&noisy.signal, &noisy.pattern).unwrap();
    let c = p.spectra_real(&clean.signal, &clean.pattern).unwrap();
    for l in 0..4 {
        let d = (2 * l + 1) as f64;
        let net = a.signal_power[l] / d - a.signal_noise;
        let want = c.signal_power[l] / d;
        assert!(
            (net / want - 1.0).abs() < 0.25,
            "l {l}: {net:e} vs {want:e}"
        );
    }
    // The high degrees carry noise only: weight 0.
    assert!(
        a.weights[b / 2..].iter().all(|&x| x == 0.0),
        "{:?}",
        a.weights
    );
}

/// On scenes with a known rotation (smooth, not band-limited, noise 1 in both inputs):
/// the automatic weights beat all degrees, and the reported 1-sigma angle covers the
/// error in a calibrated share of the seeds (about 60% for an isotropic Gaussian error).
#[test]
fn automatic_weights_and_coverage_on_noisy_scenes() {
    let b = 32;
    let uniform = plan(b, true, DegreeWeights::Uniform).unwrap();
    let auto = plan(b, true, DegreeWeights::Automatic).unwrap();
    let mut grid = vec![0.0; auto.num_grid()];
    let (mut all, mut weighted, mut covered) = (Vec::new(), Vec::new(), 0);
    let seeds = 20;
    for seed in 0..seeds {
        let s = vmf_scene(b, seed, 1.0);
        let u = uniform.find_real(&s.signal, &s.pattern, &mut grid).unwrap();
        let a = auto.find_real(&s.signal, &s.pattern, &mut grid).unwrap();
        all.push(u.rotation.angle_to(&s.rotation));
        let err = a.rotation.angle_to(&s.rotation);
        weighted.push(err);
        covered += usize::from(err <= a.uncertainty.sigma);
        assert!(a.uncertainty.sigma.is_finite() && a.peak_ratio >= 1.0);
    }
    let median = |v: &mut Vec<f64>| {
        v.sort_by(f64::total_cmp);
        0.5 * (v[v.len() / 2 - 1] + v[v.len() / 2])
    };
    let (ma, mw) = (median(&mut all), median(&mut weighted));
    assert!(
        mw < 0.7 * ma,
        "median error: weighted {mw:e}, all degrees {ma:e}"
    );
    let share = covered as f64 / seeds as f64;
    assert!((0.45..=0.9).contains(&share), "1 sigma covers {share}");
}

/// Weights that cannot weight are refused with the reason.
#[test]
fn bad_weights_are_refused() {
    let b = 8;
    let msg = |w: Vec<f64>| match plan(b, false, DegreeWeights::Given(w)) {
        Err(e) => e.to_string(),
        Ok(_) => panic!("accepted"),
    };
    assert!(msg(vec![1.0; b - 1]).contains("need 8"));
    let mut w = vec![1.0; b];
    w[3] = -1.0;
    assert!(msg(w.clone()).contains("w_3"));
    w[3] = f64::NAN;
    assert!(msg(w).contains("w_3"));
    assert!(msg(vec![0.0; b]).contains("0 everywhere"));
}

/// The uncertainty of a rotation that is not a maximum is unbounded, and bad arguments
/// are errors.
#[test]
fn uncertainty_arguments() {
    let b = 8;
    let truth = Rotation::new(0.5, 1.0, 1.5);
    let (signal, pattern) = rotated_pair(b, &truth, 2);
    let p = plan(b, false, DegreeWeights::Uniform).unwrap();
    let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(b)];
    p.coefficients(&signal, &pattern, &mut coeffs).unwrap();
    let sp = p.spectra(&signal, &pattern).unwrap();
    let far = Rotation::new(0.5 + 1.2, 1.0, 1.5);
    assert!(p
        .uncertainty(&coeffs, &far, &sp)
        .unwrap()
        .sigma
        .is_infinite());
    assert!(p.uncertainty(&coeffs[1..], &truth, &sp).is_err());
    let nan = Rotation::new(f64::NAN, 0.0, 0.0);
    assert!(p.uncertainty(&coeffs, &nan, &sp).is_err());
}

/// Quaternions and Euler angles: `from_quaternion` inverts `quaternion` (as rotations),
/// also at `beta = 0` and `pi`, and `-q` is the same rotation.
#[test]
fn rotation_from_quaternion() {
    for g in [
        Rotation::new(0.3, 1.2, 5.9),
        Rotation::new(4.0, 0.0, 1.0),
        Rotation::new(1.0, std::f64::consts::PI, 2.5),
        Rotation::new(6.0, 3.0, 0.1),
    ] {
        let q = g.quaternion();
        let back = Rotation::from_quaternion(q);
        assert!(back.angle_to(&g) < 1e-15, "{g:?} -> {back:?}");
        let neg = Rotation::from_quaternion(q.map(|x| -x));
        assert!(neg.angle_to(&g) < 1e-15);
        assert!((0.0..=std::f64::consts::PI).contains(&back.beta));
    }
}

/// An `f32` plan with automatic weights finds the `f64` plan's grid peak, and its refined
/// rotation (computed in `f64`) within 1e-8 rad.
#[test]
fn automatic_weights_in_single_precision() {
    let b = 32;
    let s = vmf_scene(b, 11, 0.5);
    let opts = CorrelationOptions::default()
        .with_real(true)
        .with_weights(DegreeWeights::Automatic)
        .with_threads(2);
    let p64 = Correlation::<f64>::new(b, &opts).unwrap();
    let p32 = Correlation::<f32>::new(b, &opts).unwrap();
    let narrow = |v: &[f64]| v.iter().map(|&x| x as f32).collect::<Vec<f32>>();
    let (sig, pat) = (narrow(&s.signal), narrow(&s.pattern));
    let widen = |v: &[f32]| v.iter().map(|&x| x as f64).collect::<Vec<f64>>();
    let mut g64 = vec![0.0; p64.num_grid()];
    let mut g32 = vec![0.0f32; p32.num_grid()];
    let m64 = p64.find_real(&widen(&sig), &widen(&pat), &mut g64).unwrap();
    let m32 = p32.find_real(&sig, &pat, &mut g32).unwrap();
    assert_eq!(m64.grid_peak.index, m32.grid_peak.index);
    assert!(m64.rotation.angle_to(&m32.rotation) < 1e-8);
}
