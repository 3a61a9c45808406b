//! [`Footprint`]: what a plan of the engine holds, known before it is made.

use super::betas::LanePairs;
use super::dwt_stage::DwtStage;
use super::fft_stage::ROW_PAD;
use crate::options::Options;
use crate::shape::{CoefLayout, Shape};
use crate::simd::Isa;
use crate::workers::WORKER_STACK_BYTES;
use crate::Real;

/// What a plan of the engine holds, known before it is made.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Footprint {
    /// Everything but the chunk buffer: the DWT stage's tables and per-worker scratch, the
    /// workers' FFT buffers and stacks, the lane pairs' tables.
    pub(super) rest: usize,
    /// What the chunk buffer may take (the workspace cap).
    pub(super) budget: usize,
    /// Lane pairs and lanes per vector.
    pub(super) pairs: usize,
    pub(super) lanes_w: usize,
    /// Bytes of a value of the lane rows.
    pub(super) value_bytes: usize,
    /// Lane-row strides of the complex transforms and (real plans) of the real ones.
    pub(super) strides: [Option<usize>; 2],
}

impl Footprint {
    /// The footprint of the plan [`Engine::new`](super::Engine::new) in `T` makes of these
    /// arguments.
    pub(crate) fn new<T: Real>(
        shape: &Shape,
        pairs: &LanePairs,
        (isa, threads): (Isa, usize),
        options: &Options,
    ) -> Footprint {
        let layout = CoefLayout::new(shape);
        let w = isa.lanes_of::<T>();
        let max_lanes = 2 * pairs.pairs.next_multiple_of(w);
        let tables = pairs.pairs * LanePairs::bytes_per_pair(shape.degree_limit);
        let rest = DwtStage::<T>::bytes(shape.degree_limit, 0, threads, max_lanes)
            .saturating_add(threads * (Self::work_bytes::<T>(shape, options) + WORKER_STACK_BYTES))
            .saturating_add(tables);
        // The library's one rule (see `Options::default_workspace`).
        let sample_bytes = if options.real { T::BYTES } else { 2 * T::BYTES };
        let arrays = sample_bytes * shape.num_samples() + 2 * T::BYTES * shape.num_coeffs();
        let budget = options
            .max_workspace_bytes
            .unwrap_or_else(|| Options::default_workspace_here(arrays).saturating_sub(rest));
        let strides = [
            Some(DwtStage::<T>::row_stride_of(&layout, false)),
            options
                .real
                .then(|| DwtStage::<T>::row_stride_of(&layout, true)),
        ];
        Footprint {
            rest,
            budget,
            pairs: pairs.pairs,
            lanes_w: w,
            value_bytes: T::BYTES,
            strides,
        }
    }

    /// Bytes of one worker's FFT buffers (see [`Engine::reserve`](super::Engine::reserve)): two work buffers of
    /// a slice (the forward's and the inverse's), and on a real plan two half-spectrum
    /// buffers and the reals of a slice.
    pub(super) fn work_bytes<T: Real>(shape: &Shape, options: &Options) -> usize {
        let (na, ng) = (shape.n_alpha, shape.n_gamma);
        let value = 2 * T::BYTES;
        let mut bytes = 2 * na * (ng + ROW_PAD) * value;
        if options.real {
            bytes += 2 * na * (ng / 2 + 1 + ROW_PAD) * value + na * ng * T::BYTES;
        }
        bytes
    }

    /// Lane pairs whose rows, `row_stride` values apart, the workspace cap holds.
    pub(super) fn room(&self, row_stride: usize) -> usize {
        self.budget / (row_stride * 2 * self.value_bytes).max(1)
    }

    /// [`Footprint::room`] for one transform: at least one pair, at most all.
    pub(super) fn most_pairs(&self, row_stride: usize) -> usize {
        self.room(row_stride).clamp(1, self.pairs)
    }

    /// Lane pairs per chunk: what the workspace cap holds for one transform with the rows
    /// of the padding lanes (a chunk's pairs rounded up to the vector width; at least one
    /// pair), the pairs spread evenly over the fewest chunks, a multiple of the vector
    /// width when that fits. It does not depend on the batch, so a batch sums in the order
    /// of single executes.
    pub(super) fn chunk_pairs(&self, row_stride: usize) -> usize {
        let pairs = self.pairs;
        let w = self.lanes_w;
        let room = self.room(row_stride);
        let fit = if room >= w { room / w * w } else { room }.clamp(1, pairs);
        let h = pairs.div_ceil(pairs.div_ceil(fit));
        if h >= w && h.next_multiple_of(w) <= fit {
            h.next_multiple_of(w)
        } else {
            h
        }
    }

    /// Bytes of the chunk buffer of one transform (the scratch a single call needs): the
    /// larger of the complex and the real transforms'.
    pub(crate) fn scratch_bytes(&self) -> usize {
        self.strides
            .iter()
            .flatten()
            .map(|&rs| {
                self.value_bytes * rs * 2 * self.chunk_pairs(rs).next_multiple_of(self.lanes_w)
            })
            .max()
            .unwrap_or(0)
    }

    /// Bytes of the whole plan: the chunk buffer and the rest.
    pub(crate) fn total(&self) -> usize {
        self.rest.saturating_add(self.scratch_bytes())
    }
}
