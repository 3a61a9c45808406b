//! Shared helpers for the so3fft integration tests.
//!
//! Everything here is written independently of the library: a small PRNG, parsers for the
//! reference files in tests/data, an independent Wigner-d (Wigner's explicit factorial
//! sum, only meant for small degrees), quadrature weights from the formula in docs/conventions.md, and
//! direct (naive, FFT-free) summations of the inverse and forward transforms.
#![allow(dead_code)]

use so3fft::{Complex32, Complex64};
use std::f64::consts::PI;
use std::path::PathBuf;

// ---------------------------------------------------------------------------------------------
// PRNG: xorshift64* (Vigna). Deterministic, no external crates.
// ---------------------------------------------------------------------------------------------
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Rng {
        // avoid the all-zero state; scramble the seed a little (splitmix64 step)
        let mut z = seed.wrapping_add(0x9E37_79B9_7F4A_7C15);
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        Rng(if z == 0 { 0x1234_5678_9ABC_DEF1 } else { z })
    }
    pub fn next_u64(&mut self) -> u64 {
        let mut x = self.0;
        x ^= x >> 12;
        x ^= x << 25;
        x ^= x >> 27;
        self.0 = x;
        x.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    /// uniform in [0, 1)
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
    }
    /// uniform in [-1, 1)
    pub fn sym(&mut self) -> f64 {
        2.0 * self.unit() - 1.0
    }
    pub fn complex(&mut self) -> Complex64 {
        Complex64::new(self.sym(), self.sym())
    }
    pub fn complex_vec(&mut self, n: usize) -> Vec<Complex64> {
        (0..n).map(|_| self.complex()).collect()
    }
}

// ---------------------------------------------------------------------------------------------
// Sizes and layouts, written from docs/conventions.md (independently of the library's helpers).
// ---------------------------------------------------------------------------------------------
pub fn n_samples(b: usize) -> usize {
    8 * b * b * b
}
pub fn n_coeffs(b: usize) -> usize {
    (4 * b * b * b - b) / 3
}
/// Flat sample index: k*(2B)^2 + j1*(2B) + j2 (beta slowest, gamma fastest).
pub fn s_idx(b: usize, k: usize, j1: usize, j2: usize) -> usize {
    let n = 2 * b;
    (k * n + j1) * n + j2
}
/// SOFT order enumeration of orders: 0, 1, ..., B-1, -(B-1), ..., -1.
pub fn soft_orders(b: usize) -> Vec<isize> {
    let bi = b as isize;
    (0..bi).chain(-(bi - 1)..0).collect()
}
/// Independent coefficient layout: enumerate the blocks (M, M') in SOFT's row-major order and
/// l = max(|M|,|M'|)..B-1 inside a block; returns a dense table indexed by
/// [(l, M+B-1, M'+B-1)] -> flat index (usize::MAX where not a valid triple).
pub struct Layout {
    pub b: usize,
    table: Vec<usize>,
}
impl Layout {
    pub fn new(b: usize) -> Layout {
        let w = 2 * b - 1;
        let mut table = vec![usize::MAX; b * w * w];
        let mut next = 0usize;
        for &m in &soft_orders(b) {
            for &mp in &soft_orders(b) {
                let l0 = m.unsigned_abs().max(mp.unsigned_abs());
                for l in l0..b {
                    table[(l * w + (m + b as isize - 1) as usize) * w
                        + (mp + b as isize - 1) as usize] = next;
                    next += 1;
                }
            }
        }
        assert_eq!(next, n_coeffs(b));
        Layout { b, table }
    }
    pub fn idx(&self, l: usize, m: isize, mp: isize) -> usize {
        let b = self.b;
        let w = 2 * b - 1;
        let v = self.table
            [(l * w + (m + b as isize - 1) as usize) * w + (mp + b as isize - 1) as usize];
        assert!(v != usize::MAX, "invalid triple l={l} m={m} mp={mp}");
        v
    }
}
/// All valid (l, M, M') for bandwidth b.
pub fn triples(b: usize) -> Vec<(usize, isize, isize)> {
    let mut v = Vec::with_capacity(n_coeffs(b));
    for l in 0..b {
        let li = l as isize;
        for m in -li..=li {
            for mp in -li..=li {
                v.push((l, m, mp));
            }
        }
    }
    v
}

// ---------------------------------------------------------------------------------------------
// Grid and weights from docs/conventions.md (sample grid, quadrature weights).
// ---------------------------------------------------------------------------------------------
pub fn grid_beta(b: usize, k: usize) -> f64 {
    PI * (2 * k + 1) as f64 / (4 * b) as f64
}
/// w_B(k) = (2/B) sin(beta_k) sum_{i=0}^{B-1} sin((2i+1) beta_k)/(2i+1), k = 0..2B-1.
pub fn weights_formula(b: usize) -> Vec<f64> {
    (0..2 * b)
        .map(|k| {
            let bk = grid_beta(b, k);
            let mut s = 0.0;
            for i in 0..b {
                let o = (2 * i + 1) as f64;
                s += (o * bk).sin() / o;
            }
            2.0 / b as f64 * bk.sin() * s
        })
        .collect()
}
/// exp(i * sign * m * pi * j / B), argument reduced exactly modulo 2B before the trig call.
pub fn grid_phase(b: usize, m: isize, j: usize, sign: f64) -> Complex64 {
    let n = 2 * b as isize;
    let r = (m * j as isize).rem_euclid(n);
    let ang = PI * r as f64 / b as f64;
    Complex64::new(ang.cos(), sign * ang.sin())
}

// ---------------------------------------------------------------------------------------------
// Independent Wigner small-d: Wigner's explicit sum (Wikipedia form, row m' = M, column m = M').
//   d^l_{M,M'}(b) = sqrt((l+M)!(l-M)!(l+M')!(l-M')!) *
//     sum_s (-1)^(M-M'+s) c^(2l+M'-M-2s) s^(M-M'+2s) / ((l+M'-s)! s! (M-M'+s)! (l-M-s)!)
// with c = cos(b/2), s = sin(b/2). Accurate to ~1e-14 for l < 10 in f64 (sum of |terms| <= 2^l).
// ---------------------------------------------------------------------------------------------
fn fact(n: i64) -> f64 {
    assert!(n >= 0);
    (1..=n).fold(1.0f64, |a, k| a * k as f64)
}
pub fn wigner_d_explicit(l: usize, m: isize, mp: isize, beta: f64) -> f64 {
    let l = l as i64;
    let (m, mp) = (m as i64, mp as i64);
    assert!(m.abs() <= l && mp.abs() <= l);
    let c = (beta / 2.0).cos();
    let s = (beta / 2.0).sin();
    let pref = (fact(l + m) * fact(l - m) * fact(l + mp) * fact(l - mp)).sqrt();
    let smin = 0.max(mp - m);
    let smax = (l + mp).min(l - m);
    let mut total = 0.0;
    for k in smin..=smax {
        let sign = if (m - mp + k).rem_euclid(2) == 0 {
            1.0
        } else {
            -1.0
        };
        let den = fact(l + mp - k) * fact(k) * fact(m - mp + k) * fact(l - m - k);
        total +=
            sign * c.powi((2 * l + mp - m - 2 * k) as i32) * s.powi((m - mp + 2 * k) as i32) / den;
    }
    pref * total
}
/// Normalised dt^l = sqrt((2l+1)/2) d^l.
pub fn dt_explicit(l: usize, m: isize, mp: isize, beta: f64) -> f64 {
    ((2 * l + 1) as f64 / 2.0).sqrt() * wigner_d_explicit(l, m, mp, beta)
}

/// Table of dt^l_{M,M'}(beta_k) for all triples at bandwidth b: [k][triple index in `triples(b)` order].
fn dt_table(b: usize, trip: &[(usize, isize, isize)]) -> Vec<Vec<f64>> {
    (0..2 * b)
        .map(|k| {
            let bk = grid_beta(b, k);
            trip.iter()
                .map(|&(l, m, mp)| dt_explicit(l, m, mp, bk))
                .collect()
        })
        .collect()
}

/// Naive inverse: f(a_j1, b_k, g_j2) = sum fhat(l,M,M') (1/(2pi)) dt^l(b_k) e^{-iM a} e^{-iM' g}.
/// `coefs` in the SOFT layout (independent Layout). O(B^3 * #coefs).
pub fn direct_inverse(b: usize, coefs: &[Complex64]) -> Vec<Complex64> {
    assert_eq!(coefs.len(), n_coeffs(b));
    let n = 2 * b;
    let lay = Layout::new(b);
    let trip = triples(b);
    let dt = dt_table(b, &trip);
    let c: Vec<Complex64> = trip
        .iter()
        .map(|&(l, m, mp)| coefs[lay.idx(l, m, mp)])
        .collect();
    let inv2pi = 1.0 / (2.0 * PI);
    let mut out = vec![Complex64::new(0.0, 0.0); n_samples(b)];
    for k in 0..n {
        for j1 in 0..n {
            for j2 in 0..n {
                let mut acc = Complex64::new(0.0, 0.0);
                for (t, &(_, m, mp)) in trip.iter().enumerate() {
                    let e = grid_phase(b, m, j1, -1.0) * grid_phase(b, mp, j2, -1.0);
                    acc += c[t] * e * dt[k][t];
                }
                out[s_idx(b, k, j1, j2)] = acc * inv2pi;
            }
        }
    }
    out
}

/// Naive forward quadrature:
/// fhat(l,M,M') = (pi/(2B^2)) sum_k w_B(k) dt^l(b_k) sum_{j1,j2} e^{+iM a_j1} e^{+iM' g_j2} f.
/// Weights from `weights_formula`. Output in the SOFT layout.
pub fn direct_forward(b: usize, samples: &[Complex64]) -> Vec<Complex64> {
    assert_eq!(samples.len(), n_samples(b));
    let n = 2 * b;
    let lay = Layout::new(b);
    let trip = triples(b);
    let dt = dt_table(b, &trip);
    let w = weights_formula(b);
    let mut out = vec![Complex64::new(0.0, 0.0); n_coeffs(b)];
    let scale = PI / (2.0 * (b * b) as f64);
    // S[k][M][M'] = sum_{j1,j2} e^{+iM a} e^{+iM' g} f  (naive 2-D sums, no FFT)
    let w2 = 2 * b - 1;
    let bi = b as isize;
    for k in 0..n {
        let mut s = vec![Complex64::new(0.0, 0.0); w2 * w2];
        for m in -(bi - 1)..bi {
            for mp in -(bi - 1)..bi {
                let mut acc = Complex64::new(0.0, 0.0);
                for j1 in 0..n {
                    let ea = grid_phase(b, m, j1, 1.0);
                    for j2 in 0..n {
                        acc += ea * grid_phase(b, mp, j2, 1.0) * samples[s_idx(b, k, j1, j2)];
                    }
                }
                s[(m + bi - 1) as usize * w2 + (mp + bi - 1) as usize] = acc;
            }
        }
        for (t, &(l, m, mp)) in trip.iter().enumerate() {
            out[lay.idx(l, m, mp)] +=
                s[(m + bi - 1) as usize * w2 + (mp + bi - 1) as usize] * (w[k] * dt[k][t]);
        }
    }
    for v in out.iter_mut() {
        *v *= scale;
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Error helpers
// ---------------------------------------------------------------------------------------------
/// max |a_i - b_i| and the index where it occurs.
pub fn max_abs_diff(a: &[Complex64], b: &[Complex64]) -> (f64, usize) {
    assert_eq!(a.len(), b.len());
    let mut best = (0.0f64, 0usize);
    for (i, (x, y)) in a.iter().zip(b.iter()).enumerate() {
        let d = (x - y).norm();
        if d > best.0 || d.is_nan() {
            best = (if d.is_nan() { f64::INFINITY } else { d }, i);
        }
    }
    best
}
pub fn max_abs(a: &[Complex64]) -> f64 {
    a.iter().map(|x| x.norm()).fold(0.0, f64::max)
}
pub fn bitwise_equal(a: &[Complex64], b: &[Complex64]) -> bool {
    a.len() == b.len()
        && a.iter()
            .zip(b.iter())
            .all(|(x, y)| x.re.to_bits() == y.re.to_bits() && x.im.to_bits() == y.im.to_bits())
}

/// Random coefficients satisfying the real-signal symmetry fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M')).
pub fn random_real_signal_coefs(b: usize, rng: &mut Rng) -> Vec<Complex64> {
    let lay = Layout::new(b);
    let mut c = vec![Complex64::new(0.0, 0.0); n_coeffs(b)];
    for (l, m, mp) in triples(b) {
        if (m, mp) < (-m, -mp) {
            let v = rng.complex();
            c[lay.idx(l, m, mp)] = v;
            let sign = if (m - mp).rem_euclid(2) == 0 {
                1.0
            } else {
                -1.0
            };
            c[lay.idx(l, -m, -mp)] = v.conj() * sign;
        } else if m == 0 && mp == 0 {
            c[lay.idx(l, 0, 0)] = Complex64::new(rng.sym(), 0.0);
        }
    }
    c
}

// ---------------------------------------------------------------------------------------------
// Test data
// ---------------------------------------------------------------------------------------------
/// The repository's root: this module is compiled into the library's tests and into the
/// tools package's (`tools/`), whose manifest directory is one level down.
pub fn repository_dir() -> PathBuf {
    let manifest = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    if manifest.join("tests").join("data").is_dir() {
        manifest
    } else {
        manifest.join("..")
    }
}

pub fn testdata_dir() -> PathBuf {
    if let Ok(d) = std::env::var("SO3FFT_TESTDATA") {
        if !d.is_empty() {
            return PathBuf::from(d);
        }
    }
    repository_dir().join("tests").join("data")
}

fn num<T: std::str::FromStr>(tok: &str, path: &std::path::Path, lineno: usize, line: &str) -> T {
    tok.parse().unwrap_or_else(|_| {
        panic!(
            "{}:{}: cannot parse {:?} in line {:?}",
            path.display(),
            lineno + 1,
            tok,
            line
        )
    })
}

pub struct TransformRef {
    pub b: usize,
    /// (l, M, M', value)
    pub coefs: Vec<(usize, isize, isize, Complex64)>,
    /// (k, j1, j2, value)
    pub samples: Vec<(usize, usize, usize, Complex64)>,
}

pub fn parse_transform(name: &str) -> TransformRef {
    let path = testdata_dir().join(name);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut b = 0usize;
    let mut ncoef = 0usize;
    let mut nsamp = 0usize;
    let mut section = "";
    let mut coefs = Vec::new();
    let mut samples = Vec::new();
    for (lineno, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let t: Vec<&str> = line.split_whitespace().collect();
        let bad = || -> ! {
            panic!(
                "{}:{}: cannot parse line {:?}",
                path.display(),
                lineno + 1,
                line
            )
        };
        match (t[0], t.len()) {
            ("B", 2) => b = num(t[1], &path, lineno, line),
            ("coef", 2) => {
                section = "coef";
                ncoef = num(t[1], &path, lineno, line);
            }
            ("sample", 2) => {
                section = "sample";
                nsamp = num(t[1], &path, lineno, line);
            }
            (_, 5) => {
                let v = Complex64::new(
                    num(t[3], &path, lineno, line),
                    num(t[4], &path, lineno, line),
                );
                match section {
                    "coef" => coefs.push((
                        num(t[0], &path, lineno, line),
                        num(t[1], &path, lineno, line),
                        num(t[2], &path, lineno, line),
                        v,
                    )),
                    "sample" => samples.push((
                        num(t[0], &path, lineno, line),
                        num(t[1], &path, lineno, line),
                        num(t[2], &path, lineno, line),
                        v,
                    )),
                    _ => bad(),
                }
            }
            _ => bad(),
        }
    }
    assert!(b > 0, "{}: no B line", path.display());
    assert_eq!(coefs.len(), ncoef, "{}: coefficient count", path.display());
    assert_eq!(samples.len(), nsamp, "{}: sample count", path.display());
    assert_eq!(
        ncoef,
        n_coeffs(b),
        "{}: coefficient count vs B",
        path.display()
    );
    assert_eq!(nsamp, n_samples(b), "{}: sample count vs B", path.display());
    TransformRef { b, coefs, samples }
}

pub struct WignerRow {
    pub l: usize,
    pub m: isize,
    pub mp: isize,
    pub beta: f64,
    pub d: f64,
}

pub fn parse_wigner_csv() -> Vec<WignerRow> {
    let path = testdata_dir().join("wigner_d_reference.csv");
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let mut rows = Vec::new();
    for (lineno, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') || line.starts_with("l,") {
            continue;
        }
        let t: Vec<&str> = line.split(',').collect();
        let bad = || -> ! { panic!("{}:{}: cannot parse {:?}", path.display(), lineno + 1, line) };
        if t.len() != 5 {
            bad();
        }
        rows.push(WignerRow {
            l: num(t[0], &path, lineno, line),
            m: num(t[1], &path, lineno, line),
            mp: num(t[2], &path, lineno, line),
            beta: num(t[3], &path, lineno, line),
            // Rust's parser rounds tiny values (e.g. 1e-400) to 0 / subnormals correctly.
            d: num(t[4], &path, lineno, line),
        });
    }
    rows
}

/// Absolute tolerance for a computed `d^l_{M,M'}(beta)` (`|d| <= 1`) at degree `l`.
///
/// Two parts, both in units of `eps = 2.2e-16`:
/// * start value and recurrence away from the poles: the start value `c^a s^b` (`a + b <= 2l`)
///   has condition number `a + b` with respect to the rounded half-angle cos/sin, and the
///   three-term recurrence adds roughly O(l) roundings: a few times `l * eps`, hence
///   `max(1e-14, 4e-16 l)` (4.1e-13 at l = 1023; a flat 1e-14 for l <= 6);
/// * near the poles (within about 1/l of beta = 0 or pi) the recurrence's two solutions are
///   nearly degenerate (a double characteristic root), so a rounding error made at step j grows
///   like (l - j) instead of staying bounded; l such errors of random sign add up to about
///   `l^{3/2} eps / sqrt 3`. The library never forms a rounded cos(beta) (it recurs in
///   1 -/+ cos(beta), which is exact to a few ulps), so there is no argument error on top.
///   The tolerance allows `min(l^{3/2}, sqrt(l) / sin(beta)) * eps`: the full amount at the
///   poles (7.3e-12 at l = 1023, where 2.6e-12 is measured), fading out as `l sin(beta)`
///   grows past 1.
pub fn wigner_tol(l: usize, beta: f64) -> f64 {
    let lf = l as f64;
    let base = if l <= 6 {
        1e-14
    } else {
        f64::max(1e-14, 4e-16 * lf)
    };
    let s = beta.sin().abs();
    let pole = if s > 0.0 {
        f64::min(lf * lf.sqrt(), lf.sqrt() / s)
    } else {
        lf * lf.sqrt()
    };
    base + pole * f64::EPSILON
}

/// A reference file of `tests/data/s2/`: its scalar lines (`key value`) and its sections
/// (`section NAME COUNT` followed by rows of numbers).
pub struct S2Reference {
    pub scalars: std::collections::HashMap<String, f64>,
    pub sections: std::collections::HashMap<String, Vec<Vec<f64>>>,
}

impl std::ops::Index<&str> for S2Reference {
    type Output = Vec<Vec<f64>>;
    fn index(&self, name: &str) -> &Vec<Vec<f64>> {
        &self.sections[name]
    }
}

/// Reads `tests/data/s2/<name>`.
pub fn read_s2_reference(name: &str) -> S2Reference {
    let path = format!("{}/tests/data/s2/{name}", repository_dir().display());
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{path}: {e}"));
    let mut out = S2Reference {
        scalars: Default::default(),
        sections: Default::default(),
    };
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    while let Some(line) = lines.next() {
        let words: Vec<&str> = line.split_whitespace().collect();
        match words.as_slice() {
            ["section", name, count] => {
                let count: usize = count.parse().unwrap();
                let rows = (0..count)
                    .map(|_| {
                        lines
                            .next()
                            .unwrap()
                            .split_whitespace()
                            .map(|w| w.parse::<f64>().unwrap())
                            .collect()
                    })
                    .collect();
                out.sections.insert(name.to_string(), rows);
            }
            [key, value] => {
                out.scalars.insert(key.to_string(), value.parse().unwrap());
            }
            _ => {}
        }
    }
    out
}

// ---------------------------------------------------------------------------------------------
// Partial-plan shapes.
// ---------------------------------------------------------------------------------------------

/// Makes the coefficients of `shape` those of a real signal:
/// `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`, and `fhat(l,0,0)` real.
pub fn make_hermitian(shape: &so3fft::Shape, c: &mut [Complex64]) {
    let (a, n) = (
        shape.order_limit_alpha as isize,
        shape.order_limit_gamma as isize,
    );
    for l in 0..shape.degree_limit {
        for m in -a..=a {
            for mp in -n..=n {
                let (Some(i), Some(j)) = (shape.coef_index(l, m, mp), shape.coef_index(l, -m, -mp))
                else {
                    continue;
                };
                if i < j {
                    let sg = if (m - mp).rem_euclid(2) == 0 {
                        1.0
                    } else {
                        -1.0
                    };
                    c[j] = c[i].conj() * sg;
                } else if i == j {
                    c[i].im = 0.0;
                }
            }
        }
    }
}

/// A uniform value in `[-0.5, 0.5)` from a 64-bit linear congruential state.
pub fn rnd(state: &mut u64) -> f64 {
    *state = state
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    (*state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
}

/// Samples (`j k re im`) and coefficients (`index l m re im`) of an S^2 reference file at
/// bandwidth `b`, the samples ring-major (`2B x 2B`), the coefficients in `seanindex`
/// order (the index each row names, checked against `l` and `m` by the callers).
pub fn s2_samples_and_coefs(name: &str, b: usize) -> (Vec<Complex64>, Vec<Complex64>) {
    let r = read_s2_reference(name);
    let n = 2 * b;
    let mut samples = vec![Complex64::default(); n * n];
    for row in &r["samples"] {
        samples[row[0] as usize * n + row[1] as usize] = Complex64::new(row[2], row[3]);
    }
    let mut coefs = vec![Complex64::default(); b * b];
    for row in &r["coefs"] {
        coefs[row[0] as usize] = Complex64::new(row[3], row[4]);
    }
    (samples, coefs)
}

// ---------------------------------------------------------------------------------------------
// Single precision: values rounded to f32 and back, and the relative L2 error.
// ---------------------------------------------------------------------------------------------
/// `v` rounded to single precision.
pub fn narrow(v: &[Complex64]) -> Vec<Complex32> {
    v.iter()
        .map(|z| Complex32::new(z.re as f32, z.im as f32))
        .collect()
}

/// `v` in double precision (exact).
pub fn widen(v: &[Complex32]) -> Vec<Complex64> {
    v.iter()
        .map(|z| Complex64::new(z.re as f64, z.im as f64))
        .collect()
}

/// `||a - b|| / ||b||`.
pub fn relative_l2(a: &[Complex64], b: &[Complex64]) -> f64 {
    assert_eq!(a.len(), b.len());
    let num: f64 = a.iter().zip(b).map(|(x, y)| (x - y).norm_sqr()).sum();
    let den: f64 = b.iter().map(|y| y.norm_sqr()).sum();
    (num / den).sqrt()
}
