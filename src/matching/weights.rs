//! Per-degree weights of a correlation, and their estimate from noisy inputs: the power
//! spectra of signal and pattern, a white-noise floor fitted at the high degrees, and the
//! weights that minimise the variance of the peak's position (`docs/matching-noise.md`).

use crate::error::{Error, Result};
use crate::s2::order_start;
use crate::Real;
use num_complex::Complex;

/// How a correlation weights its degrees: `C(g) = sum_l w_l <f_l, (g h)_l>`, with `f_l`, `h_l`
/// the degree-`l` parts of signal and pattern.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum DegreeWeights {
    /// `w_l = 1`: the plain correlation.
    #[default]
    Uniform,
    /// The caller's weights `w_0..=w_deg_lim` (finite, `>= 0`, not all zero): a band-pass,
    /// a resolution filter, a degree limit below the plan's.
    Given(Vec<f64>),
    /// Weights estimated from the two inputs at each call ([`Spectra::estimate`]): the
    /// degrees the noise dominates are turned down.
    Automatic,
}

impl DegreeWeights {
    /// An error unless the weights suit a plan combining degrees `0..=deg_lim` (with
    /// `normalized`, degree 0 does not count).
    pub(crate) fn check(&self, deg_lim: usize, normalized: bool) -> Result<()> {
        let DegreeWeights::Given(w) = self else {
            return Ok(());
        };
        if w.len() != deg_lim + 1 {
            return Err(Error::InvalidArgument(format!(
                "{} degree weights for degrees 0..={deg_lim}: need {}",
                w.len(),
                deg_lim + 1
            )));
        }
        if let Some((l, x)) = w
            .iter()
            .enumerate()
            .find(|(_, x)| !(x.is_finite() && **x >= 0.0))
        {
            return Err(Error::InvalidArgument(format!(
                "degree weight w_{l} = {x}: weights must be finite and >= 0"
            )));
        }
        let from = usize::from(normalized);
        if w[from.min(deg_lim)..].iter().all(|&x| x == 0.0) || (normalized && deg_lim == 0) {
            return Err(Error::InvalidArgument(format!(
                "every degree weight{} is 0: the correlation would be 0 everywhere",
                if normalized { " from degree 1 on" } else { "" }
            )));
        }
        Ok(())
    }
}

/// What the inputs of one correlation tell about signal and noise, and the weights used.
#[derive(Clone, Debug, PartialEq)]
pub struct Spectra {
    /// `P_f(l) = sum_m |fhat(l,m)|^2` of the signal, degrees `0..b_in` (the orthonormal
    /// harmonics: `sum_l P_f(l)` is the squared norm `int |f|^2`).
    pub signal_power: Vec<f64>,
    /// `P_h(l)` of the pattern.
    pub pattern_power: Vec<f64>,
    /// The signal's noise power per coefficient, fitted at the high degrees
    /// ([`noise_floor`]); 0 for exactly band-limited data.
    pub signal_noise: f64,
    /// The pattern's noise power per coefficient.
    pub pattern_noise: f64,
    /// The weights `w_0..=w_deg_lim` the correlation applies to these inputs.
    pub weights: Vec<f64>,
}

impl Spectra {
    /// The spectra of S^2 coefficients `sig` and `pat` (bandwidth `b`), and the weights of
    /// `mode` for degrees `0..=deg_lim`: for [`DegreeWeights::Automatic`],
    /// `w_l = sqrt(s_f s_h) / (s_f n_h + s_h n_f + n_f n_h)` scaled to a largest weight of 1,
    /// with `n` the noise floors and `s` the signal powers per coefficient net of the noise
    /// (three-degree means, 0 where they do not stand out of it: [`noise_weights`]). That
    /// `w_l` minimises the variance of the peak's position when the
    /// noise is white and independent in the two inputs (`docs/matching-noise.md`); with
    /// noise-free inputs it is uniform.
    pub fn estimate<C: Real>(
        (sig, pat): (&[Complex<C>], &[Complex<C>]),
        b: usize,
        deg_lim: usize,
        mode: &DegreeWeights,
    ) -> Spectra {
        let signal_power = degree_powers(sig, b);
        let pattern_power = degree_powers(pat, b);
        let signal_noise = noise_floor(&per_coefficient(&signal_power));
        let pattern_noise = noise_floor(&per_coefficient(&pattern_power));
        let weights = match mode {
            DegreeWeights::Uniform => vec![1.0; deg_lim + 1],
            DegreeWeights::Given(w) => w.clone(),
            DegreeWeights::Automatic => noise_weights(
                (&signal_power[..=deg_lim], &pattern_power[..=deg_lim]),
                (signal_noise, pattern_noise),
            ),
        };
        Spectra {
            signal_power,
            pattern_power,
            signal_noise,
            pattern_noise,
            weights,
        }
    }

    /// The signal power per coefficient at degree `l` net of the noise floor.
    pub(crate) fn signal_net(&self, l: usize) -> f64 {
        (self.signal_power[l] / (2 * l + 1) as f64 - self.signal_noise).max(0.0)
    }

    /// The pattern's power per coefficient at degree `l` net of its noise floor.
    pub(crate) fn pattern_net(&self, l: usize) -> f64 {
        (self.pattern_power[l] / (2 * l + 1) as f64 - self.pattern_noise).max(0.0)
    }
}

/// `P(l) = sum_m |c(l,m)|^2` for degrees `0..b` of S^2 coefficients `c` (bandwidth `b`,
/// `seanindex` order), summed in `f64`.
pub fn degree_powers<C: Real>(c: &[Complex<C>], b: usize) -> Vec<f64> {
    assert_eq!(c.len(), b * b, "S^2 coefficients of bandwidth {b}");
    let mut p = vec![0.0; b];
    for m in -(b as isize - 1)..b as isize {
        let first = m.unsigned_abs();
        let row = &c[order_start(b, m)..][..b - first];
        for (l, z) in (first..b).zip(row) {
            p[l] += z.re.to_f64().powi(2) + z.im.to_f64().powi(2);
        }
    }
    p
}

/// `P(l) / (2l + 1)`: the mean power of a degree's coefficients.
fn per_coefficient(p: &[f64]) -> Vec<f64> {
    p.iter()
        .enumerate()
        .map(|(l, x)| x / (2 * l + 1) as f64)
        .collect()
}

/// The white-noise floor of mean powers per coefficient `p` (degrees `0..p.len()`): the
/// median over the top quarter of the degrees (at least 4 of them, at most all but
/// degree 0). White noise at the sample points has the same expected power per
/// coefficient at every degree; a signal smooth enough for its spectrum to have decayed
/// in the top quarter adds nothing there. A signal with power up to the last degree
/// (sharp edges, aliasing) raises the floor and the weights then turn those degrees
/// down too.
pub fn noise_floor(p: &[f64]) -> f64 {
    let b = p.len();
    if b < 2 {
        return 0.0;
    }
    let count = (b / 4).max(4).min(b - 1);
    let mut top: Vec<f64> = p[b - count..].to_vec();
    top.sort_by(f64::total_cmp);
    let mid = top.len() / 2;
    if top.len() % 2 == 1 {
        top[mid]
    } else {
        0.5 * (top[mid - 1] + top[mid])
    }
}

/// Standard deviations of its noise by which a degree's estimated signal power must
/// stand out to count.
const SIGNIFICANCE: f64 = 3.0;

/// Signal powers per coefficient net of the noise floor `n`, from the degree powers `p`:
/// the mean over degrees `l-1..=l+1` (signal spectra are smooth in `l`, the noise is not),
/// 0 where that mean does not stand out of the noise by [`SIGNIFICANCE`] standard
/// deviations (pure noise would otherwise get weight at every high degree, where its
/// products grow as `l^3`).
fn net_signal(p: &[f64], n: f64) -> Vec<f64> {
    let raw: Vec<f64> = p
        .iter()
        .enumerate()
        .map(|(l, x)| x / (2 * l + 1) as f64 - n)
        .collect();
    (0..raw.len())
        .map(|l| {
            let window = l.saturating_sub(1)..(l + 2).min(raw.len());
            let count = window.len() as f64;
            // The mean noise power of `2l+1` coefficients has standard deviation
            // `n sqrt(2/(2l+1))`; the window's mean, about `1/sqrt(count)` of that.
            let var: f64 = window
                .clone()
                .map(|j| 2.0 / (2 * j + 1) as f64)
                .sum::<f64>();
            let sd = n * var.sqrt() / count;
            let mean = window.map(|j| raw[j]).sum::<f64>() / count;
            if mean > SIGNIFICANCE * sd {
                mean
            } else {
                0.0
            }
        })
        .collect()
}

/// The noise-optimal weights of degrees `0..pf.len()` from the signal's and the pattern's
/// degree powers `pf`, `ph` and noise floors `nf`, `nh` (see [`Spectra::estimate`]),
/// largest 1; uniform where both floors are 0, and where no degree carries signal.
pub fn noise_weights((pf, ph): (&[f64], &[f64]), (nf, nh): (f64, f64)) -> Vec<f64> {
    // Floors of exactly 0 (band-limited data): a relative floor keeps the formula's limit
    // (uniform weights for a scaled, rotated copy) without dividing by 0.
    let top = pf.iter().chain(ph).fold(0.0f64, |m, &x| m.max(x));
    let tiny = 1e-300f64.max(1e-30 * top);
    let (nf, nh) = (nf.max(tiny), nh.max(tiny));
    let (sf, sh) = (net_signal(pf, nf), net_signal(ph, nh));
    let raw: Vec<f64> = (0..pf.len())
        .map(|l| (sf[l] * sh[l]).sqrt() / (sf[l] * nh + sh[l] * nf + nf * nh))
        .collect();
    let max = raw.iter().fold(0.0f64, |m, &x| m.max(x));
    if !(max > 0.0 && max.is_finite()) {
        return vec![1.0; pf.len()];
    }
    raw.iter().map(|x| x / max).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The floor of a flat spectrum is its level; a decaying signal below the top quarter
    /// does not move it.
    #[test]
    fn floor_of_known_spectra() {
        let b = 64;
        let flat = vec![2.5e-3; b];
        assert_eq!(noise_floor(&flat), 2.5e-3);
        let decaying: Vec<f64> = (0..b)
            .map(|l| (-((l * l) as f64) / 40.0).exp() + 1e-4)
            .collect();
        let n = noise_floor(&decaying);
        assert!((n - 1e-4).abs() < 1e-12 * 1e-4 + 1e-16, "{n}");
    }

    /// With known signal and noise powers the weights follow the formula where the signal
    /// stands out of the noise (to the bias of the three-degree mean, 2% for a spectrum
    /// falling by e^(1/3) per degree), are 0 where it does not, and are uniform for
    /// noise-free copies.
    #[test]
    fn weights_of_known_spectra() {
        let b = 48;
        let s = |l: usize| (-(l as f64) / 3.0).exp();
        let n = 1e-4;
        let p: Vec<f64> = (0..b).map(|l| (s(l) + n) * (2 * l + 1) as f64).collect();
        let w = noise_weights((&p, &p), (n, n));
        let formula = |x: f64| x / (2.0 * x * n + n * n);
        let mean3 = |l: usize| (s(l - 1) + s(l) + s(l + 1)) / 3.0;
        let w0 = formula((s(0) + s(1)) / 2.0);
        for (l, &got) in w.iter().enumerate().take(b - 1).skip(1) {
            let sd = n * (2.0 / (2 * l + 1) as f64).sqrt() / 3f64.sqrt();
            if mean3(l) > 5.0 * sd {
                let want = formula(mean3(l)) / w0;
                assert!((got - want).abs() < 0.02 * want, "l {l}: {got} vs {want}");
            } else if mean3(l) < sd {
                assert_eq!(got, 0.0, "l {l}");
            }
        }
        // Noise-free: uniform (a scaled copy too).
        let clean: Vec<f64> = (0..b).map(|l| s(l) * (2 * l + 1) as f64).collect();
        let scaled: Vec<f64> = clean.iter().map(|x| 9.0 * x).collect();
        let w = noise_weights((&clean, &scaled), (0.0, 0.0));
        assert!(w.iter().all(|&x| (x - 1.0).abs() < 1e-12), "{w:?}");
        // No signal at all: uniform rather than 0/0.
        assert!(noise_weights((&[0.0; 4], &[0.0; 4]), (0.0, 0.0)) == vec![1.0; 4]);
    }

    #[test]
    fn bad_weights_are_refused() {
        let given = |w: Vec<f64>| DegreeWeights::Given(w).check(3, false);
        assert!(given(vec![1.0; 4]).is_ok());
        assert!(given(vec![1.0; 3]).is_err());
        assert!(given(vec![1.0, -0.5, 1.0, 1.0]).is_err());
        assert!(given(vec![1.0, f64::NAN, 1.0, 1.0]).is_err());
        assert!(given(vec![0.0; 4]).is_err());
        assert!(DegreeWeights::Given(vec![1.0, 0.0, 0.0, 0.0])
            .check(3, true)
            .is_err());
        let msg = given(vec![1.0, f64::INFINITY, 1.0, 1.0])
            .unwrap_err()
            .to_string();
        assert!(msg.contains("w_1"), "{msg}");
    }
}
