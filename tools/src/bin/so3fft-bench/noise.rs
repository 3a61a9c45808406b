//! `so3fft-bench noise`: how accurately matching finds a rotation in noisy data. Scenes of
//! smooth functions that are not band-limited, rotated analytically
//! (`so3fft::matching::scene`), white noise in both inputs; per bandwidth and noise level,
//! over many seeds, the angle error of the grid argmax, of the refinement with all degrees,
//! with each fixed degree limit (the best chosen in hindsight), and with the automatic
//! weights, and how often the reported 1-sigma angle covers the error. Then the cost of the
//! weights and of the uncertainty. Table, CSV and chart.

use crate::cli::Options;
use crate::workload::median;
use so3fft::matching::scene::{vmf_scene, Scene};
use so3fft::matching::{Correlation, CorrelationOptions, DegreeWeights, Match};
use so3fft_tools::chart::{self, Figure, LegendPlace, Line, Marker, Panel, Series, XTicks};
use so3fft_tools::progress::Steps;
use std::time::Instant;

/// Noise levels, relative to the samples' rms.
const NOISE: [f64; 4] = [0.0, 0.3, 1.0, 3.0];
/// Degree limits tried; those below B.
const LIMITS: [usize; 8] = [8, 10, 12, 16, 24, 32, 48, usize::MAX];
/// Scenes per bandwidth and noise level unless `--runs` says.
const DEFAULT_SEEDS: usize = 20;

/// One scene's outcome (angles in degrees).
struct Outcome {
    grid: f64,
    all: f64,
    /// Per degree limit of [`limits`], the refined error.
    limited: Vec<f64>,
    auto: f64,
    sigma: f64,
    peak_ratio: f64,
}

/// One bandwidth and noise level over all seeds.
pub struct Level {
    pub b: usize,
    pub noise: f64,
    outcomes: Vec<Outcome>,
    limits: Vec<usize>,
}

/// Median and 90th percentile.
fn spread(v: &[f64]) -> (f64, f64) {
    let mut s = v.to_vec();
    s.sort_by(f64::total_cmp);
    let p90 = s[((0.9 * (s.len() - 1) as f64).round() as usize).min(s.len() - 1)];
    (median(v), p90)
}

impl Level {
    fn column(&self, f: impl Fn(&Outcome) -> f64) -> Vec<f64> {
        self.outcomes.iter().map(f).collect()
    }

    /// The degree limit with the smallest median error, and its errors.
    fn best_limit(&self) -> (usize, Vec<f64>) {
        (0..self.limits.len())
            .map(|i| (self.limits[i], self.column(|o| o.limited[i])))
            .min_by(|a, b| median(&a.1).total_cmp(&median(&b.1)))
            .expect("at least one limit")
    }

    /// Fraction of seeds whose error is at most the reported sigma.
    fn coverage(&self) -> f64 {
        let hits = self.outcomes.iter().filter(|o| o.auto <= o.sigma).count();
        hits as f64 / self.outcomes.len() as f64
    }
}

/// The degree limits of [`LIMITS`] below `b` (the last one `b - 1`).
fn limits(b: usize) -> Vec<usize> {
    let mut v: Vec<usize> = LIMITS.iter().map(|&l| l.min(b - 1)).collect();
    v.dedup();
    v
}

/// A real correlation plan of bandwidth `b` on the grid of `b`.
fn plan(
    b: usize,
    threads: usize,
    deg_lim: Option<usize>,
    weights: DegreeWeights,
) -> so3fft::Result<Correlation> {
    Correlation::new(
        b,
        &CorrelationOptions::default()
            .with_real(true)
            .with_deg_lim(deg_lim)
            .with_weights(weights)
            .with_threads(threads),
    )
}

fn degrees(rad: f64) -> f64 {
    rad.to_degrees()
}

/// Runs the whole pipeline of `plan` on `scene`.
fn find(plan: &Correlation, scene: &Scene, grid: &mut [f64]) -> so3fft::Result<Match> {
    plan.find_real(&scene.signal, &scene.pattern, grid)
}

pub fn run(opts: &Options) -> so3fft::Result<()> {
    let threads = *opts.threads.last().expect("a thread count");
    let seeds = opts.runs.unwrap_or(DEFAULT_SEEDS);
    let mut levels = Vec::new();
    let steps = Steps::new(
        (opts.bandwidths.len() * NOISE.len() * seeds) as u64,
        "scenes",
    );
    for &b in &opts.bandwidths {
        let lims = limits(b);
        let uniform = plan(b, threads, None, DegreeWeights::Uniform)?;
        let auto = plan(b, threads, None, DegreeWeights::Automatic)?;
        let limited: Vec<Correlation> = lims
            .iter()
            .map(|&l| plan(b, threads, Some(l), DegreeWeights::Uniform))
            .collect::<so3fft::Result<_>>()?;
        let mut grid = vec![0.0; uniform.num_grid()];
        for &noise in &NOISE {
            steps.message(format!("B = {b}, noise {noise}"));
            let mut outcomes = Vec::new();
            for seed in 0..seeds as u64 {
                let scene = vmf_scene(b, seed, noise);
                let truth = scene.rotation;
                let err = |m: &Match| degrees(m.rotation.angle_to(&truth));
                let all = find(&uniform, &scene, &mut grid)?;
                let a = find(&auto, &scene, &mut grid)?;
                let limited = limited
                    .iter()
                    .map(|p| find(p, &scene, &mut grid).map(|m| err(&m)))
                    .collect::<so3fft::Result<Vec<f64>>>()?;
                outcomes.push(Outcome {
                    grid: degrees(all.grid_peak.rotation().angle_to(&truth)),
                    all: err(&all),
                    limited,
                    auto: err(&a),
                    sigma: degrees(a.uncertainty.sigma),
                    peak_ratio: a.peak_ratio,
                });
                steps.step();
            }
            levels.push(Level {
                b,
                noise,
                outcomes,
                limits: lims.clone(),
            });
        }
    }
    drop(steps);
    print_table(&levels, seeds);
    write_csv(opts, &levels)?;
    write_chart(opts, &levels)?;
    costs(opts, threads)
}

fn print_table(levels: &[Level], seeds: usize) {
    println!(
        "Angle error to the true rotation, degrees: median / 90th percentile over {seeds} scenes \
         (7 von Mises-Fisher bumps, noise relative to the samples' rms, real plans)"
    );
    println!(
        "{:>4} {:>5} | {:>15} | {:>15} | {:>21} | {:>15} | {:>8} | {:>10}",
        "B",
        "noise",
        "grid argmax",
        "refined, all",
        "best fixed limit",
        "automatic",
        "coverage",
        "peak ratio"
    );
    for lv in levels {
        let fmt = |v: &[f64]| {
            let (m, p) = spread(v);
            format!("{m:>7.4} {p:>7.4}")
        };
        let (lim, best) = lv.best_limit();
        println!(
            "{:>4} {:>5} | {} | {} | {:>4}: {} | {} | {:>7.0}% | {:>10.3}",
            lv.b,
            lv.noise,
            fmt(&lv.column(|o| o.grid)),
            fmt(&lv.column(|o| o.all)),
            lim,
            fmt(&best),
            fmt(&lv.column(|o| o.auto)),
            100.0 * lv.coverage(),
            median(&lv.column(|o| o.peak_ratio)),
        );
    }
}

fn write_csv(opts: &Options, levels: &[Level]) -> so3fft::Result<()> {
    let header = [
        "b",
        "noise",
        "seed",
        "grid_deg",
        "all_deg",
        "auto_deg",
        "sigma_deg",
        "peak_ratio",
        "limits",
        "limited_deg",
    ];
    let rows = levels.iter().flat_map(|lv| {
        lv.outcomes.iter().enumerate().map(move |(seed, o)| {
            let join = |v: Vec<String>| v.join(" ");
            vec![
                lv.b.to_string(),
                lv.noise.to_string(),
                seed.to_string(),
                format!("{:.6e}", o.grid),
                format!("{:.6e}", o.all),
                format!("{:.6e}", o.auto),
                format!("{:.6e}", o.sigma),
                format!("{:.6e}", o.peak_ratio),
                join(lv.limits.iter().map(|l| l.to_string()).collect()),
                join(o.limited.iter().map(|e| format!("{e:.6e}")).collect()),
            ]
        })
    });
    so3fft_tools::csv_out::write(&opts.csv, &header, rows)
        .map_err(|e| so3fft::Error::InvalidArgument(format!("{}: {e}", opts.csv.display())))
}

fn write_chart(opts: &Options, levels: &[Level]) -> so3fft::Result<()> {
    let mut bs: Vec<usize> = levels.iter().map(|l| l.b).collect();
    bs.dedup();
    let panels = bs
        .iter()
        .map(|&b| {
            let mut series = vec![
                Series::new(
                    "grid argmax",
                    chart::hex("#888888"),
                    Line::Dotted,
                    Marker::Square,
                ),
                Series::new(
                    "refined, all degrees",
                    chart::hex("#1f77b4"),
                    Line::Dashed,
                    Marker::Triangle,
                ),
                Series::new(
                    "refined, best fixed degree limit (hindsight)",
                    chart::hex("#2ca02c"),
                    Line::Dashed,
                    Marker::Diamond,
                ),
                Series::new(
                    "refined, automatic weights",
                    chart::hex("#d62728"),
                    Line::Solid,
                    Marker::Circle,
                ),
                Series::new(
                    "reported 1-sigma angle (median)",
                    chart::hex("#d62728"),
                    Line::NoLine,
                    Marker::Diamond,
                ),
            ];
            for lv in levels.iter().filter(|l| l.b == b) {
                let m = |v: Vec<f64>| median(&v);
                series[0].push(lv.noise, m(lv.column(|o| o.grid)));
                series[1].push(lv.noise, m(lv.column(|o| o.all)));
                series[2].push(lv.noise, m(lv.best_limit().1));
                series[3].push_labelled(
                    lv.noise,
                    m(lv.column(|o| o.auto)),
                    format!("{:.0}%", 100.0 * lv.coverage()),
                );
                series[4].push(lv.noise, m(lv.column(|o| o.sigma)));
            }
            Panel {
                title: format!("B = {b}: median angle error (label: coverage of 1 sigma)"),
                x_label: "noise (relative to the samples' rms)".into(),
                y_label: "angle error, degrees".into(),
                x_ticks: XTicks::Decades,
                series,
                x_rules: Vec::new(),
                y_rules: Vec::new(),
            }
        })
        .collect();
    let figure = Figure {
        panels,
        panel_width: 560,
        plot_height: 360,
        legend: LegendPlace::Below,
        columns: 3,
    };
    let svg = figure.svg().map_err(so3fft::Error::InvalidArgument)?;
    std::fs::write(&opts.plot, svg)
        .map_err(|e| so3fft::Error::InvalidArgument(format!("{}: {e}", opts.plot.display())))?;
    println!("wrote {} and {}", opts.csv.display(), opts.plot.display());
    Ok(())
}

/// The cost of the automatic weights in the pipeline (correlation and argmax) and of the
/// uncertainty against one refinement: calls alternating, medians.
fn costs(opts: &Options, threads: usize) -> so3fft::Result<()> {
    println!("\nCost (medians of alternating calls, {threads} threads):");
    println!(
        "{:>4} | {:>12} {:>12} {:>8} | {:>12} {:>12} {:>8}",
        "B", "uniform s", "automatic s", "ratio", "refine s", "uncertain. s", "ratio"
    );
    for &b in &opts.bandwidths {
        let uniform = plan(b, threads, None, DegreeWeights::Uniform)?;
        let auto = plan(b, threads, None, DegreeWeights::Automatic)?;
        let scene = vmf_scene(b, 7, 1.0);
        let mut grid = vec![0.0; uniform.num_grid()];
        let mut coeffs = vec![so3fft::Complex64::default(); so3fft::num_coeffs(b)];
        let (mut tu, mut ta, mut tr, mut tc) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
        let runs = opts.runs_for(b).max(6);
        for run in 0..runs {
            // Each plan goes first in every other run.
            let mut pair = [(&uniform, &mut tu), (&auto, &mut ta)];
            if run % 2 == 1 {
                pair.reverse();
            }
            for (p, t) in pair {
                let start = Instant::now();
                p.correlate_real_argmax(&scene.signal, &scene.pattern, &mut grid)?;
                t.push(start.elapsed().as_secs_f64());
            }
            let peak = auto.correlate_real_argmax(&scene.signal, &scene.pattern, &mut grid)?;
            auto.coefficients_real(&scene.signal, &scene.pattern, &mut coeffs)?;
            let spectra = auto.spectra_real(&scene.signal, &scene.pattern)?;
            let start = Instant::now();
            let (g, _) = auto.refine(&coeffs, &peak.rotation())?;
            tr.push(start.elapsed().as_secs_f64());
            let start = Instant::now();
            auto.uncertainty(&coeffs, &g, &spectra)?;
            tc.push(start.elapsed().as_secs_f64());
        }
        let (u, a, r, c) = (median(&tu), median(&ta), median(&tr), median(&tc));
        println!(
            "{b:>4} | {u:>12.3e} {a:>12.3e} {:>8.3} | {r:>12.3e} {c:>12.3e} {:>8.3}",
            a / u,
            c / r
        );
    }
    Ok(())
}
