//! Cluster-major layout of the chunk buffer: the DWT kernels' own layout.
//!
//! The chunk buffer holds one block per cluster, in the plan's cluster order. A block has
//! one row per lane (beta point of the chunk) and `P` doubles per row: the (re, im) pairs of
//! the cluster's order pairs ("slots"), `P = 16` for 8 slots, 8 for up to 4. The forward
//! DWT kernel reads a block as it is (`xin[lane * P + q]`) and the inverse kernel writes its
//! results straight into it, so the DWT stage neither gathers nor transposes: that work is
//! done once, in cache, by the FFT stage, which moves each transformed slice into (or out
//! of) the rows of all clusters.
//!
//! That is the forward's layout, whose DWT kernel reads a whole block at a time. The
//! inverse's FFT stage instead reads one pair of rows (a beta and its mirror) of every
//! block at a time, and in that layout those reads are 256 bytes every block, each a few
//! lines from memory. So an inverse whose blocks do not stay in the cache (see
//! `plain_store_limit` in `build.rs`) uses the buffer "half-major": two halves, one with the
//! low-beta rows and one with the mirror rows, each holding row `j` of every block, cluster
//! after cluster, then row `j + 1` ([`BufLayout::HalfMajor`]); its DWT kernel writes its
//! rows far apart with non-temporal stores, and its FFT stage reads two sequential runs.
//! The two halves need not be adjacent: a chunk's buffer can then live in the low-beta and
//! the mirror slices of another chunk of the output (see `Spare` in `schedule.rs`).
//!
//! A forward allowed to overwrite its input splits its buffers the same way but keeps
//! them cluster-major within each half ([`BufLayout::Split`]): its kernel reads a
//! block at a time, `P` doubles per row, low-beta rows from one half and mirror rows from
//! the other.
//!
//! Slot `q` of cluster `c` holds the value of order pair `(M, M')` at the row's beta, or,
//! for a "reversed" member (see `symmetry.rs`), at the mirrored beta `pi - beta`: `slot_index[8c+q]`
//! is where that value sits in a transformed slice, and bit `q` of `reversed[c]` says whether it
//! is taken from the mirrored slice.

use super::shared::SendPtr;
use crate::symmetry::Cluster;

/// How a chunk buffer holds the blocks (see the module documentation); the split layouts
/// carry the doubles from their low-beta half to their mirror half (`t.total() / 2` in
/// one piece of memory, far more when the halves are in two other chunks' slices).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum BufLayout {
    /// Cluster-major, the two rows of a pair side by side.
    Blocks,
    /// Two cluster-major halves (the forward that may overwrite its input).
    Split(usize),
    /// Two halves each holding row `j` of every cluster, then row `j + 1` (an inverse
    /// whose blocks do not stay in the cache: written with non-temporal stores).
    HalfMajor(usize),
}

/// A chunk buffer: where its blocks start and how they are laid out.
#[derive(Clone, Copy)]
pub(super) struct ChunkBuf {
    /// Start of the buffer (64-byte aligned).
    pub base: SendPtr<f64>,
    /// How the buffer holds the blocks.
    pub layout: BufLayout,
}

/// Where a cluster's block is in a chunk buffer: row `2j` at `base + j * pair_stride`,
/// row `2j + 1` `row_gap` further, `width` doubles each (see [`Blocks::pair_rows`]).
#[derive(Clone, Copy)]
pub(super) struct BlockRows {
    pub base: *mut f64,
    pub width: usize,
    pub pair_stride: usize,
    pub row_gap: usize,
}

/// No slot (unused entry of a cluster with fewer than 8 members).
pub(super) const NONE: u32 = u32::MAX;

/// Slot tables and block offsets of one layout (complex or real-signal transforms).
pub(super) struct Blocks {
    /// Doubles per lane row of each cluster's block.
    row_len: Vec<u8>,
    /// `pofs[c]`: doubles per lane of all blocks before cluster `c` (length `C + 1`).
    pofs: Vec<usize>,
    /// Source index of each slot in a transformed slice (`NONE` for unused slots).
    pub slot_index: Vec<u32>,
    /// Real layout only: a second index the inverse writes the slot's value to (`NONE`).
    pub slot_neg_index: Vec<u32>,
    /// Bit `q` set: slot `q` reads and writes the mirrored slice.
    pub reversed: Vec<u8>,
    /// Whether a cluster's block is regular: every slot used, the first half of the slots
    /// from the own slice and the second half from the mirrored one, no second index. All
    /// 8-member clusters are (complex layout: 8 slots; real: their 4 representatives); the
    /// block copies have a written-out path for them.
    pub regular: Vec<bool>,
    /// Low betas per chunk (`h` of a full chunk) for this layout.
    pub chunk: usize,
    /// Lanes of every block: room for the padded lanes of a full chunk,
    /// `2 * chunk` rounded up to a multiple of 16.
    pub lanes: usize,
    /// Whether the block copies prefetch slice values ahead: only when a pair of
    /// transformed slices (unpadded) is larger than a core's L2 cache (assumed 2 MiB);
    /// below that the prefetches only cost instructions.
    pub prefetch_slices: bool,
}

/// Bytes of a pair of transformed slices above which the block copies prefetch.
const PREFETCH_ABOVE: usize = 2 << 20;

impl Blocks {
    /// BufLayout of the complex transforms: every member of every cluster, in member order.
    /// Slices are `2B x 2B` in the FFT scratch, rows `rs = slice_stride(2B)` apart, with
    /// `(M, M')` at `(M mod 2B) rs + (M' mod 2B)`.
    pub fn complex(b: usize, clusters: &[(u32, u32)], chunk: usize) -> Blocks {
        let n = 2 * b as isize;
        let rs = crate::fft::slice_stride(2 * b) as isize;
        let pair_bytes = 2 * (2 * b) * (2 * b) * 16;
        Blocks::build(clusters, chunk, pair_bytes, |cl| {
            let mut out = [(NONE, NONE, false); 8];
            for (q, mem) in cl.members().iter().enumerate() {
                let idx = mem.m.rem_euclid(n) * rs + mem.mp.rem_euclid(n);
                out[q] = (idx as u32, NONE, mem.reversed);
            }
            (out, cl.members().len())
        })
    }

    /// BufLayout of the real-signal transforms: the representatives of each cluster (see
    /// `real.rs`), indexed in the half spectrum of `2B x (B+1)` values of an r2c transform,
    /// `(a, b')` at `(a mod 2B)(B+1) + b'`. For `M' = 0`, `M > 0` the inverse also writes
    /// the value to `(-M, 0)` (`slot_neg_index`).
    pub fn real(b: usize, clusters: &[(u32, u32)], chunk: usize) -> Blocks {
        let n = 2 * b as isize;
        let half = |a: isize, bp: isize| (a.rem_euclid(n) * (b as isize + 1) + bp) as u32;
        let pair_bytes = 2 * (2 * b) * (b + 1) * 16;
        Blocks::build(clusters, chunk, pair_bytes, |cl| {
            let mut out = [(NONE, NONE, false); 8];
            let (reps, nr) = super::members::representatives(cl);
            for (q, mem) in reps[..nr].iter().enumerate() {
                let neg_idx = if mem.mp == 0 && mem.m != 0 {
                    half(-mem.m, 0)
                } else {
                    NONE
                };
                out[q] = (half(mem.m, mem.mp), neg_idx, mem.reversed);
            }
            (out, nr)
        })
    }

    fn build(
        clusters: &[(u32, u32)],
        chunk: usize,
        pair_bytes: usize,
        slots: impl Fn(&Cluster) -> ([(u32, u32, bool); 8], usize),
    ) -> Blocks {
        let nc = clusters.len();
        let mut t = Blocks {
            row_len: Vec::with_capacity(nc),
            pofs: Vec::with_capacity(nc + 1),
            slot_index: vec![NONE; 8 * nc],
            slot_neg_index: vec![NONE; 8 * nc],
            reversed: vec![0; nc],
            regular: vec![false; nc],
            chunk,
            lanes: Blocks::lanes_for(chunk),
            prefetch_slices: pair_bytes > PREFETCH_ABOVE,
        };
        let mut acc = 0;
        for (c, &(m, mp)) in clusters.iter().enumerate() {
            let cl = Cluster::new(m as usize, mp as usize);
            let (s, len) = slots(&cl);
            let p = if len > 4 { 16 } else { 8 };
            t.row_len.push(p as u8);
            t.pofs.push(acc);
            acc += p;
            for (q, &(idx, neg_idx, reversed)) in s[..len].iter().enumerate() {
                t.slot_index[8 * c + q] = idx;
                t.slot_neg_index[8 * c + q] = neg_idx;
                t.reversed[c] |= (reversed as u8) << q;
            }
            let half = p / 4;
            t.regular[c] = len == p / 2
                && t.reversed[c] as usize == ((1 << len) - 1) & !((1 << half) - 1)
                && s[..len].iter().all(|x| x.1 == NONE);
        }
        t.pofs.push(acc);
        t
    }

    /// Number of clusters.
    pub fn len(&self) -> usize {
        self.row_len.len()
    }

    /// Doubles per lane row of cluster `c`'s block.
    pub fn row_len(&self, c: usize) -> usize {
        self.row_len[c] as usize
    }

    /// Lanes of every block for chunks of `chunk` low betas (see [`Blocks::lanes`]).
    pub fn lanes_for(chunk: usize) -> usize {
        2 * chunk.next_multiple_of(8)
    }

    /// The largest chunk whose blocks fit in `doubles` doubles, with [`Blocks::lanes_for`]
    /// lanes of `doubles_per_lane` each: a multiple of 8 (the padding lanes take memory
    /// too), at least 8 (a smaller chunk would take the same memory for less work) and at
    /// most `b`.
    pub fn chunk_for(doubles: usize, doubles_per_lane: usize, b: usize) -> usize {
        let h = doubles / (16 * doubles_per_lane) * 8;
        h.max(8).min(b)
    }

    /// Offset (in doubles) of cluster `c`'s block.
    pub fn offset(&self, c: usize) -> usize {
        self.pofs[c] * self.lanes
    }

    /// Where cluster `c`'s two rows of pair `j` are in a chunk buffer of `layout`: the
    /// offset (in doubles) of row `2j`, the doubles from one pair's rows to the next, and
    /// from row `2j` to row `2j + 1`. The one place that knows the layouts.
    pub fn pair_rows(&self, c: usize, j: usize, layout: BufLayout) -> (usize, usize, usize) {
        let p = self.row_len(c);
        match layout {
            BufLayout::Blocks => (self.offset(c) + 2 * j * p, 2 * p, p),
            BufLayout::Split(gap) => (self.pofs[c] * (self.lanes / 2) + j * p, p, gap),
            BufLayout::HalfMajor(gap) => {
                let stride = self.pofs[self.len()];
                (j * stride + self.pofs[c], stride, gap)
            }
        }
    }

    /// Where cluster `c`'s block is in the chunk buffer `buf`.
    pub fn rows(&self, c: usize, buf: ChunkBuf) -> BlockRows {
        let (at, pair_stride, row_gap) = self.pair_rows(c, 0, buf.layout);
        BlockRows {
            base: buf.base.get().wrapping_add(at),
            width: self.row_len(c),
            pair_stride,
            row_gap,
        }
    }

    /// Half-major layout: doubles of one half for `pairs` pairs of rows.
    pub fn half_len(&self, pairs: usize) -> usize {
        pairs * self.pofs[self.len()]
    }

    /// Doubles of the whole buffer.
    pub fn total(&self) -> usize {
        self.pofs[self.len()] * self.lanes
    }

    /// Doubles per lane over all blocks (for memory estimates before the tables exist):
    /// 16 per generic cluster, 8 per other cluster (complex), 8 per cluster (real).
    pub fn doubles_per_lane(b: usize, real: bool) -> usize {
        let generic = crate::symmetry::num_generic(b);
        let other = 2 * b.saturating_sub(1) + 1;
        if real {
            8 * (generic + other)
        } else {
            16 * generic + 8 * other
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::symmetry::cluster_pairs;
    use std::collections::HashSet;

    /// Every in-band frequency of a slice appears in exactly one slot; the per-lane size
    /// formula matches the tables.
    #[test]
    fn complex_slots_cover_the_band_once() {
        for b in 1..20usize {
            let cl = cluster_pairs(b);
            let t = Blocks::complex(b, &cl, 1);
            let n = 2 * b;
            let rs = crate::fft::slice_stride(n);
            let mut seen = HashSet::new();
            for c in 0..t.len() {
                for q in 0..8 {
                    let idx = t.slot_index[8 * c + q];
                    if idx != NONE {
                        assert!(2 * q < t.row_len(c));
                        assert!(seen.insert(idx));
                        let (a, g) = (idx as usize / rs, idx as usize % rs);
                        assert!(a < n && g < n, "outside the slice or in its padding");
                        assert!(a != b && g != b, "frequency B is out of band");
                    }
                }
            }
            assert_eq!(seen.len(), (n - 1) * (n - 1));
            // The fast path of the block copies covers every 8-member cluster, and its
            // premise holds exactly where it is taken: all slots used, the first half
            // from the own slice, the second from the mirrored one.
            let r = Blocks::real(b, &cl, 8);
            for (c, &(m, mp)) in cl.iter().enumerate() {
                let cluster = Cluster::new(m as usize, mp as usize);
                let (reps, nr) = crate::plan::members::representatives(&cluster);
                let slots = [(&t, cluster.members()), (&r, &reps[..nr])];
                for (l, members) in slots {
                    let p = if members.len() > 4 { 16 } else { 8 };
                    let half = p / 4;
                    let pattern = members.len() == p / 2
                        && members
                            .iter()
                            .enumerate()
                            .all(|(q, x)| x.reversed == (q >= half))
                        && members.iter().all(|x| x.mp != 0);
                    assert_eq!(l.regular[c], pattern, "({m},{mp})");
                }
                if m > mp && mp > 0 {
                    assert!(t.regular[c] && r.regular[c], "({m},{mp})");
                }
            }
            assert_eq!(t.total(), 16 * Blocks::doubles_per_lane(b, false));
            let r = Blocks::real(b, &cl, 1);
            assert_eq!(r.total(), 16 * Blocks::doubles_per_lane(b, true));
        }
    }
}
