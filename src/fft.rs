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

/// An FFTW-allocated (SIMD-aligned) complex buffer.
pub(crate) struct AlignedBuf {
    ptr: *mut Complex64,
    len: usize,
}

// SAFETY: the buffer is plain memory owned by this value.
unsafe impl Send for AlignedBuf {}
unsafe impl Sync for AlignedBuf {}

impl AlignedBuf {
    /// Allocate `len` complex values (uninitialised memory is zeroed).
    pub fn new(len: usize) -> Result<AlignedBuf> {
        let bytes = len
            .checked_mul(16)
            .ok_or(Error::OutOfMemory { bytes: usize::MAX })?;
        let ptr = unsafe { ffi::fftw_malloc(bytes.max(16)) } as *mut Complex64;
        if ptr.is_null() {
            return Err(Error::OutOfMemory { bytes });
        }
        unsafe { std::ptr::write_bytes(ptr, 0, len) };
        Ok(AlignedBuf { ptr, len })
    }

    pub fn as_mut_ptr(&self) -> *mut Complex64 {
        self.ptr
    }

    pub fn len(&self) -> usize {
        self.len
    }
}

impl Drop for AlignedBuf {
    fn drop(&mut self) {
        unsafe { ffi::fftw_free(self.ptr as *mut _) }
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

/// A batch of `howmany` out-of-place `n x n` DFTs between slice-major arrays (one slice of
/// `n*n` contiguous values after another) and the pair-major chunk buffer (value `(a, b)` of
/// batch member `s` at `(a*n + b)*stride + s`), so that the DWT reads each order pair's
/// betas contiguously. The transposition is folded into FFTW's strides.
pub(crate) struct ChunkFft {
    plan: RawPlan,
}

/// Sign of the exponent: `+1` is FFTW_BACKWARD (used by the forward SO(3) transform).
pub(crate) const SIGN_PLUS: i32 = ffi::FFTW_BACKWARD as i32;
/// `-1` is FFTW_FORWARD (used by the inverse SO(3) transform).
pub(crate) const SIGN_MINUS: i32 = ffi::FFTW_FORWARD;

impl ChunkFft {
    /// `to_pairs`: slice-major input to pair-major output (forward SO(3) transform, sign +1);
    /// otherwise pair-major input to slice-major output (inverse, sign -1).
    pub fn new(n: usize, howmany: usize, stride: usize, to_pairs: bool, rigor: Rigor) -> Result<ChunkFft> {
        let nn = n * n;
        // Planning may write to both arrays (FFTW_MEASURE), so plan on scratch memory.
        let slices = AlignedBuf::new(howmany * nn)?;
        let pairs = AlignedBuf::new(stride * nn)?;
        let dims = [n as i32, n as i32];
        let flags = rigor.flags() | ffi::FFTW_UNALIGNED;
        let p = {
            let _g = planner_lock();
            unsafe {
                if to_pairs {
                    ffi::fftw_plan_many_dft(
                        2, dims.as_ptr(), howmany as i32,
                        slices.as_mut_ptr(), std::ptr::null(), 1, nn as i32,
                        pairs.as_mut_ptr(), std::ptr::null(), stride as i32, 1,
                        SIGN_PLUS, flags | ffi::FFTW_PRESERVE_INPUT,
                    )
                } else {
                    ffi::fftw_plan_many_dft(
                        2, dims.as_ptr(), howmany as i32,
                        pairs.as_mut_ptr(), std::ptr::null(), stride as i32, 1,
                        slices.as_mut_ptr(), std::ptr::null(), 1, nn as i32,
                        SIGN_MINUS, flags,
                    )
                }
            }
        };
        if p.is_null() {
            return Err(Error::Fftw(format!("could not plan {howmany} DFTs of size {n}x{n}")));
        }
        Ok(ChunkFft { plan: RawPlan(p) })
    }

    /// Execute on new arrays.
    ///
    /// # Safety
    /// `inp` and `out` must span the extents the plan was made for and not overlap.
    pub unsafe fn execute(&self, inp: *const Complex64, out: *mut Complex64) {
        ffi::fftw_execute_dft(self.plan.0, inp as *mut _, out);
    }
}
