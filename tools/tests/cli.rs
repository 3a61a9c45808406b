//! The command lines of so3fft-bench and so3fft-stress as a user meets them: help, exit
//! status 2 on bad usage, and the stress suite's redraw from a CSV file (exit status from
//! the accuracy targets, charts and tables written), and the noise tool end to end at B = 8
//! (the only test here that runs transforms, in well under a second).

use std::path::PathBuf;
use std::process::Command;

/// Exit status, stdout and stderr of `bin` run with `args`.
fn run(bin: &str, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(bin).args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const BENCH: &str = env!("CARGO_BIN_EXE_so3fft-bench");
const STRESS: &str = env!("CARGO_BIN_EXE_so3fft-stress");

fn temp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("so3fft-cli-{}-{name}", std::process::id()))
}

#[test]
fn bench_help_lists_tools_and_options() {
    let (code, out, _) = run(BENCH, &["--help"]);
    assert_eq!(code, 0);
    for needle in [
        "stages",
        "scaling",
        "real",
        "--s2",
        "--match",
        "noise",
        "--mpi-model",
        "--partial",
        "--bandwidths",
        "--threads",
        "--runs",
        "--csv",
        "--plot",
        "--rigor",
        "--naive-max",
        "--big",
        "--quick",
        "--soft",
        "--mode",
        "--isa",
        "--workspace-mib",
    ] {
        assert!(out.contains(needle), "{needle} missing from --help");
    }
}

/// The noise tool runs end to end at a small bandwidth: a row per scene in the CSV, the
/// chart, and the cost table.
#[test]
fn bench_noise_smoke() {
    let (csv, svg) = (temp("noise.csv"), temp("noise.svg"));
    let (code, out, err) = run(
        BENCH,
        &[
            "noise",
            "--bandwidths",
            "8",
            "--runs",
            "2",
            "--csv",
            csv.to_str().unwrap(),
            "--plot",
            svg.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("automatic") && out.contains("coverage"),
        "{out}"
    );
    let rows = std::fs::read_to_string(&csv).unwrap();
    // Header, then 4 noise levels x 2 scenes.
    assert_eq!(rows.lines().count(), 1 + 4 * 2, "{rows}");
    assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
}

/// Bad usage exits with status 2 before anything is measured.
#[test]
fn bench_bad_usage_exits_2() {
    for args in [
        &["--frobnicate"][..],
        &["--bandwidths", "512"],
        &["--bandwidths", "16,x"],
        &["--runs", "0"],
        &["--rigor", "sloppy"],
        &["stages", "--mode", "sideways"],
        &["--quick", "--bandwidths", "128"],
        &["--isa", "sse2"],
    ] {
        let (code, out, err) = run(BENCH, args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty(), "{args:?} printed: {out}");
        assert!(err.contains("error"), "{args:?}: {err}");
    }
}

#[test]
fn stress_bad_usage_exits_2() {
    let (code, out, _) = run(STRESS, &["--help"]);
    assert_eq!(code, 0);
    for needle in [
        "--quick",
        "--big",
        "--only",
        "--docs",
        "--from-csv",
        "--time-svg",
        "--precision",
    ] {
        assert!(out.contains(needle), "{needle} missing from --help");
    }
    for args in [
        &["--frobnicate"][..],
        &["--threads", "many"],
        &["--only", "reference,nonsense"],
        &["--csv"],
        &["--from-csv", "x.csv", "--quick"],
        &["--precision", "f16"],
        &["--from-csv", "x.csv", "--precision", "f32"],
    ] {
        let (code, _, err) = run(STRESS, args);
        assert_eq!(code, 2, "{args:?}: {err}");
    }
    let (code, _, err) = run(STRESS, &["--from-csv", "/nonexistent/rows.csv"]);
    assert_eq!(code, 2, "{err}");
}

/// Rows written by hand: round trips under the SO(3) target pass (status 0), one above it
/// fails (status 1); charts and the summary tables are drawn from the file.
#[test]
fn stress_redraws_from_csv() {
    let header = "test,B,variant,rel_l2,max_abs,time_s,note\n";
    let good = format!(
        "{header}roundtrip,16,complex,6.0e-16,3.0e-15,1.0e-3,\"\"\n\
         roundtrip,32,complex,1.0e-15,5.0e-15,8.0e-3,\"\"\n\
         roundtrip,64,complex,1.6e-15,9.0e-15,6.0e-2,\"\"\n\
         determinism,64,plan-complex,NaN,NaN,1.0e-2,\"bit-identical, 1/2/4 threads\"\n"
    );
    let csv = temp("rows.csv");
    let (svg, time_svg) = (temp("err.svg"), temp("time.svg"));
    std::fs::write(&csv, &good).unwrap();
    let args = [
        "--from-csv",
        csv.to_str().unwrap(),
        "--svg",
        svg.to_str().unwrap(),
        "--time-svg",
        time_svg.to_str().unwrap(),
    ];
    let (code, out, err) = run(STRESS, &args);
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        out.contains("[met] SO(3) round trip rel L2 <= 1e-14"),
        "{out}"
    );
    assert!(
        out.contains("worst 1.60e-15 (complex B = 64; 3 rows, B = 16..64)"),
        "{out}"
    );
    assert!(out.contains("[met] determinism"), "{out}");
    let chart = std::fs::read_to_string(&svg).unwrap();
    // Least-squares slope of ln(error) on ln(B) for the three points: 0.7075.
    assert!(
        chart.contains("complex f64 (~B^0.71)"),
        "fitted exponent missing"
    );
    assert!(std::fs::read_to_string(&time_svg).unwrap().contains("<svg"));

    let bad = good.replace("1.6e-15,9.0e-15", "2.0e-14,9.0e-14");
    std::fs::write(&csv, bad).unwrap();
    let (code, out, _) = run(STRESS, &args);
    assert_eq!(code, 1, "{out}");
    assert!(out.contains("[MISSED] SO(3) round trip"), "{out}");

    // --docs: the tables between the markers, the rows left to the CSV.
    let dir = temp("docs");
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("stability.md"),
        "# Title\n\n<!-- stress-tables:begin (generated by so3fft-stress --docs docs) -->\nold\n<!-- stress-tables:end -->\nafter\n",
    )
    .unwrap();
    std::fs::write(&csv, &good).unwrap();
    let (code, _, err) = run(
        STRESS,
        &[
            "--from-csv",
            csv.to_str().unwrap(),
            "--docs",
            dir.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{err}");
    let md = std::fs::read_to_string(dir.join("stability.md")).unwrap();
    assert!(!md.contains("\nold\n") && md.ends_with("<!-- stress-tables:end -->\nafter\n"));
    assert!(md.contains(
        "| roundtrip complex | f64 | 3 | 1 | 16..64 | 1.60e-15 (complex B = 64) | 9.00e-15 (complex B = 64) | met: SO(3) round trip rel L2 <= 1e-14 (complex, real) |"
    ), "{md}");
    assert!(md.contains("[stability.csv](stability.csv)"));
    assert!(
        !dir.join("stability.csv").exists(),
        "--from-csv rewrote the CSV"
    );
    assert!(dir.join("stability.svg").exists() && dir.join("time-vs-error.svg").exists());
    std::fs::remove_dir_all(dir).unwrap();
    for f in [csv, svg, time_svg] {
        std::fs::remove_file(f).unwrap();
    }
}

/// Rows with the precision column: f32 round trips are held to their own target (1e-5 up
/// to B = 512), a failing f32 row fails the run, the f32 matching peak must be f64's (or
/// a tie), and the charts and tables split the rows by precision.
#[test]
fn stress_f32_rows_have_their_own_targets() {
    let header = "test,B,variant,precision,rel_l2,max_abs,time_s,note\n";
    let good = format!(
        "{header}roundtrip,16,complex,f64,6.0e-16,3.0e-15,1.0e-3,\"\"\n\
         roundtrip,32,complex,f64,1.0e-15,5.0e-15,8.0e-3,\"\"\n\
         roundtrip,64,complex,f64,1.6e-15,9.0e-15,6.0e-2,\"\"\n\
         roundtrip,16,complex,f32,2.8e-7,1.2e-6,6.0e-4,\"\"\n\
         roundtrip,32,complex,f32,5.3e-7,3.0e-6,4.0e-3,\"\"\n\
         roundtrip,64,complex,f32,8.5e-7,5.1e-6,3.0e-2,\"\"\n\
         roundtrip,512,s2-complex,f32,4.3e-6,2.0e-5,0.5,\"\"\n\
         roundtrip,1024,s2-complex,f32,1.2e-5,5.0e-5,2.0,\"\"\n\
         matching,16,match-grid,f64,NaN,6.9e-2,2.0e-4,\"angle error (rad); grid step pi/16\"\n\
         matching,16,match-grid,f32,NaN,6.9e-2,1.0e-4,\"angle error (rad); grid step pi/16; peak = f64's grid point\"\n"
    );
    let csv = temp("rows32.csv");
    let dir = temp("docs32");
    std::fs::create_dir_all(&dir).unwrap();
    let md = "<!-- stress-tables:begin (generated by so3fft-stress --docs docs) -->\n<!-- stress-tables:end -->\n";
    std::fs::write(dir.join("stability.md"), md).unwrap();
    std::fs::write(&csv, &good).unwrap();
    let args = [
        "--from-csv",
        csv.to_str().unwrap(),
        "--docs",
        dir.to_str().unwrap(),
    ];
    let (code, out, err) = run(STRESS, &args);
    assert_eq!(code, 0, "{out}{err}");
    // B = 1024 is above the f32 target's range: reported, not held to it.
    assert!(
        out.contains("[met] f32 round trip rel L2 <= 1e-5 up to B = 512")
            && out.contains("worst 4.30e-6 (s2-complex B = 512; 4 rows, B = 16..512)"),
        "{out}"
    );
    assert!(out.contains("[met] f32 matching"), "{out}");
    assert!(out.contains("[not run] f32 SO(3) round trip rel L2 <= 1e-5 at B = 512"));
    let md = std::fs::read_to_string(dir.join("stability.md")).unwrap();
    for line in [
        "| roundtrip | complex | f64 | 0.71 |",
        "| roundtrip | complex | f32 |",
        "| roundtrip complex | f32 | 3 | 1 | 16..64 | 8.50e-7 (complex B = 64) |",
    ] {
        assert!(md.contains(line), "{line} missing: {md}");
    }
    let chart = std::fs::read_to_string(dir.join("stability.svg")).unwrap();
    assert!(chart.contains("complex f32 (~B^"), "f32 series missing");
    let time = std::fs::read_to_string(dir.join("time-vs-error.svg")).unwrap();
    for needle in [
        "SO(3) round trips",
        "S^2 round trips",
        "Rotational matching",
        "complex f32",
        "s2-complex f32",
        "match-grid f32",
        "SOFT 2.0 SO(3)",
        "ducc0 S^2",
    ] {
        assert!(
            time.contains(needle),
            "{needle} missing from the time chart"
        );
    }

    // One f32 row above its target, one f32 peak away from f64's: both fail the run.
    for (from, to, missed) in [
        ("8.5e-7,5.1e-6", "2.5e-5,9.1e-5", "[MISSED] f32 round trip"),
        (
            "peak = f64's grid point",
            "peak NOT f64's: 1e-3 below",
            "[MISSED] f32 matching",
        ),
    ] {
        std::fs::write(&csv, good.replace(from, to)).unwrap();
        let (code, out, _) = run(STRESS, &args);
        assert_eq!(code, 1, "{out}");
        assert!(out.contains(missed), "{out}");
    }
    std::fs::remove_dir_all(dir).unwrap();
    std::fs::remove_file(csv).unwrap();
}
