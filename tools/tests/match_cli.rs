//! The `so3fft-match` tool: a reference correlation recovered from sample files, and bad
//! files rejected with the file and line named and exit status 2.

#[path = "../../tests/common/mod.rs"]
mod common;

use std::path::PathBuf;
use std::process::Command;

fn write(name: &str, numbers: &[f64]) -> PathBuf {
    let path = std::env::temp_dir().join(format!("so3fft-match-{}-{name}", std::process::id()));
    let text: String = numbers.iter().map(|x| format!("{x:?}\n")).collect();
    std::fs::write(&path, text).unwrap();
    path
}

/// Samples of a reference section, interleaved (complex) or real parts only.
fn samples(r: &common::S2Reference, section: &str, real: bool) -> Vec<f64> {
    let n = 2 * r.scalars["B"] as usize;
    let mut v = vec![0.0; if real { n * n } else { 2 * n * n }];
    for row in &r[section] {
        let i = row[0] as usize * n + row[1] as usize;
        if real {
            v[i] = row[2];
        } else {
            v[2 * i] = row[2];
            v[2 * i + 1] = row[3];
        }
    }
    v
}

fn run(args: &[&std::ffi::OsStr]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_so3fft-match"))
        .args(args)
        .output()
        .unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

#[test]
fn recovers_the_reference_rotations() {
    for (name, real) in [("cor_B8_complex.txt", false), ("cor_B16_real.txt", true)] {
        let r = common::read_s2_reference(name);
        let sig = write(&format!("{name}.sig"), &samples(&r, "signal", real));
        let pat = write(&format!("{name}.pat"), &samples(&r, "pattern", real));
        let (code, out, err) = run(&[
            sig.as_os_str(),
            pat.as_os_str(),
            "--top".as_ref(),
            "3".as_ref(),
        ]);
        assert_eq!(code, 0, "{name}: {err}");
        let want = format!(
            "grid peak:    alpha {:.10} beta {:.10} gamma {:.10}",
            r.scalars["alpha"], r.scalars["beta"], r.scalars["gamma"]
        );
        assert!(out.contains(&want), "{name}: {out}");
        assert!(
            out.contains("refined peak:") && out.contains("peak 3:"),
            "{out}"
        );
        std::fs::remove_file(sig).unwrap();
        std::fs::remove_file(pat).unwrap();
    }
}

#[test]
fn bad_files_are_named_with_their_line() {
    let good = write("good", &[0.5; 64]);
    let short = write("short", &[0.5; 63]);
    let text = std::env::temp_dir().join(format!("so3fft-match-{}-text", std::process::id()));
    std::fs::write(&text, "1.0\n2.0\nabc\n").unwrap();
    let nan = std::env::temp_dir().join(format!("so3fft-match-{}-nan", std::process::id()));
    std::fs::write(&nan, "1.0\nNaN\n").unwrap();
    for (file, needle) in [
        (&short, "63 numbers".to_string()),
        (&text, format!("{}:3: not a number", text.display())),
        (&nan, format!("{}:2: not a finite number", nan.display())),
    ] {
        let (code, _, err) = run(&[file.as_os_str(), good.as_os_str()]);
        assert_eq!(code, 2, "{err}");
        assert!(err.contains(&needle), "expected '{needle}' in: {err}");
    }
    let (code, _, err) = run(&[good.as_os_str()]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = run(&[good.as_os_str(), short.as_os_str()]);
    assert_eq!(code, 2, "{err}");
    for f in [good, short, text, nan] {
        std::fs::remove_file(f).unwrap();
    }
}
