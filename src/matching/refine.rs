//! Peaks refined off the grid: the band-limited correlation evaluated at any rotation from
//! its SO(3) coefficients, and maximised by damped Newton steps.

use super::rotation::Rotation;
use crate::grid::block_start;
use crate::numeric::{sin_cos_dd, Dd, Ext};
use crate::simd::Isa;
use crate::symmetry::Cluster;
use crate::wigner::column::column_with;
use crate::wigner::{start_norms, BetaTables, RecCoeffs, RecTables};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;

/// A band-limited function on SO(3) given by its coefficients (bandwidth `b`, degrees up to
/// `lmax`), in the normalisation of the inverse transform (`docs/conventions.md`):
/// `C(g) = sum fhat(l,M,M') (1/2pi) sqrt((2l+1)/2) D^l_{M,M'}(g)`.
pub struct So3Series<'a> {
    b: usize,
    lmax: usize,
    coeffs: &'a [Complex64],
    recurrence: RecTables,
    /// Norms of the starting values per base pair `(m, m')`, index `m(m+1)/2 + m'`.
    norms: Vec<Ext>,
    isa: Isa,
}

/// Value and derivatives in `alpha` and `gamma` at one rotation.
#[derive(Clone, Copy, Default)]
struct Local {
    c: Complex64,
    a: Complex64,
    g: Complex64,
    aa: Complex64,
    ag: Complex64,
    gg: Complex64,
}

impl<'a> So3Series<'a> {
    /// The series of `coeffs` (`(4b^3 - b)/3` values, `so3CoefLoc` order), degrees `<= lmax`.
    pub fn new(b: usize, lmax: usize, coeffs: &'a [Complex64]) -> So3Series<'a> {
        assert!(lmax < b && coeffs.len() == crate::num_coeffs(b));
        So3Series {
            b,
            lmax,
            coeffs,
            recurrence: RecTables::new(lmax + 1),
            norms: start_norms(lmax + 1),
            isa: Isa::detect(),
        }
    }

    /// `S[M][M'](beta) = sum_l fhat(l,M,M') (1/2pi) sqrt((2l+1)/2) d^l_{M,M'}(beta)`, row
    /// `M + lmax`, column `M' + lmax`.
    fn beta_sums(&self, beta: f64) -> Vec<Complex64> {
        let top = self.lmax as isize;
        let w = 2 * self.lmax + 1;
        let mut s = vec![Complex64::default(); w * w];
        // The half-angle cosine and sine of beta, and (swapped) of pi - beta, for the
        // members of a cluster that are reflected (see `symmetry`).
        let (sn, cs) = if (0.0..=PI).contains(&beta) {
            sin_cos_dd(Dd::new(beta / 2.0))
        } else {
            (Dd::new((beta / 2.0).sin()), Dd::new((beta / 2.0).cos()))
        };
        let betas = BetaTables::new(&[(cs, sn), (sn, cs)], 2 * self.lmax);
        // The members' sums of the clusters with base order `m`, as (index in `s`, value).
        let row = |m: usize| -> Vec<(usize, Complex64)> {
            let mut rec = RecCoeffs::new(self.lmax + 1);
            let mut out = Vec::with_capacity(8 * (m + 1));
            for mp in 0..=m {
                let cluster = Cluster::new(m, mp);
                rec.resize(self.lmax + 1 - m);
                self.recurrence.coeffs(m, mp, &mut rec);
                let norm = self.norms[m * (m + 1) / 2 + mp];
                let mut cols: [Option<Vec<f64>>; 2] = [None, None];
                for mem in cluster.members() {
                    let k = usize::from(mem.reversed);
                    let col = cols[k].get_or_insert_with(|| {
                        column_with(self.isa, &betas, k, (m, mp, norm), &rec)
                    });
                    // Degree l = m + i is at block_start + i.
                    let block = &self.coeffs[block_start(self.b, mem.m, mem.mp)..][..col.len()];
                    let (even, odd) = (mem.sign_at(m), mem.sign_at(m + 1));
                    let mut sum = Complex64::default();
                    for (i, (dt, c)) in col.iter().zip(block).enumerate() {
                        let sign = if i % 2 == 0 { even } else { odd };
                        sum += c * (sign * dt);
                    }
                    let at = (mem.m + top) as usize * w + (mem.mp + top) as usize;
                    out.push((at, sum / (2.0 * PI)));
                }
            }
            out
        };
        // On a worker pool (`Correlation::refine`), the base orders are spread over its
        // threads; elsewhere they run on the calling thread.
        let rows: Vec<Vec<(usize, Complex64)>> = if rayon::current_thread_index().is_some() {
            (0..=self.lmax).into_par_iter().map(row).collect()
        } else {
            (0..=self.lmax).map(row).collect()
        };
        for (at, v) in rows.into_iter().flatten() {
            s[at] = v;
        }
        s
    }

    /// Value and `alpha`, `gamma` derivatives from the beta sums `s`.
    fn local(&self, s: &[Complex64], alpha: f64, gamma: f64) -> Local {
        let top = self.lmax as isize;
        let w = 2 * self.lmax + 1;
        let mut out = Local::default();
        let phases = |angle: f64| -> Vec<Complex64> {
            (-top..=top)
                .map(|m| Complex64::from_polar(1.0, -(m as f64) * angle))
                .collect()
        };
        let (pa, pg) = (phases(alpha), phases(gamma));
        for m in -top..=top {
            let ea = pa[(m + top) as usize];
            for mp in -top..=top {
                let v =
                    s[(m + top) as usize * w + (mp + top) as usize] * ea * pg[(mp + top) as usize];
                let (fm, fmp) = (m as f64, mp as f64);
                let i = Complex64::new(0.0, 1.0);
                out.c += v;
                out.a += v * (-i * fm);
                out.g += v * (-i * fmp);
                out.aa += v * (-fm * fm);
                out.ag += v * (-fm * fmp);
                out.gg += v * (-fmp * fmp);
            }
        }
        out
    }

    /// The value at rotation `g`.
    pub fn value(&self, g: &Rotation) -> Complex64 {
        self.local(&self.beta_sums(g.beta), g.alpha, g.gamma).c
    }

    /// `|C|^2` at `g` and the beta sums there (for [`So3Series::derivatives`]).
    fn objective(&self, g: &Rotation) -> (f64, Vec<Complex64>) {
        let s = self.beta_sums(g.beta);
        (self.local(&s, g.alpha, g.gamma).c.norm_sqr(), s)
    }

    /// Gradient and Hessian of `|C|^2` in `(alpha, beta, gamma)` at `g`, given the beta
    /// sums `mid` there (the beta derivatives by central differences of step `h`).
    fn derivatives(&self, g: &Rotation, mid: &[Complex64], h: f64) -> ([f64; 3], [[f64; 3]; 3]) {
        let at = |beta: f64| self.local(&self.beta_sums(beta), g.alpha, g.gamma);
        let (lo, hi) = (at(g.beta - h), at(g.beta + h));
        let mid = self.local(mid, g.alpha, g.gamma);
        let c = mid.c;
        let d = [mid.a, (hi.c - lo.c) / (2.0 * h), mid.g];
        let dab = (hi.a - lo.a) / (2.0 * h);
        let dgb = (hi.g - lo.g) / (2.0 * h);
        let dbb = (hi.c - 2.0 * mid.c + lo.c) / (h * h);
        let dd = [
            [mid.aa, dab, mid.ag],
            [dab, dbb, dgb],
            [mid.ag, dgb, mid.gg],
        ];
        let grad = d.map(|di| 2.0 * (c.conj() * di).re);
        let mut hess = [[0.0; 3]; 3];
        for i in 0..3 {
            for j in 0..3 {
                hess[i][j] = 2.0 * (d[i].conj() * d[j] + c.conj() * dd[i][j]).re;
            }
        }
        (grad, hess)
    }

    /// The rotation near `start` where `|C|^2` is largest, by damped Newton steps
    /// (Levenberg-Marquardt), and `|C|^2` there. A trial step costs one evaluation of the
    /// beta sums, an accepted one two more (the beta derivatives).
    pub fn maximise(&self, start: &Rotation) -> (Rotation, f64) {
        // Step of the beta differences: small enough that their error (h^2 l_max / 6 in
        // the position of the maximum) is far below 1e-8 rad.
        let h = 1e-5;
        let mut g = *start;
        let (mut f, mid) = self.objective(&g);
        let (mut grad, mut hess) = self.derivatives(&g, &mid, h);
        let mut mu = 0.0f64;
        for _ in 0..60 {
            let scale = hess.iter().flatten().fold(0.0f64, |m, v| m.max(v.abs()));
            let mut moved = false;
            for _ in 0..30 {
                // Solve (mu I - H) s = grad.
                let mut a = [[0.0; 3]; 3];
                for i in 0..3 {
                    for j in 0..3 {
                        a[i][j] = -hess[i][j] + if i == j { mu } else { 0.0 };
                    }
                }
                let Some(s) = solve3(a, grad) else {
                    mu = (2.0 * mu).max(1e-8 * scale.max(1e-300));
                    continue;
                };
                let step = s.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                let next = Rotation::new(g.alpha + s[0], g.beta + s[1], g.gamma + s[2]);
                let (nf, nmid) = self.objective(&next);
                if nf >= f {
                    (g, f) = (next, nf);
                    // Near the maximum the steps shrink fast: a step this small leaves an
                    // error far below the next one's.
                    if step < 1e-10 {
                        return (g, f);
                    }
                    (grad, hess) = self.derivatives(&g, &nmid, h);
                    mu /= 4.0;
                    moved = true;
                    break;
                }
                // A step this small that does not raise `|C|^2` is at what rounding lets
                // it tell apart: done (damped retries would only be rejected again).
                if step < 1e-9 {
                    return (g, f);
                }
                mu = (4.0 * mu).max(1e-6 * scale.max(1e-300));
            }
            if !moved {
                break;
            }
        }
        (g, f)
    }
}

/// Solves the 3 x 3 system `a s = r` (Gaussian elimination with pivoting); `None` if
/// singular.
fn solve3(mut a: [[f64; 3]; 3], mut r: [f64; 3]) -> Option<[f64; 3]> {
    for col in 0..3 {
        let p = (col..3).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        if a[p][col].abs() < 1e-300 || !a[p][col].is_finite() {
            return None;
        }
        a.swap(col, p);
        r.swap(col, p);
        let pivot = a[col];
        for row in col + 1..3 {
            let f = a[row][col] / pivot[col];
            for (x, p) in a[row].iter_mut().zip(pivot).skip(col) {
                *x -= f * p;
            }
            r[row] -= f * r[col];
        }
    }
    let mut s = [0.0; 3];
    for i in (0..3).rev() {
        let tail: f64 = (i + 1..3).map(|k| a[i][k] * s[k]).sum();
        s[i] = (r[i] - tail) / a[i][i];
    }
    s.iter().all(|v| v.is_finite()).then_some(s)
}
