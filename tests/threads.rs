//! Results must not depend on the number of threads (Options::threads = 1 vs 2).

mod common;

use common::*;
use so3fft::{Complex64, Options, Plan};

const TOL: f64 = 1e-15;

#[test]
fn threads_1_vs_2() {
    let mut fails = Vec::new();
    for b in [16usize, 48] {
        let p1 = Plan::new(b, &Options::default().with_threads(1)).expect("plan threads=1");
        let p2 = Plan::new(b, &Options::default().with_threads(2)).expect("plan threads=2");
        assert_eq!(p1.threads(), 1, "Plan::threads() for threads=1");
        assert_eq!(p2.threads(), 2, "Plan::threads() for threads=2");
        let mut rng = Rng::new(900 + b as u64);
        let samples = rng.complex_vec(n_samples(b));
        let coefs = rng.complex_vec(n_coeffs(b));
        let z = Complex64::new(0.0, 0.0);
        let (mut c1, mut c2) = (vec![z; n_coeffs(b)], vec![z; n_coeffs(b)]);
        p1.forward(&samples, &mut c1).unwrap();
        p2.forward(&samples, &mut c2).unwrap();
        let (mut s1, mut s2) = (vec![z; n_samples(b)], vec![z; n_samples(b)]);
        p1.inverse(&coefs, &mut s1).unwrap();
        p2.inverse(&coefs, &mut s2).unwrap();
        let (ef, _) = max_abs_diff(&c1, &c2);
        let (ei, _) = max_abs_diff(&s1, &s2);
        println!(
            "B={b}: forward 1 vs 2 threads max diff {ef:.3e} (bitwise identical: {}), inverse max diff {ei:.3e} (bitwise identical: {})",
            bitwise_equal(&c1, &c2),
            bitwise_equal(&s1, &s2)
        );
        // repeated runs with 2 threads must also agree with each other
        let mut c3 = vec![z; n_coeffs(b)];
        p2.forward(&samples, &mut c3).unwrap();
        println!(
            "B={b}: two runs with 2 threads bitwise identical: {}",
            bitwise_equal(&c2, &c3)
        );
        if ef.is_nan() || ef > TOL {
            fails.push(format!("B={b}: forward differs by {ef:e}"));
        }
        if ei.is_nan() || ei > TOL {
            fails.push(format!("B={b}: inverse differs by {ei:e}"));
        }
    }
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

/// The plan is Send + Sync and execute takes &self: concurrent use on different arrays must give
/// the same numbers as sequential use.
#[test]
fn concurrent_execution_on_shared_plan() {
    let b = 12;
    let plan = Plan::new(b, &Options::default().with_threads(1)).unwrap();
    let inputs: Vec<Vec<Complex64>> = (0..4)
        .map(|i| Rng::new(70 + i).complex_vec(n_samples(b)))
        .collect();
    let z = Complex64::new(0.0, 0.0);
    let seq: Vec<Vec<Complex64>> = inputs
        .iter()
        .map(|x| {
            let mut c = vec![z; n_coeffs(b)];
            plan.forward(x, &mut c).unwrap();
            c
        })
        .collect();
    let par: Vec<Vec<Complex64>> = std::thread::scope(|s| {
        let hs: Vec<_> = inputs
            .iter()
            .map(|x| {
                let plan = &plan;
                s.spawn(move || {
                    let mut c = vec![z; n_coeffs(b)];
                    plan.forward(x, &mut c).unwrap();
                    c
                })
            })
            .collect();
        hs.into_iter().map(|h| h.join().unwrap()).collect()
    });
    for (i, (a, c)) in seq.iter().zip(&par).enumerate() {
        let (e, _) = max_abs_diff(a, c);
        assert!(e <= TOL, "input {i}: concurrent result differs by {e:e}");
    }
}
