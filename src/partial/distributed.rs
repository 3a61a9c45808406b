//! [`DistributedPlan`]: a partial plan's transforms spread over the ranks of a group of
//! processes (MPI, or threads of one process for tests), each holding a part of the samples
//! and a part of the coefficients.
//!
//! - Samples: rank `r` owns the lane pairs `j0_r .. j1_r` (contiguous, as equal as can be),
//!   i.e. the beta slices `j0_r .. j1_r` and their mirrors `2 B_grid - j1_r .. 2 B_grid - j0_r`,
//!   two contiguous runs of the global sample array, stored one after the other.
//! - Coefficients: rank `r` owns a contiguous run of the clusters (in the order of
//!   `symmetry.rs`, split by their cost, degrees times row width), and stores, cluster after
//!   cluster and order pair after order pair, the degrees `max(|M|, |M'|, L0) .. L - 1` of each
//!   order pair of its clusters ([`DistributedPlan::local_coef_index`]).
//! - Forward: the FFT stage on the local slices gives their lane rows (every cluster's values,
//!   see `dwt_stage.rs`); one all-to-all exchange sends each rank the segment of every lane
//!   row that holds its clusters; the DWT stage then runs each local cluster over all betas.
//!   The inverse runs the same steps backwards. Each lane is one kernel lane in both, and a
//!   cluster's kernel call covers all betas, so the results are bitwise those of a
//!   single-process [`PartialPlan`](super::PartialPlan) of the same shape whose chunk holds
//!   every beta (its default up to large bandwidths).

use super::betas::{Betas, LanePairs};
use super::dwt_stage::{ChunkLanes, ClusterPlan};
use super::plan::{General, PartialOptions};
use super::shape::Shape;
use crate::error::{check_length, Error, Result};
use crate::fft::AlignedBuf;
use crate::plan::Direction;
use crate::simd::Isa;
use crate::workers::{SendConstPtr, SendPtr};
use num_complex::Complex64;
use rayon::prelude::*;

/// What a distributed plan needs of its group of processes. Every method is collective:
/// all ranks call it, in the same order.
pub trait Exchange: Sync {
    /// This process's rank, `0 .. size`.
    fn rank(&self) -> usize;
    /// Number of ranks.
    fn size(&self) -> usize;
    /// Sends `send` to rank `dest` and receives into `recv` what rank `src` sends here (every
    /// rank calls it at once, each with its own pair; lengths agree pairwise: the callers
    /// compute them from the same plan).
    fn sendrecv(&self, send: &[f64], dest: usize, recv: &mut [f64], src: usize) -> Result<()>;
    /// The largest of the ranks' `value`s, on every rank.
    fn max(&self, value: u64) -> Result<u64>;
}

/// Page-aligned doubles, zero-filled (huge pages where the system gives them): the lane
/// rows are written and read far apart, which 4 KiB pages would turn into TLB misses.
struct Rows {
    buf: AlignedBuf,
    len: usize,
}

impl Rows {
    fn new(len: usize) -> Result<Rows> {
        Ok(Rows {
            buf: AlignedBuf::new(len.div_ceil(2).max(1))?,
            len,
        })
    }
}

impl std::ops::Deref for Rows {
    type Target = [f64];
    fn deref(&self) -> &[f64] {
        // SAFETY: the buffer holds at least `len` doubles (`len / 2` complex values rounded
        // up), initialised (zero-filled at creation), owned by `self`.
        unsafe { std::slice::from_raw_parts(self.buf.as_mut_ptr().cast::<f64>(), self.len) }
    }
}

impl std::ops::DerefMut for Rows {
    fn deref_mut(&mut self) -> &mut [f64] {
        // SAFETY: as for `deref`; `&mut self` makes the borrow exclusive.
        unsafe { std::slice::from_raw_parts_mut(self.buf.as_mut_ptr().cast::<f64>(), self.len) }
    }
}

/// Wall times of a distributed transform's parts on this rank, in seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct DistributedTimes {
    /// The slice DFTs and the moves between slices and lane rows.
    pub fft: f64,
    /// The all-to-all exchange (with the packing around it).
    pub exchange: f64,
    /// The DWT stage.
    pub dwt: f64,
    /// The whole call.
    pub total: f64,
}

/// A rank's share of the betas and the clusters.
struct Share {
    /// Lane pairs `j0 .. j1`.
    pairs: (usize, usize),
    /// Clusters `c0 .. c1` (indices into the DWT stage's cluster list).
    clusters: (usize, usize),
    /// The clusters' doubles in a lane row: `offset(c0) .. offset(c1)`.
    segment: (usize, usize),
}

/// The transforms of a [`Shape`] over the ranks of an [`Exchange`].
pub struct DistributedPlan<X: Exchange> {
    comm: X,
    shape: Shape,
    real: bool,
    direction: Direction,
    general: General,
    shares: Vec<Share>,
    /// The local clusters, their blocks at local coefficient offsets and their slots at
    /// offsets within the local segment of a lane row.
    local: Vec<ClusterPlan>,
    local_coeffs: usize,
    /// Times of the last transform on this rank.
    last: std::sync::Mutex<DistributedTimes>,
    /// The lane rows of the FFT stage and of the DWT stage, kept between transforms.
    rows: std::sync::Mutex<Option<(Rows, Rows)>>,
    /// The exchange's packed blocks (sent and received), kept between transforms.
    packed: std::sync::Mutex<(Vec<f64>, Vec<f64>)>,
}

/// An error on every rank if it is one on any (agreed through `comm`).
fn collective<X: Exchange, T>(comm: &X, r: Result<T>) -> Result<T> {
    let failed = comm.max(u64::from(r.is_err()))?;
    match (r, failed) {
        (Ok(v), 0) => Ok(v),
        (Err(e), _) => Err(e),
        (Ok(_), _) => Err(Error::InvalidArgument(
            "another rank of the distributed plan failed (see its error)".into(),
        )),
    }
}

/// What a rank builds of a plan (everything but the exchange).
struct Parts {
    shape: Shape,
    real: bool,
    direction: Direction,
    general: General,
    shares: Vec<Share>,
    local: Vec<ClusterPlan>,
    local_coeffs: usize,
}

impl<T: Exchange + ?Sized> Exchange for &T {
    fn rank(&self) -> usize {
        (**self).rank()
    }
    fn size(&self) -> usize {
        (**self).size()
    }
    fn sendrecv(&self, send: &[f64], dest: usize, recv: &mut [f64], src: usize) -> Result<()> {
        (**self).sendrecv(send, dest, recv, src)
    }
    fn max(&self, value: u64) -> Result<u64> {
        (**self).max(value)
    }
}

impl<X: Exchange> DistributedPlan<X> {
    /// A plan for `shape` over the ranks of `comm` (collective; every rank passes the same
    /// shape and options). `options.betas` must be [`Betas::All`]; batches are not offered.
    pub fn new(comm: X, shape: &Shape, options: &PartialOptions) -> Result<Self> {
        // The ranks first agree on the shape and options (a rank with others would exchange
        // other lengths), then each builds its part; a failure anywhere fails every rank.
        let key = [
            shape.degree_limit,
            shape.degree_min,
            shape.order_limit_alpha,
            shape.order_limit_gamma,
            shape.grid_bandwidth,
            shape.n_alpha,
            shape.n_gamma,
            options.real as usize,
            options.direction as usize,
            options.skip_bits.map_or(usize::MAX, |b| b as usize),
        ]
        .iter()
        .fold(0xcbf29ce484222325u64, |h, &v| {
            (h ^ v as u64).wrapping_mul(0x100000001b3)
        });
        // Both calls on every rank (collective): the largest key and the smallest.
        let (largest, smallest) = (comm.max(key)?, !comm.max(!key)?);
        if largest != smallest {
            return Err(Error::InvalidArgument(
                "the ranks of a distributed plan were given different shapes or options".into(),
            ));
        }
        let parts = collective(&comm, Self::build(&comm, shape, options))?;
        Ok(DistributedPlan {
            comm,
            shape: parts.shape,
            real: parts.real,
            direction: parts.direction,
            general: parts.general,
            shares: parts.shares,
            local: parts.local,
            local_coeffs: parts.local_coeffs,
            last: std::sync::Mutex::new(DistributedTimes::default()),
            rows: std::sync::Mutex::new(None),
            packed: std::sync::Mutex::new((Vec::new(), Vec::new())),
        })
    }

    /// What a rank whose arguments were bad calls instead of [`DistributedPlan::new`]: it
    /// takes part in the agreement with a key no rank can match, so every rank returns an
    /// error and none waits.
    pub fn refuse_collectively(comm: &X) -> Result<()> {
        // The others' largest key becomes u64::MAX and their smallest 0: they differ.
        comm.max(u64::MAX)?;
        comm.max(u64::MAX)?;
        Ok(())
    }

    fn build(comm: &X, shape: &Shape, options: &PartialOptions) -> Result<Parts> {
        shape.validate()?;
        if options.betas != Betas::All {
            return Err(Error::InvalidArgument(
                "a distributed plan evaluates every beta of the grid".into(),
            ));
        }
        if options.direction != Direction::Inverse {
            shape.check_forward()?;
        }
        let threads = crate::workers::thread_count(options.threads)?;
        let isa = Isa::resolve(options.isa)?;
        let bits = match options.skip_bits {
            None => crate::wigner::DEFAULT_SKIP_BITS,
            Some(b) => b,
        };
        let pairs = LanePairs::new(shape, &Betas::All)?;
        let np = pairs.pairs;
        // One chunk of every beta: a cluster's kernel call covers all lanes.
        let opts = PartialOptions {
            max_workspace_bytes: Some(usize::MAX / 4),
            ..options.clone()
        };
        let general = General::new(shape, pairs, (isa, bits, threads), &opts)?;
        let p = comm.size();
        let clusters = &general.dwt.clusters;
        let cost: Vec<usize> = clusters
            .iter()
            .map(|c| (shape.degree_limit - c.m) * c.p)
            .collect();
        let total: usize = cost.iter().sum();
        let mut bounds = vec![0usize; p + 1];
        let mut acc = 0;
        let mut r = 1;
        for (c, &w) in cost.iter().enumerate() {
            while r < p && acc >= total * r / p {
                bounds[r] = c;
                r += 1;
            }
            acc += w;
        }
        for b in bounds.iter_mut().skip(r) {
            *b = clusters.len();
        }
        bounds[p] = clusters.len();
        let offset = |c: usize| {
            clusters
                .get(c)
                .map_or(general.dwt.row_total, |cl| cl.offset)
        };
        let shares: Vec<Share> = (0..p)
            .map(|r| Share {
                pairs: (r * np / p, (r + 1) * np / p),
                clusters: (bounds[r], bounds[r + 1]),
                segment: (offset(bounds[r]), offset(bounds[r + 1])),
            })
            .collect();
        let me = &shares[comm.rank()];
        let mut local = Vec::new();
        let mut at = 0;
        for cl in &clusters[me.clusters.0..me.clusters.1] {
            let mut c = cl.clone();
            c.offset -= me.segment.0;
            let starts: Vec<usize> = c
                .slots
                .iter()
                .map(|s| {
                    let st = at;
                    at += shape.degree_limit - s.first;
                    st
                })
                .collect();
            // The real inverse reads a pair's partner, a member of the same cluster.
            let partner: Vec<usize> = c
                .slots
                .iter()
                .map(|s| {
                    c.slots
                        .iter()
                        .position(|t| t.member.m == -s.member.m && t.member.mp == -s.member.mp)
                        .map_or(usize::MAX, |i| starts[i])
                })
                .collect();
            for ((s, &st), &pt) in c.slots.iter_mut().zip(&starts).zip(&partner) {
                s.block = st;
                s.partner_block = pt;
            }
            local.push(c);
        }
        Ok(Parts {
            shape: *shape,
            real: options.real,
            direction: options.direction,
            general,
            shares,
            local,
            local_coeffs: at,
        })
    }

    /// Lane pairs `j0 .. j1` of this rank: it holds the slices `j0 .. j1`, then the slices
    /// `2 B_grid - j1 .. 2 B_grid - j0`.
    pub fn local_pairs(&self) -> (usize, usize) {
        self.shares[self.comm.rank()].pairs
    }

    /// Samples of this rank.
    pub fn local_num_samples(&self) -> usize {
        let (j0, j1) = self.local_pairs();
        2 * (j1 - j0) * self.shape.slice_len()
    }

    /// Coefficients of this rank.
    pub fn local_num_coeffs(&self) -> usize {
        self.local_coeffs
    }

    /// Where `fhat(l, m, mp)` is held: `(rank, index in that rank's coefficients)`, `None`
    /// when the shape does not hold it.
    pub fn coef_owner(&self, l: usize, m: isize, mp: isize) -> Option<(usize, usize)> {
        self.shape.coef_index(l, m, mp)?;
        let (a, b) = (m.unsigned_abs(), mp.unsigned_abs());
        let (bm, bmp) = (a.max(b), a.min(b));
        let c = self
            .general
            .dwt
            .clusters
            .iter()
            .position(|c| (c.m, c.mp) == (bm, bmp))?;
        let rank = self
            .shares
            .iter()
            .position(|s| (s.clusters.0..s.clusters.1).contains(&c))?;
        // Offsets within the owner's coefficients: count the blocks before this one.
        let mut at = 0;
        for cl in &self.general.dwt.clusters[self.shares[rank].clusters.0..c] {
            at += cl
                .slots
                .iter()
                .map(|s| self.shape.degree_limit - s.first)
                .sum::<usize>();
        }
        for s in &self.general.dwt.clusters[c].slots {
            if (s.member.m, s.member.mp) == (m, mp) {
                return Some((rank, at + l - s.first));
            }
            at += self.shape.degree_limit - s.first;
        }
        None
    }

    /// Index of `fhat(l, m, mp)` in this rank's coefficients, `None` if another rank (or no
    /// rank) holds it.
    pub fn local_coef_index(&self, l: usize, m: isize, mp: isize) -> Option<usize> {
        self.coef_owner(l, m, mp)
            .filter(|&(r, _)| r == self.comm.rank())
            .map(|(_, i)| i)
    }

    fn check(&self, forward: bool, real: bool, samples: usize, coeffs: usize) -> Result<()> {
        self.direction.check_runs(forward)?;
        if real && !self.real {
            return Err(Error::InvalidArgument(
                "real-signal transform on a plan made without the real option".into(),
            ));
        }
        check_length("local samples", self.local_num_samples(), samples)?;
        check_length("local coefficients", self.local_coeffs, coeffs)
    }

    /// Forward (collective): this rank's samples to this rank's coefficients.
    pub fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<()> {
        collective(
            &self.comm,
            self.check(true, false, samples.len(), coeffs.len()),
        )?;
        self.forward_impl(SendConstPtr(samples.as_ptr().cast()), coeffs, false)
    }

    /// Forward of real samples (collective; plan made with `real`).
    pub fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<()> {
        collective(
            &self.comm,
            self.check(true, true, samples.len(), coeffs.len()),
        )?;
        self.forward_impl(SendConstPtr(samples.as_ptr()), coeffs, true)
    }

    /// Inverse (collective): this rank's coefficients to this rank's samples.
    pub fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<()> {
        collective(
            &self.comm,
            self.check(false, false, samples.len(), coeffs.len()),
        )?;
        self.inverse_impl(coeffs, SendPtr(samples.as_mut_ptr().cast()), false)
    }

    /// Inverse to real samples (collective; reads the representatives as
    /// [`PartialPlan::inverse_real`](super::PartialPlan::inverse_real)).
    pub fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<()> {
        collective(
            &self.comm,
            self.check(false, true, samples.len(), coeffs.len()),
        )?;
        self.inverse_impl(coeffs, SendPtr(samples.as_mut_ptr()), true)
    }

    /// Times of this rank's part of the last transform.
    pub fn last_times(&self) -> DistributedTimes {
        *self.last.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// Bytes this rank holds during a transform besides its arrays: the lane rows of its
    /// slices (all clusters) and of its clusters (all betas); the exchange adds one packed
    /// block for one other rank at a time, and the plan's tables and per-worker FFT buffers
    /// come on top (`O(L^2)` and a few slices).
    pub fn local_workspace_bytes(&self) -> usize {
        let (loc, all) = (self.local_lanes(), self.all_lanes());
        let rows = 2 * loc.h * loc.row_len + all.lanes() * all.row_len;
        8 * rows
    }

    /// The two row buffers, taken from the plan (or new when another call has them), at
    /// their sizes: `a` for this rank's slices, `b` for this rank's clusters.
    fn take_rows(&self) -> Result<(Rows, Rows)> {
        let (loc, all) = (self.local_lanes(), self.all_lanes());
        let (na, nb) = (2 * loc.h * loc.row_len, all.lanes() * all.row_len);
        let kept = match self.rows.try_lock() {
            Ok(mut g) => g.take(),
            Err(_) => None,
        };
        match kept {
            Some((a, b)) if a.len == na && b.len == nb => Ok((a, b)),
            _ => Ok((Rows::new(na)?, Rows::new(nb)?)),
        }
    }

    fn put_rows(&self, rows: (Rows, Rows)) {
        if let Ok(mut g) = self.rows.try_lock() {
            *g = Some(rows);
        }
    }

    fn record(&self, t: DistributedTimes) {
        *self.last.lock().unwrap_or_else(|e| e.into_inner()) = t;
    }

    /// Lanes of the DWT stage: every pair, padded to the vector width.
    fn all_lanes(&self) -> ChunkLanes {
        let me = &self.shares[self.comm.rank()];
        let np = self.general.pairs.pairs;
        ChunkLanes {
            j0: 0,
            h: np,
            hp: np.next_multiple_of(self.general.lanes_w),
            row_len: me.segment.1 - me.segment.0,
        }
    }

    /// This rank's lane rows in the FFT stage's layout: `2 h` rows of `row_total`.
    fn local_lanes(&self) -> ChunkLanes {
        let (j0, j1) = self.local_pairs();
        ChunkLanes {
            j0,
            h: j1 - j0,
            hp: j1 - j0,
            row_len: self.general.dwt.row_total,
        }
    }

    /// Slice `s` of this rank's samples: `(pair within the rank, upper)`.
    fn local_slices(&self) -> Vec<(usize, bool)> {
        let h = self.local_lanes().h;
        (0..h)
            .map(|jj| (jj, false))
            .chain((0..h).rev().map(|jj| (jj, true)))
            .collect()
    }

    /// The exchange between the FFT stage's rows (`a`: this rank's pairs, every cluster) and
    /// the DWT stage's rows (`b`: every pair, this rank's clusters). `to_dwt`: `a` to `b`.
    /// Rank `r` sends to `r + k` and receives from `r - k` in step `k` (one packed block at a
    /// time); its own part is copied directly.
    fn exchange(&self, a: &mut [f64], b: &mut [f64], to_dwt: bool) -> Result<()> {
        let (me, p) = (self.comm.rank(), self.comm.size());
        let rt = self.general.dwt.row_total;
        let all = self.all_lanes();
        let mine = &self.shares[me];
        let my_len = mine.segment.1 - mine.segment.0;
        let ha = mine.pairs.1 - mine.pairs.0;
        // Row `i < 2 h_q` of rank q's pairs in `b`: lower rows at the pair, upper at hp + pair.
        let b_row = |share: &Share, i: usize| {
            let hq = share.pairs.1 - share.pairs.0;
            if i < hq {
                share.pairs.0 + i
            } else {
                all.hp + share.pairs.0 + i - hq
            }
        };
        // `a`'s part for rank q: rows `0..2 ha`, columns of q's segment.
        let a_block = |share: &Share| (share.segment.0, share.segment.1 - share.segment.0);
        let (mut send, mut recv) = match self.packed.try_lock() {
            Ok(mut g) => std::mem::take(&mut *g),
            Err(_) => (Vec::new(), Vec::new()),
        };
        for step in 0..p {
            let (dest, src) = ((me + step) % p, (me + p - step) % p);
            let (sd, ss) = (&self.shares[dest], &self.shares[src]);
            if to_dwt {
                let (col, len) = a_block(sd);
                let h_src = ss.pairs.1 - ss.pairs.0;
                if step == 0 {
                    for i in 0..2 * ha {
                        let r = b_row(mine, i);
                        b[r * my_len..][..my_len].copy_from_slice(&a[i * rt + col..][..len]);
                    }
                    continue;
                }
                send.clear();
                for i in 0..2 * ha {
                    send.extend_from_slice(&a[i * rt + col..][..len]);
                }
                recv.resize(2 * h_src * my_len, 0.0);
                self.comm.sendrecv(&send, dest, &mut recv, src)?;
                for i in 0..2 * h_src {
                    let r = b_row(ss, i);
                    b[r * my_len..][..my_len].copy_from_slice(&recv[i * my_len..][..my_len]);
                }
            } else {
                let (col, len) = a_block(ss);
                let h_dest = sd.pairs.1 - sd.pairs.0;
                if step == 0 {
                    for i in 0..2 * ha {
                        let r = b_row(mine, i);
                        a[i * rt + col..][..len].copy_from_slice(&b[r * my_len..][..my_len]);
                    }
                    continue;
                }
                send.clear();
                for i in 0..2 * h_dest {
                    let r = b_row(sd, i);
                    send.extend_from_slice(&b[r * my_len..][..my_len]);
                }
                recv.resize(2 * ha * len, 0.0);
                self.comm.sendrecv(&send, dest, &mut recv, src)?;
                for i in 0..2 * ha {
                    a[i * rt + col..][..len].copy_from_slice(&recv[i * len..][..len]);
                }
            }
        }
        if let Ok(mut g) = self.packed.try_lock() {
            *g = (send, recv);
        }
        Ok(())
    }

    fn forward_impl(
        &self,
        inp: SendConstPtr<f64>,
        coeffs: &mut [Complex64],
        real: bool,
    ) -> Result<()> {
        let g = &self.general;
        let loc = self.local_lanes();
        let all = self.all_lanes();
        let slice_len = self.shape.slice_len();
        let (mut a, mut b) = self.take_rows()?;
        let a_ptr = SendPtr(a.as_mut_ptr());
        let per_value = if real { 1 } else { 2 };
        let slices = self.local_slices();
        let start = std::time::Instant::now();
        let done: Result<()> = g.workers.pool().install(|| {
            slices
                .par_iter()
                .enumerate()
                .try_for_each(|(s, &(jj, upper))| {
                    g.with_work(|work| {
                        let rows = g.lane_rows(a_ptr.get(), 0, loc, (jj, upper));
                        let weight = g.pair_weight[loc.j0 + jj];
                        // SAFETY: local slice `s` is inside the checked local samples; the slots
                        // written are this slice's, of its two rows of `a` (`2 h` rows of
                        // `row_total`); its mirror writes the other slots of the same rows.
                        unsafe {
                            let at = s * slice_len * per_value;
                            if real {
                                let w = g.fft.half_buf(work)?;
                                g.fft.forward_real(w, inp.get().add(at));
                                g.gather_real(w, rows, weight);
                            } else {
                                let w = g.fft.fwd_buf(work)?;
                                g.fft.forward(w, inp.get().add(at).cast());
                                g.gather(w, rows, weight);
                            }
                        }
                        Ok(())
                    })
                })
        });
        collective(&self.comm, done)?;
        let t1 = std::time::Instant::now();
        self.exchange(&mut a[..], &mut b[..], true)?;
        // Padding lanes: the kernel multiplies them by exact zeros, which must not meet a
        // non-finite value an inverse left there.
        for half in 0..2 {
            let from = half * all.hp + all.h;
            b[from * all.row_len..(half * all.hp + all.hp) * all.row_len].fill(0.0);
        }
        let t2 = std::time::Instant::now();
        let b_ptr = SendPtr(b.as_mut_ptr());
        let coef = SendPtr(coeffs.as_mut_ptr());
        g.workers.pool().install(|| {
            self.local.par_iter().for_each(|cl| {
                g.dwt.with_scratch(|sc| {
                    let n = g.dwt.setup(sc, cl, &g.pairs, all);
                    // SAFETY: this cluster's slots of `b`'s lane rows (padding rows zero, the
                    // others filled by the exchange); its coefficient blocks are inside the
                    // local coefficients (checked length) and this task's.
                    unsafe {
                        g.dwt
                            .forward(sc, cl, all, n, b_ptr.get().add(cl.offset), coef.get(), true)
                    }
                })
            })
        });
        let t3 = std::time::Instant::now();
        self.record(DistributedTimes {
            fft: (t1 - start).as_secs_f64(),
            exchange: (t2 - t1).as_secs_f64(),
            dwt: (t3 - t2).as_secs_f64(),
            total: (t3 - start).as_secs_f64(),
        });
        self.put_rows((a, b));
        Ok(())
    }

    fn inverse_impl(&self, coeffs: &[Complex64], out: SendPtr<f64>, real: bool) -> Result<()> {
        let g = &self.general;
        let loc = self.local_lanes();
        let all = self.all_lanes();
        let slice_len = self.shape.slice_len();
        let start = std::time::Instant::now();
        let (mut a, mut b) = self.take_rows()?;
        let b_ptr = SendPtr(b.as_mut_ptr());
        let coef = SendConstPtr(coeffs.as_ptr());
        g.workers.pool().install(|| {
            self.local.par_iter().for_each(|cl| {
                g.dwt.with_scratch(|sc| {
                    let n = g.dwt.setup(sc, cl, &g.pairs, all);
                    // SAFETY: the local coefficients (checked length), read only; this
                    // cluster's slots of `b`'s lane rows, written by this task only.
                    unsafe {
                        g.dwt.inverse(
                            sc,
                            cl,
                            all,
                            n,
                            coef.get(),
                            (real, false),
                            b_ptr.get().add(cl.offset),
                        )
                    }
                })
            })
        });
        let t1 = std::time::Instant::now();
        self.exchange(&mut a[..], &mut b[..], false)?;
        let t2 = std::time::Instant::now();
        let a_ptr = SendPtr(a.as_mut_ptr());
        let slices = self.local_slices();
        let done: Result<()> = g.workers.pool().install(|| {
            slices
                .par_iter()
                .enumerate()
                .try_for_each(|(s, &(jj, upper))| {
                    g.with_work(|work| {
                        let rows = g.lane_rows(a_ptr.get(), 0, loc, (jj, upper));
                        // SAFETY: the rows of `a` were filled by the exchange (finished); local
                        // slice `s` is inside the checked local samples and this task's.
                        unsafe {
                            if real {
                                let w = g.fft.half_buf(work)?;
                                g.scatter_real(w, rows);
                                g.fft.inverse_real(w, out.get().add(s * slice_len));
                            } else {
                                let w = g.fft.inv_buf(work)?;
                                g.scatter(w, rows);
                                g.fft
                                    .inverse(w, out.get().cast::<Complex64>().add(s * slice_len));
                            }
                        }
                        Ok(())
                    })
                })
        });
        let t3 = std::time::Instant::now();
        self.record(DistributedTimes {
            dwt: (t1 - start).as_secs_f64(),
            exchange: (t2 - t1).as_secs_f64(),
            fft: (t3 - t2).as_secs_f64(),
            total: (t3 - start).as_secs_f64(),
        });
        self.put_rows((a, b));
        collective(&self.comm, done)
    }
}

/// An [`Exchange`] among threads of one process (for tests and for trying the distributed
/// layout without MPI): [`ThreadExchange::group`] makes the members, one per thread.
pub struct ThreadExchange {
    rank: usize,
    shared: std::sync::Arc<Shared>,
}

struct Shared {
    size: usize,
    barrier: std::sync::Barrier,
    mailbox: std::sync::Mutex<Vec<Vec<f64>>>,
    values: std::sync::Mutex<Vec<u64>>,
}

impl ThreadExchange {
    /// `size` members, rank `r` at index `r`; each must be used by its own thread.
    pub fn group(size: usize) -> Vec<ThreadExchange> {
        let shared = std::sync::Arc::new(Shared {
            size,
            barrier: std::sync::Barrier::new(size),
            mailbox: std::sync::Mutex::new(vec![Vec::new(); size * size]),
            values: std::sync::Mutex::new(vec![0; size]),
        });
        (0..size)
            .map(|rank| ThreadExchange {
                rank,
                shared: shared.clone(),
            })
            .collect()
    }
}

impl Exchange for ThreadExchange {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.shared.size
    }

    fn sendrecv(&self, send: &[f64], dest: usize, recv: &mut [f64], src: usize) -> Result<()> {
        let (p, me) = (self.shared.size, self.rank);
        {
            let mut mail = self
                .shared
                .mailbox
                .lock()
                .unwrap_or_else(|e| e.into_inner());
            mail[me * p + dest] = send.to_vec();
        }
        self.shared.barrier.wait();
        let data = {
            let mut mail = self
                .shared
                .mailbox
                .lock()
                .unwrap_or_else(|e| e.into_inner());
            std::mem::take(&mut mail[src * p + me])
        };
        self.shared.barrier.wait();
        if data.len() != recv.len() {
            return Err(Error::InvalidArgument(
                "exchange: message lengths differ".into(),
            ));
        }
        recv.copy_from_slice(&data);
        Ok(())
    }

    fn max(&self, value: u64) -> Result<u64> {
        self.shared.values.lock().unwrap_or_else(|e| e.into_inner())[self.rank] = value;
        self.shared.barrier.wait();
        let m = self
            .shared
            .values
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .iter()
            .copied()
            .max()
            .unwrap_or(0);
        self.shared.barrier.wait();
        Ok(m)
    }
}
