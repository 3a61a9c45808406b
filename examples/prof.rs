//! Stage times of repeated transforms, for profiling (`perf record`) and for comparing two
//! builds run alternately: each transform prints the seconds of its FFT and DWT stages (the
//! forwards also the whole transform).
//!
//! ```text
//! cargo run --release --example prof -- [B] [MODE] [REPS] [WORKSPACE_MIB]
//! ```
//!
//! `B` the bandwidth (default 256); `MODE` one of `inv`, `fwd`, `both` (default), `dfwd`
//! (the forward that may overwrite its input), `rinv`, `rfwd`, `rboth` (real signals);
//! `REPS` the number of repetitions (default 3); `WORKSPACE_MIB` a cap on the chunk buffer
//! (default: the plan's default). Environment: `THREADS` (default 1), `FFT=fftw|slices`
//! (FFT-stage threading, default chosen by timing), `PATIENT` (FFTW's patient planning).
//! Take the best or the median of the printed times: the first repetition includes page
//! faults and cold caches.

use so3fft::{Complex64, Direction, Plan, PlanOptions, Rigor};

const MODES: [&str; 7] = ["inv", "fwd", "both", "dfwd", "rinv", "rfwd", "rboth"];

fn usage(msg: &str) -> ! {
    eprintln!("prof: {msg}");
    eprintln!(
        "usage: prof [B] [{}] [REPS] [WORKSPACE_MIB]",
        MODES.join("|")
    );
    std::process::exit(2)
}

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let num = |i: usize, default: usize, what: &str| -> usize {
        a.get(i).map_or(default, |s| {
            s.parse()
                .unwrap_or_else(|_| usage(&format!("{what} must be a number, not {s:?}")))
        })
    };
    let b = num(1, 256, "B");
    let dir = a.get(2).cloned().unwrap_or("both".into());
    if !MODES.contains(&dir.as_str()) {
        usage(&format!("unknown mode {dir:?}"));
    }
    let reps = num(3, 3, "REPS");
    let ws: Option<usize> = a.get(4).map(|_| num(4, 0, "WORKSPACE_MIB") << 20);
    let real = dir.starts_with('r');
    let opts = PlanOptions {
        threads: std::env::var("THREADS")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(1),
        rigor: if std::env::var("PATIENT").is_ok() {
            Rigor::Patient
        } else {
            Rigor::Measure
        },
        max_workspace_bytes: ws,
        direction: Direction::Both,
        real,
        fft_threading: match std::env::var("FFT").as_deref() {
            Ok("fftw") => so3fft::FftThreading::FftwThreads,
            Ok("slices") => so3fft::FftThreading::SlicesAcrossWorkers,
            _ => so3fft::FftThreading::Auto,
        },
        ..Default::default()
    };
    let p = Plan::new(b, &opts).unwrap_or_else(|e| usage(&format!("cannot plan: {e}")));
    eprintln!("fft threading {:?}", p.fft_threading());
    let mut c = vec![Complex64::new(0.0, 0.0); p.num_coeffs()];
    let mut s: u64 = 0x1234567;
    for x in c.iter_mut() {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        *x = Complex64::new(
            (s % 1000) as f64 / 500.0 - 1.0,
            ((s >> 20) % 1000) as f64 / 500.0 - 1.0,
        );
    }
    let mut c2 = c.clone();
    if real {
        let mut f = vec![0.0f64; p.num_samples()];
        for x in f.iter_mut() {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            *x = (s % 1000) as f64 / 500.0 - 1.0;
        }
        p.forward_real(&f, &mut c).unwrap();
        for _ in 0..reps {
            if dir != "rfwd" {
                let t = p.inverse_real_timed(&c, &mut f).unwrap();
                eprintln!("rinv fft {:.4} dwt {:.4}", t.fft, t.dwt);
            }
            if dir != "rinv" {
                let t = p.forward_real_timed(&f, &mut c2).unwrap();
                eprintln!(
                    "rfwd fft {:.4} dwt {:.4} total {:.4}",
                    t.fft, t.dwt, t.total
                );
            }
        }
        return;
    }
    let mut f = vec![Complex64::new(0.0, 0.0); p.num_samples()];
    p.inverse(&c, &mut f).unwrap();
    for _ in 0..reps {
        if dir != "fwd" && dir != "dfwd" {
            let t = p.inverse_timed(&c, &mut f).unwrap();
            eprintln!("inv fft {:.4} dwt {:.4}", t.fft, t.dwt);
        }
        if dir == "dfwd" {
            let mut g = f.clone();
            let t = p.forward_destroying_input_timed(&mut g, &mut c2).unwrap();
            eprintln!("dfwd fft {:.4} dwt {:.4}", t.fft, t.dwt);
        } else if dir != "inv" {
            let t = p.forward_timed(&f, &mut c2).unwrap();
            eprintln!("fwd fft {:.4} dwt {:.4} total {:.4}", t.fft, t.dwt, t.total);
        }
    }
    eprintln!("workspace {} MiB", p.workspace_bytes() >> 20);
}
