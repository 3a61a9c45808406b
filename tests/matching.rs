//! Rotational matching against the reference data (`tests/data/s2/cor_*`, correlations from
//! the definition with mpmath, SOFT's argmax rule) and exact properties.

mod common;

use num_complex::Complex64;
use so3fft::matching::{grid_argmax, grid_argmax_real, Correlation, CorrelationOptions};

struct Case {
    b: usize,
    real: bool,
    signal: Vec<Complex64>,
    pattern: Vec<Complex64>,
    maxloc: usize,
    angles: [f64; 3],
    peak: f64,
    runner_up: Option<f64>,
}

fn case(name: &str) -> Case {
    let r = common::read_s2_reference(name);
    let b = r.scalars["B"] as usize;
    let n = 2 * b;
    let grid = |section: &str| {
        let mut v = vec![Complex64::default(); n * n];
        for row in &r[section] {
            v[row[0] as usize * n + row[1] as usize] = Complex64::new(row[2], row[3]);
        }
        v
    };
    Case {
        b,
        real: r.scalars["isReal"] != 0.0,
        signal: grid("signal"),
        pattern: grid("pattern"),
        maxloc: r.scalars["maxloc"] as usize,
        angles: [r.scalars["alpha"], r.scalars["beta"], r.scalars["gamma"]],
        peak: r.scalars["peak"],
        runner_up: r.scalars.get("runner_up").copied(),
    }
}

fn correlate(c: &Case, b_out: Option<usize>) -> (so3fft::matching::Peak, usize) {
    let plan = Correlation::new(
        c.b,
        &CorrelationOptions::default()
            .with_real(c.real)
            .with_threads(2)
            .with_b_out(b_out),
    )
    .unwrap();
    let b_out = plan.b_out();
    if c.real {
        let re = |v: &[Complex64]| v.iter().map(|z| z.re).collect::<Vec<f64>>();
        let mut out = vec![0.0; plan.num_grid()];
        plan.correlate_real(&re(&c.signal), &re(&c.pattern), &mut out)
            .unwrap();
        (grid_argmax_real(b_out, &out), b_out)
    } else {
        let mut out = vec![Complex64::default(); plan.num_grid()];
        plan.correlate(&c.signal, &c.pattern, &mut out).unwrap();
        (grid_argmax(b_out, &out), b_out)
    }
}

#[test]
fn rotations_recovered_on_the_grid() {
    for name in [
        "cor_B8_complex.txt",
        "cor_B8_real.txt",
        "cor_B16_complex.txt",
        "cor_B16_real.txt",
    ] {
        let c = case(name);
        let (peak, _) = correlate(&c, None);
        assert_eq!(peak.index, c.maxloc, "{name}");
        assert_eq!([peak.alpha, peak.beta, peak.gamma], c.angles, "{name}");
        assert!(
            (peak.value - c.peak).abs() < 1e-10 * c.peak,
            "{name}: peak {} against {}",
            peak.value,
            c.peak
        );
        assert!(c.runner_up.is_some_and(|r| r < c.peak));
    }
}

/// A finer output grid (B_out = 2 L) contains the rotation of the coarse grid: the peak
/// lands on the same rotation (grid index mapped to the finer grid).
#[test]
fn oversampled_grid_finds_the_same_rotation() {
    for name in ["cor_B8_complex.txt", "cor_B8_real.txt"] {
        let c = case(name);
        let (peak, b_out) = correlate(&c, Some(2 * c.b));
        assert_eq!(b_out, 16);
        let pi = std::f64::consts::PI;
        // alpha and gamma: the same multiples of pi / 8 are on the finer grid.
        assert!(
            (peak.alpha - c.angles[0]).abs() < 1e-12,
            "{name}: alpha {}",
            peak.alpha
        );
        assert!(
            (peak.gamma - c.angles[2]).abs() < 1e-12,
            "{name}: gamma {}",
            peak.gamma
        );
        // beta: the finer grid's nodes are offset; the nearest is within half its step.
        assert!((peak.beta - c.angles[1]).abs() <= pi / (4.0 * b_out as f64) + 1e-12);
    }
}

#[test]
fn ties_and_zero_signals_follow_softs_rule() {
    let c = case("cor_B8_zero_signal.txt");
    let (peak, _) = correlate(&c, None);
    assert_eq!((peak.index, peak.value), (0, 0.0));
    // Axially symmetric signal = pattern: 256 exact ties at k_beta = 0 in exact
    // arithmetic; rounding may pick another of them, but never another beta.
    let c = case("cor_B8_axisymmetric_tie.txt");
    let (peak, _) = correlate(&c, None);
    assert_eq!(peak.index / 256, 0, "beta index of the tie");
    assert!((peak.value - c.peak).abs() < 1e-12 * c.peak);
}

#[test]
fn bad_arguments_are_errors() {
    let opts = |b_out, deg_lim| {
        CorrelationOptions::default()
            .with_b_out(b_out)
            .with_deg_lim(deg_lim)
    };
    assert!(Correlation::<f64>::new(0, &opts(None, None)).is_err());
    assert!(Correlation::<f64>::new(8, &opts(Some(4), Some(4))).is_err());
    assert!(Correlation::<f64>::new(8, &opts(None, Some(8))).is_err());
    let plan = Correlation::new(4, &opts(None, None)).unwrap();
    let s = vec![Complex64::default(); 64];
    let mut out = vec![Complex64::default(); plan.num_grid()];
    assert!(plan.correlate(&s[..63], &s, &mut out).is_err());
    assert!(plan.correlate(&s, &s, &mut out[1..]).is_err());
    assert!(plan
        .correlate_real(&[0.0; 64], &[0.0; 64], &mut [0.0; 512])
        .is_err());
}

use so3fft::matching::{rotate_s2_coeffs, Rotation, So3Series};
use so3fft::s2::{s2_coef_index, S2Plan};
use so3fft::Options;

fn s2_plan(b: usize) -> S2Plan {
    S2Plan::new(b, &Options::default().with_threads(2)).unwrap()
}

/// Rotation of S^2 functions against the reference (`f(g^-1 x)` evaluated directly with
/// mpmath at off-grid angles): coefficients rotated, then synthesised.
#[test]
fn rotation_matches_reference() {
    for name in ["rot_B8_complex.txt", "rot_B8_real.txt"] {
        let r = common::read_s2_reference(name);
        let b = r.scalars["B"] as usize;
        let n = 2 * b;
        let grid = |section: &str| {
            let mut v = vec![Complex64::default(); n * n];
            for row in &r[section] {
                v[row[0] as usize * n + row[1] as usize] = Complex64::new(row[2], row[3]);
            }
            v
        };
        let (input, want) = (grid("input"), grid("output"));
        let g = Rotation::new(r.scalars["alpha"], r.scalars["beta"], r.scalars["gamma"]);
        let p = s2_plan(b);
        let mut coefs = vec![Complex64::default(); b * b];
        p.forward(&input, &mut coefs).unwrap();
        let rotated = rotate_s2_coeffs(b, &coefs, &g).unwrap();
        let mut got = vec![Complex64::default(); n * n];
        p.inverse(&rotated, &mut got).unwrap();
        let scale = want.iter().map(|z| z.norm()).fold(0.0, f64::max);
        let err = got
            .iter()
            .zip(&want)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        assert!(err < 1e-13 * scale, "{name}: error {err:e} (scale {scale})");
    }
}

#[test]
fn rotations_compose_like_quaternions() {
    let g = Rotation::new(0.3, 1.1, -2.0);
    let m = g.matrix();
    // Rz(a) Ry(b) Rz(c) applied to e_z is (cos a sin b, sin a sin b, cos b).
    let col = [m[0][2], m[1][2], m[2][2]];
    let want = [
        0.3f64.cos() * 1.1f64.sin(),
        0.3f64.sin() * 1.1f64.sin(),
        1.1f64.cos(),
    ];
    for (x, y) in col.iter().zip(want) {
        assert!((x - y).abs() < 1e-15);
    }
    assert!(g.angle_to(&g) < 1e-15);
    let h = Rotation::new(0.3 + 1e-9, 1.1, -2.0);
    assert!((g.angle_to(&h) - 1e-9).abs() < 1e-15);
}

/// A random band-limited pattern rotated by a random off-grid rotation: the grid peak is
/// within one grid step of the truth and the refined peak within 1e-8 rad, for real and
/// complex inputs, odd and even bandwidths, and an oversampled grid.
#[test]
fn off_grid_rotations_recovered_and_refined() {
    let mut rng = common::Rng::new(77);
    for (l, b_out, real) in [
        (8usize, None, false),
        (9, None, true),
        (12, Some(16usize), true),
        (16, None, false),
    ] {
        let mut hat = rng.complex_vec(l * l);
        if real {
            for deg in 0..l {
                hat[s2_coef_index(l, deg, 0)].im = 0.0;
                for m in 1..=deg as isize {
                    let c = hat[s2_coef_index(l, deg, m)];
                    hat[s2_coef_index(l, deg, -m)] = if m % 2 == 0 { c.conj() } else { -c.conj() };
                }
            }
        }
        let truth = Rotation::new(
            0.2 + 5.0 * rng.unit(),
            0.3 + 2.5 * rng.unit(),
            0.2 + 5.0 * rng.unit(),
        );
        let rotated = rotate_s2_coeffs(l, &hat, &truth).unwrap();
        let p = s2_plan(l);
        let n = 4 * l * l;
        let (mut sig, mut pat) = (vec![Complex64::default(); n], vec![Complex64::default(); n]);
        p.inverse(&rotated, &mut sig).unwrap();
        p.inverse(&hat, &mut pat).unwrap();
        let plan = Correlation::new(
            l,
            &CorrelationOptions::default()
                .with_real(real)
                .with_b_out(b_out)
                .with_threads(2),
        )
        .unwrap();
        let bo = plan.b_out();
        let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(bo)];
        let peak = if real {
            let re = |v: &[Complex64]| v.iter().map(|z| z.re).collect::<Vec<_>>();
            let mut out = vec![0.0; plan.num_grid()];
            plan.correlate_real(&re(&sig), &re(&pat), &mut out).unwrap();
            plan.coefficients_real(&re(&sig), &re(&pat), &mut coeffs)
                .unwrap();
            grid_argmax_real(bo, &out)
        } else {
            let mut out = vec![Complex64::default(); plan.num_grid()];
            plan.correlate(&sig, &pat, &mut out).unwrap();
            plan.coefficients(&sig, &pat, &mut coeffs).unwrap();
            grid_argmax(bo, &out)
        };
        let step = std::f64::consts::PI / bo as f64;
        let grid_err = peak.rotation().angle_to(&truth);
        assert!(
            grid_err < 1.5 * step,
            "L = {l}: grid peak {grid_err} rad off (step {step})"
        );
        let series = So3Series::new(bo, plan.deg_lim(), &coeffs);
        // The series reproduces the grid value.
        let v = series.value(&peak.rotation());
        assert!((v.norm_sqr() - peak.value).abs() < 1e-9 * peak.value);
        let (refined, value) = series.maximise(&peak.rotation());
        let err = refined.angle_to(&truth);
        assert!(
            err < 1e-8,
            "L = {l} real {real}: refined {err:e} rad off the truth"
        );
        assert!(value >= peak.value);
    }
}

/// Planted maxima on a flat grid come back largest first; one within the separation angle
/// of a larger one is dropped.
#[test]
fn top_peaks_are_separated_local_maxima() {
    use so3fft::matching::top_peaks;
    let b = 4;
    let n = 2 * b;
    let mut grid = vec![Complex64::new(0.1, 0.0); n * n * n];
    let at = |k: usize, a: usize, g: usize| (k * n + a) * n + g;
    grid[at(1, 2, 3)] = Complex64::new(3.0, 0.0);
    grid[at(6, 5, 0)] = Complex64::new(0.0, 2.0);
    grid[at(1, 2, 5)] = Complex64::new(1.0, 0.0); // 2 grid steps in gamma from the first
    let peaks = top_peaks(b, &grid, 5, 0.1);
    assert_eq!(peaks[0].index, at(1, 2, 3));
    assert_eq!(peaks[1].index, at(6, 5, 0));
    assert_eq!(peaks[2].index, at(1, 2, 5));
    assert_eq!((peaks[0].value, peaks[1].value), (9.0, 4.0));
    // The third is pi/2 (gamma) from the first: dropped with a separation of 2 rad.
    let separated = top_peaks(b, &grid, 5, 2.0);
    assert_eq!(separated[0].index, at(1, 2, 3));
    assert!(separated.iter().all(|p| p.index != at(1, 2, 5)));
    for (i, p) in separated.iter().enumerate() {
        for q in &separated[..i] {
            assert!(q.rotation().angle_to(&p.rotation()) >= 2.0);
        }
    }
}

/// The combination of S^2 coefficients against the mpmath reference (`combine_B8_*`), for
/// `bwOut` below, equal to the input bandwidth and degree limits below the top.
#[test]
fn combine_matches_reference() {
    use so3fft::matching::combine;
    for name in [
        "combine_B8_to_B4_deg3.txt",
        "combine_B8_to_B8_deg4.txt",
        "combine_B8_to_B8_deg7.txt",
    ] {
        let r = common::read_s2_reference(name);
        let (b_in, b_out, deg) = (
            r.scalars["bwIn"] as usize,
            r.scalars["bwOut"] as usize,
            r.scalars["degLim"] as usize,
        );
        let coefs = |section: &str, n: usize| {
            let mut v = vec![Complex64::default(); n];
            for row in &r[section] {
                let k = row.len();
                v[row[0] as usize] = Complex64::new(row[k - 2], row[k - 1]);
            }
            v
        };
        let (sig, pat) = (coefs("sig", b_in * b_in), coefs("pat", b_in * b_in));
        let want = coefs("so3coef", so3fft::num_coeffs(b_out));
        let mut got = vec![Complex64::new(9.0, 9.0); so3fft::num_coeffs(b_out)];
        combine((&sig, &pat), b_in, deg, b_out, &mut got).unwrap();
        let scale = want.iter().map(|z| z.norm()).fold(0.0, f64::max);
        let err = got
            .iter()
            .zip(&want)
            .map(|(a, b)| (a - b).norm())
            .fold(0.0, f64::max);
        assert!(err < 1e-14 * scale, "{name}: error {err:e}");
    }
}

fn random_s2_samples(l: usize, seed: u64) -> (Vec<Complex64>, Vec<Complex64>) {
    let mut rng = common::Rng::new(seed);
    let hat = rng.complex_vec(l * l);
    let mut s = vec![Complex64::default(); 4 * l * l];
    s2_plan(l).inverse(&hat, &mut s).unwrap();
    (hat, s)
}

/// Normalised cross-correlation: a rotated copy of the pattern, scaled by 2.5 and shifted
/// by a constant, correlates to 1 at the rotation (refined), and nowhere above 1.
#[test]
fn normalized_correlation_peaks_at_one() {
    let l = 10;
    let (hat, pat) = random_s2_samples(l, 31);
    let truth = Rotation::new(1.1, 0.7, 2.9);
    let mut rotated = rotate_s2_coeffs(l, &hat, &truth).unwrap();
    for c in rotated.iter_mut() {
        *c *= 2.5;
    }
    rotated[s2_coef_index(l, 0, 0)] += Complex64::new(3.0, -1.0);
    let mut sig = vec![Complex64::default(); 4 * l * l];
    s2_plan(l).inverse(&rotated, &mut sig).unwrap();
    let plan = Correlation::new(
        l,
        &CorrelationOptions::default()
            .with_normalized(true)
            .with_threads(2),
    )
    .unwrap();
    let mut grid = vec![Complex64::default(); plan.num_grid()];
    plan.correlate(&sig, &pat, &mut grid).unwrap();
    let top = grid.iter().map(|z| z.norm()).fold(0.0, f64::max);
    assert!(top <= 1.0 + 1e-12 && top > 0.5, "largest |C| {top}");
    let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(l)];
    plan.coefficients(&sig, &pat, &mut coeffs).unwrap();
    let (g, value) =
        So3Series::new(l, plan.deg_lim(), &coeffs).maximise(&grid_argmax(l, &grid).rotation());
    assert!((value - 1.0).abs() < 1e-10, "refined |C|^2 = {value}");
    assert!(g.angle_to(&truth) < 1e-8);
}

/// Shells: the weighted sum of the shells' correlations, from one inverse transform.
#[test]
fn shells_add_up_with_their_weights() {
    let l = 8;
    let (_, s1) = random_s2_samples(l, 1);
    let (_, p1) = random_s2_samples(l, 2);
    let (_, s2) = random_s2_samples(l, 3);
    let (_, p2) = random_s2_samples(l, 4);
    let plan = Correlation::new(l, &CorrelationOptions::default().with_threads(2)).unwrap();
    let n = plan.num_grid();
    let (mut c1, mut c2, mut both) = (
        vec![Complex64::default(); n],
        vec![Complex64::default(); n],
        vec![Complex64::default(); n],
    );
    plan.correlate(&s1, &p1, &mut c1).unwrap();
    plan.correlate(&s2, &p2, &mut c2).unwrap();
    plan.correlate_shells(&[(&s1, &p1, 0.7), (&s2, &p2, -1.3)], &mut both)
        .unwrap();
    let scale = both.iter().map(|z| z.norm()).fold(0.0, f64::max);
    for ((a, b), c) in c1.iter().zip(&c2).zip(&both) {
        assert!((a * 0.7 - b * 1.3 - c).norm() < 1e-12 * scale);
    }
    assert!(plan.correlate_shells(&[], &mut both).is_err());
    assert!(plan
        .correlate_shells(&[(&s1, &p1, f64::NAN)], &mut both)
        .is_err());
}

/// Many patterns against one signal: bitwise the results of single correlations (the
/// signal's transform is reused), complex and real.
#[test]
fn many_patterns_equal_single_correlations() {
    let l = 6;
    let (_, sig) = random_s2_samples(l, 5);
    let pats: Vec<Complex64> = (0..3)
        .flat_map(|k| random_s2_samples(l, 10 + k).1)
        .collect();
    let plan = Correlation::new(l, &CorrelationOptions::default().with_threads(2)).unwrap();
    let (ns, ng) = (4 * l * l, plan.num_grid());
    let mut many = vec![Complex64::default(); 3 * ng];
    plan.correlate_many(&sig, &pats, &mut many).unwrap();
    for k in 0..3 {
        let mut one = vec![Complex64::default(); ng];
        plan.correlate(&sig, &pats[k * ns..][..ns], &mut one)
            .unwrap();
        assert!(one == many[k * ng..][..ng], "pattern {k}");
    }
    let re = |v: &[Complex64]| v.iter().map(|z| z.re).collect::<Vec<f64>>();
    let rplan = Correlation::new(l, &CorrelationOptions::default().with_real(true)).unwrap();
    let mut rmany = vec![0.0; 3 * ng];
    rplan
        .correlate_many_real(&re(&sig), &re(&pats), &mut rmany)
        .unwrap();
    for k in 0..3 {
        let mut one = vec![0.0; ng];
        rplan
            .correlate_real(&re(&sig), &re(&pats[k * ns..][..ns]), &mut one)
            .unwrap();
        assert!(one == rmany[k * ng..][..ng], "real pattern {k}");
    }
    assert!(plan
        .correlate_many(&sig, &pats[..ns - 1], &mut many)
        .is_err());
}

/// The whole correlation grid against its definition, `C(g) = int f(x) conj(h(g^-1 x)) dx`,
/// at small L: f and h summed directly from their coefficients with the explicit `Y_l^m`,
/// `h` at the rotated points `g^-1 x` (rotation matrix), the integral by the exact S^2
/// quadrature of bandwidth 2L (the product has degree < 2L - 1).
#[test]
fn correlation_grid_matches_direct_integration() {
    let l = 4usize;
    let mut rng = common::Rng::new(8);
    let (fhat, hhat) = (rng.complex_vec(l * l), rng.complex_vec(l * l));
    let y = |deg: usize, m: isize, theta: f64, phi: f64| {
        Complex64::from_polar(
            common::dt_explicit(deg, m, 0, theta) / (2.0 * std::f64::consts::PI).sqrt(),
            m as f64 * phi,
        )
    };
    let eval = |hat: &[Complex64], theta: f64, phi: f64| {
        let mut v = Complex64::default();
        for deg in 0..l {
            for m in -(deg as isize)..=deg as isize {
                v += hat[s2_coef_index(l, deg, m)] * y(deg, m, theta, phi);
            }
        }
        v
    };
    // Samples for the plan (grid of bandwidth L).
    let grid_samples = |hat: &[Complex64]| {
        let n = 2 * l;
        let mut s = vec![Complex64::default(); n * n];
        for j in 0..n {
            for k in 0..n {
                let (theta, phi) = (so3fft::beta(l, j), so3fft::alpha(l, k));
                s[j * n + k] = eval(hat, theta, phi);
            }
        }
        s
    };
    let plan = Correlation::new(l, &CorrelationOptions::default()).unwrap();
    let mut grid = vec![Complex64::default(); plan.num_grid()];
    plan.correlate(&grid_samples(&fhat), &grid_samples(&hhat), &mut grid)
        .unwrap();

    let bq = 2 * l; // quadrature bandwidth
    let wq = so3fft::weights(bq);
    let nq = 2 * bq;
    let points: Vec<(f64, [f64; 3], Complex64)> = (0..nq * nq)
        .map(|i| {
            let (j, k) = (i / nq, i % nq);
            let (theta, phi) = (so3fft::beta(bq, j), so3fft::alpha(bq, k));
            let x = [
                theta.sin() * phi.cos(),
                theta.sin() * phi.sin(),
                theta.cos(),
            ];
            let w = wq[j] * std::f64::consts::PI / bq as f64;
            (w, x, eval(&fhat, theta, phi))
        })
        .collect();
    let n = 2 * l;
    let scale = grid.iter().map(|z| z.norm()).fold(0.0, f64::max);
    for (index, got) in grid.iter().enumerate() {
        let peak = so3fft::matching::Peak::at(l, index, 0.0);
        let r = peak.rotation().matrix();
        let mut want = Complex64::default();
        for &(w, x, fx) in &points {
            // g^-1 x = R^T x
            let v = [
                r[0][0] * x[0] + r[1][0] * x[1] + r[2][0] * x[2],
                r[0][1] * x[0] + r[1][1] * x[1] + r[2][1] * x[2],
                r[0][2] * x[0] + r[1][2] * x[1] + r[2][2] * x[2],
            ];
            let theta = v[2].clamp(-1.0, 1.0).acos();
            let phi = v[1].atan2(v[0]);
            want += fx * eval(&hhat, theta, phi).conj() * w;
        }
        assert!(
            (got - want).norm() < 1e-12 * scale,
            "grid point {index} of {}: {got} against {want}",
            n * n * n
        );
    }
}

/// Correlations on a finer grid (`b_out > b_in`) or with a degree limit run on a partial
/// plan: their grids equal the full plan's inverse of the correlation's coefficients.
#[test]
fn padded_and_degree_limited_grids_match_the_full_inverse() {
    use so3fft::Plan;
    for (b_in, b_out, deg_lim, real) in [
        (8, 16, None, false),
        (8, 16, Some(4), true),
        (8, 8, Some(3), false),
        (6, 12, Some(2), true),
    ] {
        let opts = CorrelationOptions::default()
            .with_b_out(Some(b_out))
            .with_deg_lim(deg_lim)
            .with_real(real)
            .with_threads(2);
        let plan = Correlation::new(b_in, &opts).unwrap();
        let n = 4 * b_in * b_in;
        let mut state = 17u64;
        let mut rnd = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        let full = Plan::new(b_out, &Options::default().with_real(real)).unwrap();
        let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(b_out)];
        let mut want = vec![Complex64::default(); plan.num_grid()];
        if real {
            let sig: Vec<f64> = (0..n).map(|_| rnd()).collect();
            let pat: Vec<f64> = (0..n).map(|_| rnd()).collect();
            plan.coefficients_real(&sig, &pat, &mut coeffs).unwrap();
            let mut got = vec![0.0; plan.num_grid()];
            plan.correlate_real(&sig, &pat, &mut got).unwrap();
            full.inverse(&coeffs, &mut want).unwrap();
            let scale = want.iter().map(|z| z.norm()).fold(0.0, f64::max);
            for (g, w) in got.iter().zip(&want) {
                assert!(
                    (g - w.re).abs() < 1e-13 * scale,
                    "{b_in} {b_out} {deg_lim:?}"
                );
            }
        } else {
            let sig: Vec<Complex64> = (0..n).map(|_| Complex64::new(rnd(), rnd())).collect();
            let pat: Vec<Complex64> = (0..n).map(|_| Complex64::new(rnd(), rnd())).collect();
            plan.coefficients(&sig, &pat, &mut coeffs).unwrap();
            let mut got = vec![Complex64::default(); plan.num_grid()];
            plan.correlate(&sig, &pat, &mut got).unwrap();
            full.inverse(&coeffs, &mut want).unwrap();
            let scale = want.iter().map(|z| z.norm()).fold(0.0, f64::max);
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).norm() < 1e-13 * scale, "{b_in} {b_out} {deg_lim:?}");
            }
        }
    }
}

/// Several peaks refined together reach the maxima each reaches alone: the ten largest
/// grid peaks of a random correlation (most of them side maxima, some starting where
/// `|C|^2` is not concave), refined in lock step and one by one.
#[test]
fn peaks_refined_together_reach_the_same_maxima() {
    use so3fft::matching::top_peaks;
    let l = 12;
    let mut rng = common::Rng::new(5);
    let p = s2_plan(l);
    let n = 4 * l * l;
    let (mut sig, mut pat) = (vec![Complex64::default(); n], vec![Complex64::default(); n]);
    p.inverse(&rng.complex_vec(l * l), &mut sig).unwrap();
    p.inverse(&rng.complex_vec(l * l), &mut pat).unwrap();
    let plan = Correlation::new(l, &CorrelationOptions::default().with_threads(2)).unwrap();
    let mut grid = vec![Complex64::default(); plan.num_grid()];
    plan.correlate(&sig, &pat, &mut grid).unwrap();
    let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(l)];
    plan.coefficients(&sig, &pat, &mut coeffs).unwrap();
    let starts: Vec<Rotation> = top_peaks(l, &grid, 10, 0.3)
        .iter()
        .map(|p| p.rotation())
        .collect();
    assert!(starts.len() >= 5);
    let together = plan.refine_many(&coeffs, &starts).unwrap();
    let series = So3Series::new(l, l - 1, &coeffs);
    for (start, (g, value)) in starts.iter().zip(&together) {
        let (alone, alone_value) = plan.refine(&coeffs, start).unwrap();
        assert!(
            g.angle_to(&alone) < 1e-9,
            "from {start:?}: {g:?} together, {alone:?} alone"
        );
        assert!((value - alone_value).abs() <= 1e-12 * value);
        // Angles in their canonical ranges.
        let tau = 2.0 * std::f64::consts::PI;
        assert!((0.0..=std::f64::consts::PI).contains(&g.beta));
        assert!((0.0..tau).contains(&g.alpha) && (0.0..tau).contains(&g.gamma));
        // A maximum: the value there is |C|^2 of the series, and no larger nearby.
        assert!((series.value(g).norm_sqr() - value).abs() <= 1e-12 * value);
        let around: Vec<Rotation> = (0..6)
            .map(|k| {
                let d = if k % 2 == 0 { 1e-4 } else { -1e-4 };
                let mut a = [g.alpha, g.beta, g.gamma];
                a[k / 2] += d;
                Rotation::new(a[0], a[1], a[2])
            })
            .collect();
        for v in series.values(&around) {
            assert!(v.norm_sqr() <= *value, "not a maximum at {g:?}");
        }
    }
    assert!(plan.refine_many(&coeffs, &[]).unwrap().is_empty());
    let nan = Rotation::new(0.0, f64::NAN, 0.0);
    assert!(plan.refine_many(&coeffs, &[nan]).is_err());
}

/// Rotations near the poles of the Euler angles (`beta` near 0 or pi, where only
/// `alpha + gamma` or `alpha - gamma` is defined and the Hessian in the angles is nearly
/// singular) are refined like any other.
#[test]
fn rotations_near_the_poles_refined() {
    let l = 16;
    let mut rng = common::Rng::new(9);
    let hat = rng.complex_vec(l * l);
    let p = s2_plan(l);
    let plan = Correlation::new(l, &CorrelationOptions::default().with_threads(2)).unwrap();
    for beta in [1e-3, 0.02, std::f64::consts::PI - 1e-3, 1e-9] {
        let truth = Rotation::new(1.1, beta, 2.3);
        let n = 4 * l * l;
        let (mut sig, mut pat) = (vec![Complex64::default(); n], vec![Complex64::default(); n]);
        p.inverse(&rotate_s2_coeffs(l, &hat, &truth).unwrap(), &mut sig)
            .unwrap();
        p.inverse(&hat, &mut pat).unwrap();
        let mut grid = vec![Complex64::default(); plan.num_grid()];
        plan.correlate(&sig, &pat, &mut grid).unwrap();
        let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(l)];
        plan.coefficients(&sig, &pat, &mut coeffs).unwrap();
        let (g, _) = plan
            .refine(&coeffs, &grid_argmax(l, &grid).rotation())
            .unwrap();
        let err = g.angle_to(&truth);
        assert!(
            err < 1e-8,
            "beta {beta:e}: refined {err:e} rad off the truth"
        );
    }
}

/// The argmax found while the inverse computes the grid (`correlate_argmax`,
/// `correlate_real_argmax`) is the scan's (`grid_argmax`) exactly, index and value, and
/// the grid is the plain correlation's bit for bit: on the full transform and on a finer
/// grid (both with their slices watched), with one and two threads,
/// including an all-zero grid and exact ties.
#[test]
fn fused_argmax_equals_the_scan() {
    for name in [
        "cor_B8_complex.txt",
        "cor_B8_real.txt",
        "cor_B16_complex.txt",
        "cor_B16_real.txt",
        "cor_B8_zero_signal.txt",
        "cor_B8_axisymmetric_tie.txt",
    ] {
        let c = case(name);
        for (b_out, threads) in [(None, 1), (None, 2), (Some(2 * c.b), 2)] {
            let plan = Correlation::new(
                c.b,
                &CorrelationOptions::default()
                    .with_real(c.real)
                    .with_threads(threads)
                    .with_b_out(b_out),
            )
            .unwrap();
            let b_out = plan.b_out();
            let what = format!("{name} b_out={b_out} threads={threads}");
            let (fused, scanned) = if c.real {
                let re = |v: &[Complex64]| v.iter().map(|z| z.re).collect::<Vec<f64>>();
                let (s, p) = (re(&c.signal), re(&c.pattern));
                let mut plain = vec![0.0; plan.num_grid()];
                plan.correlate_real(&s, &p, &mut plain).unwrap();
                let mut out = vec![f64::NAN; plan.num_grid()];
                let fused = plan.correlate_real_argmax(&s, &p, &mut out).unwrap();
                let same = out
                    .iter()
                    .zip(&plain)
                    .all(|(a, b)| a.to_bits() == b.to_bits());
                assert!(same, "{what}: grid");
                (fused, grid_argmax_real(b_out, &plain))
            } else {
                let mut plain = vec![Complex64::default(); plan.num_grid()];
                plan.correlate(&c.signal, &c.pattern, &mut plain).unwrap();
                let mut out = vec![Complex64::new(f64::NAN, 0.0); plan.num_grid()];
                let fused = plan
                    .correlate_argmax(&c.signal, &c.pattern, &mut out)
                    .unwrap();
                assert!(out == plain, "{what}: grid");
                (fused, grid_argmax(b_out, &plain))
            };
            assert_eq!(fused.index, scanned.index, "{what}");
            assert_eq!(fused.value.to_bits(), scanned.value.to_bits(), "{what}");
            if b_out == c.b && !name.contains("tie") {
                assert_eq!(fused.index, c.maxloc, "{what}: reference");
            }
        }
        // A plan for the other kind of input refuses.
        let plan =
            Correlation::new(c.b, &CorrelationOptions::default().with_real(!c.real)).unwrap();
        let n = plan.num_grid();
        if c.real {
            let s = vec![0.0; 4 * c.b * c.b];
            assert!(plan
                .correlate_real_argmax(&s, &s, &mut vec![0.0; n])
                .is_err());
        } else {
            let mut out = vec![Complex64::default(); n];
            assert!(plan
                .correlate_argmax(&c.signal, &c.pattern, &mut out)
                .is_err());
        }
    }
}
