//! Which betas a partial plan evaluates ([`Betas`]) and how they become kernel lanes: pairs
//! of a beta and its mirror `pi - beta` ([`LanePairs`]), since a cluster's "reversed"
//! members (see `symmetry.rs`) at one beta are its base function at the mirror.

use crate::error::{Error, Result};
use crate::numeric::{sin_cos_dd, Dd, PI_DD};
use crate::options::Betas;
use crate::shape::Shape;
use crate::wigner::BetaTables;
use std::f64::consts::PI;

/// Kernel lanes in pairs: point `j` (`j < pairs`) is a beta `<= pi/2` and point
/// `pairs + j` its mirror. Each output slice is one point of a pair.
pub(crate) struct LanePairs {
    /// Recurrence arguments and starting-value tables of the `2 pairs` points.
    pub tables: BetaTables,
    pub pairs: usize,
    /// Number of output slices.
    pub n_slices: usize,
    /// Per pair: the output slices of its lower and upper point (`usize::MAX`: not written).
    pub outputs: Vec<[usize; 2]>,
    /// When no pair writes both its points (see [`LanePairs::new`]): the first pair that
    /// writes its upper point (the pairs before it write their lower point, or nothing:
    /// padding); a multiple of the vector width unless it is `pairs`. The inverse then runs
    /// each cluster's direct members only at the written points and its reversed members
    /// only at their mirrors.
    pub first_upper_pair: Option<usize>,
}

/// `(cos(x), sin(x))` of a half angle `x` in double-double.
fn half_angle_point(x: Dd) -> (Dd, Dd) {
    let (s, c) = sin_cos_dd(x);
    (c, s)
}

impl LanePairs {
    /// Bytes of the tables per pair at degree limit `l`: two points, each with its powers
    /// of the half-angle cosine and sine up to `2L` (about `64 (66 + L/32)` bytes), and the
    /// bookkeeping.
    pub fn bytes_per_pair(l: usize) -> usize {
        2 * (64 * (66 + l / 32) + 64) + 96
    }

    /// The lanes of `betas` on `shape`'s grid. With `split = Some(w)` and no pair writing
    /// both its points, the pairs are ordered by the point they write, lower first, padded
    /// to a multiple of `w` with pairs that write nothing (see
    /// [`LanePairs::first_upper_pair`]).
    pub fn new(shape: &Shape, betas: &Betas, split: Option<usize>) -> Result<LanePairs> {
        let bg = shape.grid_bandwidth;
        let nb = 2 * bg;
        // What the tables take, checked before anything is made.
        let count = match betas {
            Betas::All => bg,
            Betas::Indices(v) => v.len(),
            Betas::Values(v) => v.len(),
        };
        // Twice the tables (their vectors grow by copies) and 1 MiB for the rest of
        // planning's small allocations, which have no checks of their own.
        let per_pair = LanePairs::bytes_per_pair(shape.degree_limit);
        crate::system::check_headroom(count.saturating_mul(2 * per_pair).saturating_add(1 << 20))?;
        // Half angles of the lower points, and which slices each pair writes.
        let mut half: Vec<Dd> = Vec::new();
        let mut outputs: Vec<[usize; 2]> = Vec::new();
        let mut n_slices = 0;
        let grid_half = |k: usize| {
            PI_DD
                .mul_f((2 * k + 1) as f64)
                .div(Dd::new((8 * bg) as f64))
        };
        match betas {
            Betas::All => {
                for j in 0..bg {
                    half.push(grid_half(j));
                    outputs.push([j, nb - 1 - j]);
                }
                n_slices = nb;
            }
            Betas::Indices(ks) => {
                let mut pair_of = vec![usize::MAX; bg];
                for (s, &k) in ks.iter().enumerate() {
                    if k >= nb {
                        return Err(Error::InvalidArgument(format!(
                            "beta index {k} outside the grid (0..{nb})"
                        )));
                    }
                    let (low, upper) = (k.min(nb - 1 - k), k >= bg);
                    if pair_of[low] == usize::MAX {
                        pair_of[low] = half.len();
                        half.push(grid_half(low));
                        outputs.push([usize::MAX; 2]);
                    }
                    let pair = pair_of[low];
                    let o = &mut outputs[pair][upper as usize];
                    if *o != usize::MAX {
                        return Err(Error::InvalidArgument(format!(
                            "beta index {k} given twice"
                        )));
                    }
                    *o = s;
                    n_slices += 1;
                }
            }
            Betas::Values(vs) => {
                for (s, &b) in vs.iter().enumerate() {
                    if !(0.0..=PI).contains(&b) {
                        return Err(Error::InvalidArgument(format!(
                            "beta value {b} outside [0, pi]"
                        )));
                    }
                    let upper = b > PI / 2.0;
                    // The lower point's half angle: b/2, or (pi - b)/2 = pi/2 - b/2.
                    let x = Dd::new(b).mul_f(0.5);
                    let x = if upper { PI_DD.mul_f(0.5).sub(x) } else { x };
                    half.push(x);
                    let mut o = [usize::MAX; 2];
                    o[upper as usize] = s;
                    outputs.push(o);
                    n_slices += 1;
                }
            }
        }
        if half.is_empty() {
            return Err(Error::InvalidArgument("no betas selected".into()));
        }
        let mut first_upper_pair = None;
        if let Some(w) = split {
            if outputs.iter().all(|o| o.contains(&usize::MAX)) {
                let writes_upper = |j: &usize| outputs[*j][1] != usize::MAX;
                let (mut order, upper): (Vec<usize>, Vec<usize>) =
                    (0..half.len()).partition(|j| !writes_upper(j));
                let lower = order.len();
                order.extend(upper);
                let pad = if lower < order.len() {
                    lower.next_multiple_of(w) - lower
                } else {
                    0
                };
                let mut h = Vec::with_capacity(half.len() + pad);
                let mut o = Vec::with_capacity(half.len() + pad);
                for (i, &j) in order.iter().enumerate() {
                    if i == lower {
                        // Padding pairs: any valid point, nothing written.
                        h.extend(std::iter::repeat_n(half[order[0]], pad));
                        o.extend(std::iter::repeat_n([usize::MAX; 2], pad));
                    }
                    h.push(half[j]);
                    o.push(outputs[j]);
                }
                (half, outputs) = (h, o);
                first_upper_pair = Some(lower + pad);
            }
        }
        let pairs = half.len();
        let maxpow = 2 * shape.degree_limit;
        // Lower points, then their mirrors: the mirror's half angle is pi/2 - x, whose
        // cosine and sine are the sine and cosine of x.
        let mut points: Vec<(Dd, Dd)> = half.iter().map(|&x| half_angle_point(x)).collect();
        for j in 0..pairs {
            let (c, s) = points[j];
            points.push((s, c));
        }
        Ok(LanePairs {
            tables: BetaTables::new(&points, maxpow),
            pairs,
            n_slices,
            outputs,
            first_upper_pair,
        })
    }
}
