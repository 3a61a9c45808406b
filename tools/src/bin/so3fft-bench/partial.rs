//! `so3fft-bench partial` (or `--partial`): what each kind of partial plan costs against
//! the transform it replaces, as ratios measured in the same run (medians of alternating
//! runs): degree-limited on an oversampled grid, order-limited (pruned FFTs, and large B),
//! batched, selected betas, and looser skip thresholds. Columns: docs/benchmark.md.

use crate::cli::Options;
use crate::workload::{median, random_coeffs};
use so3fft::{Batch, Betas, Complex64, Direction, PartialPlan, Plan, Shape, StageTimes};

/// Wigner terms of an inverse or forward: `(l, M, M')` of the shape times the betas.
fn terms(s: &Shape, betas: usize) -> f64 {
    let (a, n) = (s.order_limit_alpha as isize, s.order_limit_gamma as isize);
    let mut t = 0usize;
    for m in -a..=a {
        for mp in -n..=n {
            let lo = m.unsigned_abs().max(mp.unsigned_abs()).max(s.degree_min);
            t += s.degree_limit.saturating_sub(lo);
        }
    }
    t as f64 * betas as f64
}

/// Relative max error of `got` against `want`.
fn rel_err(got: &[Complex64], want: &[Complex64]) -> f64 {
    let d = got
        .iter()
        .zip(want)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    d / want.iter().map(|b| b.norm()).fold(0.0, f64::max)
}

/// Medians of the stage times of `runs` calls of each of `fs`, called in turn (A, B, A, B..).
pub(crate) fn alternate<const K: usize>(
    runs: usize,
    fs: &mut [&mut dyn FnMut() -> so3fft::Result<StageTimes>; K],
) -> so3fft::Result<[StageTimes; K]> {
    let mut all: [Vec<StageTimes>; K] = std::array::from_fn(|_| Vec::new());
    for _ in 0..runs {
        for (f, v) in fs.iter_mut().zip(all.iter_mut()) {
            v.push(f()?);
        }
    }
    Ok(std::array::from_fn(|k| {
        let v = &all[k];
        let m = |g: fn(&StageTimes) -> f64| median(&v.iter().map(g).collect::<Vec<_>>());
        StageTimes {
            fft: m(|s| s.fft),
            dwt: m(|s| s.dwt),
            exchange: m(|s| s.exchange),
            total: m(|s| s.total),
        }
    }))
}

fn opts(threads: usize, o: &Options) -> so3fft::Options {
    so3fft::Options::default()
        .with_threads(threads)
        .with_rigor(o.rigor)
}

fn full_plan(b: usize, threads: usize, o: &Options) -> so3fft::Result<Plan> {
    Plan::new(
        b,
        &so3fft::Options::default()
            .with_threads(threads)
            .with_rigor(o.rigor),
    )
}

fn zeros(n: usize) -> Vec<Complex64> {
    vec![Complex64::default(); n]
}

/// Runs every row; `opts.threads` gives the thread count of the unbatched rows (its last
/// entry), the batched rows use one thread.
pub fn run(o: &Options) -> so3fft::Result<()> {
    let threads = *o.threads.last().expect("a thread count");
    let runs = o.runs.unwrap_or(5);
    let peak1 = crate::peak::measure(1).one_core;
    println!(
        "Partial plans ({threads} threads unless noted; medians of {runs} alternating runs, ms)"
    );
    println!("FMA peak of one core: {peak1:.1} GFLOP/s\n");
    degree_limited(o, threads, runs)?;
    order_limited(o, threads, runs)?;
    order_limited_large(o, threads)?;
    batched(o, runs, peak1)?;
    selected_betas(o, threads, runs)?;
    skip_thresholds(o, threads, runs)?;
    Ok(())
}

/// 1: degree limit L = 128 on the B = 256 grid against the full B = 256 inverse.
fn degree_limited(o: &Options, threads: usize, runs: usize) -> so3fft::Result<()> {
    let (b, l) = (256, 128);
    let full = full_plan(b, threads, o)?;
    let s = Shape::new(l).with_grid(b, 2 * b, 2 * b);
    let pp = PartialPlan::new(&s, &opts(threads, o).with_direction(Direction::Inverse))?;
    let cf = random_coeffs(full.num_coeffs(), 1);
    let cp = random_coeffs(pp.num_coeffs(), 2);
    let mut x = zeros(full.num_samples());
    let mut y = zeros(pp.num_samples());
    let [tf, tp] = alternate(
        runs,
        &mut [&mut || full.inverse(&cf, &mut x), &mut || {
            pp.inverse_many(one(&pp), &cp, &mut y)
        }],
    )?;
    let (term_f, term_p) = (terms(&Shape::new(b), 2 * b), terms(&s, 2 * b));
    println!("1. Degree limit L = {l} on the B = {b} grid, inverse (target: DWT <= 0.2 of full):");
    println!(
        "   full B={b}: DWT {:.1} FFT {:.1} total {:.1}; partial: DWT {:.1} FFT {:.1} total {:.1}",
        tf.dwt * 1e3,
        tf.fft * 1e3,
        tf.total * 1e3,
        tp.dwt * 1e3,
        tp.fft * 1e3,
        tp.total * 1e3
    );
    println!(
        "   DWT ratio {:.3} (terms ratio {:.3}); time per term partial/full {:.2}\n",
        tp.dwt / tf.dwt,
        term_p / term_f,
        (tp.dwt / term_p) / (tf.dwt / term_f)
    );
    Ok(())
}

fn one(p: &PartialPlan) -> Batch {
    Batch {
        count: 1,
        in_dist: p.num_coeffs(),
        out_dist: p.num_samples(),
    }
}

/// 2: order limits on SOFT's grid (pruned FFTs) at B = 128.
fn order_limited(o: &Options, threads: usize, runs: usize) -> so3fft::Result<()> {
    let b = 128;
    let full = full_plan(b, threads, o)?;
    println!("2. Order limits on the B = {b} grid (pruned FFTs), inverse and forward:");
    println!(
        "   {:>5} {:>5} {:>9} {:>9} {:>9} {:>9} {:>9} {:>10}",
        "Mmax", "N", "inv FFT", "/full", "fwd FFT", "/full", "inv tot", "round trip"
    );
    let cf = random_coeffs(full.num_coeffs(), 1);
    let mut x = zeros(full.num_samples());
    let mut back = zeros(full.num_coeffs());
    for (mmax, n) in [(8, 8), (32, 32), (127, 8)] {
        let s = Shape::new(b)
            .with_orders(mmax, n)
            .with_grid(b, 2 * b, 2 * b);
        let pp = PartialPlan::new(&s, &opts(threads, o))?;
        let cp = random_coeffs(pp.num_coeffs(), 3);
        let mut y = zeros(pp.num_samples());
        let mut cb = zeros(pp.num_coeffs());
        let [fi, pi] = alternate(
            runs,
            &mut [&mut || full.inverse(&cf, &mut x), &mut || {
                pp.inverse_many(one(&pp), &cp, &mut y)
            }],
        )?;
        let [ff, pf] = alternate(
            runs,
            &mut [&mut || full.forward(&x, &mut back), &mut || {
                pp.forward_many(one_fwd(&pp), &y, &mut cb)
            }],
        )?;
        println!(
            "   {mmax:>5} {n:>5} {:>9.2} {:>9.3} {:>9.2} {:>9.3} {:>9.2} {:>10.2e}",
            pi.fft * 1e3,
            pi.fft / fi.fft,
            pf.fft * 1e3,
            pf.fft / ff.fft,
            pi.total * 1e3,
            rel_err(&cb, &cp)
        );
    }
    println!();
    Ok(())
}

fn one_fwd(p: &PartialPlan) -> Batch {
    Batch {
        count: 1,
        in_dist: p.num_samples(),
        out_dist: p.num_coeffs(),
    }
}

/// 3: `Mmax = N = 8` at B = 1024 and 2048 (grid `2B x 17 x 17`).
fn order_limited_large(o: &Options, threads: usize) -> so3fft::Result<()> {
    println!("3. Mmax = N = 8, L = B (grid 2B x 17 x 17), one run each:");
    for b in [1024, 2048] {
        let s = Shape::new(b).with_orders(8, 8);
        let pp = PartialPlan::new(&s, &opts(threads, o))?;
        let c = random_coeffs(pp.num_coeffs(), 5);
        let mut y = zeros(pp.num_samples());
        let mut back = zeros(pp.num_coeffs());
        let ti = pp.inverse_many(one(&pp), &c, &mut y)?;
        let tf = pp.forward_many(one_fwd(&pp), &y, &mut back)?;
        println!(
            "   B = {b}: inverse {:.0} ms (DWT {:.0}), forward {:.0} ms (DWT {:.0}), round trip {:.2e}",
            ti.total * 1e3,
            ti.dwt * 1e3,
            tf.total * 1e3,
            tf.dwt * 1e3,
            rel_err(&back, &c)
        );
    }
    println!();
    Ok(())
}

/// 4: eight transforms in one execute against eight single executes, one thread.
fn batched(o: &Options, runs: usize, peak1: f64) -> so3fft::Result<()> {
    println!("4. Batches of 8 against 8 single executes, one thread (target: DWT <= 0.75;");
    println!("   workspace for a group of 8 transforms, about their sample arrays; B = 256");
    println!("   would need 2 x 17 GB of sample arrays: not run):");
    println!(
        "   {:>5} {:>4} {:>10} {:>10} {:>7} {:>10} {:>10} {:>7} {:>6}",
        "B", "dir", "8 single", "batch", "ratio", "DWT 8x1", "DWT batch", "ratio", "%peak"
    );
    for b in [64, 128] {
        let s = Shape::new(b);
        // A batch shares each cluster's recurrence among the transforms of a group, as
        // many as the workspace holds (the default 512 MB: two at B = 128); here 8.
        let pp = PartialPlan::new(
            &s,
            &opts(1, o).with_max_workspace_bytes(Some(
                (8 * s.num_samples() * 16 / 20 * 21).max(512 << 20),
            )),
        )?;
        let (nc, ns) = (pp.num_coeffs(), pp.num_samples());
        let c = random_coeffs(8 * nc, 7);
        let mut x = zeros(8 * ns);
        let mut back = zeros(8 * nc);
        let bi = Batch {
            count: 8,
            in_dist: nc,
            out_dist: ns,
        };
        let bf = Batch {
            count: 8,
            in_dist: ns,
            out_dist: nc,
        };
        let mut singles_inv = || -> so3fft::Result<StageTimes> {
            let mut sum = StageTimes::default();
            for t in 0..8 {
                let r = pp.inverse_many(one(&pp), &c[t * nc..][..nc], &mut x[t * ns..][..ns])?;
                sum.dwt += r.dwt;
                sum.total += r.total;
            }
            Ok(sum)
        };
        let runs = runs.min(3);
        let mut xb = zeros(8 * ns);
        let [si, bi_t] = alternate(
            runs,
            &mut [&mut singles_inv, &mut || pp.inverse_many(bi, &c, &mut xb)],
        )?;
        let mut singles_fwd = || -> so3fft::Result<StageTimes> {
            let mut sum = StageTimes::default();
            for t in 0..8 {
                let r =
                    pp.forward_many(one_fwd(&pp), &xb[t * ns..][..ns], &mut back[t * nc..][..nc])?;
                sum.dwt += r.dwt;
                sum.total += r.total;
            }
            Ok(sum)
        };
        let mut back_b = zeros(8 * nc);
        let [sf, bf_t] = alternate(
            runs,
            &mut [&mut singles_fwd, &mut || {
                pp.forward_many(bf, &xb, &mut back_b)
            }],
        )?;
        let flops = 4.0 * terms(&s, 2 * b) * 8.0;
        for (dir, single, batch) in [("inv", si, bi_t), ("fwd", sf, bf_t)] {
            println!(
                "   {b:>5} {dir:>4} {:>10.1} {:>10.1} {:>7.3} {:>10.1} {:>10.1} {:>7.3} {:>5.0}%",
                single.total * 1e3,
                batch.total * 1e3,
                batch.total / single.total,
                single.dwt * 1e3,
                batch.dwt * 1e3,
                batch.dwt / single.dwt,
                100.0 * flops / batch.dwt / 1e9 / peak1
            );
        }
    }
    println!();
    Ok(())
}

/// 5: the inverse at 1/16 of the betas against the full inverse.
fn selected_betas(o: &Options, threads: usize, runs: usize) -> so3fft::Result<()> {
    println!("5. Inverse at 1/16 of the betas (every 16th), against all (target <= 0.15):");
    for b in [128, 256] {
        let s = Shape::new(b);
        let full = full_plan(b, threads, o)?;
        let ks: Vec<usize> = (0..2 * b).step_by(16).collect();
        let sel = PartialPlan::new(&s, &opts(threads, o).with_betas(Betas::Indices(ks)))?;
        let c = random_coeffs(full.num_coeffs(), 9);
        let mut x = zeros(full.num_samples());
        let mut y = zeros(sel.num_samples());
        let [tf, ts] = alternate(
            runs,
            &mut [&mut || full.inverse(&c, &mut x), &mut || {
                sel.inverse_many(one(&sel), &c, &mut y)
            }],
        )?;
        println!(
            "   B = {b}: all {:.1} ms, 1/16 {:.2} ms (DWT {:.2}, FFT {:.2}): ratio {:.3}",
            tf.total * 1e3,
            ts.total * 1e3,
            ts.dwt * 1e3,
            ts.fft * 1e3,
            ts.total / tf.total
        );
    }
    println!();
    Ok(())
}

/// 6: skip thresholds `2^-24` (6e-8) and `2^-34` (6e-11) against the default `2^-64`,
/// B = 64..256.
fn skip_thresholds(o: &Options, threads: usize, runs: usize) -> so3fft::Result<()> {
    println!("6. Skip thresholds: round trip (inverse + forward) time against the default 2^-64");
    println!(
        "   {:>5} {:>9} {:>9} {:>7} {:>10} {:>10}",
        "B", "threshold", "ms", "/def", "err", "err def"
    );
    for b in [64, 128, 256] {
        let mk = |bits: Option<u32>| {
            PartialPlan::new(&Shape::new(b), &opts(threads, o).with_skip_bits(bits))
        };
        let def = mk(None)?;
        let c = random_coeffs(def.num_coeffs(), 11);
        let (nc, ns) = (def.num_coeffs(), def.num_samples());
        for bits in [24, 34] {
            let tp = mk(Some(bits))?;
            let (mut x0, mut x1) = (zeros(ns), zeros(ns));
            let (mut b0, mut b1) = (zeros(nc), zeros(nc));
            let rt = |p: &PartialPlan, x: &mut Vec<Complex64>, bk: &mut Vec<Complex64>| {
                let a = p.inverse_many(one(p), &c, x)?;
                let f = p.forward_many(one_fwd(p), x, bk)?;
                Ok(StageTimes {
                    total: a.total + f.total,
                    ..StageTimes::default()
                })
            };
            let [t0, t1] = alternate(
                runs,
                &mut [&mut || rt(&def, &mut x0, &mut b0), &mut || {
                    rt(&tp, &mut x1, &mut b1)
                }],
            )?;
            println!(
                "   {b:>5} {:>9.1e} {:>9.1} {:>7.3} {:>10.2e} {:>10.2e}",
                2f64.powi(-(bits as i32)),
                t1.total * 1e3,
                t1.total / t0.total,
                rel_err(&b1, &c),
                rel_err(&b0, &c)
            );
        }
    }
    Ok(())
}
