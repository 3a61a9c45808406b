//! The plan's own guarantees: threads, pools, the real paths in complex arrays, the
//! watched inverse.

#[test]
fn plan_is_send_sync() {
    fn is<T: Send + Sync>() {}
    is::<super::Plan>();
}

/// Plans made without a pool share the process's pool of their thread count: many plans,
/// one set of workers; another thread count, other workers; the plans on one pool give
/// the same samples as a plan alone.
#[test]
fn plans_of_a_thread_count_share_the_process_pool() {
    use crate::workers::WorkerPool;
    let options = |threads| super::Options {
        threads,
        ..Default::default()
    };
    let plans: Vec<super::Plan> = (0..12)
        .map(|i| super::Plan::new(4 + i % 3, &options(2)).unwrap())
        .collect();
    let pool = WorkerPool::process(2).unwrap();
    assert!(plans.iter().all(|p| p.engine().workers().same_as(&pool)));
    let three = super::Plan::new(4, &options(3)).unwrap();
    assert!(!three.engine().workers().same_as(&pool));
    assert!(three
        .engine()
        .workers()
        .same_as(&WorkerPool::process(3).unwrap()));
    let s2 = crate::s2::S2Plan::<f64>::new(
        8,
        &crate::options::Options {
            threads: 2,
            ..Default::default()
        },
    )
    .unwrap();
    assert!(s2.workers().same_as(&pool));
    // Executions on the shared workers, one after another and from two threads at once.
    let coeffs: Vec<num_complex::Complex64> = (0..plans[0].num_coeffs())
        .map(|i| num_complex::Complex64::new((i as f64).sin(), (2.0 * i as f64).cos()))
        .collect();
    let mut want = vec![num_complex::Complex64::default(); plans[0].num_samples()];
    three.inverse(&coeffs, &mut want).unwrap();
    std::thread::scope(|s| {
        for p in [&plans[0], &plans[3]] {
            let (coeffs, want) = (&coeffs, &want);
            s.spawn(move || {
                let mut got = vec![num_complex::Complex64::default(); p.num_samples()];
                for _ in 0..5 {
                    p.inverse(coeffs, &mut got).unwrap();
                    assert!(got == *want);
                }
            });
        }
    });
}

/// Plans on one shared pool: the threads run until the last plan on them is dropped (and
/// that drop waits for them); a plan on a pool of another thread count is refused; a plan
/// executed from inside the pool (as a correlation runs its stages) gives the same
/// samples as one on its own workers, bit for bit.
#[test]
fn plans_share_a_pool() {
    use crate::workers::WorkerPool;
    use num_complex::Complex64;
    let options = super::Options {
        threads: 2,
        ..Default::default()
    };
    let pool = WorkerPool::new(2, "so3fft-test").unwrap();
    let live = pool.live_count();
    let a = super::Plan::new_on(6, &options, Some(&pool)).unwrap();
    let b = super::Plan::new_on(6, &options, Some(&pool)).unwrap();
    let three = super::Options {
        threads: 3,
        ..Default::default()
    };
    assert!(super::Plan::<f64>::new_on(6, &three, Some(&pool)).is_err());
    let own = super::Plan::new(6, &options).unwrap();
    let coeffs: Vec<Complex64> = (0..own.num_coeffs())
        .map(|i| Complex64::new((i as f64 * 0.7).sin(), (i as f64 * 1.3).cos()))
        .collect();
    let mut want = vec![Complex64::default(); own.num_samples()];
    own.inverse(&coeffs, &mut want).unwrap();
    let mut got = want.clone();
    pool.pool()
        .install(|| a.inverse(&coeffs, &mut got))
        .unwrap();
    assert!(got.iter().zip(&want).all(|(x, y)| x == y));
    drop(pool);
    drop(a);
    assert_eq!(*live.0.lock().unwrap(), 2, "b still holds the threads");
    b.inverse(&coeffs, &mut got).unwrap();
    assert!(got.iter().zip(&want).all(|(x, y)| x == y));
    drop(b);
    assert_eq!(*live.0.lock().unwrap(), 0);
}

/// The real inverse into a complex array (the FFT stage writing each slice's reals as
/// `(x, 0)`, the chained chunks' buffers in the complex output's slices) gives the real
/// inverse's samples (bit for bit into a 16-byte aligned output) and imaginary parts
/// exactly +0: one chunk, chunks of 16 pairs (chained: their rows fit in the complex
/// output's slices) and of one pair, output 16-byte aligned or not.
#[test]
fn real_inverse_into_complex_matches_real_samples() {
    use num_complex::Complex64;
    for (b, cap) in [
        (24usize, None),
        (36, Some(1_500_000usize)),
        (37, Some(1usize)),
        (20, Some(500_000)),
        (41, None),
    ] {
        let opts = super::Options {
            max_workspace_bytes: cap,
            real: true,
            threads: 2,
            ..Default::default()
        };
        let plan = super::Plan::new(b, &opts).unwrap();
        let mut x = 0.3f64;
        // Any coefficients: the real inverse reads one block of each pair.
        let coefs: Vec<Complex64> = (0..plan.num_coeffs())
            .map(|_| {
                x = (x * 3.9 * (1.0 - x)).clamp(1e-3, 1.0 - 1e-3);
                Complex64::new(x - 0.5, 0.25 - x / 2.0)
            })
            .collect();
        let ns = plan.num_samples();
        {
            let mut want = vec![0.0; ns];
            plan.inverse_real(&coefs, &mut want).unwrap();
            for aligned in [true, false] {
                // Doubles from `skip`: 16-byte aligned or only 8 (FFTW's unaligned plans,
                // whose rounding may differ in the last bit).
                let mut raw = vec![f64::NAN; 2 * ns + 1];
                let skip = (0..2)
                    .find(|&k| {
                        (raw.as_ptr().wrapping_add(k) as usize).is_multiple_of(16) == aligned
                    })
                    .unwrap();
                let ptr = raw[skip..].as_mut_ptr() as *mut Complex64;
                // SAFETY: 2 ns doubles from `skip` lie in `raw`; Complex64 needs 8 bytes.
                let out = unsafe { std::slice::from_raw_parts_mut(ptr, ns) };
                plan.engine().inverse_real_to_complex(&coefs, out).unwrap();
                let scale = want.iter().fold(0.0f64, |a, w| a.max(w.abs()));
                let tol = if aligned { 0.0 } else { 1e-15 * scale };
                let ok = out
                    .iter()
                    .zip(&want)
                    .all(|(z, w)| (z.re - w).abs() <= tol && z.im.to_bits() == 0.0f64.to_bits());
                let worst = out
                    .iter()
                    .zip(&want)
                    .map(|(z, w)| (z.re - w).abs().max(z.im.abs()))
                    .fold(0.0f64, f64::max);
                assert!(ok, "B={b} cap={cap:?} aligned={aligned}: {worst:e}");
            }
        }
    }
}

/// An inverse with a watch shows it every beta slice exactly once, with the values the
/// slice holds in the output (complex: rows of a work buffer, padded, or of the output;
/// real: the output slice), complex and real, with one chunk and with several.
#[test]
fn watched_inverse_shows_every_slice_once() {
    use crate::engine::SliceRef;
    use num_complex::Complex64;
    use std::sync::Mutex;
    for (b, cap) in [(12usize, None), (36, Some(1usize))] {
        let opts = super::Options {
            threads: 2,
            real: true,
            max_workspace_bytes: cap,
            ..Default::default()
        };
        let plan = super::Plan::new(b, &opts).unwrap();
        let n = 2 * b;
        let coeffs: Vec<Complex64> = (0..plan.num_coeffs())
            .map(|i| Complex64::new((i as f64 * 0.37).sin(), (i as f64 * 0.71).cos()))
            .collect();
        // Complex: each slice's rows as seen.
        let seen: Mutex<Vec<Option<Vec<Complex64>>>> = Mutex::new(vec![None; n]);
        let watch = |k: usize, s: SliceRef| {
            let SliceRef::Complex {
                values,
                row,
                stride,
            } = s
            else {
                panic!("real slice from the complex inverse")
            };
            assert_eq!(row, n);
            let rows: Vec<Complex64> = (0..n)
                .flat_map(|r| values[r * stride..][..n].iter().copied())
                .collect();
            let old = seen.lock().unwrap()[k].replace(rows);
            assert!(old.is_none(), "B={b}: slice {k} twice");
        };
        let mut out = vec![Complex64::default(); plan.num_samples()];
        plan.engine()
            .inverse_watched(&coeffs, &mut out, &watch)
            .unwrap();
        for (k, s) in seen.into_inner().unwrap().into_iter().enumerate() {
            let s = s.unwrap_or_else(|| panic!("B={b}: slice {k} not shown"));
            assert!(
                s == out[k * n * n..][..n * n],
                "B={b} cap={cap:?}: slice {k}"
            );
        }
        // Real.
        let seen: Mutex<Vec<Option<Vec<f64>>>> = Mutex::new(vec![None; n]);
        let watch = |k: usize, s: SliceRef| {
            let SliceRef::Real(v) = s else {
                panic!("complex slice from the real inverse")
            };
            let old = seen.lock().unwrap()[k].replace(v.to_vec());
            assert!(old.is_none(), "B={b}: real slice {k} twice");
        };
        let mut out = vec![0.0; plan.num_samples()];
        plan.engine()
            .inverse_real_watched(&coeffs, &mut out, &watch)
            .unwrap();
        for (k, s) in seen.into_inner().unwrap().into_iter().enumerate() {
            let s = s.unwrap_or_else(|| panic!("B={b}: real slice {k} not shown"));
            let same = s
                .iter()
                .zip(&out[k * n * n..][..n * n])
                .all(|(a, b)| a.to_bits() == b.to_bits());
            assert!(same, "B={b} cap={cap:?}: real slice {k}");
        }
    }
}
