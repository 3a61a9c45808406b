//! Result rows, the printed table, the 1-to-N thread speed-ups and the CSV file.

use std::fmt::Write as _;
use std::io;
use std::path::Path;

/// Median stage times of one direction, in seconds.
#[derive(Clone, Copy, Debug, Default)]
pub struct Stages {
    pub fft: f64,
    pub dwt: f64,
}

/// Everything measured for one (bandwidth, threads) configuration.
#[derive(Clone, Debug)]
pub struct Row {
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
}

impl Row {
    pub fn fwd_dwt_gflops(&self) -> f64 {
        self.dwt_flops as f64 / self.fwd.dwt / 1e9
    }

    pub fn inv_dwt_gflops(&self) -> f64 {
        self.dwt_flops as f64 / self.inv.dwt / 1e9
    }

    /// Peak available to this configuration: single-core peak times threads used. (The measured
    /// all-core peak is printed too; on this machine it is within a few per cent of that.)
    fn peak(&self) -> f64 {
        self.peak_1core * self.threads as f64
    }

    pub fn fwd_frac_peak(&self) -> f64 {
        self.fwd_dwt_gflops() / self.peak()
    }

    pub fn inv_frac_peak(&self) -> f64 {
        self.inv_dwt_gflops() / self.peak()
    }
}

/// Column header of the printed table.
pub fn table_header() -> String {
    format!(
        "{:>5} {:>3} {:>4} | {:>9} {:>9} | {:>9} {:>9} {:>9} {:>9} | {:>7} {:>7} {:>5} {:>5} | {:>8} {:>8}\n{}",
        "B", "thr", "runs",
        "fwd s", "inv s",
        "fwd fft", "fwd dwt", "inv fft", "inv dwt",
        "fwd GF", "inv GF", "fwd%", "inv%",
        "max err", "rel L2",
        "-".repeat(134),
    )
}

/// One line of the printed table.
pub fn table_line(r: &Row) -> String {
    format!(
        "{:>5} {:>3} {:>4} | {:>9.4e} {:>9.4e} | {:>9.3e} {:>9.3e} {:>9.3e} {:>9.3e} | {:>7.2} {:>7.2} {:>5.1} {:>5.1} | {:>8.2e} {:>8.2e}",
        r.bandwidth, r.threads, r.runs,
        r.fwd_median, r.inv_median,
        r.fwd.fft, r.fwd.dwt, r.inv.fft, r.inv.dwt,
        r.fwd_dwt_gflops(), r.inv_dwt_gflops(),
        100.0 * r.fwd_frac_peak(), 100.0 * r.inv_frac_peak(),
        r.max_abs_err, r.rel_l2_err,
    )
}

/// Speed-up of every multi-threaded row over the single-threaded row of the same bandwidth
/// (whole transform and DWT stage); empty when no bandwidth was measured with both.
pub fn speedups(rows: &[Row]) -> String {
    let mut out = String::new();
    for one in rows.iter().filter(|r| r.threads == 1) {
        let many = rows
            .iter()
            .filter(|r| r.bandwidth == one.bandwidth && r.threads > 1);
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

const CSV_HEADER: &str = "bandwidth,threads,runs,fwd_median_s,inv_median_s,fwd_fft_s,fwd_dwt_s,\
inv_fft_s,inv_dwt_s,dwt_flops,fwd_dwt_gflops,inv_dwt_gflops,peak_gflops_1core,fwd_dwt_frac_peak,\
inv_dwt_frac_peak,roundtrip_max_abs_err,roundtrip_rel_l2_err";

/// CSV text of all rows. Floats use Rust's shortest round-trip formatting in exponent form
/// (`{:e}`), so nothing is lost and tiny errors stay readable.
pub fn csv(rows: &[Row]) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    for r in rows {
        let fields = [
            r.bandwidth.to_string(),
            r.threads.to_string(),
            r.runs.to_string(),
            format!("{:e}", r.fwd_median),
            format!("{:e}", r.inv_median),
            format!("{:e}", r.fwd.fft),
            format!("{:e}", r.fwd.dwt),
            format!("{:e}", r.inv.fft),
            format!("{:e}", r.inv.dwt),
            r.dwt_flops.to_string(),
            format!("{:e}", r.fwd_dwt_gflops()),
            format!("{:e}", r.inv_dwt_gflops()),
            format!("{:e}", r.peak_1core),
            format!("{:e}", r.fwd_frac_peak()),
            format!("{:e}", r.inv_frac_peak()),
            format!("{:e}", r.max_abs_err),
            format!("{:e}", r.rel_l2_err),
        ];
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// Writes the CSV file.
pub fn write_csv(path: &Path, rows: &[Row]) -> io::Result<()> {
    std::fs::write(path, csv(rows))
}
