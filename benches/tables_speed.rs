//! Time of the plan-time tables and the per-cluster setup of the DWT stage (measures,
//! asserts nothing): the tables at large bandwidths, the recurrence coefficients and the
//! starting values of every cluster.
//!
//! Run: `cargo bench --features internals --bench tables_speed`

use so3fft::internals::{start_norms, BetaTables, Ext, RecCoeffs, RecTables};
use so3fft::{weights, Isa, Real};

fn main() {
    table_build_speed();
    coeffs_speed();
    for isa in [Isa::Avx512, Isa::Avx2, Isa::Scalar] {
        if isa.is_supported() {
            starts_speed::<f64>(isa);
            starts_speed::<f32>(isa);
        }
    }
}

/// Time of the plan's tables at large bandwidths.
fn table_build_speed() {
    for b in [512usize, 2048] {
        let t = std::time::Instant::now();
        let n = start_norms(b);
        let t1 = t.elapsed().as_secs_f64();
        let bt = BetaTables::grid(b);
        let t2 = t.elapsed().as_secs_f64();
        let rt = RecTables::new(b);
        let t3 = t.elapsed().as_secs_f64();
        let w = weights(b);
        let t4 = t.elapsed().as_secs_f64();
        std::hint::black_box((&n, &bt, &rt, &w));
        println!(
            "B = {b}: start_norms {t1:.3} s, BetaTables {:.3} s, RecTables {:.3} s, \
             weights {:.3} s",
            t2 - t1,
            t3 - t2,
            t4 - t3
        );
    }
}

/// Time of the coefficients of every cluster at B = 256 (one chunk's worth).
fn coeffs_speed() {
    let b = 256;
    let rt = RecTables::new(b);
    let mut r = RecCoeffs::new(b);
    let mut best = f64::MAX;
    for _ in 0..7 {
        let t = std::time::Instant::now();
        for m in 0..b {
            for mp in 0..=m {
                r.resize(b - m);
                rt.coeffs(m, mp, &mut r);
            }
        }
        best = best.min(t.elapsed().as_secs_f64());
        std::hint::black_box(&r);
    }
    println!("coeffs for all clusters of B = {b}: {:.2} ms", best * 1e3);
}

/// Time of the starting values of every cluster at B = 256, two halves of 51 points
/// per cluster and chunk, five chunks (what a plan with the default workspace does), in
/// element type `T` with the instruction set `isa`.
fn starts_speed<T: Real>(isa: Isa) {
    let b = 256;
    let bt = BetaTables::grid(b);
    let norm = Ext { mant: 0.5, exp: 0 };
    let h = 51;
    let (mut p, mut sc) = (vec![T::default(); h], vec![T::default(); h]);
    let mut best = f64::MAX;
    for _ in 0..5 {
        let t = std::time::Instant::now();
        for lo in (0..b).step_by(h) {
            let h = h.min(b - lo);
            for m in 0..b {
                for mp in 0..=m {
                    for k0 in [lo, 2 * b - lo - h] {
                        bt.starts(isa, k0, m, mp, norm, 64, &mut p[..h], &mut sc[..h]);
                    }
                }
            }
        }
        best = best.min(t.elapsed().as_secs_f64());
        std::hint::black_box(&p);
    }
    println!(
        "starts for all clusters and chunks of B = {b} ({}, {isa:?}): {:.2} ms",
        std::any::type_name::<T>(),
        best * 1e3
    );
}
