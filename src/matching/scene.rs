//! Synthetic scenes for testing a matching pipeline against a known answer: a smooth
//! function on the sphere that is not band-limited, the same function rotated analytically
//! (not through its coefficients), both sampled on the S^2 grid, with white noise added.

use super::rotation::Rotation;

/// A pattern, a rotated copy of it (the signal) and the rotation, as real samples on the
/// S^2 grid of bandwidth `b` (`(2b)^2` values each, `docs/conventions-s2.md`).
#[derive(Clone, Debug)]
pub struct Scene {
    /// `h` sampled, plus noise.
    pub pattern: Vec<f64>,
    /// `f(x) = h(g^-1 x)` sampled, plus noise of its own.
    pub signal: Vec<f64>,
    /// The rotation `g`, uniformly distributed on SO(3): the correlation's true peak.
    pub rotation: Rotation,
}

/// A seeded generator (SplitMix64) of uniform and normal numbers.
struct Random(u64);

impl Random {
    fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    fn uniform(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }

    /// Standard normal (Box-Muller).
    fn normal(&mut self) -> f64 {
        let u = 1.0 - self.uniform();
        let v = self.uniform();
        (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos()
    }

    /// A uniformly distributed unit vector.
    fn direction(&mut self) -> [f64; 3] {
        loop {
            let v = [self.normal(), self.normal(), self.normal()];
            let n = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
            if n > 1e-12 {
                return v.map(|x| x / n);
            }
        }
    }
}

/// A scene of bandwidth `b` from `seed`: the pattern is a sum of seven von Mises-Fisher
/// bumps `a exp(kappa (mu . x - 1))` (directions `mu` uniform, concentrations `kappa` in
/// `[4, 40]`, amplitudes in `[0.5, 1.5]`), the rotation uniform, and each input gets white
/// Gaussian noise of standard deviation `noise` times the rms of its clean samples.
pub fn vmf_scene(b: usize, seed: u64, noise: f64) -> Scene {
    let mut rng = Random(seed ^ 0x5EED_0F5C_E4E5_0000);
    let bumps: Vec<([f64; 3], f64, f64)> = (0..7)
        .map(|_| {
            let mu = rng.direction();
            let kappa = 4.0 + 36.0 * rng.uniform();
            let a = 0.5 + rng.uniform();
            (mu, kappa, a)
        })
        .collect();
    let q = {
        let v = [rng.normal(), rng.normal(), rng.normal(), rng.normal()];
        let n = v.iter().map(|x| x * x).sum::<f64>().sqrt();
        v.map(|x| x / n)
    };
    let rotation = Rotation::from_quaternion(q);
    let m = rotation.matrix();
    let turned: Vec<([f64; 3], f64, f64)> = bumps
        .iter()
        .map(|&(mu, k, a)| {
            let r = std::array::from_fn(|i| (0..3).map(|j| m[i][j] * mu[j]).sum());
            (r, k, a)
        })
        .collect();
    let n = 2 * b;
    let sample = |bumps: &[([f64; 3], f64, f64)]| -> Vec<f64> {
        let mut out = Vec::with_capacity(n * n);
        for j in 0..n {
            let theta = std::f64::consts::PI * (2 * j + 1) as f64 / (4 * b) as f64;
            for k in 0..n {
                let phi = std::f64::consts::PI * k as f64 / b as f64;
                let x = [
                    theta.sin() * phi.cos(),
                    theta.sin() * phi.sin(),
                    theta.cos(),
                ];
                let dot = |mu: &[f64; 3]| mu[0] * x[0] + mu[1] * x[1] + mu[2] * x[2];
                out.push(
                    bumps
                        .iter()
                        .map(|(mu, kappa, a)| a * (kappa * (dot(mu) - 1.0)).exp())
                        .sum(),
                );
            }
        }
        out
    };
    let mut pattern = sample(&bumps);
    let mut signal = sample(&turned);
    for v in [&mut pattern, &mut signal] {
        let rms = (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
        for x in v.iter_mut() {
            *x += noise * rms * rng.normal();
        }
    }
    Scene {
        pattern,
        signal,
        rotation,
    }
}
