//! Command-line options of `so3fft-bench` (clap), and the defaults each tool fills in.

use clap::{CommandFactory, Parser, Subcommand, ValueEnum};
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

/// Timing, accuracy and efficiency of the SO(3) FFT.
///
/// Without a TOOL, the full benchmark: each B <= 256 and thread count, inverse then forward
/// on random coefficients, stage times (medians), DWT GFLOP/s against the FMA peak measured
/// in the same run, round-trip errors, peak memory. Per B also: the transforms without
/// skipping of negligible Wigner-d prefixes (first thread count) and the plain DWT. Writes a
/// CSV file and an SVG plot. Columns and formulas: docs/benchmark.md.
#[derive(Parser, Debug)]
#[command(
    name = "so3fft-bench",
    version,
    args_override_self = true,
    disable_help_subcommand = true
)]
pub struct Cli {
    /// The narrower measurement to run instead of the full benchmark.
    #[command(subcommand)]
    pub tool: Option<ToolCommand>,
    #[command(flatten)]
    pub args: Args,
}

/// The tools other than the full benchmark (they take the same options).
#[derive(Subcommand, Debug, Clone, Copy, PartialEq, Eq)]
pub enum ToolCommand {
    /// Stage times of repeated transforms, one line per transform on stderr, for profiling
    /// (perf record) and for comparing two builds run alternately; defaults --bandwidths 256
    /// --threads 1 --runs 3.
    Stages,
    /// Thread scaling on a shared machine: windows of inverse + forward pairs (at least
    /// 0.3 s each) that count only while other processes use under 3% of the machine, thread
    /// counts alternating; medians of --runs clean windows (default 5); defaults --bandwidths
    /// 64,128,256 --threads 1,2.
    Scaling,
    /// Only the real-signal transforms against the complex ones (round trips interleaved,
    /// last thread count); default --bandwidths 64,128,256.
    Real,
    /// The S^2 transforms: real and complex synthesis and analysis, medians, GFLOP/s against
    /// the peak, round-trip errors; B up to 4096 allowed.
    #[command(long_flag = "s2")]
    S2,
    /// The SO(3) transforms in single against double precision: complex and real, inverse
    /// and forward, calls alternating run by run; medians, time ratios, round-trip errors and
    /// plan memory; defaults --bandwidths 64,128,256 --threads 2.
    Precision,
    /// Rotational matching: a rotated random function recovered; pipeline medians (complex,
    /// real), one refinement and ten peaks refined together, grid and refined angle errors;
    /// the pipeline against its floor (FFTW alone on the grid's slices + the DWT at its
    /// in-cache kernel rate; the DWT part needs --features internals); eight patterns against
    /// one signal (per pattern) and four shells against one correlation.
    #[command(long_flag = "match")]
    Match,
    /// Matching accuracy against noise: scenes of smooth functions that are not band-limited,
    /// rotated analytically, noise 0, 0.3, 1, 3 in both inputs; median and 90th percentile of
    /// the angle error of the grid argmax, refinement with all degrees, the best fixed degree
    /// limit (hindsight) and the automatic weights, the coverage of the reported 1-sigma
    /// angle, and what weights and uncertainty cost; --runs scenes per level [default 20];
    /// defaults --bandwidths 32,64,128 --threads 2.
    Noise,
    /// Distributed plans at B = 1024, 2048 on 8..256 nodes: memory per rank, bytes exchanged,
    /// expected time, from one-core rates measured here.
    #[command(long_flag = "mpi-model")]
    MpiModel,
    /// Partial plans against the transforms they replace: degree-limited on a finer grid,
    /// order-limited (B = 128, and 1024, 2048), batches of 8, 1/16 of the betas, skip
    /// thresholds 2^-24 and 2^-34 (ratios in one run).
    #[command(long_flag = "partial")]
    Partial,
}

/// The options every tool takes (before or after the tool's name).
#[derive(clap::Args, Debug, Clone)]
pub struct Args {
    /// Comma-separated bandwidths B, 1..=256, above 256 only with --big [default:
    /// 16,32,64,128,256; each tool has its own]
    #[arg(long, value_name = "LIST", value_parser = parse_list, global = true)]
    pub bandwidths: Option<CountList>,
    /// Comma-separated thread counts, 0 = all cores [default: 1,2]
    #[arg(long, value_name = "LIST", value_parser = parse_list, global = true)]
    pub threads: Option<CountList>,
    /// Timed runs per configuration [default: 5; 3 at B = 256; B > 256: always 1]
    #[arg(long, value_name = "N", value_parser = parse_positive, global = true)]
    pub runs: Option<usize>,
    /// CSV output file
    #[arg(long, value_name = "PATH", default_value = "bench.csv", global = true)]
    pub csv: PathBuf,
    /// SVG plot of time and error against B [default: the CSV path with extension .svg,
    /// i.e. bench.svg]
    #[arg(long, value_name = "PATH", global = true)]
    pub plot: Option<PathBuf>,
    /// FFTW planner rigour (measure: with estimate the FFT stage is 10-20% slower at B = 128
    /// and 256)
    #[arg(long, value_name = "R", value_enum, ignore_case = true, default_value_t = RigorArg::Measure, global = true)]
    pub rigor: RigorArg,
    /// Largest B of the plain one-thread DWT timed for comparison (0 = none; about 1 s per
    /// direction at 128) [default: 128]
    #[arg(long, value_name = "B", global = true)]
    pub naive_max: Option<usize>,
    /// Also run B = 512 (added unless the list has a B above 256): needs minutes and about
    /// 22 GB. B > 256 runs once, with the largest thread count only: complex inverse then
    /// forward (peak memory of the forward against input + output), the same without
    /// skipping, and a real-signal round trip; random coefficients are regenerated from a
    /// seed instead of being stored. Skipped with a message when MemAvailable is too small.
    #[arg(long, global = true)]
    pub big: bool,
    /// CI smoke test: only B <= 64, 3 runs, plain DWT at B = 16 only
    #[arg(long, global = true)]
    pub quick: bool,
    /// Also time the SOFT 2.0 entry points against the native plan (each B)
    #[arg(long, global = true)]
    pub soft: bool,
    /// Transforms of the stages tool (dfwd: the forward that may overwrite its input;
    /// r...: real signals)
    #[arg(long, value_name = "M", value_enum, default_value_t = StageMode::Both, global = true)]
    pub mode: StageMode,
    /// Kernels' instruction set [default: the best this CPU has]; sets SO3FFT_ISA for every
    /// plan, SOFT call and the FMA peak, so a host with AVX-512 can measure the AVX2 kernels
    #[arg(long, value_name = "I", value_enum, ignore_case = true, global = true)]
    pub isa: Option<IsaArg>,
    /// Stages: cap on the plan's chunk buffer, MiB [default: the plan's default]
    #[arg(long, value_name = "N", global = true)]
    pub workspace_mib: Option<usize>,
}

/// A comma-separated list of counts (`--bandwidths`, `--threads`).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CountList(pub Vec<usize>);

/// FFTW planner rigour as named on the command line.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum RigorArg {
    Estimate,
    Measure,
    Patient,
    Exhaustive,
}

impl From<RigorArg> for Rigor {
    fn from(r: RigorArg) -> Rigor {
        match r {
            RigorArg::Estimate => Rigor::Estimate,
            RigorArg::Measure => Rigor::Measure,
            RigorArg::Patient => Rigor::Patient,
            RigorArg::Exhaustive => Rigor::Exhaustive,
        }
    }
}

/// Kernel instruction sets `--isa` accepts.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum IsaArg {
    Avx512,
    Avx2,
    Scalar,
}

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
    /// SO(3) transforms in f32 against f64 (`precision.rs`).
    Precision,
    /// Rotational matching (`matching.rs`).
    Match,
    /// Matching accuracy against noise (`noise.rs`).
    Noise,
    /// Partial plans (`partial.rs`).
    Partial,
    /// The distributed plans' model for large B (`mpi_model.rs`).
    MpiModel,
}

/// Transforms the `stages` tool repeats.
#[derive(ValueEnum, Debug, Clone, Copy, PartialEq, Eq)]
pub enum StageMode {
    #[value(name = "inv")]
    Inverse,
    #[value(name = "fwd")]
    Forward,
    #[value(name = "both")]
    Both,
    /// The forward that may overwrite its input.
    #[value(name = "dfwd")]
    ForwardDestroying,
    #[value(name = "rinv")]
    RealInverse,
    #[value(name = "rfwd")]
    RealForward,
    #[value(name = "rboth")]
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

impl Cli {
    /// The options of the run, each tool's defaults filled in; a usage error (exit status 2)
    /// for bandwidths that cannot run.
    pub fn into_options(self) -> Result<Options, clap::Error> {
        let a = self.args;
        let mut opts = Options {
            tool: self.tool.map_or(Tool::Full, Tool::from),
            runs: a.runs,
            csv: a.csv.clone(),
            rigor: a.rigor.into(),
            quick: a.quick,
            soft: a.soft,
            big: a.big,
            plot: a.plot.unwrap_or_else(|| a.csv.with_extension("svg")),
            naive_max: a.naive_max.unwrap_or(DEFAULT_NAIVE_MAX),
            stage_mode: a.mode,
            workspace_bytes: a.workspace_mib.map(|mib| mib << 20),
            isa: a.isa.map(|isa| {
                isa.to_possible_value()
                    .expect("no skipped values")
                    .get_name()
                    .to_string()
            }),
            ..Options::default()
        };
        let bandwidths_given = a.bandwidths.is_some();
        if let Some(CountList(list)) = a.bandwidths {
            opts.bandwidths = list;
        }
        let threads_given = a.threads.is_some();
        if let Some(CountList(list)) = a.threads {
            opts.threads = list;
        }
        apply_tool_defaults(&mut opts, bandwidths_given, threads_given);
        if opts.big && !opts.bandwidths.iter().any(|&b| b > MAX_REGULAR_BANDWIDTH) {
            opts.bandwidths.push(BIG_BANDWIDTH);
        }
        if opts.quick {
            apply_quick(&mut opts, bandwidths_given, a.naive_max.is_some());
        }
        check(&opts)
            .map_err(|msg| Cli::command().error(clap::error::ErrorKind::ValueValidation, msg))?;
        Ok(opts)
    }
}

impl From<ToolCommand> for Tool {
    fn from(t: ToolCommand) -> Tool {
        match t {
            ToolCommand::Stages => Tool::Stages,
            ToolCommand::Scaling => Tool::Scaling,
            ToolCommand::Real => Tool::Real,
            ToolCommand::S2 => Tool::S2,
            ToolCommand::Precision => Tool::Precision,
            ToolCommand::Match => Tool::Match,
            ToolCommand::Noise => Tool::Noise,
            ToolCommand::MpiModel => Tool::MpiModel,
            ToolCommand::Partial => Tool::Partial,
        }
    }
}

/// Refuses bandwidths and thread lists that cannot run.
fn check(opts: &Options) -> Result<(), String> {
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
    Ok(())
}

/// Defaults of the tools other than the full benchmark, where not given.
fn apply_tool_defaults(opts: &mut Options, bandwidths_given: bool, threads_given: bool) {
    let (bandwidths, threads, runs) = match opts.tool {
        Tool::Full => return,
        Tool::Stages => (vec![256], vec![1], Some(3)),
        Tool::Scaling => (vec![64, 128, 256], vec![1, 2], Some(5)),
        Tool::Real => (vec![64, 128, 256], vec![1, 2], None),
        Tool::S2 => (vec![128, 256, 512, 1024], vec![1, 2], None),
        Tool::Precision => (vec![64, 128, 256], vec![2], None),
        Tool::Match => (vec![16, 32, 64, 128], vec![2], None),
        Tool::Noise => (vec![32, 64, 128], vec![2], None),
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

/// A comma-separated list of counts; empty entries are skipped.
fn parse_list(text: &str) -> Result<CountList, String> {
    text.split(',')
        .filter(|s| !s.trim().is_empty())
        .map(|s| s.trim().parse::<usize>().map_err(|e| format!("'{s}': {e}")))
        .collect::<Result<_, _>>()
        .map(CountList)
}

/// A count of at least 1.
fn parse_positive(text: &str) -> Result<usize, String> {
    match text.trim().parse::<usize>() {
        Ok(0) => Err("must be at least 1".into()),
        Ok(n) => Ok(n),
        Err(e) => Err(format!("'{text}': {e}")),
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
    use super::{Cli, Options, StageMode, Tool};
    use clap::error::ErrorKind;
    use clap::Parser;

    fn parse(args: &[&str]) -> Result<Options, clap::Error> {
        let argv = std::iter::once("so3fft-bench").chain(args.iter().copied());
        Cli::try_parse_from(argv)?.into_options()
    }

    fn options(args: &[&str]) -> Options {
        parse(args).unwrap_or_else(|e| panic!("{args:?}: {e}"))
    }

    fn error_kind(args: &[&str]) -> ErrorKind {
        match parse(args) {
            Ok(o) => panic!("{args:?} accepted: {o:?}"),
            Err(e) => e.kind(),
        }
    }

    #[test]
    fn full_run_quick_defaults() {
        let opts = options(&["--quick", "--csv", "target/x.csv"]);
        assert_eq!(opts.tool, Tool::Full);
        assert_eq!(opts.bandwidths, [16, 32, 64]);
        assert_eq!(opts.runs, Some(3));
        assert_eq!(opts.naive_max, 16);
        assert_eq!(opts.plot.to_str(), Some("target/x.svg"));
    }

    /// Without options: the documented defaults (B = 16..256, threads 1,2, measure,
    /// bench.csv and bench.svg, plain DWT to 128, five runs to B = 128 and three at 256).
    #[test]
    fn full_run_defaults() {
        let opts = options(&[]);
        assert_eq!(opts.tool, Tool::Full);
        assert_eq!(opts.bandwidths, [16, 32, 64, 128, 256]);
        assert_eq!(opts.threads, [1, 2]);
        assert_eq!(opts.rigor, so3fft::Rigor::Measure);
        assert_eq!(opts.csv.to_str(), Some("bench.csv"));
        assert_eq!(opts.plot.to_str(), Some("bench.svg"));
        assert_eq!(opts.naive_max, 128);
        assert_eq!((opts.runs_for(128), opts.runs_for(256)), (5, 3));
        assert_eq!(opts.stage_mode, StageMode::Both);
        assert!(!opts.quick && !opts.soft && !opts.big);
        assert_eq!((opts.isa, opts.workspace_bytes), (None, None));
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
        assert_eq!(
            error_kind(&["stages", "--mode", "sideways"]),
            ErrorKind::InvalidValue
        );
    }

    /// Each tool by name and, where documented, as a flag.
    #[test]
    fn tool_names_and_flags() {
        for (args, tool) in [
            (&["s2"][..], Tool::S2),
            (&["--s2"], Tool::S2),
            (&["match"], Tool::Match),
            (&["--match", "--runs", "7"], Tool::Match),
            (&["partial"], Tool::Partial),
            (&["--partial"], Tool::Partial),
            (&["mpi-model"], Tool::MpiModel),
            (&["--mpi-model"], Tool::MpiModel),
        ] {
            assert_eq!(options(args).tool, tool, "{args:?}");
        }
        assert_eq!(options(&["s2"]).bandwidths, [128, 256, 512, 1024]);
        assert_eq!(options(&["match"]).threads, [2]);
        // S^2 bandwidths above 256 need no --big.
        assert_eq!(options(&["s2", "--bandwidths", "4096"]).bandwidths, [4096]);
    }

    /// The documented invocations of README.md and docs/*.md parse to what they say.
    #[test]
    fn documented_command_lines() {
        let opts = options(&[
            "--bandwidths",
            "64,128,256",
            "--threads",
            "1,2",
            "--rigor",
            "measure",
        ]);
        assert_eq!(
            (opts.bandwidths, opts.threads),
            (vec![64, 128, 256], vec![1, 2])
        );
        let opts = options(&["--bandwidths", "512", "--big", "--threads", "2"]);
        assert_eq!(opts.runs_for(512), 1);
        assert_eq!((opts.bandwidths, opts.threads), (vec![512], vec![2]));
        assert!(options(&["--soft"]).soft);
        let opts = options(&[
            "stages",
            "--isa",
            "avx2",
            "--bandwidths",
            "64,128,256",
            "--threads",
            "2",
            "--mode",
            "both",
            "--runs",
            "7",
        ]);
        assert_eq!(
            (opts.tool, opts.isa.as_deref(), opts.runs),
            (Tool::Stages, Some("avx2"), Some(7))
        );
        assert_eq!(
            options(&["stages", "--mode", "inv"]).stage_mode,
            StageMode::Inverse
        );
        assert_eq!(
            options(&["s2", "--isa", "AVX512"]).isa.as_deref(),
            Some("avx512")
        );
        assert_eq!(options(&["--rigor=Patient"]).rigor, so3fft::Rigor::Patient);
        assert_eq!(
            options(&["stages", "--workspace-mib", "3"]).workspace_bytes,
            Some(3 << 20)
        );
    }

    /// `--big` adds B = 512 unless a B above 256 is listed; the last of a repeated option wins;
    /// empty list entries are skipped.
    #[test]
    fn big_repeats_and_lists() {
        assert_eq!(options(&["--big"]).bandwidths, [16, 32, 64, 128, 256, 512]);
        assert_eq!(
            options(&["--big", "--bandwidths", "1024"]).bandwidths,
            [1024]
        );
        assert_eq!(options(&["--runs", "2", "--runs", "4"]).runs, Some(4));
        assert_eq!(options(&["--threads", "1,,2,"]).threads, [1, 2]);
        let opts = options(&["--quick", "--bandwidths", "16,128", "--naive-max", "100"]);
        assert_eq!((opts.bandwidths, opts.naive_max), (vec![16], 64));
    }

    /// Bad usage is a clap error (exit status 2): unknown options, bad values, bandwidths out
    /// of range or above 256 without --big, nothing left to run; --help is not a failure.
    #[test]
    fn bad_usage_is_refused() {
        assert_eq!(error_kind(&["--frobnicate"]), ErrorKind::UnknownArgument);
        assert_eq!(error_kind(&["--runs", "0"]), ErrorKind::ValueValidation);
        assert_eq!(error_kind(&["--runs"]), ErrorKind::InvalidValue);
        assert_eq!(
            error_kind(&["--bandwidths", "16,x"]),
            ErrorKind::ValueValidation
        );
        assert_eq!(error_kind(&["--rigor", "sloppy"]), ErrorKind::InvalidValue);
        assert_eq!(error_kind(&["--isa", "sse2"]), ErrorKind::InvalidValue);
        assert_eq!(
            error_kind(&["--bandwidths", "512"]),
            ErrorKind::ValueValidation
        );
        assert_eq!(
            error_kind(&["--bandwidths", "0"]),
            ErrorKind::ValueValidation
        );
        assert_eq!(
            error_kind(&["--quick", "--bandwidths", "128"]),
            ErrorKind::ValueValidation
        );
        assert_eq!(error_kind(&["--threads", ","]), ErrorKind::ValueValidation);
        assert_eq!(error_kind(&["--help"]), ErrorKind::DisplayHelp);
        assert_eq!(error_kind(&["stages", "-h"]), ErrorKind::DisplayHelp);
        for args in [&["--frobnicate"][..], &["--bandwidths", "512"]] {
            assert_eq!(parse(args).unwrap_err().exit_code(), 2, "{args:?}");
        }
        assert_eq!(parse(&["--help"]).unwrap_err().exit_code(), 0);
    }
}
