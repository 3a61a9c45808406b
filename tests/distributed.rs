//! Distributed plans over 1..4 ranks (threads of this process, `ThreadExchange`) against the
//! single-process partial plan: bitwise equal results (each lane is the same kernel lane,
//! each cluster's sum runs over all betas in one call in both), complex and real, forward and
//! inverse, and collective errors.

mod common;

use so3fft::{Complex64, DistributedPlan, Exchange, Options, PartialPlan, Shape, ThreadExchange};

fn opts(real: bool) -> Options {
    Options::default().with_threads(1).with_real(real)
}

/// Every `(l, m, mp)` the shape holds, with its global index.
fn entries(s: &Shape) -> Vec<(usize, isize, isize, usize)> {
    let (a, n) = (s.order_limit_alpha as isize, s.order_limit_gamma as isize);
    let mut v = Vec::new();
    for l in 0..s.degree_limit {
        for m in -a..=a {
            for mp in -n..=n {
                if let Some(i) = s.coef_index(l, m, mp) {
                    v.push((l, m, mp, i));
                }
            }
        }
    }
    v
}

/// The global slices a rank holds, in its local order.
fn local_slices(s: &Shape, (j0, j1): (usize, usize)) -> Vec<usize> {
    let nb = s.n_beta();
    (j0..j1).chain(nb - j1..nb - j0).collect()
}

fn check_shape(s: Shape, ranks: usize, real: bool) {
    check_grouped(s, ranks, real, None);
}

/// Equality with the single-process plan: bitwise in one group of pairs; with a workspace
/// cap of `cap` bytes (several groups) to rounding, `tol` relative to the largest value.
fn check_grouped(s: Shape, ranks: usize, real: bool, cap: Option<usize>) {
    let tol = if cap.is_some() { 1e-14 } else { 0.0 };
    let close = |x: &[f64], y: &[f64]| {
        let big = y.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        x.iter().zip(y).all(|(a, b)| (a - b).abs() <= tol * big)
    };
    let flat = |z: &[Complex64]| -> Vec<f64> { z.iter().flat_map(|v| [v.re, v.im]).collect() };
    let dist_opts = opts(real).with_max_workspace_bytes(cap);
    let single = PartialPlan::new(&s, &opts(real)).unwrap();
    let (nc, ns, sl) = (s.num_coeffs(), s.num_samples(), s.slice_len());
    let mut st = 5u64;
    let mut c: Vec<Complex64> = (0..nc)
        .map(|_| Complex64::new(common::rnd(&mut st), common::rnd(&mut st)))
        .collect();
    let samples: Vec<Complex64> = (0..ns)
        .map(|_| {
            Complex64::new(
                common::rnd(&mut st),
                if real { 0.0 } else { common::rnd(&mut st) },
            )
        })
        .collect();
    if real {
        common::make_hermitian(&s, &mut c);
    }
    // Single-process results.
    let mut want_x = vec![Complex64::default(); ns];
    let mut want_xr = vec![0.0; ns];
    let mut want_c = vec![Complex64::default(); nc];
    if real {
        single.inverse_real(&c, &mut want_xr).unwrap();
        let re: Vec<f64> = samples.iter().map(|z| z.re).collect();
        single.forward_real(&re, &mut want_c).unwrap();
    } else {
        single.inverse(&c, &mut want_x).unwrap();
        single.forward(&samples, &mut want_c).unwrap();
    }
    let group = ThreadExchange::group(ranks);
    std::thread::scope(|scope| {
        for comm in &group {
            let (c, samples) = (&c, &samples);
            let (want_x, want_xr, want_c) = (&want_x, &want_xr, &want_c);
            let (dist_opts, close, flat) = (&dist_opts, &close, &flat);
            scope.spawn(move || {
                let plan = DistributedPlan::new(comm, &s, dist_opts).unwrap();
                assert_eq!(plan.groups() > 1, cap.is_some(), "groups {}", plan.groups());
                let mine = local_slices(&s, plan.local_pairs());
                assert_eq!(plan.local_num_samples(), mine.len() * sl);
                // Local coefficients from the global ones.
                let mut lc = vec![Complex64::default(); plan.local_num_coeffs()];
                let mut held = 0;
                for (l, m, mp, i) in entries(&s) {
                    let (owner, at) = plan.coef_owner(l, m, mp).unwrap();
                    if owner == comm.rank() {
                        assert_eq!(plan.local_coef_index(l, m, mp), Some(at));
                        lc[at] = c[i];
                        held += 1;
                    }
                }
                assert_eq!(held, lc.len());
                let local_samples: Vec<Complex64> = mine
                    .iter()
                    .flat_map(|&k| samples[k * sl..][..sl].to_vec())
                    .collect();
                let mut back = vec![Complex64::default(); lc.len()];
                if real {
                    let mut x = vec![0.0; plan.local_num_samples()];
                    plan.inverse_real(&lc, &mut x).unwrap();
                    for (t, &k) in mine.iter().enumerate() {
                        assert!(
                            close(&x[t * sl..][..sl], &want_xr[k * sl..][..sl]),
                            "real inverse slice {k}"
                        );
                    }
                    let re: Vec<f64> = local_samples.iter().map(|z| z.re).collect();
                    plan.forward_real(&re, &mut back).unwrap();
                } else {
                    let mut x = vec![Complex64::default(); plan.local_num_samples()];
                    plan.inverse(&lc, &mut x).unwrap();
                    for (t, &k) in mine.iter().enumerate() {
                        assert!(
                            close(&flat(&x[t * sl..][..sl]), &flat(&want_x[k * sl..][..sl])),
                            "inverse slice {k}"
                        );
                    }
                    plan.forward(&local_samples, &mut back).unwrap();
                }
                let big = want_c.iter().fold(1.0f64, |m, v| m.max(v.norm()));
                for (l, m, mp, i) in entries(&s) {
                    if let Some(at) = plan.local_coef_index(l, m, mp) {
                        assert!(
                            (back[at] - want_c[i]).norm() <= tol * big,
                            "forward ({l},{m},{mp}) on {} ranks: {} vs {}",
                            ranks,
                            back[at],
                            want_c[i]
                        );
                    }
                }
            });
        }
    });
}

#[test]
fn equals_single_process_plan() {
    for ranks in 1..=4 {
        for real in [false, true] {
            check_shape(Shape::new(6), ranks, real);
            check_shape(
                Shape::new(9).with_orders(4, 2).with_grid(10, 11, 7),
                ranks,
                real,
            );
        }
    }
    check_shape(Shape::new(5).with_degree_min(2), 3, false);
}

#[test]
fn groups_of_pairs_agree_to_rounding() {
    // A small workspace cap splits the pairs into groups: the forward sums each cluster over
    // the groups, the inverse evaluates them group by group.
    for ranks in [1, 2, 3] {
        for real in [false, true] {
            check_grouped(Shape::new(16), ranks, real, Some(60_000));
            // The smallest cap: as many groups as the smallest share has pairs.
            check_grouped(Shape::new(11), ranks, real, Some(1));
            check_grouped(
                Shape::new(13).with_orders(6, 4).with_grid(15, 17, 11),
                ranks,
                real,
                Some(20_000),
            );
        }
    }
}

#[test]
fn collective_errors() {
    // Ranks given different shapes: every rank gets the error, nobody waits forever.
    let group = ThreadExchange::group(3);
    std::thread::scope(|scope| {
        for comm in &group {
            scope.spawn(move || {
                let b = if comm.rank() == 1 { 7 } else { 6 };
                let r = DistributedPlan::new(comm, &Shape::new(b), &opts(false));
                assert!(r.is_err());
            });
        }
    });
    // A skip threshold outside the accepted range is refused on every rank, as by a
    // partial plan.
    for bits in [5u32, 1000] {
        let bad = opts(false).with_skip_bits(Some(bits));
        let refused = |r: so3fft::Result<()>| matches!(r, Err(so3fft::Error::InvalidArgument(m)) if m.contains("skip_bits"));
        assert!(refused(
            PartialPlan::<f64>::new(&Shape::new(6), &bad).map(|_| ())
        ));
        let group = ThreadExchange::group(2);
        std::thread::scope(|scope| {
            for comm in &group {
                let bad = &bad;
                scope.spawn(move || {
                    let r = DistributedPlan::new(comm, &Shape::new(6), bad).map(|_| ());
                    assert!(refused(r), "rank {}", comm.rank());
                });
            }
        });
    }
    // The ends of the range, and 0 (no skipping), are accepted.
    for bits in [0u32, 24, 560] {
        let good = opts(false).with_skip_bits(Some(bits));
        let group = ThreadExchange::group(2);
        std::thread::scope(|scope| {
            for comm in &group {
                let good = &good;
                scope.spawn(move || {
                    assert!(DistributedPlan::new(comm, &Shape::new(6), good).is_ok());
                });
            }
        });
    }
    // One rank refuses (bad arguments of its own): the others fail too.
    let group = ThreadExchange::group(3);
    std::thread::scope(|scope| {
        for comm in &group {
            scope.spawn(move || {
                if comm.rank() == 0 {
                    DistributedPlan::refuse_collectively(&comm).unwrap();
                } else {
                    assert!(DistributedPlan::new(comm, &Shape::new(5), &opts(false)).is_err());
                }
            });
        }
    });
    // One rank passes a wrong array length: all ranks fail the execute.
    let group = ThreadExchange::group(2);
    std::thread::scope(|scope| {
        for comm in &group {
            scope.spawn(move || {
                let s = Shape::new(4);
                let plan = DistributedPlan::new(comm, &s, &opts(false)).unwrap();
                let c = vec![Complex64::default(); plan.local_num_coeffs()];
                let short = usize::from(comm.rank() == 0);
                let mut x = vec![Complex64::default(); plan.local_num_samples() - short];
                assert!(plan.inverse(&c, &mut x).is_err());
            });
        }
    });
}
