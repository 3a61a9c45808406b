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
        &CorrelationOptions {
            real: c.real,
            threads: 2,
            b_out,
            ..Default::default()
        },
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
    let opts = |b_out, deg_lim| CorrelationOptions {
        b_out,
        deg_lim,
        ..Default::default()
    };
    assert!(Correlation::new(0, &opts(None, None)).is_err());
    assert!(Correlation::new(8, &opts(Some(4), Some(4))).is_err());
    assert!(Correlation::new(8, &opts(None, Some(8))).is_err());
    let plan = Correlation::new(4, &opts(None, None)).unwrap();
    let s = vec![Complex64::default(); 64];
    let mut out = vec![Complex64::default(); plan.num_grid()];
    assert!(plan.correlate(&s[..63], &s, &mut out).is_err());
    assert!(plan.correlate(&s, &s, &mut out[1..]).is_err());
    assert!(plan
        .correlate_real(&[0.0; 64], &[0.0; 64], &mut [0.0; 512])
        .is_err());
}
