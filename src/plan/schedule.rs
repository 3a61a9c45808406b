//! The schedule of an execution: chunks of mirrored pairs of beta slices, groups of chunks
//! sharing one pass of the DWT stage, and where each chunk's buffer lives.

use super::blocks::{Blocks, ChunkBuf};
use crate::symmetry::Cluster;

/// A cluster of the processing order for the DWT stage: its index, the cluster, and the
/// one after it (whose memory its kernel prefetches), if any.
#[derive(Clone, Copy)]
pub(super) struct ClusterStep {
    pub(super) index: usize,
    pub(super) cluster: Cluster,
    pub(super) next: Option<Cluster>,
}

/// A chunk and the buffer that holds its blocks.
#[derive(Clone, Copy)]
pub(super) struct PlacedChunk {
    pub(super) chunk: Chunk,
    pub(super) buf: ChunkBuf,
}

/// Where a chunk stands for the DWT stage of a cluster.
#[derive(Clone, Copy)]
pub(super) struct Pass {
    /// The chunk and its buffer. The buffer's layout is cluster-major, split in two halves
    /// (the forward's chain, [`Schedule::chain`]), or half-major (an inverse whose blocks are
    /// too large to stay in the cache until the FFT stage reads them, written with
    /// non-temporal stores, see `build::plain_store_limit`); see `plan/blocks.rs`.
    pub(super) placed: PlacedChunk,
    /// A chunk of the transform's first group (the forward assigns the coefficients
    /// rather than adds to them then).
    pub(super) first_group: bool,
    /// Position in its group; for a position above 0 the previous call was the same
    /// cluster on the group's previous chunk (the inverse reuses its coefficient rows, the
    /// forward adds to its sums).
    pub(super) position: usize,
    /// The group's last chunk (the forward writes the cluster's sums then).
    pub(super) last_in_group: bool,
    /// The last chunk of the transform's last group: after this call the forward's
    /// coefficients of the cluster are final.
    pub(super) last_of_transform: bool,
    /// The buffer of the group's next chunk, if any: the next call is this cluster on it,
    /// so that is what to prefetch (forward: this cluster's block there; inverse: nothing,
    /// its coefficient rows are kept).
    pub(super) next_in_group: Option<ChunkBuf>,
    /// The group's first chunk: after the group's last chunk the next call is the next
    /// cluster on that one (the forward prefetches its block there).
    pub(super) group_head: PlacedChunk,
}

/// A buffer for a chunk in spare memory (see [`Spare`]): its low-beta half, and the
/// doubles from there to its mirror half (the split and half-major layouts; a buffer in
/// one piece has its halves half its length apart).
#[derive(Clone, Copy, Debug)]
pub(super) struct SpareBuf {
    pub(super) low: *mut f64,
    pub(super) gap: usize,
}

/// A chunk of a group and where its buffer is: `None` for the plan's chunk buffer.
#[derive(Clone, Copy)]
pub(super) struct ChunkPlace {
    pub(super) chunk: Chunk,
    pub(super) spare: Option<SpareBuf>,
}

/// The chunks of a transform in groups that share one pass of the DWT stage.
pub(super) struct ChunkGroups {
    pub(super) groups: Vec<Vec<ChunkPlace>>,
    /// Whether the groups are a chain ([`Schedule::chain`]), whose buffers are in two pieces.
    pub(super) chained: bool,
}

/// The beta slices of one chunk: the `h` low betas `lo .. lo+h` and their mirrors
/// `2B-1-lo .. 2B-1-lo-h`. The DWT kernels see them as lanes, each half padded to `hp` (a
/// multiple of the vector width) so that no vector mixes the lower and upper half: lane
/// `j < h` is beta `lo + j` and lane `hp + j` its mirror `2B-1-lo-j` (the upper half runs
/// down). In the blocks of the chunk buffer the two are adjacent rows `2j` and `2j+1`
/// (`dwt::Lanes::interleaved`), so the FFT stage moves each mirrored pair of slices in
/// and out of one contiguous piece of every block; in the split and half-major layouts
/// (`plan/blocks.rs`) row `2j` is in one half and row `2j+1` in the other.
#[derive(Clone, Copy)]
pub(super) struct Chunk {
    pub(super) lo: usize,
    pub(super) h: usize,
    pub(super) hp: usize,
}

impl Chunk {
    /// `(first lane, lowest beta)` of the lower and upper half; each holds `h` betas,
    /// ascending in the lower half and descending in the upper one.
    pub(super) fn halves(&self, b: usize) -> [(usize, usize); 2] {
        [(0, self.lo), (self.hp, 2 * b - self.lo - self.h)]
    }

    /// Number of lanes.
    pub(super) fn lanes(&self) -> usize {
        2 * self.hp
    }

    /// Betas of the mirrored pair `j < h` (lanes `j` and `hp + j`, block rows `2j` and
    /// `2j + 1`): `lo + j` and `2B-1-lo-j`.
    pub(super) fn pair_betas(&self, b: usize, j: usize) -> (usize, usize) {
        (self.lo + j, 2 * b - 1 - self.lo - j)
    }
}

/// The output array of an inverse, or the input of a forward allowed to overwrite it, as
/// room for chunk buffers. The inverse's FFT stage
/// writes the output slice of a beta only when that beta's chunk is done, so the slices of
/// the betas of later chunks are free until then: a group of chunks whose buffers (all
/// but the first, which uses the plan's buffer) fit there runs its DWT stage as one pass,
/// reading each cluster's coefficients once for the whole group instead of once per
/// chunk. A forward may likewise put the buffers of a group in the input slices of earlier groups (already
/// read), and adds each cluster's sums over the group's chunks to the coefficients once
/// (the real forward of real samples).
///
/// Where the buffers fit, both go further: a buffer in two halves (half-major for the
/// inverse, two cluster-major halves for the forward, see `plan/blocks.rs`) can live in
/// the low-beta and the mirror slices of one other chunk, and all chunks run as one group
/// (see [`Schedule::chain`]).
pub(super) struct Spare {
    /// Start of the array (`2B` slices of `slice_bytes`, beta slowest).
    pub(super) base: *mut u8,
    pub(super) slice_bytes: usize,
}

impl Spare {
    /// The `2B` beta slices of a sample array at `base` (`4B^2` values of `T` each).
    pub(super) fn over<T>(base: *mut T, b: usize) -> Spare {
        Spare {
            base: base as *mut u8,
            slice_bytes: 4 * b * b * std::mem::size_of::<T>(),
        }
    }

    /// Forward: buffers of `bytes` each (a multiple of 64), 64-byte aligned, as many as
    /// fit (up to `g`) in the input slices of the betas before `lo` and from `2B-lo` on,
    /// which the FFT stage has read already.
    pub(super) fn consumed(&self, b: usize, lo: usize, g: usize, bytes: usize) -> Vec<*mut f64> {
        let mut out = Vec::new();
        for (from, to) in [(0, lo), (2 * b - lo, 2 * b)] {
            let (from, to) = (from * self.slice_bytes, to * self.slice_bytes);
            let mut at = from + self.base.wrapping_add(from).align_offset(64);
            while out.len() < g && at <= to && to - at >= bytes {
                out.push(self.base.wrapping_add(at) as *mut f64);
                at += bytes;
            }
        }
        out
    }

    /// The two halves of a half-major buffer, `bytes` each, 64-byte aligned: one in the
    /// low-beta slices of chunk `ch`, one in its mirror slices; `None` if they do not fit.
    pub(super) fn halves(
        &self,
        b: usize,
        ch: &Chunk,
        bytes: usize,
    ) -> Option<(*mut f64, *mut f64)> {
        let region = |first: usize| {
            let (from, to) = (first * self.slice_bytes, (first + ch.h) * self.slice_bytes);
            let at = from + self.base.wrapping_add(from).align_offset(64);
            (at <= to && to - at >= bytes).then(|| self.base.wrapping_add(at) as *mut f64)
        };
        Some((region(ch.lo)?, region(2 * b - ch.lo - ch.h)?))
    }

    /// Inverse: buffers of `bytes` each (a multiple of 64) for `g` chunks in the slices of the
    /// betas `hi..2B-hi`, 64-byte aligned; `None` if they do not fit.
    pub(super) fn room(
        &self,
        b: usize,
        hi: usize,
        g: usize,
        bytes: usize,
    ) -> Option<Vec<*mut f64>> {
        let (from, to) = (
            hi * self.slice_bytes,
            (2 * b).checked_sub(hi)? * self.slice_bytes,
        );
        let start = self.base.wrapping_add(from);
        let from = from + start.align_offset(64);
        (to >= from && to - from >= g * bytes).then(|| {
            (0..g)
                .map(|k| self.base.wrapping_add(from + k * bytes) as *mut f64)
                .collect()
        })
    }
}

/// What the schedule of a plan's executions depends on: the bandwidth, the kernels'
/// vector width, and the size of the chunk buffer and the store limit of the inverse.
#[derive(Clone, Copy, Debug)]
pub(super) struct Schedule {
    /// The bandwidth `B`.
    pub(super) b: usize,
    /// Lanes of the DWT kernels' vectors (each half of a chunk is padded to a multiple).
    pub(super) vector_lanes: usize,
    /// Bytes of the plan's chunk buffer.
    pub(super) buf_bytes: usize,
    /// Most bytes of blocks an inverse group writes with ordinary stores (see
    /// `build::plain_store_limit`).
    pub(super) plain_store_limit: usize,
}

impl Schedule {
    /// The chunks of layout `t` in groups that share one pass of the DWT stage, each with
    /// its buffer: `None` for the plan's chunk buffer, else a part of `spare` (the
    /// inverse's output, or the input of a forward that may overwrite it, see [`Spare`]).
    /// Without `spare` every group is one chunk. With each buffer comes the gap (doubles)
    /// from its low-beta half to its mirror half in the half-major layout; the plan's
    /// buffer has its halves `t.total() / 2` apart, and so do the buffers placed whole.
    pub(super) fn chunk_groups(
        &self,
        t: &Blocks,
        forward: bool,
        spare: Option<&Spare>,
    ) -> ChunkGroups {
        // The inverse's chain only where the blocks would not stay in the cache anyway:
        // its buffers are half-major, written with non-temporal stores.
        let chain = match spare {
            Some(sp) if forward => self.chain(t, sp, |_| 8 * (t.total() / 2)),
            Some(sp) if self.streams_blocks(self.chunks(t).count()) => self
                .chain(t, sp, |ch| 8 * t.half_len(ch.hp))
                .map(|g| g.into_iter().rev().collect()),
            _ => None,
        };
        match chain {
            Some(g) => ChunkGroups {
                groups: vec![g],
                chained: true,
            },
            None => ChunkGroups {
                groups: self.chunk_groups_whole(t, forward, spare),
                chained: false,
            },
        }
    }

    /// All chunks of layout `t` as one group, each chunk's buffer except chunk 0's (the
    /// plan's buffer) in two halves of `half_bytes(chunk)` bytes in the low-beta and the
    /// mirror slices of the chunk before it, with the gap (doubles) between the halves;
    /// `None` with fewer than two chunks or if a half does not fit.
    ///
    /// The forward (input it may overwrite) runs the chunks in this order: chunk `k - 1`'s
    /// FFT stage has read its slices when chunk `k`'s writes there. Its buffers are split
    /// in two cluster-major halves, each with room for a full chunk, so every cluster's
    /// sums reach the coefficients once. The inverse runs them in reverse (equator first):
    /// chunk `k - 1`'s FFT stage writes its output slices only after chunk `k`'s has read
    /// its buffer. Its buffers are half-major, and it reads each cluster's coefficients and
    /// computes its recurrence coefficients once, not once per group.
    ///
    /// The real layout's row per lane (`4B^2 + 4B` doubles) is longer than a real slice
    /// (`4B^2`), so in real samples a full chunk's buffer never fits in another full
    /// chunk's slices: its inverse chain exists only for two chunks, the second one short
    /// (half-major halves hold only the chunk's own pairs), its forward chain never.
    pub(super) fn chain(
        &self,
        t: &Blocks,
        spare: &Spare,
        half_bytes: impl Fn(&Chunk) -> usize,
    ) -> Option<Vec<ChunkPlace>> {
        let chunks: Vec<Chunk> = self.chunks(t).collect();
        if chunks.len() < 2 {
            return None;
        }
        let mut group = vec![ChunkPlace {
            chunk: chunks[0],
            spare: None,
        }];
        for w in chunks.windows(2) {
            let (low, mirror) = spare.halves(self.b, &w[0], half_bytes(&w[1]))?;
            let gap = (mirror as usize - low as usize) / 8;
            group.push(ChunkPlace {
                chunk: w[1],
                spare: Some(SpareBuf { low, gap }),
            });
        }
        Some(group)
    }

    /// [`Schedule::chunk_groups`] without the chain: every buffer in one piece.
    pub(super) fn chunk_groups_whole(
        &self,
        t: &Blocks,
        forward: bool,
        spare: Option<&Spare>,
    ) -> Vec<Vec<ChunkPlace>> {
        let whole = t.total() / 2;
        let chunks: Vec<Chunk> = self.chunks(t).collect();
        let bytes = (t.total() * 8).next_multiple_of(64);
        let mut groups = Vec::new();
        let mut i = 0;
        while i < chunks.len() {
            let mut g = 1;
            let mut at = Vec::new();
            if let (true, Some(sp)) = (forward, spare) {
                at = sp.consumed(self.b, chunks[i].lo, chunks.len() - i - 1, bytes);
                g += at.len();
            } else if let Some(sp) = spare {
                // Add chunks while the buffers of all but the first fit in the output
                // slices of the betas after the group's (written only by later groups).
                while i + g < chunks.len() {
                    let hi = chunks[i + g].lo + chunks[i + g].h;
                    match sp.room(self.b, hi, g, bytes) {
                        Some(ptrs) => {
                            at = ptrs;
                            g += 1;
                        }
                        None => break,
                    }
                }
            }
            let mut group = vec![ChunkPlace {
                chunk: chunks[i],
                spare: None,
            }];
            group.extend(
                chunks[i + 1..i + g]
                    .iter()
                    .zip(at)
                    .map(|(c, low)| ChunkPlace {
                        chunk: *c,
                        spare: Some(SpareBuf { low, gap: whole }),
                    }),
            );
            groups.push(group);
            i += g;
        }
        groups
    }

    /// The chunks of layout `t`.
    pub(super) fn chunks(&self, t: &Blocks) -> impl Iterator<Item = Chunk> + '_ {
        let (b, chunk) = (self.b, t.chunk);
        (0..b).step_by(chunk).map(move |lo| {
            let h = chunk.min(b - lo);
            let hp = h.next_multiple_of(self.vector_lanes);
            Chunk { lo, h, hp }
        })
    }

    /// Whether an inverse group of `chunks` chunks writes its blocks with non-temporal
    /// stores, half-major (see `plan/blocks.rs`): when they are too large to stay in the
    /// cache until the FFT stage reads them (`build::plain_store_limit`).
    pub(super) fn streams_blocks(&self, chunks: usize) -> bool {
        chunks * self.buf_bytes > self.plain_store_limit
    }
}
