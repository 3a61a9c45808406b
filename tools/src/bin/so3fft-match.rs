//! `so3fft-match SIGNAL PATTERN [options]`: rotational matching of two functions on the
//! sphere given as S^2 sample files in SOFT's sample-data text format (one number per line,
//! `(2B)^2` real values or `2 (2B)^2` interleaved real and imaginary parts, samples
//! `f(theta_j, phi_k)` at `j 2B + k`). Prints the rotation `g = Rz(alpha) Ry(beta) Rz(gamma)`
//! with `signal(x) ~ pattern(g^-1 x)`: the grid peak, the peak refined off the grid, the
//! correlation value, how sure the peak is (the rms angle of its error from the inputs'
//! noise, its ratio to the next separate peak), the noise floors, and the time of each
//! stage. `--weights` weights the correlation's degrees: uniformly, by the noise estimated
//! from the inputs (`auto`), or by a file.

use clap::Parser;
use so3fft::matching::{top_peaks, Correlation, CorrelationOptions, DegreeWeights, Match, Peak};
use so3fft::Complex64;
use std::process::ExitCode;
use std::time::Instant;

/// The numbers of a file, one per non-empty line, each with its line number and text; a
/// message naming the file and the line for text that is not a number.
fn read_numbers(path: &str) -> Result<Vec<(usize, f64, String)>, String> {
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
        out.push((i + 1, v, t.to_string()));
    }
    Ok(out)
}

/// Reads a sample file: the numbers, or a message naming the file and the line.
fn read_samples(path: &str) -> Result<Vec<f64>, String> {
    read_numbers(path)?
        .into_iter()
        .map(|(line, v, t)| {
            if v.is_finite() {
                Ok(v)
            } else {
                Err(format!("{path}:{line}: not a finite number: '{t}'"))
            }
        })
        .collect()
}

/// Reads a weight file: `count` weights `w_0 ..` one per line, finite, `>= 0` and not all
/// 0, or a message naming the file (and the line).
fn read_weights(path: &str, count: usize) -> Result<Vec<f64>, String> {
    let out: Vec<f64> = read_numbers(path)?
        .into_iter()
        .map(|(line, v, t)| {
            if v.is_finite() && v >= 0.0 {
                Ok(v)
            } else {
                Err(format!(
                    "{path}:{line}: weight '{t}': weights must be finite and >= 0"
                ))
            }
        })
        .collect::<Result<_, _>>()?;
    if out.len() != count {
        return Err(format!(
            "{path}: {} weights, need {count} (w_0 .. w_{}, one per line; see --degree-limit)",
            out.len(),
            count - 1
        ));
    }
    if out.iter().all(|&w| w == 0.0) {
        return Err(format!("{path}: every weight is 0"));
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
    /// Degree weights: uniform, auto (estimated from the inputs' noise), or a file of
    /// D+1 weights w_0 .. w_D, one per line (D the degree limit; a file named auto: ./auto)
    #[arg(long, value_name = "uniform|auto|FILE", default_value = "uniform")]
    weights: String,
    /// Highest degree correlated [default: min(B, bout) - 1]
    #[arg(long = "degree-limit", value_name = "D")]
    degree_limit: Option<usize>,
}

fn show(p: &Peak) -> String {
    format!(
        "alpha {:.10} beta {:.10} gamma {:.10}",
        p.alpha, p.beta, p.gamma
    )
}

/// The highest degree weighted at least a tenth of the largest weight.
fn top_weighted(w: &[f64]) -> usize {
    let max = w.iter().fold(0.0f64, |m, &x| m.max(x));
    w.iter().rposition(|&x| x >= 0.1 * max).unwrap_or(0)
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
    let bo = args.b_out.unwrap_or(b);
    if bo == 0 {
        return Err(bad(
            "--bout 0: the grid's bandwidth must be at least 1".into()
        ));
    }
    let deg_lim = args.degree_limit.unwrap_or(b.min(bo).saturating_sub(1));
    if deg_lim >= b.min(bo) {
        return Err(bad(format!(
            "degree limit {deg_lim}: must be below both bandwidths ({b} and {bo})"
        )));
    }
    let weights = match args.weights.as_str() {
        "uniform" => DegreeWeights::Uniform,
        "auto" => DegreeWeights::Automatic,
        file => DegreeWeights::Given(read_weights(file, deg_lim + 1).map_err(bad)?),
    };
    // Bad arguments the library finds (bandwidths, weights) are the caller's too.
    let fail = |e: so3fft::Error| {
        let code = match e {
            so3fft::Error::InvalidArgument(_) | so3fft::Error::InvalidBandwidth { .. } => 2,
            _ => 1,
        };
        (code, e.to_string())
    };
    let t = Instant::now();
    let plan = Correlation::new(
        b,
        &CorrelationOptions::default()
            .with_b_out(args.b_out)
            .with_deg_lim(Some(deg_lim))
            .with_real(real)
            .with_threads(args.threads)
            .with_weights(weights),
    )
    .map_err(fail)?;
    let t_plan = t.elapsed().as_secs_f64();
    let fail = |e: so3fft::Error| (1u8, e.to_string());
    let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(bo)];
    let separate = 2.0 * std::f64::consts::PI / bo as f64;
    let to_c = |v: &[f64]| -> Vec<Complex64> {
        v.chunks_exact(2)
            .map(|p| Complex64::new(p[0], p[1]))
            .collect()
    };
    let t = Instant::now();
    // The grid, its peak refined, the uncertainty; then the other top peaks of the grid.
    let (found, peaks): (Match, Vec<Peak>) = if real {
        let mut grid = vec![0.0; plan.num_grid()];
        let found = plan.find_real(&sig, &pat, &mut grid).map_err(fail)?;
        let peaks = if args.top > 1 {
            let as_complex: Vec<Complex64> = grid.iter().map(|&x| Complex64::new(x, 0.0)).collect();
            top_peaks(bo, &as_complex, args.top, separate)
        } else {
            Vec::new()
        };
        (found, peaks)
    } else {
        let (s, p) = (to_c(&sig), to_c(&pat));
        let mut grid = vec![Complex64::default(); plan.num_grid()];
        let found = plan.find(&s, &p, &mut grid).map_err(fail)?;
        let peaks = if args.top > 1 {
            top_peaks(bo, &grid, args.top, separate)
        } else {
            Vec::new()
        };
        (found, peaks)
    };
    let t_find = t.elapsed().as_secs_f64();
    let t = Instant::now();
    let refined_all = if peaks.is_empty() {
        Vec::new()
    } else {
        if real {
            plan.coefficients_real(&sig, &pat, &mut coeffs)
                .map_err(fail)?;
        } else {
            plan.coefficients(&to_c(&sig), &to_c(&pat), &mut coeffs)
                .map_err(fail)?;
        }
        let starts: Vec<_> = peaks.iter().map(|p| p.rotation()).collect();
        plan.refine_many(&coeffs, &starts).map_err(fail)?
    };
    let t_top = t.elapsed().as_secs_f64();
    let (best, refined, value) = (&found.grid_peak, found.rotation, found.value);
    println!(
        "input: B = {b}, {} samples; SO(3) grid of bandwidth {bo} (step {:.3e} rad); degrees 0..={deg_lim}",
        if real { "real" } else { "complex" },
        std::f64::consts::PI / bo as f64
    );
    println!("grid peak:    {}  |C|^2 = {:.12e}", show(best), best.value);
    println!(
        "refined peak: alpha {:.10} beta {:.10} gamma {:.10}  |C|^2 = {value:.12e}  ({:.3e} rad from the grid peak)",
        refined.alpha,
        refined.beta,
        refined.gamma,
        refined.angle_to(&best.rotation())
    );
    let sigma = found.uncertainty.sigma;
    println!(
        "uncertainty:  sigma = {:.6e} deg ({sigma:.6e} rad), the rms angle of the error from the noise",
        sigma.to_degrees()
    );
    println!(
        "peak ratio:   {:.6} (|C| over the next peak at least {:.4e} rad away; near 1: ambiguous)",
        found.peak_ratio, found.separation
    );
    println!(
        "noise floor:  signal {:.6e}, pattern {:.6e} (power per S^2 coefficient)",
        found.spectra.signal_noise, found.spectra.pattern_noise
    );
    let w = &found.spectra.weights;
    match plan.weights() {
        DegreeWeights::Uniform => println!("weights:      uniform"),
        DegreeWeights::Automatic => println!(
            "weights:      auto; highest degree weighted >= 0.1 of the largest: {} (of {deg_lim})",
            top_weighted(w)
        ),
        DegreeWeights::Given(_) => println!(
            "weights:      {}; highest degree weighted >= 0.1 of the largest: {} (of {deg_lim})",
            args.weights,
            top_weighted(w)
        ),
    }
    for (i, (p, &(g, v))) in peaks.iter().zip(&refined_all).enumerate() {
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
        "time: plan {t_plan:.4} s, correlation, grid peak, refinement and uncertainty {t_find:.4} s, top peaks {t_top:.4} s"
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
