//! Error reporting and index helpers (closed-form values of docs/conventions.md, coefficient layout).

mod common;

use common::*;
use so3fft::{Complex64, Direction, Error, Options, Plan, MAX_BANDWIDTH};

fn opts() -> Options {
    Options::default()
}

#[test]
fn invalid_bandwidth() {
    match Plan::<f64>::new(0, &opts()) {
        Err(Error::InvalidBandwidth { bandwidth, max }) => {
            assert_eq!(bandwidth, 0);
            assert_eq!(max, MAX_BANDWIDTH);
        }
        Err(e) => panic!("Plan::<f64>::new(0): expected InvalidBandwidth, got {e:?}"),
        Ok(_) => panic!("Plan::<f64>::new(0) succeeded"),
    }
    match Plan::<f64>::new(MAX_BANDWIDTH + 1, &opts()) {
        Err(Error::InvalidBandwidth { bandwidth, max }) => {
            assert_eq!(bandwidth, MAX_BANDWIDTH + 1);
            assert_eq!(max, MAX_BANDWIDTH);
        }
        Err(e) => panic!("Plan::<f64>::new(MAX+1): expected InvalidBandwidth, got {e:?}"),
        Ok(_) => panic!("Plan::<f64>::new(MAX_BANDWIDTH+1) succeeded"),
    }
    // the error must be displayable
    let e = Plan::<f64>::new(0, &opts()).err().unwrap();
    assert!(!format!("{e}").is_empty());
    let _: &dyn std::error::Error = &e;
}

#[test]
fn length_mismatch_leaves_output_untouched() {
    let b = 4;
    let p = Plan::<f64>::new(b, &opts()).unwrap();
    let (ns, nc) = (n_samples(b), n_coeffs(b));
    let sentinel = Complex64::new(12345.0, -678.0);
    let good_s = vec![Complex64::new(0.5, 0.25); ns];
    let good_c = vec![Complex64::new(0.5, 0.25); nc];
    let is_mismatch =
        |r: so3fft::Result<so3fft::StageTimes>| matches!(r, Err(Error::LengthMismatch { .. }));
    // forward: wrong input length (short and long), wrong output length
    for (sl, cl) in [
        (ns - 1, nc),
        (ns + 1, nc),
        (ns, nc - 1),
        (ns, nc + 1),
        (0, nc),
        (ns, 0),
    ] {
        let s = vec![Complex64::new(1.0, 0.0); sl];
        let mut c = vec![sentinel; cl];
        let r = p.forward(&s, &mut c);
        assert!(
            is_mismatch(r.clone()),
            "forward with lengths ({sl},{cl}): expected LengthMismatch, got {r:?}"
        );
        assert!(
            c.iter().all(|&x| x == sentinel),
            "forward with lengths ({sl},{cl}) modified the output buffer"
        );
    }
    for (cl, sl) in [
        (nc - 1, ns),
        (nc + 1, ns),
        (nc, ns - 1),
        (nc, ns + 1),
        (0, ns),
        (nc, 0),
    ] {
        let c = vec![Complex64::new(1.0, 0.0); cl];
        let mut s = vec![sentinel; sl];
        let r = p.inverse(&c, &mut s);
        assert!(
            is_mismatch(r.clone()),
            "inverse with lengths ({cl},{sl}): expected LengthMismatch, got {r:?}"
        );
        assert!(
            s.iter().all(|&x| x == sentinel),
            "inverse with lengths ({cl},{sl}) modified the output buffer"
        );
    }
    // the reported numbers
    let mut c = vec![sentinel; nc];
    match p.forward(&good_s[..ns - 3], &mut c) {
        Err(Error::LengthMismatch { expected, got, .. }) => {
            assert_eq!(expected, ns);
            assert_eq!(got, ns - 3);
        }
        r => panic!("expected LengthMismatch, got {r:?}"),
    }
    // timed variants check as well
    let mut s = vec![sentinel; ns + 2];
    assert!(matches!(
        p.inverse(&good_c, &mut s),
        Err(Error::LengthMismatch { .. })
    ));
    assert!(s.iter().all(|&x| x == sentinel));
    let mut c = vec![sentinel; nc + 2];
    assert!(matches!(
        p.forward(&good_s, &mut c),
        Err(Error::LengthMismatch { .. })
    ));
    assert!(c.iter().all(|&x| x == sentinel));
    // and a correct call still works after the errors
    let mut c = vec![sentinel; nc];
    p.forward(&good_s, &mut c).unwrap();
    let t = p.forward(&good_s, &mut c).unwrap();
    assert!(t.total >= 0.0 && t.fft >= 0.0 && t.dwt >= 0.0);
}

#[test]
fn wrong_direction() {
    let b = 4;
    let (ns, nc) = (n_samples(b), n_coeffs(b));
    let sentinel = Complex64::new(-3.0, 7.0);
    let pi = Plan::<f64>::new(b, &opts().with_direction(Direction::Inverse)).unwrap();
    let s = vec![Complex64::new(1.0, 0.0); ns];
    let mut c = vec![sentinel; nc];
    let r = pi.forward(&s, &mut c);
    assert_eq!(r, Err(Error::WrongDirection), "forward on an Inverse plan");
    assert!(
        c.iter().all(|&x| x == sentinel),
        "forward on an Inverse plan modified the output"
    );
    assert!(matches!(pi.forward(&s, &mut c), Err(Error::WrongDirection)));
    // inverse on the inverse plan works
    pi.inverse(&c, &mut vec![Complex64::new(0.0, 0.0); ns])
        .unwrap();

    let pf = Plan::<f64>::new(b, &opts().with_direction(Direction::Forward)).unwrap();
    let c = vec![Complex64::new(1.0, 0.0); nc];
    let mut s = vec![sentinel; ns];
    let r = pf.inverse(&c, &mut s);
    assert_eq!(r, Err(Error::WrongDirection), "inverse on a Forward plan");
    assert!(
        s.iter().all(|&x| x == sentinel),
        "inverse on a Forward plan modified the output"
    );
    assert!(matches!(pf.inverse(&c, &mut s), Err(Error::WrongDirection)));
    pf.forward(&s, &mut vec![Complex64::new(0.0, 0.0); nc])
        .unwrap();
}

#[test]
fn try_coef_index_errors() {
    let b = 8;
    let bad: [(usize, isize, isize); 8] = [
        (3, 4, 0),
        (3, 0, -4),
        (3, -4, -4),
        (0, 1, 0),
        (8, 0, 0),
        (9, 1, 1),
        (8, 8, 8),
        (7, 8, 0),
    ];
    for (l, m, mp) in bad {
        let r = so3fft::try_coef_index(b, l, m, mp);
        assert!(
            r.is_err(),
            "try_coef_index({b},{l},{m},{mp}) = {r:?}, expected an error"
        );
        if let Err(e) = &r {
            assert!(
                matches!(e, Error::InvalidArgument(_)),
                "try_coef_index({b},{l},{m},{mp}): unexpected error kind {e:?}"
            );
        }
    }
    assert!(
        so3fft::try_coef_index(0, 0, 0, 0).is_err(),
        "try_coef_index with B = 0"
    );
    assert_eq!(
        so3fft::try_coef_index(b, 7, -7, 7),
        Ok(so3fft::coef_index(b, 7, -7, 7))
    );
}

/// Address-space limit for the child process that builds the MAX_BANDWIDTH plan. A plan must not
/// allocate the (2B)^3 sample grid (1 TiB at B = 2048); a few GiB for tables, FFTW plans and the
/// default beta-chunk workspace are plenty.
const CHILD_AS_LIMIT_KIB: u64 = 8 * 1024 * 1024; // 8 GiB

/// Plan::<f64>::new(MAX_BANDWIDTH) must either succeed or return OutOfMemory, without panicking or
/// aborting. It runs in a child process (this test binary, running the ignored test below) under
/// `ulimit -v` so that a plan which over-allocates gets a failed allocation instead of eating the
/// machine's memory. An over-allocating library that uses infallible allocation aborts the child;
/// that is reported as a failure.
#[test]
fn max_bandwidth_plan_does_not_panic() {
    let exe = std::env::current_exe().expect("current_exe");
    let t0 = std::time::Instant::now();
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg(format!("ulimit -v {CHILD_AS_LIMIT_KIB} && exec timeout 300 \"$0\" --exact child_max_bandwidth_plan --ignored --nocapture --test-threads=1"))
        .arg(&exe)
        .env("SO3FFT_LIMITED_CHILD", "1")
        .output()
        .expect("spawn child test process");
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);
    println!(
        "child ({:.1}s, status {:?}):\n{stdout}",
        t0.elapsed().as_secs_f64(),
        out.status
    );
    let tail: String = stderr
        .lines()
        .rev()
        .take(15)
        .collect::<Vec<_>>()
        .into_iter()
        .rev()
        .collect::<Vec<_>>()
        .join("\n");
    assert!(
        out.status.success() && stdout.contains("CHILD-RESULT:"),
        "Plan::<f64>::new(MAX_BANDWIDTH = {}) under a {} GiB address-space limit did not return Ok/OutOfMemory cleanly \
         (exit status {:?}; a signal means abort/kill, e.g. an infallible allocation failed).\nchild stdout:\n{stdout}\nchild stderr (tail):\n{tail}",
        MAX_BANDWIDTH,
        CHILD_AS_LIMIT_KIB / (1024 * 1024),
        out.status
    );
}

#[test]
#[ignore = "run only as the memory-limited child of max_bandwidth_plan_does_not_panic"]
fn child_max_bandwidth_plan() {
    if std::env::var("SO3FFT_LIMITED_CHILD").ok().as_deref() != Some("1") {
        println!("skipped: only runs under the address-space limit set by max_bandwidth_plan_does_not_panic");
        return;
    }
    let t0 = std::time::Instant::now();
    let r = std::panic::catch_unwind(|| {
        Plan::<f64>::new(MAX_BANDWIDTH, &Options::default())
            .map(|p| (p.bandwidth(), p.num_samples(), p.num_coeffs()))
    });
    match r {
        Err(_) => panic!("Plan::<f64>::new(MAX_BANDWIDTH) panicked"),
        Ok(Ok((bw, ns, nc))) => {
            assert_eq!(bw, MAX_BANDWIDTH);
            assert_eq!(ns, n_samples(MAX_BANDWIDTH));
            assert_eq!(nc, n_coeffs(MAX_BANDWIDTH));
            println!(
                "CHILD-RESULT: Plan::<f64>::new(MAX_BANDWIDTH={MAX_BANDWIDTH}) succeeded in {:.2}s",
                t0.elapsed().as_secs_f64()
            );
        }
        Ok(Err(Error::OutOfMemory { bytes })) => {
            println!(
                "CHILD-RESULT: Plan::<f64>::new(MAX_BANDWIDTH) -> OutOfMemory {{ bytes: {bytes} }}"
            )
        }
        Ok(Err(e)) => panic!("Plan::<f64>::new(MAX_BANDWIDTH) returned unexpected error {e:?}"),
    }
}

/// A small workspace cap must still give a correct plan (or be rejected with an error).
#[test]
fn tiny_workspace_cap() {
    let b = 16;
    match Plan::<f64>::new(b, &Options::default().with_max_workspace_bytes(Some(4096))) {
        Ok(p) => {
            let mut rng = Rng::new(5);
            let c = rng.complex_vec(n_coeffs(b));
            let mut f = vec![Complex64::new(0.0, 0.0); n_samples(b)];
            p.inverse(&c, &mut f).unwrap();
            let mut c2 = vec![Complex64::new(0.0, 0.0); n_coeffs(b)];
            p.forward(&f, &mut c2).unwrap();
            let (e, _) = max_abs_diff(&c, &c2);
            println!("B={b} with max_workspace_bytes=4096: roundtrip err {e:.3e}");
            assert!(e <= 1e-13, "roundtrip with tiny workspace cap: {e:e}");
        }
        Err(e) => println!("note: B={b} with max_workspace_bytes=4096 rejected: {e:?}"),
    }
}

// ---- index helpers ----------------------------------------------------------------------------

#[test]
fn coef_index_spec_spot_values_b256() {
    let b = 256;
    // (M, M', l) -> index, from docs/conventions.md (coefficient layout)
    let cases: [(isize, isize, usize, usize); 7] = [
        (0, 0, 0, 0),
        (0, 0, 255, 255),
        (0, 1, 1, 256),
        (0, -1, 1, 65281),
        (1, 0, 1, 65536),
        (-1, 0, 1, 22304001),
        (-1, -1, 255, 22369535),
    ];
    for (m, mp, l, want) in cases {
        assert_eq!(
            so3fft::coef_index(b, l, m, mp),
            want,
            "coef_index(B=256, l={l}, M={m}, M'={mp})"
        );
        assert_eq!(
            so3fft::try_coef_index(b, l, m, mp),
            Ok(want),
            "try_coef_index(B=256, l={l}, M={m}, M'={mp})"
        );
    }
    assert_eq!(so3fft::num_coeffs(b), 22369536);
    assert_eq!(so3fft::num_coeffs(b), n_coeffs(b));
}

#[test]
fn coef_index_bijection_and_layout() {
    for b in 1..=12usize {
        let n = so3fft::num_coeffs(b);
        assert_eq!(n, n_coeffs(b), "num_coeffs({b})");
        let lay = Layout::new(b);
        let mut seen = vec![false; n];
        for (l, m, mp) in triples(b) {
            let i = so3fft::coef_index(b, l, m, mp);
            assert!(i < n, "coef_index({b},{l},{m},{mp}) = {i} out of range {n}");
            assert!(!seen[i], "coef_index({b},{l},{m},{mp}) = {i} duplicated");
            seen[i] = true;
            assert_eq!(
                i,
                lay.idx(l, m, mp),
                "coef_index({b},{l},{m},{mp}) differs from SOFT block order"
            );
            assert_eq!(so3fft::try_coef_index(b, l, m, mp), Ok(i));
        }
        assert!(seen.iter().all(|&s| s), "B={b}: not onto");
    }
}

#[test]
fn sample_index_and_grid_helpers() {
    for b in [1usize, 2, 5, 8] {
        let n = 2 * b;
        assert_eq!(so3fft::num_samples(b), n * n * n);
        for k in 0..n {
            for j1 in 0..n {
                for j2 in 0..n {
                    assert_eq!(
                        so3fft::sample_index(b, j1, k, j2),
                        k * n * n + j1 * n + j2,
                        "sample_index({b}, j1={j1}, k={k}, j2={j2})"
                    );
                }
            }
        }
        let pi = std::f64::consts::PI;
        for j in 0..n {
            let a = pi * j as f64 / b as f64;
            assert!(
                (so3fft::alpha(b, j) - a).abs() <= 4.0 * f64::EPSILON,
                "alpha({b},{j})"
            );
            assert!(
                (so3fft::gamma(b, j) - a).abs() <= 4.0 * f64::EPSILON,
                "gamma({b},{j})"
            );
            assert!(
                (so3fft::beta(b, j) - grid_beta(b, j)).abs() <= 4.0 * f64::EPSILON,
                "beta({b},{j})"
            );
        }
    }
}

/// Skip thresholds outside the documented range are rejected (0 means "no skipping").
#[test]
fn invalid_skip_bits() {
    for bits in [1u32, 23, 561, 10_000] {
        let r = Plan::<f64>::new(4, &Options::default().with_skip_bits(Some(bits)));
        assert!(
            matches!(r, Err(Error::InvalidArgument(_))),
            "skip_bits {bits}"
        );
    }
}

/// With the default workspace a plan needs at most 5% beyond the caller's arrays at
/// B = 512 (issue 5: a complex forward at B = 512 must run in input + output + 5%), and
/// `memory_bytes` covers the chunk buffer. Planning only: nothing of grid size is touched.
#[test]
fn default_plan_memory_within_five_percent_at_512() {
    let b = 512;
    let options = Options::default().with_direction(Direction::Forward);
    let estimate = Plan::<f64>::memory_needed(b, &options).unwrap();
    match Plan::<f64>::new(b, &options) {
        Ok(plan) => {
            let arrays = (plan.num_samples() + plan.num_coeffs()) * 16;
            let ratio = plan.memory_bytes() as f64 / arrays as f64;
            // The estimate made before planning is what the plan holds (unless the memory
            // available changed in between by enough to move the default).
            let rel = (estimate as f64 - plan.memory_bytes() as f64).abs() / estimate as f64;
            assert!(
                rel < 0.05,
                "estimate {estimate}, plan {}",
                plan.memory_bytes()
            );
            println!(
                "B = 512: plan {} MiB (workspace {} MiB), {:.2}% of the arrays",
                plan.memory_bytes() >> 20,
                plan.workspace_bytes() >> 20,
                100.0 * ratio
            );
            assert!(
                ratio <= 0.05,
                "plan memory {:.2}% of the arrays",
                100.0 * ratio
            );
            assert!(plan.workspace_bytes() < plan.memory_bytes());
        }
        // A machine with little memory: the plan refuses cleanly, which is also correct.
        Err(Error::OutOfMemory { .. }) => println!("B = 512 plan refused: out of memory"),
        Err(e) => panic!("unexpected error {e:?}"),
    }
}

/// `Plan::memory_needed` validates like `Plan::new` and predicts `memory_bytes` exactly for
/// small plans (whose default workspace does not depend on the available memory), for both
/// layouts and explicit workspace caps.
#[test]
fn memory_estimate_matches_plans() {
    for b in [1usize, 7, 24, 64] {
        for real in [false, true] {
            for cap in [None, Some(1usize << 20), Some(64 << 20)] {
                let options = Options::default()
                    .with_real(real)
                    .with_threads(2)
                    .with_max_workspace_bytes(cap);
                let estimate = Plan::<f64>::memory_needed(b, &options).unwrap();
                let plan = Plan::<f64>::new(b, &options).unwrap();
                assert_eq!(
                    estimate,
                    plan.memory_bytes(),
                    "B={b} real={real} cap={cap:?}"
                );
                assert!(plan.workspace_bytes() < plan.memory_bytes());
                if let Some(cap) = cap {
                    // The documented formula (`Plan::workspace_bytes`), written out here:
                    // rows of d doubles per beta (16 per 8-member cluster, 8 per other:
                    // 8B^2 - 8B + 8; the real rows 4B^2 + 4B) padded to an odd number of
                    // cache lines; two rows per pair; the cap holds `room` pairs, a whole
                    // number of vectors of them where it holds one; the B pairs spread
                    // evenly over the fewest chunks of at most that, rounded up to the
                    // vector width where that still fits; the buffer holds each chunk
                    // rounded up to the vector width. It is the larger of the two.
                    let w = plan.isa().lanes();
                    let bytes = |d: usize| {
                        let rs = if (d / 8).is_multiple_of(2) { d + 8 } else { d };
                        let room = cap / (16 * rs);
                        let fit = if room >= w { room / w * w } else { room }.clamp(1, b);
                        let mut h = b.div_ceil(b.div_ceil(fit));
                        if h >= w && h.next_multiple_of(w) <= fit {
                            h = h.next_multiple_of(w);
                        }
                        16 * rs * h.next_multiple_of(w)
                    };
                    let mut want = bytes(8 * b * b - 8 * b + 8);
                    if real {
                        want = want.max(bytes(4 * b * b + 4 * b));
                    }
                    assert_eq!(plan.workspace_bytes(), want, "B={b} real={real} cap={cap}");
                }
            }
        }
    }
    assert!(matches!(
        Plan::<f64>::memory_needed(0, &Options::default()),
        Err(Error::InvalidBandwidth { .. })
    ));
    assert!(Plan::<f64>::memory_needed(8, &Options::default().with_skip_bits(Some(7))).is_err());
}
