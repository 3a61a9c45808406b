//! Test data, error measures, flop counts and memory estimates of one benchmark configuration.

use so3fft::Complex64;

/// xorshift64* generator (Vigna 2016): tiny, fast and reproducible across platforms, which is
/// all benchmark data needs; the crate has no `rand` dependency.
pub struct XorShift64Star(u64);

impl XorShift64Star {
    /// A zero state would stay zero forever, so it is replaced by a fixed odd constant.
    pub fn new(seed: u64) -> Self {
        XorShift64Star(if seed == 0 {
            0x9E37_79B9_7F4A_7C15
        } else {
            seed
        })
    }

    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }

    /// Uniform in [-1, 1), from the top 53 bits (the low bits of xorshift64* are weaker).
    pub fn next_signed_unit(&mut self) -> f64 {
        let unit = (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64);
        2.0 * unit - 1.0
    }
}

/// `n` coefficients with real and imaginary parts uniform in [-1, 1].
///
/// Every (l, m, m') slot is a free coefficient of a band-limited function on SO(3), so any
/// values form a valid input and the round trip must reproduce them exactly up to rounding.
pub fn random_coeffs(n: usize, seed: u64) -> Vec<Complex64> {
    let mut rng = XorShift64Star::new(seed);
    (0..n)
        .map(|_| {
            let re = rng.next_signed_unit();
            Complex64::new(re, rng.next_signed_unit())
        })
        .collect()
}

/// Error of a round trip (inverse then forward) against the original coefficients.
#[derive(Clone, Copy, Debug, Default)]
pub struct RoundTripError {
    pub max_abs: f64,
    pub rel_l2: f64,
}

impl RoundTripError {
    /// Elementwise worst of two measurements (errors of several runs are combined this way).
    pub fn worst(self, other: RoundTripError) -> RoundTripError {
        RoundTripError {
            max_abs: self.max_abs.max(other.max_abs),
            rel_l2: self.rel_l2.max(other.rel_l2),
        }
    }
}

/// Max absolute error and relative L2 error ||result - reference|| / ||reference||.
/// A NaN anywhere makes both NaN (NaN must not vanish in a `max`).
pub fn roundtrip_error(reference: &[Complex64], result: &[Complex64]) -> RoundTripError {
    assert_eq!(reference.len(), result.len());
    let (mut max_abs, mut diff2, mut ref2) = (0.0f64, 0.0f64, 0.0f64);
    for (r, x) in reference.iter().zip(result) {
        let d = (x - r).norm();
        max_abs = if d.is_nan() { f64::NAN } else { max_abs.max(d) };
        diff2 += d * d;
        ref2 += r.norm_sqr();
    }
    RoundTripError {
        max_abs,
        rel_l2: (diff2 / ref2).sqrt(),
    }
}

/// Median of a non-empty sample (mean of the two middle values for an even count).
pub fn median(values: &[f64]) -> f64 {
    assert!(!values.is_empty(), "median of an empty sample");
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let mid = sorted.len() / 2;
    if sorted.len() % 2 == 1 {
        sorted[mid]
    } else {
        0.5 * (sorted[mid - 1] + sorted[mid])
    }
}

/// Exact DWT flop count per direction: for each order pair (m, m') the stage touches the
/// degrees l = max(|m|,|m'|)..B-1 at 2B betas with two FMAs (4 flops) each, i.e.
/// 8B * sum_{(m,m')} (B - max(|m|,|m'|)) = 8B * (4B^3 - B) / 3.
pub fn dwt_flops_exact(b: usize) -> u64 {
    let b = b as u64;
    8 * b * (4 * b * b * b - b) / 3
}

/// DWT flops per direction of the real-signal transforms: only one order pair of each
/// `(M, M') <-> (-M, -M')` pair is transformed, `(T + B)/2` of the `T = (4B^3 - B)/3`
/// coefficients (the pair (0, 0) is its own partner), so `8B (T + B)/2 = 4B (T + B)`.
pub fn dwt_flops_real(b: usize) -> u64 {
    let b = b as u64;
    4 * b * ((4 * b * b * b - b) / 3 + b)
}

/// Leading-order DWT flop count 32 B^4 / 3 (shown next to the exact one for comparison).
pub fn dwt_flops_approx(b: usize) -> f64 {
    32.0 * (b as f64).powi(4) / 3.0
}

/// Bytes one configuration is expected to need: the bench's own sample array and two coefficient
/// arrays (input and round-trip output), plus one more sample-sized array for the library's
/// intermediate data (an estimate: its chunked workspace is usually smaller).
pub fn estimated_bytes(b: usize) -> usize {
    let elem = std::mem::size_of::<Complex64>();
    elem * (2 * so3fft::num_samples(b) + 2 * so3fft::num_coeffs(b))
}

/// Bytes of a transform's input and output at bandwidth `b`: complex samples, or real ones
/// with `real`, plus the complex coefficients (the "in+out" of the memory figures).
pub fn array_bytes(b: usize, real: bool) -> u64 {
    let sample = if real { 8 } else { 16 };
    (sample * so3fft::num_samples(b) + 16 * so3fft::num_coeffs(b)) as u64
}

/// `MemAvailable` from /proc/meminfo in bytes, or `None` where it cannot be read.
pub fn mem_available_bytes() -> Option<usize> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: usize = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}
