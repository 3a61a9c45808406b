//! The FFTW stage: 2-D DFTs of beta slices over (alpha, gamma).
//!
//! FFTW's planner is not thread-safe, and the host program may use FFTW too: every
//! planner call (plan creation and destruction) holds [`planner_lock`], and
//! `fftw_make_planner_thread_safe()` is called once so planning from the host's own
//! threads is serialised with ours. Executing a plan on new arrays is thread-safe, so
//! slices are transformed in parallel on the plan's rayon pool. We never change FFTW's
//! process-wide thread settings.

use crate::error::{Error, Result};
use fftw_sys as ffi;
use num_complex::Complex64;
use std::sync::{Mutex, MutexGuard, Once};

/// FFTW planner rigour (FFTW_ESTIMATE ... FFTW_EXHAUSTIVE).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Rigor {
    /// Heuristic plan, no measurement (fast planning).
    #[default]
    Estimate,
    /// Measure a few candidates (planning takes up to a second; faster transforms).
    Measure,
    /// Measure more candidates.
    Patient,
    /// Measure everything.
    Exhaustive,
}

impl Rigor {
    fn flags(self) -> u32 {
        match self {
            Rigor::Estimate => ffi::FFTW_ESTIMATE,
            Rigor::Measure => ffi::FFTW_MEASURE,
            Rigor::Patient => ffi::FFTW_PATIENT,
            Rigor::Exhaustive => ffi::FFTW_EXHAUSTIVE,
        }
    }
}

static LOCK: Mutex<()> = Mutex::new(());
static INIT: Once = Once::new();

/// The global lock around FFTW planner calls.
pub(crate) fn planner_lock() -> MutexGuard<'static, ()> {
    INIT.call_once(|| unsafe { ffi::fftw_make_planner_thread_safe() });
    LOCK.lock().unwrap_or_else(|e| e.into_inner())
}

/// A page-aligned complex buffer, zero-filled. Large buffers are mapped directly and
/// asked to use transparent huge pages: the chunk buffer is read and written with large
/// strides, and 4 KiB pages would make nearly every access a TLB miss.
pub(crate) struct AlignedBuf {
    ptr: *mut Complex64,
    bytes: usize,
}

// SAFETY: the buffer is plain memory owned by this value.
unsafe impl Send for AlignedBuf {}
unsafe impl Sync for AlignedBuf {}

impl AlignedBuf {
    /// Allocate `len` complex values, zero-filled and touched (so page faults happen here).
    /// From 2 MiB on the mapping starts on a 2 MiB boundary and is a whole number of 2 MiB
    /// pages, so that transparent huge pages can back all of it: an unaligned mapping of a
    /// little over 2 MiB (a worker's FFT scratch at B = 128) holds no huge page at all, and
    /// the random accesses of the block copies then miss the TLB (measured: the real
    /// forward's FFT stage 10% slower).
    pub fn new(len: usize) -> Result<AlignedBuf> {
        const HUGE: usize = 1 << 21;
        let want = len
            .checked_mul(16)
            .ok_or(Error::OutOfMemory { bytes: usize::MAX })?
            .max(4096);
        let huge = want >= HUGE;
        let bytes = if huge {
            want.checked_next_multiple_of(HUGE)
                .ok_or(Error::OutOfMemory { bytes: usize::MAX })?
        } else {
            want
        };
        // Room to move the start to a 2 MiB boundary.
        let map = bytes
            .checked_add(if huge { HUGE } else { 0 })
            .ok_or(Error::OutOfMemory { bytes: usize::MAX })?;
        // SAFETY: anonymous private mapping; checked for failure below.
        let raw = unsafe {
            libc::mmap(
                std::ptr::null_mut(),
                map,
                libc::PROT_READ | libc::PROT_WRITE,
                libc::MAP_PRIVATE | libc::MAP_ANONYMOUS | libc::MAP_NORESERVE,
                -1,
                0,
            )
        };
        if raw == libc::MAP_FAILED {
            return Err(Error::OutOfMemory { bytes: want });
        }
        let ptr = if huge {
            // Give back the unaligned head and the tail beyond `bytes`.
            let start = raw as usize;
            let aligned = start.next_multiple_of(HUGE);
            let (head, tail) = (aligned - start, start + map - (aligned + bytes));
            // SAFETY: both ranges lie inside the mapping just made and are page-aligned.
            unsafe {
                if head > 0 {
                    libc::munmap(raw, head);
                }
                if tail > 0 {
                    libc::munmap((aligned + bytes) as *mut libc::c_void, tail);
                }
            }
            aligned as *mut libc::c_void
        } else {
            raw
        };
        unsafe {
            if huge {
                libc::madvise(ptr, bytes, libc::MADV_HUGEPAGE);
            }
            // Touch every page now rather than inside the first transform. With no swap
            // and overcommit, a failure here would be the kernel's OOM killer, so callers
            // check available memory for very large plans (see Plan::new).
            std::ptr::write_bytes(ptr as *mut u8, 0, bytes);
        }
        Ok(AlignedBuf {
            ptr: ptr as *mut Complex64,
            bytes,
        })
    }

    pub fn as_mut_ptr(&self) -> *mut Complex64 {
        self.ptr
    }
}

impl Drop for AlignedBuf {
    fn drop(&mut self) {
        // SAFETY: the mapping was created in `new` with this size.
        unsafe {
            libc::munmap(self.ptr as *mut libc::c_void, self.bytes);
        }
    }
}

struct RawPlan(ffi::fftw_plan);
// SAFETY: FFTW plans may be executed from any thread (new-array execute is thread-safe);
// creation and destruction hold the planner lock.
unsafe impl Send for RawPlan {}
unsafe impl Sync for RawPlan {}

impl Drop for RawPlan {
    fn drop(&mut self) {
        let _g = planner_lock();
        unsafe { ffi::fftw_destroy_plan(self.0) }
    }
}

/// FFTW's current thread count for new plans. `fftw_planner_nthreads` exists from FFTW
/// 3.3.9 on and is looked up at run time, so the library still loads with 3.3.8 (where the
/// host's setting cannot be read and is taken to be FFTW's default, 1).
fn fftw_planner_nthreads() -> std::os::raw::c_int {
    type F = unsafe extern "C" fn() -> std::os::raw::c_int;
    // SAFETY: dlsym with a NUL-terminated name; the symbol, when present, has this type.
    unsafe {
        let sym = libc::dlsym(libc::RTLD_DEFAULT, c"fftw_planner_nthreads".as_ptr());
        if sym.is_null() {
            1
        } else {
            std::mem::transmute::<*mut libc::c_void, F>(sym)()
        }
    }
}

static THREADS_INIT: Once = Once::new();
static THREADS_OK: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
/// The process that initialised FFTW's threads: in a child made by `fork()` FFTW's worker
/// threads do not exist, and a threaded FFTW plan would wait for them forever, so plans
/// made there are single-threaded.
static THREADS_PID: std::sync::atomic::AtomicU32 = std::sync::atomic::AtomicU32::new(0);

/// Complex values of padding after each row of a slice in the FFT scratch. A slice's rows
/// of `2B` values are a multiple of 4 KiB apart for many B, so a walk down a column stays
/// in one set of the caches and FFTW copies columns out and back (`fftw_cpy2d`). One
/// cache line of padding avoids that: FFTW's in-place 2-D transforms run 15-35% faster
/// for `n = 64 .. 512` here (FFTW_MEASURE, best of 7 batches; 1.45 -> 1.03 ms at n = 512).
pub(crate) const SLICE_PAD: usize = 4;

/// Row stride, in complex values, of an `n x n` slice in the FFT scratch.
pub(crate) const fn slice_stride(n: usize) -> usize {
    n + SLICE_PAD
}

/// Plan one in-place `n x n` DFT of a slice with rows [`slice_stride`]`(n)` apart; with
/// `nthreads > 1` the plan runs on FFTW's own threads.
///
/// FFTW's thread count for new plans is process-wide: it is set only while this plan is
/// made, under the planner lock, and the host's value is restored before the lock is
/// released, so the host's FFTW settings are unchanged when we return.
fn make_plan(n: usize, sign: i32, flags: u32, nthreads: usize) -> Result<RawPlan> {
    // Planning may write to the array (FFTW_MEASURE): plan on scratch memory.
    let rs = slice_stride(n);
    let a = AlignedBuf::new(n * rs)?;
    let dims = [
        ffi::fftw_iodim {
            n: n as i32,
            is: rs as i32,
            os: rs as i32,
        },
        ffi::fftw_iodim {
            n: n as i32,
            is: 1,
            os: 1,
        },
    ];
    let p = {
        let _g = planner_lock();
        unsafe {
            let threaded = nthreads > 1 && {
                THREADS_INIT.call_once(|| {
                    let ok = ffi::fftw_init_threads() != 0;
                    THREADS_OK.store(ok, std::sync::atomic::Ordering::Relaxed);
                    THREADS_PID.store(std::process::id(), std::sync::atomic::Ordering::Relaxed);
                });
                THREADS_OK.load(std::sync::atomic::Ordering::Relaxed)
                    && THREADS_PID.load(std::sync::atomic::Ordering::Relaxed) == std::process::id()
            };
            let host = if threaded {
                let host = fftw_planner_nthreads();
                ffi::fftw_plan_with_nthreads(nthreads as i32);
                Some(host)
            } else {
                None
            };
            let d = a.as_mut_ptr();
            let p =
                ffi::fftw_plan_guru_dft(2, dims.as_ptr(), 0, std::ptr::null(), d, d, sign, flags);
            if let Some(host) = host {
                ffi::fftw_plan_with_nthreads(host);
            }
            p
        }
    };
    if p.is_null() {
        return Err(Error::Fftw(format!("could not plan a {n}x{n} DFT")));
    }
    Ok(RawPlan(p))
}

/// Sign of the exponent: `+1` is FFTW_BACKWARD (used by the forward SO(3) transform).
pub(crate) const SIGN_PLUS: i32 = ffi::FFTW_BACKWARD as i32;
/// `-1` is FFTW_FORWARD (used by the inverse SO(3) transform).
pub(crate) const SIGN_MINUS: i32 = ffi::FFTW_FORWARD;

/// In-place `n x n` complex DFT of one beta slice in the FFT scratch, rows
/// [`slice_stride`]`(n)` apart.
pub(crate) struct SliceFft {
    aligned: RawPlan,
    /// Plan for arrays not aligned as FFTW's SIMD code wants (FFTW_UNALIGNED, planned
    /// with FFTW_ESTIMATE, on as many threads). The scratch slices always are aligned;
    /// this is a safety net.
    unaligned: RawPlan,
}

impl SliceFft {
    /// A plan for one slice; `nthreads > 1` makes it run on FFTW's own threads.
    pub fn new(n: usize, sign: i32, rigor: Rigor, nthreads: usize) -> Result<SliceFft> {
        Ok(SliceFft {
            aligned: make_plan(n, sign, rigor.flags(), nthreads)?,
            unaligned: make_plan(n, sign, ffi::FFTW_ESTIMATE | ffi::FFTW_UNALIGNED, nthreads)?,
        })
    }

    /// Transform the slice at `data` in place.
    ///
    /// # Safety
    /// `data` valid for `n * slice_stride(n)` values.
    pub unsafe fn in_place(&self, data: *mut Complex64) {
        let plan = if ffi::fftw_alignment_of(data as *mut f64) == 0 {
            &self.aligned
        } else {
            &self.unaligned
        };
        ffi::fftw_execute_dft(plan.0, data, data);
    }
}

/// Plan one `n x n` real-to-complex (`r2c`) or complex-to-real (`c2r`) DFT, single-threaded.
fn make_real_plan(n: usize, r2c: bool, flags: u32) -> Result<RawPlan> {
    // Scratch for planning (FFTW_MEASURE writes): room for n^2 reals or n(n/2+1) complex.
    let a = AlignedBuf::new(n * n)?;
    let b = AlignedBuf::new(n * n)?;
    let p = {
        let _g = planner_lock();
        unsafe {
            if r2c {
                ffi::fftw_plan_dft_r2c_2d(
                    n as i32,
                    n as i32,
                    a.as_mut_ptr() as *mut f64,
                    b.as_mut_ptr(),
                    flags | ffi::FFTW_PRESERVE_INPUT,
                )
            } else {
                // A multi-dimensional c2r cannot preserve its input; ours is scratch.
                ffi::fftw_plan_dft_c2r_2d(
                    n as i32,
                    n as i32,
                    a.as_mut_ptr(),
                    b.as_mut_ptr() as *mut f64,
                    flags,
                )
            }
        }
    };
    if p.is_null() {
        return Err(Error::Fftw(format!("could not plan a real {n}x{n} DFT")));
    }
    Ok(RawPlan(p))
}

/// Real-data slice transforms: `r2c` (FFTW sign -1, output `n x (n/2+1)`) and its
/// inverse-direction `c2r` (sign +1), each with an aligned and an unaligned variant.
pub(crate) struct SliceFftReal {
    r2c: RawPlan,
    r2c_unaligned: RawPlan,
    c2r: RawPlan,
    c2r_unaligned: RawPlan,
}

impl SliceFftReal {
    pub fn new(n: usize, rigor: Rigor) -> Result<SliceFftReal> {
        let u = ffi::FFTW_ESTIMATE | ffi::FFTW_UNALIGNED;
        Ok(SliceFftReal {
            r2c: make_real_plan(n, true, rigor.flags())?,
            r2c_unaligned: make_real_plan(n, true, u)?,
            c2r: make_real_plan(n, false, rigor.flags())?,
            c2r_unaligned: make_real_plan(n, false, u)?,
        })
    }

    /// `n*n` reals at `inp` to `n*(n/2+1)` complex values at `out`.
    ///
    /// # Safety
    /// Both pointers valid for those extents, no overlap.
    pub unsafe fn r2c(&self, inp: *const f64, out: *mut Complex64) {
        let aligned = ffi::fftw_alignment_of(inp as *mut f64) == 0
            && ffi::fftw_alignment_of(out as *mut f64) == 0;
        let p = if aligned {
            &self.r2c
        } else {
            &self.r2c_unaligned
        };
        ffi::fftw_execute_dft_r2c(p.0, inp as *mut f64, out);
    }

    /// `n*(n/2+1)` complex values at `inp` (destroyed) to `n*n` reals at `out`.
    ///
    /// # Safety
    /// Both pointers valid for those extents, no overlap.
    pub unsafe fn c2r(&self, inp: *mut Complex64, out: *mut f64) {
        let aligned =
            ffi::fftw_alignment_of(inp as *mut f64) == 0 && ffi::fftw_alignment_of(out) == 0;
        let p = if aligned {
            &self.c2r
        } else {
            &self.c2r_unaligned
        };
        ffi::fftw_execute_dft_c2r(p.0, inp, out);
    }
}

/// Copy `rows` rows of `len` doubles from rows `ss` doubles apart at `src` to rows `ds`
/// apart at `dst`; with `stream`, by non-temporal stores where `dst` and its rows are
/// 16-byte aligned (for memory the transform does not read again: ordinary stores would
/// first read every line).
///
/// # Safety
/// Both valid for those extents, no overlap.
pub(crate) unsafe fn copy_rows(
    src: *const f64,
    ss: usize,
    dst: *mut f64,
    ds: usize,
    rows: usize,
    len: usize,
    stream: bool,
) {
    #[cfg(target_arch = "x86_64")]
    if stream && (dst as usize).is_multiple_of(16) && ds.is_multiple_of(2) && len.is_multiple_of(2)
    {
        use std::arch::x86_64::{_mm_loadu_pd, _mm_sfence, _mm_stream_pd};
        for r in 0..rows {
            let (s, d) = (src.add(r * ss), dst.add(r * ds));
            for i in (0..len).step_by(2) {
                _mm_stream_pd(d.add(i), _mm_loadu_pd(s.add(i)));
            }
        }
        _mm_sfence();
        return;
    }
    let _ = stream;
    for r in 0..rows {
        std::ptr::copy_nonoverlapping(src.add(r * ss), dst.add(r * ds), len);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Buffers from 2 MiB on start on a 2 MiB boundary; every size is zero-filled and
    /// writable to its last value, and dropping gives the memory back (no crash when
    /// many are made and dropped).
    #[test]
    fn aligned_buffers() {
        for len in [
            1usize,
            255,
            4096,
            (1 << 17) - 1,
            1 << 17,
            (1 << 17) + 1,
            300_000,
        ] {
            for _ in 0..3 {
                let b = AlignedBuf::new(len).unwrap();
                let p = b.as_mut_ptr();
                if len * 16 >= 1 << 21 {
                    assert_eq!(p as usize % (1 << 21), 0, "len {len}");
                } else {
                    assert_eq!(p as usize % 4096, 0, "len {len}");
                }
                // SAFETY: `len` values were allocated.
                let s = unsafe { std::slice::from_raw_parts_mut(p, len) };
                assert!(s.iter().all(|z| z.re == 0.0 && z.im == 0.0));
                s[len - 1] = Complex64::new(1.0, 2.0);
                s[0] = Complex64::new(3.0, 4.0);
            }
        }
    }
}
