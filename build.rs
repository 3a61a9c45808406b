fn main() {
    // fftw-sys's "system" feature links fftw3 only; the planner thread-safety hook lives in
    // fftw3_threads.
    println!("cargo:rustc-link-lib=fftw3_threads");
    println!("cargo:rerun-if-changed=build.rs");
}
