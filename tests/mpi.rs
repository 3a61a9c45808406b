//! Distributed plans over MPI (feature `mpi`; `cargo test --release --features mpi --test mpi`).
//!
//! Run plainly, this test starts itself under `mpirun -np N` for N = 1 .. 4 (each run killed
//! after 600 s, so a deadlock fails instead of hanging) and fails if any run fails. Run under
//! `mpirun` (`OMPI_COMM_WORLD_SIZE` or `PMI_SIZE` set), every rank checks its part against a
//! single-process plan of the same shape (bitwise: complex and real, forward and inverse), a
//! distributed round trip with `|M|, |M'| <= 8` at B = 1024, and collective errors (ranks
//! given different shapes; one rank out of memory: the same error class on every rank), and exits non-zero on every rank if any check fails on any rank.
//! Also plans run in groups of pairs (a small workspace cap), against the single-process
//! plan to rounding.

mod common;

use so3fft::partial::{mpi_finalize, mpi_init, MpiExchange};
use so3fft::{Complex64, DistributedPlan, Exchange, Options, PartialPlan, Shape};
use std::process::{Command, ExitCode, Stdio};
use std::time::{Duration, Instant};

/// Longest a run on N ranks may take.
const TIMEOUT: Duration = Duration::from_secs(600);

fn opts(real: bool) -> Options {
    Options::default().with_threads(1).with_real(real)
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
/// Whether `x` differs from `y`: bitwise (`tol = 0`), or by more than `tol` times the
/// largest value of `y`.
fn differs(x: &[f64], y: &[f64], tol: f64) -> bool {
    let big = y.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    x.len() != y.len() || x.iter().zip(y).any(|(a, b)| (a - b).abs() > tol * big)
}

fn flat(z: &[Complex64]) -> Vec<f64> {
    z.iter().flat_map(|v| [v.re, v.im]).collect()
}

/// Agreement with the single-process plan: bitwise in one group of pairs; with a workspace
/// cap of `cap` bytes (several groups of pairs), to 1e-14 of the largest value. The number
/// of mismatches.
fn agreement(
    comm: &MpiExchange,
    s: Shape,
    real: bool,
    cap: Option<usize>,
) -> so3fft::Result<usize> {
    let single = PartialPlan::new(&s, &opts(real))?;
    let options = opts(real).with_max_workspace_bytes(cap);
    let plan = DistributedPlan::new(comm, &s, &options)?;
    let tol = if cap.is_some() { 1e-14 } else { 0.0 };
    let mut bad = usize::from((plan.groups() > 1) != cap.is_some());
    let (ns, sl) = (s.num_samples(), s.slice_len());
    let mut st = 3u64;
    let mut c: Vec<Complex64> = (0..s.num_coeffs())
        .map(|_| Complex64::new(common::rnd(&mut st), common::rnd(&mut st)))
        .collect();
    if real {
        common::make_hermitian(&s, &mut c);
    }
    let lc = local_coeffs(&plan, &s, &c);
    let mine = slices(&s, plan.local_pairs());
    let mut back = vec![Complex64::default(); lc.len()];
    let mut want_c = vec![Complex64::default(); c.len()];
    if real {
        let mut x = vec![0.0; ns];
        single.inverse_real(&c, &mut x)?;
        let mut lx = vec![0.0; plan.local_num_samples()];
        plan.inverse_real(&lc, &mut lx)?;
        for (t, &k) in mine.iter().enumerate() {
            bad += usize::from(differs(&lx[t * sl..][..sl], &x[k * sl..][..sl], tol));
        }
        single.forward_real(&x, &mut want_c)?;
        plan.forward_real(&lx, &mut back)?;
    } else {
        let mut x = vec![Complex64::default(); ns];
        single.inverse(&c, &mut x)?;
        let mut lx = vec![Complex64::default(); plan.local_num_samples()];
        plan.inverse(&lc, &mut lx)?;
        for (t, &k) in mine.iter().enumerate() {
            let (got, want) = (flat(&lx[t * sl..][..sl]), flat(&x[k * sl..][..sl]));
            bad += usize::from(differs(&got, &want, tol));
        }
        single.forward(&x, &mut want_c)?;
        plan.forward(&lx, &mut back)?;
    }
    let want = local_coeffs(&plan, &s, &want_c);
    bad += usize::from(differs(&flat(&back), &flat(&want), tol));
    Ok(bad)
}

fn run(comm: &MpiExchange) -> so3fft::Result<usize> {
    let mut bad = 0;
    for real in [false, true] {
        bad += agreement(comm, Shape::new(16), real, None)?;
        let odd = Shape::new(12).with_orders(7, 3).with_grid(13, 17, 9);
        bad += agreement(comm, odd, real, None)?;
        // Groups of pairs: the smallest cap gives the most groups.
        bad += agreement(comm, Shape::new(16), real, Some(1))?;
        bad += agreement(comm, odd, real, Some(12_000))?;
    }
    // Order-limited B = 1024 over the ranks: a round trip.
    let s = Shape::new(1024).with_orders(8, 8);
    let plan = DistributedPlan::new(comm, &s, &Options::default())?;
    let mut st = 11u64 + comm.rank() as u64;
    let c: Vec<Complex64> = (0..plan.local_num_coeffs())
        .map(|_| Complex64::new(common::rnd(&mut st), common::rnd(&mut st)))
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
    // A rank that cannot allocate its buffers (its address space capped just above what it
    // uses): every rank's execute fails, none waits in the exchange.
    let s = Shape::new(64);
    let plan = DistributedPlan::new(comm, &s, &opts(false))?;
    let c = vec![Complex64::default(); plan.local_num_coeffs()];
    let mut x = vec![Complex64::default(); plan.local_num_samples()];
    let capped = comm.rank() == 0;
    let old = if capped {
        cap_address_space(4 << 20)
    } else {
        None
    };
    let r = plan.inverse(&c, &mut x);
    if let Some(old) = old {
        // SAFETY: `old` is the limit read by getrlimit; raising the soft limit back is allowed.
        unsafe { libc::setrlimit(libc::RLIMIT_AS, &old) };
    }
    // The same error class on every rank (C: SO3FFT_ENOMEM everywhere).
    if !matches!(r, Err(so3fft::Error::OutOfMemory { .. })) {
        eprintln!(
            "rank {}: expected an out-of-memory error, got {r:?}",
            comm.rank()
        );
        bad += 1;
    }
    bad += usize::from(plan.inverse(&c, &mut x).is_err());
    // Ranks given different shapes: every rank gets the error.
    let other = Shape::new(8 + usize::from(comm.rank() == comm.size() - 1 && comm.size() > 1));
    let r = DistributedPlan::new(comm, &other, &opts(false));
    bad += usize::from(r.is_err() != (comm.size() > 1));
    Ok(bad)
}

/// Caps this process's address space at its current size plus `extra` bytes; the old limit.
fn cap_address_space(extra: u64) -> Option<libc::rlimit> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: u64 = status
        .lines()
        .find(|l| l.starts_with("VmSize:"))?
        .split_whitespace()
        .nth(1)?
        .parse()
        .ok()?;
    let mut old = libc::rlimit {
        rlim_cur: 0,
        rlim_max: 0,
    };
    // SAFETY: `old` is a valid out-pointer; the new limit is a plain value.
    unsafe {
        if libc::getrlimit(libc::RLIMIT_AS, &mut old) != 0 {
            return None;
        }
        let cap = libc::rlimit {
            rlim_cur: kb * 1024 + extra,
            rlim_max: old.rlim_max,
        };
        (libc::setrlimit(libc::RLIMIT_AS, &cap) == 0).then_some(old)
    }
}

/// On a rank under `mpirun`: the checks; the exit code is the same on every rank.
fn rank_main() -> ExitCode {
    mpi_init().expect("MPI_Init");
    let comm = MpiExchange::world().expect("MPI_COMM_WORLD");
    let bad = run(&comm).unwrap_or_else(|e| {
        eprintln!("rank {}: {e}", comm.rank());
        1
    });
    let any = comm.max(bad as u64).unwrap_or(1);
    if comm.rank() == 0 {
        println!(
            "mpi test on {} ranks: {}",
            comm.size(),
            if any == 0 {
                "all checks passed"
            } else {
                "FAILED"
            }
        );
    }
    mpi_finalize().ok();
    if any == 0 {
        ExitCode::SUCCESS
    } else {
        ExitCode::FAILURE
    }
}

/// Open MPI refuses to run as root and more ranks than cores unless told to; other MPIs need
/// no flag for either and would reject these.
fn mpirun_flags() -> std::io::Result<Vec<&'static str>> {
    let out = Command::new("mpirun").arg("--version").output()?;
    let text = String::from_utf8_lossy(&out.stdout) + String::from_utf8_lossy(&out.stderr);
    Ok(if text.contains("Open MPI") || text.contains("OpenRTE") {
        vec!["--allow-run-as-root", "--oversubscribe"]
    } else {
        Vec::new()
    })
}

/// `mpirun -np np <this executable>`, its output going to ours; Err if it failed or timed out.
fn launch(exe: &std::path::Path, flags: &[&str], np: usize) -> Result<(), String> {
    println!("--- mpirun -np {np}");
    let mut child = Command::new("mpirun")
        .args(flags)
        .args(["-np", &np.to_string()])
        .arg(exe)
        .stdin(Stdio::null())
        .spawn()
        .map_err(|e| format!("starting mpirun: {e}"))?;
    let start = Instant::now();
    loop {
        match child.try_wait() {
            Ok(Some(status)) if status.success() => return Ok(()),
            Ok(Some(status)) => return Err(format!("{status}")),
            Ok(None) if start.elapsed() > TIMEOUT => break,
            Ok(None) => std::thread::sleep(Duration::from_millis(100)),
            Err(e) => return Err(format!("waiting for mpirun: {e}")),
        }
    }
    // SIGTERM first: mpirun then ends its ranks; SIGKILL would leave them running.
    // SAFETY: kill(2) on our own child's pid, which try_wait has not reaped.
    unsafe { libc::kill(child.id() as libc::pid_t, libc::SIGTERM) };
    let grace = Instant::now();
    while matches!(child.try_wait(), Ok(None)) && grace.elapsed() < Duration::from_secs(10) {
        std::thread::sleep(Duration::from_millis(100));
    }
    child.kill().ok();
    child.wait().ok();
    Err(format!("timed out after {} s", TIMEOUT.as_secs()))
}

fn main() -> ExitCode {
    if std::env::var_os("OMPI_COMM_WORLD_SIZE").is_some() || std::env::var_os("PMI_SIZE").is_some()
    {
        return rank_main();
    }
    let flags = match mpirun_flags() {
        Ok(flags) => flags,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            eprintln!(
                "mpi test: `mpirun` not found on PATH; install MPI (Debian: openmpi-bin \
                 libopenmpi-dev, as scripts/install-deps.sh does) to run the distributed checks"
            );
            return ExitCode::FAILURE;
        }
        Err(e) => {
            eprintln!("mpi test: running `mpirun --version`: {e}");
            return ExitCode::FAILURE;
        }
    };
    let exe = std::env::current_exe().expect("path of the test executable");
    let mut failed = Vec::new();
    for np in 1..=4 {
        if let Err(e) = launch(&exe, &flags, np) {
            eprintln!("mpi test on {np} ranks: {e}");
            failed.push(np);
        }
    }
    if failed.is_empty() {
        println!("mpi test: 1 .. 4 ranks passed");
        ExitCode::SUCCESS
    } else {
        eprintln!("mpi test: failed on {failed:?} ranks");
        ExitCode::FAILURE
    }
}
