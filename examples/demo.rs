//! The main job: round trips (inverse then forward) of random band-limited signals at a
//! few bandwidths, printing the time of each stage and the error; then rotational matching:
//! a random band-limited function on the sphere, rotated by a random off-grid rotation, is
//! found again on the SO(3) grid and refined off it, with the angle errors and the time of
//! each stage.
//!
//! `cargo run --release --example demo [-- B1,B2,... [L]]`

use so3fft::matching::Rotation;
use so3fft::matching::{grid_argmax_real, rotate_s2_coeffs, Correlation, CorrelationOptions};
use so3fft::s2::{s2_coef_index, S2Plan};
use so3fft::{Complex64, Options, Plan};
use std::time::Instant;

fn random_coeffs(n: usize, seed: u64) -> Vec<Complex64> {
    let mut s = seed;
    let mut next = move || {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    (0..n).map(|_| Complex64::new(next(), next())).collect()
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let bws: Vec<usize> = match std::env::args().nth(1) {
        Some(s) => s
            .split(',')
            .map(|x| x.trim().parse())
            .collect::<Result<_, _>>()?,
        None => vec![8, 16, 32, 64, 128],
    };
    let opts = Options::default()
        .with_rigor(so3fft::Rigor::Measure)
        .with_threads(
            std::env::var("SO3FFT_THREADS")
                .ok()
                .and_then(|s| s.parse().ok())
                .unwrap_or(0),
        )
        .with_max_workspace_bytes(
            std::env::var("SO3FFT_WORKSPACE_MB")
                .ok()
                .and_then(|s| s.parse::<usize>().ok())
                .map(|mb| mb << 20),
        )
        .with_skip_bits(
            std::env::var("SO3FFT_SKIP_BITS")
                .ok()
                .and_then(|s| s.parse().ok()),
        )
        .with_fft_threading(match std::env::var("SO3FFT_FFT_THREADING").as_deref() {
            Ok("workers") => so3fft::FftThreading::SlicesAcrossWorkers,
            Ok("fftw") => so3fft::FftThreading::FftwThreads,
            _ => so3fft::FftThreading::Auto,
        });
    println!("so3fft demo: random coefficients -> inverse -> forward, all cores");
    println!(
        "{:>5} {:>7} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>9} {:>11} {:>11}",
        "B",
        "threads",
        "plan s",
        "inv s",
        "inv FFT",
        "inv DWT",
        "fwd s",
        "fwd FFT",
        "fwd DWT",
        "max abs err",
        "rel L2 err"
    );
    for b in bws {
        let t = Instant::now();
        let plan = Plan::new(b, &opts)?;
        let t_plan = t.elapsed().as_secs_f64();
        let coeffs = random_coeffs(plan.num_coeffs(), 0x5eed + b as u64);
        let mut samples = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
        let mut back = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
        let ti = plan.inverse(&coeffs, &mut samples)?;
        let tf = plan.forward(&samples, &mut back)?;
        let (mut emax, mut num, mut den) = (0.0f64, 0.0, 0.0);
        for (a, c) in back.iter().zip(&coeffs) {
            emax = emax.max((a - c).norm());
            num += (a - c).norm_sqr();
            den += c.norm_sqr();
        }
        println!(
            "{:>5} {:>7} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>9.4} {:>11.3e} {:>11.3e}",
            b,
            plan.threads(),
            t_plan,
            ti.total,
            ti.fft,
            ti.dwt,
            tf.total,
            tf.fft,
            tf.dwt,
            emax,
            (num / den).sqrt()
        );
    }
    let l = match std::env::args().nth(2) {
        Some(s) => s.trim().parse()?,
        None => 64,
    };
    matching(l, opts.threads)
}

/// Rotational matching of a real band-limited function of bandwidth `l` with a rotated copy.
fn matching(l: usize, threads: usize) -> Result<(), Box<dyn std::error::Error>> {
    println!();
    println!("rotational matching, L = {l}: pattern h random (real, degrees < L), signal f = h rotated by g");
    // A real function: fhat(l,-m) = (-1)^m conj(fhat(l,m)), decaying like 1/(1+l).
    let mut hat = random_coeffs(l * l, 0xa11ce);
    for deg in 0..l {
        let decay = 1.0 / (1.0 + deg as f64);
        hat[s2_coef_index(l, deg, 0)] =
            Complex64::new(hat[s2_coef_index(l, deg, 0)].re * decay, 0.0);
        for m in 1..=deg as isize {
            let c = hat[s2_coef_index(l, deg, m)] * decay;
            hat[s2_coef_index(l, deg, m)] = c;
            hat[s2_coef_index(l, deg, -m)] = if m % 2 == 0 { c.conj() } else { -c.conj() };
        }
    }
    let truth = Rotation::new(1.234567, 0.987654, 4.321098);
    let s2 = S2Plan::new(l, &Options::default().with_threads(threads))?;
    let (mut sig, mut pat) = (vec![0.0; s2.num_samples()], vec![0.0; s2.num_samples()]);
    s2.inverse_real(&rotate_s2_coeffs(l, &hat, &truth)?, &mut sig)?;
    s2.inverse_real(&hat, &mut pat)?;

    let t = Instant::now();
    let plan = Correlation::new(
        l,
        &CorrelationOptions::default()
            .with_real(true)
            .with_threads(threads),
    )?;
    let t_plan = t.elapsed().as_secs_f64();
    let mut grid = vec![0.0; plan.num_grid()];
    let t = Instant::now();
    plan.correlate_real(&sig, &pat, &mut grid)?;
    let t_corr = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let peak = grid_argmax_real(plan.b_out(), &grid);
    let t_peak = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(plan.b_out())];
    plan.coefficients_real(&sig, &pat, &mut coeffs)?;
    let (refined, _) = plan.refine(&coeffs, &peak.rotation())?;
    let t_refine = t.elapsed().as_secs_f64();
    let show = |g: &Rotation| format!("({:.9}, {:.9}, {:.9})", g.alpha, g.beta, g.gamma);
    println!(
        "  true rotation     (alpha, beta, gamma) = {}",
        show(&truth)
    );
    println!(
        "  grid peak                              = {}  off by {:.3e} rad (grid step {:.3e})",
        show(&peak.rotation()),
        peak.rotation().angle_to(&truth),
        std::f64::consts::PI / plan.b_out() as f64
    );
    println!(
        "  refined                                = {}  off by {:.3e} rad",
        show(&refined),
        refined.angle_to(&truth)
    );
    println!(
        "  time: plan {t_plan:.4} s, correlation (2 S^2 forwards, combine, inverse SO(3)) {t_corr:.4} s, \
         grid argmax {t_peak:.4} s, refinement {t_refine:.4} s"
    );
    Ok(())
}
