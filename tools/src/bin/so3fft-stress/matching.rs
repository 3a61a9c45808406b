//! Rotational matching as points of the time-against-error chart: a random band-limited
//! function on S^2 and its copy rotated by a known off-grid rotation; the rotation recovered
//! from the correlation grid (`match-grid`), on a grid twice as fine (`match-grid-2x`, a
//! partial plan: degrees below L on the grid of 2L), and refined off the grid
//! (`match-refined`). Error: the geodesic angle to the true rotation (rad); time: the
//! pipeline (two S^2 forwards, combine, inverse SO(3), argmax), plus one refinement.
//!
//! In `f32` the samples are those of `f64` rounded to `f32`; the grid peak is checked
//! against the peak of the `f64` pipeline on the same (widened) samples: the same grid
//! point, or a point whose `f64` value is within `f32` rounding of the maximum (a tie).
//! Refinement runs in `f64` from the `f64` coefficients the `f32` plan computes.

use crate::precision::{narrow, widen, Float, Precision};
use crate::record::{Report, Row};
use crate::rng::SplitMix64;
use so3fft::matching::{
    grid_argmax, rotate_s2_coeffs, Correlation, CorrelationOptions, Peak, Rotation,
};
use so3fft::s2::S2Plan;
use so3fft::{Complex, Complex64, Options};
use std::time::Instant;

/// How far below the `f64` maximum `|C|^2` the `f64` value at the `f32` peak may be for a
/// tie: `f32` rounding of the grid (relative errors near `1e-6`, see docs/precision.md),
/// with a margin.
pub const TIE: f64 = 1e-5;

/// A correlation computed by [`pipeline`].
struct Computed<T: Float> {
    plan: Correlation<T>,
    grid: Vec<Complex<T>>,
    peak: Peak,
    /// Seconds of the pipeline with the argmax.
    time: f64,
}

/// The grid of `Correlation<T>` for `(L, b_out)` on `sig` and `pat`, its peak and the time
/// of the pipeline (after a warm-up if `warm`).
fn pipeline<T: Float>(
    l: usize,
    b_out: usize,
    threads: usize,
    (sig, pat): (&[Complex<T>], &[Complex<T>]),
    warm: bool,
) -> so3fft::Result<Computed<T>> {
    let plan = Correlation::<T>::new(
        l,
        &CorrelationOptions::default()
            .with_b_out(Some(b_out))
            .with_threads(threads),
    )?;
    let zero = crate::precision::zero::<T>();
    let mut grid = vec![zero; plan.num_grid()];
    if warm {
        plan.correlate(sig, pat, &mut grid)?; // first-touch of buffers
    }
    let start = Instant::now();
    plan.correlate(sig, pat, &mut grid)?;
    let peak = grid_argmax(b_out, &grid);
    let time = start.elapsed().as_secs_f64();
    Ok(Computed {
        plan,
        grid,
        peak,
        time,
    })
}

/// How the `f32` peak compares with the `f64` pipeline's on the same samples.
fn against_f64(
    l: usize,
    b_out: usize,
    threads: usize,
    sig: &[Complex64],
    pat: &[Complex64],
    peak32: &Peak,
) -> so3fft::Result<String> {
    let reference = pipeline::<f64>(l, b_out, threads, (sig, pat), false)?;
    let (grid, peak64) = (reference.grid, reference.peak);
    if peak32.index == peak64.index {
        return Ok("peak = f64's grid point".into());
    }
    let there = grid[peak32.index].norm_sqr();
    let below = (peak64.value - there) / peak64.value;
    Ok(if below <= TIE {
        format!("peak: a tie with f64's, {below:.1e} below its |C|^2")
    } else {
        format!("peak NOT f64's: {below:.1e} below its |C|^2")
    })
}

/// Matching at each `L` of `bandwidths` on `threads` workers, in each of `precisions` (one
/// after the other for each `L`, so that their times see the same load of a shared host).
pub fn run(
    bandwidths: &[usize],
    threads: usize,
    precisions: &[Precision],
    report: &mut Report,
) -> so3fft::Result<()> {
    let truth = Rotation::new(2.1234567, 1.2345678, 0.3456789);
    for &l in bandwidths {
        let s2 = S2Plan::<f64>::new(l, &Options::default().with_threads(threads))?;
        let mut rng = SplitMix64::new(31 + l as u64);
        let hat = rng.complex_vec(l * l);
        let ns = s2.num_samples();
        let (mut sig, mut pat) = (
            vec![Complex64::default(); ns],
            vec![Complex64::default(); ns],
        );
        s2.inverse(&rotate_s2_coeffs(l, &hat, &truth)?, &mut sig)?;
        s2.inverse(&hat, &mut pat)?;
        for &p in precisions {
            match p {
                Precision::F64 => rows::<f64>(l, threads, (&sig, &pat), &truth, report)?,
                Precision::F32 => rows::<f32>(l, threads, (&sig, &pat), &truth, report)?,
            }
        }
    }
    Ok(())
}

/// The rows of one `L` in `T`, from the `f64` samples `sig`, `pat` rounded to `T`.
fn rows<T: Float>(
    l: usize,
    threads: usize,
    (sig, pat): (&[Complex64], &[Complex64]),
    truth: &Rotation,
    report: &mut Report,
) -> so3fft::Result<()> {
    let (sig_t, pat_t) = (narrow::<T>(sig), narrow::<T>(pat));
    for (variant, b_out) in [("match-grid", l), ("match-grid-2x", 2 * l)] {
        let computed = pipeline::<T>(l, b_out, threads, (&sig_t, &pat_t), true)?;
        let (plan, peak, t_grid) = (computed.plan, computed.peak, computed.time);
        let err = peak.rotation().angle_to(truth);
        let mut note = format!("grid step pi/{b_out}");
        if T::PRECISION != Precision::F64 {
            let (sig64, pat64) = (widen(&sig_t), widen(&pat_t));
            note += "; ";
            note += &against_f64(l, b_out, threads, &sig64, &pat64, &peak)?;
        }
        report.push(row::<T>(l, variant, err, t_grid, &note));
        if b_out == l {
            let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(l)];
            let start = Instant::now();
            plan.coefficients(&sig_t, &pat_t, &mut coeffs)?;
            let (refined, _) = plan.refine(&coeffs, &peak.rotation())?;
            let t_refine = start.elapsed().as_secs_f64();
            let err = refined.angle_to(truth);
            report.push(row::<T>(
                l,
                "match-refined",
                err,
                t_grid + t_refine,
                "grid + refinement",
            ));
        }
    }
    Ok(())
}

fn row<T: Float>(l: usize, variant: &str, angle: f64, time_s: f64, note: &str) -> Row {
    Row {
        test: "matching".into(),
        b: l,
        variant: variant.into(),
        precision: T::PRECISION,
        rel_l2: f64::NAN,
        max_abs: angle,
        time_s,
        note: format!("angle error (rad); {note}"),
    }
}
