//! Peaks refined off the grid: the band-limited correlation evaluated at any rotation from
//! its SO(3) coefficients, and maximised by damped Newton steps, several peaks in lock step
//! (one pass over the coefficients per step serves all of them).

use super::rotation::Rotation;
use super::series::{Local, SeriesTables};
use crate::simd::Isa;
use num_complex::Complex64;
use std::f64::consts::PI;
use std::sync::Arc;

/// A band-limited function on SO(3) given by its coefficients (bandwidth `b`, degrees up to
/// `lmax`), in the normalisation of the inverse transform (`docs/conventions.md`):
/// `C(g) = sum fhat(l,M,M') (1/2pi) sqrt((2l+1)/2) D^l_{M,M'}(g)`.
pub struct So3Series {
    /// The coefficients in the evaluation's order ([`SeriesTables::pack`]).
    packed: Vec<Complex64>,
    tables: Arc<SeriesTables>,
    isa: Isa,
}

/// `|C|^2`, its gradient and its Hessian in `(alpha, beta, gamma)`.
type Objective = (f64, [f64; 3], [[f64; 3]; 3]);

fn objective(l: &Local) -> Objective {
    let grad = l.d.map(|di| 2.0 * (l.c.conj() * di).re);
    let hess = std::array::from_fn(|i| {
        std::array::from_fn(|j| 2.0 * (l.d[i].conj() * l.d[j] + l.c.conj() * l.dd[i][j]).re)
    });
    (l.c.norm_sqr(), grad, hess)
}

/// One peak's damped Newton (Levenberg-Marquardt) search for the largest `|C|^2`.
struct Search {
    g: Rotation,
    f: f64,
    grad: [f64; 3],
    hess: [[f64; 3]; 3],
    /// Damping of the next trial.
    mu: f64,
    /// Accepted steps, and rounds without one since the last.
    steps: usize,
    failures: usize,
    /// The trial rotations under evaluation: rotation, step size, damping.
    trials: Vec<(Rotation, f64, f64)>,
    /// Largest step (max-norm) of a trial.
    radius: f64,
    /// Line-search lengths tried this round (see [`Search::propose_more`]).
    lengths_tried: usize,
    done: bool,
}

/// An undamped Newton step below this size (max-norm, radians) from a point where `|C|^2`
/// is concave is taken without evaluating it, and ends the search: its error is of the
/// order of its square, while `|C|^2` itself cannot tell such steps apart (it changes by
/// less than its rounding error).
const NEGLIGIBLE_STEP: f64 = 1e-8;

impl Search {
    fn new(g: Rotation, (f, grad, hess): Objective, radius: f64) -> Search {
        Search {
            g,
            f,
            grad,
            hess,
            mu: 0.0,
            steps: 0,
            failures: 0,
            trials: Vec::new(),
            radius,
            lengths_tried: 0,
            done: false,
        }
    }

    /// The smallest damping worth trying once a trial was rejected.
    fn min_damping(&self) -> f64 {
        1e-6 * self
            .hess
            .iter()
            .flatten()
            .fold(0.0f64, |m, v| m.max(v.abs()))
            .max(1e-300)
    }

    /// The step solving `(mu I - H) s = grad` and its size, if the system is regular.
    fn step(&self, mu: f64) -> Option<([f64; 3], f64)> {
        let a = std::array::from_fn(|i| {
            std::array::from_fn(|j| -self.hess[i][j] + if i == j { mu } else { 0.0 })
        });
        let s = solve3(a, self.grad)?;
        Some((s, s.iter().fold(0.0f64, |m, v| m.max(v.abs()))))
    }

    /// Adds the trial `length` times the step of damping `mu`; false if singular, or if
    /// the step reaches beyond the trust radius and a trial of the same damping already
    /// stops there (the same point).
    fn add_trial(&mut self, mu: f64, length: f64) -> bool {
        let Some((mut s, mut size)) = self.step(mu) else {
            return false;
        };
        s = s.map(|v| v * length);
        size *= length;
        // No step beyond the trust radius (a grid step: the peak is near its grid point).
        if size > self.radius {
            if self.trials.iter().any(|t| t.2 == mu && t.1 == self.radius) {
                return false;
            }
            s = s.map(|v| v * (self.radius / size));
            size = self.radius;
        }
        let g = &self.g;
        let next = Rotation::new(g.alpha + s[0], g.beta + s[1], g.gamma + s[2]);
        self.trials.push((next, size, mu));
        true
    }

    /// Sets the first trial of the next round, or ends the search: on a concave top the
    /// undamped Newton step (and the end if it is negligible), elsewhere a step damped
    /// enough to go uphill (`mu` above the largest eigenvalue of the Hessian).
    fn propose(&mut self) {
        self.trials.clear();
        self.lengths_tried = 0;
        if self.done {
            return;
        }
        let mut mu = self.mu;
        if concave(&self.hess) {
            if let Some((s, size)) = self.step(0.0) {
                if size < NEGLIGIBLE_STEP {
                    let g = &self.g;
                    self.g = Rotation::new(g.alpha + s[0], g.beta + s[1], g.gamma + s[2]);
                    self.done = true;
                    return;
                }
            }
            if self.failures == 0 {
                mu = 0.0;
            }
        } else {
            // Just above the largest eigenvalue: the step follows the directions where
            // `|C|^2` curves upward (away from a saddle or a minimum); the spare lanes try
            // more strongly damped steps.
            mu = mu.max(largest_eigenvalue(&self.hess) + self.min_damping());
        }
        for _ in 0..30 {
            if self.add_trial(mu, 1.0) {
                return;
            }
            mu = (2.0 * mu).max(1e-8 * self.min_damping() / 1e-6);
        }
        self.done = true;
    }

    /// Adds a trial in a spare lane of the round: after an undamped Newton step, the same
    /// direction at another length (a line search in the same pass: from a grid point the
    /// first Newton steps are off by a third), else a more strongly damped step.
    fn propose_more(&mut self) {
        const LENGTHS: [f64; 8] = [0.5, 1.5, 0.75, 1.25, 2.0, 0.25, 1.75, 0.875];
        let Some(&(_, _, mu)) = self.trials.last() else {
            return;
        };
        if mu == 0.0 {
            // The next length that gives a new point.
            while self.lengths_tried < LENGTHS.len() {
                let length = LENGTHS[self.lengths_tried];
                self.lengths_tried += 1;
                if self.add_trial(0.0, length) {
                    return;
                }
            }
        } else {
            self.add_trial((4.0 * mu).max(self.min_damping()), 1.0);
        }
    }

    /// Takes the trials' objectives: moves to the best trial if `|C|^2` did not fall there.
    fn update(&mut self, results: &[Objective]) {
        let trials = std::mem::take(&mut self.trials);
        // A NaN value never wins.
        let key = |i: usize| {
            if results[i].0.is_nan() {
                f64::NEG_INFINITY
            } else {
                results[i].0
            }
        };
        let best = (0..results.len()).max_by(|&a, &b| key(a).total_cmp(&key(b)));
        let Some(best) = best else {
            return;
        };
        let (next, size, mu) = trials[best];
        let (nf, grad, hess) = results[best];
        if nf >= self.f {
            (self.g, self.f, self.grad, self.hess) = (next, nf, grad, hess);
            self.steps += 1;
            self.failures = 0;
            self.mu = mu / 4.0;
            // Near the maximum the steps shrink fast: a step this small leaves an error far
            // below the next one's.
            self.done = size < 1e-10 || self.steps >= 60;
        } else if trials.iter().all(|t| t.1 < 1e-9) {
            // Steps this small that do not raise `|C|^2` are at what rounding lets them
            // tell apart: done (damped retries would only be rejected again).
            self.done = true;
        } else {
            let last = trials.iter().fold(0.0f64, |m, t| m.max(t.2));
            self.mu = (4.0 * last).max(self.min_damping());
            self.failures += 1;
            self.done = self.failures >= 30;
        }
    }
}

/// The largest eigenvalue of the symmetric `h` (the trigonometric solution of the
/// characteristic cubic).
fn largest_eigenvalue(h: &[[f64; 3]; 3]) -> f64 {
    let off = h[0][1] * h[0][1] + h[0][2] * h[0][2] + h[1][2] * h[1][2];
    let q = (h[0][0] + h[1][1] + h[2][2]) / 3.0;
    let diag = (0..3).map(|i| (h[i][i] - q).powi(2)).sum::<f64>();
    let p = ((diag + 2.0 * off) / 6.0).sqrt();
    if p == 0.0 || !p.is_finite() {
        return h[0][0].max(h[1][1]).max(h[2][2]);
    }
    // B = (h - q I) / p; det(B) / 2 in [-1, 1].
    let b: [[f64; 3]; 3] = std::array::from_fn(|i| {
        std::array::from_fn(|j| (h[i][j] - if i == j { q } else { 0.0 }) / p)
    });
    let det = b[0][0] * (b[1][1] * b[2][2] - b[1][2] * b[2][1])
        - b[0][1] * (b[1][0] * b[2][2] - b[1][2] * b[2][0])
        + b[0][2] * (b[1][0] * b[2][1] - b[1][1] * b[2][0]);
    let phi = (det / 2.0).clamp(-1.0, 1.0).acos() / 3.0;
    q + 2.0 * p * phi.cos()
}

/// Whether the symmetric `h` is negative definite (Sylvester's criterion on `-h`).
fn concave(h: &[[f64; 3]; 3]) -> bool {
    let d1 = -h[0][0];
    let d2 = h[0][0] * h[1][1] - h[0][1] * h[1][0];
    let d3 = h[0][0] * (h[1][1] * h[2][2] - h[1][2] * h[2][1])
        - h[0][1] * (h[1][0] * h[2][2] - h[1][2] * h[2][0])
        + h[0][2] * (h[1][0] * h[2][1] - h[1][1] * h[2][0]);
    d1 > 0.0 && d2 > 0.0 && -d3 > 0.0
}

impl So3Series {
    /// The series of `coeffs` (`(4b^3 - b)/3` values, `so3CoefLoc` order), degrees `<= lmax`.
    pub fn new(b: usize, lmax: usize, coeffs: &[Complex64]) -> So3Series {
        Self::with_tables(Arc::new(SeriesTables::new(b, lmax)), coeffs)
    }

    /// The series of `coeffs` with tables built before (their `b` and `lmax`).
    pub(crate) fn with_tables(tables: Arc<SeriesTables>, coeffs: &[Complex64]) -> So3Series {
        assert!(coeffs.len() == crate::num_coeffs(tables.b));
        So3Series {
            packed: tables.pack(coeffs),
            tables,
            isa: Isa::selected().unwrap_or_else(|_| Isa::detect()),
        }
    }

    fn evaluate(&self, points: &[Rotation]) -> Vec<Local> {
        let pts: Vec<[f64; 3]> = points.iter().map(|g| [g.alpha, g.beta, g.gamma]).collect();
        self.tables.evaluate(self.isa, &self.packed, &pts)
    }

    /// The value at rotation `g`.
    pub fn value(&self, g: &Rotation) -> Complex64 {
        self.evaluate(std::slice::from_ref(g))[0].c
    }

    /// The values at every rotation of `gs`, in one pass over the coefficients.
    pub fn values(&self, gs: &[Rotation]) -> Vec<Complex64> {
        self.evaluate(gs).iter().map(|l| l.c).collect()
    }

    /// The rotation near `start` where `|C|^2` is largest, by damped Newton steps
    /// (Levenberg-Marquardt), with `beta` in `[0, pi]` and `alpha`, `gamma` in `[0, 2 pi)`,
    /// and `|C|^2` there (a final Newton step below 1e-8 rad is taken without evaluating
    /// it: the value is then the one before it, equal to rounding). Near `beta = 0` or `pi`
    /// the Euler angles are degenerate and the result is accurate to about 1e-9 rad.
    pub fn maximise(&self, start: &Rotation) -> (Rotation, f64) {
        self.maximise_many(std::slice::from_ref(start))[0]
    }

    /// [`So3Series::maximise`] from every rotation of `starts`, in lock step: each round
    /// evaluates the trial rotations of all unfinished searches in one pass over the
    /// coefficients (value, gradient and Hessian from the differentiated recurrence). The
    /// vector lanes a round leaves over carry more strongly damped trials of the searches.
    pub fn maximise_many(&self, starts: &[Rotation]) -> Vec<(Rotation, f64)> {
        let radius = PI / (self.tables.lmax + 1) as f64;
        let first = self.evaluate(starts);
        let mut searches: Vec<Search> = starts
            .iter()
            .zip(&first)
            .map(|(g, l)| Search::new(*g, objective(l), radius))
            .collect();
        let w = self.isa.lanes();
        loop {
            searches.iter_mut().for_each(Search::propose);
            let open: Vec<usize> = (0..searches.len())
                .filter(|&i| !searches[i].trials.is_empty())
                .collect();
            if open.is_empty() {
                break;
            }
            let spare = open.len().div_ceil(w) * w - open.len();
            for k in 0..spare {
                searches[open[k % open.len()]].propose_more();
            }
            let trials: Vec<Rotation> = open
                .iter()
                .flat_map(|&i| searches[i].trials.iter().map(|t| t.0))
                .collect();
            let mut results = self.evaluate(&trials).into_iter().map(|l| objective(&l));
            for &i in &open {
                let r: Vec<Objective> = results.by_ref().take(searches[i].trials.len()).collect();
                searches[i].update(&r);
            }
        }
        searches.iter().map(|s| (s.g.normalized(), s.f)).collect()
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

#[cfg(test)]
mod tests {
    use super::*;

    /// On a concave top whose Newton step reaches far beyond the trust radius, the spare
    /// lanes' line search adds only distinct points: the lengths that would stop at the
    /// radius again are left out, and no length is tried twice.
    #[test]
    fn line_search_points_are_distinct() {
        let radius = 0.05;
        let hess = [[-1.0, 0.0, 0.0], [0.0, -2.0, 0.0], [0.0, 0.0, -3.0]];
        for grad in [[1.0, 0.5, 0.3], [1e-3, 2e-3, 0.0]] {
            let mut s = Search::new(Rotation::new(0.1, 1.0, 0.2), (1.0, grad, hess), radius);
            s.propose();
            for _ in 0..20 {
                s.propose_more();
            }
            assert!(!s.trials.is_empty() && s.trials.len() <= 9);
            for (i, a) in s.trials.iter().enumerate() {
                assert!(a.1 <= radius);
                for b in &s.trials[..i] {
                    let d = (a.0.alpha - b.0.alpha).abs()
                        + (a.0.beta - b.0.beta).abs()
                        + (a.0.gamma - b.0.gamma).abs();
                    assert!(d > 0.0, "grad {grad:?}: trials {i} repeats a point");
                }
            }
        }
        // The large step: one trial at the radius, then only the lengths that stay inside.
        let mut s = Search::new(
            Rotation::new(0.1, 1.0, 0.2),
            (1.0, [1.0, 0.5, 0.3], hess),
            radius,
        );
        s.propose();
        for _ in 0..20 {
            s.propose_more();
        }
        let at_radius = s.trials.iter().filter(|t| t.1 == radius).count();
        assert_eq!(at_radius, 1);
    }
}
