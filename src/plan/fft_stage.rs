//! The FFT stage of the complex transforms, one mirrored pair of beta slices at a time.
//!
//! Forward: both slices of a pair (`beta` and `pi - beta`) are copied into the worker's
//! cache-resident scratch, transformed in place, and moved, weighted, into the rows of
//! every cluster's block (`blocks.rs`): the pair fills the rows of two lanes completely,
//! each written as whole cache lines with non-temporal stores. Inverse: the two rows of
//! every block are read back into two slices, which are transformed into a spare slice and
//! streamed to the samples. The pairs are spread over the workers, or, with FFTW's threads,
//! run one after another with the block copies spread over the workers.

use super::blocks::{Blocks, NONE};
use super::*;

/// Clusters whose rows are prefetched ahead by the inverse copy.
const PREFETCH_CLUSTERS: usize = 16;

impl Plan {
    /// FFT stage of one chunk: forward from `grid` into the blocks of `buf`, or inverse
    /// from `buf` into `grid`.
    pub(super) fn fft_chunk(
        &self,
        ch: &Chunk,
        forward: bool,
        grid: *mut Complex64,
        buf: *mut f64,
    ) -> Result<()> {
        let fft = if forward {
            self.fwd_fft.as_ref()
        } else {
            self.inv_fft.as_ref()
        }
        .ok_or(Error::WrongDirection)?;
        let nn = 4 * self.b * self.b;
        let grid = SyncPtr(grid);
        let slices = move |k: usize| SyncPtr(grid.get().wrapping_add(k * nn));
        self.fft_pairs(ch, fft, self.fftw_threaded, forward, &slices, buf, ch.h)
    }

    /// The first `npairs` pairs of [`Plan::fft_chunk`] with the slice plan `fft`; `slice(k)`
    /// is where the samples of beta `k` are. With `fftw_threaded`, pairs one after another
    /// (`fft` runs on FFTW's threads, the block copies are spread over the workers), else
    /// pairs spread over the workers.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn fft_pairs(
        &self,
        ch: &Chunk,
        fft: &SliceFft,
        fftw_threaded: bool,
        forward: bool,
        slice: &(dyn Fn(usize) -> SyncPtr<Complex64> + Sync),
        buf: *mut f64,
        npairs: usize,
    ) -> Result<()> {
        let buf = SyncPtr(buf);
        let run = |j: usize| -> Result<()> {
            let (k0, k1) = ch.pair_betas(self.b, j);
            self.with_fft_scratch(|scratch| unsafe {
                // SAFETY: the scratch holds three slices; pair `j` owns its two rows of
                // every block and its two sample slices.
                self.fft_pair(
                    fft,
                    forward,
                    [slice(k0).get(), slice(k1).get()],
                    [self.wq[k0], self.wq[k1]],
                    scratch.as_mut_ptr(),
                    buf.get(),
                    j,
                    fftw_threaded,
                );
                Ok(())
            })
        };
        if fftw_threaded {
            (0..npairs).try_for_each(run)
        } else {
            (0..npairs).into_par_iter().try_for_each(run)
        }
    }

    /// One pair of a chunk through the scratch `sp` (three slices): `grid` are the pair's
    /// sample slices, `w` their forward weights; `parallel_copy` spreads the block copies
    /// over the workers.
    #[allow(clippy::too_many_arguments)]
    unsafe fn fft_pair(
        &self,
        fft: &SliceFft,
        forward: bool,
        grid: [*mut Complex64; 2],
        w: [f64; 2],
        sp: *mut Complex64,
        buf: *mut f64,
        j: usize,
        parallel_copy: bool,
    ) {
        let n = 2 * self.b;
        let nn = n * n;
        let s = [sp, sp.add(nn)];
        let spare = sp.add(2 * nn);
        if forward {
            for (&dst, &src) in s.iter().zip(&grid) {
                if fft.has_in_place() {
                    // Copied first (a sequential read the prefetchers follow), then
                    // transformed in the cache: faster than FFTW reading the samples.
                    std::ptr::copy_nonoverlapping(src, dst, nn);
                    fft.in_place(dst, spare, n);
                } else {
                    fft.execute(src, dst);
                }
            }
            let (s0, s1) = (SyncPtr(s[0]), SyncPtr(s[1]));
            let b = SyncPtr(buf);
            self.for_cluster_ranges(&self.blocks, parallel_copy, |c0, c1| {
                scatter_pair(
                    &self.blocks,
                    [s0.get(), s1.get()],
                    w,
                    false,
                    b.get(),
                    j,
                    c0..c1,
                )
            });
        } else {
            let (s0, s1) = (SyncPtr(s[0]), SyncPtr(s[1]));
            let b = SyncPtr(buf);
            self.for_cluster_ranges(&self.blocks, parallel_copy, |c0, c1| {
                gather_pair(
                    &self.blocks,
                    [s0.get(), s1.get()],
                    false,
                    b.get(),
                    j,
                    c0..c1,
                )
            });
            for (&src, &dst) in s.iter().zip(&grid) {
                // Frequency B (alpha or gamma) is outside the band limit.
                for i in 0..n {
                    *src.add(self.b * n + i) = Complex64::new(0.0, 0.0);
                    *src.add(i * n + self.b) = Complex64::new(0.0, 0.0);
                }
                if (dst as usize).is_multiple_of(16) {
                    // Into the cache-resident spare slice, then streamed to the samples:
                    // FFTW's own stores would first read every line of `dst` from memory.
                    fft.execute(src, spare);
                    fft::stream_copy(spare, dst, nn);
                } else {
                    fft.execute(src, dst);
                }
            }
        }
    }

    /// Run `f(c0, c1)` over all clusters of `t`: in one piece, or, with `parallel`, in
    /// pieces spread over the workers.
    pub(super) fn for_cluster_ranges(
        &self,
        t: &Blocks,
        parallel: bool,
        f: impl Fn(usize, usize) + Sync,
    ) {
        let nc = t.len();
        if parallel {
            let step = nc.div_ceil(4 * self.threads).max(1);
            (0..nc.div_ceil(step))
                .into_par_iter()
                .for_each(|i| f(i * step, ((i + 1) * step).min(nc)));
        } else {
            f(0, nc);
        }
    }
}

/// Write the rows of pair `j` (rows `2j` and `2j + 1`, adjacent) of the blocks of
/// clusters `cs` from a pair of transformed slices `s` (beta, then pi - beta), scaled by
/// their weights `w` (and conjugated with `conj`): the first row takes each slot from its
/// own slice, the second from the other one; reversed slots the other way round. Unused
/// slots are zero.
///
/// # Safety
/// `s` are valid for every index in the slot tables; `buf` holds the blocks of `t`,
/// 64-byte aligned, and nobody else writes these rows.
#[allow(clippy::too_many_arguments)]
pub(super) unsafe fn scatter_pair(
    t: &Blocks,
    s: [*const Complex64; 2],
    w: [f64; 2],
    conj: bool,
    buf: *mut f64,
    j: usize,
    cs: std::ops::Range<usize>,
) {
    let ci = if conj { -1.0 } else { 1.0 };
    let wi = [w[0] * ci, w[1] * ci];
    for c in cs {
        let p = t.p(c);
        let rev = t.rev[c];
        let mut rows = [0.0f64; 32];
        for q in 0..p / 2 {
            let fi = *t.fi.get_unchecked(8 * c + q);
            if fi == NONE {
                continue;
            }
            let fi = fi as usize;
            let (a, b) = (*s[0].add(fi), *s[1].add(fi));
            let r = ((rev >> q) & 1) as usize * p;
            rows[r + 2 * q] = a.re * w[0];
            rows[r + 2 * q + 1] = a.im * wi[0];
            rows[p - r + 2 * q] = b.re * w[1];
            rows[p - r + 2 * q + 1] = b.im * wi[1];
        }
        stream_rows(buf.add(t.offset(c) + 2 * j * p), &rows, 2 * p);
    }
    fence();
}

/// The reverse of [`scatter_pair`] without weights: slots of the rows of pair `j` into
/// the pair of slices `s` (conjugated with `conj`; the real layout's second index `fi2`
/// gets the value itself).
///
/// # Safety
/// As for [`scatter_pair`], with `s` written.
pub(super) unsafe fn gather_pair(
    t: &Blocks,
    s: [*mut Complex64; 2],
    conj: bool,
    buf: *const f64,
    j: usize,
    cs: std::ops::Range<usize>,
) {
    let end = cs.end;
    for c in cs {
        #[cfg(target_arch = "x86_64")]
        if c + PREFETCH_CLUSTERS < end {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let cf = c + PREFETCH_CLUSTERS;
            let pf = t.p(cf);
            let rows = buf.add(t.offset(cf) + 2 * j * pf) as *const i8;
            for line in 0..pf / 4 {
                _mm_prefetch::<_MM_HINT_T0>(rows.add(64 * line));
            }
        }
        let p = t.p(c);
        let row = buf.add(t.offset(c) + 2 * j * p);
        let rev = t.rev[c];
        for q in 0..p / 2 {
            let fi = *t.fi.get_unchecked(8 * c + q);
            if fi == NONE {
                continue;
            }
            let r = ((rev >> q) & 1) as usize * p;
            let a = Complex64::new(*row.add(r + 2 * q), *row.add(r + 2 * q + 1));
            let b = Complex64::new(*row.add(p - r + 2 * q), *row.add(p - r + 2 * q + 1));
            let fi = fi as usize;
            if conj {
                *s[0].add(fi) = a.conj();
                *s[1].add(fi) = b.conj();
                let fi2 = *t.fi2.get_unchecked(8 * c + q);
                if fi2 != NONE {
                    *s[0].add(fi2 as usize) = a;
                    *s[1].add(fi2 as usize) = b;
                }
            } else {
                *s[0].add(fi) = a;
                *s[1].add(fi) = b;
            }
        }
    }
}

/// Store `len` doubles (16 or 32: whole 64-byte lines at a 64-byte aligned `dst`) without
/// reading the lines first.
#[inline(always)]
unsafe fn stream_rows(dst: *mut f64, rows: &[f64; 32], len: usize) {
    #[cfg(target_arch = "x86_64")]
    {
        use std::arch::x86_64::{_mm_loadu_pd, _mm_stream_pd};
        if (dst as usize).is_multiple_of(64) {
            for i in (0..len).step_by(2) {
                _mm_stream_pd(dst.add(i), _mm_loadu_pd(rows.as_ptr().add(i)));
            }
            return;
        }
    }
    std::ptr::copy_nonoverlapping(rows.as_ptr(), dst, len);
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
