//! Distributed plans over MPI (feature `mpi`), run by `scripts/test.sh` under
//! `mpirun -np 1..4`: every rank checks its part against a single-process plan of the same
//! shape (bitwise: complex and real, forward and inverse), a distributed round trip with
//! `|M|, |M'| <= 8` at B = 1024, and a collective error (ranks given different shapes).
//! Exits non-zero on every rank if any check fails on any rank.
//!
//! `mpirun -np 3 target/release/examples/mpi_check`
//!
//! With `--bench B THREADS RUNS`: times inverse + forward of the full shape at bandwidth `B`
//! on the ranks (THREADS workers each): medians, the exchange's share, each rank's workspace
//! and peak resident memory.

use so3fft::partial::{mpi_finalize, mpi_init, MpiExchange};
use so3fft::{Complex64, DistributedPlan, Exchange, PartialOptions, PartialPlan, Shape};

fn rnd(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

fn opts(real: bool) -> PartialOptions {
    PartialOptions {
        threads: 1,
        real,
        general_engine: true,
        ..PartialOptions::default()
    }
}

/// A real signal's coefficients: `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`.
fn hermitian(s: &Shape, c: &mut [Complex64]) {
    let (a, n) = (s.order_limit_alpha as isize, s.order_limit_gamma as isize);
    for l in 0..s.degree_limit {
        for m in -a..=a {
            for mp in -n..=n {
                if let (Some(i), Some(j)) = (s.coef_index(l, m, mp), s.coef_index(l, -m, -mp)) {
                    if i < j {
                        let sg = if (m - mp).rem_euclid(2) == 0 {
                            1.0
                        } else {
                            -1.0
                        };
                        c[j] = c[i].conj() * sg;
                    } else if i == j {
                        c[i].im = 0.0;
                    }
                }
            }
        }
    }
}

/// Local coefficients of `plan` taken from the global array `c`.
fn local_coeffs<X: Exchange>(
    plan: &DistributedPlan<X>,
    s: &Shape,
    c: &[Complex64],
) -> Vec<Complex64> {
    let mut lc = vec![Complex64::default(); plan.local_num_coeffs()];
    let (a, n) = (s.order_limit_alpha as isize, s.order_limit_gamma as isize);
    for l in 0..s.degree_limit {
        for m in -a..=a {
            for mp in -n..=n {
                if let Some(at) = plan.local_coef_index(l, m, mp) {
                    lc[at] = c[s.coef_index(l, m, mp).expect("held")];
                }
            }
        }
    }
    lc
}

/// The global slices of this rank, in local order.
fn slices(s: &Shape, (j0, j1): (usize, usize)) -> Vec<usize> {
    let nb = s.n_beta();
    (j0..j1).chain(nb - j1..nb - j0).collect()
}

/// Bitwise agreement with the single-process plan; the number of mismatches.
fn agreement(comm: &MpiExchange, s: Shape, real: bool) -> so3fft::Result<usize> {
    let single = PartialPlan::new(&s, &opts(real))?;
    let plan = DistributedPlan::new(comm, &s, &opts(real))?;
    let (ns, sl) = (s.num_samples(), s.slice_len());
    let mut st = 3u64;
    let mut c: Vec<Complex64> = (0..s.num_coeffs())
        .map(|_| Complex64::new(rnd(&mut st), rnd(&mut st)))
        .collect();
    if real {
        hermitian(&s, &mut c);
    }
    let lc = local_coeffs(&plan, &s, &c);
    let mine = slices(&s, plan.local_pairs());
    let mut bad = 0;
    let mut back = vec![Complex64::default(); lc.len()];
    let mut want_c = vec![Complex64::default(); c.len()];
    if real {
        let mut x = vec![0.0; ns];
        single.inverse_real(&c, &mut x)?;
        let mut lx = vec![0.0; plan.local_num_samples()];
        plan.inverse_real(&lc, &mut lx)?;
        for (t, &k) in mine.iter().enumerate() {
            bad += usize::from(lx[t * sl..][..sl] != x[k * sl..][..sl]);
        }
        single.forward_real(&x, &mut want_c)?;
        plan.forward_real(&lx, &mut back)?;
    } else {
        let mut x = vec![Complex64::default(); ns];
        single.inverse(&c, &mut x)?;
        let mut lx = vec![Complex64::default(); plan.local_num_samples()];
        plan.inverse(&lc, &mut lx)?;
        for (t, &k) in mine.iter().enumerate() {
            bad += usize::from(lx[t * sl..][..sl] != x[k * sl..][..sl]);
        }
        single.forward(&x, &mut want_c)?;
        plan.forward(&lx, &mut back)?;
    }
    bad += usize::from(back != local_coeffs(&plan, &s, &want_c));
    Ok(bad)
}

fn run(comm: &MpiExchange) -> so3fft::Result<usize> {
    let mut bad = 0;
    for real in [false, true] {
        bad += agreement(comm, Shape::new(16), real)?;
        bad += agreement(
            comm,
            Shape::new(12).with_orders(7, 3).with_grid(13, 17, 9),
            real,
        )?;
    }
    // Order-limited B = 1024 over the ranks: a round trip.
    let s = Shape::new(1024).with_orders(8, 8);
    let plan = DistributedPlan::new(comm, &s, &PartialOptions::default())?;
    let mut st = 11u64 + comm.rank() as u64;
    let c: Vec<Complex64> = (0..plan.local_num_coeffs())
        .map(|_| Complex64::new(rnd(&mut st), rnd(&mut st)))
        .collect();
    let mut x = vec![Complex64::default(); plan.local_num_samples()];
    let t = std::time::Instant::now();
    plan.inverse(&c, &mut x)?;
    let mut back = vec![Complex64::default(); c.len()];
    plan.forward(&x, &mut back)?;
    let err = back
        .iter()
        .zip(&c)
        .map(|(a, b)| (a - b).norm())
        .fold(0.0, f64::max);
    let worst = f64::from_bits(comm.max(err.to_bits())?);
    if comm.rank() == 0 {
        println!(
            "B = 1024, |M|,|M'| <= 8 over {} ranks: round trip {:.0} ms, max error {worst:.1e}",
            comm.size(),
            t.elapsed().as_secs_f64() * 1e3
        );
    }
    bad += usize::from(worst > 1e-11);
    // Ranks given different shapes: every rank gets the error.
    let other = Shape::new(8 + usize::from(comm.rank() == comm.size() - 1 && comm.size() > 1));
    let r = DistributedPlan::new(comm, &other, &opts(false));
    bad += usize::from(r.is_err() != (comm.size() > 1));
    Ok(bad)
}

/// Peak resident memory of this process (`VmHWM`), bytes.
fn peak_rss() -> usize {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmHWM:"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse::<usize>().ok())
        })
        .map_or(0, |kb| kb * 1024)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn bench(comm: &MpiExchange, b: usize, threads: usize, runs: usize) -> so3fft::Result<()> {
    let s = Shape::new(b);
    let o = PartialOptions {
        threads,
        rigor: so3fft::Rigor::Measure,
        ..PartialOptions::default()
    };
    let plan = DistributedPlan::new(comm, &s, &o)?;
    // What the planner says this rank will hold, before anything large is allocated.
    let arrays = 16 * (plan.local_num_samples() + plan.local_num_coeffs());
    let planned = arrays + plan.local_workspace_bytes();
    let seed = 7u64 + comm.rank() as u64;
    let coeffs = |st: &mut u64| Complex64::new(rnd(st), rnd(st));
    let mut st = seed;
    let mut c: Vec<Complex64> = (0..plan.local_num_coeffs())
        .map(|_| coeffs(&mut st))
        .collect();
    let mut x = vec![Complex64::default(); plan.local_num_samples()];
    let (mut inv, mut fwd, mut ex) = (Vec::new(), Vec::new(), Vec::new());
    let (mut dwt, mut fft) = (Vec::new(), Vec::new());
    for _ in 0..runs {
        // Round trips in place: the coefficients come back to rounding each time.
        plan.inverse(&c, &mut x)?;
        let ti = plan.last_times();
        plan.forward(&x, &mut c)?;
        let tf = plan.last_times();
        inv.push(ti.total);
        fwd.push(tf.total);
        ex.push((ti.exchange + tf.exchange) / (ti.total + tf.total));
        dwt.push(ti.dwt + tf.dwt);
        fft.push(ti.fft + tf.fft);
    }
    let mut st = seed;
    let err = c
        .iter()
        .map(|v| (v - coeffs(&mut st)).norm())
        .fold(0.0, f64::max);
    let worst = f64::from_bits(comm.max(err.to_bits())?);
    let (i, f, e) = (median(inv), median(fwd), median(ex));
    let mine = format!(
        "rank {} of {}: B = {b}, {threads} threads, {} groups: inverse {:.1} ms, forward {:.1} ms, \
         exchange {:.0}% (DWT {:.0} ms, FFT {:.0} ms), planned {:.0} MB (arrays {:.0} MB + workspace {:.0} MB), peak RSS {:.0} MB, \
         error after {runs} round trips {worst:.1e}",
        comm.rank(),
        comm.size(),
        plan.groups(),
        i * 1e3,
        f * 1e3,
        e * 100.0,
        median(dwt) * 1e3,
        median(fft) * 1e3,
        planned as f64 / 1e6,
        arrays as f64 / 1e6,
        plan.local_workspace_bytes() as f64 / 1e6,
        peak_rss() as f64 / 1e6
    );
    println!("{mine}");
    Ok(())
}

fn main() {
    mpi_init().expect("MPI_Init");
    let comm = MpiExchange::world().expect("MPI_COMM_WORLD");
    let args: Vec<String> = std::env::args().collect();
    if args.get(1).map(String::as_str) == Some("--bench") {
        let num = |i: usize, d: usize| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(d);
        if let Err(e) = bench(&comm, num(2, 128), num(3, 1), num(4, 5)) {
            eprintln!("rank {}: {e}", comm.rank());
        }
        mpi_finalize().ok();
        return;
    }
    let bad = run(&comm).unwrap_or_else(|e| {
        eprintln!("rank {}: {e}", comm.rank());
        1
    });
    let any = comm.max(bad as u64).unwrap_or(1);
    if comm.rank() == 0 {
        println!(
            "mpi_check on {} ranks: {}",
            comm.size(),
            if any == 0 {
                "all checks passed"
            } else {
                "FAILED"
            }
        );
    }
    mpi_finalize().ok();
    std::process::exit(i32::from(any != 0));
}
