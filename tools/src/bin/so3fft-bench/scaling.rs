//! `so3fft-bench scaling`: thread scaling on a shared machine, the whole transform and its
//! stages for each thread count, with windows disturbed by other processes thrown away.
//!
//! Each measurement is a window of `k` inverse + forward pairs (`k` chosen so the window
//! lasts at least [`WINDOW_SECONDS`] on the first thread count). A window counts only if the
//! CPU time used by other processes during it (from `/proc/stat`, minus this process's own
//! time) stays below [`DISTURBANCE_LIMIT`] of the machine; otherwise it is repeated. The
//! plans of the thread counts alternate, and medians of the clean windows are reported.

use crate::cli::Options;
use crate::workload::{median, random_coeffs};
use so3fft::{Complex64, Plan, StageTimes};
use so3fft_tools::bar_println;
use so3fft_tools::progress::Steps;
use std::time::{Duration, Instant};

/// Shortest window, in seconds of the first thread count's round trip.
const WINDOW_SECONDS: f64 = 0.3;
/// Largest share of the machine other processes may use during a clean window.
const DISTURBANCE_LIMIT: f64 = 0.03;

/// CPU clock ticks from `/proc`.
#[derive(Clone, Copy)]
struct Ticks {
    /// Busy ticks of the whole machine.
    busy: u64,
    /// All ticks of the whole machine.
    all: u64,
    /// User and system ticks of this process.
    own: u64,
}

impl Ticks {
    /// Now (zeros where `/proc` cannot be read).
    fn read() -> Ticks {
        let stat = std::fs::read_to_string("/proc/stat").unwrap_or_default();
        let cpu: Vec<u64> = stat
            .lines()
            .next()
            .unwrap_or("")
            .split_whitespace()
            .skip(1)
            .filter_map(|x| x.parse().ok())
            .collect();
        let all: u64 = cpu.iter().sum();
        let idle = cpu.get(3).copied().unwrap_or(0) + cpu.get(4).copied().unwrap_or(0);
        let own = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
        // Fields after the command name (which may contain spaces), from the state on:
        // utime is the 12th, stime the 13th.
        let rest = own.rsplit(')').next().unwrap_or("");
        let fields: Vec<&str> = rest.split_whitespace().collect();
        let field = |i: usize| {
            fields
                .get(i)
                .and_then(|x| x.parse::<u64>().ok())
                .unwrap_or(0)
        };
        Ticks {
            busy: all - idle,
            all,
            own: field(11) + field(12),
        }
    }
}

/// Mean stage times of the inverse and the forward over one window.
#[derive(Clone, Copy, Default)]
struct Window {
    inverse: StageTimes,
    forward: StageTimes,
}

/// The arrays of one bandwidth's round trips.
struct RoundTrip {
    coeffs: Vec<Complex64>,
    samples: Vec<Complex64>,
    result: Vec<Complex64>,
}

impl RoundTrip {
    /// One clean window of `pairs` inverse + forward pairs of `plan`.
    fn clean_window(&mut self, plan: &Plan, pairs: usize) -> Result<Window, so3fft::Error> {
        loop {
            let before = Ticks::read();
            let mut window = Window::default();
            let share = 1.0 / pairs as f64;
            for _ in 0..pairs {
                let inverse = plan.inverse(&self.coeffs, &mut self.samples)?;
                let forward = plan.forward(&self.samples, &mut self.result)?;
                for (sum, x) in [
                    (&mut window.inverse, inverse),
                    (&mut window.forward, forward),
                ] {
                    sum.fft += x.fft * share;
                    sum.dwt += x.dwt * share;
                    sum.total += x.total * share;
                }
            }
            let after = Ticks::read();
            let all = (after.all - before.all) as f64;
            let others = (after.busy - before.busy).saturating_sub(after.own - before.own);
            if (others as f64) <= DISTURBANCE_LIMIT * all + 1.0 {
                return Ok(window);
            }
            so3fft_tools::bar_eprintln!(
                "window disturbed: other processes used {:.0}% of the machine",
                100.0 * others as f64 / all
            );
            std::thread::sleep(Duration::from_millis(500));
        }
    }
}

/// Runs the scaling measurement for every bandwidth of `opts`.
pub fn run(opts: &Options) -> Result<(), so3fft::Error> {
    let runs = opts.runs.unwrap_or(5);
    println!("medians of {runs} clean windows; seconds per transform");
    println!(
        "{:>5} {:>3} {:>10} {:>10} {:>10} {:>10} {:>10} {:>10}  fft threading",
        "B", "thr", "inv", "inv fft", "inv dwt", "fwd", "fwd fft", "fwd dwt"
    );
    let bar = Steps::new(opts.bandwidths.len() as u64, "bandwidths");
    for &b in &opts.bandwidths {
        bar.message(format!("(B = {b})"));
        let plans = opts
            .threads
            .iter()
            .map(|&threads| {
                Plan::new(
                    b,
                    &so3fft::Options::default()
                        .with_threads(threads)
                        .with_rigor(opts.rigor),
                )
            })
            .collect::<Result<Vec<_>, _>>()?;
        scale_bandwidth(b, &plans, runs)?;
        bar.step();
    }
    Ok(())
}

/// Clean windows of every plan of bandwidth `b`, in turn; prints their medians and the
/// speed-ups over the first plan.
fn scale_bandwidth(b: usize, plans: &[Plan], runs: usize) -> Result<(), so3fft::Error> {
    let mut round_trip = RoundTrip {
        coeffs: random_coeffs(so3fft::num_coeffs(b), 0x9e37_79b9_7f4a_7c15 ^ b as u64),
        samples: vec![Complex64::default(); so3fft::num_samples(b)],
        result: vec![Complex64::default(); so3fft::num_coeffs(b)],
    };
    // Window length from the first plan's warm-up round trip.
    let start = Instant::now();
    plans[0].inverse(&round_trip.coeffs, &mut round_trip.samples)?;
    plans[0].forward(&round_trip.samples, &mut round_trip.result)?;
    let pairs = ((WINDOW_SECONDS / start.elapsed().as_secs_f64()).ceil() as usize).max(1);
    for plan in &plans[1..] {
        plan.inverse(&round_trip.coeffs, &mut round_trip.samples)?;
    }
    let mut windows: Vec<Vec<Window>> = vec![Vec::new(); plans.len()];
    for run in 0..runs {
        for i in 0..plans.len() {
            let which = (i + run) % plans.len();
            windows[which].push(round_trip.clean_window(&plans[which], pairs)?);
        }
    }
    let mut round_trip_medians = Vec::new();
    for (plan, windows) in plans.iter().zip(&windows) {
        let of = |f: fn(&Window) -> f64| median(&windows.iter().map(f).collect::<Vec<_>>());
        bar_println!(
            "{:>5} {:>3} {:>10.4e} {:>10.4e} {:>10.4e} {:>10.4e} {:>10.4e} {:>10.4e}",
            b,
            plan.threads(),
            of(|w| w.inverse.total),
            of(|w| w.inverse.fft),
            of(|w| w.inverse.dwt),
            of(|w| w.forward.total),
            of(|w| w.forward.fft),
            of(|w| w.forward.dwt),
        );
        round_trip_medians.push((
            of(|w| w.inverse.total + w.forward.total),
            of(|w| w.inverse.fft + w.forward.fft),
        ));
    }
    // Speed-ups from the medians of per-window sums (inverse + forward).
    let (total_first, fft_first) = round_trip_medians[0];
    for (plan, (total, fft)) in plans.iter().zip(&round_trip_medians).skip(1) {
        bar_println!(
            "B = {b}: {} threads over {}: whole transform {:.3}x, FFT stage {:.3}x",
            plan.threads(),
            plans[0].threads(),
            total_first / total,
            fft_first / fft
        );
    }
    Ok(())
}
