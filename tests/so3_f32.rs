//! SO(3) transforms in single precision: against the reference data (`tests/data/`), against
//! the double-precision plans on the same data (full and partial shapes, real signals,
//! selected betas, batches, every instruction set), and round trips.

mod common;

use common::{narrow, parse_transform, random_real_signal_coefs, relative_l2, widen, Rng};
use num_complex::{Complex32, Complex64};
use so3fft::{Batch, Betas, Isa, Options, PartialPlan, Plan, Shape};

fn relative_l2_real(a: &[f32], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let num: f64 = a.iter().zip(b).map(|(&x, y)| (x as f64 - y).powi(2)).sum();
    let den: f64 = b.iter().map(|y| y * y).sum();
    (num / den).sqrt()
}

fn options(isa: Option<Isa>) -> Options {
    let mut o = Options::default().with_threads(2);
    o.isa = isa;
    o
}

/// The instruction sets this machine runs (the plans of the others are refused).
fn isas() -> Vec<Isa> {
    [Isa::Avx512, Isa::Avx2, Isa::Scalar]
        .into_iter()
        .filter(|&i| Plan::<f32>::new(2, &options(Some(i))).is_ok())
        .collect()
}

/// The reference transforms (mpmath) at B = 4 (complex) and B = 8 (real signal), to
/// single-precision accuracy.
#[test]
fn float_transforms_match_reference() {
    for name in ["transform_B4_complex.txt", "transform_B8_real.txt"] {
        let r = parse_transform(name);
        let b = r.b;
        let mut coefs = vec![Complex64::default(); so3fft::num_coeffs(b)];
        for &(l, m, mp, v) in &r.coefs {
            coefs[so3fft::coef_index(b, l, m, mp)] = v;
        }
        let mut samples = vec![Complex64::default(); so3fft::num_samples(b)];
        for &(k, j1, j2, v) in &r.samples {
            samples[so3fft::sample_index(b, j1, k, j2)] = v;
        }
        let plan = Plan::<f32>::new(b, &options(None)).unwrap();
        let mut got = vec![Complex32::default(); plan.num_coeffs()];
        plan.forward(&narrow(&samples), &mut got).unwrap();
        let e = relative_l2(&widen(&got), &coefs);
        assert!(e < 2e-6, "{name}: forward against the reference {e:e}");
        let mut back = vec![Complex32::default(); plan.num_samples()];
        plan.inverse(&narrow(&coefs), &mut back).unwrap();
        let e = relative_l2(&widen(&back), &samples);
        assert!(e < 2e-6, "{name}: inverse against the reference {e:e}");
    }
}

/// Complex and real transforms in f32 against f64 on the same data, and the f32 round
/// trip, on every instruction set and at odd, even and vector-crossing bandwidths.
#[test]
fn float_against_double_every_isa() {
    for isa in isas() {
        for b in [1, 5, 16, 33, 64] {
            println!("{isa:?} B={b}");
            let o = options(Some(isa)).with_real(true);
            let p32 = Plan::<f32>::new(b, &o).unwrap();
            let p64 = Plan::<f64>::new(b, &o).unwrap();
            let c = Rng::new(b as u64).complex_vec(p64.num_coeffs());
            let mut s64 = vec![Complex64::default(); p64.num_samples()];
            p64.inverse(&c, &mut s64).unwrap();
            let mut s32 = vec![Complex32::default(); p32.num_samples()];
            p32.inverse(&narrow(&c), &mut s32).unwrap();
            let e = relative_l2(&widen(&s32), &s64);
            assert!(e < 5e-6, "{isa:?} B={b}: inverse {e:e}");
            let mut c32 = vec![Complex32::default(); p32.num_coeffs()];
            p32.forward(&narrow(&s64), &mut c32).unwrap();
            let e = relative_l2(&widen(&c32), &c);
            assert!(e < 5e-6, "{isa:?} B={b}: forward {e:e}");
            p32.forward(&s32, &mut c32).unwrap();
            let e = relative_l2(&widen(&c32), &c);
            assert!(e < 1e-5, "{isa:?} B={b}: round trip {e:e}");

            // Real signals.
            let c = random_real_signal_coefs(b, &mut Rng::new(7 + b as u64));
            let mut r64 = vec![0.0f64; p64.num_samples()];
            p64.inverse_real(&c, &mut r64).unwrap();
            let mut r32 = vec![0.0f32; p32.num_samples()];
            p32.inverse_real(&narrow(&c), &mut r32).unwrap();
            let e = relative_l2_real(&r32, &r64);
            assert!(e < 5e-6, "{isa:?} B={b}: real inverse {e:e}");
            p32.forward_real(&r32, &mut c32).unwrap();
            let e = relative_l2(&widen(&c32), &c);
            assert!(e < 1e-5, "{isa:?} B={b}: real round trip {e:e}");
        }
    }
}

/// The round trip of random coefficients in f32, complex and real, relative L2 error.
fn round_trip(b: usize, real: bool) -> f64 {
    let plan = Plan::<f32>::new(b, &options(None).with_real(real)).unwrap();
    let mut rng = Rng::new(b as u64 + 100);
    let c = narrow(&if real {
        random_real_signal_coefs(b, &mut rng)
    } else {
        rng.complex_vec(plan.num_coeffs())
    });
    let mut back = vec![Complex32::default(); plan.num_coeffs()];
    if real {
        let mut s = vec![0.0f32; plan.num_samples()];
        plan.inverse_real(&c, &mut s).unwrap();
        plan.forward_real(&s, &mut back).unwrap();
    } else {
        let mut s = vec![Complex32::default(); plan.num_samples()];
        plan.inverse(&c, &mut s).unwrap();
        plan.forward(&s, &mut back).unwrap();
    }
    let e = relative_l2(&widen(&back), &widen(&c));
    println!("B={b} real={real}: f32 round trip {e:.2e}");
    e
}

#[test]
fn float_round_trip_b128() {
    for real in [false, true] {
        assert!(round_trip(128, real) < 1e-5);
    }
}

/// The larger bandwidths of the target (`1e-5` up to B = 512); minutes and gigabytes.
#[test]
#[ignore]
fn float_round_trip_large() {
    for b in [256, 512] {
        for real in [false, true] {
            assert!(round_trip(b, real) < 1e-5);
        }
    }
}

/// Signals of the low orders only, where the f32 recurrence is weakest and the plan runs
/// the f64 kernels: their own relative error stays at single-precision rounding, at both
/// sides of the rule's bandwidth steps.
#[test]
fn float_low_orders() {
    for b in [64, 160] {
        let p32 = Plan::<f32>::new(b, &options(None)).unwrap();
        let p64 = Plan::<f64>::new(b, &options(None)).unwrap();
        let mut rng = Rng::new(5);
        let mut c = vec![Complex64::default(); p64.num_coeffs()];
        for l in 0..b {
            for m in -1isize..=1 {
                for mp in -(l.min(6) as isize)..=l.min(6) as isize {
                    if m.unsigned_abs() <= l {
                        c[so3fft::coef_index(b, l, m, mp)] = rng.complex();
                    }
                }
            }
        }
        let mut s64 = vec![Complex64::default(); p64.num_samples()];
        p64.inverse(&c, &mut s64).unwrap();
        let mut s32 = vec![Complex32::default(); p32.num_samples()];
        p32.inverse(&narrow(&c), &mut s32).unwrap();
        let e = relative_l2(&widen(&s32), &s64);
        assert!(e < 2e-6, "B={b}: low-order inverse {e:e}");
        let mut back = vec![Complex32::default(); p32.num_coeffs()];
        p32.forward(&s32, &mut back).unwrap();
        let e = relative_l2(&widen(&back), &c);
        assert!(e < 3e-6, "B={b}: low-order round trip {e:e}");
    }
}

/// Partial shapes (degree and order limits, other grids, a lower degree limit) in f32
/// against the same shapes in f64.
#[test]
fn float_partial_shapes() {
    let b = 24;
    let shapes = [
        Shape::new(b).with_orders(4, 2).with_grid(b, 2 * b, 2 * b),
        Shape::new(b).with_orders(1, 7).with_grid(b, 2 * b, 2 * b),
        Shape::new(b).with_degree_min(5),
        Shape::new(b).with_orders(11, 3).with_degree_min(4),
        Shape::new(b).with_grid(b + 3, 2 * b + 1, 2 * b + 3),
    ];
    for isa in isas() {
        for s in &shapes {
            let o = options(Some(isa));
            let p32 = PartialPlan::<f32>::new(s, &o).unwrap();
            let p64 = PartialPlan::<f64>::new(s, &o).unwrap();
            let c = Rng::new(3).complex_vec(s.num_coeffs());
            let mut x64 = vec![Complex64::default(); p64.num_samples()];
            p64.inverse(&c, &mut x64).unwrap();
            let mut x32 = vec![Complex32::default(); p32.num_samples()];
            p32.inverse(&narrow(&c), &mut x32).unwrap();
            let e = relative_l2(&widen(&x32), &x64);
            assert!(e < 5e-6, "{isa:?} {s:?}: inverse {e:e}");
            let mut back = vec![Complex32::default(); p32.num_coeffs()];
            p32.forward(&x32, &mut back).unwrap();
            let e = relative_l2(&widen(&back), &c);
            assert!(e < 1e-5, "{isa:?} {s:?}: round trip {e:e}");
        }
    }
}

/// Selected betas (with and without their mirrors: split chunks) in f32 against f64.
#[test]
fn float_selected_betas() {
    let s = Shape::new(20).with_orders(9, 6).with_grid(22, 24, 20);
    let c = Rng::new(13).complex_vec(s.num_coeffs());
    let selections = [
        Betas::Indices(vec![23, 0, 5, 18, 6, 11, 12]),
        Betas::Indices((0..20).collect()),
        Betas::Indices((24..44).collect()),
        Betas::Values(vec![0.0, 0.3, std::f64::consts::FRAC_PI_2, 2.9, 1.0]),
    ];
    for isa in isas() {
        for sel in &selections {
            let o = options(Some(isa)).with_betas(sel.clone());
            let p32 = PartialPlan::<f32>::new(&s, &o).unwrap();
            let p64 = PartialPlan::<f64>::new(&s, &o).unwrap();
            let mut y64 = vec![Complex64::default(); p64.num_samples()];
            p64.inverse(&c, &mut y64).unwrap();
            let mut y32 = vec![Complex32::default(); p32.num_samples()];
            p32.inverse(&narrow(&c), &mut y32).unwrap();
            let e = relative_l2(&widen(&y32), &y64);
            assert!(e < 5e-6, "{isa:?} {sel:?}: {e:e}");
        }
    }
}

/// Batches in f32 equal single calls bit for bit (forward and inverse, complex and real),
/// with a workspace cap that makes several chunks and groups.
#[test]
fn float_batches_equal_single_calls() {
    let b = 20;
    let s = Shape::new(b);
    for cap in [None, Some(64 << 10)] {
        let mut o = options(None).with_real(true);
        o.max_workspace_bytes = cap;
        let p = PartialPlan::<f32>::new(&s, &o).unwrap();
        let (nc, ns, count) = (p.num_coeffs(), p.num_samples(), 3);
        let mut rng = Rng::new(21);
        let c = narrow(&rng.complex_vec(nc * count));
        let batch = |i, o| Batch {
            count,
            in_dist: i,
            out_dist: o,
        };
        let mut many = vec![Complex32::default(); ns * count];
        p.inverse_many(batch(nc, ns), &c, &mut many).unwrap();
        let mut back_many = vec![Complex32::default(); nc * count];
        p.forward_many(batch(ns, nc), &many, &mut back_many)
            .unwrap();
        for t in 0..count {
            let mut one = vec![Complex32::default(); ns];
            p.inverse(&c[t * nc..][..nc], &mut one).unwrap();
            assert!(
                same_bits(&one, &many[t * ns..][..ns]),
                "cap {cap:?}: inverse {t}"
            );
            let mut back = vec![Complex32::default(); nc];
            p.forward(&one, &mut back).unwrap();
            assert!(
                same_bits(&back, &back_many[t * nc..][..nc]),
                "cap {cap:?}: forward {t}"
            );
        }
        // Real signals.
        let reals: Vec<f32> = (0..ns * count).map(|_| rng.sym() as f32).collect();
        let mut c_many = vec![Complex32::default(); nc * count];
        p.forward_real_many(batch(ns, nc), &reals, &mut c_many)
            .unwrap();
        let mut r_many = vec![0.0f32; ns * count];
        p.inverse_real_many(batch(nc, ns), &c_many, &mut r_many)
            .unwrap();
        for t in 0..count {
            let mut one = vec![Complex32::default(); nc];
            p.forward_real(&reals[t * ns..][..ns], &mut one).unwrap();
            assert!(
                same_bits(&one, &c_many[t * nc..][..nc]),
                "cap {cap:?}: real forward {t}"
            );
            let mut r = vec![0.0f32; ns];
            p.inverse_real(&one, &mut r).unwrap();
            let same = r
                .iter()
                .zip(&r_many[t * ns..])
                .all(|(x, y)| x.to_bits() == y.to_bits());
            assert!(same, "cap {cap:?}: real inverse {t}");
        }
    }
}

fn same_bits(a: &[Complex32], b: &[Complex32]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.re.to_bits() == y.re.to_bits() && x.im.to_bits() == y.im.to_bits())
}

/// Bad arguments give the same errors as in f64, and the f32 plan holds less memory than
/// the f64 one and says so before it is made.
#[test]
fn float_errors_and_memory() {
    let b = 16;
    let o = options(None);
    let p32 = Plan::<f32>::new(b, &o).unwrap();
    let p64 = Plan::<f64>::new(b, &o).unwrap();
    let mut s32 = vec![Complex32::default(); p32.num_samples() - 1];
    let mut s64 = vec![Complex64::default(); p64.num_samples() - 1];
    let c32 = vec![Complex32::default(); p32.num_coeffs()];
    let c64 = vec![Complex64::default(); p64.num_coeffs()];
    let e32 = p32.inverse(&c32, &mut s32).unwrap_err().to_string();
    let e64 = p64.inverse(&c64, &mut s64).unwrap_err().to_string();
    assert_eq!(e32, e64);
    let e32 = p32
        .inverse_real(&c32, &mut [0.0f32; 8])
        .unwrap_err()
        .to_string();
    let e64 = p64
        .inverse_real(&c64, &mut [0.0f64; 8])
        .unwrap_err()
        .to_string();
    assert_eq!(e32, e64);
    let bad = Options::default().with_skip_bits(Some(200));
    assert!(Plan::<f32>::new(b, &bad).is_err(), "f32 skip bits range");
    assert!(Plan::<f64>::new(b, &bad).is_ok());
    for b in [16, 64] {
        let m32 = Plan::<f32>::memory_needed(b, &o).unwrap();
        let m64 = Plan::<f64>::memory_needed(b, &o).unwrap();
        let p = Plan::<f32>::new(b, &o).unwrap();
        assert_eq!(p.memory_bytes(), m32, "B={b}");
        assert!(m32 < m64, "B={b}: f32 {m32} against f64 {m64}");
    }
}
