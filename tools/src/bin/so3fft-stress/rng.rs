//! The PRNG shared with `tests/data/stress/gen_stress_reference.py`: splitmix64, whose
//! `sym()` draws are exact doubles, so both sides build the same inputs bit for bit.

use so3fft::Complex64;

/// splitmix64 (Vigna).
pub struct SplitMix64 {
    state: u64,
}

impl SplitMix64 {
    /// A generator started at `seed`.
    pub fn new(seed: u64) -> SplitMix64 {
        SplitMix64 { state: seed }
    }

    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[-1, 1)` with 53 random bits (as the Python side computes it).
    pub fn sym(&mut self) -> f64 {
        2.0 * ((self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)) - 1.0
    }

    /// A complex value, real part drawn first.
    pub fn complex(&mut self) -> Complex64 {
        let re = self.sym();
        Complex64::new(re, self.sym())
    }

    /// `n` complex values.
    pub fn complex_vec(&mut self, n: usize) -> Vec<Complex64> {
        (0..n).map(|_| self.complex()).collect()
    }
}
