//! Kernel inputs for one cluster on the sample grid: shared by the kernel tests and the
//! measuring tools in `benches/` (feature `internals`).

use super::lanes::{Lanes, Prefetch, Rec};
use crate::numeric::Elem;
use crate::numeric::{frexp, Ext};
use crate::wigner::starts::{big, start_norm, to_scaled, BaseStart, BetaTables, DEFAULT_SKIP_BITS};
use crate::wigner::{RecCoeffs, RecTables};

/// Skip threshold of the kernel tests and benchmarks: `SO3FFT_SKIP_BITS` or the default.
pub fn test_skip_bits() -> u32 {
    std::env::var("SO3FFT_SKIP_BITS")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(DEFAULT_SKIP_BITS)
}

/// The kernel inputs of one cluster at some grid betas.
pub struct ClusterInputs {
    /// Recurrence coefficients for the degrees `m .. b`.
    pub coeffs: RecCoeffs,
    /// Recurrence argument of each beta ([`Lanes::tau`]).
    pub tau: Vec<f64>,
    /// Scaled starting value of each beta ([`Lanes::p`]).
    pub p: Vec<f64>,
    /// Scale index of each beta ([`Lanes::sc`]).
    pub sc: Vec<f64>,
}

/// Recurrence coefficients of base pair `(m, mp)` at bandwidth `b` and lane inputs for
/// `nbs` points spread evenly over the grid (lower half first, as in a chunk).
pub fn cluster_setup(b: usize, m: usize, mp: usize, nbs: usize) -> ClusterInputs {
    ClusterTables::new(b).setup(m, mp, nbs)
}

/// `nbs` grid betas of bandwidth `b` spread evenly over the grid.
fn spread(b: usize, nbs: usize) -> Vec<usize> {
    (0..nbs).map(|s| s * (2 * b) / nbs).collect()
}

/// As [`cluster_setup`], for the grid betas `ks`.
#[cfg(test)]
pub fn cluster_setup_at(b: usize, m: usize, mp: usize, ks: &[usize]) -> ClusterInputs {
    ClusterTables::new(b).setup_at(m, mp, ks)
}

/// The bandwidth-wide tables of [`cluster_setup`] (grid betas, recurrence tables), built
/// once for the setup of many clusters.
pub struct ClusterTables {
    b: usize,
    bt: BetaTables,
    rt: RecTables,
}

impl ClusterTables {
    /// The tables of bandwidth `b`.
    pub fn new(b: usize) -> ClusterTables {
        ClusterTables {
            b,
            bt: BetaTables::grid(b),
            rt: RecTables::new(b),
        }
    }

    /// [`cluster_setup`] of base pair `(m, mp)` at `nbs` points, with these tables.
    pub fn setup(&self, m: usize, mp: usize, nbs: usize) -> ClusterInputs {
        self.setup_at(m, mp, &spread(self.b, nbs))
    }

    /// As [`ClusterTables::setup`], for the grid betas `ks`.
    pub fn setup_at(&self, m: usize, mp: usize, ks: &[usize]) -> ClusterInputs {
        let (b, bt) = (self.b, &self.bt);
        let nbs = ks.len();
        let norm = start_norm(m, mp);
        let mut rc = RecCoeffs::new(b - m);
        self.rt.coeffs(m, mp, &mut rc);
        let (mut tau, mut p, mut sc) = (vec![0.0; nbs], vec![0.0; nbs], vec![0.0; nbs]);
        let base = BaseStart::new(m, mp, norm, test_skip_bits());
        for (s, &k) in ks.iter().enumerate() {
            tau[s] = if k < b { bt.tau_lo[k] } else { bt.tau_hi[k] };
            (p[s], sc[s]) = bt.start(k, &base, 1.0);
        }
        ClusterInputs {
            coeffs: rc,
            tau,
            p,
            sc,
        }
    }
}

/// `len` values of `buf` from its first 64-byte boundary (as the plan's chunk
/// buffers); `buf` holds at least `len + 64 / size_of::<T>() - 1`.
#[cfg(feature = "internals")]
pub fn aligned<T>(buf: &[T], len: usize) -> &[T] {
    &buf[buf.as_ptr().align_offset(64)..][..len]
}

/// Kernel lanes over `cluster_setup`'s arrays, default skip threshold.
pub fn grid_lanes<'a>(tau: &'a [f64], p: &'a [f64], sc: &'a [f64], upper_from: usize) -> Lanes<'a> {
    Lanes {
        tau,
        p,
        sc,
        upper_from,
        big: big(test_skip_bits()),
        skip: true,
        interleaved: true,
        prefetch: Prefetch::none(),
        stream: true,
        pair_stride: 0,
        row_gap: 0,
    }
}

/// A cluster's kernel inputs in floats (see [`ClusterInputs::to_f32`]).
pub struct FloatInputs {
    coeffs: RecCoeffs<f32>,
    /// Recurrence argument of each beta.
    pub tau: Vec<f32>,
    /// Scaled starting value of each beta, in the float scaled form.
    pub p: Vec<f32>,
    /// Scale index of each beta, in the float scaled form.
    pub sc: Vec<f32>,
}

impl ClusterInputs {
    /// The inputs rounded to floats: the coefficients and arguments to nearest, each start
    /// moved from the double scaled form to the float one.
    pub fn to_f32(&self) -> FloatInputs {
        let mut coeffs = RecCoeffs::new(0);
        coeffs.narrow_from(&self.coeffs);
        let (p, sc) = self
            .p
            .iter()
            .zip(&self.sc)
            .map(|(&v, &k)| {
                // The true value is v 2^(step k).
                let (mant, e) = frexp(v);
                let value = Ext {
                    mant,
                    exp: e + f64::SCALE_STEP * k as i64,
                };
                to_scaled::<f32>(value, test_skip_bits())
            })
            .unzip();
        FloatInputs {
            coeffs,
            tau: self.tau.iter().map(|&x| x as f32).collect(),
            p,
            sc,
        }
    }
}

impl FloatInputs {
    /// The coefficients of the first `n` degrees.
    pub fn rec(&self, n: usize) -> Rec<'_, f32> {
        Rec::new(&self.coeffs, n)
    }

    /// Kernel lanes as [`grid_lanes`] gives them.
    pub fn lanes(&self, upper_from: usize) -> Lanes<'_, f32> {
        let l = grid_lanes(&[], &[], &[], upper_from);
        Lanes {
            tau: &self.tau,
            p: &self.p,
            sc: &self.sc,
            upper_from,
            big: big::<f32>(test_skip_bits()),
            skip: l.skip,
            interleaved: l.interleaved,
            prefetch: l.prefetch,
            stream: l.stream,
            pair_stride: l.pair_stride,
            row_gap: l.row_gap,
        }
    }
}
