//! Throughput of the DWT kernels (measures, asserts nothing): one cluster at a time
//! against the FMA peak of one core, and the kernel time summed over every cluster of a
//! bandwidth.
//!
//! Run: `cargo bench --features internals --bench kernel_speed [-- --isa avx2]`
//! (the kernels of the best instruction set unless `--isa avx512|avx2` names one; the peak
//! is measured with the same vectors; the skip threshold follows `SO3FFT_SKIP_BITS` if set).

use so3fft::internals::{
    aligned, cluster_pairs, cluster_setup, fma_peak, forward, forward_parity, grid_lanes, inverse,
    inverse_parity, parity_partial_len, ClusterInputs, Rec,
};
use so3fft::Isa;

fn main() {
    let isa = isa_arg();
    println!(
        "{isa:?} kernels; FMA peak of one core: {:.1} GFLOP/s",
        fma_peak(isa)
    );
    kernel_gflops(isa);
    parity_times(isa);
    all_clusters_gflops(isa);
}

/// The S^2 parity kernels (`m' = 0`, the B northern rings) in f64 and f32, best of 7
/// batches of 20 calls, measured in alternation.
fn parity_times(isa: Isa) {
    for &(b, m) in &[(256usize, 40usize), (512, 100), (1024, 300)] {
        let n = b - m;
        let mut ci = cluster_setup(b, m, 0, 2 * b);
        for v in [&mut ci.tau, &mut ci.p, &mut ci.sc] {
            v.truncate(b);
        }
        let ci32 = ci.to_f32();
        let rec = Rec::new(&ci.coeffs, n);
        let mut lanes = grid_lanes(&ci.tau, &ci.p, &ci.sc, b);
        let rec32 = ci32.rec(n);
        let mut lanes32 = ci32.lanes(b);
        (lanes.interleaved, lanes.stream) = (false, false);
        (lanes32.interleaved, lanes32.stream) = (false, false);
        let (w, w32) = (isa.lanes(), 2 * isa.lanes());
        for c in [2usize, 4] {
            let (fin, fin32) = (vec![0.5; n * c], vec![0.5f32; n * c]);
            let (x, x32) = (vec![0.5; 2 * c * b], vec![0.5f32; 2 * c * b]);
            let (mut y, mut y32) = (vec![0.0; 2 * c * b], vec![0.0f32; 2 * c * b]);
            let mut part = vec![0.0; parity_partial_len(n, c, w)];
            let mut ft = vec![0.0; (n * c).next_multiple_of(w)];
            let mut part32 = vec![0.0f32; parity_partial_len(n, c, w32)];
            let mut ft32 = vec![0.0f32; (n * c).next_multiple_of(w32)];
            let mut best = [f64::INFINITY; 4];
            for _ in 0..7 {
                let mut time = |k: usize, f: &mut dyn FnMut()| {
                    let t = std::time::Instant::now();
                    for _ in 0..20 {
                        f();
                    }
                    best[k] = best[k].min(t.elapsed().as_secs_f64() / 20.0);
                };
                time(0, &mut || {
                    inverse_parity(isa, c, &rec, &lanes, &fin, &mut y)
                });
                time(1, &mut || {
                    inverse_parity(isa, c, &rec32, &lanes32, &fin32, &mut y32)
                });
                time(2, &mut || {
                    forward_parity(isa, c, &rec, &lanes, &x, (&mut part, &mut ft))
                });
                time(3, &mut || {
                    forward_parity(isa, c, &rec32, &lanes32, &x32, (&mut part32, &mut ft32))
                });
            }
            println!(
                "parity B={b} m={m} C={c}: inverse {:.1} us, f32/f64 {:.2}; forward {:.1} us, f32/f64 {:.2}",
                best[0] * 1e6,
                best[1] / best[0],
                best[2] * 1e6,
                best[3] / best[2]
            );
        }
    }
}

/// The instruction set `--isa NAME` names (default: the best this CPU has).
fn isa_arg() -> Isa {
    let args: Vec<String> = std::env::args().collect();
    let name = args
        .iter()
        .position(|a| a == "--isa")
        .and_then(|k| args.get(k + 1));
    let isa = match name.map(String::as_str) {
        None => Isa::detect(),
        Some("avx512") => Isa::Avx512,
        Some("avx2") => Isa::Avx2,
        Some(other) => {
            eprintln!("kernel_speed: --isa takes avx512 or avx2, not {other}");
            std::process::exit(2)
        }
    };
    if !isa.is_supported() {
        eprintln!("kernel_speed: this CPU does not support {isa:?}");
        std::process::exit(2)
    }
    isa
}

/// Kernel-only throughput: GFLOP/s of the fused
/// recurrence + accumulation for one generic cluster, all 2B grid betas, against the
/// FMA peak. Forward, inverse and the peak are measured in alternation and each keeps
/// its best batch: the machine is shared and noisy.
fn kernel_gflops(isa: Isa) {
    // (B, betas, columns, m): m = B / 8 has long negligible prefixes near the poles,
    // m = 2 nearly none (the fast phase alone).
    for &(b, nbs, pw, m) in &[
        (256usize, 512usize, 16usize, 32usize),
        (256, 128, 16, 32),
        (128, 256, 16, 16),
        (256, 512, 8, 32),
        (256, 512, 16, 2),
        (256, 512, 8, 2),
    ] {
        let mp = m / 2;
        let n = b - m;
        let inputs = cluster_setup(b, m, mp, nbs);
        let ci = inputs.to_f32();
        let ClusterInputs {
            coeffs: rc,
            tau: x,
            p,
            sc,
        } = inputs;
        let rec = Rec::new(&rc, n);
        let lanes = grid_lanes(&x, &p, &sc, nbs / 2);
        let (rec32, lanes32) = (ci.rec(n), ci.lanes(nbs / 2));
        let xbuf = vec![0.5; nbs * 16 + 8];
        let xin = aligned(&xbuf, nbs * 16);
        let xbuf32 = vec![0.5f32; nbs * 16 + 16];
        let xin32 = aligned(&xbuf32, nbs * 16);
        let mut f = vec![0.0; (n + 8) * 16];
        let mut y = vec![0.0; nbs * 16];
        let mut f32s = vec![0.0f32; (n + 16) * 16];
        let mut y32 = vec![0.0f32; nbs * 16];
        let batch = |f: &mut dyn FnMut()| {
            let t = std::time::Instant::now();
            for _ in 0..50 {
                f();
            }
            t.elapsed().as_secs_f64() / 50.0
        };
        let mut best = [f64::INFINITY; 4];
        let mut peak = 0.0f64;
        for _ in 0..7 {
            best[0] = best[0].min(batch(&mut || {
                forward(isa, pw, &rec, &lanes, xin, &mut f);
            }));
            best[1] = best[1].min(batch(&mut || {
                inverse(
                    isa,
                    pw,
                    &rec,
                    &lanes,
                    &mut f[..n * pw],
                    &mut |_, _, _| {},
                    &mut y,
                )
            }));
            best[2] = best[2].min(batch(&mut || {
                forward(isa, pw, &rec32, &lanes32, xin32, &mut f32s);
            }));
            best[3] = best[3].min(batch(&mut || {
                inverse(
                    isa,
                    pw,
                    &rec32,
                    &lanes32,
                    &mut f32s[..n * pw],
                    &mut |_, _, _| {},
                    &mut y32,
                )
            }));
            peak = peak.max(fma_peak(isa));
        }
        let flops = (n * nbs * pw * 2) as f64;
        let [gf, gi] = [flops / best[0] / 1e9, flops / best[1] / 1e9];
        println!(
            "B={b} nb={nbs} L={n} P={pw} m={m}: forward {gf:.1} GFLOP/s ({:.0}%), inverse {gi:.1} GFLOP/s ({:.0}%), peak {peak:.1}; f32/f64 time: forward {:.2}, inverse {:.2}",
            100.0 * gf / peak,
            100.0 * gi / peak,
            best[2] / best[0],
            best[3] / best[1]
        );
    }
}

/// Kernel time summed over every cluster of a bandwidth (all 2B betas as one chunk),
/// against the nominal DWT flop count.
fn all_clusters_gflops(isa: Isa) {
    for b in [128usize, 256] {
        let nbs = 2 * b;
        let (mut tf, mut ti) = (0.0, 0.0);
        let mut qt = [0.0f64; 4];
        let mut qtf = [0.0f64; 4];
        let mut qf = [0.0f64; 4];
        let xbuf = vec![0.5; nbs * 16 + 8];
        let xin = aligned(&xbuf, nbs * 16);
        let mut f = vec![0.0; (b + 8) * 16];
        let mut y = vec![0.0; nbs * 16];
        for (m, mp) in cluster_pairs(b) {
            let (m, mp) = (m as usize, mp as usize);
            let n = b - m;
            let ClusterInputs {
                coeffs: rc,
                tau: x,
                p,
                sc,
            } = cluster_setup(b, m, mp, nbs);
            let rec = Rec::new(&rc, n);
            let lanes = grid_lanes(&x, &p, &sc, b);
            let pw = if m == mp || mp == 0 { 8 } else { 16 };
            let t = std::time::Instant::now();
            forward(isa, pw, &rec, &lanes, xin, &mut f[..(n + 8) * pw]);
            let dt = t.elapsed().as_secs_f64();
            tf += dt;
            qtf[4 * m / b] += dt;
            let t = std::time::Instant::now();
            let y = &mut y[..nbs * pw];
            inverse(
                isa,
                pw,
                &rec,
                &lanes,
                &mut f[..n * pw],
                &mut |_, _, _| {},
                y,
            );
            let dt = t.elapsed().as_secs_f64();
            ti += dt;
            qt[4 * m / b] += dt;
            qf[4 * m / b] += (n * nbs * pw * 2) as f64;
        }
        for q in 0..4 {
            println!(
                "  m in quarter {q}: forward {:.1}, inverse {:.1} GFLOP/s nominal, {:.3} s / {:.3} s",
                qf[q] / qtf[q] / 1e9,
                qf[q] / qt[q] / 1e9,
                qtf[q],
                qt[q]
            );
        }
        let flops = 8.0 * b as f64 * (4.0 * (b as f64).powi(3) - b as f64) / 3.0;
        let peak = fma_peak(isa);
        println!(
            "B={b}: kernels over all clusters: forward {:.3} s ({:.1} GFLOP/s, {:.0}%), inverse {:.3} s ({:.1} GFLOP/s, {:.0}%), peak {peak:.1}",
            tf,
            flops / tf / 1e9,
            100.0 * flops / tf / 1e9 / peak,
            ti,
            flops / ti / 1e9,
            100.0 * flops / ti / 1e9 / peak
        );
    }
}
