//! Build script: link FFTW's threads library, give the shared library a SONAME, and
//! generate the C header `include/so3fft.h` from `src/capi/` with cbindgen.
//!
//! The header is committed. It is rewritten only when its content changes, so builds do
//! not touch it needlessly. With `SO3FFT_CHECK_HEADER=1` in the environment (CI) the
//! script never writes it and fails when the committed header differs from the generated
//! one; the generated header is always also written to `$OUT_DIR/so3fft.h`.

use std::env;
use std::fs;
use std::path::PathBuf;

/// The native C API: cbindgen reads this file and the modules it declares, in the order
/// of their declarations.
const CAPI_ROOT: &str = "src/capi/mod.rs";

/// SONAME of the shared library: bump the number with any ABI break.
const SONAME: &str = "libso3fft.so.0";

fn main() {
    // fftw-sys's "system" feature links fftw3 and fftw3f only; the planner thread-safety
    // hooks (fftw_make_planner_thread_safe, fftwf_make_planner_thread_safe), which the
    // library calls for both precisions when it is loaded, live in the threads libraries.
    // Single precision first: a static link needs each threads library before its FFTW.
    println!("cargo:rustc-link-lib=fftw3f_threads");
    println!("cargo:rustc-link-lib=fftw3_threads");
    println!("cargo:rerun-if-changed=build.rs");

    let target_os = env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if target_os == "linux" || target_os == "freebsd" {
        println!("cargo:rustc-cdylib-link-arg=-Wl,-soname,{SONAME}");
    }

    generate_header();
    if env::var_os("CARGO_FEATURE_MPI").is_some() {
        build_mpi_shim();
    }
}

/// Compiles `src/distributed/mpi_shim.c` with the include and link flags `mpicc` reports.
fn build_mpi_shim() {
    let shim = "src/distributed/mpi_shim.c";
    println!("cargo:rerun-if-changed={shim}");
    let showme = |what: &str| -> Vec<String> {
        let out = std::process::Command::new("mpicc")
            .arg(format!("--showme:{what}"))
            .output()
            .unwrap_or_else(|e| panic!("feature mpi: running `mpicc --showme:{what}`: {e}"));
        String::from_utf8_lossy(&out.stdout)
            .split_whitespace()
            .map(str::to_string)
            .collect()
    };
    let mut build = cc::Build::new();
    build.file(shim).warnings(true);
    for flag in showme("compile") {
        if let Some(dir) = flag.strip_prefix("-I") {
            build.include(dir);
        } else {
            build.flag(&flag);
        }
    }
    build.compile("so3fft_mpi_shim");
    for flag in showme("link") {
        if let Some(dir) = flag.strip_prefix("-L") {
            println!("cargo:rustc-link-search=native={dir}");
        } else if let Some(lib) = flag.strip_prefix("-l") {
            println!("cargo:rustc-link-lib={lib}");
        }
    }
}

fn generate_header() {
    let root = PathBuf::from(env::var("CARGO_MANIFEST_DIR").expect("CARGO_MANIFEST_DIR"));
    let out_dir = PathBuf::from(env::var("OUT_DIR").expect("OUT_DIR"));
    let capi = root.join(CAPI_ROOT);
    let config_path = root.join("cbindgen.toml");
    let header_path = root.join("include/so3fft.h");
    // A directory: cargo scans all of it for changes.
    let capi_dir = capi.parent().expect("src/capi");
    for p in [capi_dir, &config_path, &header_path] {
        println!("cargo:rerun-if-changed={}", p.display());
    }
    println!("cargo:rerun-if-env-changed=SO3FFT_CHECK_HEADER");

    let mut config = cbindgen::Config::from_file(&config_path)
        .unwrap_or_else(|e| panic!("reading {}: {e}", config_path.display()));
    let version = env::var("CARGO_PKG_VERSION").expect("CARGO_PKG_VERSION");
    let part = |k: &str| env::var(k).expect("CARGO_PKG_VERSION_*");
    config.after_includes = Some(format!(
        "\n// Version of this header (compare with so3fft_version() at run time).\n\
         #define SO3FFT_VERSION \"{version}\"\n\
         #define SO3FFT_VERSION_MAJOR {}\n\
         #define SO3FFT_VERSION_MINOR {}\n\
         #define SO3FFT_VERSION_PATCH {}",
        part("CARGO_PKG_VERSION_MAJOR"),
        part("CARGO_PKG_VERSION_MINOR"),
        part("CARGO_PKG_VERSION_PATCH"),
    ));

    let bindings = cbindgen::Builder::new()
        .with_config(config)
        .with_src(&capi)
        .generate()
        .unwrap_or_else(|e| panic!("cbindgen failed on src/capi/: {e}"));
    let mut raw = Vec::new();
    bindings.write(&mut raw);
    let generated = parenthesize_negative_defines(&String::from_utf8(raw).expect("UTF-8 header"));
    let generated = generated.into_bytes();
    fs::write(out_dir.join("so3fft.h"), &generated).expect("writing $OUT_DIR/so3fft.h");

    let committed = fs::read(&header_path).ok();
    if committed.as_deref() == Some(generated.as_slice()) {
        return;
    }
    if env::var("SO3FFT_CHECK_HEADER").is_ok_and(|v| v == "1") {
        panic!(
            "include/so3fft.h is out of date: it differs from the header generated from \
             src/capi/ (see {}). Rebuild without SO3FFT_CHECK_HEADER=1 to regenerate it \
             and commit the result.",
            out_dir.join("so3fft.h").display()
        );
    }
    let written = fs::create_dir_all(header_path.parent().expect("include dir"))
        .and_then(|_| fs::write(&header_path, &generated));
    if let Err(e) = written {
        // E.g. a read-only source tree (cargo package --verify): not fatal.
        println!(
            "cargo:warning=could not write {}: {e}",
            header_path.display()
        );
    }
}

/// cbindgen drops the parentheses of `-1`: write `#define X (-1)` so the macros are safe
/// in any expression.
fn parenthesize_negative_defines(header: &str) -> String {
    let mut out = String::with_capacity(header.len() + 64);
    for line in header.split_inclusive('\n') {
        let body = line.trim_end_matches('\n');
        let mut parts = body.splitn(3, ' ');
        if let (Some("#define"), Some(name), Some(value)) =
            (parts.next(), parts.next(), parts.next())
        {
            if value.starts_with('-') && value[1..].chars().all(|c| c.is_ascii_digit()) {
                out.push_str(&format!("#define {name} ({value})"));
                out.push_str(&line[body.len()..]);
                continue;
            }
        }
        out.push_str(line);
    }
    out
}
