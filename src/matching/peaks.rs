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
