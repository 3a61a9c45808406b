//! Peaks of a correlation on the SO(3) grid.

use crate::grid::{alpha, beta, gamma};
use num_complex::Complex64;

/// A grid point of a correlation: its flat index, Euler angles (z-y-z) and value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Peak {
    /// Flat index `k_beta (2B)^2 + j_alpha 2B + j_gamma`.
    pub index: usize,
    /// `alpha = pi j_alpha / B`.
    pub alpha: f64,
    /// `beta = pi (2 k_beta + 1) / (4B)`.
    pub beta: f64,
    /// `gamma = pi j_gamma / B`.
    pub gamma: f64,
    /// `|C|^2` there.
    pub value: f64,
}

impl Peak {
    /// The peak's rotation.
    pub fn rotation(&self) -> super::Rotation {
        super::Rotation::new(self.alpha, self.beta, self.gamma)
    }

    /// The grid point `index` of bandwidth `b` with value `value`.
    pub fn at(b: usize, index: usize, value: f64) -> Peak {
        let n = 2 * b;
        let (k, j, i) = (index / (n * n), index / n % n, index % n);
        Peak {
            index,
            alpha: alpha(b, j),
            beta: beta(b, k),
            gamma: gamma(b, i),
            value,
        }
    }
}

/// The largest `|C|^2` of the grid `values` (bandwidth `b`), scanned in flat order from 0
/// and replaced only by a strictly larger value: ties go to the lowest index, an all-zero
/// grid gives index 0 (SOFT's `softFFTWCor2` rule). NaN values are never taken.
pub fn grid_argmax(b: usize, values: &[Complex64]) -> Peak {
    argmax_by(b, values.iter().map(|z| z.norm_sqr()))
}

/// [`grid_argmax`] of a real grid (`|C|^2 = C^2`).
pub fn grid_argmax_real(b: usize, values: &[f64]) -> Peak {
    argmax_by(b, values.iter().map(|x| x * x))
}

fn argmax_by(b: usize, values: impl Iterator<Item = f64>) -> Peak {
    let (mut best, mut at) = (0.0, 0);
    for (i, v) in values.enumerate() {
        if v > best {
            (best, at) = (v, i);
        }
    }
    Peak::at(b, at, best)
}

/// Up to `k` peaks of `|C|^2` on the grid `values` (bandwidth `b`), largest first: grid
/// points at least as large as their 26 neighbours (`alpha`, `gamma` periodic), each at
/// least `min_angle` radians (geodesic) from every larger peak taken.
pub fn top_peaks(b: usize, values: &[Complex64], k: usize, min_angle: f64) -> Vec<Peak> {
    let n = 2 * b;
    assert_eq!(values.len(), n * n * n);
    let v = |kb: usize, ja: usize, jg: usize| values[(kb * n + ja) * n + jg].norm_sqr();
    let mut maxima = Vec::new();
    for kb in 0..n {
        for ja in 0..n {
            for jg in 0..n {
                let x = v(kb, ja, jg);
                if x.is_nan() || x <= 0.0 {
                    continue;
                }
                let mut local = true;
                'around: for db in -1isize..=1 {
                    let kk = kb as isize + db;
                    if kk < 0 || kk >= n as isize {
                        continue;
                    }
                    for da in [n - 1, 0, 1] {
                        for dg in [n - 1, 0, 1] {
                            if db == 0 && da == 0 && dg == 0 {
                                continue;
                            }
                            if v(kk as usize, (ja + da) % n, (jg + dg) % n) > x {
                                local = false;
                                break 'around;
                            }
                        }
                    }
                }
                if local {
                    maxima.push(Peak::at(b, (kb * n + ja) * n + jg, x));
                }
            }
        }
    }
    maxima.sort_by(|a, c| c.value.total_cmp(&a.value).then(a.index.cmp(&c.index)));
    let mut taken: Vec<Peak> = Vec::new();
    for p in maxima {
        if taken.len() == k {
            break;
        }
        if taken
            .iter()
            .all(|t| t.rotation().angle_to(&p.rotation()) >= min_angle)
        {
            taken.push(p);
        }
    }
    taken
}
