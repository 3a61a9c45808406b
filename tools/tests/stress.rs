//! The quick subset of the stress suite (`so3fft-stress`, docs/stability.md) as assertions:
//! exact reference values, round trips and Parseval against the accuracy targets, exact
//! scaling by powers of two, subnormal and NaN / Inf inputs, determinism across thread
//! counts, and every instruction set; in `f64` and `f32`. The suite's modules are compiled
//! in from the binary.

#[allow(dead_code)]
#[path = "../src/bin/so3fft-stress/adversarial.rs"]
mod adversarial;
#[allow(dead_code)]
#[path = "../src/bin/so3fft-stress/determinism.rs"]
mod determinism;
#[allow(dead_code)]
#[path = "../src/bin/so3fft-stress/precision.rs"]
mod precision;
#[allow(dead_code)]
#[path = "../src/bin/so3fft-stress/record.rs"]
mod record;
#[allow(dead_code)]
#[path = "../src/bin/so3fft-stress/reference.rs"]
mod reference;
#[allow(dead_code)]
#[path = "../src/bin/so3fft-stress/rng.rs"]
mod rng;
#[allow(dead_code)]
#[path = "../src/bin/so3fft-stress/roundtrip.rs"]
mod roundtrip;

use precision::{Float, Precision};
use record::{Report, Row};
use reference::{
    check_forward, check_inverse, default_data_dir, supported_isas, ForwardKind,
    FORWARD_BANDWIDTHS, INVERSE_BANDWIDTHS, POLES_BANDWIDTHS,
};
use std::time::Duration;

/// The bound on the relative L2 error of the SO(3) round trip in f64.
const TARGET_REL: f64 = 1e-14;
/// The bound on the relative L2 error of every f32 round trip up to B = 512.
const TARGET_REL_F32: f64 = 1e-5;

/// Every row of `report` whose test is `test`.
fn rows<'a>(report: &'a Report, test: &str) -> Vec<&'a Row> {
    report.rows.iter().filter(|r| r.test == test).collect()
}

/// The splitmix64 stream matches the Python generator's (values printed by
/// `gen_stress_reference.py`'s `SplitMix64(1)`).
#[test]
fn prng_matches_the_generator() {
    let mut r = rng::SplitMix64::new(1);
    assert_eq!(r.next_u64(), 0x910a_2dec_8902_5cc1);
    assert_eq!(r.next_u64(), 0xbeeb_8da1_658e_ec67);
}

/// Inverse and forward against the 40-digit values of tests/data/stress, on every
/// instruction set of this CPU, in `T`: relative L2 error below `limit`.
fn exact_reference<T: Float>(limit: f64) {
    let dir = default_data_dir();
    let p = T::PRECISION;
    for isa in supported_isas() {
        for b in INVERSE_BANDWIDTHS {
            let (e, _) = check_inverse::<T>(&dir, b, isa, 2).unwrap();
            assert!(e.rel_l2 <= limit, "{p} inverse B={b} {isa:?}: {e:?}");
        }
        for b in FORWARD_BANDWIDTHS {
            let (e, _) = check_forward::<T>(&dir, b, ForwardKind::Everywhere, isa, 2).unwrap();
            assert!(e.rel_l2 <= limit, "{p} forward B={b} {isa:?}: {e:?}");
        }
        for b in POLES_BANDWIDTHS {
            let (e, _) = check_forward::<T>(&dir, b, ForwardKind::Poles, isa, 2).unwrap();
            assert!(e.rel_l2 <= limit, "{p} poles B={b} {isa:?}: {e:?}");
        }
    }
}

/// The exact reference in f64 (within the round-trip target) and f32 (inputs rounded to
/// f32; single-precision rounding, about 1e-6 at B = 32).
#[test]
fn transforms_match_exact_reference() {
    exact_reference::<f64>(TARGET_REL);
    exact_reference::<f32>(5e-6);
}

/// The quick round trips in `T`: `forward(inverse(c))` within `limits.0`, Parseval within
/// `limits.1`, `inverse(forward(f))` of band-limited `f` within `limits.2`.
fn round_trips<T: Float>(limits: (f64, f64, f64)) {
    let mut report = Report::default();
    let ranges = roundtrip::Ranges {
        full_max: 64,
        partial_max: 128,
        s2_max: 256,
        variants: true,
    };
    roundtrip::run(ranges, 2, &[T::PRECISION], &mut report).unwrap();
    assert!(report.rows.iter().all(|r| r.precision == T::PRECISION));
    for (test, limit) in [
        ("roundtrip", limits.0),
        ("parseval", limits.1),
        ("inv-fwd", limits.2),
    ] {
        let rows = rows(&report, test);
        assert!(rows.len() >= 26, "{test}: {} rows", rows.len());
        for r in rows {
            assert!(r.rel_l2 <= limit, "{r:?}");
        }
    }
}

/// Round trips of the full plan (complex, real, skipping off), order-limited partial plans
/// and S^2 at small B: in f64 `forward(inverse(c))` within the target, Parseval to
/// rounding, and `inverse(forward(f))` of band-limited `f` within 1e-13 (its error grows
/// faster, about B^1.4 for the partial plans; no target); in f32 the round trip within
/// the f32 target, Parseval within 1e-6 and `inverse(forward(f))` within 2e-5.
#[test]
fn round_trips_meet_the_target() {
    round_trips::<f64>((TARGET_REL, 1e-15, 1e-13));
    round_trips::<f32>((TARGET_REL_F32, 1e-6, 2e-5));
}

/// Single coefficients at the top degree and orders (SO(3) and S^2): the inverse matches
/// the closed form, the round trip returns the coefficient.
fn top_orders<T: Float>(inverse_limit: f64, round_trip_limit: f64) {
    let mut report = Report::default();
    for b in [16, 64] {
        adversarial::top_order::<T>(b, 2, &mut report).unwrap();
    }
    for b in [64, 256] {
        adversarial::s2_top_order::<T>(b, 2, &mut report).unwrap();
    }
    for test in ["top-order-inverse", "s2-top-order-inverse"] {
        for r in rows(&report, test) {
            assert!(r.rel_l2 <= inverse_limit, "{r:?}");
        }
    }
    for test in ["top-order-roundtrip", "s2-top-order-roundtrip"] {
        for r in rows(&report, test) {
            assert!(r.rel_l2 <= round_trip_limit, "{r:?}");
        }
    }
}

#[test]
fn top_orders_are_accurate() {
    top_orders::<f64>(1e-14, 1e-15);
    top_orders::<f32>(1e-6, 1e-6);
}

/// `T(2^k x) = 2^k T(x)` bit for bit for every transform kind: in f64 for k up to +-1000
/// (at B = 16 no value leaves the normal range), in f32 for the exponents in range
/// (+-1, +-12, 100); 2^-120 makes f32 values subnormal, so some results must differ.
#[test]
fn scaling_by_powers_of_two_is_exact() {
    for t in adversarial::transforms::<f64>(16, 2).unwrap() {
        for k in Precision::F64.scale_exponents() {
            let s = adversarial::scaling(&t, k).unwrap();
            assert_eq!(
                (s.differing, s.overflowing),
                (0, 0),
                "{} k={k}: {s:?}",
                t.name
            );
        }
    }
    for t in adversarial::transforms::<f32>(16, 2).unwrap() {
        for k in Precision::F32.scale_exponents() {
            let s = adversarial::scaling(&t, k).unwrap();
            if Precision::F32.scale_in_range(k) {
                assert_eq!(
                    (s.differing, s.overflowing),
                    (0, 0),
                    "{} k={k}: {s:?}",
                    t.name
                );
            }
            if k == -120 {
                assert!(s.differing > 0, "{} k={k}: {s:?}", t.name);
            }
        }
    }
}

/// Subnormal inputs give finite results, accurate to the bits the inputs keep (f64:
/// `2^-1040 x` keeps about 34 bits; f32: `2^-136 x` about 13, and products in the kernels
/// lose more).
#[test]
fn subnormal_inputs_stay_finite() {
    let mut report = Report::default();
    adversarial::subnormal_rows::<f64>(16, 2, &mut report).unwrap();
    adversarial::subnormal_rows::<f32>(16, 2, &mut report).unwrap();
    assert_eq!(report.rows.len(), 20);
    for r in &report.rows {
        assert!(r.note.ends_with("; finite"), "{r:?}");
        let limit = match r.precision {
            Precision::F64 => 1e-6,
            Precision::F32 => 3e-2,
        };
        assert!(r.rel_l2 <= limit, "{r:?}");
    }
}

/// One NaN or infinite input value: every transform returns (no hang, no error), and
/// the documented propagation holds (docs/stability.md): a poisoned value the transform
/// reads reaches some output; with skipping off a NaN reaches every output; a NaN in the
/// coefficient `(1, 0, 0)` reaches every sample (its Wigner d is nowhere negligible); a
/// real inverse ignores a poisoned coefficient in a block it does not read. (With
/// skipping on, outputs whose Wigner-d factor for the poisoned input is below the skip
/// threshold stay finite: the contribution is skipped, not multiplied.)
fn nan_and_inf<T: Float>() {
    for t in adversarial::transforms::<T>(16, 2).unwrap() {
        let name = t.name;
        let t = std::sync::Arc::new(t);
        for poison in adversarial::POISONS {
            let what = format!("{} {name} {}", T::PRECISION, poison.name);
            let timeout = Duration::from_secs(30);
            let counts = adversarial::poisoned::<T>(t.clone(), poison, timeout)
                .unwrap_or_else(|| panic!("{what}: no result after 30 s"))
                .unwrap()
                .0;
            let total = counts.nan + counts.inf + counts.finite;
            let is_nan = poison.value.re.is_nan();
            let unread =
                name == "so3-real-inverse" && matches!(poison.at, adversarial::PoisonSite::Last);
            if unread {
                assert_eq!(counts.finite, total, "{what}");
                continue;
            }
            assert!(counts.finite < total, "{what}: {counts:?}");
            if is_nan && name.ends_with("-noskip") {
                assert_eq!(counts.nan, total, "{what}: {counts:?}");
            }
            let low = matches!(poison.at, adversarial::PoisonSite::Low);
            if is_nan && low && name.contains("inverse") {
                assert_eq!(counts.nan, total, "{what}: {counts:?}");
            }
        }
    }
}

#[test]
fn nan_and_inf_propagate_as_documented() {
    nan_and_inf::<f64>();
    nan_and_inf::<f32>();
}

/// Every plan kind gives identical bits on 1, 2 and 4 threads and across executes, in
/// both precisions.
#[test]
fn results_do_not_depend_on_threads() {
    for kind in determinism::KINDS {
        let (outcome, _) = determinism::check::<f64>(kind, 32).unwrap();
        assert!(outcome.identical(), "f64 {kind:?}: {outcome:?}");
        let (outcome, _) = determinism::check::<f32>(kind, 32).unwrap();
        assert!(outcome.identical(), "f32 {kind:?}: {outcome:?}");
    }
}

/// Every instruction set meets the target of `T`, with errors of the same size (within 2x).
fn isa_agreement<T: Float>(limit: f64) {
    let mut report = Report::default();
    let bw = reference::IsaBandwidths {
        so3: 32,
        partial: 64,
        s2: 128,
    };
    reference::isa_roundtrips::<T>(bw, 2, &mut report).unwrap();
    for prefix in ["so3-", "partial-m8-", "s2-"] {
        let errs: Vec<f64> = report
            .rows
            .iter()
            .filter(|r| r.variant.starts_with(prefix))
            .map(|r| r.rel_l2)
            .collect();
        let (lo, hi) = errs
            .iter()
            .fold((f64::INFINITY, 0.0f64), |(a, b), &e| (a.min(e), b.max(e)));
        assert!(hi <= limit, "{prefix}: {errs:?}");
        assert!(hi <= 2.0 * lo, "{prefix}: {errs:?}");
    }
}

#[test]
fn instruction_sets_agree() {
    isa_agreement::<f64>(TARGET_REL);
    isa_agreement::<f32>(TARGET_REL_F32);
}
