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
//!   see `dwt_stage.rs`); an all-to-all exchange sends each rank the segment of every lane
//!   row that holds its clusters; the DWT stage then runs each local cluster over the betas.
//!   The inverse runs the same steps backwards.
//! - Groups: to bound the memory, the pairs run in groups (every rank's first pairs, then
//!   its next ones, ...): FFT stage, exchange and DWT stage per group, the forward summing
//!   each cluster over the groups. The lane tables list the pairs group after group, so a
//!   group's lanes are one contiguous run.
//! - In one group (the default whenever the rows fit in the workspace cap) each lane is one
//!   kernel lane and a cluster's kernel call covers all betas, as in a single-process
//!   [`PartialPlan`](crate::PartialPlan) whose chunk holds every beta: the results are
//!   bitwise equal. With several groups the forward adds the same terms in another order.

use super::exchange::Exchange;
use crate::dwt::Prefetch;
use crate::engine::{padded_row, ChunkLanes, ClusterPlan, Engine, LanePairs, LaneRows};
use crate::error::{check_length, Error, Result};
use crate::fft::AlignedBuf;
use crate::options::{Betas, Direction, Options};
use crate::shape::Shape;
use crate::simd::Isa;
use crate::transform::StageTimes;
use crate::transform::{Scratch, Transform};
use crate::workers::{SendConstPtr, SendPtr};
use num_complex::Complex64;
use rayon::prelude::*;

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

/// A rank's share of the betas and the clusters.
struct Share {
    /// Lane pairs `j0 .. j1`.
    pairs: (usize, usize),
    /// Clusters `c0 .. c1` (indices into the DWT stage's cluster list).
    clusters: (usize, usize),
}

/// The lane rows of one member set (every member, or the real transforms' `M' >= 0`, see
/// `Engine::members`): where each rank's clusters are in a lane row, and this rank's
/// clusters.
struct RankView {
    /// Per rank, its clusters' doubles in a lane row: `offset(c0) .. offset(c1)`.
    segments: Vec<(usize, usize)>,
    /// This rank's clusters, their blocks at local coefficient offsets and their slots at
    /// offsets within its segment of a lane row.
    local: Vec<ClusterPlan>,
}

/// Where one group's rows are on a rank.
struct GroupRows {
    /// The DWT stage's lanes of the group (every rank's pairs), rows of the rank's segment.
    ch: ChunkLanes,
    /// Per rank: its pairs' offset among the group's lanes, and their number.
    parts: Vec<(usize, usize)>,
    /// Per rank (not this one): its block in `a`, `(first double, row length)`; rows
    /// `0 .. n_me` lower, `n_me .. 2 n_me` mirrors.
    blocks: Vec<(usize, usize)>,
    /// This rank's pairs in the group.
    n_me: usize,
}

/// The transforms of a [`Shape`] over the ranks of an [`Exchange`].
pub struct DistributedPlan<X: Exchange> {
    comm: X,
    parts: Parts,
    /// The FFT stage's lane rows of other ranks' clusters (`a`) and the DWT stage's lane
    /// rows (`b`), kept between transforms.
    rows: std::sync::Mutex<Option<(Rows, Rows)>>,
}

/// The classes of errors the ranks agree on (those of the C error codes), by priority.
const INVALID: u64 = 1;
const BANDWIDTH: u64 = 2;
const DIRECTION: u64 = 3;
const FFTW: u64 = 4;
const NO_MEMORY: u64 = 5;

fn error_class(e: &Error) -> u64 {
    match e {
        Error::InvalidArgument(_) | Error::LengthMismatch { .. } => INVALID,
        Error::InvalidBandwidth { .. } => BANDWIDTH,
        Error::WrongDirection => DIRECTION,
        Error::Fftw(_) => FFTW,
        Error::OutOfMemory { .. } | Error::Resources(_) => NO_MEMORY,
    }
}

/// An error on every rank if it is one on any, of the same class everywhere (agreed through
/// `comm`: the highest class of the ranks' errors): a rank whose own error is of that class
/// returns it, the others an error of that class saying that another rank failed.
fn collective<X: Exchange, T>(comm: &X, r: Result<T>) -> Result<T> {
    let class = comm.max(r.as_ref().err().map_or(0, error_class))?;
    if class == 0 {
        return r;
    }
    // Every rank knows that one failed; for memory, they also agree on the largest request.
    let bytes = match &r {
        Err(Error::OutOfMemory { bytes }) => *bytes as u64,
        _ => 0,
    };
    let bytes = if class == NO_MEMORY {
        comm.max(bytes)? as usize
    } else {
        0
    };
    let other = "another rank of the distributed plan failed (see its error)";
    match r {
        Err(e) if error_class(&e) == class => Err(e),
        _ => Err(match class {
            NO_MEMORY => Error::OutOfMemory { bytes },
            FFTW => Error::Fftw(other.into()),
            DIRECTION => Error::WrongDirection,
            BANDWIDTH => Error::InvalidBandwidth {
                bandwidth: 0,
                max: crate::MAX_BANDWIDTH,
            },
            _ => Error::InvalidArgument(other.into()),
        }),
    }
}

/// Pairs of a rank's range `(j0, j1)` in group `k` of `groups`.
fn group_range((j0, j1): (usize, usize), k: usize, groups: usize) -> (usize, usize) {
    let h = j1 - j0;
    (j0 + k * h / groups, j0 + (k + 1) * h / groups)
}

/// Doubles of rank `rank`'s two buffers when the transforms run in `groups` groups, for
/// rows of every rank's segment of `widths` doubles (padded, see [`RankView::widths`]) and vectors of `w` lanes:
/// `a`, the lane rows of its slices in one group for the other ranks' clusters, and `b`,
/// the group's lane rows of its own clusters (every rank's pairs, padded to vectors).
fn row_sizes(
    (shares, widths): (&[Share], &[usize]),
    rank: usize,
    groups: usize,
    w: usize,
) -> (usize, usize) {
    let count = |r: usize, k: usize| {
        let (g0, g1) = group_range(shares[r].pairs, k, groups);
        g1 - g0
    };
    let n_me = (0..groups).map(|k| count(rank, k)).max().unwrap_or(0);
    let hp = (0..groups)
        .map(|k| (0..shares.len()).map(|r| count(r, k)).sum::<usize>())
        .max()
        .unwrap_or(0)
        .next_multiple_of(w);
    let others: usize = widths.iter().sum::<usize>() - widths[rank];
    (2 * n_me * others, 2 * hp * widths[rank])
}

impl RankView {
    /// Every rank's row length in the row buffers: its segment, padded ([`padded_row`]).
    fn widths(&self) -> Vec<usize> {
        self.segments
            .iter()
            .map(|s| padded_row::<f64>(s.1 - s.0))
            .collect()
    }
}

/// What a rank builds of a plan (everything but the exchange and the buffers).
struct Parts {
    shape: Shape,
    real: bool,
    direction: Direction,
    general: Engine,
    shares: Vec<Share>,
    /// The lane rows of every member, and with `real` those of the real transforms.
    views: Vec<RankView>,
    local_coeffs: usize,
    /// Groups of pairs the transforms run in (see [`DistributedPlan::groups`]).
    groups: usize,
}

impl<X: Exchange> DistributedPlan<X> {
    /// A plan for `shape` over the ranks of `comm` (collective; every rank passes the same
    /// shape and options). `options.betas` must be [`Betas::All`]; batches are not offered.
    pub fn new(comm: X, shape: &Shape, options: &Options) -> Result<Self> {
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
            options.max_workspace_bytes.unwrap_or(0),
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
            parts,
            rows: std::sync::Mutex::new(None),
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

    fn build(comm: &X, shape: &Shape, options: &Options) -> Result<Parts> {
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
        let skip = options.skip()?;
        options.check_workspace()?;
        let pairs = LanePairs::new(shape, &Betas::All, None)?;
        let np = pairs.pairs;
        // One chunk of every beta: a cluster's kernel call covers all lanes.
        let opts = Options {
            max_workspace_bytes: Some(usize::MAX / 4),
            ..options.clone()
        };
        let mut general = Engine::new(shape, pairs, (isa, skip, threads), &opts, None)?;
        let p = comm.size();
        let clusters = &general.dwt.clusters;
        // A cluster's DWT work: its degrees times its columns, plus what each cluster costs
        // besides the kernel's steps (starting values, recurrence coefficients, gathers and
        // scatters of its coefficients), about `CLUSTER_STEPS` steps.
        const CLUSTER_STEPS: usize = 12;
        let cost: Vec<usize> = clusters
            .iter()
            .map(|c| (shape.degree_limit - c.m + CLUSTER_STEPS) * c.p)
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
        let shares: Vec<Share> = (0..p)
            .map(|r| Share {
                pairs: (r * np / p, (r + 1) * np / p),
                clusters: (bounds[r], bounds[r + 1]),
            })
            .collect();
        // Every rank's segment of a lane row of the clusters `all`.
        let segments = |all: &[ClusterPlan], row_total: usize| -> Vec<(usize, usize)> {
            let offset = |c: usize| all.get(c).map_or(row_total, |cl| cl.offset);
            shares
                .iter()
                .map(|s| (offset(s.clusters.0), offset(s.clusters.1)))
                .collect()
        };
        let me = &shares[comm.rank()];
        let full_segments = segments(clusters, general.dwt.row_total);
        let seg0 = full_segments[comm.rank()].0;
        let mut local = Vec::new();
        let mut at = 0;
        for cl in &clusters[me.clusters.0..me.clusters.1] {
            let mut c = cl.clone();
            c.offset -= seg0;
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
        let mut views = vec![RankView {
            segments: full_segments,
            local,
        }];
        if options.real {
            // The real transforms' clusters (the same clusters, members `M' >= 0`), their
            // slots at the blocks of the same members in the local coefficients.
            let half = general.members(true).dwt;
            assert_eq!(half.clusters.len(), clusters.len());
            let segments = segments(&half.clusters, half.row_total);
            let seg0 = segments[comm.rank()].0;
            let local = half.clusters[me.clusters.0..me.clusters.1]
                .iter()
                .zip(&views[0].local)
                .map(|(cl, full)| {
                    let block = |m: isize, mp: isize| {
                        full.slots
                            .iter()
                            .find(|s| (s.member.m, s.member.mp) == (m, mp))
                            .map_or(usize::MAX, |s| s.block)
                    };
                    let mut c = cl.clone();
                    c.offset -= seg0;
                    for s in &mut c.slots {
                        s.block = block(s.member.m, s.member.mp);
                        s.partner_block = block(-s.member.m, -s.member.mp);
                    }
                    c
                })
                .collect();
            views.push(RankView { segments, local });
        }
        // Every rank computes the same group count: from every rank's sizes and budget.
        let widths = views[0].widths();
        let sample_bytes = if options.real { 8 } else { 16 };
        let coeffs_of = |share: &Share| -> usize {
            clusters[share.clusters.0..share.clusters.1]
                .iter()
                .flat_map(|c| c.slots.iter())
                .map(|sl| shape.degree_limit - sl.first)
                .sum()
        };
        let budget = |share: &Share| {
            options.max_workspace_bytes.unwrap_or_else(|| {
                let h = share.pairs.1 - share.pairs.0;
                let arrays = sample_bytes * 2 * h * shape.slice_len() + 16 * coeffs_of(share);
                Options::default_workspace(arrays)
            })
        };
        let most = shares
            .iter()
            .map(|sh| sh.pairs.1 - sh.pairs.0)
            .filter(|&h| h > 0)
            .min()
            .unwrap_or(1);
        let groups = (1..=most)
            .find(|&k| {
                (0..p).all(|r| {
                    let (a, b) = row_sizes((&shares, &widths), r, k, general.lanes_w());
                    8 * (a + b) <= budget(&shares[r])
                })
            })
            .unwrap_or(most);
        if groups > 1 {
            // Lanes in group order: group 0 of every rank, then group 1, ..., so that each
            // group's lanes are a contiguous run of the kernels' lane tables.
            let order: Vec<usize> = (0..groups)
                .flat_map(|k| {
                    let shares = &shares;
                    (0..p).flat_map(move |r| {
                        let (g0, g1) = group_range(shares[r].pairs, k, groups);
                        g0..g1
                    })
                })
                .collect();
            general.pairs = LanePairs::new(shape, &Betas::Indices(order), None)?;
        }
        Ok(Parts {
            shape: *shape,
            real: options.real,
            direction: options.direction,
            general,
            shares,
            views,
            local_coeffs: at,
            groups,
        })
    }

    /// Lane pairs `j0 .. j1` of this rank: it holds the slices `j0 .. j1`, then the slices
    /// `2 B_grid - j1 .. 2 B_grid - j0`.
    pub fn local_pairs(&self) -> (usize, usize) {
        self.parts.shares[self.comm.rank()].pairs
    }

    /// Samples of this rank.
    pub fn local_num_samples(&self) -> usize {
        let (j0, j1) = self.local_pairs();
        2 * (j1 - j0) * self.parts.shape.slice_len()
    }

    /// Coefficients of this rank.
    pub fn local_num_coeffs(&self) -> usize {
        self.parts.local_coeffs
    }

    /// Where `fhat(l, m, mp)` is held: `(rank, index in that rank's coefficients)`, `None`
    /// when the shape does not hold it.
    pub fn coef_owner(&self, l: usize, m: isize, mp: isize) -> Option<(usize, usize)> {
        self.parts.shape.coef_index(l, m, mp)?;
        let (a, b) = (m.unsigned_abs(), mp.unsigned_abs());
        let (bm, bmp) = (a.max(b), a.min(b));
        let c = self
            .parts
            .general
            .dwt
            .clusters
            .iter()
            .position(|c| (c.m, c.mp) == (bm, bmp))?;
        let rank = self
            .parts
            .shares
            .iter()
            .position(|s| (s.clusters.0..s.clusters.1).contains(&c))?;
        // Offsets within the owner's coefficients: count the blocks before this one.
        let mut at = 0;
        for cl in &self.parts.general.dwt.clusters[self.parts.shares[rank].clusters.0..c] {
            at += cl
                .slots
                .iter()
                .map(|s| self.parts.shape.degree_limit - s.first)
                .sum::<usize>();
        }
        for s in &self.parts.general.dwt.clusters[c].slots {
            if (s.member.m, s.member.mp) == (m, mp) {
                return Some((rank, at + l - s.first));
            }
            at += self.parts.shape.degree_limit - s.first;
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
        self.parts.general.workers.check_process()?;
        self.parts.direction.check_runs(forward)?;
        if real && !self.parts.real {
            return Err(Error::InvalidArgument(
                "real-signal transform on a plan made without the real option".into(),
            ));
        }
        check_length("local samples", self.local_num_samples(), samples)?;
        check_length("local coefficients", self.parts.local_coeffs, coeffs)
    }

    /// Forward (collective): this rank's samples to this rank's coefficients; the time of
    /// each stage on this rank.
    pub fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        let inp = (SendConstPtr(samples.as_ptr().cast()), samples.len());
        self.forward_impl(inp, coeffs, (false, None))
    }

    /// Forward of real samples (collective; plan made with `real`).
    pub fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        let inp = (SendConstPtr(samples.as_ptr()), samples.len());
        self.forward_impl(inp, coeffs, (true, None))
    }

    /// Inverse (collective): this rank's coefficients to this rank's samples; the time of
    /// each stage on this rank.
    pub fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<StageTimes> {
        let out = (SendPtr(samples.as_mut_ptr().cast()), samples.len());
        self.inverse_impl(coeffs, out, (false, None))
    }

    /// Inverse to real samples (collective; reads the representatives as
    /// [`PartialPlan::inverse_real`](crate::PartialPlan::inverse_real)).
    pub fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<StageTimes> {
        let out = (SendPtr(samples.as_mut_ptr()), samples.len());
        self.inverse_impl(coeffs, out, (true, None))
    }

    /// Bytes this rank holds during a transform besides its arrays (known at plan time, taken
    /// at the first transform and kept): the lane rows of its slices in one group of pairs
    /// for the other ranks' clusters, and the group's lane rows of its own clusters (every
    /// rank's pairs of the group). The plan's tables and per-worker FFT buffers come on top
    /// (`O(B L)` and a few slices).
    pub fn local_workspace_bytes(&self) -> usize {
        let (a, b) = self.row_sizes();
        8 * (a + b)
    }

    /// Number of groups of pairs a transform runs in: the fewest whose buffers fit every
    /// rank's workspace cap (`Options::max_workspace_bytes`, by default
    /// [`Options::default_workspace`] of the rank's arrays). With one group the results are bitwise
    /// those of a single-process plan; with more, the forward sums each cluster over the
    /// groups in turn (a different order of the same sum, equal to rounding).
    pub fn groups(&self) -> usize {
        self.parts.groups
    }

    /// The lane rows of the complex transforms, or of the real ones (`real`).
    fn view(&self, real: bool) -> &RankView {
        &self.parts.views[usize::from(real).min(self.parts.views.len() - 1)]
    }

    /// The sizes of the two row buffers (those of every member: the real transforms' rows
    /// are shorter and fit).
    fn row_sizes(&self) -> (usize, usize) {
        row_sizes(
            (&self.parts.shares, &self.parts.views[0].widths()),
            self.comm.rank(),
            self.parts.groups,
            self.parts.general.lanes_w(),
        )
    }

    /// The two row buffers, taken from the plan (or new when another call has them), at
    /// their sizes: `a` for this rank's slices, `b` for this rank's clusters.
    fn take_rows(&self) -> Result<(Rows, Rows)> {
        let (na, nb) = self.row_sizes();
        let kept = match self.rows.try_lock() {
            Ok(mut g) => g.take(),
            Err(_) => None,
        };
        match kept {
            Some((a, b)) if a.len == na && b.len == nb => Ok((a, b)),
            _ => Ok((Rows::new(na)?, Rows::new(nb)?)),
        }
    }

    /// Runs `f` on the two row buffers (see [`DistributedPlan::take_rows`]): in the
    /// caller's `scratch` if given (collective: a scratch too small on any rank fails
    /// every rank), else the plan's.
    fn with_rows<R>(
        &self,
        scratch: Option<&mut Scratch>,
        f: impl FnOnce(&mut [f64], &mut [f64]) -> Result<R>,
    ) -> Result<R> {
        let (na, nb) = self.row_sizes();
        let gap = na.next_multiple_of(8);
        match scratch {
            Some(s) => {
                let rows = collective(&self.comm, s.doubles(gap + nb))?;
                let (a, b) = rows.split_at_mut(gap);
                f(&mut a[..na], b)
            }
            None => {
                let (mut a, mut b) = collective(&self.comm, self.take_rows())?;
                let r = f(&mut a, &mut b);
                self.put_rows((a, b));
                r
            }
        }
    }

    fn put_rows(&self, rows: (Rows, Rows)) {
        if let Ok(mut g) = self.rows.try_lock() {
            *g = Some(rows);
        }
    }

    /// Where the rows of group `k` are on this rank (made once per group of a transform).
    fn group_rows(&self, k: usize, view: &RankView) -> GroupRows {
        let (me, shares) = (self.comm.rank(), &self.parts.shares);
        let counts: Vec<usize> = shares
            .iter()
            .map(|s| {
                let (g0, g1) = group_range(s.pairs, k, self.parts.groups);
                g1 - g0
            })
            .collect();
        let offsets: Vec<usize> = counts
            .iter()
            .scan(0, |at, &n| {
                *at += n;
                Some(*at - n)
            })
            .collect();
        let first: usize = shares
            .iter()
            .map(|s| group_range(s.pairs, k, self.parts.groups).0 - s.pairs.0)
            .sum();
        let h: usize = counts.iter().sum();
        let n_me = counts[me];
        let widths = view.widths();
        let width = |q: usize| widths[q];
        let mut at = 0;
        let blocks = (0..shares.len())
            .map(|q| {
                let block = (at, width(q));
                if q != me {
                    at += 2 * n_me * width(q);
                }
                block
            })
            .collect();
        let hp = h.next_multiple_of(self.parts.general.lanes_w());
        GroupRows {
            ch: ChunkLanes {
                j0: first,
                h,
                hp,
                row_len: width(me),
                upper_gap: hp * width(me),
                first_upper_pair: None,
            },
            parts: offsets.into_iter().zip(counts).collect(),
            blocks,
            n_me,
        }
    }

    /// A slice's lane rows in group `gr` (`jj`: its pair within this rank's pairs of the
    /// group), one part per rank's clusters: this rank's in `b` (where the DWT stage runs
    /// on them), the others' in their blocks of `a` (sent and received whole).
    fn slice_parts(
        &self,
        (a, b): (*mut f64, *mut f64),
        (gr, view): (&GroupRows, &RankView),
        (jj, upper): (usize, bool),
    ) -> Vec<LaneRows> {
        let me = self.comm.rank();
        self.parts
            .shares
            .iter()
            .enumerate()
            .map(|(q, sh)| {
                // Rows of the part: base, rows per half, this pair's row, row length.
                let (base, half, lane, len) = if q == me {
                    (b, gr.ch.hp, gr.parts[me].0 + jj, gr.ch.row_len)
                } else {
                    let (at, len) = gr.blocks[q];
                    (a.wrapping_add(at), gr.n_me, jj, len)
                };
                let (r, rm) = if upper {
                    (half + lane, lane)
                } else {
                    (lane, half + lane)
                };
                let rows = (base.wrapping_add(r * len), base.wrapping_add(rm * len));
                LaneRows::part(rows, sh.clusters, view.segments[q].0)
            })
            .collect()
    }

    /// This rank's pairs of slices of group `k`: `(pair within the group, [index of the
    /// lower slice, of the upper one] in the local samples)`. The FFT stage handles both
    /// slices of a pair in one task (as the single-process plan).
    fn group_pairs(&self, k: usize) -> Vec<(usize, [usize; 2])> {
        let (j0, j1) = self.local_pairs();
        let h = j1 - j0;
        let (g0, g1) = group_range((j0, j1), k, self.parts.groups);
        (g0..g1)
            .map(|j| (j - g0, [j - j0, 2 * h - 1 - (j - j0)]))
            .collect()
    }

    /// The exchange of group `gr` between `a` (this rank's slices, other ranks' clusters)
    /// and `b` (every rank's slices of the group, this rank's clusters). `to_dwt`: `a` to
    /// `b`. Rank `r` sends to `r + s` and receives from `r - s` in step `s`, lower rows then
    /// mirror rows; every block moves whole, from and into its place (nothing is packed).
    fn exchange(
        &self,
        (a, b): (&mut [f64], &mut [f64]),
        to_dwt: bool,
        gr: &GroupRows,
    ) -> Result<()> {
        let (me, p) = (self.comm.rank(), self.comm.size());
        let (ch, n_me) = (gr.ch, gr.n_me);
        let my_len = ch.row_len;
        for step in 1..p {
            let (dest, src) = ((me + step) % p, (me + p - step) % p);
            // The rank whose rows of `b` move and the rank whose columns of `a` move.
            let (other, q) = if to_dwt { (src, dest) } else { (dest, src) };
            let (off, n) = gr.parts[other];
            let (at, len) = gr.blocks[q];
            for half in 0..2 {
                let run = (half * ch.hp + off) * my_len..(half * ch.hp + off + n) * my_len;
                let block = at + half * n_me * len..at + (half + 1) * n_me * len;
                if to_dwt {
                    self.comm.sendrecv(&a[block], dest, &mut b[run], src)?;
                } else {
                    self.comm.sendrecv(&b[run], dest, &mut a[block], src)?;
                }
            }
        }
        Ok(())
    }

    /// A forward (collective) from `inp.1` samples at `inp.0` (complex values, or reals
    /// with `real`) after the checks, in the caller's `scratch` if given.
    fn forward_impl(
        &self,
        (inp, samples): (SendConstPtr<f64>, usize),
        coeffs: &mut [Complex64],
        (real, scratch): (bool, Option<&mut Scratch>),
    ) -> Result<StageTimes> {
        collective(&self.comm, self.check(true, real, samples, coeffs.len()))?;
        // A rank that cannot have its buffers fails every rank (none waits in an exchange).
        self.with_rows(scratch, |a, b| self.forward_rows(inp, coeffs, real, (a, b)))
    }

    fn forward_rows(
        &self,
        inp: SendConstPtr<f64>,
        coeffs: &mut [Complex64],
        real: bool,
        (a, b): (&mut [f64], &mut [f64]),
    ) -> Result<StageTimes> {
        let g = &self.parts.general;
        let (view, m) = (self.view(real), g.members(real));
        let slice_len = self.parts.shape.slice_len();
        let per_value = if real { 1 } else { 2 };
        let mut times = StageTimes::default();
        let start = std::time::Instant::now();
        for k in 0..self.parts.groups {
            let t0 = std::time::Instant::now();
            let gr = self.group_rows(k, view);
            let ch = gr.ch;
            let g0 = group_range(self.local_pairs(), k, self.parts.groups).0;
            let ab = (SendPtr(a.as_mut_ptr()), SendPtr(b.as_mut_ptr()));
            let pairs = self.group_pairs(k);
            let done: Result<()> = g.workers.pool().install(|| {
                pairs.par_iter().try_for_each(|&(jj, [s0, s1])| {
                    g.with_work(|work| {
                        let rows =
                            self.slice_parts((ab.0.get(), ab.1.get()), (&gr, view), (jj, false));
                        let weight = g.pair_weight[g0 + jj];
                        let at = |s: usize| s * slice_len * per_value;
                        // SAFETY: local slices `s0` and `s1` are inside the checked local
                        // samples; the slots written are the pair's, of its two rows in each
                        // part (in `a` and `b`, sized for the group), this task's alone.
                        unsafe {
                            if real {
                                let (w0, w1) = g.fft.half_pair(work)?;
                                g.fft.forward_real(w0, inp.get().add(at(s0)));
                                g.fft.forward_real(w1, inp.get().add(at(s1)));
                                g.gather_real_pair(m, (w0, w1), &rows, weight);
                            } else {
                                let (w0, w1) = g.fft.fwd_pair(work)?;
                                g.fft.forward(w0, inp.get().add(at(s0)).cast());
                                g.fft.forward(w1, inp.get().add(at(s1)).cast());
                                g.gather_pair(m, (w0, w1), &rows, weight);
                            }
                        }
                        Ok(())
                    })
                })
            });
            collective(&self.comm, done)?;
            let t1 = std::time::Instant::now();
            self.exchange((&mut *a, &mut *b), true, &gr)?;
            // Padding lanes: the kernel multiplies them by exact zeros, which must not meet
            // a non-finite value an inverse left there.
            for half in 0..2 {
                let from = half * ch.hp + ch.h;
                b[from * ch.row_len..(half + 1) * ch.hp * ch.row_len].fill(0.0);
            }
            let t2 = std::time::Instant::now();
            let b_ptr = SendPtr(b.as_mut_ptr());
            let coef = SendPtr(coeffs.as_mut_ptr());
            g.workers.pool().install(|| {
                let local = &view.local;
                local.par_iter().enumerate().for_each(|(i, cl)| {
                    m.dwt.with_scratch(|sc| {
                        let n = m.dwt.setup(sc, cl, &g.pairs, ch);
                        let next = local.get(i + 1).map_or(Prefetch::none(), |nc| {
                            let rows = b_ptr.get().wrapping_add(nc.offset);
                            m.dwt.forward_hints(nc, ch, rows, coef.get())
                        });
                        // SAFETY: this cluster's slots of `b`'s lane rows of the group
                        // (padding rows zero, the others filled by the exchange); its
                        // coefficient blocks are inside the local coefficients (checked
                        // length) and this task's.
                        unsafe {
                            let rows = b_ptr.get().add(cl.offset);
                            m.dwt
                                .forward(sc, cl, (ch, n), rows, (coef.get(), k == 0, next))
                        }
                    })
                })
            });
            let t3 = std::time::Instant::now();
            times.fft += (t1 - t0).as_secs_f64();
            times.exchange += (t2 - t1).as_secs_f64();
            times.dwt += (t3 - t2).as_secs_f64();
        }
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }

    /// An inverse (collective) into `out.1` samples at `out.0` (complex values, or reals
    /// with `real`) after the checks, in the caller's `scratch` if given.
    fn inverse_impl(
        &self,
        coeffs: &[Complex64],
        (out, samples): (SendPtr<f64>, usize),
        (real, scratch): (bool, Option<&mut Scratch>),
    ) -> Result<StageTimes> {
        collective(&self.comm, self.check(false, real, samples, coeffs.len()))?;
        // A rank that cannot have its buffers fails every rank (none waits in an exchange).
        self.with_rows(scratch, |a, b| self.inverse_rows(coeffs, out, real, (a, b)))
    }

    fn inverse_rows(
        &self,
        coeffs: &[Complex64],
        out: SendPtr<f64>,
        real: bool,
        (a, b): (&mut [f64], &mut [f64]),
    ) -> Result<StageTimes> {
        let g = &self.parts.general;
        let (view, m) = (self.view(real), g.members(real));
        let slice_len = self.parts.shape.slice_len();
        let start = std::time::Instant::now();
        let mut times = StageTimes::default();
        let mut done: Result<()> = Ok(());
        for k in 0..self.parts.groups {
            let t0 = std::time::Instant::now();
            let gr = self.group_rows(k, view);
            let ch = gr.ch;
            let b_ptr = SendPtr(b.as_mut_ptr());
            let coef = SendConstPtr(coeffs.as_ptr());
            // Rows far larger than the caches go out with non-temporal stores (as in the
            // single-process plan).
            let stream = 8 * b.len() > 8 << 20;
            let local = &view.local;
            g.workers.pool().install(|| {
                local.par_iter().enumerate().for_each(|(i, cl)| {
                    m.dwt.with_scratch(|sc| {
                        let n = m.dwt.setup(sc, cl, &g.pairs, ch);
                        // The coefficient blocks the next cluster (likely this task's next
                        // one) reads.
                        let next = local.get(i + 1).map_or(Prefetch::none(), |nc| {
                            m.dwt.coefficient_hints(nc, coef.get(), real)
                        });
                        // SAFETY: the local coefficients (checked length), read only; this
                        // cluster's slots of `b`'s lane rows of the group, written by this
                        // task only.
                        unsafe {
                            m.dwt.inverse(
                                sc,
                                cl,
                                ch,
                                n,
                                coef.get(),
                                (real, stream, next),
                                b_ptr.get().add(cl.offset),
                            )
                        }
                    })
                })
            });
            let t1 = std::time::Instant::now();
            self.exchange((&mut *a, &mut *b), false, &gr)?;
            let t2 = std::time::Instant::now();
            let ab = (SendPtr(a.as_mut_ptr()), SendPtr(b.as_mut_ptr()));
            let pairs = self.group_pairs(k);
            let group_done: Result<()> = g.workers.pool().install(|| {
                pairs.par_iter().try_for_each(|&(jj, [s0, s1])| {
                    g.with_work(|work| {
                        let rows =
                            self.slice_parts((ab.0.get(), ab.1.get()), (&gr, view), (jj, false));
                        // SAFETY: the parts' rows were written by the DWT stage (`b`) and
                        // the exchange (`a`), both finished; local slices `s0` and `s1` are
                        // inside the checked local samples and this task's.
                        unsafe {
                            if real {
                                let (w0, w1) = g.fft.half_pair(work)?;
                                g.scatter_real_pair(m, (w0, w1), &rows);
                                g.fft.inverse_real(w0, out.get().add(s0 * slice_len), None);
                                g.fft.inverse_real(w1, out.get().add(s1 * slice_len), None);
                            } else {
                                let (w0, w1) = g.fft.inv_pair(work)?;
                                g.scatter_pair(m, (w0, w1), &rows);
                                let o = out.get().cast::<Complex64>();
                                g.fft.inverse(w0, o.add(s0 * slice_len), None);
                                g.fft.inverse(w1, o.add(s1 * slice_len), None);
                            }
                        }
                        Ok(())
                    })
                })
            });
            // A failed slice fails the call (after every group, so that no rank leaves the
            // exchanges early).
            if done.is_ok() {
                done = group_done;
            }
            let t3 = std::time::Instant::now();
            times.dwt += (t1 - t0).as_secs_f64();
            times.exchange += (t2 - t1).as_secs_f64();
            times.fft += (t3 - t2).as_secs_f64();
        }
        times.total = start.elapsed().as_secs_f64();
        collective(&self.comm, done).map(|()| times)
    }
}

impl<X: Exchange> Transform for DistributedPlan<X> {
    /// This rank's samples.
    fn num_samples(&self) -> usize {
        self.local_num_samples()
    }

    /// This rank's coefficients.
    fn num_coeffs(&self) -> usize {
        self.local_num_coeffs()
    }

    /// This rank's two row buffers (see [`DistributedPlan::local_workspace_bytes`]).
    fn scratch_bytes(&self) -> usize {
        let (na, nb) = self.row_sizes();
        8 * (na.next_multiple_of(8) + nb)
    }

    fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        DistributedPlan::forward(self, samples, coeffs)
    }

    fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<StageTimes> {
        DistributedPlan::inverse(self, coeffs, samples)
    }

    fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        DistributedPlan::forward_real(self, samples, coeffs)
    }

    fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<StageTimes> {
        DistributedPlan::inverse_real(self, coeffs, samples)
    }

    fn forward_with_scratch(
        &self,
        samples: &[Complex64],
        coeffs: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let inp = (SendConstPtr(samples.as_ptr().cast()), samples.len());
        self.forward_impl(inp, coeffs, (false, Some(scratch)))
    }

    fn inverse_with_scratch(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let out = (SendPtr(samples.as_mut_ptr().cast()), samples.len());
        self.inverse_impl(coeffs, out, (false, Some(scratch)))
    }

    fn forward_real_with_scratch(
        &self,
        samples: &[f64],
        coeffs: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let inp = (SendConstPtr(samples.as_ptr()), samples.len());
        self.forward_impl(inp, coeffs, (true, Some(scratch)))
    }

    fn inverse_real_with_scratch(
        &self,
        coeffs: &[Complex64],
        samples: &mut [f64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        let out = (SendPtr(samples.as_mut_ptr()), samples.len());
        self.inverse_impl(coeffs, out, (true, Some(scratch)))
    }
}
