//! [`Shape`]: which coefficients and which samples a partial plan has, their layouts and
//! the conditions a shape must meet.

use crate::error::{Error, Result};
use crate::grid::MAX_BANDWIDTH;
use std::f64::consts::PI;

/// Largest alpha or gamma sample count of a partial plan.
pub const MAX_GRID_SIDE: usize = 1 << 14;

/// The coefficients and the sample grid of a partial plan (see `docs/partial-plans.md`).
///
/// Coefficients: degrees `degree_min <= l < degree_limit`, orders `|M| <= order_limit_alpha`
/// (paired with alpha) and `|M'| <= order_limit_gamma` (paired with gamma), stored in the
/// block order of SOFT's `so3CoefLoc` with the absent blocks and degrees left out
/// ([`Shape::coef_index`]).
///
/// Samples: `2 grid_bandwidth` betas `pi (2k+1) / (4 grid_bandwidth)`, `n_alpha` alphas
/// `2 pi j / n_alpha`, `n_gamma` gammas `2 pi j / n_gamma`, at index
/// `(k n_alpha + j_alpha) n_gamma + j_gamma` (beta slowest, gamma fastest).
///
/// [`Shape::new`]`(L)` is the full transform of bandwidth `L` on SOFT's grid, whose layouts
/// are those of [`Plan`](crate::Plan).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Shape {
    /// `L`: degrees `l < L` (`1 ..= MAX_BANDWIDTH`).
    pub degree_limit: usize,
    /// `L0`: degrees `l >= L0` (`L0 < L`; default 0).
    pub degree_min: usize,
    /// `Mmax`: orders `|M| <= Mmax` (`< L`; default `L - 1`).
    pub order_limit_alpha: usize,
    /// `N`: orders `|M'| <= N` (`< L`; default `L - 1`).
    pub order_limit_gamma: usize,
    /// `B_grid`: the beta grid has `2 B_grid` points (default `L`; the forward needs
    /// `B_grid >= L`).
    pub grid_bandwidth: usize,
    /// Alpha samples (default `2 B_grid`; at least `2 Mmax + 1`).
    pub n_alpha: usize,
    /// Gamma samples (default `2 B_grid`; at least `2 N + 1`).
    pub n_gamma: usize,
}

impl Shape {
    /// The full transform of bandwidth `l` on SOFT's grid (`2L x 2L x 2L`).
    pub fn new(l: usize) -> Shape {
        Shape {
            degree_limit: l,
            degree_min: 0,
            order_limit_alpha: l.saturating_sub(1),
            order_limit_gamma: l.saturating_sub(1),
            grid_bandwidth: l,
            n_alpha: 2 * l,
            n_gamma: 2 * l,
        }
    }

    /// This shape with orders `|M| <= m_max`, `|M'| <= mp_max` and the smallest grid of
    /// `2 B_grid` betas that samples them, `(2 m_max + 1) x (2 mp_max + 1)` in alpha and gamma.
    pub fn with_orders(self, m_max: usize, mp_max: usize) -> Shape {
        Shape {
            order_limit_alpha: m_max,
            order_limit_gamma: mp_max,
            n_alpha: 2 * m_max + 1,
            n_gamma: 2 * mp_max + 1,
            ..self
        }
    }

    /// This shape on the grid of `2 b_grid` betas and `n_alpha x n_gamma` alphas and gammas.
    pub fn with_grid(self, b_grid: usize, n_alpha: usize, n_gamma: usize) -> Shape {
        Shape {
            grid_bandwidth: b_grid,
            n_alpha,
            n_gamma,
            ..self
        }
    }

    /// This shape with degrees `l >= l0` only.
    pub fn with_degree_min(self, l0: usize) -> Shape {
        Shape {
            degree_min: l0,
            ..self
        }
    }

    /// Whether this is [`Shape::new`] of its degree limit (the full plan's layouts).
    pub fn is_full(&self) -> bool {
        *self == Shape::new(self.degree_limit)
    }

    /// `Ok` if both directions can run on this shape, else the violated condition.
    /// (The forward also needs `B_grid >= L`: [`Shape::check_forward`].)
    pub fn validate(&self) -> Result<()> {
        let s = self;
        let l = s.degree_limit;
        let bad = |msg: String| Err(Error::InvalidArgument(format!("shape: {msg}")));
        if l == 0 || l > MAX_BANDWIDTH {
            return bad(format!("degree limit L = {l} outside 1..={MAX_BANDWIDTH}"));
        }
        if s.degree_min >= l {
            return bad(format!(
                "lowest degree L0 = {} not below the degree limit L = {l}",
                s.degree_min
            ));
        }
        if s.order_limit_alpha >= l || s.order_limit_gamma >= l {
            return bad(format!(
                "order limits Mmax = {}, N = {} must be below L = {l}",
                s.order_limit_alpha, s.order_limit_gamma
            ));
        }
        if s.grid_bandwidth == 0 || s.grid_bandwidth > 4 * MAX_BANDWIDTH {
            return bad(format!(
                "grid bandwidth B_grid = {} outside 1..={}",
                s.grid_bandwidth,
                4 * MAX_BANDWIDTH
            ));
        }
        if s.n_alpha < 2 * s.order_limit_alpha + 1 {
            return bad(format!(
                "n_alpha = {} < 2 Mmax + 1 = {} (orders |M| <= {} need that many alphas)",
                s.n_alpha,
                2 * s.order_limit_alpha + 1,
                s.order_limit_alpha
            ));
        }
        if s.n_gamma < 2 * s.order_limit_gamma + 1 {
            return bad(format!(
                "n_gamma = {} < 2 N + 1 = {} (orders |M'| <= {} need that many gammas)",
                s.n_gamma,
                2 * s.order_limit_gamma + 1,
                s.order_limit_gamma
            ));
        }
        if s.n_alpha > MAX_GRID_SIDE || s.n_gamma > MAX_GRID_SIDE {
            return bad(format!(
                "n_alpha = {}, n_gamma = {}: at most {MAX_GRID_SIDE} each",
                s.n_alpha, s.n_gamma
            ));
        }
        let slice = s.n_alpha as u128 * s.n_gamma as u128;
        if slice * 2 * s.grid_bandwidth as u128 * 16 > isize::MAX as u128 {
            return bad("the sample array would not fit in memory".into());
        }
        Ok(())
    }

    /// `Ok` if the forward transform is exact on this shape: [`Shape::validate`] and
    /// `B_grid >= L` (the quadrature weights of `B_grid` integrate degrees below `2 B_grid`).
    pub fn check_forward(&self) -> Result<()> {
        self.validate()?;
        if self.grid_bandwidth < self.degree_limit {
            return Err(Error::InvalidArgument(format!(
                "shape: the forward needs B_grid >= L (B_grid = {}, L = {})",
                self.grid_bandwidth, self.degree_limit
            )));
        }
        Ok(())
    }

    /// Number of beta samples, `2 B_grid`.
    pub fn n_beta(&self) -> usize {
        2 * self.grid_bandwidth
    }

    /// Number of samples, `2 B_grid n_alpha n_gamma`.
    pub fn num_samples(&self) -> usize {
        self.n_beta() * self.slice_len()
    }

    /// Samples of one beta slice, `n_alpha n_gamma`.
    pub fn slice_len(&self) -> usize {
        self.n_alpha * self.n_gamma
    }

    /// Flat index of the sample `(alpha_j_alpha, beta_k, gamma_j_gamma)`.
    pub fn sample_index(&self, j_alpha: usize, k_beta: usize, j_gamma: usize) -> usize {
        (k_beta * self.n_alpha + j_alpha) * self.n_gamma + j_gamma
    }

    /// `alpha_j = 2 pi j / n_alpha`.
    pub fn alpha(&self, j: usize) -> f64 {
        2.0 * PI * j as f64 / self.n_alpha as f64
    }

    /// `beta_k = pi (2k+1) / (4 B_grid)`.
    pub fn beta(&self, k: usize) -> f64 {
        crate::grid::beta(self.grid_bandwidth, k)
    }

    /// `gamma_j = 2 pi j / n_gamma`.
    pub fn gamma(&self, j: usize) -> f64 {
        2.0 * PI * j as f64 / self.n_gamma as f64
    }

    /// Degrees stored for the order pair `(m, mp)`: `max(|m|, |mp|, L0) .. L`.
    fn degrees(&self, m: isize, mp: isize) -> std::ops::Range<usize> {
        let lo = m.unsigned_abs().max(mp.unsigned_abs()).max(self.degree_min);
        lo..self.degree_limit
    }

    /// Number of coefficients (0 for a shape that does not validate).
    pub fn num_coeffs(&self) -> usize {
        if self.validate().is_err() {
            return 0;
        }
        CoefLayout::new(self).total
    }

    /// Index of `fhat(l, m, mp)` in the coefficient array, `None` if the shape does not
    /// hold it (or does not validate). Blocks `(M, M')` in row-major order, each order
    /// running `0, 1, .., limit, -limit, .., -1`; block `(M, M')` holds the degrees
    /// `max(|M|, |M'|, L0) ..= L - 1`.
    pub fn coef_index(&self, l: usize, m: isize, mp: isize) -> Option<usize> {
        if self.validate().is_err()
            || m.unsigned_abs() > self.order_limit_alpha
            || mp.unsigned_abs() > self.order_limit_gamma
            || !self.degrees(m, mp).contains(&l)
        {
            return None;
        }
        let layout = CoefLayout::new(self);
        Some(layout.block_start(m, mp) + l - self.degrees(m, mp).start)
    }
}

/// Where each block of a shape's coefficients starts.
pub(crate) struct CoefLayout {
    mmax: usize,
    n: usize,
    /// Start of block `(M, M')` at `[row(M) (2N+1) + col(M')]`, `row(M) = M mod (2Mmax+1)`.
    starts: Vec<usize>,
    /// Number of coefficients.
    pub total: usize,
    /// The shape's degree bounds.
    pub l0: usize,
    pub l: usize,
}

impl CoefLayout {
    /// The layout of a valid shape.
    pub fn new(s: &Shape) -> CoefLayout {
        let (mmax, n) = (s.order_limit_alpha, s.order_limit_gamma);
        let (rows, cols) = (2 * mmax + 1, 2 * n + 1);
        let order = |i: usize, lim: usize| -> isize {
            if i <= lim {
                i as isize
            } else {
                i as isize - (2 * lim + 1) as isize
            }
        };
        let mut starts = vec![0; rows * cols];
        let mut at = 0;
        for (i, row) in starts.chunks_exact_mut(cols).enumerate() {
            for (j, st) in row.iter_mut().enumerate() {
                *st = at;
                at += s.degrees(order(i, mmax), order(j, n)).len();
            }
        }
        CoefLayout {
            mmax,
            n,
            starts,
            total: at,
            l0: s.degree_min,
            l: s.degree_limit,
        }
    }

    /// Start of block `(m, mp)` (`|m| <= Mmax`, `|mp| <= N`): the coefficient of degree
    /// [`CoefLayout::first_degree`].
    pub fn block_start(&self, m: isize, mp: isize) -> usize {
        let r = m.rem_euclid(2 * self.mmax as isize + 1) as usize;
        let c = mp.rem_euclid(2 * self.n as isize + 1) as usize;
        self.starts[r * (2 * self.n + 1) + c]
    }

    /// Lowest degree stored in block `(m, mp)`.
    pub fn first_degree(&self, m: isize, mp: isize) -> usize {
        m.unsigned_abs().max(mp.unsigned_abs()).max(self.l0)
    }

    /// Whether the shape holds the order pair `(m, mp)`.
    pub fn holds(&self, m: isize, mp: isize) -> bool {
        m.unsigned_abs() <= self.mmax && mp.unsigned_abs() <= self.n
    }
}
