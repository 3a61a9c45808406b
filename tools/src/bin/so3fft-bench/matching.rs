//! `so3fft-bench match` (or `--match`): rotational matching. Per bandwidth `L`: a random
//! band-limited pattern rotated by a random off-grid rotation is recovered; medians of the
//! pipeline (two S^2 forwards, combine, inverse SO(3), grid argmax) for complex and real
//! inputs, the time of one refinement (the true peak) and of ten peaks refined together,
//! and the grid and refined angle errors; then many templates (eight patterns against one
//! signal) and shells (four) against a single correlation. A second table sets each
//! pipeline median against the pipeline's floor measured in the same run (`floor.rs`).

use crate::cli::{rigor_name, Options};
use crate::floor::{self, SliceFloor};
use crate::workload::{dwt_flops_exact, dwt_flops_real, median, random_coeffs};
use so3fft::matching::{rotate_s2_coeffs, top_peaks, Correlation, CorrelationOptions, Rotation};
use so3fft::s2::S2Plan;
use so3fft::Complex64;
use std::time::Instant;

/// One line of the floor table: a bandwidth and thread count.
struct FloorRow {
    l: usize,
    threads: usize,
    /// Pipeline medians (seconds): complex, real.
    pipeline: (f64, f64),
    /// The floor's FFT part (medians, seconds): complex, real.
    fft: (f64, f64),
    /// The DWT kernels' summed time over every cluster, one thread (`None`: no
    /// `internals`).
    dwt_one_thread: Option<f64>,
}

/// Runs the matching measurement for every bandwidth and thread count of `opts`.
pub fn run(opts: &Options) -> so3fft::Result<()> {
    // Before any library plan exists (see floor.rs for why that is safe).
    let slice_plans = floor::plan_slices(&opts.bandwidths, opts.rigor)?;
    let mut floor_rows = Vec::new();
    println!("rotational matching: medians in ms; angle errors in rad (geodesic)");
    println!(
        "{:>5} {:>3} {:>10} {:>10} {:>10} {:>10} {:>10} {:>11} {:>11}",
        "L",
        "thr",
        "complex",
        "real",
        "1 refine",
        "10 peaks",
        "grid step",
        "grid err",
        "refined err"
    );
    for &l in &opts.bandwidths {
        let dwt_one_thread = floor::dwt_kernel_seconds(l)?;
        for &threads in &opts.threads {
            let runs = opts.runs.unwrap_or(5);
            let truth = Rotation::new(2.1234567, 1.2345678, 0.3456789);
            let s2 = S2Plan::new(l, &so3fft::Options::default().with_threads(threads))?;
            let ns = s2.num_samples();
            // Complex inputs.
            let hat = random_coeffs(l * l, 3);
            let (mut sig, mut pat) = (
                vec![Complex64::default(); ns],
                vec![Complex64::default(); ns],
            );
            s2.inverse(&rotate_s2_coeffs(l, &hat, &truth)?, &mut sig)?;
            s2.inverse(&hat, &mut pat)?;
            let plan = Correlation::new(
                l,
                &CorrelationOptions::default().with_plans(
                    so3fft::Options::default()
                        .with_threads(threads)
                        .with_rigor(opts.rigor),
                ),
            )?;
            // The floor's FFT part: its runs right after the pipeline's of the same kind
            // (not interleaved with them, which takes the pipeline's data out of the caches
            // between its runs: real inputs at L = 64 took 7.1 ms against 5.2, medians of
            // six alternated rounds here).
            let mut slice_floor = SliceFloor::new(floor::plans_for(&slice_plans, l), threads)?;
            let mut grid = vec![Complex64::default(); plan.num_grid()];
            let mut times = Vec::new();
            let mut peak = None;
            for _ in 0..runs {
                let t = Instant::now();
                // The argmax taken while the grid is computed (`grid_argmax`'s point).
                peak = Some(plan.correlate_argmax(&sig, &pat, &mut grid)?);
                times.push(t.elapsed().as_secs_f64());
            }
            let fft_times: Vec<f64> = (0..runs).map(|_| slice_floor.complex()).collect();
            let (t_complex, fft_complex) = (median(&times), median(&fft_times));
            // Real inputs.
            let rhat = crate::s2::hermitian(l, 5);
            let (mut rsig, mut rpat) = (vec![0.0; ns], vec![0.0; ns]);
            s2.inverse_real(&rotate_s2_coeffs(l, &rhat, &truth)?, &mut rsig)?;
            s2.inverse_real(&rhat, &mut rpat)?;
            let rplan = Correlation::new(
                l,
                &CorrelationOptions::default().with_real(true).with_plans(
                    so3fft::Options::default()
                        .with_threads(threads)
                        .with_rigor(opts.rigor),
                ),
            )?;
            let mut rgrid = vec![0.0; rplan.num_grid()];
            let mut times = Vec::new();
            for _ in 0..runs {
                let t = Instant::now();
                let _ = rplan.correlate_real_argmax(&rsig, &rpat, &mut rgrid)?;
                times.push(t.elapsed().as_secs_f64());
            }
            let fft_times: Vec<f64> = (0..runs).map(|_| slice_floor.real()).collect();
            let (t_real, fft_real) = (median(&times), median(&fft_times));
            drop(slice_floor);
            // Ten peaks refined together (complex inputs): the grid's ten largest local
            // maxima at least two grid steps apart, the largest being the true peak.
            let peak = peak.expect("at least one run");
            let mut coeffs = vec![Complex64::default(); so3fft::num_coeffs(l)];
            plan.coefficients(&sig, &pat, &mut coeffs)?;
            let step = std::f64::consts::PI / l as f64;
            let mut starts: Vec<Rotation> = top_peaks(l, &grid, 10, 2.0 * step)
                .iter()
                .map(|p| p.rotation())
                .collect();
            starts.resize(10, peak.rotation());
            let (mut one, mut ten) = (Vec::new(), Vec::new());
            let mut refined = peak.rotation();
            for _ in 0..runs {
                let t = Instant::now();
                refined = plan.refine(&coeffs, &peak.rotation())?.0;
                one.push(t.elapsed().as_secs_f64());
                let t = Instant::now();
                let _ = plan.refine_many(&coeffs, &starts)?;
                ten.push(t.elapsed().as_secs_f64());
            }
            let (t_one, t_ten) = (median(&one), median(&ten));
            println!(
                "{l:>5} {:>3} {:>10.3} {:>10.3} {:>10.3} {:>10.3} {:>10.3e} {:>11.3e} {:>11.3e}",
                threads,
                t_complex * 1e3,
                t_real * 1e3,
                t_one * 1e3,
                t_ten * 1e3,
                std::f64::consts::PI / l as f64,
                peak.rotation().angle_to(&truth),
                refined.angle_to(&truth)
            );
            floor_rows.push(FloorRow {
                l,
                threads,
                pipeline: (t_complex, t_real),
                fft: (fft_complex, fft_real),
                dwt_one_thread,
            });
        }
    }
    print_floor(opts, &floor_rows)?;
    drop(slice_plans);
    many_and_shells(opts)
}

/// The floor table: per bandwidth, thread count and kind, the pipeline median, the floor's
/// FFT and DWT parts, the floor and pipeline / floor.
fn print_floor(opts: &Options, rows: &[FloorRow]) -> so3fft::Result<()> {
    let isa = format!("{:?}", so3fft::Isa::selected()?).to_ascii_lowercase();
    println!();
    println!("matching floor (docs/benchmark.md): medians in ms; floor = FFT + DWT");
    println!(
        "  FFT: FFTW alone on the grid's 2L slices of 2L x 2L (complex: in-place c2c; real: \
         c2r from the half spectra), rigor {}, slices split over the threads, no copies",
        rigor_name(opts.rigor)
    );
    println!(
        "  DWT: nominal DWT flops (real: the real count) / the {isa} inverse kernel's \
         in-cache rate (DWT GF/s: every cluster, one thread) / threads"
    );
    println!(
        "{:>5} {:>3} {:>8} {:>10} {:>10} {:>10} {:>9} {:>10} {:>10}",
        "L", "thr", "kind", "pipeline", "FFT", "DWT", "DWT GF/s", "floor", "pipe/floor"
    );
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    for r in rows {
        let threads = if r.threads == 0 { cores } else { r.threads };
        for (kind, pipeline, fft, flops) in [
            ("complex", r.pipeline.0, r.fft.0, dwt_flops_exact(r.l)),
            ("real", r.pipeline.1, r.fft.1, dwt_flops_real(r.l)),
        ] {
            let head = format!(
                "{:>5} {:>3} {kind:>8} {:>10.3} {:>10.3}",
                r.l,
                r.threads,
                pipeline * 1e3,
                fft * 1e3
            );
            match r.dwt_one_thread {
                Some(t) => {
                    // The kernels' rate over every cluster, against the exact count.
                    let rate = dwt_flops_exact(r.l) as f64 / t;
                    let dwt = flops as f64 / rate / threads as f64;
                    let floor = fft + dwt;
                    println!(
                        "{head} {:>10.3} {:>9.1} {:>10.3} {:>10.2}",
                        dwt * 1e3,
                        rate / 1e9,
                        floor * 1e3,
                        pipeline / floor
                    );
                }
                None => println!("{head}  n/a (build with --features internals)"),
            }
        }
    }
    Ok(())
}

/// Many templates and shells: per `L`, one complex correlation (no argmax), eight patterns
/// against one signal (`correlate_many`: the signal transformed once) per pattern, and four
/// weighted shells (`correlate_shells`: four pairs of S^2 transforms, one inverse); medians.
fn many_and_shells(opts: &Options) -> so3fft::Result<()> {
    println!();
    println!("many templates and shells: medians in ms");
    println!(
        "{:>5} {:>3} {:>10} {:>14} {:>10} {:>10}",
        "L", "thr", "single", "8 patterns/1", "ratio", "4 shells"
    );
    for &l in &opts.bandwidths {
        for &threads in &opts.threads {
            let runs = opts.runs.unwrap_or(5);
            let plan = Correlation::new(
                l,
                &CorrelationOptions::default().with_plans(
                    so3fft::Options::default()
                        .with_threads(threads)
                        .with_rigor(opts.rigor),
                ),
            )?;
            let ns = 4 * l * l;
            let (sig, pats) = (random_coeffs(ns, 11), random_coeffs(8 * ns, 12));
            let mut grid = vec![Complex64::default(); plan.num_grid()];
            let mut grids = vec![Complex64::default(); 8 * plan.num_grid()];
            let (mut one, mut many, mut shells) = (Vec::new(), Vec::new(), Vec::new());
            let shell_list: Vec<(&[Complex64], &[Complex64], f64)> = (0..4)
                .map(|s| {
                    (
                        &pats[s * ns..][..ns],
                        &pats[(s + 4) * ns..][..ns],
                        1.0 + s as f64,
                    )
                })
                .collect();
            for _ in 0..runs {
                let t = Instant::now();
                plan.correlate(&sig, &pats[..ns], &mut grid)?;
                one.push(t.elapsed().as_secs_f64());
                let t = Instant::now();
                plan.correlate_many(&sig, &pats, &mut grids)?;
                many.push(t.elapsed().as_secs_f64() / 8.0);
                let t = Instant::now();
                plan.correlate_shells(&shell_list, &mut grid)?;
                shells.push(t.elapsed().as_secs_f64());
            }
            let (t_one, t_many, t_shells) = (median(&one), median(&many), median(&shells));
            println!(
                "{l:>5} {threads:>3} {:>10.3} {:>14.3} {:>10.3} {:>10.3}",
                t_one * 1e3,
                t_many * 1e3,
                t_many / t_one,
                t_shells * 1e3
            );
        }
    }
    Ok(())
}
