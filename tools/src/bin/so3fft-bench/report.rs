//! Result rows, the printed tables, the 1-to-N thread speed-ups and the CSV file.
//!
//! A value that does not apply to a row (the FFT stage of the plain DWT, say) is NaN in the
//! row, "n/a" in the tables and an empty field in the CSV.

use std::fmt::Write as _;
use std::path::Path;

/// Median stage times of one direction, in seconds.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stages {
    pub fft: f64,
    pub dwt: f64,
}

/// What a row measures.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Variant {
    /// The library's complex transforms, default options (skipping negligible Wigner-d).
    Complex,
    /// The same with `skip_bits: Some(0)` (every degree of every beta computed).
    NoSkip,
    /// The plain one-thread DWT of `naive.rs` (no FFT stage; times are DWT times).
    Naive,
    /// The real-signal transforms `forward_real` / `inverse_real`.
    Real,
}

impl Variant {
    pub fn name(self) -> &'static str {
        match self {
            Variant::Complex => "complex",
            Variant::NoSkip => "noskip",
            Variant::Naive => "naive",
            Variant::Real => "real",
        }
    }
}

/// Resident memory of a measured phase (see `memory.rs`), in bytes.
#[derive(Clone, Copy, Debug)]
pub struct Memory {
    /// Peak resident set size during the phase (`VmHWM` after a reset).
    pub peak: u64,
    /// Resident set size when the phase started.
    pub start: u64,
    /// `Plan::memory_bytes()` (0 for the plain DWT).
    pub plan: u64,
    /// Input plus output of one transform: samples and coefficients.
    pub arrays: u64,
}

impl Memory {
    /// The figures of a measured `phase` with the plan's and the arrays' bytes.
    pub fn of_phase(phase: crate::memory::Phase, plan: u64, arrays: u64) -> Memory {
        Memory {
            peak: phase.peak,
            start: phase.start,
            plan,
            arrays,
        }
    }

    pub fn peak_over_arrays(&self) -> f64 {
        self.peak as f64 / self.arrays as f64
    }

    pub fn growth(&self) -> u64 {
        self.peak.saturating_sub(self.start)
    }
}

/// Everything measured for one (variant, bandwidth, threads) configuration.
#[derive(Clone, Debug)]
pub struct Row {
    pub variant: Variant,
    pub bandwidth: usize,
    /// Threads the plan actually uses (a request of 0 means all cores).
    pub threads: usize,
    pub runs: usize,
    pub fwd_median: f64,
    pub inv_median: f64,
    pub fwd: Stages,
    pub inv: Stages,
    /// DWT flops per direction (exact count).
    pub dwt_flops: u64,
    /// Measured single-core FMA peak, GFLOP/s.
    pub peak_1core: f64,
    pub max_abs_err: f64,
    pub rel_l2_err: f64,
    /// Peak memory of the timed phase (`None`: not measurable).
    pub memory: Option<Memory>,
    /// (forward, inverse) ratios whose meaning depends on the variant: `Naive`: library
    /// one-thread DWT stage time / plain DWT time; `NoSkip`: DWT stage time without / with
    /// skipping; `Real`: whole-transform time real / complex at the same B and threads.
    pub ratio: Option<(f64, f64)>,
    /// (forward, inverse) process CPU time, all threads, medians (`None`: not measured).
    pub cpu: Option<(f64, f64)>,
}

impl Row {
    pub fn fwd_dwt_gflops(&self) -> f64 {
        self.dwt_flops as f64 / self.fwd.dwt / 1e9
    }

    pub fn inv_dwt_gflops(&self) -> f64 {
        self.dwt_flops as f64 / self.inv.dwt / 1e9
    }

    /// Peak available to this configuration: single-core peak times threads used (the measured
    /// all-core peak is printed in the header for comparison).
    fn peak(&self) -> f64 {
        self.peak_1core * self.threads as f64
    }

    pub fn fwd_frac_peak(&self) -> f64 {
        self.fwd_dwt_gflops() / self.peak()
    }

    pub fn inv_frac_peak(&self) -> f64 {
        self.inv_dwt_gflops() / self.peak()
    }

    /// Share of its threads' time the run got: CPU time / (wall time x threads), forward and
    /// inverse together. Well below 1: other processes had the cores (or threads idled).
    pub fn utilisation(&self) -> f64 {
        let (wf, wi) = if self.variant == Variant::Naive {
            (self.fwd.dwt, self.inv.dwt)
        } else {
            (self.fwd_median, self.inv_median)
        };
        self.cpu.map_or(f64::NAN, |(f, i)| {
            (f + i) / ((wf + wi) * self.threads as f64)
        })
    }
}

/// Column header of the printed table.
pub fn table_header() -> String {
    format!(
        "{:>5} {:>3} {:>4} | {:>9} {:>9} | {:>9} {:>9} {:>9} {:>9} | {:>7} {:>7} {:>5} {:>5} | {:>8} {:>8} | {:>8} {:>4}\n{}",
        "B", "thr", "runs",
        "fwd s", "inv s",
        "fwd fft", "fwd dwt", "inv fft", "inv dwt",
        "fwd GF", "inv GF", "fwd%", "inv%",
        "max err", "rel L2",
        "peak MiB", "util",
        "-".repeat(150),
    )
}

/// `x` in the given format, or "n/a" when NaN (a value that does not apply).
macro_rules! or_na {
    ($x:expr, $fmt:literal) => {{
        let x: f64 = $x;
        if x.is_nan() {
            "n/a".to_string()
        } else {
            format!($fmt, x)
        }
    }};
}

fn mib(bytes: u64) -> f64 {
    bytes as f64 / (1u64 << 20) as f64
}

fn peak_mib(r: &Row) -> String {
    r.memory
        .map_or("n/a".to_string(), |m| format!("{:.0}", mib(m.peak)))
}

/// One line of the printed table.
pub fn table_line(r: &Row) -> String {
    format!(
        "{:>5} {:>3} {:>4} | {:>9} {:>9} | {:>9} {:>9} {:>9} {:>9} | {:>7.2} {:>7.2} {:>5.1} {:>5.1} | {:>8.2e} {:>8.2e} | {:>8} {:>4}",
        r.bandwidth, r.threads, r.runs,
        or_na!(r.fwd_median, "{:.4e}"), or_na!(r.inv_median, "{:.4e}"),
        or_na!(r.fwd.fft, "{:.3e}"), or_na!(r.fwd.dwt, "{:.3e}"),
        or_na!(r.inv.fft, "{:.3e}"), or_na!(r.inv.dwt, "{:.3e}"),
        r.fwd_dwt_gflops(), r.inv_dwt_gflops(),
        100.0 * r.fwd_frac_peak(), 100.0 * r.inv_frac_peak(),
        r.max_abs_err, r.rel_l2_err,
        peak_mib(r), or_na!(r.utilisation(), "{:.2}"),
    )
}

/// Speed-up of every multi-threaded row over the single-threaded row of the same bandwidth
/// (whole transform and DWT stage; complex rows only); empty when no bandwidth was measured
/// with both.
pub fn speedups(rows: &[Row]) -> String {
    let complex = || rows.iter().filter(|r| r.variant == Variant::Complex);
    let mut out = String::new();
    for one in complex().filter(|r| r.threads == 1) {
        let many = complex().filter(|r| r.bandwidth == one.bandwidth && r.threads > 1);
        for r in many {
            let _ = writeln!(
                out,
                "B = {:>4}: {} threads over 1: forward {:.2}x, inverse {:.2}x (DWT stage {:.2}x / {:.2}x)",
                r.bandwidth,
                r.threads,
                one.fwd_median / r.fwd_median,
                one.inv_median / r.inv_median,
                one.fwd.dwt / r.fwd.dwt,
                one.inv.dwt / r.inv.dwt,
            );
        }
    }
    out
}

/// The row of `variant` at (b, threads), if measured.
pub fn find(rows: &[Row], variant: Variant, b: usize, threads: usize) -> Option<&Row> {
    rows.iter()
        .find(|r| r.variant == variant && r.bandwidth == b && r.threads == threads)
}

/// With against without skipping of negligible Wigner-d prefixes, per bandwidth: the no-skip
/// rows, whose `ratio` (no-skip / skip DWT stage) comes from runs paired with a skipping
/// plan (interleaved at B <= 256; see the callers), and the complex row of the same threads
/// for the errors with skipping. `missing` lists the bandwidths where the no-skip plan could
/// not be made, with the reason.
pub fn skip_table(rows: &[Row], missing: &[(usize, String)]) -> String {
    let mut out = format!(
        "{:>5} {:>3} | {:>9} {:>9} {:>6} | {:>9} {:>9} {:>6} | {:>8} {:>8} | {:>8} {:>8} | {:>4}\n{}\n",
        "B", "thr",
        "fwd dwt", "no-skip", "ratio",
        "inv dwt", "no-skip", "ratio",
        "max err", "no-skip",
        "rel L2", "no-skip",
        "util",
        "-".repeat(111),
    );
    let mut bandwidths: Vec<usize> = rows
        .iter()
        .filter(|r| r.variant == Variant::NoSkip)
        .map(|r| r.bandwidth)
        .chain(missing.iter().map(|m| m.0))
        .collect();
    bandwidths.sort_unstable();
    bandwidths.dedup();
    for b in bandwidths {
        if let Some(noskip) = rows
            .iter()
            .find(|r| r.variant == Variant::NoSkip && r.bandwidth == b)
        {
            let (rf, ri) = noskip.ratio.unwrap_or((f64::NAN, f64::NAN));
            let skip_row = find(rows, Variant::Complex, b, noskip.threads);
            let err = |f: fn(&Row) -> f64| skip_row.map_or(f64::NAN, f);
            let _ = writeln!(
                out,
                "{:>5} {:>3} | {:>9} {:>9.3e} {:>6} | {:>9} {:>9.3e} {:>6} | {:>8.2e} {:>8.2e} | {:>8.2e} {:>8.2e} | {:>4}",
                b, noskip.threads,
                or_na!(noskip.fwd.dwt / rf, "{:.3e}"), noskip.fwd.dwt, or_na!(rf, "{:.3}"),
                or_na!(noskip.inv.dwt / ri, "{:.3e}"), noskip.inv.dwt, or_na!(ri, "{:.3}"),
                err(|r| r.max_abs_err), noskip.max_abs_err,
                err(|r| r.rel_l2_err), noskip.rel_l2_err,
                or_na!(noskip.utilisation(), "{:.2}"),
            );
        } else if let Some((_, why)) = missing.iter().find(|m| m.0 == b) {
            let _ = writeln!(out, "{b:>5}     | no-skip run n/a: {why}");
        }
    }
    out
}

/// The plain one-thread DWT against the library's one-thread DWT stage.
pub fn naive_table(rows: &[Row]) -> String {
    let mut out = format!(
        "{:>5} | {:>9} {:>9} {:>8} {:>7} | {:>9} {:>9} {:>8} {:>7} | {:>7} | {:>8} {:>8}\n{}\n",
        "B",
        "plain fwd",
        "lib fwd",
        "lib/pl",
        "speedup",
        "plain inv",
        "lib inv",
        "lib/pl",
        "speedup",
        "pl GF",
        "max err",
        "rel L2",
        "-".repeat(112),
    );
    for r in rows.iter().filter(|r| r.variant == Variant::Naive) {
        let (rf, ri) = r.ratio.unwrap_or((f64::NAN, f64::NAN));
        let _ = writeln!(
            out,
            "{:>5} | {:>9.3e} {:>9} {:>8} {:>6}x | {:>9.3e} {:>9} {:>8} {:>6}x | {:>7.2} | {:>8.2e} {:>8.2e}",
            r.bandwidth,
            r.fwd.dwt, or_na!(rf * r.fwd.dwt, "{:.3e}"), or_na!(rf, "{:.4}"), or_na!(1.0 / rf, "{:.1}"),
            r.inv.dwt, or_na!(ri * r.inv.dwt, "{:.3e}"), or_na!(ri, "{:.4}"), or_na!(1.0 / ri, "{:.1}"),
            r.fwd_dwt_gflops(),
            r.max_abs_err, r.rel_l2_err,
        );
    }
    out
}

/// Peak memory of every row that has it.
pub fn memory_table(rows: &[Row]) -> String {
    let mut out = format!(
        "{:>5} {:>3} {:>8} | {:>10} {:>10} {:>10} {:>10} | {:>10}\n{}\n",
        "B",
        "thr",
        "variant",
        "peak MiB",
        "growth MiB",
        "plan MiB",
        "in+out MiB",
        "peak/(in+out)",
        "-".repeat(86),
    );
    for r in rows {
        if let Some(m) = r.memory {
            let _ = writeln!(
                out,
                "{:>5} {:>3} {:>8} | {:>10.1} {:>10.1} {:>10.1} {:>10.1} | {:>10.4}",
                r.bandwidth,
                r.threads,
                r.variant.name(),
                mib(m.peak),
                mib(m.growth()),
                mib(m.plan),
                mib(m.arrays),
                m.peak_over_arrays(),
            );
        }
    }
    out
}

/// Real-signal rows against the complex rows of the same B and threads.
pub fn real_table(rows: &[Row]) -> String {
    let mut out = format!(
        "{:>5} {:>3} | {:>9} {:>9} | {:>9} {:>9} | {:>9} {:>9} | {:>8} {:>8} | {:>8}\n{}\n",
        "B",
        "thr",
        "real inv",
        "real fwd",
        "cplx inv",
        "cplx fwd",
        "inv r/c",
        "fwd r/c",
        "max err",
        "rel L2",
        "peak MiB",
        "-".repeat(112),
    );
    for r in rows.iter().filter(|r| r.variant == Variant::Real) {
        let (rf, ri) = r.ratio.unwrap_or((f64::NAN, f64::NAN));
        let _ = writeln!(
            out,
            "{:>5} {:>3} | {:>9.3e} {:>9.3e} | {:>9} {:>9} | {:>9} {:>9} | {:>8.2e} {:>8.2e} | {:>8}",
            r.bandwidth, r.threads,
            r.inv_median, r.fwd_median,
            or_na!(r.inv_median / ri, "{:.3e}"), or_na!(r.fwd_median / rf, "{:.3e}"),
            or_na!(ri, "{:.3}"), or_na!(rf, "{:.3}"),
            r.max_abs_err, r.rel_l2_err,
            peak_mib(r),
        );
    }
    out
}

/// CSV columns; `docs/benchmark.md` describes each (new columns go at the end, so readers of
/// the first ones keep working).
const CSV_HEADER: [&str; 32] = [
    "bandwidth",
    "threads",
    "runs",
    "fwd_median_s",
    "inv_median_s",
    "fwd_fft_s",
    "fwd_dwt_s",
    "inv_fft_s",
    "inv_dwt_s",
    "dwt_flops",
    "fwd_dwt_gflops",
    "inv_dwt_gflops",
    "peak_gflops_1core",
    "fwd_dwt_frac_peak",
    "inv_dwt_frac_peak",
    "roundtrip_max_abs_err",
    "roundtrip_rel_l2_err",
    "variant",
    "peak_rss_bytes",
    "rss_growth_bytes",
    "plan_memory_bytes",
    "arrays_bytes",
    "peak_over_arrays",
    "lib_over_naive_fwd_dwt",
    "lib_over_naive_inv_dwt",
    "noskip_over_skip_fwd_dwt",
    "noskip_over_skip_inv_dwt",
    "real_over_complex_fwd",
    "real_over_complex_inv",
    "fwd_cpu_s",
    "inv_cpu_s",
    "utilisation",
];

/// A float field: Rust's shortest round-trip formatting in exponent form (`{:e}`), so nothing
/// is lost and tiny errors stay readable; empty when NaN (does not apply).
fn num(x: f64) -> String {
    if x.is_nan() {
        String::new()
    } else {
        format!("{x:e}")
    }
}

/// The CSV fields of a row, in [`CSV_HEADER`]'s order. Errors keep NaN (a NaN error is a
/// result).
fn csv_record(r: &Row) -> [String; 32] {
    let mem = |f: fn(&Memory) -> String| r.memory.as_ref().map_or(String::new(), f);
    let ratio = |v: Variant, fwd: bool| match (r.ratio, r.variant == v) {
        (Some((f, i)), true) => num(if fwd { f } else { i }),
        _ => String::new(),
    };
    [
        r.bandwidth.to_string(),
        r.threads.to_string(),
        r.runs.to_string(),
        num(r.fwd_median),
        num(r.inv_median),
        num(r.fwd.fft),
        num(r.fwd.dwt),
        num(r.inv.fft),
        num(r.inv.dwt),
        r.dwt_flops.to_string(),
        num(r.fwd_dwt_gflops()),
        num(r.inv_dwt_gflops()),
        num(r.peak_1core),
        num(r.fwd_frac_peak()),
        num(r.inv_frac_peak()),
        format!("{:e}", r.max_abs_err),
        format!("{:e}", r.rel_l2_err),
        r.variant.name().to_string(),
        mem(|m| m.peak.to_string()),
        mem(|m| m.growth().to_string()),
        mem(|m| m.plan.to_string()),
        mem(|m| m.arrays.to_string()),
        mem(|m| num(m.peak_over_arrays())),
        ratio(Variant::Naive, true),
        ratio(Variant::Naive, false),
        ratio(Variant::NoSkip, true),
        ratio(Variant::NoSkip, false),
        ratio(Variant::Real, true),
        ratio(Variant::Real, false),
        r.cpu.map_or(String::new(), |c| num(c.0)),
        r.cpu.map_or(String::new(), |c| num(c.1)),
        num(r.utilisation()),
    ]
}

/// Writes the CSV file: the header, then one record per row.
pub fn write_csv(path: &Path, rows: &[Row]) -> csv::Result<()> {
    so3fft_tools::csv_out::write(path, &CSV_HEADER, rows.iter().map(csv_record))
}
