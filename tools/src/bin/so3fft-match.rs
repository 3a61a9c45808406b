//! `so3fft-match SIGNAL PATTERN [options]`: rotational matching of two functions on the
//! sphere given as S^2 sample files in SOFT's sample-data text format (one number per line,
//! `(2B)^2` real values or `2 (2B)^2` interleaved real and imaginary parts, samples
//! `f(theta_j, phi_k)` at `j 2B + k`). Prints the rotation `g = Rz(alpha) Ry(beta) Rz(gamma)`
//! with `signal(x) ~ pattern(g^-1 x)`: the grid peak, the peak refined off the grid, the
//! correlation value and the time of each stage.

use clap::Parser;
use so3fft::matching::{
    grid_argmax, grid_argmax_real, top_peaks, Correlation, CorrelationOptions, Peak,
};
use so3fft::Complex64;
use std::process::ExitCode;
use std::time::Instant;

/// Reads a sample file: the numbers, or a message naming the file and the line.
fn read_samples(path: &str) -> Result<Vec<f64>, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{path}: {e}"))?;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() {
            continue;
        }
        let v: f64 = t
            .parse()
            .map_err(|_| format!("{path}:{}: not a number: '{t}'", i + 1))?;
        if !v.is_finite() {
            return Err(format!("{path}:{}: not a finite number: '{t}'", i + 1));
        }
        out.push(v);
    }
    Ok(out)
}

/// Bandwidth and kind (real?) of `count` samples, if it is a valid count.
fn shape(count: usize) -> Option<(usize, bool)> {
    let side = |n: usize| {
        let s = (n as f64).sqrt().round() as usize;
        (s * s == n && s.is_multiple_of(2) && s > 0).then_some(s / 2)
    };
    if let Some(b) = side(count) {
        return Some((b, true));
    }
    count
        .is_multiple_of(2)
        .then(|| side(count / 2))
        .flatten()
        .map(|b| (b, false))
}

/// Rotational matching of two functions on the sphere given as S^2 sample files.
///
/// Prints the rotation g = Rz(alpha) Ry(beta) Rz(gamma) with signal(x) ~ pattern(g^-1 x):
/// the grid peak, the peak refined off the grid, the correlation value and the time of each
/// stage.
#[derive(Parser, Debug)]
#[command(
    name = "so3fft-match",
    version,
    args_override_self = true,
    after_help = "Exit status: 0 success, 2 bad arguments or input files, 1 other errors."
)]
struct Args {
    /// S^2 samples, one number per line: (2B)^2 real values, or 2(2B)^2 numbers (real and
    /// imaginary parts interleaved) for complex data
    signal: String,
    /// Samples of the pattern, of the same kind and B as SIGNAL
    pattern: String,
    /// Bandwidth of the SO(3) grid searched [default: B; larger is finer]
    #[arg(long = "bout", value_name = "B")]
    b_out: Option<usize>,
    /// Also list the K largest separated grid peaks, each refined
    #[arg(long, value_name = "K", default_value_t = 1)]
    top: usize,
    /// Worker threads (0 = all cores)
    #[arg(long, value_name = "N", default_value_t = 0)]
    threads: usize,
}

fn show(p: &Peak) -> String {
    format!(
        "alpha {:.10} beta {:.10} gamma {:.10}",
        p.alpha, p.beta, p.gamma
    )
}

fn run(args: &Args) -> Result<(), (u8, String)> {
    let bad = |m: String| (2u8, m);
    let sig = read_samples(&args.signal).map_err(bad)?;
    let pat = read_samples(&args.pattern).map_err(bad)?;
    let (b, real) = shape(sig.len()).ok_or_else(|| {
        bad(format!(
            "{}: {} numbers is neither (2B)^2 real nor 2 (2B)^2 complex samples",
            args.signal,
            sig.len()
        ))
    })?;
    if pat.len() != sig.len() {
        return Err(bad(format!(
            "{}: {} numbers, but {} has {}",
            args.pattern,
            pat.len(),
            args.signal,
            sig.len()
        )));
    }
    let fail = |e: so3fft::Error| (1u8, e.to_string());
    let t = Instant::now();
    let plan = Correlation::new(
        b,
        &CorrelationOptions::default()
            .with_b_out(args.b_out)
            .with_real(real)
            .with_threads(args.threads),
    )
    .map_err(fail)?;
    let t_plan = t.elapsed().as_secs_f64();
    let bo = plan.b_out();
    let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(bo)];
    let t = Instant::now();
    let (best, peaks) = if real {
        let mut grid = vec![0.0; plan.num_grid()];
        plan.correlate_real(&sig, &pat, &mut grid).map_err(fail)?;
        let as_complex: Vec<Complex64>;
        let peaks = if args.top > 1 {
            as_complex = grid.iter().map(|&x| Complex64::new(x, 0.0)).collect();
            top_peaks(
                bo,
                &as_complex,
                args.top,
                2.0 * std::f64::consts::PI / bo as f64,
            )
        } else {
            Vec::new()
        };
        (grid_argmax_real(bo, &grid), peaks)
    } else {
        let to_c = |v: &[f64]| -> Vec<Complex64> {
            v.chunks_exact(2)
                .map(|p| Complex64::new(p[0], p[1]))
                .collect()
        };
        let (s, p) = (to_c(&sig), to_c(&pat));
        let mut grid = vec![Complex64::default(); plan.num_grid()];
        plan.correlate(&s, &p, &mut grid).map_err(fail)?;
        let peaks = if args.top > 1 {
            top_peaks(bo, &grid, args.top, 2.0 * std::f64::consts::PI / bo as f64)
        } else {
            Vec::new()
        };
        (grid_argmax(bo, &grid), peaks)
    };
    let t_corr = t.elapsed().as_secs_f64();
    let t = Instant::now();
    if real {
        plan.coefficients_real(&sig, &pat, &mut coeffs)
            .map_err(fail)?;
    } else {
        let to_c = |v: &[f64]| -> Vec<Complex64> {
            v.chunks_exact(2)
                .map(|p| Complex64::new(p[0], p[1]))
                .collect()
        };
        plan.coefficients(&to_c(&sig), &to_c(&pat), &mut coeffs)
            .map_err(fail)?;
    }
    // The best grid peak and the top peaks, refined together.
    let starts: Vec<_> = std::iter::once(best.rotation())
        .chain(peaks.iter().map(|p| p.rotation()))
        .collect();
    let refined_all = plan.refine_many(&coeffs, &starts).map_err(fail)?;
    let (refined, value) = refined_all[0];
    let t_refine = t.elapsed().as_secs_f64();
    println!(
        "input: B = {b}, {} samples; SO(3) grid of bandwidth {bo} (step {:.3e} rad)",
        if real { "real" } else { "complex" },
        std::f64::consts::PI / bo as f64
    );
    println!("grid peak:    {}  |C|^2 = {:.12e}", show(&best), best.value);
    println!(
        "refined peak: alpha {:.10} beta {:.10} gamma {:.10}  |C|^2 = {value:.12e}  ({:.3e} rad from the grid peak)",
        refined.alpha,
        refined.beta,
        refined.gamma,
        refined.angle_to(&best.rotation())
    );
    for (i, (p, &(g, v))) in peaks.iter().zip(&refined_all[1..]).enumerate() {
        println!(
            "peak {}: grid {}  refined alpha {:.10} beta {:.10} gamma {:.10}  |C|^2 = {v:.6e}",
            i + 1,
            show(p),
            g.alpha,
            g.beta,
            g.gamma
        );
    }
    println!(
        "time: plan {t_plan:.4} s, correlation and grid peaks {t_corr:.4} s, refinement {t_refine:.4} s"
    );
    Ok(())
}

fn main() -> ExitCode {
    // Usage errors exit with status 2, --help and --version with 0 (clap).
    let mut args = Args::parse();
    args.top = args.top.max(1);
    match run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err((code, m)) => {
            eprintln!("so3fft-match: {m}");
            ExitCode::from(code)
        }
    }
}
