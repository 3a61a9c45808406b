//! Command-line options of `so3fft-bench`.
//!
//! Hand-written parser: the binary may only depend on std and the crate's own dependencies,
//! so no argument-parsing crate is available.

use so3fft::Rigor;
use std::path::PathBuf;

/// Runs per configuration when `--runs` is not given (smaller at large B, see [`Options::runs_for`]).
pub const DEFAULT_RUNS: usize = 5;
/// Runs per configuration under `--quick`.
const QUICK_RUNS: usize = 3;
/// Largest bandwidth `--quick` keeps: the smoke test must finish in seconds.
const QUICK_MAX_BANDWIDTH: usize = 64;
/// Largest bandwidth allowed without `--big`. Above it a round trip needs minutes and most of
/// the memory, and the bench runs the memory-lean procedure (`big.rs`).
pub const MAX_REGULAR_BANDWIDTH: usize = 256;
/// Bandwidth `--big` adds.
pub const BIG_BANDWIDTH: usize = 512;
/// Largest bandwidth of the plain DWT by default (its cost grows as B^4).
const DEFAULT_NAIVE_MAX: usize = 128;
/// ... and under `--quick`.
const QUICK_NAIVE_MAX: usize = 16;

pub const USAGE: &str = "\
usage: so3fft-bench [TOOL] [options]
TOOL (default: the full benchmark described below):
  stages              stage times of repeated transforms, one line per transform on stderr,
                      for profiling (perf record) and for comparing two builds run
                      alternately; defaults --bandwidths 256 --threads 1 --runs 3
  scaling             thread scaling on a shared machine: windows of inverse + forward pairs
                      (at least 0.3 s each) that count only while other processes use under
                      3% of the machine, thread counts alternating; medians of --runs clean
                      windows (default 5); defaults --bandwidths 64,128,256 --threads 1,2
  real                only the real-signal transforms against the complex ones (round trips
                      interleaved, last thread count); default --bandwidths 64,128,256
  s2 (or --s2)        the S^2 transforms: real and complex synthesis and analysis, medians,
                      GFLOP/s against the peak, round-trip errors; B up to 4096 allowed
  match (or --match)  rotational matching: a rotated random function recovered; pipeline
                      medians (complex, real), one refinement and ten peaks refined
                      together, grid and refined angle errors; the pipeline against its
                      floor (FFTW alone on the grid's slices + the DWT at its in-cache kernel
                      rate; the DWT part needs --features internals); eight patterns against
                      one signal (per pattern) and four shells against one correlation
  mpi-model (or --mpi-model)  distributed plans at B = 1024, 2048 on 8..256 nodes: memory
                      per rank, bytes exchanged, expected time, from one-core rates measured here
                      --runs 7
  partial (or --partial)  partial plans against the transforms they replace: degree-limited
                      on a finer grid, order-limited (B = 128, and 1024, 2048), batches of 8,
                      1/16 of the betas, skip thresholds 2^-24 and 2^-34 (ratios in one run)
options:
  --bandwidths LIST   comma-separated bandwidths B, 1..=256, above 256 only with --big
                      (default 16,32,64,128,256)
  --threads LIST      comma-separated thread counts, 0 = all cores (default 1,2)
  --runs N            timed runs per configuration (default 5; 3 at B = 256; B > 256: always 1)
  --csv PATH          CSV output file (default bench.csv)
  --plot PATH         SVG plot of time and error against B (default: the CSV path with
                      extension .svg, i.e. bench.svg)
  --rigor R           FFTW planner rigour: estimate | measure | patient | exhaustive (default
                      measure: with estimate the FFT stage is 10-20% slower at B = 128 and 256)
  --naive-max B       largest B of the plain one-thread DWT timed for comparison (default 128,
                      0 = none; about 1 s per direction at 128)
  --big               also run B = 512 (added unless the list has a B above 256): needs minutes
                      and about 22 GB. B > 256 runs once, with the largest thread count only:
                      complex inverse then forward (peak memory of the forward against input +
                      output), the same without skipping, and a real-signal round trip; random
                      coefficients are regenerated from a seed instead of being stored. Skipped
                      with a message when MemAvailable is too small.
  --quick             CI smoke test: only B <= 64, 3 runs, plain DWT at B = 16 only
  --soft              also time the SOFT 2.0 entry points against the native plan (each B)
  --mode M            stages: inv | fwd | both | dfwd (the forward that may overwrite its
                      input) | rinv | rfwd | rboth (real signals); default both
  --isa I             kernels' instruction set: avx512 | avx2 | scalar (default: the best this
                      CPU has); sets SO3FFT_ISA for every plan, SOFT call and the FMA peak, so
                      a host with AVX-512 can measure the AVX2 kernels
  --workspace-mib N   stages: cap on the plan's chunk buffer (default: the plan's default)
  -h, --help          print this help

Each B <= 256 and thread count: inverse then forward on random coefficients, stage times
(medians), DWT GFLOP/s against the FMA peak measured in the same run, round-trip errors, peak
memory. Per B also: the transforms without skipping of negligible Wigner-d prefixes (first
thread count) and the plain DWT. Columns and formulas: notes/bench.md.";

/// Which measurement the command line asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Tool {
    /// The full benchmark: tables, CSV and plot.
    Full,
    /// Stage times of repeated transforms (`stages.rs`).
    Stages,
    /// Thread scaling in clean windows (`scaling.rs`).
    Scaling,
    /// Real-signal against complex transforms only.
    Real,
    /// The S^2 (spherical-harmonic) transforms (`s2.rs`).
    S2,
    /// Rotational matching (`matching.rs`).
    Match,
    /// Partial plans (`partial.rs`).
    Partial,
    /// The distributed plans' model for large B (`mpi_model.rs`).
    MpiModel,
}

/// Transforms the `stages` tool repeats.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StageMode {
    Inverse,
    Forward,
    Both,
    /// The forward that may overwrite its input.
    ForwardDestroying,
    RealInverse,
    RealForward,
    RealBoth,
}

impl StageMode {
    /// Whether the mode runs the real-signal transforms.
    pub fn real(self) -> bool {
        matches!(
            self,
            StageMode::RealInverse | StageMode::RealForward | StageMode::RealBoth
        )
    }

    /// Whether the mode runs an inverse.
    pub fn inverse(self) -> bool {
        matches!(
            self,
            StageMode::Inverse | StageMode::Both | StageMode::RealInverse | StageMode::RealBoth
        )
    }

    /// Whether the mode runs a forward.
    pub fn forward(self) -> bool {
        !matches!(self, StageMode::Inverse | StageMode::RealInverse)
    }
}

/// Parsed benchmark options.
#[derive(Debug, Clone)]
pub struct Options {
    pub tool: Tool,
    pub bandwidths: Vec<usize>,
    pub threads: Vec<usize>,
    /// `Some` when the user chose the run count (then it is used at every B).
    pub runs: Option<usize>,
    pub csv: PathBuf,
    pub rigor: Rigor,
    pub quick: bool,
    /// Compare the SOFT compatibility layer with the native plan.
    pub soft: bool,
    /// Allow bandwidths above [`MAX_REGULAR_BANDWIDTH`] (and add [`BIG_BANDWIDTH`]).
    pub big: bool,
    /// SVG plot file.
    pub plot: PathBuf,
    /// Largest bandwidth of the plain DWT (0: none).
    pub naive_max: usize,
    /// Transforms of the `stages` tool.
    pub stage_mode: StageMode,
    /// Cap on the chunk buffer of the `stages` tool's plan (`None`: the plan's default).
    pub workspace_bytes: Option<usize>,
    /// Instruction set named by `--isa` (given to the library as `SO3FFT_ISA`).
    pub isa: Option<String>,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            tool: Tool::Full,
            bandwidths: vec![16, 32, 64, 128, 256],
            threads: vec![1, 2],
            runs: None,
            csv: PathBuf::from("bench.csv"),
            // Not the library's default (Estimate): FFTW_ESTIMATE plans make the FFT stage
            // several times slower at large B, which would hide the DWT. Planning time is not
            // part of any timing.
            rigor: Rigor::Measure,
            quick: false,
            soft: false,
            big: false,
            plot: PathBuf::from("bench.svg"),
            naive_max: DEFAULT_NAIVE_MAX,
            stage_mode: StageMode::Both,
            workspace_bytes: None,
            isa: None,
        }
    }
}

impl Options {
    /// Number of timed runs at bandwidth `b`.
    ///
    /// An explicit `--runs` wins (except above [`MAX_REGULAR_BANDWIDTH`], always one run).
    /// Otherwise the default shrinks with B because one transform costs O(B^4): five runs at
    /// B = 512 would take minutes for little extra information.
    pub fn runs_for(&self, b: usize) -> usize {
        match self.runs {
            _ if b > MAX_REGULAR_BANDWIDTH => 1,
            Some(n) => n,
            None if b <= 128 => DEFAULT_RUNS,
            None if b <= 256 => 3,
            None => 1,
        }
    }
}

/// What the command line asks for.
pub enum Command {
    Run(Options),
    Help,
}

/// Parses the arguments after the program name. Accepts `--opt value` and `--opt=value`.
pub fn parse<I: IntoIterator<Item = String>>(args: I) -> Result<Command, String> {
    let mut opts = Options::default();
    let mut bandwidths_given = false;
    let mut plot_given = false;
    let mut naive_given = false;
    let mut threads_given = false;
    let mut args = args.into_iter().peekable();
    opts.tool = match args.peek().map(String::as_str) {
        Some("stages") => Tool::Stages,
        Some("scaling") => Tool::Scaling,
        Some("real") => Tool::Real,
        Some("s2" | "--s2") => Tool::S2,
        Some("match" | "--match") => Tool::Match,
        Some("partial" | "--partial") => Tool::Partial,
        Some("mpi-model" | "--mpi-model") => Tool::MpiModel,
        _ => Tool::Full,
    };
    if opts.tool != Tool::Full {
        args.next();
    }
    while let Some(arg) = args.next() {
        let (name, inline) = match arg.split_once('=') {
            Some((n, v)) if n.starts_with("--") => (n.to_string(), Some(v.to_string())),
            _ => (arg.clone(), None),
        };
        let mut value = || {
            inline
                .clone()
                .or_else(|| args.next())
                .ok_or_else(|| format!("{name} needs a value"))
        };
        match name.as_str() {
            "-h" | "--help" => return Ok(Command::Help),
            "--quick" => opts.quick = true,
            "--soft" => opts.soft = true,
            "--big" => opts.big = true,
            "--plot" => {
                opts.plot = PathBuf::from(value()?);
                plot_given = true;
            }
            "--naive-max" => {
                let text = value()?;
                opts.naive_max = text
                    .trim()
                    .parse()
                    .map_err(|e| format!("--naive-max: '{text}': {e}"))?;
                naive_given = true;
            }
            "--bandwidths" => {
                opts.bandwidths = parse_list(&value()?, "--bandwidths")?;
                bandwidths_given = true;
            }
            "--threads" => {
                opts.threads = parse_list(&value()?, "--threads")?;
                threads_given = true;
            }
            "--mode" => opts.stage_mode = parse_stage_mode(&value()?)?,
            "--workspace-mib" => {
                let text = value()?;
                let mib: usize = text
                    .trim()
                    .parse()
                    .map_err(|e| format!("--workspace-mib: '{text}': {e}"))?;
                opts.workspace_bytes = Some(mib << 20);
            }
            "--runs" => opts.runs = Some(parse_positive(&value()?, "--runs")?),
            "--csv" => opts.csv = PathBuf::from(value()?),
            "--rigor" => opts.rigor = parse_rigor(&value()?)?,
            "--isa" => {
                let text = value()?.trim().to_ascii_lowercase();
                if !matches!(text.as_str(), "avx512" | "avx2" | "scalar") {
                    return Err(format!("--isa: '{text}' is not avx512, avx2 or scalar"));
                }
                opts.isa = Some(text);
            }
            _ => return Err(format!("unknown option '{arg}'")),
        }
    }
    apply_tool_defaults(&mut opts, bandwidths_given, threads_given);
    if !plot_given {
        opts.plot = opts.csv.with_extension("svg");
    }
    if opts.big && !opts.bandwidths.iter().any(|&b| b > MAX_REGULAR_BANDWIDTH) {
        opts.bandwidths.push(BIG_BANDWIDTH);
    }
    if opts.quick {
        apply_quick(&mut opts, bandwidths_given, naive_given);
    }
    if opts.bandwidths.is_empty() {
        return Err("no bandwidth left to run".into());
    }
    // Checked here because the memory estimate would overflow before the plan could refuse.
    let max_b = if opts.tool == Tool::S2 {
        so3fft::s2::S2_MAX_BANDWIDTH
    } else {
        so3fft::MAX_BANDWIDTH
    };
    if let Some(&b) = opts.bandwidths.iter().find(|&&b| b == 0 || b > max_b) {
        return Err(format!("--bandwidths: {b} is not in 1..={max_b}"));
    }
    if !opts.big && opts.tool != Tool::S2 {
        if let Some(&b) = opts.bandwidths.iter().find(|&&b| b > MAX_REGULAR_BANDWIDTH) {
            return Err(format!(
                "--bandwidths: B = {b} needs --big (minutes of run time, most of the memory)"
            ));
        }
    }
    if opts.threads.is_empty() {
        return Err("--threads: no thread count given".into());
    }
    Ok(Command::Run(opts))
}

/// Defaults of the tools other than the full benchmark, where not given.
fn apply_tool_defaults(opts: &mut Options, bandwidths_given: bool, threads_given: bool) {
    let (bandwidths, threads, runs) = match opts.tool {
        Tool::Full => return,
        Tool::Stages => (vec![256], vec![1], Some(3)),
        Tool::Scaling => (vec![64, 128, 256], vec![1, 2], Some(5)),
        Tool::Real => (vec![64, 128, 256], vec![1, 2], None),
        Tool::S2 => (vec![128, 256, 512, 1024], vec![1, 2], None),
        Tool::Match => (vec![16, 32, 64, 128], vec![2], None),
        Tool::Partial => (vec![256], vec![2], None),
        Tool::MpiModel => (vec![128], vec![1], None),
    };
    if !bandwidths_given {
        opts.bandwidths = bandwidths;
    }
    if !threads_given {
        opts.threads = threads;
    }
    if opts.runs.is_none() {
        opts.runs = runs;
    }
}

/// `--quick` limits B to 64 (keeping a user list's small entries), uses 3 runs unless
/// `--runs` was given and runs the plain DWT at B = 16 only (unless `--naive-max` was given,
/// still at most 64), so CI gets a smoke test of a few seconds.
fn apply_quick(opts: &mut Options, bandwidths_given: bool, naive_given: bool) {
    if bandwidths_given {
        opts.bandwidths.retain(|&b| b <= QUICK_MAX_BANDWIDTH);
    } else {
        opts.bandwidths = vec![16, 32, 64];
    }
    opts.runs.get_or_insert(QUICK_RUNS);
    opts.naive_max = if naive_given {
        opts.naive_max.min(QUICK_MAX_BANDWIDTH)
    } else {
        QUICK_NAIVE_MAX
    };
}

fn parse_list(text: &str, what: &str) -> Result<Vec<usize>, String> {
    text.split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| {
            s.trim()
                .parse::<usize>()
                .map_err(|e| format!("{what}: '{s}': {e}"))
        })
        .collect()
}

fn parse_positive(text: &str, what: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(0) => Err(format!("{what} must be at least 1")),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("{what}: '{text}': {e}")),
    }
}

fn parse_rigor(text: &str) -> Result<Rigor, String> {
    match text.to_ascii_lowercase().as_str() {
        "estimate" => Ok(Rigor::Estimate),
        "measure" => Ok(Rigor::Measure),
        "patient" => Ok(Rigor::Patient),
        "exhaustive" => Ok(Rigor::Exhaustive),
        _ => Err(format!(
            "--rigor: '{text}' is not estimate, measure, patient or exhaustive"
        )),
    }
}

fn parse_stage_mode(text: &str) -> Result<StageMode, String> {
    match text {
        "inv" => Ok(StageMode::Inverse),
        "fwd" => Ok(StageMode::Forward),
        "both" => Ok(StageMode::Both),
        "dfwd" => Ok(StageMode::ForwardDestroying),
        "rinv" => Ok(StageMode::RealInverse),
        "rfwd" => Ok(StageMode::RealForward),
        "rboth" => Ok(StageMode::RealBoth),
        _ => Err(format!(
            "--mode: '{text}' is not inv, fwd, both, dfwd, rinv, rfwd or rboth"
        )),
    }
}

/// Lower-case name of a rigour, as accepted by `--rigor`.
pub fn rigor_name(rigor: Rigor) -> &'static str {
    match rigor {
        Rigor::Estimate => "estimate",
        Rigor::Measure => "measure",
        Rigor::Patient => "patient",
        Rigor::Exhaustive => "exhaustive",
    }
}

#[cfg(test)]
mod tests {
    use super::{parse, Command, StageMode, Tool};

    fn options(args: &[&str]) -> super::Options {
        match parse(args.iter().map(|a| a.to_string())) {
            Ok(Command::Run(opts)) => opts,
            Ok(Command::Help) => panic!("help"),
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn full_run_quick_defaults() {
        let opts = options(&["--quick", "--csv", "target/x.csv"]);
        assert_eq!(opts.tool, Tool::Full);
        assert_eq!(opts.bandwidths, [16, 32, 64]);
        assert_eq!(opts.runs, Some(3));
        assert_eq!(opts.plot.to_str(), Some("target/x.svg"));
    }

    #[test]
    fn tools_and_their_defaults() {
        let opts = options(&["stages", "--mode=rfwd"]);
        assert_eq!(opts.tool, Tool::Stages);
        assert_eq!((opts.bandwidths, opts.threads), (vec![256], vec![1]));
        assert_eq!(opts.runs, Some(3));
        assert_eq!(opts.stage_mode, StageMode::RealForward);
        let opts = options(&["scaling", "--bandwidths", "32", "--runs", "2"]);
        assert_eq!(opts.tool, Tool::Scaling);
        assert_eq!((opts.bandwidths, opts.threads), (vec![32], vec![1, 2]));
        assert_eq!(opts.runs, Some(2));
        let opts = options(&["real"]);
        assert_eq!((opts.tool, opts.runs), (Tool::Real, None));
        assert_eq!(opts.bandwidths, [64, 128, 256]);
        assert!(parse(["stages", "--mode", "sideways"].map(String::from)).is_err());
    }
}
