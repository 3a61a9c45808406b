//! The `so3fft-match` tool: a reference correlation recovered from sample files, a noisy
//! scene matched with estimated weights (the uncertainty and the peak ratio reported), and
//! bad sample or weight files rejected with the file and line named and exit status 2.

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

/// The number after `key` on the output line starting with `line`.
fn number_after(out: &str, line: &str, key: &str) -> f64 {
    let l = out
        .lines()
        .find(|l| l.starts_with(line))
        .unwrap_or_else(|| panic!("no line '{line}' in: {out}"));
    let rest = &l[l.find(key).unwrap_or_else(|| panic!("no '{key}' in: {l}")) + key.len()..];
    let word = rest.split_whitespace().next().unwrap();
    word.trim_end_matches(',').parse().unwrap()
}

/// A noisy scene with a known rotation, matched with estimated weights: the refined
/// rotation within a few sigma of the truth, and the uncertainty, peak ratio, noise floors
/// and weighted degrees reported; uniform and file weights too.
#[test]
fn noisy_scene_with_weights() {
    let b = 16;
    let scene = so3fft::matching::scene::vmf_scene(b, 7, 0.3);
    let sig = write("scene.sig", &scene.signal);
    let pat = write("scene.pat", &scene.pattern);
    let (code, out, err) = run(&[
        sig.as_os_str(),
        pat.as_os_str(),
        "--weights".as_ref(),
        "auto".as_ref(),
    ]);
    assert_eq!(code, 0, "{err}");
    for needle in [
        "grid peak:",
        "refined peak:",
        "sigma = ",
        "peak ratio:",
        "noise floor:",
        "weights:      auto; highest degree weighted",
    ] {
        assert!(out.contains(needle), "expected '{needle}' in: {out}");
    }
    let angle = |name: &str| number_after(&out, "refined peak:", name);
    let found = so3fft::matching::Rotation::new(angle("alpha "), angle("beta "), angle("gamma "));
    let sigma = number_after(&out, "uncertainty:", "(");
    let error = found.angle_to(&scene.rotation);
    assert!(
        sigma > 0.0 && error < 5.0 * sigma,
        "error {error} rad, sigma {sigma}: {out}"
    );
    assert!(
        number_after(&out, "peak ratio:", "peak ratio:") > 1.0,
        "{out}"
    );
    assert!(number_after(&out, "noise floor:", "signal ") > 0.0, "{out}");

    // Uniform weights, and a file of weights for degrees 0..=9.
    let (code, out, err) = run(&[sig.as_os_str(), pat.as_os_str()]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("weights:      uniform") && out.contains("sigma = "),
        "{out}"
    );
    let weights: Vec<f64> = (0..10).map(|l| 1.0 / (1.0 + l as f64)).collect();
    let wfile = write("weights", &weights);
    let (code, out, err) = run(&[
        sig.as_os_str(),
        pat.as_os_str(),
        "--weights".as_ref(),
        wfile.as_os_str(),
        "--degree-limit".as_ref(),
        "9".as_ref(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("degrees 0..=9"), "{out}");
    assert!(
        out.contains("highest degree weighted >= 0.1 of the largest: 9 (of 9)"),
        "{out}"
    );
    for f in [sig, pat, wfile] {
        std::fs::remove_file(f).unwrap();
    }
}

#[test]
fn bad_weight_files_exit_with_status_2() {
    let good = write("wgood", &[0.5; 64]);
    let path = |name: &str| {
        let file = format!("so3fft-match-{}-weights-{name}", std::process::id());
        std::env::temp_dir().join(file)
    };
    // B = 4: weights w_0 .. w_3 by default.
    let cases = [
        ("count", "1\n1\n1\n", "3 weights, need 4".to_string()),
        (
            "negative",
            "1\n-0.5\n1\n1\n",
            ":2: weight '-0.5'".to_string(),
        ),
        ("nan", "1\n1\nNaN\n1\n", ":3: weight 'NaN'".to_string()),
        (
            "text",
            "1\nheavy\n1\n1\n",
            ":2: not a number: 'heavy'".to_string(),
        ),
        ("zero", "0\n0\n0\n0\n", "every weight is 0".to_string()),
    ];
    for (name, text, needle) in &cases {
        let file = path(name);
        std::fs::write(&file, text).unwrap();
        let (code, _, err) = run(&[
            good.as_os_str(),
            good.as_os_str(),
            "--weights".as_ref(),
            file.as_os_str(),
        ]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(
            err.contains(needle.as_str()),
            "{name}: expected '{needle}' in: {err}"
        );
        std::fs::remove_file(file).unwrap();
    }
    // A missing file, and a degree limit the bandwidth does not have.
    let (code, _, err) = run(&[
        good.as_os_str(),
        good.as_os_str(),
        "--weights".as_ref(),
        path("missing").as_os_str(),
    ]);
    assert_eq!(code, 2, "{err}");
    let (code, _, err) = run(&[
        good.as_os_str(),
        good.as_os_str(),
        "--degree-limit".as_ref(),
        "4".as_ref(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("degree limit 4"), "{err}");
    std::fs::remove_file(good).unwrap();
}
