//! Wigner-d symmetries and DWT clusters: all the symmetry bookkeeping lives here.
//!
//! For a base pair `(m, m')` with `m >= m' >= 0` and `v_l(beta) = d^l_{m,m'}(beta)`,
//! the seven symmetries (docs/conventions.md: rotations, Wigner d) give, with `beta' = pi - beta`:
//!
//! | member      | d^l of the member at beta       |
//! |-------------|---------------------------------|
//! | `( m,  m')` | `v_l(beta)`                      |
//! | `(-m, -m')` | `(-1)^(m-m') v_l(beta)`          |
//! | `( m', m)`  | `(-1)^(m-m') v_l(beta)`          |
//! | `(-m', -m)` | `v_l(beta)`                      |
//! | `( m, -m')` | `(-1)^(l+m)  v_l(beta')`         |
//! | `(-m,  m')` | `(-1)^(l-m') v_l(beta')`         |
//! | `( m', -m)` | `(-1)^(l+m)  v_l(beta')`         |
//! | `(-m',  m)` | `(-1)^(l+m') v_l(beta')`         |
//!
//! On the sample grid `beta_{2B-1-k} = pi - beta_k`, so "reversed" members read the
//! mirrored beta slice. Duplicates (when `m' = 0` or `m = m'`) are dropped, leaving
//! clusters of 8, 4 (`m' = 0` or `m = m' > 0`) or 1 (`m = m' = 0`) order pairs.
//!
//! The seed paper enumerates the clusters with `m > m' > 0` by its triangle-to-rectangle
//! map `kappa -> (i, j) -> (m, m')`, which pairs an expensive row (small `m`) with a cheap
//! one (large `m`) so that consecutive kappa ranges carry similar work. Here that map
//! orders square tiles of clusters, which also keeps the FFT stage's accesses to a
//! transformed slice local (see [`cluster_pairs`]).

/// One order pair of a cluster and how its Wigner d follows from the base pair's.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Member {
    /// Order paired with alpha.
    pub m: isize,
    /// Order paired with gamma.
    pub mp: isize,
    /// Constant sign factor (+1 or -1).
    pub sign: i8,
    /// Whether an extra `(-1)^l` applies.
    pub parity: bool,
    /// Whether the member uses the base function at `pi - beta`.
    pub reversed: bool,
}

impl Member {
    /// Sign factor at degree `l`.
    #[inline]
    pub fn sign_at(&self, l: usize) -> f64 {
        let s = if self.parity && l % 2 == 1 {
            -self.sign
        } else {
            self.sign
        };
        s as f64
    }
}

/// A group of order pairs sharing one Wigner-d recurrence (no heap: plans build
/// them on the fly from the base pair).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) struct Cluster {
    /// Base order `m` (`m >= m' >= 0`); also the lowest degree `l0`.
    pub m: usize,
    /// Base order `m'`.
    pub mp: usize,
    slots: [Member; 8],
    len: usize,
}

fn neg1(e: isize) -> i8 {
    if e.rem_euclid(2) == 0 {
        1
    } else {
        -1
    }
}

impl Cluster {
    /// The cluster of base pair `(m, mp)`, `m >= mp >= 0`.
    pub fn new(m: usize, mp: usize) -> Cluster {
        assert!(m >= mp);
        let (a, b) = (m as isize, mp as isize);
        let s = neg1(a - b);
        let all = [
            (a, b, 1, false, false),
            (-a, -b, s, false, false),
            (b, a, s, false, false),
            (-b, -a, 1, false, false),
            (a, -b, neg1(a), true, true),
            (-a, b, neg1(b), true, true),
            (b, -a, neg1(a), true, true),
            (-b, a, neg1(b), true, true),
        ];
        let first = Member {
            m: a,
            mp: b,
            sign: 1,
            parity: false,
            reversed: false,
        };
        let mut c = Cluster {
            m,
            mp,
            slots: [first; 8],
            len: 0,
        };
        for (m, mp, sign, parity, reversed) in all {
            if !c.members().iter().any(|x| x.m == m && x.mp == mp) {
                c.slots[c.len] = Member {
                    m,
                    mp,
                    sign,
                    parity,
                    reversed,
                };
                c.len += 1;
            }
        }
        c
    }

    /// The distinct members (1, 4 or 8).
    pub fn members(&self) -> &[Member] {
        &self.slots[..self.len]
    }
}

/// Number of generic clusters (`m > m' > 0`): `(B-1)(B-2)/2`.
#[cfg(test)]
pub(crate) fn num_generic(b: usize) -> usize {
    if b < 3 {
        0
    } else {
        (b - 1) * (b - 2) / 2
    }
}

/// The seed paper's map from the linear index `kappa` to the base pair `(m, m')`,
/// `1 <= m' < m <= B-1`, through the rectangle indices `(i, j)`.
#[cfg(any(test, feature = "internals"))]
pub(crate) fn kappa_to_pair(b: usize, kappa: usize) -> (usize, usize) {
    let i = kappa / (b - 1) + 1;
    let j = kappa % (b - 1) + 1;
    if j > i {
        (b - i, b - j)
    } else {
        (i + 1, j)
    }
}

/// Side of the square tiles of base pairs that [`cluster_pairs`] keeps together.
#[cfg(any(test, feature = "internals"))]
pub(crate) const TILE: usize = 8;

/// Base pairs of all clusters of bandwidth `b`, `0 <= m' <= m < B`, in processing order.
/// Together their clusters cover every order pair `(M, M')`, `|M|, |M'| < B`, exactly once.
///
/// The base pairs are cut into `TILE x TILE` tiles (`m` and `m'` each in one run of
/// `TILE` values), and a tile's pairs are consecutive (`m` outer, `m'` inner). The FFT
/// stage moves every cluster's values in or out of a transformed slice, at the rows and
/// columns `+-m`, `+-m'` of the slice: within a tile these are a few rows and a few
/// cache lines of each, which stay in L1, instead of a new line per member and cluster.
/// The tiles themselves, a triangle `0 <= tb <= ta < T` (`T = ceil(B / TILE)`), are
/// enumerated with the seed paper's index map ([`kappa_to_pair`] on the triangle
/// `1 <= tb + 1 < ta + 2 <= T + 1`), which interleaves expensive rows of tiles (small
/// `m`) with cheap ones, so any contiguous run of tiles carries a similar amount of work.
#[cfg(any(test, feature = "internals"))]
pub fn cluster_pairs(b: usize) -> Vec<(u32, u32)> {
    let t = b.div_ceil(TILE);
    let tiles = (0..t * (t + 1) / 2).map(|k| {
        let (x, y) = kappa_to_pair(t + 2, k);
        (x - 2, y - 1)
    });
    let mut v = Vec::with_capacity(b * (b + 1) / 2);
    for (ta, tb) in tiles {
        for m in ta * TILE..((ta + 1) * TILE).min(b) {
            for mp in tb * TILE..((tb + 1) * TILE).min(m + 1) {
                v.push((m as u32, mp as u32));
            }
        }
    }
    v
}

/// Where the order pair `(m, mp)` lives: its cluster's base pair and its member entry.
pub(crate) fn locate(m: isize, mp: isize) -> (usize, usize, Member) {
    let a = m.unsigned_abs();
    let b = mp.unsigned_abs();
    let (bm, bmp) = (a.max(b), a.min(b));
    let c = Cluster::new(bm, bmp);
    let mem = *c
        .members()
        .iter()
        .find(|x| x.m == m && x.mp == mp)
        .expect("every order pair is a member of its base cluster");
    (bm, bmp, mem)
}

#[cfg(test)]
mod tests {
    use super::{cluster_pairs, kappa_to_pair, num_generic, Cluster};
    use std::collections::HashSet;

    #[test]
    fn kappa_map_is_bijection_onto_strict_triangle() {
        for b in 3..40 {
            let mut seen = HashSet::new();
            for k in 0..num_generic(b) {
                let (m, mp) = kappa_to_pair(b, k);
                assert!(1 <= mp && mp < m && m < b, "b={b} k={k} -> ({m},{mp})");
                assert!(seen.insert((m, mp)), "duplicate ({m},{mp}) at b={b}");
            }
            assert_eq!(seen.len(), (b - 1) * (b - 2) / 2);
        }
    }

    #[test]
    fn clusters_cover_every_pair_once() {
        for b in 1..30usize {
            let bi = b as isize;
            let mut seen = HashSet::new();
            for (m, mp) in cluster_pairs(b) {
                let c = Cluster::new(m as usize, mp as usize);
                let expect = if c.m == 0 {
                    1
                } else if c.mp == 0 || c.mp == c.m {
                    4
                } else {
                    8
                };
                assert_eq!(c.members().len(), expect);
                for mem in c.members() {
                    assert!(mem.m.abs() < bi && mem.mp.abs() < bi);
                    assert_eq!(mem.m.unsigned_abs().max(mem.mp.unsigned_abs()), c.m);
                    assert!(seen.insert((mem.m, mem.mp)));
                }
            }
            assert_eq!(seen.len(), (2 * b - 1) * (2 * b - 1));
        }
    }

    /// Independent Wigner d by the explicit factorial sum (fine for small l).
    fn d_explicit(l: i64, m: i64, mp: i64, beta: f64) -> f64 {
        let f = |n: i64| -> f64 { (1..=n).map(|i| i as f64).product() };
        let (c, s) = ((beta / 2.0).cos(), (beta / 2.0).sin());
        let pref = (f(l + m) * f(l - m) * f(l + mp) * f(l - mp)).sqrt();
        let mut t = 0.0;
        for k in 0.max(mp - m)..=(l + mp).min(l - m) {
            let sg = if (m - mp + k) % 2 == 0 { 1.0 } else { -1.0 };
            t += sg * c.powi((2 * l + mp - m - 2 * k) as i32) * s.powi((m - mp + 2 * k) as i32)
                / (f(l + mp - k) * f(k) * f(m - mp + k) * f(l - m - k));
        }
        pref * t
    }

    #[test]
    fn member_rules_match_explicit_wigner_d() {
        for &beta in &[0.37, 1.1, 2.6] {
            for bm in 0..7usize {
                for bmp in 0..=bm {
                    let c = Cluster::new(bm, bmp);
                    for mem in c.members() {
                        for l in bm..9 {
                            let li = l as i64;
                            let base_b = if mem.reversed {
                                std::f64::consts::PI - beta
                            } else {
                                beta
                            };
                            let v = d_explicit(li, bm as i64, bmp as i64, base_b);
                            let want = d_explicit(li, mem.m as i64, mem.mp as i64, beta);
                            let got = mem.sign_at(l) * v;
                            assert!(
                                (got - want).abs() < 1e-12,
                                "l={l} member=({},{}) base=({bm},{bmp}) got {got} want {want}",
                                mem.m,
                                mem.mp
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn explicit_d_closed_forms() {
        let b: f64 = 0.7;
        assert!((d_explicit(1, 1, 0, b) + b.sin() / 2f64.sqrt()).abs() < 1e-15);
        assert!((d_explicit(1, 0, 0, b) - b.cos()).abs() < 1e-15);
        assert!((d_explicit(1, 1, 1, b) - (1.0 + b.cos()) / 2.0).abs() < 1e-15);
    }
}
