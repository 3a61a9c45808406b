//! Distributed plans over MPI (feature `mpi`): times of inverse + forward of the full shape
//! at bandwidth `B` on the ranks (`THREADS` workers each), medians of `RUNS`, the exchange's
//! share, each rank's planned memory (before allocating) and measured peak, and the round-trip
//! error (`RUNS = 0`: the planned memory only). The checks are `tests/mpi.rs` (`cargo test --release --features mpi --test mpi`).
//!
//! `cargo build --release --features mpi --example mpi_bench`
//! `mpirun --bind-to none -np 2 target/release/examples/mpi_bench B THREADS RUNS`

use so3fft::distributed::{mpi_finalize, mpi_init, MpiExchange};
use so3fft::{Complex64, DistributedPlan, Exchange, Options, Shape};

fn rnd(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
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
    let o = Options::default()
        .with_threads(threads)
        .with_rigor(so3fft::Rigor::Measure);
    let plan = DistributedPlan::new(comm, &s, &o)?;
    // What the planner says this rank will hold, before anything large is allocated.
    let arrays = 16 * (plan.local_num_samples() + plan.local_num_coeffs());
    let planned = arrays + plan.local_workspace_bytes();
    if runs == 0 {
        println!(
            "rank {} of {}: B = {b}, {} groups: planned {:.0} MB (arrays {:.0} MB + workspace {:.0} MB), \
             peak RSS after planning {:.0} MB",
            comm.rank(),
            comm.size(),
            plan.groups(),
            planned as f64 / 1e6,
            arrays as f64 / 1e6,
            plan.local_workspace_bytes() as f64 / 1e6,
            peak_rss() as f64 / 1e6
        );
        return Ok(());
    }
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
        let ti = plan.inverse(&c, &mut x)?;
        let tf = plan.forward(&x, &mut c)?;
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
    let num = |i: usize, d: usize| args.get(i).and_then(|a| a.parse().ok()).unwrap_or(d);
    let failed = bench(&comm, num(1, 128), num(2, 1), num(3, 5)).map_err(|e| {
        eprintln!("rank {}: {e}", comm.rank());
    });
    mpi_finalize().ok();
    std::process::exit(i32::from(failed.is_err()));
}
