//! Peaks of a correlation on the SO(3) grid.

use super::rotation::quaternion_angle;
use crate::grid::{alpha, beta, gamma};
use crate::Real;
use num_complex::Complex;
use rayon::prelude::*;

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
/// grid gives index 0 (SOFT's `softFFTWCor2` rule). NaN values are never taken. The
/// magnitudes are computed in `f64`, exactly for an `f32` grid.
pub fn grid_argmax<T: Real>(b: usize, values: &[Complex<T>]) -> Peak {
    argmax_by(b, values, norm_sqr)
}

/// [`grid_argmax`] of a real grid (`|C|^2 = C^2`).
pub fn grid_argmax_real<T: Real>(b: usize, values: &[T]) -> Peak {
    argmax_by(b, values, square)
}

/// `|z|^2` in `f64`.
#[inline(always)]
fn norm_sqr<T: Real>(z: Complex<T>) -> f64 {
    let (re, im) = (z.re.to_f64(), z.im.to_f64());
    re * re + im * im
}

/// `x^2` in `f64`.
#[inline(always)]
fn square<T: Real>(x: T) -> f64 {
    let x = x.to_f64();
    x * x
}

/// The first largest `f(v)` of `values` (strictly larger replaces; NaN is never taken),
/// with its index plus `base`, against the candidate of the values before them (`start`;
/// `(0.0, usize::MAX)`: none, which stays when no value is positive). In blocks: a
/// block's maximum first (eight independent running maxima, which vectorise), then, only
/// when it beats the best so far, the first index in the block that reaches it.
fn first_largest_in<T: Copy>(
    values: &[T],
    base: usize,
    f: &impl Fn(T) -> f64,
    (mut best, mut at): (f64, usize),
) -> (f64, usize) {
    const BLOCK: usize = 1024;
    for (k, block) in values.chunks(BLOCK).enumerate() {
        let mut lanes = [0.0f64; 8];
        let mut groups = block.chunks_exact(8);
        for g in &mut groups {
            for (m, &v) in lanes.iter_mut().zip(g) {
                let x = f(v);
                // NaN compares false and is never taken.
                *m = if x > *m { x } else { *m };
            }
        }
        let top = groups
            .remainder()
            .iter()
            .map(|&v| f(v))
            .chain(lanes)
            .fold(0.0, |m, x| if x > m { x } else { m });
        // Only a block that beats the values before it is searched again.
        if top > best {
            let i = block.iter().position(|&v| f(v) == top).unwrap_or(0);
            (best, at) = (top, base + k * BLOCK + i);
        }
    }
    (best, at)
}

/// Of two `(value, index)` candidates, the larger value, or at equal values the lower
/// index: the candidate a scan in flat order keeps.
fn first_largest(x: (f64, usize), y: (f64, usize)) -> (f64, usize) {
    if y.0 > x.0 || (y.0 == x.0 && y.1 < x.1) {
        y
    } else {
        x
    }
}

/// The peak of the candidate `best` of a grid of bandwidth `b`: index 0 when no value
/// was positive.
fn peak_of(b: usize, (best, at): (f64, usize)) -> Peak {
    Peak::at(b, if at == usize::MAX { 0 } else { at }, best)
}

/// The scan of [`grid_argmax`], in parts spread over rayon's current pool (each part's first
/// largest value; the parts' results combined by value, then by the lower index): the same
/// index as a one-by-one scan.
fn argmax_by<T: Copy + Sync>(b: usize, values: &[T], f: impl Fn(T) -> f64 + Sync) -> Peak {
    const PART: usize = 1 << 16;
    let best = values
        .par_chunks(PART)
        .enumerate()
        .map(|(p, part)| first_largest_in(part, p * PART, &f, (0.0, usize::MAX)))
        .reduce(|| (0.0, usize::MAX), first_largest);
    peak_of(b, best)
}

/// [`grid_argmax`] gathered slice by slice while an inverse computes the grid (each slice
/// scanned while in the cache, see `SliceWatch`): [`SliceArgmax::watch`] takes the slices
/// in any order, [`SliceArgmax::peak`] gives the same peak as a scan of the whole grid.
pub(crate) struct SliceArgmax {
    b: usize,
    /// The best candidate of the slices seen so far (merged in any order by
    /// [`first_largest`], which prefers the larger value, then the lower index).
    best: std::sync::Mutex<(f64, usize)>,
}

impl SliceArgmax {
    /// For a grid of bandwidth `b`.
    pub(crate) fn new(b: usize) -> SliceArgmax {
        SliceArgmax {
            b,
            best: std::sync::Mutex::new((0.0, usize::MAX)),
        }
    }

    /// Scans beta slice `k` (`|C|^2`: `|z|^2` of complex values, `x^2` of real ones).
    pub(crate) fn watch<T: Real>(&self, k: usize, slice: crate::engine::SliceRef<T>) {
        use crate::engine::SliceRef;
        let n = 2 * self.b;
        let base = k * n * n;
        let found = match slice {
            SliceRef::Real(v) => first_largest_in(&v[..n * n], base, &square, (0.0, usize::MAX)),
            SliceRef::Complex {
                values,
                row,
                stride,
            } => (0..row).fold((0.0, usize::MAX), |acc, r| {
                // Rows in flat order, each with the largest value before it.
                let cells = &values[r * stride..][..row];
                first_largest_in(cells, base + r * row, &norm_sqr, acc)
            }),
        };
        let mut best = self.best.lock().unwrap_or_else(|e| e.into_inner());
        *best = first_largest(*best, found);
    }

    /// The grid's first largest value over the slices seen.
    pub(crate) fn peak(&self) -> Peak {
        peak_of(self.b, *self.best.lock().unwrap_or_else(|e| e.into_inner()))
    }
}

/// Up to `k` peaks of `|C|^2` on the grid `values` (bandwidth `b`), largest first: grid
/// points at least as large as their 26 neighbours (`alpha`, `gamma` periodic), each at
/// least `min_angle` radians (geodesic) from every larger peak taken. On a worker pool the
/// beta slices are spread over its threads.
///
/// # Panics
/// If `values` does not hold `(2b)^3` values or `min_angle` is negative or NaN.
pub fn top_peaks<T: Real>(b: usize, values: &[Complex<T>], k: usize, min_angle: f64) -> Vec<Peak> {
    select_peaks(b, values, norm_sqr, (k, min_angle))
}

/// [`top_peaks`] of a real grid (`C^2`).
///
/// # Panics
/// As [`top_peaks`].
pub fn top_peaks_real<T: Real>(b: usize, values: &[T], k: usize, min_angle: f64) -> Vec<Peak> {
    select_peaks(b, values, square, (k, min_angle))
}

fn select_peaks<T: Copy + Sync>(
    b: usize,
    values: &[T],
    square: impl Fn(T) -> f64 + Sync,
    (k, min_angle): (usize, f64),
) -> Vec<Peak> {
    let n = 2 * b;
    assert_eq!(
        values.len(),
        n * n * n,
        "a grid of bandwidth {b} holds (2b)^3 values"
    );
    assert!(
        min_angle >= 0.0,
        "min_angle {min_angle} is not an angle >= 0"
    );
    // Runs of beta slices, each scanned with the squared magnitudes of three slices.
    let runs = if rayon::current_thread_index().is_some() {
        (4 * rayon::current_num_threads()).min(n)
    } else {
        1
    };
    let run = |r: usize| local_maxima(b, values, &square, (r * n / runs)..((r + 1) * n / runs));
    let mut maxima: Vec<Peak> = if runs > 1 {
        (0..runs).into_par_iter().flat_map_iter(run).collect()
    } else {
        run(0)
    };
    maxima.sort_by(|a, c| c.value.total_cmp(&a.value).then(a.index.cmp(&c.index)));
    // The taken peaks' quaternions, made once.
    let mut taken: Vec<(Peak, [f64; 4])> = Vec::new();
    for p in maxima {
        if taken.len() == k {
            break;
        }
        let q = p.rotation().quaternion();
        if taken
            .iter()
            .all(|(_, t)| quaternion_angle(*t, q) >= min_angle)
        {
            taken.push((p, q));
        }
    }
    taken.into_iter().map(|(p, _)| p).collect()
}

/// The local maxima of `|C|^2` (see [`top_peaks`]) in the beta slices `slices`, in index
/// order. The squared magnitudes of the slice below, the slice and the slice above are
/// kept in a rolling window (three slices of `(2b)^2` doubles).
fn local_maxima<T: Copy>(
    b: usize,
    values: &[T],
    square: impl Fn(T) -> f64,
    slices: std::ops::Range<usize>,
) -> Vec<Peak> {
    let n = 2 * b;
    let area = n * n;
    let norms = |kb: usize, out: &mut Vec<f64>| {
        out.clear();
        out.extend(values[kb * area..][..area].iter().map(|&z| square(z)));
    };
    let (mut below, mut here, mut above) = (Vec::new(), Vec::new(), Vec::new());
    let mut found = Vec::new();
    let mut candidates: Vec<bool> = Vec::with_capacity(n);
    for kb in slices.clone() {
        if kb == slices.start {
            if kb > 0 {
                norms(kb - 1, &mut below);
            }
            norms(kb, &mut here);
        } else {
            std::mem::swap(&mut below, &mut here);
            std::mem::swap(&mut here, &mut above);
        }
        if kb + 1 < n {
            norms(kb + 1, &mut above);
        } else {
            above.clear();
        }
        // The neighbouring slices that exist (beta is not periodic).
        let others: Vec<&[f64]> = [&below, &above]
            .into_iter()
            .filter(|s| !s.is_empty())
            .map(|s| &s[..])
            .collect();
        for ja in 0..n {
            let rows = [(ja + n - 1) % n, ja, (ja + 1) % n];
            let row = &here[ja * n..][..n];
            // Points positive and not below their two neighbours along gamma, without
            // branches (a smooth row has only a few); the rest of the test for those.
            candidates.clear();
            candidates.extend((0..n).map(|jg| {
                let x = row[jg];
                let left = row[if jg == 0 { n - 1 } else { jg - 1 }];
                let right = row[if jg + 1 == n { 0 } else { jg + 1 }];
                // (A NaN neighbour does not count as larger.)
                let below = |y: f64| y.partial_cmp(&x) != Some(std::cmp::Ordering::Greater);
                (x > 0.0) & below(left) & below(right)
            }));
            for jg in (0..n).filter(|&jg| candidates[jg]) {
                let x = row[jg];
                let cols = [
                    if jg == 0 { n - 1 } else { jg - 1 },
                    jg,
                    if jg + 1 == n { 0 } else { jg + 1 },
                ];
                let larger = |s: &[f64], skip_centre: bool| {
                    rows.iter().any(|&r| {
                        cols.iter()
                            .any(|&c| !(skip_centre && r == ja && c == jg) && s[r * n + c] > x)
                    })
                };
                if larger(&here, true) || others.iter().any(|s| larger(s, false)) {
                    continue;
                }
                found.push(Peak::at(b, kb * area + ja * n + jg, x));
            }
        }
    }
    found
}

#[cfg(test)]
mod tests {
    use super::*;
    use num_complex::Complex64;

    /// The rule itself: a one-by-one scan taking only strictly larger values.
    fn plain(values: &[f64]) -> (usize, f64) {
        let (mut best, mut at) = (0.0, 0);
        for (i, &v) in values.iter().enumerate() {
            if v * v > best {
                (best, at) = (v * v, i);
            }
        }
        (at, best)
    }

    /// The rule of `top_peaks` point by point: every grid point with a positive value and no
    /// larger one among its 26 neighbours, largest first, then separated greedily.
    fn plain_peaks(b: usize, values: &[Complex64], k: usize, min_angle: f64) -> Vec<Peak> {
        let n = 2 * b as isize;
        let v = |kb: isize, ja: isize, jg: isize| {
            values[((kb * n + ja.rem_euclid(n)) * n + jg.rem_euclid(n)) as usize].norm_sqr()
        };
        let mut maxima = Vec::new();
        for kb in 0..n {
            for ja in 0..n {
                for jg in 0..n {
                    let x = v(kb, ja, jg);
                    let neighbours = (-1..=1)
                        .filter(|d| (0..n).contains(&(kb + d)))
                        .flat_map(|d| (-1..=1).flat_map(move |e| (-1..=1).map(move |f| (d, e, f))))
                        .filter(|&t| t != (0, 0, 0));
                    // (A NaN neighbour does not count as larger.)
                    if x > 0.0
                        && !neighbours
                            .clone()
                            .any(|(d, e, f)| v(kb + d, ja + e, jg + f) > x)
                    {
                        maxima.push(Peak::at(b, ((kb * n + ja) * n + jg) as usize, x));
                    }
                }
            }
        }
        maxima.sort_by(|a, c| c.value.total_cmp(&a.value).then(a.index.cmp(&c.index)));
        let mut taken: Vec<Peak> = Vec::new();
        for p in maxima {
            if taken.len() < k
                && taken
                    .iter()
                    .all(|t| t.rotation().angle_to(&p.rotation()) >= min_angle)
            {
                taken.push(p);
            }
        }
        taken
    }

    #[test]
    fn top_peaks_follow_the_rule_on_every_thread_count() {
        let b = 6;
        let n = 8 * b * b * b;
        let mut state = 7u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            (state >> 40) % 7
        };
        // Few distinct values (plateaus and ties), a NaN; peaks at the beta edges and across
        // the periodic alpha and gamma edges.
        let mut v: Vec<Complex64> = (0..n).map(|_| Complex64::new(next() as f64, 0.0)).collect();
        v[5] = Complex64::new(f64::NAN, 0.0);
        v[0] = Complex64::new(50.0, 0.0);
        v[n - 1] = Complex64::new(40.0, 0.0);
        v[11] = Complex64::new(45.0, 0.0);
        for (k, angle) in [(usize::MAX, 0.0), (10, 0.3), (3, 2.0)] {
            let want = plain_peaks(b, &v, k, angle);
            assert_eq!(top_peaks(b, &v, k, angle), want);
            let re: Vec<f64> = v.iter().map(|z| -z.re).collect();
            assert_eq!(top_peaks_real(b, &re, k, angle), want);
            for threads in [2, 3] {
                let pool = rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .unwrap();
                assert_eq!(pool.install(|| top_peaks(b, &v, k, angle)), want);
            }
        }
    }

    #[test]
    fn block_scan_takes_the_first_largest_value() {
        // Several parts of the parallel scan (2^16 values each), each of several blocks.
        let b = 33;
        let n = 8 * b * b * b;
        let mut state = 1u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            (state >> 40) % 50
        };
        // Few distinct values (many ties), a NaN and negative values; then special grids.
        let mut v: Vec<f64> = (0..n).map(|_| next() as f64 - 25.0).collect();
        v[3] = f64::NAN;
        let mut grids = vec![v.clone(), vec![0.0; n], vec![f64::NAN; n]];
        v[n - 1] = 1e3;
        grids.push(v.clone());
        v[200_000] = -1e3;
        grids.push(v.clone());
        // A tie between two parts: the earlier part's index.
        v[70_000] = 1e3;
        grids.push(v);
        for g in &grids {
            let p = grid_argmax_real(b, g);
            let (at, best) = plain(g);
            assert_eq!((p.index, p.value), (at, best));
            let z: Vec<Complex64> = g.iter().map(|&x| Complex64::new(0.0, x)).collect();
            let q = grid_argmax(b, &z);
            assert_eq!((q.index, q.value), (at, best));
        }
    }

    /// Slices shown in any order, complex ones row by row in padded rows, give the rule's
    /// point: ties within a row, across rows and across slices go to the lowest index.
    #[test]
    fn slice_watch_takes_the_first_largest_value() {
        use crate::engine::SliceRef;
        let b = 6;
        let (n, stride) = (2 * b, 2 * b + 3);
        let mut state = 7u64;
        let mut next = || {
            state = state.wrapping_mul(6364136223846793005).wrapping_add(1);
            ((state >> 40) % 9) as f64 - 4.0
        };
        let mut v: Vec<f64> = (0..n * n * n).map(|_| next()).collect();
        v[5] = f64::NAN;
        let mut grids = vec![v.clone()];
        // The largest value in a late row of slice 3, then again in an earlier row of
        // slice 3 and in slice 9: the earlier row of slice 3 wins.
        v[3 * n * n + 7 * n + 2] = 50.0;
        grids.push(v.clone());
        v[3 * n * n + 2 * n + 5] = -50.0;
        v[9 * n * n] = 50.0;
        grids.push(v);
        for g in &grids {
            let (at, best) = plain(g);
            let (real, complex) = (SliceArgmax::new(b), SliceArgmax::new(b));
            for k in (0..n).rev() {
                let slice = &g[k * n * n..][..n * n];
                real.watch(k, SliceRef::Real(slice));
                let mut padded = vec![Complex64::new(f64::NAN, 0.0); n * stride];
                for r in 0..n {
                    for c in 0..n {
                        padded[r * stride + c] = Complex64::new(slice[r * n + c], 0.0);
                    }
                }
                let values = &padded[..(n - 1) * stride + n];
                complex.watch(
                    k,
                    SliceRef::Complex {
                        values,
                        row: n,
                        stride,
                    },
                );
            }
            for p in [real.peak(), complex.peak()] {
                assert_eq!((p.index, p.value), (at, best));
            }
        }
    }
}
