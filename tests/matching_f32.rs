//! Rotational matching in single precision: the grid peak against the reference data and
//! against the double-precision pipeline, the argmax fused into the inverse against a scan
//! of the grid, and refinement from the f32 peak against the f64 one.

mod common;

use common::narrow;
use num_complex::{Complex32, Complex64};
use so3fft::matching::{
    grid_argmax, grid_argmax_real, rotate_s2_coeffs, top_peaks, Correlation, CorrelationOptions,
    Rotation,
};
use so3fft::s2::{s2_coef_index, S2Plan};
use so3fft::Options;

fn reals(v: &[Complex64]) -> Vec<f32> {
    v.iter().map(|z| z.re as f32).collect()
}

fn options(real: bool) -> CorrelationOptions {
    CorrelationOptions::default()
        .with_real(real)
        .with_threads(2)
}

/// The reference correlations (mpmath, SOFT's argmax rule): the f32 grid has its peak at
/// the same grid point, with the value to single-precision accuracy.
#[test]
fn float_rotations_recovered_on_the_grid() {
    for name in [
        "cor_B8_complex.txt",
        "cor_B8_real.txt",
        "cor_B16_complex.txt",
        "cor_B16_real.txt",
    ] {
        let r = common::read_s2_reference(name);
        let b = r.scalars["B"] as usize;
        let real = r.scalars["isReal"] != 0.0;
        let n = 2 * b;
        let grid = |section: &str| {
            let mut v = vec![Complex64::default(); n * n];
            for row in &r[section] {
                v[row[0] as usize * n + row[1] as usize] = Complex64::new(row[2], row[3]);
            }
            v
        };
        let (signal, pattern) = (grid("signal"), grid("pattern"));
        let plan = Correlation::<f32>::new(b, &options(real)).unwrap();
        let peak = if real {
            let mut out = vec![0.0f32; plan.num_grid()];
            plan.correlate_real(&reals(&signal), &reals(&pattern), &mut out)
                .unwrap();
            let fused = plan
                .correlate_real_argmax(&reals(&signal), &reals(&pattern), &mut out)
                .unwrap();
            let scanned = grid_argmax_real(b, &out);
            assert_eq!(fused, scanned, "{name}: fused argmax against the scan");
            scanned
        } else {
            let mut out = vec![Complex32::default(); plan.num_grid()];
            plan.correlate(&narrow(&signal), &narrow(&pattern), &mut out)
                .unwrap();
            let fused = plan
                .correlate_argmax(&narrow(&signal), &narrow(&pattern), &mut out)
                .unwrap();
            let scanned = grid_argmax(b, &out);
            assert_eq!(fused, scanned, "{name}: fused argmax against the scan");
            scanned
        };
        assert_eq!(peak.index, r.scalars["maxloc"] as usize, "{name}");
        let want = r.scalars["peak"];
        assert!(
            (peak.value - want).abs() < 1e-5 * want,
            "{name}: peak {} against {want}",
            peak.value
        );
    }
}

/// A random band-limited pattern rotated off the grid: the f32 pipeline finds the grid
/// point of the f64 pipeline (or, within f32 rounding, a point of the same value), its
/// top peaks are those of f64, and refinement from the f32 peak gives the f64 refinement.
#[test]
fn float_pipeline_against_double() {
    let mut rng = common::Rng::new(99);
    for (l, real) in [(16usize, false), (24, true), (64, false), (64, true)] {
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
        let p = S2Plan::<f64>::new(l, &Options::default().with_threads(2)).unwrap();
        let n = 4 * l * l;
        let (mut sig, mut pat) = (vec![Complex64::default(); n], vec![Complex64::default(); n]);
        p.inverse(&rotated, &mut sig).unwrap();
        p.inverse(&hat, &mut pat).unwrap();
        // The f32 samples, and the f64 pipeline on exactly the same values.
        let (sig32, pat32) = (narrow(&sig), narrow(&pat));
        let widen = |v: &[Complex32]| -> Vec<Complex64> {
            v.iter()
                .map(|z| Complex64::new(z.re as f64, z.im as f64))
                .collect()
        };
        let (sig, pat) = (widen(&sig32), widen(&pat32));
        let p64 = Correlation::<f64>::new(l, &options(real)).unwrap();
        let p32 = Correlation::<f32>::new(l, &options(real)).unwrap();
        let nc = so3fft::num_coeffs(l);
        let (mut c64, mut c32) = (
            vec![Complex64::default(); nc],
            vec![Complex64::default(); nc],
        );
        let (peak64, peak32, tops) = if real {
            let (r64, r32) = (
                sig.iter().map(|z| z.re).collect::<Vec<f64>>(),
                sig32.iter().map(|z| z.re).collect::<Vec<f32>>(),
            );
            let (q64, q32) = (
                pat.iter().map(|z| z.re).collect::<Vec<f64>>(),
                pat32.iter().map(|z| z.re).collect::<Vec<f32>>(),
            );
            let mut g64 = vec![0.0f64; p64.num_grid()];
            let mut g32 = vec![0.0f32; p32.num_grid()];
            let a = p64.correlate_real_argmax(&r64, &q64, &mut g64).unwrap();
            let b = p32.correlate_real_argmax(&r32, &q32, &mut g32).unwrap();
            p64.coefficients_real(&r64, &q64, &mut c64).unwrap();
            p32.coefficients_real(&r32, &q32, &mut c32).unwrap();
            let tops = (
                so3fft::matching::top_peaks_real(l, &g64, 4, 0.3),
                so3fft::matching::top_peaks_real(l, &g32, 4, 0.3),
            );
            (a, b, tops)
        } else {
            let mut g64 = vec![Complex64::default(); p64.num_grid()];
            let mut g32 = vec![Complex32::default(); p32.num_grid()];
            let a = p64.correlate_argmax(&sig, &pat, &mut g64).unwrap();
            let b = p32.correlate_argmax(&sig32, &pat32, &mut g32).unwrap();
            p64.coefficients(&sig, &pat, &mut c64).unwrap();
            p32.coefficients(&sig32, &pat32, &mut c32).unwrap();
            let tops = (top_peaks(l, &g64, 4, 0.3), top_peaks(l, &g32, 4, 0.3));
            (a, b, tops)
        };
        let what = format!("L = {l} real {real}");
        if peak32.index != peak64.index {
            // Only a tie within f32 rounding may move the peak.
            assert!(
                (peak32.value - peak64.value).abs() < 1e-5 * peak64.value,
                "{what}: f32 peak {peak32:?} against f64 {peak64:?}"
            );
        }
        assert!(
            (peak32.value - peak64.value).abs() < 1e-5 * peak64.value,
            "{what}"
        );
        let (t64, t32) = tops;
        assert_eq!(t64.len(), t32.len(), "{what}");
        for (a, b) in t64.iter().zip(&t32) {
            assert!(
                a.index == b.index || (a.value - b.value).abs() < 1e-5 * a.value,
                "{what}"
            );
        }
        // Coefficients in f64 from the same samples: the same refinement.
        assert_eq!(c32, c64, "{what}: coefficients");
        let (r64, _) = p64.refine(&c64, &peak64.rotation()).unwrap();
        let (r32, _) = p32.refine(&c32, &peak32.rotation()).unwrap();
        let d = r32.angle_to(&r64);
        assert!(d < 1e-8, "{what}: refined rotations {d:e} rad apart");
        assert!(
            r32.angle_to(&truth) < 1e-6,
            "{what}: refined {:e} from the truth",
            r32.angle_to(&truth)
        );
    }
}

/// Shells and many patterns in f32 against single correlations.
#[test]
fn float_shells_and_many() {
    let l = 12;
    let mut rng = common::Rng::new(5);
    let n = 4 * l * l;
    let fields: Vec<Vec<Complex32>> = (0..4).map(|_| narrow(&rng.complex_vec(n))).collect();
    let plan = Correlation::<f32>::new(l, &options(false)).unwrap();
    let ng = plan.num_grid();
    let mut many = vec![Complex32::default(); 3 * ng];
    let patterns: Vec<Complex32> = fields[1..].concat();
    plan.correlate_many(&fields[0], &patterns, &mut many)
        .unwrap();
    for (k, pat) in fields[1..].iter().enumerate() {
        let mut one = vec![Complex32::default(); ng];
        plan.correlate(&fields[0], pat, &mut one).unwrap();
        assert_eq!(one, many[k * ng..][..ng], "pattern {k}");
    }
    let mut sum = vec![Complex32::default(); ng];
    plan.correlate_shells(
        &[
            (&fields[0], &fields[1], 2.0),
            (&fields[2], &fields[3], -0.5),
        ],
        &mut sum,
    )
    .unwrap();
    let (mut a, mut b) = (
        vec![Complex32::default(); ng],
        vec![Complex32::default(); ng],
    );
    plan.correlate(&fields[0], &fields[1], &mut a).unwrap();
    plan.correlate(&fields[2], &fields[3], &mut b).unwrap();
    let scale = a.iter().map(|z| z.norm()).fold(0.0f32, f32::max);
    for i in 0..ng {
        let want = a[i] * 2.0 - b[i] * 0.5;
        assert!((sum[i] - want).norm() < 1e-5 * scale, "grid point {i}");
    }
}
