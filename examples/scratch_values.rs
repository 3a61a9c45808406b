use so3fft::matching::{Rotation, So3Series};
use so3fft::Complex64;
use std::time::Instant;
fn main() {
    let l: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(64);
    let n = so3fft::num_coeffs(l);
    let mut x = 12345u64;
    let mut rnd = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x as f64 / u64::MAX as f64) - 0.5
    };
    let c: Vec<Complex64> = (0..n).map(|_| Complex64::new(rnd(), rnd())).collect();
    let s = So3Series::new(l, l - 1, &c);
    let gs: Vec<Rotation> = (0..8)
        .map(|k| Rotation::new(1.0 + 0.1 * k as f64, 1.2, 0.4))
        .collect();
    let mut best = f64::MAX;
    for _ in 0..40 {
        let t = Instant::now();
        std::hint::black_box(s.values(&gs));
        best = best.min(t.elapsed().as_secs_f64());
    }
    println!("{:.3}", best * 1e3);
}
