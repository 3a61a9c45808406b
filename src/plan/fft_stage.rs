//! The FFT stage: FFTW over (alpha, gamma) of each beta slice, and the moves between the
//! transformed slices and the blocks of the chunk buffer, a group of mirrored pairs of beta
//! slices at a time.
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

use super::blocks::{Blocks, BufLayout, ChunkBuf, NONE};
use super::options::{Direction, FftThreading, PlanOptions};
use super::schedule::Chunk;
use super::shared::{lock_free, SendConstPtr, SendPtr};
use crate::error::{Error, Result};
use crate::fft::{self, AlignedBuf, SliceFft, SliceFftReal, SIGN_MINUS, SIGN_PLUS};
use crate::grid::weights;
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Mutex;

/// Most pairs per group (the row buffers of [`scatter_group`] hold `2 * MAX_GROUP` rows).
pub(super) const MAX_GROUP: usize = 4;

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
}

/// The slices of a group of mirrored pairs and where their rows are in the blocks.
pub(super) struct SliceGroup<'a> {
    /// The group's transformed slices: beta, mirror, beta, mirror, ...
    pub slices: &'a [SendPtr<Complex64>],
    /// Forward: the weight of each slice (quadrature weight and normalisation); unused by
    /// the inverse.
    pub weights: &'a [f64],
    /// The group's first pair in its chunk (block rows `2 first_pair ..`).
    pub first_pair: usize,
}

/// The FFT stage of a plan: its slice FFTs, weights and per-worker scratch.
pub(super) struct FftStage {
    b: usize,
    threads: usize,
    /// Forward slice FFT (plans that run the forward).
    fwd: Option<SliceFft>,
    /// Inverse slice FFT (plans that run the inverse).
    inv: Option<SliceFft>,
    /// Real-data slice FFTs (with `PlanOptions::real`).
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
    pub(super) fn new(b: usize, threads: usize, options: &PlanOptions) -> Result<FftStage> {
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
        self.real.as_ref().ok_or_else(|| {
            Error::InvalidArgument("the plan was made without PlanOptions::real".into())
        })
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
        forward: bool,
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
            let mut w = [0.0; 2 * MAX_GROUP];
            for jj in 0..gn {
                let (k0, k1) = ch.pair_betas(self.b, j0 + jj);
                (grid[2 * jj], grid[2 * jj + 1]) = (slice(k0).get(), slice(k1).get());
                (w[2 * jj], w[2 * jj + 1]) = (self.weights[k0], self.weights[k1]);
            }
            self.with_scratch(|scratch| {
                let group = GroupSlices {
                    grid: &grid[..2 * gn],
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
            for (src, &dst) in s.iter().zip(group.grid) {
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
                copy(src, dst);
            }
        }
    }

    /// FFT stage of one chunk for real data (see `real.rs`) with the real layout `blocks`,
    /// one mirrored pair of slices at a time: forward from `input` into the blocks (r2c,
    /// then the conjugated half spectra, weighted), or (with `input = None`) inverse from
    /// the blocks into the real sample array `grid` (c2r).
    pub(super) fn chunk_real(
        &self,
        blocks: &Blocks,
        ch: &Chunk,
        input: Option<RealInput>,
        grid: SendPtr<f64>,
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
                // SAFETY: the scratch (this task's alone) holds at least two padded slices,
                // 2n(n + 4) complex values: two half spectra (nh = n^2/2 + n each) and n^2
                // packed reals (n^2/2 values) fit; pair `j` owns its two rows of every
                // block and its two sample slices (n^2 reals each), which no other task
                // touches.
                unsafe {
                    if let Some(input) = input {
                        // Real parts of complex samples are first packed into the free
                        // part of the scratch, one slice at a time.
                        let packed = sp.add(2 * nh) as *mut f64;
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
                    } else {
                        gather_group(blocks, &group, true, buf, 0..blocks.len());
                        for (&slot, k) in s.iter().zip([k0, k1]) {
                            // Frequency B (alpha or gamma) is outside the band limit.
                            for i in 0..=b {
                                *slot.add(b * (b + 1) + i) = Complex64::new(0.0, 0.0);
                            }
                            for a in 0..n {
                                *slot.add(a * (b + 1) + b) = Complex64::new(0.0, 0.0);
                            }
                            fft.c2r(slot, grid.get().add(k * nn));
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
    weights: &'a [f64],
    first_pair: usize,
}

/// Clusters ahead whose slice values [`prefetch_slots`] requests.
const PREFETCH_SLOTS: usize = 8;

/// Prefetch the slice values of cluster `c`'s slots in the slices `sp` (into L2 for
/// reading, into L1 for writing with `write`): the slots of a cluster lie in different
/// rows of the slices, which from B = 256 on are larger than L2.
///
/// # Safety
/// `c < t.len()`.
#[inline(always)]
unsafe fn prefetch_slots(t: &Blocks, c: usize, sp: &[SendPtr<Complex64>], write: bool) {
    // SAFETY: `c < t.len()` (caller), so the slot indices `8c..8c+8` are in the
    // table; prefetches are hints and never fault.
    unsafe {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_ET0, _MM_HINT_T1};
            for q in 0..t.row_len(c) / 2 {
                let idx = *t.slot_index.get_unchecked(8 * c + q);
                if idx == NONE {
                    continue;
                }
                for s in sp {
                    let a = s.get().wrapping_add(idx as usize) as *const i8;
                    if write {
                        _mm_prefetch::<_MM_HINT_ET0>(a);
                    } else {
                        _mm_prefetch::<_MM_HINT_T1>(a);
                    }
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = (t, c, sp, write);
    }
}

/// Write the rows of the group's pairs (rows `2 first_pair ..`, where the buffer's layout
/// puts them, see `plan/blocks.rs`) of the blocks of clusters `cs` from the group's
/// transformed slices (beta, then pi - beta, for each pair), scaled by their weights (and
/// conjugated with `conj`): the first row of a pair takes each slot from its own slice,
/// the second from the other one; reversed slots the other way round. Unused slots are
/// zero.
///
/// # Safety
/// The group's slices are valid for every index in the slot tables; `buf` holds the blocks
/// of `t`, 64-byte aligned, and nobody else writes these rows meanwhile.
pub(super) unsafe fn scatter_group(
    t: &Blocks,
    group: &SliceGroup,
    conj: bool,
    buf: ChunkBuf,
    cs: std::ops::Range<usize>,
) {
    // SAFETY: the caller's contract (above): the slices hold every slot index of `t`,
    // `buf` holds the blocks, and the rows written are the caller's alone.
    unsafe {
        let (s, w, j0) = (group.slices, group.weights, group.first_pair);
        let (buf, layout) = (buf.base.get(), buf.layout);
        let ns = s.len();
        debug_assert!(ns.is_multiple_of(2) && ns <= 2 * MAX_GROUP && w.len() == ns);
        let mut sp = [std::ptr::null::<Complex64>(); 2 * MAX_GROUP];
        let (mut wr, mut wi) = ([0.0; 2 * MAX_GROUP], [0.0; 2 * MAX_GROUP]);
        for i in 0..ns {
            sp[i] = s[i].get();
            (wr[i], wi[i]) = (w[i], if conj { -w[i] } else { w[i] });
        }
        let end = cs.end;
        for c in cs {
            if t.prefetch_slices && c + PREFETCH_SLOTS < end {
                prefetch_slots(t, c + PREFETCH_SLOTS, s, false);
            }
            let p = t.row_len(c);
            let reversed = t.reversed[c];
            let (at, ps, gap) = t.pair_rows(c, j0, layout);
            let dst = (buf.add(at), ps, gap);
            if t.regular[c] {
                // The common case (`Blocks::regular`), written out.
                match p {
                    16 => scatter_regular::<8>(t, c, &sp[..ns], &wr, conj, dst),
                    _ => scatter_regular::<4>(t, c, &sp[..ns], &wr, conj, dst),
                }
                continue;
            }
            let mut rows = [0.0f64; 16 * 2 * MAX_GROUP];
            for q in 0..p / 2 {
                let idx = *t.slot_index.get_unchecked(8 * c + q);
                if idx == NONE {
                    continue;
                }
                let idx = idx as usize;
                let r = ((reversed >> q) & 1) as usize;
                for jj in 0..ns / 2 {
                    let (a, b) = (*sp[2 * jj].add(idx), *sp[2 * jj + 1].add(idx));
                    let (ra, rb) = ((2 * jj + r) * p + 2 * q, (2 * jj + 1 - r) * p + 2 * q);
                    rows[ra] = a.re * wr[2 * jj];
                    rows[ra + 1] = a.im * wi[2 * jj];
                    rows[rb] = b.re * wr[2 * jj + 1];
                    rows[rb + 1] = b.im * wi[2 * jj + 1];
                }
            }
            store_rows(dst, &rows[..ns * p], p);
        }
        fence();
    }
}

/// Store the rows of `p` doubles of a group of pairs (low-beta row and mirror row of each
/// pair in turn) at `(dst, ps, gap)` from [`Blocks::pair_rows`]: row `2j` at
/// `dst + j * ps`, row `2j + 1` `gap` further; in one piece where they are consecutive.
///
/// # Safety
/// `dst` holds `rows.len() / p` rows of `p` doubles, row `2j` at `dst + j ps` and row
/// `2j + 1` `gap` further, 64-byte aligned and written by no one else meanwhile.
#[inline(always)]
unsafe fn store_rows((dst, ps, gap): (*mut f64, usize, usize), rows: &[f64], p: usize) {
    // SAFETY: the caller's contract: the rows lie in the block at `dst`, 64-byte aligned.
    unsafe {
        if ps == 2 * p && gap == p {
            return stream_rows(dst, rows);
        }
        for (k, row) in rows.chunks_exact(p).enumerate() {
            stream_rows(dst.add((k / 2) * ps + (k % 2) * gap), row);
        }
    }
}

/// Prefetch `lines` cache lines from `a` into L1 (hints only: `a` may point past the
/// buffer).
#[inline(always)]
fn prefetch_lines(a: *const f64, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    for line in 0..lines {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: a prefetch is a hint; it never faults.
        unsafe { _mm_prefetch::<_MM_HINT_T0>((a as *const i8).wrapping_add(64 * line)) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (a, lines);
}

/// Clusters ahead whose rows [`gather_group`] prefetches in the cluster-major layout
/// (blocks in the cache).
const PREFETCH_CLUSTERS: usize = 16;

/// Bytes ahead of its reads in the half-major buffer that [`gather_group`] prefetches.
/// The hardware prefetchers follow the sequential reads, but not far enough ahead.
const GATHER_AHEAD: usize = 4096;

/// The reverse of [`scatter_group`] without weights, from a buffer of any layout (blocks,
/// or the half-major layout of a large inverse, see `plan/blocks.rs`): slots of the rows of
/// the group's pairs into its slices (conjugated with `conj`; the real layout's second
/// index (`Blocks::slot_neg_index`) gets the value itself).
///
/// # Safety
/// As for [`scatter_group`], with the slices written (their slots of clusters `cs` by no
/// one else) and the rows read.
pub(super) unsafe fn gather_group(
    t: &Blocks,
    group: &SliceGroup,
    conj: bool,
    buf: ChunkBuf,
    cs: std::ops::Range<usize>,
) {
    // SAFETY: the caller's contract (above): `buf` holds the blocks of `t`, the slices
    // every slot index, and no one else writes the slots of these clusters.
    unsafe {
        let (s, j0) = (group.slices, group.first_pair);
        let (buf, layout) = (buf.base.get() as *const f64, buf.layout);
        let ns = s.len();
        debug_assert!(ns.is_multiple_of(2) && ns <= 2 * MAX_GROUP);
        let mut sp = [std::ptr::null_mut::<Complex64>(); 2 * MAX_GROUP];
        for i in 0..ns {
            sp[i] = s[i].get();
        }
        let end = cs.end;
        for c in cs {
            if t.prefetch_slices && c + PREFETCH_SLOTS < end {
                prefetch_slots(t, c + PREFETCH_SLOTS, s, true);
            }
            let p = t.row_len(c);
            let (at, ps, gap) = t.pair_rows(c, j0, layout);
            let row = buf.add(at);
            match layout {
                // The rows of a cluster further on.
                BufLayout::Blocks => {
                    let cf = c + PREFETCH_CLUSTERS;
                    if cf < end {
                        let (at, _, _) = t.pair_rows(cf, j0, layout);
                        prefetch_lines(buf.wrapping_add(at), ns * t.row_len(cf) / 8);
                    }
                }
                // The same distance ahead in the sequential run of each half.
                BufLayout::Split(_) | BufLayout::HalfMajor(_) => {
                    for half in [row, row.wrapping_add(gap)] {
                        let a = half.wrapping_add(GATHER_AHEAD / 8);
                        prefetch_lines(a, (ns * p / 16).max(1));
                    }
                }
            }
            let reversed = t.reversed[c];
            if t.regular[c] {
                // The common case (`Blocks::regular`), written out.
                match p {
                    16 => gather_regular::<8>(t, c, &sp[..ns], conj, row, ps, gap),
                    _ => gather_regular::<4>(t, c, &sp[..ns], conj, row, ps, gap),
                }
                continue;
            }
            for q in 0..p / 2 {
                let idx = *t.slot_index.get_unchecked(8 * c + q);
                if idx == NONE {
                    continue;
                }
                let idx = idx as usize;
                let neg_idx = *t.slot_neg_index.get_unchecked(8 * c + q);
                let r = ((reversed >> q) & 1) as usize;
                for jj in 0..ns / 2 {
                    let (ra, rb) = (jj * ps + r * gap + 2 * q, jj * ps + (1 - r) * gap + 2 * q);
                    let a = Complex64::new(*row.add(ra), *row.add(ra + 1));
                    let b = Complex64::new(*row.add(rb), *row.add(rb + 1));
                    let (s0, s1) = (sp[2 * jj], sp[2 * jj + 1]);
                    if conj {
                        *s0.add(idx) = a.conj();
                        *s1.add(idx) = b.conj();
                        if neg_idx != NONE {
                            *s0.add(neg_idx as usize) = a;
                            *s1.add(neg_idx as usize) = b;
                        }
                    } else {
                        *s0.add(idx) = a;
                        *s1.add(idx) = b;
                    }
                }
            }
        }
    }
}

/// [`scatter_group`] for a regular block of `S` slots (`Blocks::regular`): slots below
/// `S/2` from the own slice, the others from the mirrored one.
///
/// # Safety
/// `c < t.len()`; `sp` are valid for every slot index of cluster `c`; `dst` as for
/// [`store_rows`], with room for `sp.len()` rows of `2S` doubles.
#[inline(always)]
unsafe fn scatter_regular<const S: usize>(
    t: &Blocks,
    c: usize,
    sp: &[*const Complex64],
    w: &[f64],
    conj: bool,
    dst: (*mut f64, usize, usize),
) {
    // SAFETY: `c < t.len()`, and the caller's contract for the slices and rows.
    unsafe {
        let f: [usize; S] =
            std::array::from_fn(|q| *t.slot_index.get_unchecked(8 * c + q) as usize);
        let (h, ns) = (S / 2, sp.len());
        let mut rows = [Complex64::new(0.0, 0.0); 8 * 2 * MAX_GROUP];
        for jj in 0..ns / 2 {
            let (s0, s1) = (sp[2 * jj], sp[2 * jj + 1]);
            let (w0, w1) = (w[2 * jj], w[2 * jj + 1]);
            let (lo, hi) = (2 * S * jj, 2 * S * jj + S);
            for q in 0..h {
                rows[lo + q] = *s0.add(f[q]) * w0;
                rows[hi + q] = *s1.add(f[q]) * w1;
                rows[hi + h + q] = *s0.add(f[h + q]) * w0;
                rows[lo + h + q] = *s1.add(f[h + q]) * w1;
            }
        }
        if conj {
            for z in &mut rows[..ns * S] {
                *z = z.conj();
            }
        }
        store_rows(
            dst,
            std::slice::from_raw_parts(rows.as_ptr() as *const f64, ns * 2 * S),
            2 * S,
        );
    }
}

/// [`gather_group`] for a regular block of `S` slots (see [`scatter_regular`]).
///
/// # Safety
/// `c < t.len()`; `sp` are valid for writes at every slot index of cluster `c`, which no
/// one else writes; `row` holds `sp.len()` rows of `2S` doubles, row `2j` at `row + j ps`
/// and row `2j + 1` `gap` further.
#[inline(always)]
unsafe fn gather_regular<const S: usize>(
    t: &Blocks,
    c: usize,
    sp: &[*mut Complex64],
    conj: bool,
    row: *const f64,
    ps: usize,
    gap: usize,
) {
    // SAFETY: `c < t.len()`, and the caller's contract for the slices and rows.
    unsafe {
        let f: [usize; S] =
            std::array::from_fn(|q| *t.slot_index.get_unchecked(8 * c + q) as usize);
        let h = S / 2;
        let rows = row as *const Complex64;
        let v = |z: Complex64| if conj { z.conj() } else { z };
        for jj in 0..sp.len() / 2 {
            let (s0, s1) = (sp[2 * jj], sp[2 * jj + 1]);
            // `ps` and `gap` are even: whole complex values.
            let (lo, hi) = (rows.add(jj * ps / 2), rows.add((jj * ps + gap) / 2));
            for q in 0..h {
                *s0.add(f[q]) = v(*lo.add(q));
                *s1.add(f[q]) = v(*hi.add(q));
                *s0.add(f[h + q]) = v(*hi.add(h + q));
                *s1.add(f[h + q]) = v(*lo.add(h + q));
            }
        }
    }
}

/// Store `rows` (whole 64-byte lines at a 64-byte aligned `dst`) without reading the
/// lines first.
///
/// # Safety
/// `dst` is valid for writes of `rows.len()` doubles (an even number), not overlapping
/// `rows`, and written by no one else meanwhile.
#[inline(always)]
unsafe fn stream_rows(dst: *mut f64, rows: &[f64]) {
    // SAFETY: `dst` is valid for `rows.len()` doubles (caller), and `rows` does not
    // overlap it (a local array).
    unsafe {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_loadu_pd, _mm_stream_pd};
            if (dst as usize).is_multiple_of(64) {
                for i in (0..rows.len()).step_by(2) {
                    _mm_stream_pd(dst.add(i), _mm_loadu_pd(rows.as_ptr().add(i)));
                }
                return;
            }
        }
        std::ptr::copy_nonoverlapping(rows.as_ptr(), dst, rows.len());
    }
}

/// Orders the non-temporal stores of [`stream_rows`] before later stores and loads.
#[inline(always)]
fn fence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a store fence has no memory operands.
    unsafe {
        std::arch::x86_64::_mm_sfence()
    };
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
