//! Partial plans (`so3fft::PartialPlan`) against direct summation, the full plan with the
//! absent coefficients zeroed, and exact properties (round trip, batches, selections,
//! real signals).

mod common;

use so3fft::wigner::wigner_d_column;
use so3fft::{
    coef_index, num_coeffs, Batch, Betas, Complex64, Direction, Isa, Options, PartialPlan, Plan,
    Shape,
};
use std::f64::consts::PI;

/// Deterministic pseudo-random values in (-1, 1).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
    fn c(&mut self) -> Complex64 {
        Complex64::new(self.next(), self.next())
    }
}

/// Every `(l, m, mp)` a shape holds.
fn triples(s: &Shape) -> Vec<(usize, isize, isize)> {
    let mut v = Vec::new();
    let (a, n) = (s.order_limit_alpha as isize, s.order_limit_gamma as isize);
    for l in s.degree_min..s.degree_limit {
        for m in -a..=a {
            for mp in -n..=n {
                if m.unsigned_abs() <= l && mp.unsigned_abs() <= l {
                    v.push((l, m, mp));
                }
            }
        }
    }
    v
}

fn random_coeffs(s: &Shape, seed: u64) -> Vec<Complex64> {
    let mut r = Rng(seed);
    (0..s.num_coeffs()).map(|_| r.c()).collect()
}

/// `sum fhat(l,M,M') Dt^l_{M,M'}(alpha, beta, gamma)` by direct summation.
fn direct(s: &Shape, c: &[Complex64], alpha: f64, beta: f64, gamma: f64) -> Complex64 {
    let (a, n) = (s.order_limit_alpha as isize, s.order_limit_gamma as isize);
    let mut sum = Complex64::default();
    for m in -a..=a {
        for mp in -n..=n {
            let lo = m.unsigned_abs().max(mp.unsigned_abs());
            if lo >= s.degree_limit {
                continue;
            }
            let d = wigner_d_column(m, mp, s.degree_limit - 1, beta);
            let phase = Complex64::from_polar(1.0, -(m as f64) * alpha - (mp as f64) * gamma);
            for l in lo.max(s.degree_min)..s.degree_limit {
                let norm = ((2 * l + 1) as f64 / 2.0).sqrt() / (2.0 * PI);
                sum += c[s.coef_index(l, m, mp).unwrap()] * phase * (d[l - lo] * norm);
            }
        }
    }
    sum
}

fn max_abs(v: &[Complex64]) -> f64 {
    v.iter().map(|x| x.norm()).fold(0.0, f64::max)
}

/// Whether `a` and `b` hold the same values bit for bit (signs of zero included).
fn same_bits(a: &[Complex64], b: &[Complex64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b)
            .all(|(x, y)| x.re.to_bits() == y.re.to_bits() && x.im.to_bits() == y.im.to_bits())
}

fn max_diff(a: &[Complex64], b: &[Complex64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}

fn opts() -> Options {
    Options::default().with_threads(2)
}

fn zeros(n: usize) -> Vec<Complex64> {
    vec![Complex64::default(); n]
}

#[test]
fn default_shape_is_todays_layout() {
    let b = 16;
    let s = Shape::new(b);
    assert!(s.is_full());
    assert_eq!(s.num_coeffs(), num_coeffs(b));
    for (l, m, mp) in triples(&s) {
        assert_eq!(s.coef_index(l, m, mp), Some(coef_index(b, l, m, mp)));
    }
    assert_eq!(s.num_samples(), 8 * b * b * b);
    assert_eq!(s.coef_index(b, 0, 0), None);
    assert_eq!(s.coef_index(2, 3, 0), None);
}

#[test]
fn limited_layout_is_dense_and_ordered() {
    let s = Shape::new(10).with_orders(3, 5).with_degree_min(2);
    let mut seen = vec![false; s.num_coeffs()];
    let mut last: Option<(usize, isize, isize, usize)> = None;
    let key = |m: isize, lim: isize| if m >= 0 { m } else { 2 * lim + 1 + m };
    let mut all = triples(&s);
    all.sort_by_key(|&(l, m, mp)| (key(m, 3), key(mp, 5), l));
    for (l, m, mp) in all {
        let i = s.coef_index(l, m, mp).unwrap();
        assert!(!seen[i]);
        seen[i] = true;
        if let Some((_, _, _, j)) = last {
            assert_eq!(i, j + 1, "blocks in so3CoefLoc order at ({l},{m},{mp})");
        }
        last = Some((l, m, mp, i));
    }
    assert!(seen.iter().all(|&x| x));
    assert_eq!(s.coef_index(5, 4, 0), None);
    assert_eq!(s.coef_index(1, 0, 0), None);
}

/// Limited shapes on SOFT's grid against the full plan with the absent coefficients zeroed
/// (inverse), and the full forward restricted to the shape (forward).
#[test]
fn limited_shapes_match_full_plan() {
    let b = 12;
    let full = Plan::new(b, &Options::default()).unwrap();
    let shapes = [
        Shape::new(b).with_orders(4, 2).with_grid(b, 2 * b, 2 * b),
        Shape::new(b).with_orders(1, 7).with_grid(b, 2 * b, 2 * b),
        Shape::new(b).with_degree_min(5),
        Shape::new(b)
            .with_orders(0, 0)
            .with_degree_min(3)
            .with_grid(b, 2 * b, 2 * b),
        Shape::new(b)
            .with_orders(11, 3)
            .with_degree_min(4)
            .with_grid(b, 2 * b, 2 * b),
    ];
    for s in shapes {
        let pp = PartialPlan::new(&s, &opts()).unwrap();
        let c = random_coeffs(&s, 3);
        let mut padded = zeros(num_coeffs(b));
        for (l, m, mp) in triples(&s) {
            padded[coef_index(b, l, m, mp)] = c[s.coef_index(l, m, mp).unwrap()];
        }
        let (mut x, mut y) = (zeros(s.num_samples()), zeros(s.num_samples()));
        pp.inverse(&c, &mut x).unwrap();
        full.inverse(&padded, &mut y).unwrap();
        let e = max_diff(&x, &y) / max_abs(&y);
        assert!(e < 1e-13, "{s:?}: inverse differs by {e:e}");
        // Forward of a full-band signal: the shape's coefficients of the full forward.
        let mut r = Rng(11);
        let all: Vec<Complex64> = (0..num_coeffs(b)).map(|_| r.c()).collect();
        full.inverse(&all, &mut y).unwrap();
        let mut got = zeros(s.num_coeffs());
        pp.forward(&y, &mut got).unwrap();
        for (l, m, mp) in triples(&s) {
            let d = (got[s.coef_index(l, m, mp).unwrap()] - all[coef_index(b, l, m, mp)]).norm();
            assert!(d < 1e-12, "{s:?}: forward ({l},{m},{mp}) off by {d:e}");
        }
    }
}

/// Odd and oversampled grids against direct summation, and the round trip.
#[test]
fn other_grids_against_direct_summation() {
    let shapes = [
        Shape::new(5).with_orders(3, 2).with_grid(7, 9, 7),
        Shape::new(6).with_grid(6, 11, 13),
        Shape::new(4)
            .with_orders(2, 3)
            .with_grid(9, 5, 8)
            .with_degree_min(1),
        Shape::new(7).with_orders(6, 0).with_grid(8, 13, 1),
    ];
    for s in shapes {
        let pp = PartialPlan::new(&s, &opts()).unwrap();
        let c = random_coeffs(&s, 5);
        let mut x = zeros(s.num_samples());
        pp.inverse(&c, &mut x).unwrap();
        let mut worst: f64 = 0.0;
        for k in 0..s.n_beta() {
            for ja in 0..s.n_alpha {
                for jg in 0..s.n_gamma {
                    let want = direct(&s, &c, s.alpha(ja), s.beta(k), s.gamma(jg));
                    let got = x[s.sample_index(ja, k, jg)];
                    worst = worst.max((want - got).norm());
                }
            }
        }
        assert!(worst < 1e-12, "{s:?}: direct summation off by {worst:e}");
        let mut back = zeros(c.len());
        pp.forward(&x, &mut back).unwrap();
        let e = max_diff(&back, &c);
        assert!(e < 1e-12, "{s:?}: round trip {e:e}");
    }
}

/// A batch gives bitwise the results of single executes (the batched inverse kernel shares
/// each cluster's recurrence among the transforms of a group; the forward runs the single
/// kernel per transform with the next one's rows prefetched), and round trips.
#[test]
fn batches_equal_single_executes() {
    // A small cap: chunks of one pair, groups of one transform; the default: one of each.
    for cap in [Some(40 << 10), None] {
        batch_case(cap);
    }
}

fn batch_case(cap: Option<usize>) {
    let s = Shape::new(9).with_orders(5, 3).with_grid(10, 12, 9);
    let o = opts().with_real(true).with_max_workspace_bytes(cap);
    let pp = PartialPlan::new(&s, &o).unwrap();
    let (nc, ns) = (s.num_coeffs(), s.num_samples());
    // More than one batched kernel call (8 transforms each), the last one odd.
    let count = 11;
    let (idist, odist) = (nc + 5, ns + 3);
    let mut r = Rng(9);
    let coeffs: Vec<Complex64> = (0..idist * count).map(|_| r.c()).collect();
    let mut many = zeros(odist * count);
    let b = Batch {
        count,
        in_dist: idist,
        out_dist: odist,
    };
    pp.inverse_many(b, &coeffs, &mut many).unwrap();
    let mut back_many = zeros(idist * count);
    let fb = Batch {
        count,
        in_dist: odist,
        out_dist: idist,
    };
    pp.forward_many(fb, &many, &mut back_many).unwrap();
    for t in 0..count {
        let mut one = zeros(ns);
        pp.inverse(&coeffs[t * idist..][..nc], &mut one).unwrap();
        assert!(same_bits(&one, &many[t * odist..][..ns]), "inverse {t}");
        let mut back = zeros(nc);
        pp.forward(&one, &mut back).unwrap();
        assert!(
            same_bits(&back, &back_many[t * idist..][..nc]),
            "forward {t}"
        );
        assert!(max_diff(&back, &coeffs[t * idist..][..nc]) < 1e-12);
    }
    // Real batches too.
    let mut hc: Vec<Complex64> = zeros(nc * count);
    for t in 0..count {
        let mut c = random_coeffs(&s, 20 + t as u64);
        common::make_hermitian(&s, &mut c);
        hc[t * nc..][..nc].copy_from_slice(&c);
    }
    let mut re_many = vec![0.0; ns * count];
    let rb = Batch {
        count,
        in_dist: nc,
        out_dist: ns,
    };
    pp.inverse_real_many(rb, &hc, &mut re_many).unwrap();
    for t in 0..count {
        let mut one = vec![0.0; ns];
        pp.inverse_real(&hc[t * nc..][..nc], &mut one).unwrap();
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert!(
            bits(&one) == bits(&re_many[t * ns..][..ns]),
            "real inverse {t}"
        );
    }
}

/// Inverses at selected betas equal the full inverse's slices (grid indices), and direct
/// summation (arbitrary values).
#[test]
fn selected_betas() {
    let s = Shape::new(10).with_orders(6, 4).with_grid(12, 14, 10);
    let c = random_coeffs(&s, 13);
    let all = PartialPlan::new(&s, &opts()).unwrap();
    let mut x = zeros(s.num_samples());
    all.inverse(&c, &mut x).unwrap();
    let ks = vec![23, 0, 5, 18, 6, 11, 12];
    let o = opts().with_betas(Betas::Indices(ks.clone()));
    let sel = PartialPlan::new(&s, &o).unwrap();
    assert_eq!(sel.direction(), Direction::Inverse);
    assert_eq!(sel.num_slices(), ks.len());
    let mut y = zeros(sel.num_samples());
    sel.inverse(&c, &mut y).unwrap();
    let sl = s.slice_len();
    for (i, &k) in ks.iter().enumerate() {
        let e = max_diff(&y[i * sl..][..sl], &x[k * sl..][..sl]);
        assert!(e < 1e-13, "slice {k}: {e:e}");
    }
    let vals = vec![0.0, 0.3, PI / 2.0, 2.9, PI, 1.0];
    let o = opts().with_betas(Betas::Values(vals.clone()));
    let sel = PartialPlan::new(&s, &o).unwrap();
    let mut y = zeros(sel.num_samples());
    sel.inverse(&c, &mut y).unwrap();
    for (i, &beta) in vals.iter().enumerate() {
        for ja in 0..s.n_alpha {
            for jg in 0..s.n_gamma {
                let want = direct(&s, &c, s.alpha(ja), beta, s.gamma(jg));
                let got = y[i * sl + ja * s.n_gamma + jg];
                assert!((want - got).norm() < 1e-12, "beta {beta}");
            }
        }
    }
}

/// Selections where no beta's mirror is selected too run each cluster's direct members at
/// the selected betas and the reversed ones at the mirrors only: against the full
/// inverse's slices on every instruction set, with selections of lower and upper betas
/// (padding between them), chunks of one pair, of a few pairs and of a vector, real plans,
/// batches, beta values and a lower degree limit; and bit for bit against the same
/// selection with a mirror added (which runs unsplit).
#[test]
fn selections_without_mirrors() {
    let isas = [Isa::Avx512, Isa::Avx2, Isa::Scalar];
    let shapes = [
        Shape::new(12).with_grid(12, 24, 25),
        Shape::new(11).with_orders(7, 4).with_grid(12, 15, 10),
        Shape::new(10).with_degree_min(3).with_grid(16, 21, 20),
    ];
    // Lower and upper betas; lower only (more than a vector); upper only; mixed again;
    // a vector of lower betas and three upper ones, or eight (split on a 32-beta grid);
    // a beta with its mirror (no split).
    let selections: [&[usize]; 7] = [
        &[1, 5, 20, 13, 8, 17],
        &[2, 4, 9, 0, 11, 6, 3, 8, 10],
        &[23, 17, 14],
        &[12, 0, 21],
        &[0, 1, 2, 3, 4, 5, 6, 7, 20, 15, 13],
        &[0, 1, 2, 3, 4, 5, 6, 7, 16, 17, 18, 19, 20, 21, 22, 23],
        &[7, 16, 2],
    ];
    for s in shapes {
        let c = random_coeffs(&s, 31);
        let mut hc = c.clone();
        common::make_hermitian(&s, &mut hc);
        let all = PartialPlan::new(&s, &opts()).unwrap();
        let mut x = zeros(s.num_samples());
        all.inverse(&c, &mut x).unwrap();
        let mut xr = zeros(s.num_samples());
        all.inverse(&hc, &mut xr).unwrap();
        let sl = s.slice_len();
        let nb = s.n_beta();
        for isa in isas.into_iter().filter(|i| i.is_supported()) {
            for ks in selections {
                // Chunks of the whole selection, of one pair, of a few, of about a vector.
                for cap in [None, Some(1), Some(30_000), Some(80_000), Some(150_000)] {
                    let o = opts()
                        .with_betas(Betas::Indices(ks.to_vec()))
                        .with_isa(Some(isa))
                        .with_max_workspace_bytes(cap);
                    let what = format!("{s:?} {isa:?} {ks:?} {cap:?}");
                    let sel = PartialPlan::new(&s, &o).unwrap();
                    let mut y = zeros(sel.num_samples());
                    sel.inverse(&c, &mut y).unwrap();
                    for (i, &k) in ks.iter().enumerate() {
                        let e = max_diff(&y[i * sl..][..sl], &x[k * sl..][..sl]);
                        assert!(e < 1e-13, "{what} slice {k}: {e:e}");
                    }
                    // With the first beta's mirror added, no pair writes one point only.
                    let mut with_mirror = ks.to_vec();
                    if !ks.contains(&(nb - 1 - ks[0])) {
                        with_mirror.push(nb - 1 - ks[0]);
                    }
                    let unsplit =
                        PartialPlan::new(&s, &o.clone().with_betas(Betas::Indices(with_mirror)))
                            .unwrap();
                    let mut z = zeros(unsplit.num_samples());
                    unsplit.inverse(&c, &mut z).unwrap();
                    assert!(
                        same_bits(&y, &z[..y.len()]),
                        "{what}: split against unsplit"
                    );
                    // The same betas as values.
                    let vals = Betas::Values(ks.iter().map(|&k| s.beta(k)).collect());
                    let by_value = PartialPlan::new(&s, &o.clone().with_betas(vals)).unwrap();
                    let mut v = zeros(by_value.num_samples());
                    by_value.inverse(&c, &mut v).unwrap();
                    let e = max_diff(&v, &y);
                    assert!(e < 1e-13, "{what}: values against indices {e:e}");
                    // Real plans: the real part of the complex inverse of Hermitian data,
                    // one at a time and as a batch of two.
                    let r = PartialPlan::new(&s, &o.clone().with_real(true)).unwrap();
                    let mut yr = vec![0.0; r.num_samples()];
                    r.inverse_real(&hc, &mut yr).unwrap();
                    for (i, &k) in ks.iter().enumerate() {
                        let e = yr[i * sl..][..sl]
                            .iter()
                            .zip(&xr[k * sl..][..sl])
                            .map(|(a, b)| (a - b.re).abs())
                            .fold(0.0, f64::max);
                        assert!(e < 1e-13, "{what} real slice {k}: {e:e}");
                    }
                    let (nc, ns) = (s.num_coeffs(), sel.num_samples());
                    let mut hcs = hc.clone();
                    hcs.extend(hc.iter().map(|v| v * 2.0));
                    let mut yr_many = vec![0.0; 2 * ns];
                    let b = Batch {
                        count: 2,
                        in_dist: nc,
                        out_dist: ns,
                    };
                    r.inverse_real_many(b, &hcs, &mut yr_many).unwrap();
                    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
                    assert!(bits(&yr_many[..ns]) == bits(&yr), "{what}: real batch");
                    let twice: Vec<f64> = yr.iter().map(|v| 2.0 * v).collect();
                    assert!(
                        bits(&yr_many[ns..]) == bits(&twice),
                        "{what}: real batch x2"
                    );
                    // A batch of three equals three single executes, bit for bit.
                    let mut cs = c.clone();
                    cs.extend(c.iter().map(|v| v * 0.5));
                    cs.extend(hc.iter());
                    let mut many = zeros(3 * ns);
                    let b = Batch {
                        count: 3,
                        in_dist: nc,
                        out_dist: ns,
                    };
                    sel.inverse_many(b, &cs, &mut many).unwrap();
                    for t in 0..3 {
                        let mut one = zeros(ns);
                        sel.inverse(&cs[t * nc..][..nc], &mut one).unwrap();
                        assert!(same_bits(&one, &many[t * ns..][..ns]), "{what}: batch {t}");
                    }
                }
            }
        }
    }
}

/// Real plans (whose real transforms run only the members `M' >= 0`) against complex ones,
/// on every instruction set, in one chunk and in several.
#[test]
fn real_against_complex() {
    let shapes = [
        Shape::new(8).with_orders(5, 3).with_grid(9, 12, 7),
        Shape::new(8)
            .with_orders(2, 6)
            .with_grid(8, 6, 14)
            .with_degree_min(2),
        Shape::new(6),
        Shape::new(13),
    ];
    let isas = [Isa::Avx512, Isa::Avx2, Isa::Scalar];
    let runs = isas
        .into_iter()
        .filter(|i| i.is_supported())
        .flat_map(|isa| [None, Some(20_000)].map(|cap| (Some(isa), cap)));
    for s in shapes {
        for (isa, cap) in runs.clone() {
            let o = opts()
                .with_real(true)
                .with_isa(isa)
                .with_max_workspace_bytes(cap);
            let pp = PartialPlan::new(&s, &o).unwrap();
            let mut c = random_coeffs(&s, 17);
            common::make_hermitian(&s, &mut c);
            let mut z = zeros(s.num_samples());
            pp.inverse(&c, &mut z).unwrap();
            assert!(z.iter().all(|v| v.im.abs() < 1e-12));
            // The real inverse reads only the representatives: spoil the others.
            let mut spoiled = c.clone();
            for (l, m, mp) in triples(&s) {
                if mp < 0 || (mp == 0 && m < 0) {
                    spoiled[s.coef_index(l, m, mp).unwrap()] = Complex64::new(9.0, 9.0);
                }
            }
            let mut re = vec![0.0; s.num_samples()];
            pp.inverse_real(&spoiled, &mut re).unwrap();
            let e = re
                .iter()
                .zip(&z)
                .map(|(a, b)| (a - b.re).abs())
                .fold(0.0, f64::max);
            assert!(e < 1e-13, "{s:?} {isa:?} {cap:?}: real inverse {e:e}");
            let mut back = zeros(c.len());
            pp.forward_real(&re, &mut back).unwrap();
            let e = max_diff(&back, &c);
            assert!(e < 1e-12, "{s:?} {isa:?} {cap:?}: real forward {e:e}");
        }
    }
}

#[test]
fn invalid_shapes_and_calls_are_rejected() {
    let bad = [
        (Shape::new(0), "degree limit"),
        (Shape::new(5000), "degree limit"),
        (Shape::new(8).with_degree_min(8), "L0"),
        (Shape::new(8).with_orders(8, 2), "order limits"),
        (
            Shape::new(8).with_orders(3, 2).with_grid(8, 6, 16),
            "n_alpha",
        ),
        (
            Shape::new(8).with_orders(3, 2).with_grid(8, 7, 4),
            "n_gamma",
        ),
        (Shape::new(8).with_grid(0, 16, 16), "B_grid"),
        (Shape::new(8).with_grid(7, 16, 16), "B_grid >= L"),
    ];
    for (s, what) in bad {
        let err = PartialPlan::<f64>::new(&s, &opts())
            .err()
            .expect("rejected");
        assert!(
            err.to_string().contains(what),
            "{s:?}: '{err}' lacks '{what}'"
        );
        assert_eq!(s.coef_index(0, 0, 0).is_none(), s.validate().is_err());
    }
    // Undersampled beta grid: fine for the inverse.
    let s = Shape::new(8).with_grid(4, 16, 16);
    let o = opts().with_direction(Direction::Inverse);
    assert!(PartialPlan::<f64>::new(&s, &o).is_ok());
    let s = Shape::new(6).with_orders(2, 2);
    for (betas, what) in [
        (Betas::Indices(vec![12]), "outside the grid"),
        (Betas::Indices(vec![1, 1]), "twice"),
        (Betas::Values(vec![-0.1]), "outside [0, pi]"),
        (Betas::Values(vec![f64::NAN]), "outside [0, pi]"),
        (Betas::Indices(vec![]), "no betas"),
    ] {
        let o = opts().with_betas(betas);
        let err = PartialPlan::<f64>::new(&s, &o).err().expect("rejected");
        assert!(err.to_string().contains(what), "'{err}' lacks '{what}'");
    }
    let o = opts()
        .with_betas(Betas::Indices(vec![1]))
        .with_direction(Direction::Forward);
    assert!(PartialPlan::<f64>::new(&s, &o).is_err());
    for bits in [1, 23, 561] {
        let o = opts().with_skip_bits(Some(bits));
        assert!(PartialPlan::<f64>::new(&s, &o).is_err());
    }
    let pp = PartialPlan::new(&s, &opts()).unwrap();
    let c = zeros(pp.num_coeffs());
    let mut x = zeros(pp.num_samples() - 1);
    assert!(pp.inverse(&c, &mut x).is_err());
    let mut x = zeros(pp.num_samples());
    assert!(pp
        .inverse_real(&c, &mut vec![0.0; pp.num_samples()])
        .is_err());
    let b = Batch {
        count: 2,
        in_dist: pp.num_coeffs(),
        out_dist: pp.num_samples() - 1,
    };
    assert!(pp.inverse_many(b, &c, &mut x).is_err());
    let b = Batch {
        count: 0,
        in_dist: 0,
        out_dist: 0,
    };
    assert!(pp.inverse_many(b, &c, &mut x).is_err());
}

/// The skip threshold: a looser one stays within its bound (docs/conventions.md,
/// `Options::skip_bits`: an inverse value moves by less than `L 2^-bits max|c|` per order
/// pair of the slice DFT).
#[test]
fn skip_threshold_bounds_the_error() {
    let s = Shape::new(48).with_orders(20, 20).with_grid(48, 41, 41);
    let c = random_coeffs(&s, 21);
    let plan = |bits| PartialPlan::new(&s, &opts().with_skip_bits(Some(bits))).unwrap();
    let mut x0 = zeros(s.num_samples());
    plan(0).inverse(&c, &mut x0).unwrap();
    let scale = max_abs(&c);
    for bits in [24u32, 34] {
        let threshold = 2f64.powi(-(bits as i32));
        let mut x = zeros(s.num_samples());
        plan(bits).inverse(&c, &mut x).unwrap();
        let bound = s.degree_limit as f64 * threshold * scale * (41.0 * 41.0);
        let e = max_diff(&x, &x0);
        assert!(e < bound, "2^-{bits}: error {e:e} above {bound:e}");
    }
}

/// The engine's inverse with its chunks chained (each chunk's rows in the output
/// slices of the chunk before it, one pass of the DWT stage) against direct summation at
/// points of every beta slice, on every instruction set, for the full shape, an
/// order-limited one and an oversampled grid.
#[test]
fn chained_inverse_against_direct_summation() {
    let shapes = [
        Shape::new(17),
        Shape::new(17).with_orders(10, 6),
        Shape::new(11).with_orders(9, 7).with_grid(20, 25, 23),
    ];
    for s in shapes {
        let c = random_coeffs(&s, 21);
        let points: Vec<(usize, Complex64)> = (0..s.n_beta())
            .flat_map(|k| {
                [(0, 0), (1, 3), (s.n_alpha - 1, s.n_gamma / 2), (5, 2)].map(|(ja, jg)| {
                    let want = direct(&s, &c, s.alpha(ja), s.beta(k), s.gamma(jg));
                    (s.sample_index(ja, k, jg), want)
                })
            })
            .collect();
        for isa in [Isa::Avx512, Isa::Avx2, Isa::Scalar]
            .into_iter()
            .filter(|i| i.is_supported())
        {
            let mut chained = 0;
            for cap in [60_000, 150_000, 300_000] {
                let o = opts()
                    .with_isa(Some(isa))
                    .with_max_workspace_bytes(Some(cap));
                let pp = PartialPlan::new(&s, &o).unwrap();
                chained = chained.max(pp.chained_inverse_chunks(false));
                let mut x = zeros(s.num_samples());
                pp.inverse(&c, &mut x).unwrap();
                let worst = points
                    .iter()
                    .map(|&(i, want)| (want - x[i]).norm())
                    .fold(0.0, f64::max);
                assert!(worst < 1e-12, "{s:?} {isa:?} cap {cap}: off by {worst:e}");
                // The round trip through the forward (chunked too).
                let mut back = zeros(c.len());
                pp.forward(&x, &mut back).unwrap();
                let e = max_diff(&back, &c);
                assert!(e < 1e-12, "{s:?} {isa:?} cap {cap}: round trip {e:e}");
            }
            assert!(chained >= 2, "{s:?} {isa:?}: no cap chains the inverse");
        }
    }
}

/// The default workspace rule leaves the chunk buffer room for every beta when the rows
/// of all of them are far below it: an order-limited shape at a large degree limit (its
/// tables per beta grow with `L`) runs in one chunk, not one beta pair at a time.
#[test]
fn default_workspace_holds_all_pairs_of_a_small_shape() {
    let b = 2048;
    let s = Shape::new(b).with_orders(8, 8).with_grid(b, 17, 17);
    let pp = PartialPlan::<f64>::new(&s, &opts()).unwrap();
    // Two lane rows per beta pair, each with at least the 17 x 17 in-band order pairs.
    let all_rows = b * 2 * 17 * 17 * 16;
    let scratch = pp.scratch_bytes();
    assert!(
        (all_rows..=512 << 20).contains(&scratch),
        "chunk buffer {scratch} bytes, the rows of every pair {all_rows}"
    );
}

/// The forward and the inverse share each worker's slice buffers: an inverse after a
/// forward on the same plan gives the bits of an inverse before it (the forward leaves
/// values where the inverse expects zeros), with the rows in place (most columns in the
/// band) and straight into the output (few columns: the others must stay zero).
#[test]
fn inverse_after_forward_is_unchanged() {
    for s in [
        Shape::new(12),
        Shape::new(16).with_orders(2, 2).with_grid(16, 32, 32),
    ] {
        let pp = PartialPlan::new(&s, &opts()).unwrap();
        let c = random_coeffs(&s, 31);
        let mut before = zeros(s.num_samples());
        pp.inverse(&c, &mut before).unwrap();
        let mut st = 77u64;
        let noise: Vec<Complex64> = (0..s.num_samples())
            .map(|_| Complex64::new(common::rnd(&mut st), common::rnd(&mut st)))
            .collect();
        let mut back = zeros(c.len());
        pp.forward(&noise, &mut back).unwrap();
        let mut after = zeros(s.num_samples());
        pp.inverse(&c, &mut after).unwrap();
        assert!(same_bits(&before, &after), "{s:?}");
    }
}
