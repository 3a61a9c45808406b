//! The DWT stage of a partial plan: the clusters whose order pairs the shape holds, and the
//! kernels over a chunk of lane pairs, writing (inverse) or reading (forward) each
//! cluster's block of the chunk buffer.
//!
//! A chunk of `h` lane pairs (padded to `hp`, a multiple of the vector width) has `2 hp`
//! lane rows: rows `0..hp` the pairs' lower points, rows `hp..2hp` their mirrors. The
//! chunk buffer is lane-major: a lane row holds every cluster's `P` doubles (16 for
//! clusters of more than four order pairs in the shape, else 8) one after another, so the
//! FFT stage reads or writes a slice's values in one sequential pass. Slot `q` of a
//! cluster's row holds the value of its `q`-th order pair present in the shape (or, for a
//! reversed member, its value at the row's mirror). With a batch, the lane rows of
//! transform `t` follow those of transform `t - 1`.

use super::betas::LanePairs;
use super::shape::CoefLayout;
use crate::dwt::{self, Lanes, Prefetch, Rec};
use crate::numeric::Ext;
use crate::simd::Isa;
use crate::symmetry::{Cluster, Member};
use crate::wigner::{big, start_norm, RecCoeffs, RecTables};
use num_complex::Complex64;
use std::f64::consts::PI;
use std::sync::Mutex;

/// One order pair of a cluster that the shape holds.
#[derive(Clone, Copy, Debug)]
pub(super) struct Slot {
    pub member: Member,
    /// Index of `(M, M')` in a work buffer of `n_alpha` rows of `n_gamma` values, rows
    /// `row_stride` apart.
    pub work: usize,
    /// Start of the pair's coefficient block and its lowest stored degree.
    pub block: usize,
    pub first: usize,
    /// The real layout's representative of `(M, M')`, `(-M, -M')` (`M' > 0`, or `M' = 0`
    /// and `M >= 0`): the real inverse reads the other one's values from it.
    pub representative: bool,
    /// Start of the block of `(-M, -M')` (the real inverse's source for a non-representative).
    pub partner_block: usize,
}

/// A cluster of the shape: base pair, starting-value norm, its slots and its block.
#[derive(Clone, Debug)]
pub(super) struct ClusterPlan {
    pub m: usize,
    pub mp: usize,
    norm: Ext,
    /// Doubles per block row: 16 for more than four slots, else 8.
    pub p: usize,
    pub slots: Vec<Slot>,
    /// Doubles before this cluster's in a lane row.
    pub offset: usize,
}

/// What one kernel call of a cluster works on: the lanes of a chunk.
#[derive(Clone, Copy, Debug)]
pub(super) struct ChunkLanes {
    /// First pair and number of pairs.
    pub j0: usize,
    pub h: usize,
    /// `h` rounded up to the vector width.
    pub hp: usize,
}

impl ChunkLanes {
    pub fn lanes(&self) -> usize {
        2 * self.hp
    }
}

/// Per-worker scratch.
pub(super) struct Scratch {
    rec: RecCoeffs,
    tau: Vec<f64>,
    start: Vec<f64>,
    scale: Vec<f64>,
    /// Inverse input / forward sums.
    data: Vec<f64>,
}

impl Scratch {
    fn new(l: usize, lanes: usize) -> Scratch {
        Scratch {
            rec: RecCoeffs::new(l),
            tau: vec![0.0; lanes],
            start: vec![0.0; lanes],
            scale: vec![0.0; lanes],
            data: vec![0.0; (l + 8) * 16],
        }
    }
}

/// The DWT stage of a partial plan.
pub(super) struct DwtStage {
    isa: Isa,
    /// Degree limit `L`.
    l: usize,
    pub clusters: Vec<ClusterPlan>,
    /// Doubles of a lane row (all clusters).
    pub row_total: usize,
    recurrence: RecTables,
    skip_bits: u32,
    skip: bool,
    scratch: Vec<Mutex<Scratch>>,
    max_lanes: usize,
}

impl DwtStage {
    /// The clusters of `layout` (slices of `n_alpha x n_gamma` values, work buffers with
    /// rows `row_stride` apart), scratch for
    /// `workers` workers and chunks of up to `max_lanes` lanes.
    pub fn new(
        layout: &CoefLayout,
        (n_alpha, n_gamma, row_stride): (usize, usize, usize),
        isa: Isa,
        (skip_bits, skip): (u32, bool),
        (workers, max_lanes): (usize, usize),
    ) -> DwtStage {
        let l = layout.l;
        let mut clusters = Vec::new();
        let mut offset = 0;
        for m in 0..l {
            for mp in 0..=m {
                let cl = Cluster::new(m, mp);
                let slots: Vec<Slot> = cl
                    .members()
                    .iter()
                    .filter(|mem| layout.holds(mem.m, mem.mp))
                    .map(|mem| Slot {
                        member: *mem,
                        work: mem.m.rem_euclid(n_alpha as isize) as usize * row_stride
                            + mem.mp.rem_euclid(n_gamma as isize) as usize,
                        block: layout.block_start(mem.m, mem.mp),
                        first: layout.first_degree(mem.m, mem.mp),
                        representative: mem.mp > 0 || (mem.mp == 0 && mem.m >= 0),
                        partner_block: layout.block_start(-mem.m, -mem.mp),
                    })
                    .collect();
                if slots.is_empty() {
                    continue;
                }
                let p = if slots.len() > 4 { 16 } else { 8 };
                clusters.push(ClusterPlan {
                    m,
                    mp,
                    norm: start_norm(m, mp),
                    p,
                    slots,
                    offset,
                });
                offset += p;
            }
        }
        let top = clusters.iter().map(|c| c.m).max().unwrap_or(0);
        let orders: Vec<usize> = (0..=top).collect();
        DwtStage {
            isa,
            l,
            clusters,
            row_total: offset,
            recurrence: RecTables::for_orders(l, &orders),
            skip_bits,
            skip,
            scratch: (0..workers)
                .map(|_| Mutex::new(Scratch::new(l, max_lanes)))
                .collect(),
            max_lanes,
        }
    }

    /// Bytes of the stage's tables and scratch (approximately).
    pub fn bytes(l: usize, clusters: usize, workers: usize, max_lanes: usize) -> usize {
        32 * (l + 1) * (l + 2)
            + clusters * 256
            + workers * 8 * (3 * max_lanes + 16 * (l + 8) + 5 * l)
    }

    /// Runs `f` with a free scratch (a private one when all are busy).
    pub fn with_scratch<R>(&self, f: impl FnOnce(&mut Scratch) -> R) -> R {
        match crate::workers::lock_free(&self.scratch) {
            Some(mut g) => f(&mut g),
            None => f(&mut Scratch::new(self.l, self.max_lanes)),
        }
    }

    /// Recurrence coefficients (with `rec`) and lane inputs of cluster `cl` for chunk `ch`;
    /// the number of degrees.
    pub fn setup(
        &self,
        sc: &mut Scratch,
        cl: &ClusterPlan,
        pairs: &LanePairs,
        ch: ChunkLanes,
    ) -> usize {
        let n = self.l - cl.m;
        sc.rec.resize(n);
        self.recurrence.coeffs(cl.m, cl.mp, &mut sc.rec);
        let t = &pairs.tables;
        let (h, hp) = (ch.h, ch.hp);
        for (half, first_point) in [(0, ch.j0), (1, pairs.pairs + ch.j0)] {
            let u0 = half * hp;
            t.starts(
                self.isa,
                first_point,
                cl.m,
                cl.mp,
                cl.norm,
                self.skip_bits,
                &mut sc.start[u0..u0 + h],
                &mut sc.scale[u0..u0 + h],
            );
            let tau = if half == 0 { &t.tau_lo } else { &t.tau_hi };
            sc.tau[u0..u0 + h].copy_from_slice(&tau[first_point..first_point + h]);
            for v in [&mut sc.tau, &mut sc.start, &mut sc.scale] {
                v[u0 + h..u0 + hp].fill(0.0);
            }
        }
        n
    }

    /// The kernels' lanes for a chunk in the lane-major buffer: lower row `j` at
    /// `j row_total`, its mirror `hp row_total` further.
    fn lanes<'a>(&self, sc: &'a Scratch, ch: ChunkLanes, stream: bool) -> Lanes<'a> {
        let nl = ch.lanes();
        Lanes {
            tau: &sc.tau[..nl],
            p: &sc.start[..nl],
            sc: &sc.scale[..nl],
            upper_from: ch.hp,
            big: big(self.skip_bits),
            skip: self.skip,
            interleaved: true,
            prefetch: Prefetch::none(),
            stream,
            pair_stride: self.row_total,
            row_gap: ch.hp * self.row_total,
        }
    }

    /// Inverse kernel of `cl` (set up by [`DwtStage::setup`], `n` degrees) from the
    /// coefficients at `coef` into the cluster's slots of the chunk's lane rows at `block`
    /// (lane row `r` at `block + r row_total`, `cl.p` doubles). With `real`, the
    /// non-representative order pairs are read from their representatives
    /// (`fhat(l,M,M') = (-1)^(M-M') conj(fhat(l,-M,-M'))`). With `stream`, written by
    /// non-temporal stores.
    ///
    /// # Safety
    /// `coef` holds the shape's coefficients (read only meanwhile); the `2 hp` rows of
    /// `cl.p` doubles at `block` are valid for writes and nobody else's meanwhile.
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn inverse(
        &self,
        sc: &mut Scratch,
        cl: &ClusterPlan,
        ch: ChunkLanes,
        n: usize,
        coef: *const Complex64,
        (real, stream): (bool, bool),
        block: *mut f64,
    ) {
        let p = cl.p;
        let mut data = std::mem::take(&mut sc.data);
        if data.len() < (self.l + 8) * 16 {
            data = vec![0.0; (self.l + 8) * 16];
        }
        let scales = &sc.rec.s;
        let scale = 1.0 / (2.0 * PI);
        let mut fill = |fin: &mut [f64], from: usize, to: usize| {
            let rows = &mut fin[from * p..to * p];
            rows.fill(0.0);
            for (q, s) in cl.slots.iter().enumerate() {
                let mem = &s.member;
                for i in from.max(s.first - cl.m)..to {
                    let l = cl.m + i;
                    let f = mem.sign_at(l) * scales[i] * scale;
                    // SAFETY: degree `l` in `s.first..L` of the pair's block (or of its
                    // partner's, which has the same degrees), inside the coefficient array
                    // (caller's contract).
                    let v = unsafe {
                        if real && !s.representative {
                            let c = *coef.add(s.partner_block + l - s.first);
                            let sg = if (mem.m - mem.mp).rem_euclid(2) == 0 {
                                1.0
                            } else {
                                -1.0
                            };
                            c.conj() * sg
                        } else {
                            *coef.add(s.block + l - s.first)
                        }
                    } * f;
                    rows[(i - from) * p + 2 * q] = v.re;
                    rows[(i - from) * p + 2 * q + 1] = v.im;
                }
            }
        };
        let rec = Rec::new(&sc.rec, n);
        let lanes = self.lanes(sc, ch, stream);
        // SAFETY: the chunk's `2 hp` rows of `p` doubles at `block`, addressed as the lanes
        // say, are the caller's (caller's contract).
        unsafe {
            dwt::inverse_raw(
                self.isa,
                p,
                &rec,
                &lanes,
                &mut data[..n * p],
                &mut fill,
                block,
            )
        };
        sc.data = data;
    }

    /// Forward kernel of `cl` over its slots of the chunk's lane rows at `block` (as for
    /// [`DwtStage::inverse`]; padding rows zero), accumulated into the coefficients at
    /// `coef` (`first`: assign instead).
    ///
    /// # Safety
    /// The rows at `block` are valid for reads; `coef` holds the shape's coefficients,
    /// whose blocks of this cluster's slots nobody else touches meanwhile.
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn forward(
        &self,
        sc: &mut Scratch,
        cl: &ClusterPlan,
        ch: ChunkLanes,
        n: usize,
        block: *const f64,
        coef: *mut Complex64,
        first: bool,
    ) {
        let p = cl.p;
        let mut data = std::mem::take(&mut sc.data);
        if data.len() < (self.l + 8) * 16 {
            data = vec![0.0; (self.l + 8) * 16];
        }
        let rec = Rec::new(&sc.rec, n);
        let lanes = self.lanes(sc, ch, false);
        // SAFETY: the `2 hp` rows of `p` doubles at `block`, read only (caller's contract).
        let lo = unsafe { dwt::forward_raw(self.isa, p, &rec, &lanes, block, &mut data) }.min(n);
        for (q, s) in cl.slots.iter().enumerate() {
            let mem = &s.member;
            for l in s.first..self.l {
                let i = l - cl.m;
                let v = if i < lo {
                    Complex64::default()
                } else {
                    Complex64::new(data[i * p + 2 * q], data[i * p + 2 * q + 1])
                        * (mem.sign_at(l) * sc.rec.s[i])
                };
                // SAFETY: degree `l` of the pair's block, this cluster's (caller's contract).
                unsafe {
                    let d = coef.add(s.block + l - s.first);
                    if first {
                        *d = v;
                    } else {
                        *d += v;
                    }
                }
            }
        }
        sc.data = data;
    }
}
