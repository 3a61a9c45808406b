//! Rotational matching as points of the time-against-error chart: a random band-limited
//! function on S^2 and its copy rotated by a known off-grid rotation; the rotation recovered
//! from the correlation grid (`match-grid`), on a grid twice as fine (`match-grid-2x`, a
//! partial plan: degrees below L on the grid of 2L), and refined off the grid
//! (`match-refined`). Error: the geodesic angle to the true rotation (rad); time: the
//! pipeline (two S^2 forwards, combine, inverse SO(3), argmax), plus one refinement.

use crate::record::{Report, Row};
use crate::rng::SplitMix64;
use so3fft::matching::{grid_argmax, rotate_s2_coeffs, Correlation, CorrelationOptions, Rotation};
use so3fft::s2::S2Plan;
use so3fft::{Complex64, Options};
use std::time::Instant;

/// Matching at each `L` of `bandwidths` on `threads` workers.
pub fn run(bandwidths: &[usize], threads: usize, report: &mut Report) -> so3fft::Result<()> {
    let truth = Rotation::new(2.1234567, 1.2345678, 0.3456789);
    for &l in bandwidths {
        let s2 = S2Plan::new(l, &Options::default().with_threads(threads))?;
        let mut rng = SplitMix64::new(31 + l as u64);
        let hat = rng.complex_vec(l * l);
        let ns = s2.num_samples();
        let (mut sig, mut pat) = (
            vec![Complex64::default(); ns],
            vec![Complex64::default(); ns],
        );
        s2.inverse(&rotate_s2_coeffs(l, &hat, &truth)?, &mut sig)?;
        s2.inverse(&hat, &mut pat)?;
        for (variant, b_out) in [("match-grid", l), ("match-grid-2x", 2 * l)] {
            let plan = Correlation::new(
                l,
                &CorrelationOptions::default()
                    .with_b_out(Some(b_out))
                    .with_threads(threads),
            )?;
            let mut grid = vec![Complex64::default(); plan.num_grid()];
            plan.correlate(&sig, &pat, &mut grid)?; // warm-up (first-touch of buffers)
            let start = Instant::now();
            plan.correlate(&sig, &pat, &mut grid)?;
            let peak = grid_argmax(b_out, &grid);
            let t_grid = start.elapsed().as_secs_f64();
            let err = peak.rotation().angle_to(&truth);
            report.push(row(
                l,
                variant,
                err,
                t_grid,
                &format!("grid step pi/{b_out}"),
            ));
            if b_out == l {
                let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(l)];
                let start = Instant::now();
                plan.coefficients(&sig, &pat, &mut coeffs)?;
                let (refined, _) = plan.refine(&coeffs, &peak.rotation())?;
                let t_refine = start.elapsed().as_secs_f64();
                let err = refined.angle_to(&truth);
                report.push(row(
                    l,
                    "match-refined",
                    err,
                    t_grid + t_refine,
                    "grid + refinement",
                ));
            }
        }
    }
    Ok(())
}

fn row(l: usize, variant: &str, angle: f64, time_s: f64, note: &str) -> Row {
    Row {
        test: "matching".into(),
        b: l,
        variant: variant.into(),
        rel_l2: f64::NAN,
        max_abs: angle,
        time_s,
        note: format!("angle error (rad); {note}"),
    }
}
