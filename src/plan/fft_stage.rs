//! The FFT stage: FFTW over (alpha, gamma) of each beta slice, a group of mirrored pairs of
//! beta slices at a time, with the moves between the transformed slices and the blocks of
//! the chunk buffer (`block_copies.rs`).
//!
//! Forward: the slices of a group of pairs (`beta` and `pi - beta`) are copied into the
//! worker's cache-resident scratch (rows padded, see [`fft::slice_stride`]), transformed in
//! place, and moved, weighted, into the rows of every cluster's block (`blocks.rs`): the
//! group fills `2g` adjacent rows of each block completely (in the split layout `g` rows
//! of each half), written as whole cache lines with non-temporal stores. Inverse: those
//! rows of every block are read back into the slices, which are transformed in place and
//! streamed to the samples. Small slices move in groups of up to 4 pairs (one longer piece
//! of each block per group), larger ones a pair at a time, which keeps the slices' random
//! accesses in L2. The groups are spread over the workers, or, with FFTW's threads, run one
//! after another with the copies spread over the workers.
//!
//! Real signals (`real.rs`) go one mirrored pair at a time through r2c / c2r slice FFTs,
//! whose half spectra fill the blocks of the real layout.

use super::block_copies::{gather_group, scatter_group, SliceGroup, MAX_GROUP};
#[cfg(feature = "internals")]
use super::blocks::BufLayout;
use super::blocks::{Blocks, ChunkBuf};
use super::schedule::Chunk;
use super::shared::{lock_free, SendConstPtr, SendPtr};
use crate::error::{Error, Result};
use crate::fft::{self, AlignedBuf, SliceFft, SliceFftReal, SIGN_MINUS, SIGN_PLUS};
use crate::grid::weights;
use crate::options::{Direction, FftThreading, Options};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Mutex;

/// Pairs per group for slices of `slice_bytes` (unpadded): up to [`MAX_GROUP`], as many as
/// keep the group's slices within about 512 KiB, half of a core's L2 (B <= 32: 4, from
/// B = 64 on: 1). The copies between slices and blocks are bound by the slice side's cache
/// misses, which fewer pairs per group keep down.
pub(super) fn pairs_per_group(slice_bytes: usize) -> usize {
    ((512usize << 10) / (2 * slice_bytes)).clamp(1, MAX_GROUP)
}

/// Complex values of a worker's FFT scratch at bandwidth `b`: a group of pairs of padded
/// slices (see [`fft::slice_stride`]).
pub(super) fn scratch_len(b: usize) -> usize {
    let n = 2 * b;
    2 * pairs_per_group(16 * n * n) * n * fft::slice_stride(n)
}

/// Where the real samples of a forward transform come from.
#[derive(Clone, Copy)]
pub(super) enum RealInput {
    /// `(2B)^3` doubles.
    Real(SendConstPtr<f64>),
    /// The real parts of `(2B)^3` complex values.
    RealParts(SendConstPtr<Complex64>),
}

/// Where the real samples of an inverse transform go.
#[derive(Clone, Copy)]
pub(super) enum RealOutput {
    /// `(2B)^3` doubles.
    Real(SendPtr<f64>),
    /// The real parts of `(2B)^3` complex values, whose imaginary parts are set to 0 in the
    /// same pass; with `stream`, by non-temporal stores (an output too large for the cache).
    RealParts {
        samples: SendPtr<Complex64>,
        stream: bool,
    },
}

/// One output slice of an inverse, handed to a [`SliceWatch`] right after it is
/// computed (while in the cache): the real slice as written, or a complex slice in the
/// scratch, `row` values per row and rows `stride` values apart.
pub(crate) enum SliceRef<'a> {
    /// The `(2B)^2` reals of the slice.
    Real(&'a [f64]),
    /// The `2B` rows of the slice.
    Complex {
        values: &'a [Complex64],
        row: usize,
        stride: usize,
    },
}

/// What an inverse calls with the beta index and the values of each output slice, once
/// per slice, from whichever worker computed it (for scans fused into the transform, such
/// as a grid's argmax).
pub(crate) type SliceWatch<'a> = &'a (dyn Fn(usize, SliceRef) + Sync);

/// The direction of a real transform's FFT stage, with its samples.
#[derive(Clone, Copy)]
pub(super) enum RealSamples<'a> {
    /// Forward: the samples are read.
    Forward(RealInput),
    /// Inverse: the samples are written (each slice shown to the watch if given).
    Inverse(RealOutput, Option<SliceWatch<'a>>),
}

/// A slice FFT and how it runs: which direction, and whether on FFTW's threads (groups
/// one after another, block copies spread over the workers) or one slice per worker.
#[derive(Clone, Copy)]
pub(super) struct SliceRun<'a> {
    /// The slice plan.
    pub fft: &'a SliceFft,
    /// Forward (samples into blocks) or inverse (blocks into samples).
    pub forward: bool,
    /// Whether `fft` runs on FFTW's threads.
    pub fftw_threaded: bool,
    /// Inverse: shown each output slice.
    pub watch: Option<SliceWatch<'a>>,
}

/// The FFT stage of a plan: its slice FFTs, weights and per-worker scratch.
pub(super) struct FftStage {
    b: usize,
    threads: usize,
    /// Forward slice FFT (plans that run the forward).
    fwd: Option<SliceFft>,
    /// Inverse slice FFT (plans that run the inverse).
    inv: Option<SliceFft>,
    /// Real-data slice FFTs (with `Options::real`).
    real: Option<SliceFftReal>,
    /// `w_B(k) * pi / (2 B^2)`: forward quadrature weight of beta `k` with the
    /// normalisation folded in.
    weights: Vec<f64>,
    /// Per-worker buffers of `2 pairs_per_group` padded slices (see [`fft::slice_stride`]).
    scratch: Vec<Mutex<AlignedBuf>>,
    /// Whether the complex slice FFTs run on FFTW's threads (else slices are spread over
    /// the workers).
    fftw_threaded: bool,
    /// Mirrored pairs of beta slices per group of the complex transforms.
    pairs_per_group: usize,
}

impl FftStage {
    /// The slice FFTs the options ask for (the complex ones on FFTW's threads only with
    /// [`FftThreading::FftwThreads`]), weights and `threads` scratch buffers.
    pub(super) fn new(b: usize, threads: usize, options: &Options) -> Result<FftStage> {
        let n = 2 * b;
        let fftw_threaded = threads > 1
            && match options.fft_threading {
                FftThreading::Auto | FftThreading::SlicesAcrossWorkers => false,
                FftThreading::FftwThreads => true,
            };
        let fftw_threads = if fftw_threaded { threads } else { 1 };
        let slice_fft = |want: bool, sign: i32| -> Result<Option<SliceFft>> {
            Ok(if want {
                Some(SliceFft::new(n, sign, options.rigor, fftw_threads)?)
            } else {
                None
            })
        };
        let fwd = slice_fft(options.direction != Direction::Inverse, SIGN_PLUS)?;
        let inv = slice_fft(options.direction != Direction::Forward, SIGN_MINUS)?;
        let real = if options.real {
            Some(SliceFftReal::new(n, options.rigor)?)
        } else {
            None
        };
        let scratch = (0..threads)
            .map(|_| AlignedBuf::new(scratch_len(b)).map(Mutex::new))
            .collect::<Result<Vec<_>>>()?;
        let norm = PI / (2.0 * (b * b) as f64);
        Ok(FftStage {
            b,
            threads,
            fwd,
            inv,
            real,
            weights: weights(b).iter().map(|w| w * norm).collect(),
            scratch,
            fftw_threaded,
            pairs_per_group: pairs_per_group(16 * n * n),
        })
    }

    /// Whether the complex slice FFTs run on FFTW's threads.
    pub(super) fn fftw_threaded(&self) -> bool {
        self.fftw_threaded
    }

    /// Mirrored pairs of beta slices per group of the complex transforms.
    pub(super) fn pairs_per_group(&self) -> usize {
        self.pairs_per_group
    }

    /// The forward and inverse slice FFTs (`None` for a direction the plan does not run).
    pub(super) fn complex_ffts(&self) -> (Option<&SliceFft>, Option<&SliceFft>) {
        (self.fwd.as_ref(), self.inv.as_ref())
    }

    /// Replace the complex slice FFTs by ones that run on FFTW's threads (the measured
    /// choice of [`FftThreading::Auto`]).
    pub(super) fn use_fftw_threads(&mut self, fwd: Option<SliceFft>, inv: Option<SliceFft>) {
        self.fwd = fwd;
        self.inv = inv;
        self.fftw_threaded = true;
    }

    /// The real-data slice FFTs, or an error for a plan made without them.
    pub(super) fn real_fft(&self) -> Result<&SliceFftReal> {
        self.real
            .as_ref()
            .ok_or_else(|| Error::InvalidArgument("the plan was made without Options::real".into()))
    }

    /// Run `f` with a per-worker FFT scratch buffer (`2 pairs_per_group` padded slices). A
    /// worker may take on another execution's group while it waits inside a parallel copy,
    /// so buffers are taken by try_lock, never by blocking; when all are busy a private one
    /// is allocated.
    fn with_scratch<R>(&self, f: impl FnOnce(&AlignedBuf) -> Result<R>) -> Result<R> {
        match lock_free(&self.scratch) {
            Some(g) => f(&g),
            None => f(&AlignedBuf::new(scratch_len(self.b))?),
        }
    }

    /// FFT stage of one chunk of the complex layout `blocks`: forward from the sample array
    /// `grid` into the chunk buffer `buf`, or inverse from `buf` into `grid`.
    pub(super) fn chunk(
        &self,
        blocks: &Blocks,
        ch: &Chunk,
        (forward, watch): (bool, Option<SliceWatch>),
        grid: SendPtr<Complex64>,
        buf: ChunkBuf,
    ) -> Result<()> {
        let fft = if forward {
            self.fwd.as_ref()
        } else {
            self.inv.as_ref()
        }
        .ok_or(Error::WrongDirection)?;
        let nn = 4 * self.b * self.b;
        let slices = move |k: usize| SendPtr(grid.get().wrapping_add(k * nn));
        let run = SliceRun {
            fft,
            forward,
            fftw_threaded: self.fftw_threaded,
            watch,
        };
        self.pairs(blocks, ch, run, &slices, buf)
    }

    /// The pairs of `ch` through the slice FFT of `run`; `slice(k)` is where the samples of
    /// beta `k` are. With FFTW's threads, groups one after another (the block copies spread
    /// over the workers), else groups spread over the workers.
    pub(super) fn pairs(
        &self,
        blocks: &Blocks,
        ch: &Chunk,
        run: SliceRun,
        slice: &(dyn Fn(usize) -> SendPtr<Complex64> + Sync),
        buf: ChunkBuf,
    ) -> Result<()> {
        let g = self.pairs_per_group;
        let npairs = ch.h;
        let one_group = |gi: usize| -> Result<()> {
            let j0 = gi * g;
            let gn = g.min(npairs - j0);
            let mut grid = [std::ptr::null_mut(); 2 * MAX_GROUP];
            let mut betas = [0; 2 * MAX_GROUP];
            let mut w = [0.0; 2 * MAX_GROUP];
            for jj in 0..gn {
                let (k0, k1) = ch.pair_betas(self.b, j0 + jj);
                (grid[2 * jj], grid[2 * jj + 1]) = (slice(k0).get(), slice(k1).get());
                (betas[2 * jj], betas[2 * jj + 1]) = (k0, k1);
                (w[2 * jj], w[2 * jj + 1]) = (self.weights[k0], self.weights[k1]);
            }
            self.with_scratch(|scratch| {
                let group = GroupSlices {
                    grid: &grid[..2 * gn],
                    betas: &betas[..2 * gn],
                    weights: &w[..2 * gn],
                    first_pair: j0,
                };
                // SAFETY: the scratch holds `2 pairs_per_group >= 2 gn` padded slices and is
                // this task's alone (locked or private); the group's pairs are its own: no
                // other task reads or writes their sample slices or their rows of the
                // blocks (`Blocks::pair_rows` gives each pair its own rows).
                unsafe { self.group(blocks, run, &group, scratch.as_mut_ptr(), buf) };
                Ok(())
            })
        };
        let ngroups = npairs.div_ceil(g);
        if run.fftw_threaded {
            (0..ngroups).try_for_each(one_group)
        } else {
            (0..ngroups).into_par_iter().try_for_each(one_group)
        }
    }

    /// One group of pairs through the scratch `sp` (`2g` padded slices, see
    /// [`fft::slice_stride`]); with FFTW's threads the block copies are spread over the
    /// workers.
    ///
    /// # Safety
    /// `sp` is valid for `group.grid.len()` padded slices and used by no one else; the
    /// sample slices `group.grid` (`(2B)^2` values each) are valid and read (forward) or
    /// written (inverse) by no other task meanwhile, nor are the group's rows of every
    /// block of `buf`, which holds a chunk of `blocks`.
    unsafe fn group(
        &self,
        blocks: &Blocks,
        run: SliceRun,
        group: &GroupSlices,
        sp: *mut Complex64,
        buf: ChunkBuf,
    ) {
        let (fft, forward, parallel_copy) = (run.fft, run.forward, run.fftw_threaded);
        let n = 2 * self.b;
        let rs = fft::slice_stride(n);
        let ns = group.grid.len();
        let mut s = [SendPtr(std::ptr::null_mut()); 2 * MAX_GROUP];
        for (i, si) in s.iter_mut().enumerate().take(ns) {
            *si = SendPtr(sp.wrapping_add(i * n * rs));
        }
        let s = &s[..ns];
        let slices = SliceGroup {
            slices: s,
            weights: group.weights,
            first_pair: group.first_pair,
        };
        // Rows of a slice between the samples (rows `2n` doubles apart) and the scratch
        // (`2 rs`), spread over the workers with `parallel_copy` (FFTW's threads wait).
        let copy = |from: *const Complex64, to: *mut Complex64| {
            let (from, to) = (SendConstPtr(from as *const f64), SendPtr(to as *mut f64));
            let (ss, ds) = if forward {
                (2 * n, 2 * rs)
            } else {
                (2 * rs, 2 * n)
            };
            let rows = |r0: usize, r1: usize| {
                let (f, t) = (
                    from.get().wrapping_add(r0 * ss),
                    to.get().wrapping_add(r0 * ds),
                );
                // SAFETY: rows r0..r1 of both slices (valid by the caller's contract),
                // disjoint between the pieces `for_ranges` hands out.
                unsafe { fft::copy_rows(f, ss, t, ds, r1 - r0, 2 * n, !forward) };
            };
            self.for_ranges(n, parallel_copy, rows);
        };
        if forward {
            for (dst, &src) in s.iter().zip(group.grid) {
                // Copied first (a sequential read the prefetchers follow), then
                // transformed in the cache: faster than FFTW reading the samples.
                copy(src, dst.get());
                // SAFETY: `dst` is a padded slice of the scratch, this task's alone.
                unsafe { fft.in_place(dst.get()) };
            }
            self.for_ranges(blocks.len(), parallel_copy, |c0, c1| {
                // SAFETY: the slices hold every slot index of `blocks`; the pieces write
                // the group's rows of disjoint clusters' blocks, which only this group
                // writes (caller's contract).
                unsafe { scatter_group(blocks, &slices, false, buf, c0..c1) }
            });
        } else {
            self.for_ranges(blocks.len(), parallel_copy, |c0, c1| {
                // SAFETY: the pieces read the group's rows of disjoint clusters' blocks and
                // write distinct slots of the scratch slices (each in-band frequency
                // belongs to one cluster's slot).
                unsafe { gather_group(blocks, &slices, false, buf, c0..c1) }
            });
            for ((src, &dst), &k) in s.iter().zip(group.grid).zip(group.betas) {
                let src = src.get();
                // SAFETY: row `b` and column `b` of a padded `n x rs` slice of the scratch.
                unsafe {
                    // Frequency B (alpha or gamma) is outside the band limit.
                    for i in 0..n {
                        *src.add(self.b * rs + i) = Complex64::new(0.0, 0.0);
                        *src.add(i * rs + self.b) = Complex64::new(0.0, 0.0);
                    }
                    // In place in the cache, then streamed to the samples: FFTW's own
                    // stores would first read every line of `dst` from memory.
                    fft.in_place(src);
                }
                if let Some(watch) = run.watch {
                    // SAFETY: the padded slice, this task's alone, holds `n` rows of `rs`.
                    let values = unsafe { std::slice::from_raw_parts(src, (n - 1) * rs + n) };
                    watch(
                        k,
                        SliceRef::Complex {
                            values,
                            row: n,
                            stride: rs,
                        },
                    );
                }
                copy(src, dst);
            }
        }
    }

    /// FFT stage of one chunk for real data (see `real.rs`) with the real layout `blocks`,
    /// one mirrored pair of slices at a time: forward from the samples into the blocks
    /// (r2c, then the conjugated half spectra, weighted), or inverse from the blocks into
    /// the samples (c2r).
    pub(super) fn chunk_real(
        &self,
        blocks: &Blocks,
        ch: &Chunk,
        samples: RealSamples<'_>,
        buf: ChunkBuf,
    ) -> Result<()> {
        let fft = self.real_fft()?;
        let (b, n) = (self.b, 2 * self.b);
        let (nn, nh) = (n * n, n * (b + 1));
        (0..ch.h).into_par_iter().try_for_each(|j| -> Result<()> {
            let (k0, k1) = ch.pair_betas(b, j);
            self.with_scratch(|scratch| {
                let sp = scratch.as_mut_ptr();
                let s = [sp, sp.wrapping_add(nh)];
                let slices = [SendPtr(s[0]), SendPtr(s[1])];
                let w = [self.weights[k0], self.weights[k1]];
                let group = SliceGroup {
                    slices: &slices,
                    weights: &w,
                    first_pair: j,
                };
                // Real samples in a complex array go through n^2 packed reals in the free
                // part of the scratch, one slice at a time.
                let packed = sp.wrapping_add(2 * nh) as *mut f64;
                // SAFETY: the scratch (this task's alone) holds at least two padded slices,
                // 2n(n + 4) complex values: two half spectra (nh = n^2/2 + n each) and n^2
                // packed reals (n^2/2 values) fit; pair `j` owns its two rows of every
                // block and its two sample slices (n^2 reals or complex values each), which
                // no other task touches.
                unsafe {
                    match samples {
                        RealSamples::Forward(input) => {
                            for (&dst, k) in s.iter().zip([k0, k1]) {
                                let src = match input {
                                    RealInput::Real(p) => p.get().add(k * nn),
                                    RealInput::RealParts(p) => {
                                        let slice = p.get().add(k * nn);
                                        for i in 0..nn {
                                            *packed.add(i) = (*slice.add(i)).re;
                                        }
                                        packed as *const f64
                                    }
                                };
                                fft.r2c(src, dst);
                            }
                            // S(M,M') = conj(R[M][M']) for M' >= 0.
                            scatter_group(blocks, &group, true, buf, 0..blocks.len());
                        }
                        RealSamples::Inverse(output, watch) => {
                            gather_group(blocks, &group, true, buf, 0..blocks.len());
                            for (&slot, k) in s.iter().zip([k0, k1]) {
                                // Frequency B (alpha or gamma) is outside the band limit.
                                for i in 0..=b {
                                    *slot.add(b * (b + 1) + i) = Complex64::new(0.0, 0.0);
                                }
                                for a in 0..n {
                                    *slot.add(a * (b + 1) + b) = Complex64::new(0.0, 0.0);
                                }
                                let written = match output {
                                    RealOutput::Real(p) => {
                                        let dst = p.get().add(k * nn);
                                        fft.c2r(slot, dst);
                                        dst as *const f64
                                    }
                                    RealOutput::RealParts { samples, stream } => {
                                        // c2r into the cache, then (x, 0) to the samples:
                                        // no second pass over them.
                                        fft.c2r(slot, packed);
                                        let dst = samples.get().add(k * nn) as *mut f64;
                                        fft::spread_reals(packed, dst, nn, stream);
                                        packed as *const f64
                                    }
                                };
                                if let Some(watch) = watch {
                                    // The slice's reals, just written (this task's).
                                    watch(
                                        k,
                                        SliceRef::Real(std::slice::from_raw_parts(written, nn)),
                                    );
                                }
                            }
                        }
                    }
                }
                Ok(())
            })
        })
    }

    /// Run `f(i0, i1)` over `0..len`: in one piece, or, with `parallel`, in pieces spread
    /// over the workers.
    fn for_ranges(&self, len: usize, parallel: bool, f: impl Fn(usize, usize) + Sync) {
        if parallel {
            let step = len.div_ceil(4 * self.threads).max(1);
            (0..len.div_ceil(step))
                .into_par_iter()
                .for_each(|i| f(i * step, ((i + 1) * step).min(len)));
        } else {
            f(0, len);
        }
    }
}

/// The sample slices of a group of pairs (beta, mirror, beta, mirror, ...), their forward
/// weights and the group's first pair.
struct GroupSlices<'a> {
    grid: &'a [*mut Complex64],
    /// The beta index of each slice of `grid`.
    betas: &'a [usize],
    weights: &'a [f64],
    first_pair: usize,
}

/// The block copies of one group of pairs of slices over all clusters of the complex
/// layout, on buffers of their own: for the measuring tools in `benches/` (feature
/// `internals`).
#[cfg(feature = "internals")]
pub struct BlockCopies {
    blocks: Blocks,
    buf: AlignedBuf,
    slices: AlignedBuf,
    pairs: usize,
    slice_len: usize,
}

#[cfg(feature = "internals")]
impl BlockCopies {
    /// Pairs per group the plans of bandwidth `b` use.
    pub fn default_pairs(b: usize) -> usize {
        pairs_per_group(16 * 4 * b * b)
    }

    /// Buffers for a group of `pairs` pairs (1 ..= 4) of padded slices at bandwidth `b` and
    /// the blocks of a chunk of 8 pairs.
    pub fn new(b: usize, pairs: usize) -> Result<BlockCopies> {
        assert!((1..=MAX_GROUP).contains(&pairs));
        let n = 2 * b;
        let blocks = Blocks::complex(b, &crate::symmetry::cluster_pairs(b), 8);
        let buf = AlignedBuf::new(blocks.total() / 2 + 8)?;
        let slice_len = n * fft::slice_stride(n);
        let slices = AlignedBuf::new(2 * pairs * slice_len)?;
        Ok(BlockCopies {
            blocks,
            buf,
            slices,
            pairs,
            slice_len,
        })
    }

    /// Run `f` with the group of slices over the scratch slices.
    fn with_group(&self, f: impl FnOnce(&SliceGroup, &Blocks, *mut f64)) {
        let s: Vec<SendPtr<Complex64>> = (0..2 * self.pairs)
            .map(|i| SendPtr(self.slices.as_mut_ptr().wrapping_add(i * self.slice_len)))
            .collect();
        let w = vec![1.0; 2 * self.pairs];
        let group = SliceGroup {
            slices: &s,
            weights: &w,
            first_pair: 0,
        };
        f(&group, &self.blocks, self.buf.as_mut_ptr() as *mut f64);
    }

    /// The forward's copy: the slices into the cluster-major blocks.
    pub fn scatter(&self) {
        self.with_group(|group, blocks, base| {
            let buf = ChunkBuf {
                base: SendPtr(base),
                layout: BufLayout::Blocks,
            };
            // SAFETY: the slices hold every slot index (padded slices of bandwidth `b`);
            // the buffer holds the blocks of a chunk of 8 pairs (at least `pairs`), all ours.
            unsafe { scatter_group(blocks, group, false, buf, 0..blocks.len()) };
        });
    }

    /// The inverse's copy as a large inverse runs it: the half-major blocks into the slices.
    pub fn gather(&self) {
        self.with_group(|group, blocks, base| {
            let buf = ChunkBuf {
                base: SendPtr(base),
                layout: BufLayout::HalfMajor(blocks.total() / 2),
            };
            // SAFETY: as for `scatter`, with the slices written and the blocks read.
            unsafe { gather_group(blocks, group, false, buf, 0..blocks.len()) };
        });
    }
}
